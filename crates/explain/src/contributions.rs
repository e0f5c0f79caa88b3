//! The pixel's colour split into paths: each path from the eye (a chain of reflections and
//! refractions) to a light term (ambient, emission, a light's diffuse or specular term, or
//! the background), with the light it brings.
//!
//! A ray's returned colour is `(local + Σ coefficient·child) × absorption`
//! (`crates/tracer/src/recorder.rs`), so a term at a hit counts in the pixel as the ray's
//! path weight times its absorption times the term, divided by the samples; a miss counts
//! as its weight times the colour it returned. Summed over every recorded ray this is the
//! pixel, up to f32 rounding. The few largest paths get a line each; the rest is one
//! `other` line, so the lines still sum to the pixel.

use std::collections::BTreeMap;

use glam::DVec3;
use whitted_tracer::ray_tree::{RayNode, RayTree};
use whitted_tracer::RayKind;

use crate::model::{Contribution, Step, Term};

/// At most this many paths get a line of their own.
pub const MAX_LINES: usize = 6;
/// Lines are added until they cover this share of the pixel.
pub const COVERED_SHARE: f64 = 0.95;

/// One step of a path as a key: ray kind, object handle (none on a miss), TIR.
type StepKey = (u8, Option<u32>, bool);
/// A whole path and its end term (with the light handle for light terms).
type PathKey = (Vec<StepKey>, Term, Option<u32>);

/// What is known of a path besides its key, for printing.
struct PathInfo {
    color: DVec3,
    steps: Vec<Step>,
    light: Option<String>,
}

/// The pixel's colour as its main contributions, largest first, then `other` and
/// `unrecorded` lines when there is light left to account for. They sum to `tree.color`.
pub fn decompose(tree: &RayTree) -> Vec<Contribution> {
    let scale = 1.0 / f64::from(tree.samples_per_pixel.max(1));
    let mut paths: BTreeMap<PathKey, PathInfo> = BTreeMap::new();
    let mut keys = Vec::new();
    let mut steps = Vec::new();
    for sample in &tree.samples {
        visit(&sample.root, scale, &mut keys, &mut steps, &mut paths);
    }
    let pixel = DVec3::from(tree.color.map(f64::from));
    let total: DVec3 = paths.values().map(|p| p.color).sum();
    let mut ranked: Vec<(PathKey, PathInfo)> = paths
        .into_iter()
        .filter(|(_, p)| p.color != DVec3::ZERO)
        .collect();
    // Largest first; the key breaks ties so the order never depends on anything else.
    ranked.sort_by(|a, b| {
        b.1.color
            .element_sum()
            .total_cmp(&a.1.color.element_sum())
            .then_with(|| a.0.cmp(&b.0))
    });
    let share = |c: DVec3| {
        let whole = pixel.element_sum();
        (whole > 0.0).then(|| (c.element_sum() / whole) as f32)
    };
    let mut lines = Vec::new();
    let mut covered = DVec3::ZERO;
    let mut rest = ranked.into_iter().peekable();
    while lines.len() < MAX_LINES {
        if covered.element_sum() >= COVERED_SHARE * total.element_sum() && !lines.is_empty() {
            break;
        }
        let Some(((_, term, _), info)) = rest.next() else {
            break;
        };
        covered += info.color;
        lines.push(Contribution {
            term,
            light: info.light,
            path: info.steps,
            color: to_f32(info.color),
            share: share(info.color),
            paths: 1,
        });
    }
    let mut other = DVec3::ZERO;
    let mut others = 0u32;
    for (_, info) in rest {
        other += info.color;
        others = others.saturating_add(1);
    }
    if others > 0 {
        lines.push(Contribution {
            term: Term::Other,
            light: None,
            path: Vec::new(),
            color: to_f32(other),
            share: share(other),
            paths: others,
        });
    }
    // A tree cut by its node budget lacks the light of the rays it did not keep: that
    // light is what the recorded paths leave of the pixel.
    if tree.unrecorded > 0 {
        let missing = (pixel - total).max(DVec3::ZERO);
        lines.push(Contribution {
            term: Term::Unrecorded,
            light: None,
            path: Vec::new(),
            color: to_f32(missing),
            share: share(missing),
            paths: 0,
        });
    }
    lines
}

fn to_f32(c: DVec3) -> [f32; 3] {
    c.as_vec3().to_array()
}

fn kind_index(kind: RayKind) -> u8 {
    match kind {
        RayKind::Camera => 0,
        RayKind::Reflected => 1,
        RayKind::Transmitted => 2,
        RayKind::Shadow => 3,
    }
}

