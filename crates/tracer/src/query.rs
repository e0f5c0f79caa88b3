//! Ray queries against a prepared scene, named by their cost: [`PreparedScene::intersect`]
//! (closest hit, cheap data only), [`PreparedScene::occluded`] (any blocker, stops at the
//! first), [`PreparedScene::filter_shadow`] (every surface crossed, for filtered shadows) and
//! [`PreparedScene::surface`] (full surface data, computed for the nearest hit only).
//!
//! Unbounded items are tested one by one, bounded ones through the CwBvh. The traversal
//! callback honours the segment `(tmin, tmax)` itself and shrinks `tmax` as hits are
//! found; BVH ids index `bounded` directly because items were reordered at build time.

use glam::{UVec2, Vec3A};
use obvhs::aabb::Aabb;
use whitted_ir::{Handle, Material};

use crate::csg::CsgScratch;
use crate::hit_error;
use crate::light_buffer::Lookup;
use crate::material::{Blend, Pick};
use crate::scene::{Item, Leaf, PreparedScene};
use crate::shapes::{plane_first_hit, sphere_first_hit, unit_normal, with_fourth, Geometry, Part};
use whitted_bvh::Ray;
use whitted_bvh::{Bvh, PacketEntry, Step, PACKET};

/// Up to this many bounded items a plain loop beats walking the BVH.
pub(crate) const LINEAR_LIMIT: usize = 4;

/// Which top-level item was hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ItemRef {
    Bounded(u32),
    Unbounded(u32),
}

/// How far (relative to the coordinates and distances involved) a shadow segment must pass
/// inside a box for the BVH walk's f32 box tests to find it there too: a thousand times
/// f32's rounding.
const WALK_ROUNDING: f64 = 1.0 / (1u64 << 14) as f64;

/// Whether the segment `(tmin, tmax)` of `ray` passes through `aabb` with room to spare:
/// by [`WALK_ROUNDING`] of the largest coordinate or distance involved, computed in f64.
/// The walk's boxes around an item hold its box, so the walk reaches the item for such a
/// segment whatever its rounding.
fn well_inside(aabb: &Aabb, ray: &Ray, tmin: f32, tmax: f32) -> bool {
    let origin = ray.origin.as_dvec3();
    let direction = ray.direction.as_dvec3();
    let (lo, hi) = (aabb.min.as_dvec3(), aabb.max.as_dvec3());
    // The segment meets the box no further than its far side: the distance that rounds.
    let reaches = (origin - (lo + hi) / 2.0).length() + (hi - lo).length();
    let scale =
        origin.abs().max(lo.abs()).max(hi.abs()).max_element() + reaches.min(f64::from(tmax));
    if !scale.is_finite() {
        return false;
    }
    let margin = scale * WALK_ROUNDING;
    let (lo, hi) = (lo + margin, hi - margin);
    // A box thinner than the margin has no inside to spare.
    if lo.cmpgt(hi).any() {
        return false;
    }
    let (mut enter, mut exit) = (f64::from(tmin) + margin, f64::from(tmax) - margin);
    for axis in 0..3 {
        let (o, d) = (origin[axis], direction[axis]);
        if d == 0.0 {
            if !(lo[axis] <= o && o <= hi[axis]) {
                return false;
            }
            continue;
        }
        let (a, b) = ((lo[axis] - o) / d, (hi[axis] - o) / d);
        enter = enter.max(a.min(b));
        exit = exit.min(a.max(b));
    }
    enter < exit
}

/// The cheap result of a closest-hit query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub item: ItemRef,
    /// The CSG leaf index within the item (0 for a plain shape).
    pub leaf: u32,
    pub part: Part,
    /// Whether the leaf's outward normal is reversed (a subtracted surface).
    pub flip: bool,
}

impl Hit {
    #[inline(always)]
    fn new(item: ItemRef, (t, leaf, part, flip): ItemHit) -> Hit {
        Hit {
            t,
            item,
            leaf,
            part,
            flip,
        }
    }
}

