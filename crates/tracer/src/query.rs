//! Ray queries against a prepared scene, named by their cost: [`PreparedScene::intersect`]
//! (closest hit, cheap data only), [`PreparedScene::occluded`] (any blocker, stops at the
//! first), [`PreparedScene::filter_shadow`] (every blocker, for filtered shadows) and
//! [`PreparedScene::surface`] (full surface data, computed for the nearest hit only).
//!
//! Unbounded items are tested one by one, bounded ones through the CwBvh. The traversal
//! callback honours the segment `(tmin, tmax)` itself and shrinks `tmax` as hits are
//! found; BVH ids index `bounded` directly because items were reordered at build time.

use glam::{UVec2, Vec3A};
use whitted_ir::{Handle, Material};

use crate::bvh::Step;
use crate::csg::CsgScratch;
use crate::ray::Ray;
use crate::scene::{Item, Leaf, PreparedScene};
use crate::shapes::{plane_first_hit, sphere_first_hit, Geometry, Part};

/// Below this many bounded items a plain loop beats walking the BVH.
const LINEAR_LIMIT: usize = 4;

/// Which top-level item was hit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ItemRef {
    Bounded(u32),
    Unbounded(u32),
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

/// What a shadow ray found between the surface and the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shadow {
    Clear,
    Blocked(Hit),
    /// Only transmissive blockers: the light passes, multiplied by their colours.
    Filtered {
        transmittance: Vec3A,
        blockers: u32,
    },
}

/// Full data for one hit.
#[derive(Clone, Copy, Debug)]
pub struct Surface<'a> {
    pub point: Vec3A,
    /// Outward unit normal of the solid (after the CSG flip).
    pub geometric_normal: Vec3A,
    pub item: &'a Item,
    pub leaf: &'a Leaf,
}

/// Per-thread buffers that queries reuse from ray to ray.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    csg: CsgScratch,
    bvh_stack: Vec<UVec2>,
}

#[inline(always)]
fn item_hit(
    item: &Item,
    ray: &Ray,
    tmin: f32,
    tmax: f32,
    scratch: &mut CsgScratch,
) -> Option<(f32, u32, Part, bool)> {
    match item {
        // Spheres first and inline: they are most of the objects in big scenes.
        Item::Shape(Leaf {
            geometry: Geometry::Sphere { center, radius },
            ..
        }) => sphere_first_hit(ray, *center, *radius, tmin, tmax).map(|t| (t, 0, 0, false)),
        Item::Shape(Leaf {
            geometry: Geometry::Plane { normal, offset },
            ..
        }) => plane_first_hit(ray, *normal, *offset, tmin, tmax).map(|t| (t, 0, 0, false)),
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

    /// Visits unbounded items, then bounded items whose boxes the segment touches. The
    /// visitor gets the current `tmax` and may shrink it or stop.
    #[inline(always)]
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
        match &self.bvh {
            Some(bvh) if self.bounded.len() > LINEAR_LIMIT => {
                bvh.traverse(ray, tmin, tmax, bvh_stack, |id, tmax| {
                    match self.bounded.get(id as usize) {
                        Some(item) => visitor(ItemRef::Bounded(id), item, tmax),
                        None => Step::Continue,
                    }
                });
            }
            _ => {
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

    /// The closest hit strictly inside `(tmin, tmax)`.
    pub(crate) fn intersect(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Option<Hit> {
        let Scratch { csg, bvh_stack } = scratch;
        let mut best = None;
        self.visit(
            ray,
            tmin,
            tmax,
            bvh_stack,
            |item_ref, item, tmax| match item_hit(item, ray, tmin, tmax, csg) {
                Some((t, leaf, part, flip)) => {
                    best = Some(Hit {
                        t,
                        item: item_ref,
                        leaf,
                        part,
                        flip,
                    });
                    Step::Shrink(t)
                }
                None => Step::Continue,
            },
        );
        best
    }

    /// Any surface strictly inside `(tmin, tmax)`: the first one found, not the nearest.
    pub(crate) fn occluded(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Option<Hit> {
        let Scratch { csg, bvh_stack } = scratch;
        let mut blocker = None;
        self.visit(
            ray,
            tmin,
            tmax,
            bvh_stack,
            |item_ref, item, tmax| match item_hit(item, ray, tmin, tmax, csg) {
                Some((t, leaf, part, flip)) => {
                    blocker = Some(Hit {
                        t,
                        item: item_ref,
                        leaf,
                        part,
                        flip,
                    });
                    Step::Stop
                }
                None => Step::Continue,
            },
        );
        blocker
    }

    /// Filtered shadows: every object crossing the segment multiplies the light by the
    /// transmissive colour of the material where the shadow ray first meets it (once per
    /// object); an opaque one (transmissive black) blocks and ends the query.
    pub(crate) fn filter_shadow(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut Scratch,
    ) -> Shadow {
        let Scratch { csg, bvh_stack } = scratch;
        let mut transmittance = Vec3A::ONE;
        let mut blockers = 0u32;
        let mut blocked = None;
        self.visit(ray, tmin, tmax, bvh_stack, |item_ref, item, _| {
            // Never shrink: every blocker counts, not just the nearest.
            let Some((t, leaf, part, flip)) = item_hit(item, ray, tmin, tmax, csg) else {
                return Step::Continue;
            };
            let hit = Hit {
                t,
                item: item_ref,
                leaf,
                part,
                flip,
            };
            let leaf = item.leaf(leaf);
            let material = self.resolve_material(leaf, ray.at(t), part);
            let kt = self.materials[material.index()].transmissive;
            if kt == Vec3A::ZERO {
                blocked = Some(hit);
                return Step::Stop;
            }
            transmittance *= kt;
            blockers += 1;
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

    /// Full surface data for a hit along `ray`.
    pub(crate) fn surface(&self, ray: &Ray, hit: &Hit) -> Surface<'_> {
        let item = self.item(hit.item);
        let leaf = item.leaf(hit.leaf);
        let point = ray.at(hit.t);
        let normal = match &leaf.geometry {
            Geometry::Sphere { center, .. } => (point - *center).normalize(),
            geometry => geometry.normal(ray, hit.t, hit.part),
        };
        Surface {
            point,
            geometric_normal: if hit.flip { -normal } else { normal },
            item,
            leaf,
        }
    }

    /// The material at a point of a leaf, after (possibly nested) patterns.
    #[inline]
    pub(crate) fn resolve_material(
        &self,
        leaf: &Leaf,
        point: Vec3A,
        part: Part,
    ) -> Handle<Material> {
        let mut material = leaf.material;
        let Some(frame) = &leaf.pattern_frame else {
            return material;
        };
        let object_point = frame.object_point(point, part);
        // Pattern parts always come earlier in the arena (validated), so this ends.
        while let Some(pattern) = &self.materials[material.index()].pattern {
            material = pattern.choose(object_point);
        }
        material
    }
}
