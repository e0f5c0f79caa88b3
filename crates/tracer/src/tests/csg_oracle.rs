//! Accelerated CSG against brute force: node bounds, the BVH over a union's or a
//! difference's children and the narrower windows of a first hit (a union's nearest child
//! crossing, a difference's first child) must give exactly the hit (distance bit for bit,
//! leaf, part, flip) of evaluating the whole window with every child of every node and no
//! bound at all, for generated trees and rays of every awkward kind.
//!
//! Trees mix spheres, boxes on a unit grid (so faces touch and coincide), capped cylinders,
//! unbounded half-spaces, exact duplicates of earlier children, and nested operations;
//! rays run along the axes and the grid's faces (±0.0 components), graze spheres, start
//! inside solids and on their surfaces, and stop at finite `tmax`.

use glam::{DMat4, DVec3, Vec3A};
use whitted_ir::{CsgOp, Handle, Material, Object, Shape};

use super::bvh_oracle::Rng;
use super::prepare;
use crate::csg::{Boundary, CsgNode, CsgScratch, CsgTree};
use crate::query::Scratch;
use crate::scene::{Item, PreparedScene};
use crate::testing::{matte, plane_y, sphere, SceneBuilder};
use whitted_bvh::Bound;
use whitted_bvh::Ray;

/// A hit as plain bits, so that `-0.0` and `0.0` (or two NaNs) never compare equal by
/// accident.
fn bits(hit: Option<Boundary>) -> Option<(u32, u32, u32, bool)> {
    hit.map(|b| (b.t.to_bits(), b.leaf, b.part, b.flip))
}

/// One generated solid: its parts are demoted, so only the caller decides what is top-level.
struct Generator<'a> {
    rng: Rng,
    b: &'a mut SceneBuilder,
    m: Handle<Material>,
    /// Leaves made so far, as (shape, transform), to repeat exactly for coincident surfaces.
    made: Vec<(Shape, DMat4)>,
    /// Where the solid being made is moved to.
    offset: DVec3,
}

impl Generator<'_> {
    fn leaf(&mut self) -> Handle<Object> {
        let rng = &mut self.rng;
        let (shape, transform) = match rng.below(12) {
            // An exact copy of an earlier leaf: every surface coincides.
            0 | 1 if !self.made.is_empty() => {
                let i = rng.below(self.made.len() as u64) as usize;
                self.made[i].clone()
            }
            // A unit box on the integer grid: neighbours share faces.
            2..=4 => {
                let corner = (rng.point(3.0)).round();
                let size = DVec3::new(
                    1.0 + rng.below(2) as f64,
                    1.0 + rng.below(2) as f64,
                    1.0 + rng.below(2) as f64,
                );
                (
                    Shape::Box {
                        min: corner,
                        max: corner + size,
                    },
                    DMat4::IDENTITY,
                )
            }
            5 => (
                Shape::Cylinder {
                    base: DVec3::new(0.0, -1.0, 0.0),
                    apex: DVec3::new(0.0, 1.0, 0.0),
                    radius: rng.range(0.2, 1.0),
                    capped: true,
                },
                DMat4::from_translation(rng.point(3.0)),
            ),
            // Spheres centred on the grid with whole or half radii touch grid faces.
            _ => {
                let center = if rng.below(2) == 0 {
                    rng.point(3.0).round()
                } else {
                    rng.point(3.0)
                };
                let radius = if rng.below(2) == 0 {
                    0.5 * (1 + rng.below(3)) as f64
                } else {
                    rng.range(0.2, 1.5)
                };
                (
                    sphere(center.x, center.y, center.z, radius),
                    DMat4::IDENTITY,
                )
            }
        };
        self.made.push((shape.clone(), transform));
        let moved = DMat4::from_translation(self.offset) * transform;
        let handle = self.b.part(shape, moved, self.m);
        self.b.demote(handle);
        handle
    }

    fn half_space(&mut self) -> Handle<Object> {
        let shape = match self.rng.below(2) {
            0 => plane_y(self.rng.range(-3.0, 3.0).round()),
            _ => Shape::Plane {
                normal: self.rng.direction(),
                offset: self.rng.range(-2.0, 2.0),
            },
        };
        let moved = DMat4::from_translation(self.offset);
        let handle = self.b.part(shape, moved, self.m);
        self.b.demote(handle);
        handle
    }

    /// A CSG node of `depth` levels: unions and differences wide enough for a BVH over
    /// their children, intersections of a few solids and half-spaces.
    fn node(&mut self, depth: u32) -> Handle<Object> {
        let op = match self.rng.below(5) {
            0 | 1 => CsgOp::Union,
            2 | 3 => CsgOp::Difference,
            _ => CsgOp::Intersection,
        };
        let count = match op {
            CsgOp::Intersection => 2 + self.rng.below(3),
            _ => 6 + self.rng.below(30),
        };
        let mut children = Vec::new();
        for i in 0..count {
            let child = match self.rng.below(12) {
                0 if depth > 0 => self.node(depth - 1),
                1 if i > 0 || op != CsgOp::Difference => self.half_space(),
                _ => self.leaf(),
            };
            children.push(child);
        }
        let handle = self.b.csg(op, children, self.m);
        self.b.demote(handle);
        handle
    }
}

