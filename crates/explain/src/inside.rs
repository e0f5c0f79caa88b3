//! Whether a world point is inside a solid object of the IR: the shapes' own definitions
//! (docs/language.md), in object space through the inverse of `world_from_object`, and CSG
//! by its operation. Used to tell that a light sits inside a solid; no ray is traced.

use glam::DVec3;
use whitted_ir::{CsgOp, Handle, Object, ObjectKind, Scene, Shape};

/// `Some(true)` when `p` is strictly inside the solid `handle`, `Some(false)` outside,
/// `None` when the object has no inside (disks, triangles, open tubes, groups).
pub fn contains(scene: &Scene, handle: Handle<Object>, p: DVec3) -> Option<bool> {
    let object = scene.objects.get(handle)?;
    match &object.kind {
        ObjectKind::Shape { shape } => {
            let local = object.world_from_object.inverse().transform_point3(p);
            shape_contains(shape, local)
        }
        ObjectKind::Csg { op, children } => {
            let mut inside = children
                .iter()
                .map(|&c| contains(scene, c, p).unwrap_or(false));
            Some(match op {
                CsgOp::Union => inside.any(|b| b),
                CsgOp::Intersection => inside.all(|b| b),
                CsgOp::Difference => inside.next().unwrap_or(false) && !inside.any(|b| b),
            })
        }
        ObjectKind::Group { .. } => None,
    }
}

fn shape_contains(shape: &Shape, p: DVec3) -> Option<bool> {
    match *shape {
        Shape::Sphere { center, radius } => Some(p.distance_squared(center) < radius * radius),
        Shape::Plane { normal, offset } => Some(normal.dot(p) < offset),
        Shape::Box { min, max } => Some(p.cmpgt(min).all() && p.cmplt(max).all()),
        Shape::Cylinder {
            base,
            apex,
            radius,
            capped: true,
        } => Some(in_tube(p, base, apex, radius, radius)),
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            capped: true,
        } => Some(in_tube(p, base, apex, base_radius, apex_radius)),
        Shape::Quadric { quadric, .. } => Some(quadric.eval(p) < 0.0),
        Shape::Torus { major, minor } => {
            let ring = (p.x * p.x + p.z * p.z).sqrt() - major;
            Some(ring * ring + p.y * p.y < minor * minor)
        }
        Shape::Cylinder { .. }
        | Shape::Cone { .. }
        | Shape::Disk { .. }
        | Shape::Triangle { .. } => None,
    }
}

/// Inside a capped tube from `base` (radius `r0`) to `apex` (radius `r1`).
fn in_tube(p: DVec3, base: DVec3, apex: DVec3, r0: f64, r1: f64) -> bool {
    let axis = apex - base;
    let length_squared = axis.length_squared();
    if length_squared <= 0.0 {
        return false;
    }
    let s = (p - base).dot(axis) / length_squared;
    if !(0.0..1.0).contains(&s) || s == 0.0 {
        return false;
    }
    let radius = r0 + (r1 - r0) * s;
    let radial = (p - base - axis * s).length_squared();
    radial < radius * radius
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_know_their_inside() {
        let sphere = Shape::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
        };
        assert_eq!(
            shape_contains(&sphere, DVec3::new(0.5, 0.0, 0.0)),
            Some(true)
        );
        assert_eq!(
            shape_contains(&sphere, DVec3::new(1.5, 0.0, 0.0)),
            Some(false)
        );
        let tube = Shape::Cylinder {
            base: DVec3::ZERO,
            apex: DVec3::Y * 2.0,
            radius: 1.0,
            capped: true,
        };
        assert_eq!(shape_contains(&tube, DVec3::new(0.5, 1.0, 0.0)), Some(true));
        assert_eq!(
            shape_contains(&tube, DVec3::new(0.5, 2.5, 0.0)),
            Some(false)
        );
        let open = Shape::Cylinder {
            base: DVec3::ZERO,
            apex: DVec3::Y,
            radius: 1.0,
            capped: false,
        };
        assert_eq!(shape_contains(&open, DVec3::ZERO), None);
        let torus = Shape::Torus {
            major: 2.0,
            minor: 0.5,
        };
        assert_eq!(
            shape_contains(&torus, DVec3::new(2.0, 0.0, 0.0)),
            Some(true)
        );
        assert_eq!(shape_contains(&torus, DVec3::ZERO), Some(false));
    }
}