/// What a shadow ray found between the surface and the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shadow {
    Clear,
    Blocked(Hit),
    /// Only transmissive surfaces: the light passes, multiplied by their colours.
    Filtered {
        transmittance: Vec3A,
        /// How many surfaces the ray crossed (a solid counts at entry and at exit).
        blockers: u32,
    },
}

/// Full data for one hit.
#[derive(Clone, Copy, Debug)]
pub struct Surface<'a> {
    /// The hit point, placed on the surface where the shape allows it (`hit_error.rs`).
    pub point: Vec3A,
    /// Per axis, how far `point` may be from the true surface: secondary and shadow rays
    /// start just outside this box along the normal.
    pub error: Vec3A,
    /// Outward unit normal of the solid (after the CSG flip).
    pub geometric_normal: Vec3A,
    /// The normal shading uses, on the same side: the geometric normal, except on smooth
    /// meshes (their interpolated vertex normals).
    pub shading_normal: Vec3A,
    pub item: &'a Item,
    pub leaf: &'a Leaf,
}

/// Which surfaces [`PreparedScene::crossings_between`] reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Crossed {
    /// Only the surfaces of solids (nested media).
    Solids,
    /// Every surface.
    Any,
}

/// Per-thread buffers that queries reuse from ray to ray.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    csg: CsgScratch,
    bvh_stack: Vec<UVec2>,
    packet_stack: Vec<PacketEntry>,
}

#[cfg(test)]
impl Scratch {
    /// The CSG buffers, for tests that call [`item_hit`] themselves.
    pub(crate) fn csg(&mut self) -> &mut CsgScratch {
        &mut self.csg
    }
}

/// What the cheap test of one item reports: the distance, the CSG leaf (0 for a plain
/// shape), the part, and whether the leaf's normal is flipped.
type ItemHit = (f32, u32, Part, bool);

/// The cheap test of one item. Spheres and planes, nearly every item of the scenes that
/// must be fast, are tested inline; everything else goes through [`other_item_hit`], kept
/// out of line so that the query loops stay small enough for the compiler to inline.
#[inline(always)]
pub(crate) fn item_hit(
    item: &Item,
    ray: &Ray,
    tmin: f32,
    tmax: f32,
    scratch: &mut CsgScratch,
) -> Option<ItemHit> {
    match item {
        Item::Shape(Leaf {
            geometry: Geometry::Sphere { center, radius },
            ..
        }) => sphere_first_hit(ray, with_fourth(*center, *radius), *radius, tmin, tmax)
            .map(|t| (t, 0, 0, false)),
        Item::Shape(Leaf {
            geometry: Geometry::Plane { normal, offset },
            ..
        }) => plane_first_hit(ray, with_fourth(*normal, *offset), *offset, tmin, tmax)
            .map(|t| (t, 0, 0, false)),
        _ => other_item_hit(item, ray, tmin, tmax, scratch),
    }
}

#[cold]
#[inline(never)]
fn other_item_hit(
    item: &Item,
    ray: &Ray,
    tmin: f32,
    tmax: f32,
    scratch: &mut CsgScratch,
) -> Option<ItemHit> {
    match item {
        Item::Shape(leaf) => leaf
            .geometry
            .first_hit(ray, tmin, tmax)
            .map(|(t, part)| (t, 0, part, false)),
        Item::Csg { tree, .. } => tree
            .first_hit(ray, tmin, tmax, scratch)
            .map(|b| (b.t, b.leaf, b.part, b.flip)),
    }
}

impl PreparedScene {
    pub(crate) fn item(&self, item: ItemRef) -> &Item {
        match item {
            ItemRef::Bounded(i) => &self.bounded[i as usize],
            ItemRef::Unbounded(i) => &self.unbounded[i as usize],
        }
    }

    /// Whether bounded items are reached through the BVH (otherwise a plain loop).
    #[inline(always)]
    fn walk_bvh(&self) -> Option<&Bvh> {
        self.bvh
            .as_ref()
            .filter(|_| self.bounded.len() > LINEAR_LIMIT)
    }

