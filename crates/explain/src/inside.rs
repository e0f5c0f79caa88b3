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
            shape_contains(scene, &shape.get(), local)
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

fn shape_contains(scene: &Scene, shape: &Shape, p: DVec3) -> Option<bool> {
    match *shape {
        Shape::Mesh { mesh, .. } => {
            let mesh = scene.meshes.get(mesh)?;
            mesh.solid.then(|| mesh_contains(mesh, p))
        }
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

/// Inside a closed mesh: a ray from `p` crosses its surface an odd number of times. The
/// direction is skewed off every axis so that it does not run along the edges and faces of
/// meshes modelled on a grid; every triangle is tested (one question, not per pixel).
fn mesh_contains(mesh: &whitted_ir::Mesh, p: DVec3) -> bool {
    let direction = DVec3::new(0.5773, 0.6131, 0.5394).normalize();
    let corner = |i: u32| {
        let [x, y, z] = mesh.positions.get(i as usize).copied().unwrap_or_default();
        DVec3::new(f64::from(x), f64::from(y), f64::from(z))
    };
    let crossings = mesh
        .triangles
        .iter()
        .filter(|&&[a, b, c]| crosses(p, direction, corner(a), corner(b), corner(c)))
        .count();
    crossings % 2 == 1
}

/// Whether the ray `origin + t·direction`, t > 0, passes through the triangle (Möller and
/// Trumbore).
fn crosses(origin: DVec3, direction: DVec3, a: DVec3, b: DVec3, c: DVec3) -> bool {
    let (e1, e2) = (b - a, c - a);
    let pvec = direction.cross(e2);
    let det = e1.dot(pvec);
    if det.abs() < 1e-300 {
        return false;
    }
    let tvec = origin - a;
    let u = tvec.dot(pvec) / det;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qvec = tvec.cross(e1);
    let v = direction.dot(qvec) / det;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    e2.dot(qvec) / det > 0.0
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
        let scene = Scene::default();
        let sphere = Shape::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
        };
        assert_eq!(
            shape_contains(&scene, &sphere, DVec3::new(0.5, 0.0, 0.0)),
            Some(true)
        );
        assert_eq!(
            shape_contains(&scene, &sphere, DVec3::new(1.5, 0.0, 0.0)),
            Some(false)
        );
        let tube = Shape::Cylinder {
            base: DVec3::ZERO,
            apex: DVec3::Y * 2.0,
            radius: 1.0,
            capped: true,
        };
        assert_eq!(
            shape_contains(&scene, &tube, DVec3::new(0.5, 1.0, 0.0)),
            Some(true)
        );
        assert_eq!(
            shape_contains(&scene, &tube, DVec3::new(0.5, 2.5, 0.0)),
            Some(false)
        );
        let open = Shape::Cylinder {
            base: DVec3::ZERO,
            apex: DVec3::Y,
            radius: 1.0,
            capped: false,
        };
        assert_eq!(shape_contains(&scene, &open, DVec3::ZERO), None);
        let torus = Shape::Torus {
            major: 2.0,
            minor: 0.5,
        };
        assert_eq!(
            shape_contains(&scene, &torus, DVec3::new(2.0, 0.0, 0.0)),
            Some(true)
        );
        assert_eq!(shape_contains(&scene, &torus, DVec3::ZERO), Some(false));
    }

    /// A unit cube as a closed mesh: points inside and outside, including ones level with
    /// its vertices and edges (where a ray along an axis would graze them); an open mesh
    /// (one face missing) has no inside.
    #[test]
    fn a_closed_mesh_knows_its_inside() {
        let positions: Vec<[f32; 3]> = (0..8)
            .map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
            .collect();
        let faces: Vec<[u32; 3]> = vec![
            [0, 2, 1],
            [1, 2, 3],
            [4, 5, 6],
            [5, 7, 6],
            [0, 1, 4],
            [1, 5, 4],
            [2, 6, 3],
            [3, 6, 7],
            [0, 4, 2],
            [2, 4, 6],
            [1, 3, 5],
            [3, 7, 5],
        ];
        let mut scene = Scene::default();
        let closed =
            whitted_ir::Mesh::new("cube".into(), positions.clone(), Vec::new(), faces.clone());
        assert!(closed.solid);
        let open = whitted_ir::Mesh::new("open".into(), positions, Vec::new(), faces[2..].to_vec());
        let closed = scene.meshes.append(closed, whitted_ir::Span::detached());
        let open = scene.meshes.append(open, whitted_ir::Span::detached());
        let cube = Shape::Mesh {
            mesh: closed,
            smooth: false,
        };
        for inside in [
            DVec3::splat(0.5),
            DVec3::new(0.01, 0.5, 0.99),
            DVec3::new(0.5, 0.0001, 0.5),
        ] {
            assert_eq!(
                shape_contains(&scene, &cube, inside),
                Some(true),
                "{inside}"
            );
        }
        for outside in [
            DVec3::splat(1.5),
            DVec3::new(-0.5, 0.5, 0.5),
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::new(0.5, 1.0001, 0.5),
        ] {
            assert_eq!(
                shape_contains(&scene, &cube, outside),
                Some(false),
                "{outside}"
            );
        }
        let open = Shape::Mesh {
            mesh: open,
            smooth: false,
        };
        assert_eq!(shape_contains(&scene, &open, DVec3::splat(0.5)), None);
    }
}
