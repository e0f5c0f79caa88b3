//! Ray-tree diff (`whitted diff`, `whitted trace --against`): one pixel's ray trees under two
//! scenes (or two settings of one scene), aligned ray by ray, and the places where they
//! diverge: a different object hit, a different material value, a ray traced in one only.
//!
//! Both trees come from the tracer's one code path (`trace_pixel`). Rays are aligned by
//! position: the camera ray of each sample, then children by kind (shadow rays by their
//! light). At the first difference in a ray the walk reports it and does not descend: what
//! lies below is its consequence. Each divergence says how much the rays concerned give the
//! pixel in A and in B (their subtree's path weight times returned colour).

mod rays;
mod text;

pub use rays::{ray_changes, Change, RayChange};
pub use text::format_text;

use serde::Serialize;
use whitted_ir::properties::MATERIAL_COLORS;
use whitted_ir::{Handle, Material, Scene};
use whitted_tracer::ray_tree::{trace_pixel, HitInfo, RayNode, RayTree, SampleChoice, TraceError};
use whitted_tracer::{PreparedScene, RayKind, RenderOptions};

use crate::findings::source_line;

/// The version of `whitted diff --json`'s document (docs/diff.md).
pub const DIFF_JSON_VERSION: u32 = 1;

/// One side of a diff: a prepared scene, the IR it was made from, and its options.
#[derive(Clone, Copy)]
pub struct Side<'a> {
    pub prepared: &'a PreparedScene,
    pub scene: &'a Scene,
    pub options: &'a RenderOptions,
}

/// Two ray trees of one pixel compared.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TreeDiff {
    pub version: u32,
    pub pixel: [u32; 2],
    /// The pixel's colour in A and in B (linear RGB, as `render` makes it).
    pub color: [[f32; 3]; 2],
    /// Settings that differ between A and B: name, value in A, value in B.
    pub settings: Vec<[String; 3]>,
    /// Every place the trees diverge, in the order of the rays (the first is the first
    /// divergence); nothing below a divergence is listed.
    pub divergences: Vec<Divergence>,
    /// Rays in A and in B.
    pub rays: [usize; 2],
}

/// One place where the two trees differ.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Divergence {
    pub sample: u32,
    /// The rays from the eye to this one (`camera`, then `reflected`, `transmitted` or
    /// `shadow`).
    pub route: Vec<RayKind>,
    pub depth: u32,
    pub kind: DivergenceKind,
    /// What differs, in words (`ior of material glass`).
    pub what: String,
    /// Its value in A and in B.
    pub values: [String; 2],
    /// `file:line:col` of what differs, in A and in B (when it has a place in the scene).
    pub location: [Option<String>; 2],
    /// The text of those lines.
    pub source_line: [Option<String>; 2],
    /// What the rays concerned give the pixel in A and in B: this ray's path weight times
    /// its returned colour over the samples (for a shadow ray, its light's term at the hit).
    pub contribution: [[f32; 3]; 2],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DivergenceKind {
    /// The ray exists in A only.
    OnlyInA,
    /// The ray exists in B only.
    OnlyInB,
    /// It hits a different object (or one hits and the other leaves the scene).
    Object,
    /// Same object, but a value of the material at the hit differs.
    Material,
    /// Same object and material, hit at another distance (the object moved or changed).
    Distance,
    /// A shadow ray found something else on its way to the light.
    Shadow,
    /// The local illumination at the hit differs (a light changed).
    Light,
    /// Both rays leave the scene but return different colours (the background).
    Background,
}

/// Records pixel `(x, y)` under A and B (every sample) and compares the trees.
pub fn diff_pixel(a: Side<'_>, b: Side<'_>, x: u32, y: u32) -> Result<TreeDiff, TraceError> {
    let tree_a = trace_pixel(a.prepared, a.scene, a.options, x, y, SampleChoice::All)?;
    let tree_b = trace_pixel(b.prepared, b.scene, b.options, x, y, SampleChoice::All)?;
    Ok(diff_trees(a.scene, &tree_a, b.scene, &tree_b))
}

