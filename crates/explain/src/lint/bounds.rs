//! World-space bounding boxes of the IR's objects, for the linter's cheap tests (is an
//! object in view, could a point lie on its surface). Computed from the IR's shape
//! parameters and `world_from_object`; unbounded shapes (planes, quadrics) have none.

use glam::{DMat4, DVec3};
use whitted_ir::{CsgOp, Handle, Object, ObjectKind, Scene, Shape};

/// An axis-aligned box in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    pub min: DVec3,
    pub max: DVec3,
}

impl Bounds {
    fn around(points: impl IntoIterator<Item = DVec3>) -> Option<Bounds> {
        let mut points = points.into_iter();
        let first = points.next()?;
        let (min, max) = points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)));
        Some(Bounds { min, max })
    }

    fn union(self, other: Bounds) -> Bounds {
        Bounds {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    fn intersection(self, other: Bounds) -> Bounds {
        Bounds {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        }
    }

    /// The eight corners.
    pub fn corners(&self) -> [DVec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            DVec3::new(a.x, a.y, a.z),
            DVec3::new(b.x, a.y, a.z),
            DVec3::new(a.x, b.y, a.z),
            DVec3::new(b.x, b.y, a.z),
            DVec3::new(a.x, a.y, b.z),
            DVec3::new(b.x, a.y, b.z),
            DVec3::new(a.x, b.y, b.z),
            DVec3::new(b.x, b.y, b.z),
        ]
    }

    /// Whether `p` is within `margin` of the box.
    pub fn contains(&self, p: DVec3, margin: f64) -> bool {
        p.cmpge(self.min - margin).all() && p.cmple(self.max + margin).all()
    }
}

/// The world bounds of `handle`, `None` when it is unbounded (a plane, a quadric, or a CSG
/// node or group that needs one).
pub fn world_bounds(scene: &Scene, handle: Handle<Object>) -> Option<Bounds> {
    let object = scene.objects.get(handle)?;
    match &object.kind {
        ObjectKind::Shape { shape } => shape_bounds(scene, &shape.get(), &object.world_from_object),
        ObjectKind::Csg { op, children } => {
            let mut boxes = children.iter().map(|&c| world_bounds(scene, c));
            match op {
                // An intersection lies within each bounded child.
                CsgOp::Intersection => boxes.flatten().reduce(Bounds::intersection),
                // A difference lies within its first child.
                CsgOp::Difference => boxes.next().flatten(),
                CsgOp::Union => boxes.try_fold(None, |acc: Option<Bounds>, b| {
                    let b = b?;
                    Some(Some(acc.map_or(b, |a| a.union(b))))
                })?,
            }
        }
        ObjectKind::Group { children } => children.iter().try_fold(None, |acc, &c| {
            let b = world_bounds(scene, c)?;
            Some(Some(acc.map_or(b, |a: Bounds| a.union(b))))
        })?,
    }
}

fn shape_bounds(scene: &Scene, shape: &Shape, world_from_object: &DMat4) -> Option<Bounds> {
    if let Shape::Sphere { center, radius } = *shape {
        // A transformed sphere's exact box, from one transformed point: along world axis
        // i it reaches `radius × |row i of the linear part|` from its centre (the common
        // case of a scene of a million spheres, eight times cheaper than eight corners).
        let centre = world_from_object.transform_point3(center);
        let linear = world_from_object.transpose();
        let reach = DVec3::new(
            linear.x_axis.truncate().length(),
            linear.y_axis.truncate().length(),
            linear.z_axis.truncate().length(),
        ) * radius;
        return Some(Bounds {
            min: centre - reach,
            max: centre + reach,
        });
    }
    let local = match *shape {
        Shape::Sphere { center, radius } => Bounds {
            min: center - radius,
            max: center + radius,
        },
        Shape::Box { min, max } => Bounds { min, max },
        Shape::Cylinder {
            base, apex, radius, ..
        } => Bounds::around([base, apex])?.grown(radius),
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            ..
        } => Bounds::around([base, apex])?.grown(base_radius.max(apex_radius)),
        Shape::Disk { center, radius, .. } => Bounds {
            min: center - radius,
            max: center + radius,
        },
        Shape::Triangle { a, b, c } => Bounds::around([a, b, c])?,
        Shape::Mesh { mesh, .. } => {
            let (min, max) = scene.meshes.get(mesh)?.bounds()?;
            Bounds { min, max }
        }
        Shape::Torus { major, minor } => {
            let r = major + minor;
            Bounds {
                min: DVec3::new(-r, -minor, -r),
                max: DVec3::new(r, minor, r),
            }
        }
        Shape::Plane { .. } | Shape::Quadric { .. } => return None,
    };
    Bounds::around(
        local
            .corners()
            .map(|corner| world_from_object.transform_point3(corner)),
    )
}

impl Bounds {
    fn grown(self, by: f64) -> Bounds {
        Bounds {
            min: self.min - by,
            max: self.max + by,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_moved_sphere_and_a_plane() {
        let sphere = Shape::Sphere {
            center: DVec3::ZERO,
            radius: 2.0,
        };
        let moved = DMat4::from_translation(DVec3::new(10.0, 0.0, 0.0));
        let b = shape_bounds(&Scene::default(), &sphere, &moved).unwrap();
        assert_eq!(b.min, DVec3::new(8.0, -2.0, -2.0));
        assert_eq!(b.max, DVec3::new(12.0, 2.0, 2.0));
        // A sphere squashed along y and turned 90 degrees about z lies flat along x.
        let squashed = DMat4::from_rotation_z(std::f64::consts::FRAC_PI_2)
            * DMat4::from_scale(DVec3::new(1.0, 3.0, 1.0));
        let b = shape_bounds(&Scene::default(), &sphere, &squashed).unwrap();
        assert!(
            (b.max - DVec3::new(6.0, 2.0, 2.0)).abs().max_element() < 1e-9,
            "{b:?}"
        );
        assert!(
            (b.min + DVec3::new(6.0, 2.0, 2.0)).abs().max_element() < 1e-9,
            "{b:?}"
        );
        let plane = Shape::Plane {
            normal: DVec3::Y,
            offset: 0.0,
        };
        assert_eq!(
            shape_bounds(&Scene::default(), &plane, &DMat4::IDENTITY),
            None
        );
    }
}