/// Rays of every awkward kind near the tree (which lies within about ±5 of the origin).
fn awkward_ray(rng: &mut Rng, made: &[(Shape, DMat4)], kind: u64) -> Ray {
    let axis_direction = |rng: &mut Rng| {
        let mut d = Vec3A::ZERO;
        let axis = rng.below(3) as usize;
        d[axis] = if rng.below(2) == 0 { 1.0 } else { -1.0 };
        for other in 0..3 {
            if other != axis && rng.below(2) == 0 {
                d[other] = -0.0;
            }
        }
        d
    };
    match kind % 6 {
        // Along an axis, on the grid's lines and faces (where boxes meet and coincide).
        0 => {
            let origin = (rng.point(6.0) * 2.0).round() * 0.5;
            Ray::new(origin.as_vec3a(), axis_direction(rng))
        }
        // Along an axis from anywhere.
        1 => Ray::new(rng.point(6.0).as_vec3a(), axis_direction(rng)),
        // Grazing a sphere: from a point on it, along a tangent.
        2 => {
            let spheres: Vec<(DVec3, f64)> = made
                .iter()
                .filter_map(|(shape, _)| match shape {
                    Shape::Sphere { center, radius } => Some((*center, *radius)),
                    _ => None,
                })
                .collect();
            let Some(&(center, radius)) =
                spheres.get(rng.below(spheres.len().max(1) as u64) as usize)
            else {
                return Ray::new(rng.point(6.0).as_vec3a(), rng.direction().as_vec3a());
            };
            let normal = rng.direction();
            let tangent = normal.cross(rng.direction()).normalize_or(DVec3::X);
            let at = center + normal * radius;
            Ray::new((at - tangent * 4.0).as_vec3a(), tangent.as_vec3a())
        }
        // From inside: a leaf's own position.
        3 => {
            let origin = match made.get(rng.below(made.len().max(1) as u64) as usize) {
                Some((Shape::Sphere { center, .. }, _)) => *center,
                Some((Shape::Box { min, max }, _)) => (*min + *max) * 0.5,
                Some((_, transform)) => transform.w_axis.truncate(),
                None => DVec3::ZERO,
            };
            Ray::new(origin.as_vec3a(), rng.direction().as_vec3a())
        }
        // A zero component, of either sign, in a random direction.
        4 => {
            let mut d = rng.direction();
            d[rng.below(3) as usize] = 0.0;
            let mut d = d.normalize_or(DVec3::Y).as_vec3a();
            for axis in 0..3 {
                if d[axis] == 0.0 && rng.below(2) == 0 {
                    d[axis] = -0.0;
                }
            }
            Ray::new(rng.point(7.0).as_vec3a(), d)
        }
        // Anywhere, towards the middle.
        _ => {
            let origin = rng.point(8.0);
            let towards = (rng.point(2.0) - origin).normalize_or(DVec3::X);
            Ray::new(origin.as_vec3a(), towards.as_vec3a())
        }
    }
}

/// The one CSG item of a scene (`None` when its bound is empty and it was left out).
fn only_tree(scene: &PreparedScene) -> Option<&CsgTree> {
    match scene.bounded.iter().chain(&scene.unbounded).next() {
        Some(Item::Csg { tree, .. }) => Some(tree),
        _ => None,
    }
}

/// Compares one ray's first hit with its windows: from `tmin` to infinity, to a finite
/// `tmax`, and again from each hit found onwards (as filtered shadows and media ask).
fn compare(
    tree: &CsgTree,
    oracle: &CsgTree,
    ray: &Ray,
    tmax: f32,
    scratch: &mut CsgScratch,
) -> Result<u32, String> {
    let mut hits = 0;
    for limit in [f32::INFINITY, tmax] {
        let mut from = 0.0;
        for _ in 0..8 {
            let fast = tree.first_hit(ray, from, limit, scratch);
            let slow = oracle.first_hit_in_whole_window(ray, from, limit, scratch);
            if bits(fast) != bits(slow) {
                let whole = tree.first_hit_in_whole_window(ray, from, limit, scratch);
                let plain = tree
                    .without_acceleration()
                    .first_hit_in_whole_window(ray, from, limit, scratch);
                let top = tree.nodes.last().cloned();
                return Err(format!(
                    "window ({from}, {limit}): accelerated {fast:?}, brute force {slow:?}\nwhole {whole:?}\nplain {plain:?}\n{top:?}"
                ));
            }
            let Some(hit) = fast else { break };
            hits += 1;
            from = hit.t;
        }
    }
    Ok(hits)
}