/// Adds the terms of `node` and its subtree to `paths`; `keys` and `steps` hold the path
/// from the eye to `node`'s parent.
fn visit(
    node: &RayNode,
    scale: f64,
    keys: &mut Vec<StepKey>,
    steps: &mut Vec<Step>,
    paths: &mut BTreeMap<PathKey, PathInfo>,
) {
    let tir = node
        .interface
        .as_ref()
        .is_some_and(|i| i.total_internal_reflection);
    keys.push((
        kind_index(node.kind),
        node.hit.as_ref().map(|h| h.object.handle),
        tir,
    ));
    steps.push(Step {
        ray: node.kind,
        tir,
        object: node.hit.as_ref().map(|h| h.object.label.clone()),
        location: node.hit.as_ref().map(|h| h.object.location.clone()),
        repeat: 1,
        made_by: node.hit.as_ref().map_or_else(Vec::new, |h| {
            h.object
                .made_by
                .iter()
                .map(|step| format!("{} at {}", step.text, step.location))
                .collect()
        }),
    });
    let weight = DVec3::from(node.weight.map(f64::from)) * scale;
    let mut add = |term: Term, light: Option<(u32, &str)>, color: [f32; 3]| {
        if color == [0.0; 3] {
            return;
        }
        let key = (keys.clone(), term, light.map(|l| l.0));
        let entry = paths.entry(key).or_insert_with(|| PathInfo {
            color: DVec3::ZERO,
            steps: compress(steps),
            light: light.map(|l| l.1.to_string()),
        });
        entry.color += weight * DVec3::from(color.map(f64::from));
    };
    match (&node.hit, &node.local) {
        (Some(hit), Some(local)) => {
            let absorption = hit.absorption;
            let absorbed = |c: [f32; 3]| {
                [
                    c[0] * absorption[0],
                    c[1] * absorption[1],
                    c[2] * absorption[2],
                ]
            };
            add(Term::Ambient, None, absorbed(local.ambient));
            add(Term::Emission, None, absorbed(local.emission));
            for light in &local.lights {
                let handle = (light.light.handle, light.light.label.as_str());
                add(Term::Diffuse, Some(handle), absorbed(light.diffuse));
                add(Term::Specular, Some(handle), absorbed(light.specular));
            }
        }
        // A miss returns the background (through the medium it travels in).
        (None, _) => add(Term::Background, None, node.color),
        (Some(_), None) => {}
    }
    for child in node.children.iter().filter(|c| c.kind != RayKind::Shadow) {
        visit(child, scale, keys, steps, paths);
    }
    keys.pop();
    steps.pop();
}

/// Merges runs of identical steps (a ray bouncing inside the same solid) into one step
/// with a repeat count.
fn compress(steps: &[Step]) -> Vec<Step> {
    let mut out: Vec<Step> = Vec::new();
    for step in steps {
        match out.last_mut() {
            Some(last)
                if last.ray == step.ray
                    && last.tir == step.tir
                    && last.object == step.object
                    && last.location == step.location
                    && step.ray != RayKind::Camera =>
            {
                last.repeat += 1
            }
            _ => out.push(step.clone()),
        }
    }
    out
}

/// The path in words: `glass, transmitted to water, reflected (TIR) ×3 to glass`.
pub fn describe_path(path: &[Step]) -> String {
    let mut words = Vec::new();
    for step in path {
        let target = step.object.as_deref().unwrap_or("the background");
        let repeat = if step.repeat > 1 {
            format!(" ×{}", step.repeat)
        } else {
            String::new()
        };
        words.push(match step.ray {
            RayKind::Camera => target.to_string(),
            kind => format!(
                "{}{}{repeat} to {target}",
                kind.name(),
                if step.tir { " (TIR)" } else { "" }
            ),
        });
    }
    words.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(ray: RayKind, tir: bool, object: Option<&str>) -> Step {
        Step {
            ray,
            tir,
            object: object.map(str::to_string),
            location: object.map(|o| format!("{o}.scene:1:1")),
            repeat: 1,
            made_by: Vec::new(),
        }
    }

    #[test]
    fn repeated_bounces_are_one_step_in_words() {
        let path = [
            step(RayKind::Camera, false, Some("glass")),
            step(RayKind::Transmitted, false, Some("glass")),
            step(RayKind::Reflected, true, Some("glass")),
            step(RayKind::Reflected, true, Some("glass")),
            step(RayKind::Reflected, true, Some("glass")),
            step(RayKind::Transmitted, false, None),
        ];
        let compressed = compress(&path);
        assert_eq!(compressed.len(), 4);
        assert_eq!(compressed[2].repeat, 3);
        assert_eq!(
            describe_path(&compressed),
            "glass, transmitted to glass, reflected (TIR) ×3 to glass, transmitted to the \
             background"
        );
        // A camera step never merges with the ray after it, even on the same object.
        assert_eq!(compress(&path[..2]).len(), 2);
    }
}
