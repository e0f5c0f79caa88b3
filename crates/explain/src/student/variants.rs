//! The colours a reference pixel would have under each behaviour a student's tracer may
//! have instead of the reference's: the settings ones traced again through the one code
//! path (`trace_pixel_with`) in a copy of the scene with that setting changed, prepared
//! once for the whole image; the others read off the reference pixel's recorded tree.

use whitted_ir::{validate, Color, Highlight, Scene, ShadowMode, ValidScene};
use whitted_tracer::ray_tree::{RayNode, RayTree};
use whitted_tracer::{
    trace_pixel_with, NoRecord, PixelAccumulator, PreparedScene, RayKind, RenderOptions,
};

use super::{Behaviour, Reference};
use crate::findings::walk;

/// How many depths below the reference's are tried (a student who stopped recursing
/// usually stopped at 0 or 1).
const LOWER_DEPTHS: u32 = 6;

/// A copy of the scene with one setting changed, prepared.
pub(super) struct Variant {
    pub behaviour: Behaviour,
    pub scene: ValidScene,
    pub prepared: PreparedScene,
    pub options: RenderOptions,
}

/// The behaviours to try against a reference scene, with the scene copies they need.
pub struct Behaviours {
    pub(super) variants: Vec<Variant>,
}

impl Behaviours {
    /// Prepares one copy of `scene` (the reference's, settings applied) per setting a
    /// student's tracer may treat differently: the other shadow modes, no ambient light, the
    /// other highlight model, back faces the other way. The copies cost a BVH build each;
    /// they are made once for every region of an image.
    pub fn new(scene: &Scene) -> Behaviours {
        let settings = &scene.settings;
        let mut changes: Vec<Behaviour> =
            [ShadowMode::None, ShadowMode::Opaque, ShadowMode::Filtered]
                .into_iter()
                .filter(|&mode| mode != settings.shadows)
                .map(|mode| Behaviour::Shadows { mode })
                .collect();
        if settings.ambient != Color::BLACK {
            changes.push(Behaviour::NoAmbient);
        }
        changes.push(Behaviour::Highlight {
            model: match settings.highlight {
                Highlight::Phong => Highlight::Blinn,
                Highlight::Blinn => Highlight::Phong,
            },
        });
        changes.push(Behaviour::ShadeBack {
            on: !settings.shade_back,
        });
        let variants = changes
            .into_iter()
            .filter_map(|behaviour| {
                let mut copy = scene.clone();
                let settings = &mut copy.settings;
                match behaviour {
                    Behaviour::Shadows { mode } => settings.shadows = mode,
                    Behaviour::NoAmbient => settings.ambient = Color::BLACK,
                    Behaviour::Highlight { model } => settings.highlight = model,
                    Behaviour::ShadeBack { on } => settings.shade_back = on,
                    _ => return None,
                }
                // A setting changed to another valid value leaves the scene valid; should
                // it not, that behaviour is simply not tried.
                let scene = validate(copy).ok()?;
                let prepared = PreparedScene::new(&scene);
                let options = RenderOptions::from_settings(&scene.settings);
                Some(Variant {
                    behaviour,
                    scene,
                    prepared,
                    options,
                })
            })
            .collect();
        Behaviours { variants }
    }

    /// The prepared copy for `behaviour`, when it is one of the settings ones.
    pub(super) fn variant(&self, behaviour: Behaviour) -> Option<&Variant> {
        self.variants.iter().find(|v| v.behaviour == behaviour)
    }