/// Bounds, the BVH over children and the union's window, against brute force, over
/// generated trees up to three levels deep.
#[test]
fn accelerated_csg_matches_brute_force_on_awkward_rays() {
    let mut compared = 0u64;
    let mut hits = 0u64;
    let mut accelerated_trees = 0;
    for seed in 0..60u64 {
        let mut b = SceneBuilder::new();
        let m = b.material(matte(0.5, 0.5, 0.5));
        let mut generator = Generator {
            rng: Rng::new(seed + 7000),
            b: &mut b,
            m,
            made: Vec::new(),
            offset: DVec3::ZERO,
        };
        let root = generator.node(1 + (seed % 3) as u32);
        let Generator { mut rng, made, .. } = generator;
        b.promote(root);
        let scene = prepare(b);
        let Some(tree) = only_tree(&scene) else {
            continue;
        };
        accelerated_trees += usize::from(!tree.accels.is_empty());
        let oracle = tree.brute_force();
        let mut scratch = CsgScratch::default();
        for k in 0..1500 {
            let ray = awkward_ray(&mut rng, &made, k);
            let tmax = rng.range(0.5, 12.0) as f32;
            match compare(tree, &oracle, &ray, tmax, &mut scratch) {
                Ok(found) => hits += u64::from(found),
                Err(message) => panic!("seed {seed}, ray {k} {ray:?}: {message}"),
            }
            compared += 1;
        }
    }
    assert!(
        accelerated_trees > 30,
        "only {accelerated_trees} trees had a BVH over children"
    );
    assert!(hits > compared / 3, "only {hits} hits over {compared} rays");
}

/// A union of many spheres, the case the nearest-crossing window is for: rays from outside
/// (the window finds the entry), from inside overlapping spheres (it must fall back), and
/// along the union's own surfaces.
#[test]
fn a_union_of_overlapping_spheres_matches_brute_force() {
    let mut compared = 0u64;
    let mut hits = 0u64;
    for seed in 0..20u64 {
        let mut rng = Rng::new(seed + 9100);
        let mut b = SceneBuilder::new();
        let m = b.material(matte(0.5, 0.5, 0.5));
        let mut made = Vec::new();
        let mut children = Vec::new();
        for _ in 0..200 {
            let center = rng.point(4.0);
            let radius = rng.range(0.3, 1.2);
            let shape = sphere(center.x, center.y, center.z, radius);
            made.push((shape.clone(), DMat4::IDENTITY));
            let child = b.part(shape, DMat4::IDENTITY, m);
            b.demote(child);
            children.push(child);
        }
        b.csg(CsgOp::Union, children, m);
        let scene = prepare(b);
        let Some(tree) = only_tree(&scene) else {
            panic!("seed {seed}: no union");
        };
        assert!(!tree.accels.is_empty(), "seed {seed}: not accelerated");
        let oracle = tree.brute_force();
        let mut scratch = CsgScratch::default();
        for k in 0..1000 {
            let ray = awkward_ray(&mut rng, &made, k);
            let tmax = rng.range(0.5, 12.0) as f32;
            match compare(tree, &oracle, &ray, tmax, &mut scratch) {
                Ok(found) => hits += u64::from(found),
                Err(message) => panic!("seed {seed}, ray {k} {ray:?}: {message}"),
            }
            compared += 1;
        }
    }
    assert!(hits > compared, "only {hits} hits over {compared} rays");
}

