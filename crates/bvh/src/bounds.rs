//! World-space bounds of shapes and CSG nodes, including the empty and the unbounded case.
//!
//! Bounds are computed in f64 from the IR and rounded outwards to f32, so the f32 box always
//! contains the f64 surface it stands for.

use glam::{DAffine3, DVec3, Vec3A};
use obvhs::aabb::Aabb;

use crate::ray::Ray;

/// Where a shape or solid can be: nowhere, inside a box, or anywhere (planes, paraboloids).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    Empty,
    Finite(Aabb),
    Infinite,
}

/// Relative and absolute padding that keeps f32 boxes conservative after rounding.
const RELATIVE_PAD: f64 = 1.0 / (1u64 << 20) as f64;
const ABSOLUTE_PAD: f64 = 1e-6;

impl Bound {
    /// The box spanning two f64 corners, padded outwards.
    pub fn from_f64(min: DVec3, max: DVec3) -> Bound {
        if !(min.is_finite() && max.is_finite()) {
            return Bound::Infinite;
        }
        if min.cmpgt(max).any() {
            return Bound::Empty;
        }
        let magnitude = min.abs().max(max.abs()).max(max - min);
        let pad = magnitude * RELATIVE_PAD + DVec3::splat(ABSOLUTE_PAD);
        let lo = (min - pad).as_vec3();
        let hi = (max + pad).as_vec3();
        if !(lo.is_finite() && hi.is_finite()) {
            return Bound::Infinite;
        }
        Bound::Finite(Aabb::new(lo.into(), hi.into()))
    }

    /// The bound of an object-space box `[min, max]` after an affine transform.
    pub fn transformed_box(world_from_local: &DAffine3, min: DVec3, max: DVec3) -> Bound {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for corner in 0..8 {
            let p = DVec3::new(
                if corner & 1 == 0 { min.x } else { max.x },
                if corner & 2 == 0 { min.y } else { max.y },
                if corner & 4 == 0 { min.z } else { max.z },
            );
            let w = world_from_local.transform_point3(p);
            lo = lo.min(w);
            hi = hi.max(w);
        }
        Bound::from_f64(lo, hi)
    }

    pub fn union(self, other: Bound) -> Bound {
        match (self, other) {
            (Bound::Empty, b) | (b, Bound::Empty) => b,
            (Bound::Infinite, _) | (_, Bound::Infinite) => Bound::Infinite,
            (Bound::Finite(a), Bound::Finite(b)) => Bound::Finite(a.union(&b)),
        }
    }

    pub fn intersection(self, other: Bound) -> Bound {
        match (self, other) {
            (Bound::Empty, _) | (_, Bound::Empty) => Bound::Empty,
            (Bound::Infinite, b) | (b, Bound::Infinite) => b,
            (Bound::Finite(a), Bound::Finite(b)) => {
                let c = a.intersection(&b);
                if c.min.cmpgt(c.max).any() {
                    Bound::Empty
                } else {
                    Bound::Finite(c)
                }
            }
        }
    }

    /// Whether the ray's segment `(tmin, tmax)` can touch what this bounds.
    #[inline]
    pub fn admits(&self, ray: &Ray, inv_direction: Vec3A, tmin: f32, tmax: f32) -> bool {
        match self {
            Bound::Empty => false,
            Bound::Infinite => true,
            Bound::Finite(aabb) => segment_touches_box(aabb, ray, inv_direction, tmin, tmax),
        }
    }
}

impl Bound {
    /// Where the ray's segment `[tmin, tmax]` first meets what this bounds (`tmin` for an
    /// unbounded solid), or `None` when it cannot: a lower bound on any crossing there.
    #[inline]
    pub fn entry(&self, ray: &Ray, inv_direction: Vec3A, tmin: f32, tmax: f32) -> Option<f32> {
        match self {
            Bound::Empty => None,
            Bound::Infinite => (tmin <= tmax).then_some(tmin),
            Bound::Finite(aabb) => segment_entry(aabb, ray, inv_direction, tmin, tmax),
        }
    }
}