    /// The closest hit strictly inside `(tmin, tmax)`. Unbounded items are tested first,
    /// then bounded ones (in BVH order); a hit must be strictly nearer than the best so far,
    /// so of two equally near surfaces the first tested wins. Inline, so that scenes of a few
    /// objects pay no call; the BVH walk is a call of its own.
    #[inline(always)]
    pub(crate) fn intersect(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Option<Hit> {
        let (mut best, mut tmax) = self.nearest_unbounded(ray, tmin, tmax, &mut scratch.csg);
        match self.walk_bvh() {
            Some(bvh) => self.intersect_bvh(bvh, ray, tmin, tmax, scratch).or(best),
            None => {
                for (i, item) in self.bounded.iter().enumerate() {
                    if let Some(found) = item_hit(item, ray, tmin, tmax, &mut scratch.csg) {
                        tmax = found.0;
                        best = Some(Hit::new(ItemRef::Bounded(i as u32), found));
                    }
                }
                best
            }
        }
    }

    /// The closest hit among unbounded items, tested one by one (a later one must be
    /// strictly nearer), and the distance bounded items must now beat.
    #[inline(always)]
    fn nearest_unbounded(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        csg: &mut CsgScratch,
    ) -> (Option<Hit>, f32) {
        let mut best = None;
        let mut tmax = tmax;
        for (i, item) in self.unbounded.iter().enumerate() {
            if let Some(found) = item_hit(item, ray, tmin, tmax, csg) {
                tmax = found.0;
                best = Some(Hit::new(ItemRef::Unbounded(i as u32), found));
            }
        }
        (best, tmax)
    }

    /// The closest hit among bounded items, through the BVH.
    #[inline(never)]
    fn intersect_bvh(
        &self,
        bvh: &Bvh,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Option<Hit> {
        let Scratch { csg, bvh_stack, .. } = scratch;
        let mut best = None;
        bvh.traverse(ray, tmin, tmax, bvh_stack, |id, tmax| {
            let Some(item) = self.bounded.get(id as usize) else {
                return Step::Continue;
            };
            match item_hit(item, ray, tmin, tmax, csg) {
                Some(found) => {
                    best = Some(Hit::new(ItemRef::Bounded(id), found));
                    Step::Shrink(found.0)
                }
                None => Step::Continue,
            }
        });
        best
    }

    /// [`PreparedScene::intersect`] of up to [`PACKET`] rays over `(tmin, ∞)` at once, the
    /// bounded items walked as a packet ([`Bvh::traverse_packet`]): `hits[r]` is what
    /// `intersect` returns for `rays[r]`, bit for bit, since each ray meets the same items
    /// in the same order. Returns false, with `hits` untouched, when the rays cannot walk
    /// together (no BVH, too many, or not all of one octant).
    pub(crate) fn intersect_packet(
        &self,
        rays: &[Ray],
        tmin: f32,
        scratch: &mut Scratch,
        hits: &mut [Option<Hit>; PACKET],
    ) -> bool {
        match self.walk_bvh() {
            Some(bvh) if rays.len() <= PACKET => {
                self.intersect_packet_bvh(bvh, rays, tmin, scratch, hits)
            }
            _ => false,
        }
    }

    #[inline(never)]
    fn intersect_packet_bvh(
        &self,
        bvh: &Bvh,
        rays: &[Ray],
        tmin: f32,
        scratch: &mut Scratch,
        hits: &mut [Option<Hit>; PACKET],
    ) -> bool {
        let Scratch {
            csg, packet_stack, ..
        } = scratch;
        // Unbounded items first, ray by ray, as `intersect` tests them.
        let mut tmax = [f32::INFINITY; PACKET];
        let mut unbounded_best: [Option<Hit>; PACKET] = [None; PACKET];
        for ((ray, tmax), best) in rays.iter().zip(&mut tmax).zip(&mut unbounded_best) {
            (*best, *tmax) = self.nearest_unbounded(ray, tmin, f32::INFINITY, csg);
        }
        let mut bounded_best: [Option<Hit>; PACKET] = [None; PACKET];
        let walked = bvh.traverse_packet(rays, tmin, &mut tmax, packet_stack, |r, id, tmax| {
            let (Some(item), Some(ray)) = (self.bounded.get(id as usize), rays.get(r)) else {
                return Step::Continue;
            };
            match item_hit(item, ray, tmin, tmax, csg) {
                Some(found) => {
                    bounded_best[r] = Some(Hit::new(ItemRef::Bounded(id), found));
                    Step::Shrink(found.0)
                }
                None => Step::Continue,
            }
        });
        if walked {
            for ((hit, bounded), unbounded) in hits.iter_mut().zip(bounded_best).zip(unbounded_best)
            {
                *hit = bounded.or(unbounded);
            }
        }
        walked
    }

    /// Any surface strictly inside `(tmin, tmax)`: the first one found, not the nearest
    /// (unbounded items first, then bounded ones in BVH order).
    #[inline(always)]
    pub(crate) fn occluded(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Option<Hit> {
        if let Some(blocker) = self.unbounded_blocker(ray, tmin, tmax, scratch) {
            return Some(blocker);
        }
        match self.walk_bvh() {
            Some(bvh) => self.occluded_bvh(bvh, ray, tmin, tmax, scratch),
            None => self.bounded.iter().enumerate().find_map(|(i, item)| {
                item_hit(item, ray, tmin, tmax, &mut scratch.csg)
                    .map(|found| Hit::new(ItemRef::Bounded(i as u32), found))
            }),
        }
    }

    /// The first unbounded item found in the segment (they are tested one by one, before
    /// the bounded ones, by both shadow queries).
    #[inline(always)]
    fn unbounded_blocker(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Option<Hit> {
        self.unbounded.iter().enumerate().find_map(|(i, item)| {
            item_hit(item, ray, tmin, tmax, &mut scratch.csg)
                .map(|found| Hit::new(ItemRef::Unbounded(i as u32), found))
        })
    }

    /// [`PreparedScene::occluded`] for a shadow ray towards light `light` (the light's own
    /// direction and distance): the same answer, and with `names_blocker` the same blocker.
    /// With a light buffer (see `light_buffer.rs`), a ray that meets none of its candidates
    /// is clear without a walk, and one that meets a candidate well inside its box is
    /// blocked; otherwise the walk answers, as it always has.
    pub(crate) fn occluded_towards(
        &self,
        light: usize,
        names_blocker: bool,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Option<Hit> {
        let Some(buffer) = self.light_buffers.get(light).and_then(Option::as_ref) else {
            return self.occluded(ray, tmin, tmax, scratch);
        };
        let (candidates, limit) = match buffer.lookup(ray, tmax) {
            Lookup::Candidates(candidates, limit) => (candidates, limit),
            Lookup::Unanswered => return self.occluded(ray, tmin, tmax, scratch),
        };
        if let Some(blocker) = self.unbounded_blocker(ray, tmin, tmax, scratch) {
            return Some(blocker);
        }
        let mut met = None;
        for candidate in candidates {
            if candidate.near > limit {
                break;
            }
            let Some(item) = self.bounded.get(candidate.item as usize) else {
                continue;
            };
            if let Some(found) = item_hit(item, ray, tmin, tmax, &mut scratch.csg) {
                met = Some((candidate.item, found));
                break;
            }
        }
        let (index, found) = met?;
        // A recorder names the blocker: the walk's. Otherwise, a segment well inside the
        // blocker's box is one the walk reaches it by (the walk tests boxes holding it); one
        // at its edge, within rounding, asks the walk.
        let inside = self
            .light_buffer_boxes
            .get(index as usize)
            .is_some_and(|aabb| well_inside(aabb, ray, tmin, tmax));
        if inside && !names_blocker {
            return Some(Hit::new(ItemRef::Bounded(index), found));
        }
        match self.walk_bvh() {
            Some(bvh) => self.occluded_bvh(bvh, ray, tmin, tmax, scratch),
            None => self.occluded(ray, tmin, tmax, scratch),
        }
    }

    /// The first bounded item found in the segment, through the BVH.
    #[inline(never)]
    fn occluded_bvh(
        &self,
        bvh: &Bvh,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Option<Hit> {
        let Scratch { csg, bvh_stack, .. } = scratch;
        let mut blocker = None;
        // Inlined into the walk: as a call, each sphere test would spill the walk's vector
        // registers (the AVX walks, compiled for other features, left it out of line).
        bvh.traverse(
            ray,
            tmin,
            tmax,
            bvh_stack,
            #[inline(always)]
            |id, tmax| {
                let Some(item) = self.bounded.get(id as usize) else {
                    return Step::Continue;
                };
                match item_hit(item, ray, tmin, tmax, csg) {
                    Some(found) => {
                        blocker = Some(Hit::new(ItemRef::Bounded(id), found));
                        Step::Stop
                    }
                    None => Step::Continue,
                }
            },
        );
        blocker
    }

    /// Visits unbounded items, then bounded items whose boxes the segment touches, in the
    /// same order as [`PreparedScene::intersect`] and [`PreparedScene::occluded`]. The
    /// visitor gets the current `tmax` and may shrink it or stop. Only the filtered-shadow
    /// query uses it; the hot queries spell their loops out.
    fn visit(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        bvh_stack: &mut Vec<UVec2>,
        mut visitor: impl FnMut(ItemRef, &Item, f32) -> Step,
    ) {
        let mut tmax = tmax;
        for (i, item) in self.unbounded.iter().enumerate() {
            match visitor(ItemRef::Unbounded(i as u32), item, tmax) {
                Step::Continue => {}
                Step::Shrink(t) => tmax = t,
                Step::Stop => return,
            }
        }
        match self.walk_bvh() {
            Some(bvh) => bvh.traverse(ray, tmin, tmax, bvh_stack, |id, tmax| {
                match self.bounded.get(id as usize) {
                    Some(item) => visitor(ItemRef::Bounded(id), item, tmax),
                    None => Step::Continue,
                }
            }),
            None => {
                for (i, item) in self.bounded.iter().enumerate() {
                    match visitor(ItemRef::Bounded(i as u32), item, tmax) {
                        Step::Continue => {}
                        Step::Shrink(t) => tmax = t,
                        Step::Stop => return,
                    }
                }
            }
        }
    }

    /// Filtered shadows: every surface the segment crosses multiplies the light by the
    /// transmissive colour of the material there, exactly as a camera ray through the same
    /// surfaces is weighted by `kt` at each (a solid box filters twice, like its 12
    /// triangles; a CSG solid at each boundary of its interval list). An opaque surface
    /// (transmissive black) blocks and ends the query.
    pub(crate) fn filter_shadow(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Shadow {
        let Scratch { csg, bvh_stack, .. } = scratch;
        let mut transmittance = Vec3A::ONE;
        let mut blockers = 0u32;
        let mut blocked = None;
        self.visit(ray, tmin, tmax, bvh_stack, |item_ref, item, _| {
            // Never shrink: every surface counts, not just the nearest. Each crossing of
            // this item is found by asking again beyond the previous one (strictly greater
            // distances, so the walk ends).
            let mut from = tmin;
            while let Some((t, leaf, part, flip)) = item_hit(item, ray, from, tmax, csg) {
                let hit = Hit {
                    t,
                    item: item_ref,
                    leaf,
                    part,
                    flip,
                };
                let leaf = item.leaf(leaf);
                let kt = match self.resolve_material(leaf, ray.at(t), part) {
                    Resolved { blend: Some(b), .. } => {
                        let first = self.materials[b.first.index()].transmissive;
                        let second = self.materials[b.second.index()].transmissive;
                        first + (second - first) * b.weight
                    }
                    Resolved { material, .. } => self.materials[material.index()].transmissive,
                };
                if kt == Vec3A::ZERO {
                    blocked = Some(hit);
                    return Step::Stop;
                }
                transmittance *= kt;
                blockers += 1;
                from = t;
            }
            Step::Continue
        });
        match (blocked, blockers) {
            (Some(hit), _) => Shadow::Blocked(hit),
            (None, 0) => Shadow::Clear,
            (None, blockers) => Shadow::Filtered {
                transmittance,
                blockers,
            },
        }
    }

    /// Every crossing of a surface (of a solid's only, with [`Crossed::Solids`]) strictly
    /// inside `(low, high)`: the surfaces in the same place as a hit, crossed as one by
    /// nested media, or told apart by nothing but rounding (z-fighting). `found` gets each
    /// crossing and returns whether to go on.
    pub(crate) fn crossings_between(
        &self,
        ray: &Ray,
        (low, high): (f32, f32),
        crossed: Crossed,
        scratch: &mut Scratch,
        mut found: impl FnMut(Hit) -> bool,
    ) {
        let Scratch { csg, bvh_stack, .. } = scratch;
        self.visit(ray, low, high, bvh_stack, |item_ref, item, _| {
            let mut from = low;
            while let Some((t, leaf, part, flip)) = item_hit(item, ray, from, high, csg) {
                if crossed == Crossed::Any || item.leaf(leaf).geometry.is_solid() {
                    let hit = Hit {
                        t,
                        item: item_ref,
                        leaf,
                        part,
                        flip,
                    };
                    if !found(hit) {
                        return Step::Stop;
                    }
                }
                from = t;
            }
            Step::Continue
        });
    }

    /// Full surface data for a hit along `ray`.
    #[inline(always)]
    pub(crate) fn surface(&self, ray: &Ray, hit: &Hit) -> Surface<'_> {
        let item = self.item(hit.item);
        let leaf = item.leaf(hit.leaf);
        let (bounded, normal) = match &leaf.geometry {
            Geometry::Sphere { center, radius } => {
                hit_error::on_sphere(with_fourth(*center, *radius), *radius, ray.at(hit.t))
            }
            // What `Geometry::normal` computes for a plane, inline: floors are hit often.
            Geometry::Plane { normal, offset } => (
                hit_error::on_plane(with_fourth(*normal, *offset), *offset, ray.at(hit.t)),
                unit_normal(with_fourth(*normal, *offset), ray),
            ),
            geometry => (
                geometry.bounded_point(ray, hit.t, hit.part),
                geometry.normal(ray, hit.t, hit.part),
            ),
        };
        let shading = match &leaf.geometry {
            Geometry::Mesh(_) => leaf
                .geometry
                .shading_normal(ray, hit.part, normal)
                .unwrap_or(normal),
            _ => normal,
        };
        let sign = if hit.flip { -1.0 } else { 1.0 };
        Surface {
            point: bounded.point,
            error: bounded.error,
            geometric_normal: sign * normal,
            shading_normal: sign * shading,
            item,
            leaf,
        }
    }

    /// The material at a point of a leaf, after (possibly nested) patterns: one material,
    /// or a blend of two (the course's `Noise`, `Marble`, `Wood`), each of which is resolved
    /// by choosing patterns alone (validation refuses a blend of blends).
    #[inline]
    pub(crate) fn resolve_material(&self, leaf: &Leaf, point: Vec3A, part: Part) -> Resolved {
        let mut material = leaf.material;
        // Only a leaf whose material has a pattern was given a frame (found in one step).
        let Some(frame) = self.pattern_frames.get(leaf.object) else {
            return Resolved {
                material,
                blend: None,
            };
        };
        let object_point = frame.object_point(point, part);
        let world_point = frame.world_from_object.transform_point3a(object_point);
        let choose = |mut material: Handle<Material>| {
            // Pattern parts always come earlier in the arena (validated), so this ends.
            while let Some(pattern) = &self.materials[material.index()].pattern {
                match pattern.pick(object_point, world_point) {
                    Pick::One(next) => material = next,
                    // Validation keeps blends out of a blend's parts; should one arrive,
                    // its first material stands for it.
                    Pick::Blend(_) => material = pattern.a,
                }
            }
            material
        };
        while let Some(pattern) = &self.materials[material.index()].pattern {
            match pattern.pick(object_point, world_point) {
                Pick::One(next) => material = next,
                Pick::Blend(weight) => {
                    let blend = Blend {
                        first: choose(pattern.a),
                        second: choose(pattern.b),
                        weight,
                    };
                    return Resolved {
                        material: blend.dominant(),
                        blend: Some(blend),
                    };
                }
            }
        }
        Resolved {
            material,
            blend: None,
        }
    }
}

/// The material at a surface point: `material` is the one to use wherever a single
/// material must stand (the medium inside, the recorded material), and `blend`, when the
/// course's blending patterns made one, is what shading uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Resolved {
    pub material: Handle<Material>,
    pub blend: Option<Blend>,
}