/// Node bounds, by hand: a union's is its children's together, an intersection's the
/// overlap of its bounded children (half-spaces do not widen it), a difference's its
/// first child's; and a bounded intersection of half-spaces goes into the scene's BVH.
#[test]
fn csg_nodes_are_bounded_by_the_rule_of_their_operation() {
    let mut b = SceneBuilder::new();
    let m = b.material(matte(0.5, 0.5, 0.5));
    let unit_box = |b: &mut SceneBuilder, lo: f64, hi: f64| {
        let handle = b.part(
            Shape::Box {
                min: DVec3::splat(lo),
                max: DVec3::splat(hi),
            },
            DMat4::IDENTITY,
            m,
        );
        b.demote(handle);
        handle
    };
    let floor = |b: &mut SceneBuilder| {
        let handle = b.part(plane_y(0.5), DMat4::IDENTITY, m);
        b.demote(handle);
        handle
    };
    let (a, c) = (unit_box(&mut b, 0.0, 2.0), unit_box(&mut b, 1.0, 3.0));
    let cut = floor(&mut b);
    b.csg(CsgOp::Intersection, vec![cut, a, c], m);
    let (a, c) = (unit_box(&mut b, 10.0, 12.0), unit_box(&mut b, 11.0, 13.0));
    b.csg(CsgOp::Difference, vec![a, c], m);
    let (a, c) = (unit_box(&mut b, 20.0, 22.0), unit_box(&mut b, 21.0, 23.0));
    b.csg(CsgOp::Union, vec![a, c], m);
    let (p, q) = (floor(&mut b), floor(&mut b));
    b.csg(CsgOp::Intersection, vec![p, q], m);
    let scene = prepare(b);
    // Only the intersection of two half-spaces is unbounded.
    assert_eq!(scene.unbounded_count(), 1);
    let root_bound = |tree: &CsgTree| match tree.nodes.last() {
        Some(CsgNode::Op { bound, .. }) => *bound,
        other => panic!("not an operation: {other:?}"),
    };
    let close = |bound: Bound, lo: f32, hi: f32| match bound {
        Bound::Finite(aabb) => {
            let (min, max) = (aabb.min, aabb.max);
            min.abs_diff_eq(Vec3A::splat(lo), 1e-4) && max.abs_diff_eq(Vec3A::splat(hi), 1e-4)
        }
        _ => false,
    };
    let mut seen = 0;
    for item in &scene.bounded {
        let Item::Csg { tree, .. } = item else {
            continue;
        };
        let bound = root_bound(tree);
        let expected = [(1.0, 2.0), (10.0, 12.0), (20.0, 23.0)];
        assert!(
            expected.iter().any(|&(lo, hi)| close(bound, lo, hi)),
            "unexpected bound {bound:?}"
        );
        seen += 1;
    }
    assert_eq!(seen, 3);
    let Some(Item::Csg { tree, .. }) = scene.unbounded.first() else {
        panic!("the half-spaces' intersection is not the unbounded item");
    };
    assert_eq!(root_bound(tree), Bound::Infinite);
}

/// The scene's queries over CSG items (bounded and not) against brute force over the
/// brute-force trees: a wrong node bound would make the scene's BVH skip a solid.
#[test]
fn scenes_of_csg_solids_match_brute_force() {
    for seed in 0..12u64 {
        let mut b = SceneBuilder::new();
        let m = b.material(matte(0.5, 0.5, 0.5));
        let mut generator = Generator {
            rng: Rng::new(seed + 8300),
            b: &mut b,
            m,
            made: Vec::new(),
            offset: DVec3::ZERO,
        };
        let mut roots = Vec::new();
        for i in 0..8 {
            // Each solid moved apart from the others, so the scene's BVH has work to do.
            generator.offset =
                DVec3::new(f64::from(i % 4) * 6.0 - 9.0, 0.0, f64::from(i / 4) * 6.0);
            roots.push(generator.node(1));
        }
        let Generator { mut rng, made, .. } = generator;
        for root in roots {
            b.promote(root);
        }
        let scene = prepare(b);
        let oracles: Vec<Option<CsgTree>> = scene
            .unbounded
            .iter()
            .chain(&scene.bounded)
            .map(|item| match item {
                Item::Csg { tree, .. } => Some(tree.brute_force()),
                Item::Shape(_) => None,
            })
            .collect();
        let mut scratch = Scratch::default();
        let mut csg = CsgScratch::default();
        for k in 0..3000 {
            let mut ray = awkward_ray(&mut rng, &made, k);
            ray.origin += Vec3A::new(rng.range(-9.0, 9.0) as f32, 0.0, rng.range(0.0, 6.0) as f32);
            let mut expected: Option<f32> = None;
            for oracle in oracles.iter().flatten() {
                let limit = expected.unwrap_or(f32::INFINITY);
                if let Some(hit) = oracle.first_hit_in_whole_window(&ray, 0.0, limit, &mut csg) {
                    expected = Some(hit.t);
                }
            }
            let got = scene.intersect(&ray, 0.0, f32::INFINITY, &mut scratch);
            assert_eq!(
                got.map(|h| h.t.to_bits()),
                expected.map(f32::to_bits),
                "seed {seed}, ray {k} {ray:?}"
            );
            let blocked = scene.occluded(&ray, 0.0, f32::INFINITY, &mut scratch);
            assert_eq!(
                blocked.is_some(),
                expected.is_some(),
                "seed {seed}, ray {k}"
            );
        }
    }
}