/// Compares two recorded trees of one pixel; `scene_a` and `scene_b` are the scenes they
/// were traced from (material values and source lines come from them).
pub fn diff_trees(scene_a: &Scene, a: &RayTree, scene_b: &Scene, b: &RayTree) -> TreeDiff {
    let walk = Walk {
        scenes: [scene_a, scene_b],
        spp: [
            a.samples_per_pixel.max(1) as f32,
            b.samples_per_pixel.max(1) as f32,
        ],
    };
    let mut divergences = Vec::new();
    let count = a.samples.len().max(b.samples.len());
    for i in 0..count {
        match (a.samples.get(i), b.samples.get(i)) {
            (Some(sa), Some(sb)) => walk.compare(
                sa.index,
                &sa.root,
                &sb.root,
                None,
                &mut vec![RayKind::Camera],
                &mut divergences,
            ),
            (Some(s), None) => divergences.push(walk.one_side(
                s.index,
                &s.root,
                None,
                &[RayKind::Camera],
                0,
                "not traced (B has fewer samples)",
            )),
            (None, Some(s)) => divergences.push(walk.one_side(
                s.index,
                &s.root,
                None,
                &[RayKind::Camera],
                1,
                "not traced (A has fewer samples)",
            )),
            (None, None) => {}
        }
    }
    let rays = |t: &RayTree| t.samples.iter().map(|s| s.root.ray_count()).sum();
    TreeDiff {
        version: DIFF_JSON_VERSION,
        pixel: a.pixel,
        color: [a.color, b.color],
        settings: settings_changes(scene_a, a, scene_b, b),
        divergences,
        rays: [rays(a), rays(b)],
    }
}

fn settings_changes(
    scene_a: &Scene,
    a: &RayTree,
    scene_b: &Scene,
    b: &RayTree,
) -> Vec<[String; 3]> {
    let (sa, sb) = (&scene_a.settings, &scene_b.settings);
    let rows: [(&str, String, String); 10] = [
        (
            "max_depth",
            a.max_depth.to_string(),
            b.max_depth.to_string(),
        ),
        (
            "min_weight",
            a.min_weight.to_string(),
            b.min_weight.to_string(),
        ),
        (
            "samples",
            a.samples_per_pixel.to_string(),
            b.samples_per_pixel.to_string(),
        ),
        (
            "image size",
            format!("{}x{}", a.image_size[0], a.image_size[1]),
            format!("{}x{}", b.image_size[0], b.image_size[1]),
        ),
        (
            "background",
            color_text(sa.background),
            color_text(sb.background),
        ),
        ("ambient", color_text(sa.ambient), color_text(sb.ambient)),
        (
            "epsilon",
            format!("{:?}", sa.epsilon),
            format!("{:?}", sb.epsilon),
        ),
        (
            "shadows",
            format!("{:?}", sa.shadows).to_lowercase(),
            format!("{:?}", sb.shadows).to_lowercase(),
        ),
        (
            "highlight",
            format!("{:?}", sa.highlight).to_lowercase(),
            format!("{:?}", sb.highlight).to_lowercase(),
        ),
        (
            "shade_back",
            sa.shade_back.to_string(),
            sb.shade_back.to_string(),
        ),
    ];
    rows.into_iter()
        .filter(|(_, x, y)| x != y)
        .map(|(name, x, y)| [name.to_string(), x, y])
        .collect()
}

fn color_text(c: whitted_ir::Color) -> String {
    format!("rgb({}, {}, {})", c.r, c.g, c.b)
}

fn rgb(c: [f32; 3]) -> String {
    format!("rgb({:.4}, {:.4}, {:.4})", c[0], c[1], c[2])
}

/// Whether two recorded numbers differ by more than f32 noise of a reordered scene.
fn differs(x: f32, y: f32) -> bool {
    (x - y).abs() > 1e-5 * x.abs().max(y.abs()).max(1.0) || x.is_nan() != y.is_nan()
}

fn differs3(x: [f32; 3], y: [f32; 3]) -> bool {
    (0..3).any(|i| differs(x[i], y[i]))
}

struct Walk<'s> {
    scenes: [&'s Scene; 2],
    spp: [f32; 2],
}

