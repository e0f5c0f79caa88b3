//! Hit points with a floating-point error bound, worked out shape by shape (the approach of
//! pbrt-v4's `Point3fi` and `OffsetRayOrigin`, written for whitted's shapes).
//!
//! A hit point computed as `origin + t·direction` is off the surface by the rounding of `t`,
//! which grows with the distance travelled and, for a quadratic, with the size of the shape
//! (its terms are of the order of `|origin − centre|²`). So each shape moves the point back
//! onto its own surface where that is cheap (a sphere radially, a plane along its normal, a
//! triangle through its barycentric coordinates, a canonical shape in its own space before
//! the transform) and bounds what is left: a few roundings of the coordinates that made it.
//! Secondary and shadow rays start [`spawn_offset`] off the surface along the normal, just
//! outside that error box, so they cannot meet the surface they leave and still meet
//! anything beyond it.

use glam::{Affine3A, DMat4, DVec4, Vec3A};

/// The unit roundoff of f32 arithmetic: half an ulp of 1.
const UNIT_ROUNDOFF: f32 = f32::EPSILON * 0.5;

/// `γ(n) = n·u / (1 − n·u)`: the bound on the relative error of a result of `n` roundings
/// (Higham; pbrt-v4's `gamma`).
#[inline(always)]
pub const fn gamma(n: u32) -> f32 {
    let nu = n as f32 * UNIT_ROUNDOFF;
    nu / (1.0 - nu)
}

/// How many times its error bound a spawned ray starts off the surface. The bound covers
/// the point; the margin covers the re-intersection test's own rounding, which is of the
/// same order (a sphere's `|o − c|² − r²` at the new origin, a plane's `offset − n·o`), and
/// the tests in `tests/acne.rs` and `tests/error_bounds.rs` find no self-hit with it over
/// sizes and offsets from 1e-3 to 1e5.
const SPAWN_MARGIN: f32 = 2.0;

/// A computed hit point and, per axis, a bound on its distance from the true surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundedPoint {
    pub point: Vec3A,
    pub error: Vec3A,
}

/// The error box's extent along the unit normal `n`: how far the point may be from the
/// surface.
#[inline(always)]
pub fn error_along(n: Vec3A, error: Vec3A) -> f32 {
    n.abs().dot(error)
}

/// The least offset, for a point that lies exactly on its surface at the origin's scale (a
/// floor at y = 0 has no error along its normal). Far above the subnormal range: an offset
/// of `f32::MIN_POSITIVE` made every shadow ray's plane test multiply two numbers that
/// small, and subnormal arithmetic halved the speed of a scene with a floor.
const LEAST_OFFSET: f32 = 1e-20;

/// How far a secondary or shadow ray starts off the surface at `point`, along the unit
/// normal `n`: the error box's extent along the normal, with a margin; at least a couple of
/// ulps of the point's coordinates, so that the new origin is never the point itself; and
/// never less than [`LEAST_OFFSET`].
#[inline(always)]
pub fn spawn_offset(n: Vec3A, error: Vec3A, point: Vec3A) -> f32 {
    let ulps = n.abs().dot(point.abs()) * f32::EPSILON * 2.0;
    (error_along(n, error) * SPAWN_MARGIN)
        .max(ulps)
        .max(LEAST_OFFSET)
}

/// A point of the sphere `|p − center| = radius`, moved radially onto it from `p`. After
/// the move the offset from the centre is within `γ(5)` of its length (a norm, a division
/// and a product), and adding the centre back rounds once more.
#[inline(always)]
pub fn on_sphere(center: Vec3A, radius: f32, p: Vec3A) -> (BoundedPoint, Vec3A) {
    let local = p - center;
    let length = local.length();
    // `normalize`'s arithmetic, so that normals keep the bits they had before points were
    // placed on the surface.
    let normal = if length > 0.0 {
        local * length.recip()
    } else {
        Vec3A::Y
    };
    let local = normal * radius;
    let point = center + local;
    let error = gamma(5) * local.abs() + gamma(2) * (center.abs() + local.abs());
    (BoundedPoint { point, error }, normal)
}

/// A point of the plane `normal·p = offset` (unit normal), moved onto it along the normal.
/// What is left is the rounding of the projection: a few ulps of the coordinates and of the
/// offset.
#[inline(always)]
pub fn on_plane(normal: Vec3A, offset: f32, p: Vec3A) -> BoundedPoint {
    let distance = normal.dot(p) - offset;
    let point = p - distance * normal;
    let error = gamma(6) * (point.abs() + offset.abs() * normal.abs());
    BoundedPoint { point, error }
}