/// The slab test, with a reciprocal direction from [`inverse_direction`] (always finite, so
/// no `0 · ∞` NaN can arise for a ray lying in a slab's plane).
#[inline]
pub fn segment_touches_box(
    aabb: &Aabb,
    ray: &Ray,
    inv_direction: Vec3A,
    tmin: f32,
    tmax: f32,
) -> bool {
    segment_entry(aabb, ray, inv_direction, tmin, tmax).is_some()
}

/// Where the ray's segment `[tmin, tmax]` first touches the box (`tmin` when it starts
/// inside), or `None` when it does not touch it (the slab test behind
/// [`segment_touches_box`]).
#[inline]
pub fn segment_entry(
    aabb: &Aabb,
    ray: &Ray,
    inv_direction: Vec3A,
    tmin: f32,
    tmax: f32,
) -> Option<f32> {
    let t1 = (aabb.min - ray.origin) * inv_direction;
    let t2 = (aabb.max - ray.origin) * inv_direction;
    let near = t1.min(t2);
    let far = t1.max(t2);
    let enter = near.x.max(near.y).max(near.z).max(tmin);
    let exit = far.x.min(far.y).min(far.z).min(tmax);
    (enter <= exit).then_some(enter)
}

/// Component-wise reciprocal, clamped like obvhs's `safe_inverse`: a component too small to
/// invert becomes ±1/ε, so slab distances stay finite and comparisons stay meaningful.
#[inline]
pub fn inverse_direction(direction: Vec3A) -> Vec3A {
    // One vector division, then the tiny components replaced (branch-free).
    let tiny = direction.abs().cmple(Vec3A::splat(f32::EPSILON));
    let clamped = Vec3A::splat(1.0 / f32::EPSILON).copysign(direction);
    Vec3A::select(tiny, clamped, Vec3A::ONE / direction)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn combining_bounds() {
        let a = Bound::from_f64(DVec3::ZERO, DVec3::ONE);
        let b = Bound::from_f64(DVec3::splat(2.0), DVec3::splat(3.0));
        assert_eq!(a.intersection(b), Bound::Empty);
        assert!(matches!(a.union(b), Bound::Finite(_)));
        assert_eq!(a.union(Bound::Infinite), Bound::Infinite);
        assert_eq!(a.intersection(Bound::Infinite), a);
        assert_eq!(Bound::Empty.union(a), a);
    }

    #[test]
    fn inverse_direction_stays_finite() {
        let inv = inverse_direction(Vec3A::new(0.5, -0.0, 1e-9));
        assert_eq!(inv.x, 2.0);
        assert_eq!(inv.y, -1.0 / f32::EPSILON);
        assert_eq!(inv.z, 1.0 / f32::EPSILON);
        assert!(
            inverse_direction(Vec3A::new(-1e-20, 0.0, -4.0)).abs_diff_eq(
                Vec3A::new(-1.0 / f32::EPSILON, 1.0 / f32::EPSILON, -0.25),
                0.0
            )
        );
    }

    #[test]
    fn slab_test_respects_the_segment() {
        let Bound::Finite(aabb) = Bound::from_f64(DVec3::splat(-1.0), DVec3::splat(1.0)) else {
            panic!("a unit box is finite");
        };
        let ray = Ray::new(Vec3A::new(0.0, 0.0, -5.0), Vec3A::Z);
        let inv = inverse_direction(ray.direction);
        assert!(segment_touches_box(&aabb, &ray, inv, 0.0, f32::INFINITY));
        assert!(!segment_touches_box(&aabb, &ray, inv, 0.0, 3.9));
        assert!(!segment_touches_box(&aabb, &ray, inv, 6.1, 10.0));
        // A ray grazing a face of the bounded solid, parallel to it, is admitted thanks to the
        // padding; one clearly outside is not.
        let in_face = Ray::new(Vec3A::new(-5.0, 1.0, 0.0), Vec3A::X);
        let inv = inverse_direction(in_face.direction);
        assert!(segment_touches_box(
            &aabb,
            &in_face,
            inv,
            0.0,
            f32::INFINITY
        ));
        let outside = Ray::new(Vec3A::new(-5.0, 1.001, 0.0), Vec3A::X);
        assert!(!segment_touches_box(
            &aabb,
            &outside,
            inv,
            0.0,
            f32::INFINITY
        ));
    }
}