    /// Each behaviour with the pixel's linear colour under it, in the order ties are broken
    /// (the commoner mistake first).
    pub(super) fn colors(
        &self,
        reference: Reference<'_>,
        tree: &RayTree,
    ) -> Vec<(Behaviour, [f32; 3])> {
        let [x, y] = tree.pixel;
        let mut out = Vec::new();
        let settings_variant = |out: &mut Vec<(Behaviour, [f32; 3])>,
                                wanted: &dyn Fn(Behaviour) -> bool| {
            for v in self.variants.iter().filter(|v| wanted(v.behaviour)) {
                out.push((v.behaviour, pixel_color(&v.prepared, &v.options, x, y)));
            }
        };
        settings_variant(&mut out, &|b| matches!(b, Behaviour::Shadows { .. }));
        let deepest = tree
            .samples
            .iter()
            .map(|s| s.root.deepest())
            .max()
            .unwrap_or(0);
        let reference_depth = reference.options.max_depth;
        for max_depth in (reference_depth.saturating_sub(LOWER_DEPTHS)..reference_depth).rev() {
            // Depths the tree never reached change nothing.
            if max_depth < deepest {
                let options = RenderOptions {
                    max_depth,
                    ..*reference.options
                };
                out.push((
                    Behaviour::Depth {
                        max_depth,
                        lowest: max_depth,
                    },
                    pixel_color(reference.prepared, &options, x, y),
                ));
            }
        }
        settings_variant(&mut out, &|b| b == Behaviour::NoAmbient);
        let samples = tree.samples.len().max(1) as f32;
        let specular = sum_over(tree, samples, false, specular_light);
        if specular.iter().any(|&c| c > 0.0) {
            out.push((Behaviour::NoSpecular, minus(tree.color, specular)));
        }
        settings_variant(&mut out, &|b| {
            matches!(b, Behaviour::Highlight { .. } | Behaviour::ShadeBack { .. })
        });
        let tir = sum_over(tree, samples, true, tir_light);
        if tir.iter().any(|&c| c > 0.0) {
            out.push((Behaviour::NoTotalInternalReflection, minus(tree.color, tir)));
        }
        if tree.samples.iter().all(|s| s.root.hit.is_some()) {
            let background = reference.scene.settings.background;
            out.push((
                Behaviour::Missed,
                [
                    background.r as f32,
                    background.g as f32,
                    background.b as f32,
                ],
            ));
        }
        if tree
            .samples
            .iter()
            .any(|s| s.root.deepest() >= reference_depth)
        {
            let max_depth = (reference_depth + 1).min(whitted_ir::limits::MAX_DEPTH);
            if max_depth > reference_depth {
                let options = RenderOptions {
                    max_depth,
                    ..*reference.options
                };
                out.push((
                    Behaviour::Depth {
                        max_depth,
                        lowest: max_depth,
                    },
                    pixel_color(reference.prepared, &options, x, y),
                ));
            }
        }
        out
    }
}

/// The pixel's colour, every sample traced without recording (the rendered pixel, bit for
/// bit).
pub(super) fn pixel_color(
    prepared: &PreparedScene,
    options: &RenderOptions,
    x: u32,
    y: u32,
) -> [f32; 3] {
    let mut pixel = PixelAccumulator::new();
    for sample in 0..options.samples_per_pixel.max(1) {
        pixel.add(trace_pixel_with(
            prepared,
            options,
            x,
            y,
            sample,
            &mut NoRecord,
        ));
    }
    pixel.mean()
}

fn minus(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|c| (a[c] - b[c]).max(0.0))
}

/// The light, at the pixel, of what `part` picks out of each ray, over every sample. With
/// `whole`, `part` picks a ray's whole light, which holds the light of the rays below it:
/// those are not counted again.
fn sum_over(
    tree: &RayTree,
    samples: f32,
    whole: bool,
    part: fn(&RayNode) -> Option<[f32; 3]>,
) -> [f32; 3] {
    let mut total = [0.0f32; 3];
    walk(tree, &mut |node, above| {
        if whole && above.iter().any(|a| part(a).is_some()) {
            return;
        }
        if let Some(light) = part(node) {
            for c in 0..3 {
                total[c] += light[c] / samples;
            }
        }
    });
    total
}

/// A hit's specular terms, weighted by the ray's path weight and the hit's absorption.
fn specular_light(node: &RayNode) -> Option<[f32; 3]> {
    let (local, hit) = (node.local.as_ref()?, node.hit.as_ref()?);
    Some(std::array::from_fn(|c| {
        let specular: f32 = local.lights.iter().map(|l| l.specular[c]).sum();
        specular * node.weight[c] * hit.absorption[c]
    }))
}

/// The whole light a totally internally reflected ray brings.
fn tir_light(node: &RayNode) -> Option<[f32; 3]> {
    let tir = node.kind == RayKind::Reflected
        && node
            .interface
            .as_ref()
            .is_some_and(|i| i.total_internal_reflection);
    tir.then(|| std::array::from_fn(|c| node.weight[c] * node.color[c]))
}
