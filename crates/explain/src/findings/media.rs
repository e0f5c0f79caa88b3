//! Findings about what light meets inside and beyond transparent objects: Beer-Lambert
//! absorption that dims a path (`absorption`), and the background seen through glass
//! (`background`), which is what makes glass in front of a black background look black.

use whitted_ir::Handle;
use whitted_tracer::ray_tree::{HitInfo, RayNode};
use whitted_tracer::RayKind;

use super::{material_location, push_unique, rgb, walk, weight_of, Context, SIGNIFICANT};
use crate::model::{Finding, FindingKind};

/// Absorption that leaves less than this of some channel along one ray is worth saying.
pub const DIMMED: f32 = 0.5;

pub(super) fn find(context: &Context<'_>, findings: &mut Vec<Finding>) {
    absorption(context, findings);
    background(context, findings);
}

/// The material of the medium a ray travels in: the surface where the nearest ray above it
/// entered a solid (reflections inside keep the medium), or the ray's own surface.
fn medium_material(context: &Context<'_>, node: &RayNode, above: &[&RayNode]) -> Option<u32> {
    let absorbs = |handle: u32| {
        context
            .scene
            .materials
            .get(Handle::from_index(handle as usize))
            .is_some_and(|m| !m.absorption.is_black())
    };
    let mut chain = above
        .iter()
        .copied()
        .chain(std::iter::once(node))
        .rev()
        .peekable();
    while let Some(ray) = chain.next() {
        let entered =
            ray.kind == RayKind::Transmitted && ray.interface.as_ref().is_some_and(|i| i.entering);
        if entered {
            let parent = chain.peek().and_then(|p| p.hit.as_ref());
            if let Some(hit) = parent.filter(|h| absorbs(h.resolved_material.handle)) {
                return Some(hit.resolved_material.handle);
            }
        }
    }
    node.hit
        .as_ref()
        .map(|h: &HitInfo| h.resolved_material.handle)
        .filter(|&h| absorbs(h))
}

fn absorption(context: &Context<'_>, findings: &mut Vec<Finding>) {
    let scene = context.scene;
    walk(context.tree, &mut |node, above| {
        let Some(hit) = &node.hit else {
            return;
        };
        let kept = hit.absorption.iter().fold(1.0f32, |m, &c| m.min(c));
        if kept >= DIMMED || weight_of(node) < SIGNIFICANT {
            return;
        }
        let Some(handle) = medium_material(context, node, above) else {
            return;
        };
        let handle = Handle::from_index(handle as usize);
        let Some(material) = scene.materials.get(handle) else {
            return;
        };
        let name = scene.material_label(handle);
        let at = material_location(scene, handle);
        let a = material.absorption.components();
        // The absorption that would keep 80% of the light over the same distance.
        let gentle = -(0.8f64).ln() / f64::from(hit.t.max(f32::MIN_POSITIVE));
        push_unique(
            findings,
            Finding {
                kind: FindingKind::Absorption,
                message: format!(
                    "Beer-Lambert absorption in material {name} over a distance of {:.3} keeps \
                     only {} of the light along this path (absorption <{}, {}, {}>)",
                    hit.t,
                    rgb(hit.absorption),
                    a[0],
                    a[1],
                    a[2]
                ),
                location: at.clone(),
                fix: format!(
                    "lower `absorption` in material {name} ({at}): {gentle:.3} per unit keeps \
                     80% over this distance; or make the object thinner"
                ),
                weight: weight_of(node) * (1.0 - kept),
                source_line: None,
            },
        );
    });
}

fn background(context: &Context<'_>, findings: &mut Vec<Finding>) {
    let scene = context.scene;
    let scale = 1.0 / context.tree.samples_per_pixel.max(1) as f32;
    // Per transmitting object: the weight of the paths through it that leave the scene.
    let mut through: Vec<(u32, String, String, f32)> = Vec::new();
    walk(context.tree, &mut |node, above| {
        if node.hit.is_some()
            || node.kind != RayKind::Transmitted && node.kind != RayKind::Reflected
        {
            return;
        }
        if weight_of(node) < SIGNIFICANT {
            return;
        }
        // The first surface the path passed through, from the eye.
        let mut rays = above.iter().copied().chain(std::iter::once(node));
        let mut previous: Option<&RayNode> = None;
        let glass = rays.find_map(|ray| {
            let found = (ray.kind == RayKind::Transmitted)
                .then(|| previous.and_then(|p| p.hit.as_ref()))
                .flatten();
            previous = Some(ray);
            found
        });
        let Some(glass) = glass else {
            return;
        };
        let weight = weight_of(node) * scale;
        match through.iter_mut().find(|t| t.0 == glass.object.handle) {
            Some(entry) => entry.3 += weight,
            None => through.push((
                glass.object.handle,
                glass.object.label.clone(),
                glass.object.location.clone(),
                weight,
            )),
        }
    });
    let background = scene.settings.background.components();
    let black = background.iter().all(|&c| c == 0.0);
    for (_, label, location, weight) in through {
        let message = format!(
            "{:.1}% of the pixel's path weight goes through {label} and leaves the scene: the \
             background (rgb({}, {}, {})) is seen through it{}",
            weight * 100.0,
            background[0],
            background[1],
            background[2],
            if black {
                ", so it looks black there"
            } else {
                ""
            }
        );
        push_unique(
            findings,
            Finding {
                kind: FindingKind::Background,
                message,
                location,
                fix: format!(
                    "glass shows what is behind it: put something (a floor, a wall) where the \
                     camera looks through {label}, or set `background` in settings to a colour"
                ),
                weight,
                source_line: None,
            },
        );
    }
}
