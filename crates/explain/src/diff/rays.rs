//! Ray by ray: every ray of one pixel's two trees that was added, removed or whose weight or
//! colour changed, aligned as the divergence walk aligns them (children by kind, shadow rays
//! by their light). Where [`super::diff_trees`] stops at the first cause, this lists the
//! consequences too (the debugger's what-if shows both).

use serde::Serialize;
use whitted_tracer::ray_tree::{RayNode, RayTree};
use whitted_tracer::RayKind;

use super::differs3;

/// One ray that differs between A and B.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RayChange {
    pub sample: u32,
    /// The rays from the eye to this one.
    pub route: Vec<RayKind>,
    pub depth: u32,
    pub change: Change,
    /// Its path weight in A and in B (`None` on the side that lacks it).
    pub weight: [Option<[f32; 3]>; 2],
    /// The colour it returns in A and in B.
    pub color: [Option<[f32; 3]>; 2],
    /// What it hits (in B, or in A for a removed ray): an object's label, a light for a
    /// shadow ray, or `nothing`.
    pub hits: String,
    /// The rays below it, for an added or removed ray (which are not listed themselves).
    pub rays_below: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Change {
    Removed,
    Added,
    Changed,
}

/// Every ray that differs between `a` and `b` (two trees of one pixel), in tree order.
pub fn ray_changes(a: &RayTree, b: &RayTree) -> Vec<RayChange> {
    let mut out = Vec::new();
    for (sa, sb) in a.samples.iter().zip(&b.samples) {
        walk(
            sa.index,
            &sa.root,
            &sb.root,
            &mut vec![RayKind::Camera],
            &mut out,
        );
    }
    for (side, extra) in [(0, &a.samples), (1, &b.samples)] {
        let shorter = a.samples.len().min(b.samples.len());
        for s in extra.iter().skip(shorter) {
            out.push(one_side(s.index, &s.root, &[RayKind::Camera], side));
        }
    }
    out
}

fn hits(node: &RayNode) -> String {
    match (&node.hit, &node.shadow) {
        (Some(hit), _) => hit.object.label.clone(),
        (None, Some(shadow)) => format!("light {}", shadow.light.label),
        (None, None) => "nothing".to_string(),
    }
}

fn one_side(sample: u32, node: &RayNode, route: &[RayKind], side: usize) -> RayChange {
    let mut weight = [None, None];
    let mut color = [None, None];
    weight[side] = Some(node.weight);
    color[side] = Some(node.color);
    RayChange {
        sample,
        route: route.to_vec(),
        depth: node.depth,
        change: if side == 0 {
            Change::Removed
        } else {
            Change::Added
        },
        weight,
        color,
        hits: hits(node),
        rays_below: node.ray_count() - 1,
    }
}

fn walk(sample: u32, a: &RayNode, b: &RayNode, route: &mut Vec<RayKind>, out: &mut Vec<RayChange>) {
    if differs3(a.weight, b.weight) || differs3(a.color, b.color) || hits(a) != hits(b) {
        out.push(RayChange {
            sample,
            route: route.clone(),
            depth: b.depth,
            change: Change::Changed,
            weight: [Some(a.weight), Some(b.weight)],
            color: [Some(a.color), Some(b.color)],
            hits: hits(b),
            rays_below: 0,
        });
    }
    let key = |n: &RayNode| (n.kind, n.shadow.as_ref().map(|s| s.light.label.clone()));
    let mut matched = vec![false; b.children.len()];
    for ca in &a.children {
        route.push(ca.kind);
        match (0..b.children.len()).find(|&j| !matched[j] && key(&b.children[j]) == key(ca)) {
            Some(j) => {
                matched[j] = true;
                walk(sample, ca, &b.children[j], route, out);
            }
            None => out.push(one_side(sample, ca, route, 0)),
        }
        route.pop();
    }
    for (j, cb) in b.children.iter().enumerate() {
        if !matched[j] {
            route.push(cb.kind);
            out.push(one_side(sample, cb, route, 1));
            route.pop();
        }
    }
}