/// The point `a + u·edge1 + v·edge2` of a triangle, from its barycentric coordinates: on
/// the triangle's plane up to the rounding of that sum, whatever the distance the ray came
/// from (where `origin + t·direction` carries the error of `t`).
#[inline(always)]
pub fn on_triangle(a: Vec3A, edge1: Vec3A, edge2: Vec3A, (u, v): (f32, f32)) -> BoundedPoint {
    let (along1, along2) = (u * edge1, v * edge2);
    let point = a + along1 + along2;
    let error = gamma(4) * (a.abs() + along1.abs() + along2.abs());
    BoundedPoint { point, error }
}

/// A point of the quadric `Pᵀ·S·P = 0` moved onto it by one Newton step along the gradient,
/// in f64; the bound is the f64 residual's distance (measured, not assumed) plus the
/// rounding to f32.
pub fn on_quadric(matrix: &DMat4, p: Vec3A) -> BoundedPoint {
    let value_and_gradient = |q: glam::DVec3| {
        let h = DVec4::from((q, 1.0));
        let s = *matrix * h;
        (h.dot(s), 2.0 * s.truncate())
    };
    let start = p.as_dvec3();
    let (value, gradient) = value_and_gradient(start);
    let g2 = gradient.length_squared();
    let moved = if g2 > 0.0 && g2.is_finite() {
        start - gradient * (value / g2)
    } else {
        start
    };
    let (value, gradient) = value_and_gradient(moved);
    let g = gradient.length();
    let residual = if g > 0.0 { value.abs() / g } else { 0.0 };
    let point = moved.as_vec3a();
    let residual = residual as f32;
    if !(point.is_finite() && residual.is_finite()) {
        return BoundedPoint {
            point: p,
            error: gamma(32) * p.abs(),
        };
    }
    BoundedPoint {
        point,
        error: Vec3A::splat(residual) + gamma(2) * point.abs(),
    }
}

/// The whole-ray bound, in ulps of the magnitudes a point `origin + t·d` came from: the
/// rounding of that sum and of `t` itself (every intersection routine solves relative to
/// the ray origin or a shape's centre), with a margin for a change of space.
const ALONG_RAY_ULPS: f32 = 32.0;

/// A point that no shape-specific rule places (a torus's quartic root): `origin + t·d`,
/// bounded by [`ALONG_RAY_ULPS`] over the magnitudes it was computed from (the bound
/// whitted used for every shape before).
#[inline]
pub fn along_ray(origin: Vec3A, direction: Vec3A, t: f32) -> BoundedPoint {
    let point = origin + t * direction;
    let magnitude = origin.abs().max_element() + t.abs() + point.abs().max_element();
    BoundedPoint {
        point,
        error: Vec3A::splat(magnitude * f32::EPSILON * ALONG_RAY_ULPS),
    }
}