impl Walk<'_> {
    /// What a ray gives the pixel; a shadow ray's light term at its parent's hit.
    fn contribution(&self, side: usize, node: &RayNode, parent: Option<&RayNode>) -> [f32; 3] {
        let spp = self.spp[side];
        if node.kind == RayKind::Shadow {
            let Some(parent) = parent else {
                return [0.0; 3];
            };
            let light = node.shadow.as_ref().map(|s| s.light.handle);
            let absorption = parent.hit.as_ref().map_or([1.0; 3], |h| h.absorption);
            let term = parent
                .local
                .as_ref()
                .and_then(|l| l.lights.iter().find(|c| Some(c.light.handle) == light))
                .map_or([0.0; 3], |c| {
                    std::array::from_fn(|i| c.diffuse[i] + c.specular[i])
                });
            return std::array::from_fn(|i| parent.weight[i] * absorption[i] * term[i] / spp);
        }
        std::array::from_fn(|i| node.weight[i] * node.color[i] / spp)
    }

    #[allow(clippy::too_many_arguments)]
    fn push(
        &self,
        out: &mut Vec<Divergence>,
        sample: u32,
        route: &[RayKind],
        node: (&RayNode, &RayNode),
        parents: (Option<&RayNode>, Option<&RayNode>),
        kind: DivergenceKind,
        what: String,
        values: [String; 2],
        location: [Option<String>; 2],
    ) {
        let source_line = [0, 1].map(|i| {
            location[i]
                .as_deref()
                .and_then(|l| source_line(self.scenes[i], l))
        });
        out.push(Divergence {
            sample,
            route: route.to_vec(),
            depth: node.0.depth,
            kind,
            what,
            values,
            location,
            source_line,
            contribution: [
                self.contribution(0, node.0, parents.0),
                self.contribution(1, node.1, parents.1),
            ],
        });
    }

    /// A ray present on one side only (`side` 0 is A); `other` says what the other side did.
    fn one_side(
        &self,
        sample: u32,
        node: &RayNode,
        parent: Option<&RayNode>,
        route: &[RayKind],
        side: usize,
        other: &str,
    ) -> Divergence {
        let what_it_did = match (&node.hit, &node.shadow) {
            (Some(hit), _) => format!("traced: hits {}", hit.object.label),
            (None, Some(shadow)) => {
                format!("traced to {}: {:?}", shadow.light.label, shadow.result).to_lowercase()
            }
            (None, None) => "traced: leaves the scene".to_string(),
        };
        let mut values = [other.to_string(), other.to_string()];
        values[side] = what_it_did;
        let mut location = [None, None];
        if let Some(hit) = &node.hit {
            location[side] = Some(hit.object.location.clone());
        }
        let source_line = [0, 1].map(|i| {
            location[i]
                .as_deref()
                .and_then(|l| source_line(self.scenes[i], l))
        });
        let mut contribution = [[0.0; 3]; 2];
        contribution[side] = self.contribution(side, node, parent);
        Divergence {
            sample,
            route: route.to_vec(),
            depth: node.depth,
            kind: if side == 0 {
                DivergenceKind::OnlyInA
            } else {
                DivergenceKind::OnlyInB
            },
            what: format!("{} ray at depth {}", node.kind.name(), node.depth),
            values,
            location,
            source_line,
            contribution,
        }
    }

    fn compare(
        &self,
        sample: u32,
        a: &RayNode,
        b: &RayNode,
        parents: Option<(&RayNode, &RayNode)>,
        route: &mut Vec<RayKind>,
        out: &mut Vec<Divergence>,
    ) {
        let ps = (parents.map(|p| p.0), parents.map(|p| p.1));
        if a.kind == RayKind::Shadow {
            self.compare_shadow(sample, a, b, ps, route, out);
            return;
        }
        let push = |out: &mut Vec<Divergence>, kind, what: String, values, location| {
            self.push(out, sample, route, (a, b), ps, kind, what, values, location)
        };
        match (&a.hit, &b.hit) {
            (None, None) => {
                if differs3(a.color, b.color) {
                    push(
                        out,
                        DivergenceKind::Background,
                        "the colour of a ray that leaves the scene".into(),
                        [rgb(a.color), rgb(b.color)],
                        [None, None],
                    );
                }
                return;
            }
            (Some(ha), None) => {
                push(
                    out,
                    DivergenceKind::Object,
                    "what the ray hits".into(),
                    [
                        ha.object.label.clone(),
                        "nothing (it leaves the scene)".into(),
                    ],
                    [Some(ha.object.location.clone()), None],
                );
                return;
            }
            (None, Some(hb)) => {
                push(
                    out,
                    DivergenceKind::Object,
                    "what the ray hits".into(),
                    [
                        "nothing (it leaves the scene)".into(),
                        hb.object.label.clone(),
                    ],
                    [None, Some(hb.object.location.clone())],
                );
                return;
            }
            (Some(ha), Some(hb)) => {
                if ha.object.label != hb.object.label || ha.leaf.label != hb.leaf.label {
                    push(
                        out,
                        DivergenceKind::Object,
                        "what the ray hits".into(),
                        [hit_label(ha), hit_label(hb)],
                        [
                            Some(ha.leaf.location.clone()),
                            Some(hb.leaf.location.clone()),
                        ],
                    );
                    return;
                }
                if let Some((field, va, vb)) = self.material_change(ha, hb) {
                    let label = &ha.resolved_material.label;
                    let what = if label == &hb.resolved_material.label {
                        format!("{field} of material {label} (at {})", ha.object.label)
                    } else {
                        format!(
                            "{field} of the material at {} ({label} in A, {} in B)",
                            ha.object.label, hb.resolved_material.label
                        )
                    };
                    // Point at the value itself where the material writes it.
                    let location = [(0, ha), (1, hb)].map(|(side, h)| {
                        let handle =
                            Handle::<Material>::from_index(h.resolved_material.handle as usize);
                        Some(
                            property_location(self.scenes[side], handle, &field)
                                .unwrap_or_else(|| h.resolved_material.location.clone()),
                        )
                    });
                    push(out, DivergenceKind::Material, what, [va, vb], location);
                    return;
                }
                if differs(ha.t, hb.t) {
                    push(
                        out,
                        DivergenceKind::Distance,
                        format!("where the ray hits {}", ha.object.label),
                        [format!("t = {}", ha.t), format!("t = {}", hb.t)],
                        [
                            Some(ha.object.location.clone()),
                            Some(hb.object.location.clone()),
                        ],
                    );
                    return;
                }
            }
        }
        if let (Some(la), Some(lb)) = (&a.local, &b.local) {
            let object = a
                .hit
                .as_ref()
                .map_or(String::new(), |h| h.object.label.clone());
            if differs3(la.ambient, lb.ambient) {
                push(
                    out,
                    DivergenceKind::Light,
                    format!("the ambient term at {object}"),
                    [rgb(la.ambient), rgb(lb.ambient)],
                    [None, None],
                );
            } else if let Some((ca, cb)) = la.lights.iter().zip(&lb.lights).find(|(ca, cb)| {
                ca.light.label != cb.light.label
                    || differs3(ca.diffuse, cb.diffuse)
                    || differs3(ca.specular, cb.specular)
            }) {
                let term = |c: &whitted_tracer::ray_tree::LightContribution| {
                    format!(
                        "{} diffuse {} specular {} ({:?})",
                        c.light.label,
                        rgb(c.diffuse),
                        rgb(c.specular),
                        c.visibility
                    )
                    .to_lowercase()
                };
                push(
                    out,
                    DivergenceKind::Light,
                    format!("the light {} gives {object}", ca.light.label),
                    [term(ca), term(cb)],
                    [
                        Some(ca.light.location.clone()),
                        Some(cb.light.location.clone()),
                    ],
                );
            } else if la.lights.len() != lb.lights.len() {
                push(
                    out,
                    DivergenceKind::Light,
                    format!("how many lights shine on {object}"),
                    [la.lights.len().to_string(), lb.lights.len().to_string()],
                    [None, None],
                );
            }
        }
        // Children by key: shadow rays by their light, the others by kind.
        let key = |n: &RayNode| (n.kind, n.shadow.as_ref().map(|s| s.light.label.clone()));
        let mut matched_b = vec![false; b.children.len()];
        for ca in &a.children {
            route.push(ca.kind);
            match b.children.iter().position(|cb| key(cb) == key(ca)) {
                Some(j) => {
                    matched_b[j] = true;
                    self.compare(sample, ca, &b.children[j], Some((a, b)), route, out);
                }
                None => {
                    let other = why_missing(b, ca.kind);
                    out.push(self.one_side(sample, ca, Some(a), route, 0, &other));
                }
            }
            route.pop();
        }
        for (j, cb) in b.children.iter().enumerate() {
            if !matched_b[j] {
                route.push(cb.kind);
                let other = why_missing(a, cb.kind);
                out.push(self.one_side(sample, cb, Some(b), route, 1, &other));
                route.pop();
            }
        }
    }

    fn compare_shadow(
        &self,
        sample: u32,
        a: &RayNode,
        b: &RayNode,
        ps: (Option<&RayNode>, Option<&RayNode>),
        route: &[RayKind],
        out: &mut Vec<Divergence>,
    ) {
        let (Some(sa), Some(sb)) = (&a.shadow, &b.shadow) else {
            return;
        };
        let describe = |s: &whitted_tracer::ray_tree::ShadowInfo| match &s.blocker {
            Some(blocker) => format!("blocked by {}", blocker.object.label),
            None => format!("{:?}", s.result).to_lowercase(),
        };
        let (da, db) = (describe(sa), describe(sb));
        if da != db || differs3(a.color, b.color) {
            let location = |s: &whitted_tracer::ray_tree::ShadowInfo| {
                s.blocker.as_ref().map(|b| b.object.location.clone())
            };
            self.push(
                out,
                sample,
                route,
                (a, b),
                ps,
                DivergenceKind::Shadow,
                format!("what the shadow ray to {} meets", sa.light.label),
                [
                    format!("{da}, passes {}", rgb(a.color)),
                    format!("{db}, passes {}", rgb(b.color)),
                ],
                [location(sa), location(sb)],
            );
        }
    }

    /// The first material value that differs at the two hits: name, value in A, in B.
    fn material_change(&self, ha: &HitInfo, hb: &HitInfo) -> Option<(String, String, String)> {
        let get = |side: usize, h: &HitInfo| {
            self.scenes[side]
                .materials
                .get(Handle::<Material>::from_index(
                    h.resolved_material.handle as usize,
                ))
        };
        let (ma, mb) = (get(0, ha)?, get(1, hb)?);
        let mut rows: Vec<(String, String, String)> = vec![
            ("ior".into(), ma.ior.to_string(), mb.ior.to_string()),
            (
                "shininess".into(),
                ma.shininess.to_string(),
                mb.shininess.to_string(),
            ),
            (
                "fresnel".into(),
                format!("{:?}", ma.fresnel).to_lowercase(),
                format!("{:?}", mb.fresnel).to_lowercase(),
            ),
            (
                "priority".into(),
                ma.priority.to_string(),
                mb.priority.to_string(),
            ),
        ];
        for row in MATERIAL_COLORS {
            rows.push((
                row.name.to_string(),
                color_text((row.get)(ma)),
                color_text((row.get)(mb)),
            ));
        }
        rows.into_iter().find(|(_, x, y)| x != y)
    }
}

/// `file:line:col` of the property `field` in a material's definition, when it is written
/// there (the scene's table of written properties; an inherited value is written in the
/// parent, and the material's own line is used).
fn property_location(scene: &Scene, material: Handle<Material>, field: &str) -> Option<String> {
    let header = scene.materials.span(material);
    scene
        .written
        .properties_in(whitted_ir::BlockKind::Material, header, field)
        .last()
        .map(|written| scene.sources.location(written.name_span))
}

fn hit_label(hit: &HitInfo) -> String {
    if hit.leaf.handle == hit.object.handle && hit.leaf.label == hit.object.label {
        hit.object.label.clone()
    } else {
        format!("{} (its part {})", hit.object.label, hit.leaf.label)
    }
}

/// Why `parent` has no child of `kind`: the recorded reason it was skipped, or that its
/// material does not ask for it.
fn why_missing(parent: &RayNode, kind: RayKind) -> String {
    match parent.skipped.iter().find(|s| s.kind == kind) {
        Some(skipped) => format!("not traced ({})", skipped.reason.name()),
        None if kind == RayKind::Shadow => "no shadow ray cast".to_string(),
        None => "not traced (the material does not ask for it)".to_string(),
    }
}