/// A point carried through an affine map with its error (pbrt-v4's rule for transforming
/// a `Point3fi`): the map scales the error it is given, and its own products and sums
/// round three times per coordinate.
#[inline]
pub fn transformed(m: &Affine3A, local: BoundedPoint) -> BoundedPoint {
    let abs = glam::Mat3A::from_cols(
        m.matrix3.x_axis.abs(),
        m.matrix3.y_axis.abs(),
        m.matrix3.z_axis.abs(),
    );
    let point = m.transform_point3a(local.point);
    let error = (1.0 + gamma(3)) * (abs * local.error)
        + gamma(3) * (abs * local.point.abs() + m.translation.abs());
    BoundedPoint { point, error }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The distance of an f32 point from the sphere, in f64: the oracle for the bound.
    fn sphere_distance(center: Vec3A, radius: f32, p: Vec3A) -> f64 {
        ((p.as_dvec3() - center.as_dvec3()).length() - f64::from(radius)).abs()
    }

    #[test]
    fn a_sphere_point_is_within_its_bound_at_every_size_and_place() {
        let mut checked = 0;
        for exponent in -3..=5 {
            let radius = 10f32.powi(exponent);
            for center in [
                Vec3A::ZERO,
                Vec3A::new(0.0, -radius, 0.0),
                Vec3A::splat(1e5),
            ] {
                for k in 0..50 {
                    let a = k as f32 * 0.7;
                    let direction = Vec3A::new(a.cos(), (a * 1.3).sin(), a.sin()).normalize();
                    // A point a little off the surface, as a ray's rounding leaves it.
                    let p = center + direction * radius * (1.0 + 1e-4);
                    let (bounded, normal) = on_sphere(center, radius, p);
                    let distance = sphere_distance(center, radius, bounded.point);
                    let along_normal = f64::from(normal.abs().dot(bounded.error));
                    assert!(
                        distance <= along_normal,
                        "radius {radius} centre {center}: {distance} off the sphere, bound \
                         {along_normal}"
                    );
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, 9 * 3 * 50);
    }

    #[test]
    fn a_plane_point_is_within_its_bound_far_from_the_origin() {
        let normal = Vec3A::new(0.3, 0.9, -0.1).normalize();
        for offset in [0.0f32, 1.0, -250.0, 1e5] {
            for k in 0..100 {
                let k = k as f32;
                let p = Vec3A::new(k * 997.0 - 5e4, offset + k * 1e-3, -k * 311.0);
                let on = on_plane(normal, offset, p);
                let exact = normal.as_dvec3().dot(on.point.as_dvec3()) - f64::from(offset);
                let bound = f64::from(normal.abs().dot(on.error));
                assert!(exact.abs() <= bound, "{exact} off the plane, bound {bound}");
            }
        }
    }

    #[test]
    fn a_triangle_point_is_on_its_plane_within_its_bound() {
        let a = Vec3A::new(1e4, 0.05, -1e4);
        let (edge1, edge2) = (Vec3A::new(2.0, 0.0, 0.0), Vec3A::new(0.0, 0.0, 2.0));
        let normal = DVec3::Y;
        for k in 0..100 {
            let (u, v) = (k as f32 / 200.0, (k % 7) as f32 / 14.0);
            let on = on_triangle(a, edge1, edge2, (u, v));
            let exact = (on.point.as_dvec3() - a.as_dvec3()).dot(normal);
            assert!(
                exact.abs() <= f64::from(on.error.y),
                "{exact} off the plane"
            );
        }
    }

    #[test]
    fn the_transformed_bound_holds_the_f64_image() {
        let m = glam::DAffine3::from_scale_rotation_translation(
            DVec3::new(3.0, 0.01, 7.0),
            glam::DQuat::from_rotation_y(0.7),
            DVec3::new(1e4, -3.0, 2.5e3),
        );
        for k in 0..100 {
            let p = Vec3A::new(k as f32 * 0.02 - 1.0, 1.0, (k % 9) as f32 * 0.2 - 0.8);
            let out = transformed(
                &m.as_affine3a(),
                BoundedPoint {
                    point: p,
                    error: Vec3A::ZERO,
                },
            );
            let exact = m.transform_point3(p.as_dvec3());
            let off = (out.point.as_dvec3() - exact).abs();
            assert!(
                off.cmple(out.error.as_dvec3()).all(),
                "{off} beyond {}",
                out.error
            );
        }
    }

    #[test]
    fn the_whole_ray_bound_grows_with_the_magnitudes() {
        // Close to the origin and to the eye: a few millionths.
        let near = along_ray(Vec3A::new(0.0, 1.0, 0.0), Vec3A::new(0.0, -1.0, 0.0), 1.0);
        assert!(near.error.x < 1e-5 && near.error.x > 0.0, "{}", near.error);
        // Far away it moves the point by several ulps.
        let far = along_ray(Vec3A::splat(1.0e5), Vec3A::new(0.0, 0.0, 1.0), 10.0);
        let p = far.point.z;
        assert!(
            p + far.error.z > p + 4.0 * (p * f32::EPSILON),
            "{}",
            far.error
        );
    }

    #[test]
    fn the_offset_is_never_zero() {
        let offset = spawn_offset(Vec3A::Y, Vec3A::ZERO, Vec3A::ZERO);
        assert!(offset > 0.0 && offset.is_normal());
        // Products with it stay normal: no slow subnormal arithmetic.
        assert!((offset * 1e-3 * 0.5).is_normal());
        // A point exactly on a plane far up still moves by at least an ulp.
        let p = Vec3A::new(0.0, 5000.0, 0.0);
        assert!(p + Vec3A::Y * spawn_offset(Vec3A::Y, Vec3A::ZERO, p) != p);
    }
}
