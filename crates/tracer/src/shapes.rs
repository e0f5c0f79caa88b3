//! Leaf shapes: where a ray crosses them, the spans along the ray inside a solid (for CSG),
//! outward normals, and bounds, for every `whitted_ir::Shape`.
//!
//! Shapes that an affine transform keeps in their family are stored directly in world space:
//! planes and triangles always, spheres and disks when the transform is a similarity.
//! Everything else is a canonical shape (unit sphere, cube `[-1, 1]³`, unit cylinder and
//! cone along `z ∈ [0, 1]`, unit disk) reached through `canonical_from_world`; its normals
//! go back through the inverse transpose, so non-uniform scale shades correctly. General
//! quadrics are transformed into world space once (`S_world = M⁻ᵀ S M⁻¹`) and solved in f64.

use glam::{DAffine3, DMat3, DMat4, DVec3, DVec4, Mat3A, Vec3, Vec3A, Vec4};
use whitted_ir::{Quadric, Shape};

use crate::hit_error::{self, BoundedPoint};
use crate::mesh::MeshInstance;
use crate::solve::{quadratic_f32, quadratic_f64};
use whitted_bvh::Bound;
use whitted_bvh::Ray;

/// Which part of a shape a boundary lies on, so that the normal is computed for the right
/// face even at an edge: cylinder and cone walls and caps, box faces `axis·2 + side`, and
/// a mesh's triangle index.
pub type Part = u32;
const WALL: Part = 0;
const BASE_CAP: Part = 1;
const APEX_CAP: Part = 2;

/// One interval of the ray parameter inside a solid, with the parts it enters and leaves by.
/// Either end may be infinite (a plane's half-space, a hyperboloid).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RawSpan {
    pub t_in: f32,
    pub part_in: Part,
    pub t_out: f32,
    pub part_out: Part,
}

/// The spans of one leaf solid, ascending and disjoint: at most two (a quadric can be
/// inside on both sides of its roots).
#[derive(Clone, Copy, Debug)]
pub struct ShapeSpans {
    len: u8,
    spans: [RawSpan; 2],
}

const NO_SPAN: RawSpan = RawSpan {
    t_in: 0.0,
    part_in: 0,
    t_out: 0.0,
    part_out: 0,
};

impl ShapeSpans {
    pub const NONE: ShapeSpans = ShapeSpans {
        len: 0,
        spans: [NO_SPAN; 2],
    };

    fn one(t_in: f32, part_in: Part, t_out: f32, part_out: Part) -> ShapeSpans {
        ShapeSpans {
            len: 1,
            spans: [
                RawSpan {
                    t_in,
                    part_in,
                    t_out,
                    part_out,
                },
                NO_SPAN,
            ],
        }
    }

    fn whole_line() -> ShapeSpans {
        ShapeSpans::one(f32::NEG_INFINITY, WALL, f32::INFINITY, WALL)
    }

    pub fn as_slice(&self) -> &[RawSpan] {
        &self.spans[..self.len as usize]
    }

    /// The first boundary strictly inside `(tmin, tmax)`.
    #[inline]
    pub fn first_boundary(&self, tmin: f32, tmax: f32) -> Option<(f32, Part)> {
        for span in self.as_slice() {
            if span.t_in > tmin {
                return (span.t_in < tmax).then_some((span.t_in, span.part_in));
            }
            if span.t_out > tmin {
                return (span.t_out < tmax).then_some((span.t_out, span.part_out));
            }
        }
        None
    }
}

/// A canonical shape in its own space, reached from world space by an affine map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Canonical {
    /// The unit sphere at the origin.
    Sphere,
    /// The cube `[-1, 1]³`.
    Cube,
    /// `x² + y² = 1` for `z ∈ [0, 1]`, with or without its end caps.
    Cylinder { capped: bool },
    /// Radius `r0 + (r1 − r0)·z` for `z ∈ [0, 1]`; the larger radius is 1.
    Cone { r0: f32, r1: f32, capped: bool },
    /// The unit disk in the plane `z = 0`, facing +z.
    Disk,
    /// The torus of major radius 1 around the y axis, tube radius `minor` (see `torus.rs`).
    Torus { minor: f32 },
}

#[derive(Clone, Debug, PartialEq)]
pub struct LocalGeometry {
    canonical_from_world: glam::Affine3A,
    /// The inverse of `canonical_from_world`: a hit point placed on the canonical surface
    /// goes back to world space through it, with its error bound.
    world_from_canonical: glam::Affine3A,
    /// The transpose of `canonical_from_world`'s linear part: the inverse transpose of
    /// `world_from_canonical`, which carries normals correctly under non-uniform scale.
    normal_from_canonical: Mat3A,
    shape: Canonical,
}

/// A quadric in world space: `Pᵀ·S·P = 0` for homogeneous points `P = (x, y, z, 1)`.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldQuadric {
    matrix: DMat4,
}

#[derive(Clone, Debug, PartialEq)]
pub struct WorldDisk {
    pub center: Vec3A,
    pub normal: Vec3A,
    pub radius: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct WorldTriangle {
    pub a: Vec3A,
    pub edge1: Vec3A,
    pub edge2: Vec3A,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// The centre as a `Vec3` (read with the radius as one `Vec3A`, [`with_fourth`]): with
    /// the tag in the spare room, the common shapes keep a `Geometry` at 24 bytes and a
    /// leaf at 32 (a `Vec3A` would align it to 16 and make both larger).
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// `normal·p = offset` with a unit normal; the solid is `normal·p < offset`.
    Plane {
        normal: Vec3,
        offset: f32,
    },
    /// Boxed, like the rarer shapes, so that the common ones keep leaves small.
    Disk(Box<WorldDisk>),
    Triangle(Box<WorldTriangle>),
    Quadric(Box<WorldQuadric>),
    Local(Box<LocalGeometry>),
    Mesh(Box<MeshInstance>),
}

impl Geometry {
    /// Prepares an IR shape under its `world_from_object` transform, with its world bound.
    pub fn new(shape: &Shape, world_from_object: &DAffine3) -> (Geometry, Bound) {
        let m = world_from_object;
        match shape {
            Shape::Sphere { center, radius } => match uniform_scale(m) {
                Some(scale) => {
                    let c = m.transform_point3(*center);
                    let r = radius * scale;
                    let bound = Bound::from_f64(c - DVec3::splat(r), c + DVec3::splat(r));
                    let geometry = Geometry::Sphere {
                        center: c.as_vec3(),
                        radius: r as f32,
                    };
                    (geometry, bound)
                }
                None => {
                    let world_from_canonical = *m
                        * DAffine3::from_scale_rotation_translation(
                            DVec3::splat(*radius),
                            glam::DQuat::IDENTITY,
                            *center,
                        );
                    (
                        Geometry::local(&world_from_canonical, Canonical::Sphere),
                        ellipsoid_bound(&world_from_canonical),
                    )
                }
            },
            Shape::Plane { normal, offset } => {
                let point = *normal * (*offset / normal.length_squared());
                let world_normal = (normal_matrix(m) * *normal).normalize();
                let world_point = m.transform_point3(point);
                let geometry = Geometry::Plane {
                    normal: world_normal.as_vec3(),
                    offset: world_normal.dot(world_point) as f32,
                };
                (geometry, Bound::Infinite)
            }
            Shape::Box { min, max } => {
                let world_from_canonical = *m
                    * DAffine3::from_scale_rotation_translation(
                        (*max - *min) * 0.5,
                        glam::DQuat::IDENTITY,
                        (*max + *min) * 0.5,
                    );
                (
                    Geometry::local(&world_from_canonical, Canonical::Cube),
                    Bound::transformed_box(&world_from_canonical, -DVec3::ONE, DVec3::ONE),
                )
            }
            Shape::Cylinder {
                base,
                apex,
                radius,
                capped,
            } => {
                let world_from_canonical = *m * axis_frame(*base, *apex, *radius);
                (
                    Geometry::local(
                        &world_from_canonical,
                        Canonical::Cylinder { capped: *capped },
                    ),
                    Bound::transformed_box(
                        &world_from_canonical,
                        DVec3::new(-1.0, -1.0, 0.0),
                        DVec3::ONE,
                    ),
                )
            }
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
                capped,
            } => {
                let largest = base_radius.max(*apex_radius);
                let world_from_canonical = *m * axis_frame(*base, *apex, largest);
                let shape = Canonical::Cone {
                    r0: (base_radius / largest) as f32,
                    r1: (apex_radius / largest) as f32,
                    capped: *capped,
                };
                (
                    Geometry::local(&world_from_canonical, shape),
                    Bound::transformed_box(
                        &world_from_canonical,
                        DVec3::new(-1.0, -1.0, 0.0),
                        DVec3::ONE,
                    ),
                )
            }
            Shape::Disk {
                center,
                normal,
                radius,
            } => {
                let unit_normal = normal.normalize();
                match uniform_scale(m) {
                    Some(scale) => {
                        let c = m.transform_point3(*center);
                        let n = (normal_matrix(m) * unit_normal).normalize();
                        let r = radius * scale;
                        // The disk's extent along each axis is r·√(1 − nᵢ²).
                        let extent = (DVec3::ONE - n * n).max(DVec3::ZERO).map(f64::sqrt) * r;
                        let geometry = Geometry::Disk(Box::new(WorldDisk {
                            center: c.as_vec3a(),
                            normal: n.as_vec3a(),
                            radius: r as f32,
                        }));
                        (geometry, Bound::from_f64(c - extent, c + extent))
                    }
                    None => {
                        let (u, v) = unit_normal.any_orthonormal_pair();
                        let frame =
                            DAffine3::from_cols(u * *radius, v * *radius, unit_normal, *center);
                        let world_from_canonical = *m * frame;
                        (
                            Geometry::local(&world_from_canonical, Canonical::Disk),
                            Bound::transformed_box(
                                &world_from_canonical,
                                DVec3::new(-1.0, -1.0, 0.0),
                                DVec3::new(1.0, 1.0, 0.0),
                            ),
                        )
                    }
                }
            }
            Shape::Triangle { a, b, c } => {
                let (a, b, c) = (
                    m.transform_point3(*a),
                    m.transform_point3(*b),
                    m.transform_point3(*c),
                );
                let geometry = Geometry::Triangle(Box::new(WorldTriangle {
                    a: a.as_vec3a(),
                    edge1: (b - a).as_vec3a(),
                    edge2: (c - a).as_vec3a(),
                }));
                (geometry, Bound::from_f64(a.min(b).min(c), a.max(b).max(c)))
            }
            Shape::Torus { major, minor } => {
                let world_from_canonical = *m * DAffine3::from_scale(DVec3::splat(*major));
                let r = minor / major;
                let extent = DVec3::new(1.0 + r, r, 1.0 + r);
                (
                    Geometry::local(&world_from_canonical, Canonical::Torus { minor: r as f32 }),
                    Bound::transformed_box(&world_from_canonical, -extent, extent),
                )
            }
            // Meshes need the scene's prepared meshes: `MeshInstance::new` makes them. Reached
            // only by a mesh missing from the scene, which validation refuses: nothing.
            Shape::Mesh { .. } => (
                Geometry::Plane {
                    normal: Vec3::Y,
                    offset: 0.0,
                },
                Bound::Empty,
            ),
            Shape::Quadric { quadric, .. } => {
                let object_matrix = quadric_matrix(quadric);
                let object_from_world = DMat4::from(m.inverse());
                let matrix = object_from_world.transpose() * object_matrix * object_from_world;
                let bound = match quadric_object_box(quadric) {
                    QuadricExtent::Empty => Bound::Empty,
                    QuadricExtent::Unbounded => Bound::Infinite,
                    QuadricExtent::Box(min, max) => Bound::transformed_box(m, min, max),
                };
                (Geometry::Quadric(Box::new(WorldQuadric { matrix })), bound)
            }
        }
    }

    fn local(world_from_canonical: &DAffine3, shape: Canonical) -> Geometry {
        let canonical_from_world = world_from_canonical.inverse();
        Geometry::Local(Box::new(LocalGeometry {
            canonical_from_world: canonical_from_world.as_affine3a(),
            world_from_canonical: world_from_canonical.as_affine3a(),
            normal_from_canonical: Mat3A::from(canonical_from_world.matrix3.transpose().as_mat3()),
            shape,
        }))
    }

    /// Whether the shape encloses a volume (CSG and refraction need an inside).
    pub fn is_solid(&self) -> bool {
        match self {
            Geometry::Disk(_) | Geometry::Triangle(_) => false,
            Geometry::Mesh(mesh) => mesh.is_solid(),
            Geometry::Local(local) => match local.shape {
                Canonical::Disk => false,
                Canonical::Cylinder { capped } | Canonical::Cone { capped, .. } => capped,
                Canonical::Sphere | Canonical::Cube | Canonical::Torus { .. } => true,
            },
            Geometry::Sphere { .. } | Geometry::Plane { .. } | Geometry::Quadric(_) => true,
        }
    }

    /// The nearest crossing of the surface strictly inside `(tmin, tmax)`: the cheap test.
    #[inline]
    pub fn first_hit(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<(f32, Part)> {
        match self {
            Geometry::Sphere { center, radius } => {
                sphere_first_hit(ray, with_fourth(*center, *radius), *radius, tmin, tmax)
                    .map(|t| (t, WALL))
            }
            Geometry::Plane { normal, offset } => {
                plane_first_hit(ray, with_fourth(*normal, *offset), *offset, tmin, tmax)
                    .map(|t| (t, WALL))
            }
            Geometry::Disk(disk) => {
                let t =
                    (disk.center - ray.origin).dot(disk.normal) / ray.direction.dot(disk.normal);
                if !(t > tmin && t < tmax) {
                    return None;
                }
                let from_center = ray.at(t) - disk.center;
                (from_center.length_squared() <= disk.radius * disk.radius).then_some((t, WALL))
            }
            Geometry::Triangle(triangle) => {
                let t = triangle_hit(ray, triangle.a, triangle.edge1, triangle.edge2)?;
                (t > tmin && t < tmax).then_some((t, WALL))
            }
            Geometry::Quadric(_) => self.spans(ray).first_boundary(tmin, tmax),
            Geometry::Mesh(mesh) => mesh.first_hit(ray, tmin, tmax),
            Geometry::Local(local) => {
                let o = local.canonical_from_world.transform_point3a(ray.origin);
                let d = local.canonical_from_world.transform_vector3a(ray.direction);
                match local.shape {
                    Canonical::Disk => {
                        let t = -o.z / d.z;
                        if !(t > tmin && t < tmax) {
                            return None;
                        }
                        let p = o + t * d;
                        (p.x * p.x + p.y * p.y <= 1.0).then_some((t, WALL))
                    }
                    Canonical::Cylinder { capped: false } => {
                        let (t0, t1) = cylinder_wall_roots(o, d)?;
                        first_within_height(o, d, [t0, t1], tmin, tmax)
                    }
                    Canonical::Cone {
                        r0,
                        r1,
                        capped: false,
                    } => {
                        let (t0, t1) = cone_wall_roots(o, d, r0, r1)?;
                        first_within_height(o, d, [t0, t1], tmin, tmax)
                    }
                    _ => canonical_spans(local.shape, o, d).first_boundary(tmin, tmax),
                }
            }
        }
    }

    /// The spans of the ray parameter (over the whole line) inside a solid. Only meaningful
    /// for solids; surfaces without an inside have none.
    pub fn spans(&self, ray: &Ray) -> ShapeSpans {
        match self {
            Geometry::Sphere { center, radius } => {
                match sphere_roots(ray, with_fourth(*center, *radius), *radius) {
                    Some((t0, t1)) => ShapeSpans::one(t0, WALL, t1, WALL),
                    None => ShapeSpans::NONE,
                }
            }
            Geometry::Plane { normal, offset } => {
                let normal = with_fourth(*normal, *offset);
                let depth = offset - normal.dot(ray.origin);
                let rate = normal.dot(ray.direction);
                if rate == 0.0 {
                    return if depth > 0.0 {
                        ShapeSpans::whole_line()
                    } else {
                        ShapeSpans::NONE
                    };
                }
                let t = depth / rate;
                if rate > 0.0 {
                    ShapeSpans::one(f32::NEG_INFINITY, WALL, t, WALL)
                } else {
                    ShapeSpans::one(t, WALL, f32::INFINITY, WALL)
                }
            }
            Geometry::Quadric(quadric) => quadric.spans(ray),
            Geometry::Local(local) => {
                if !self.is_solid() {
                    return ShapeSpans::NONE;
                }
                let o = local.canonical_from_world.transform_point3a(ray.origin);
                let d = local.canonical_from_world.transform_vector3a(ray.direction);
                canonical_spans(local.shape, o, d)
            }
            // A mesh may have any number of spans: CSG asks it directly
            // (`MeshInstance::push_spans`).
            Geometry::Disk(_) | Geometry::Triangle(_) | Geometry::Mesh(_) => ShapeSpans::NONE,
        }
    }

    /// The outward unit normal where the ray meets the surface at `t`, on `part`.
    pub fn normal(&self, ray: &Ray, t: f32, part: Part) -> Vec3A {
        let n = match self {
            Geometry::Sphere { center, radius } => ray.at(t) - with_fourth(*center, *radius),
            Geometry::Plane { normal, offset } => with_fourth(*normal, *offset),
            Geometry::Disk(disk) => disk.normal,
            Geometry::Triangle(triangle) => triangle.edge1.cross(triangle.edge2),
            Geometry::Quadric(quadric) => quadric.gradient(ray, t),
            Geometry::Mesh(mesh) => mesh.geometric_normal(part),
            Geometry::Local(local) => {
                let o = local.canonical_from_world.transform_point3a(ray.origin);
                let d = local.canonical_from_world.transform_vector3a(ray.direction);
                let p = o + t * d;
                let n = canonical_normal(local.shape, p, part);
                local.normal_from_canonical * n
            }
        };
        unit_normal(n, ray)
    }
}

impl Geometry {
    /// The hit point at `t` on `part`, placed on the surface where the shape allows it,
    /// with its error bound (`hit_error.rs`). Spheres and planes, the common case, are
    /// handled inline by `PreparedScene::surface`.
    pub fn bounded_point(&self, ray: &Ray, t: f32, part: Part) -> BoundedPoint {
        match self {
            Geometry::Sphere { center, radius } => {
                hit_error::on_sphere(with_fourth(*center, *radius), *radius, ray.at(t)).0
            }
            Geometry::Plane { normal, offset } => {
                hit_error::on_plane(with_fourth(*normal, *offset), *offset, ray.at(t))
            }
            Geometry::Disk(disk) => {
                hit_error::on_plane(disk.normal, disk.normal.dot(disk.center), ray.at(t))
            }
            Geometry::Triangle(tri) => match triangle_hit_uv(ray, tri.a, tri.edge1, tri.edge2) {
                Some(uv) => hit_error::on_triangle(tri.a, tri.edge1, tri.edge2, uv),
                None => hit_error::along_ray(ray.origin, ray.direction, t),
            },
            Geometry::Quadric(quadric) => hit_error::on_quadric(&quadric.matrix, ray.at(t)),
            Geometry::Mesh(mesh) => mesh.bounded_point(ray, t, part),
            Geometry::Local(local) => {
                let o = local.canonical_from_world.transform_point3a(ray.origin);
                let d = local.canonical_from_world.transform_vector3a(ray.direction);
                match on_canonical(local.shape, o + t * d, part) {
                    Some(canonical) => {
                        hit_error::transformed(&local.world_from_canonical, canonical)
                    }
                    None => hit_error::along_ray(ray.origin, ray.direction, t),
                }
            }
        }
    }
}

/// A canonical shape's point moved onto its surface (`part` names the face), with the
/// rounding of that move as its bound; `None` for the torus, whose quartic has no cheap
/// projection.
fn on_canonical(shape: Canonical, p: Vec3A, part: Part) -> Option<BoundedPoint> {
    let radial = |p: Vec3A, radius: f32| {
        let length = (p.x * p.x + p.y * p.y).sqrt();
        if length > 0.0 && radius > 0.0 {
            let k = radius / length;
            Vec3A::new(p.x * k, p.y * k, p.z)
        } else {
            p
        }
    };
    let point = match shape {
        Canonical::Sphere => {
            let length = p.length();
            if length > 0.0 {
                p / length
            } else {
                p
            }
        }
        Canonical::Cube => {
            let mut q = p;
            q[(part / 2) as usize] = if part % 2 == 1 { 1.0 } else { -1.0 };
            q
        }
        Canonical::Disk => Vec3A::new(p.x, p.y, 0.0),
        Canonical::Cylinder { .. } | Canonical::Cone { .. } if part == BASE_CAP => {
            Vec3A::new(p.x, p.y, 0.0)
        }
        Canonical::Cylinder { .. } | Canonical::Cone { .. } if part == APEX_CAP => {
            Vec3A::new(p.x, p.y, 1.0)
        }
        Canonical::Cylinder { .. } => radial(p, 1.0),
        Canonical::Cone { r0, r1, .. } => radial(p, r0 + (r1 - r0) * p.z),
        Canonical::Torus { .. } => return None,
    };
    Some(BoundedPoint {
        point,
        error: hit_error::gamma(6) * point.abs(),
    })
}

impl Geometry {
    /// The unit normal that shading uses where it differs from the geometric one (a smooth
    /// mesh's interpolated vertex normal), on the same side of the surface as
    /// [`Geometry::normal`]; `None` where they are the same.
    pub fn shading_normal(&self, ray: &Ray, part: Part, geometric: Vec3A) -> Option<Vec3A> {
        let Geometry::Mesh(mesh) = self else {
            return None;
        };
        let n = mesh.shading_normal(ray, part)?.normalize_or_zero();
        if n == Vec3A::ZERO {
            return None;
        }
        // A vertex normal may lean past the face at a sharp crease: keep it on the face's
        // side, where entering and leaving are decided.
        Some(if n.dot(geometric) < 0.0 { -n } else { n })
    }
}

/// `n` made unit length; at a singular point (a cone's tip, where `n` is zero) the normal
/// faces the ray, the only sensible choice.
#[inline(always)]
pub fn unit_normal(n: Vec3A, ray: &Ray) -> Vec3A {
    let unit = n.normalize_or_zero();
    if unit == Vec3A::ZERO {
        -ray.direction
    } else {
        unit
    }
}

impl WorldQuadric {
    fn spans(&self, ray: &Ray) -> ShapeSpans {
        let o = DVec4::from((ray.origin.as_dvec3(), 1.0));
        let d = DVec4::from((ray.direction.as_dvec3(), 0.0));
        let so = self.matrix * o;
        let a = d.dot(self.matrix * d);
        let h = d.dot(so);
        let c = o.dot(so);
        let to_f32 = |t: f64| t as f32;
        match quadratic_f64(a, h, c) {
            None => {
                // No crossing: the line is all inside or all outside, as the sign shows.
                let inside = if a != 0.0 { a < 0.0 } else { c < 0.0 };
                if inside {
                    ShapeSpans::whole_line()
                } else {
                    ShapeSpans::NONE
                }
            }
            Some((r1, r2)) => {
                let (t1, t2) = (to_f32(r1), to_f32(r2));
                if a > 0.0 {
                    ShapeSpans::one(t1, WALL, t2, WALL)
                } else if a < 0.0 {
                    ShapeSpans {
                        len: 2,
                        spans: [
                            RawSpan {
                                t_in: f32::NEG_INFINITY,
                                part_in: WALL,
                                t_out: t1,
                                part_out: WALL,
                            },
                            RawSpan {
                                t_in: t2,
                                part_in: WALL,
                                t_out: f32::INFINITY,
                                part_out: WALL,
                            },
                        ],
                    }
                } else {
                    // Linear along this ray: 2h·t + c < 0 on one side of the finite root.
                    let root = if t1.is_finite() { t1 } else { t2 };
                    if h > 0.0 {
                        ShapeSpans::one(f32::NEG_INFINITY, WALL, root, WALL)
                    } else {
                        ShapeSpans::one(root, WALL, f32::INFINITY, WALL)
                    }
                }
            }
        }
    }

    fn gradient(&self, ray: &Ray, t: f32) -> Vec3A {
        let p = ray.origin.as_dvec3() + f64::from(t) * ray.direction.as_dvec3();
        let g = self.matrix * DVec4::from((p, 1.0));
        g.truncate().as_vec3a()
    }
}

/// The nearest sphere crossing in `(tmin, tmax)`: the hot path of sphere scenes, with the
/// cheap rejections first (outside and moving away; missing the sphere) before the root.
#[inline(always)]
pub fn sphere_first_hit(
    ray: &Ray,
    center: Vec3A,
    radius: f32,
    tmin: f32,
    tmax: f32,
) -> Option<f32> {
    let f = ray.origin - center;
    let h = f.dot(ray.direction);
    let r2 = radius * radius;
    let c = f.length_squared() - r2;
    if c > 0.0 && h > 0.0 && tmin >= 0.0 {
        // Both roots are behind the origin (their product c is positive, their sum −2h
        // negative).
        return None;
    }
    let perpendicular = f - h * ray.direction;
    let discriminant = r2 - perpendicular.length_squared();
    if discriminant < 0.0 {
        return None;
    }
    let (t0, t1) = quadratic_f32(1.0, h, c, discriminant)?;
    if t0 > tmin {
        (t0 < tmax).then_some(t0)
    } else {
        (t1 > tmin && t1 < tmax).then_some(t1)
    }
}

/// The crossing of a plane in `(tmin, tmax)`; planes are tested by every ray of a scene
/// that has a floor, so this is kept small enough to inline.
#[inline(always)]
pub fn plane_first_hit(ray: &Ray, normal: Vec3A, offset: f32, tmin: f32, tmax: f32) -> Option<f32> {
    let depth = offset - normal.dot(ray.origin);
    let rate = normal.dot(ray.direction);
    // Behind the origin, parallel, or NaN: no division needed to say so.
    if depth * rate <= 0.0 || (depth * rate).is_nan() {
        return None;
    }
    let t = depth / rate;
    (t > tmin && t < tmax).then_some(t)
}

/// Sphere roots with the robust discriminant of Ray Tracing Gems, ch. 7: `r² − |f − (f·d)d|²`
/// instead of `(f·d)² − (|f|² − r²)`, which cancels catastrophically for distant spheres.
#[inline]
fn sphere_roots(ray: &Ray, center: Vec3A, radius: f32) -> Option<(f32, f32)> {
    let f = ray.origin - center;
    let h = f.dot(ray.direction);
    let perpendicular = f - h * ray.direction;
    let discriminant = radius * radius - perpendicular.length_squared();
    let c = f.length_squared() - radius * radius;
    quadratic_f32(1.0, h, c, discriminant)
}

/// The barycentric `(u, v)` of the point where `ray` crosses the triangle (weights of the
/// second and third corners), by the same arithmetic as [`triangle_hit`].
pub(crate) fn triangle_hit_uv(
    ray: &Ray,
    a: Vec3A,
    edge1: Vec3A,
    edge2: Vec3A,
) -> Option<(f32, f32)> {
    let p = ray.direction.cross(edge2);
    let determinant = edge1.dot(p);
    if determinant == 0.0 {
        return None;
    }
    let inverse = 1.0 / determinant;
    let s = ray.origin - a;
    let u = s.dot(p) * inverse;
    let v = ray.direction.dot(s.cross(edge1)) * inverse;
    (u.is_finite() && v.is_finite()).then_some((u.clamp(0.0, 1.0), v.clamp(0.0, 1.0)))
}

#[inline(always)]
pub(crate) fn triangle_hit(ray: &Ray, a: Vec3A, edge1: Vec3A, edge2: Vec3A) -> Option<f32> {
    // Möller–Trumbore.
    let p = ray.direction.cross(edge2);
    let determinant = edge1.dot(p);
    if determinant == 0.0 {
        return None;
    }
    let inverse = 1.0 / determinant;
    let s = ray.origin - a;
    let u = s.dot(p) * inverse;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(edge1);
    let v = ray.direction.dot(q) * inverse;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(edge2.dot(q) * inverse)
}

/// Roots of the infinite unit cylinder `x² + y² = 1` along `o + t·d`.
fn cylinder_wall_roots(o: Vec3A, d: Vec3A) -> Option<(f32, f32)> {
    let a = d.x * d.x + d.y * d.y;
    if a == 0.0 {
        return None;
    }
    let h = o.x * d.x + o.y * d.y;
    let c = o.x * o.x + o.y * o.y - 1.0;
    // Robust discriminant: a·(1 − |o⊥ − (h/a)·d⊥|²).
    let s = h / a;
    let (lx, ly) = (o.x - s * d.x, o.y - s * d.y);
    quadratic_f32(a, h, c, a * (1.0 - (lx * lx + ly * ly)))
}

/// Roots of the infinite double cone `x² + y² = (r0 + (r1 − r0)·z)²`, solved in f64
/// because its discriminant cancels badly near the cone's silhouette.
fn cone_coefficients(o: Vec3A, d: Vec3A, r0: f32, r1: f32) -> (f64, f64, f64) {
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    let (r0, k) = (f64::from(r0), f64::from(r1) - f64::from(r0));
    let rz = r0 + k * o.z;
    let a = d.x * d.x + d.y * d.y - k * k * d.z * d.z;
    let h = o.x * d.x + o.y * d.y - k * d.z * rz;
    let c = o.x * o.x + o.y * o.y - rz * rz;
    (a, h, c)
}

fn cone_wall_roots(o: Vec3A, d: Vec3A, r0: f32, r1: f32) -> Option<(f32, f32)> {
    let (a, h, c) = cone_coefficients(o, d, r0, r1);
    quadratic_f64(a, h, c).map(|(t0, t1)| (t0 as f32, t1 as f32))
}

/// For open walls: the first root in the window whose point lies within `z ∈ [0, 1]`.
fn first_within_height(
    o: Vec3A,
    d: Vec3A,
    roots: [f32; 2],
    tmin: f32,
    tmax: f32,
) -> Option<(f32, Part)> {
    roots.into_iter().find_map(|t| {
        let z = o.z + t * d.z;
        (t > tmin && t < tmax && (0.0..=1.0).contains(&z)).then_some((t, WALL))
    })
}

/// The ray's interval between the planes `z = 0` and `z = 1`, with the cap parts.
fn height_slab(o: Vec3A, d: Vec3A) -> Option<(f32, Part, f32, Part)> {
    if d.z == 0.0 {
        return (0.0..=1.0).contains(&o.z).then_some((
            f32::NEG_INFINITY,
            WALL,
            f32::INFINITY,
            WALL,
        ));
    }
    let to_base = -o.z / d.z;
    let to_apex = (1.0 - o.z) / d.z;
    Some(if d.z > 0.0 {
        (to_base, BASE_CAP, to_apex, APEX_CAP)
    } else {
        (to_apex, APEX_CAP, to_base, BASE_CAP)
    })
}

/// Intersects `(t_in, t_out)` pieces, keeping the parts of whichever bound is tighter.
fn clip(a: (f32, Part, f32, Part), b: (f32, Part, f32, Part)) -> Option<(f32, Part, f32, Part)> {
    let (t_in, part_in) = if a.0 >= b.0 { (a.0, a.1) } else { (b.0, b.1) };
    let (t_out, part_out) = if a.2 <= b.2 { (a.2, a.3) } else { (b.2, b.3) };
    (t_in <= t_out).then_some((t_in, part_in, t_out, part_out))
}

fn canonical_spans(shape: Canonical, o: Vec3A, d: Vec3A) -> ShapeSpans {
    let one = |s: Option<(f32, Part, f32, Part)>| match s {
        Some((t_in, part_in, t_out, part_out)) => ShapeSpans::one(t_in, part_in, t_out, part_out),
        None => ShapeSpans::NONE,
    };
    match shape {
        Canonical::Sphere => {
            let a = d.length_squared();
            let h = o.dot(d);
            let c = o.length_squared() - 1.0;
            let perpendicular = o - (h / a) * d;
            let discriminant = a * (1.0 - perpendicular.length_squared());
            match quadratic_f32(a, h, c, discriminant) {
                Some((t0, t1)) => ShapeSpans::one(t0, WALL, t1, WALL),
                None => ShapeSpans::NONE,
            }
        }
        Canonical::Cube => one(cube_span(o, d)),
        Canonical::Cylinder { .. } => {
            let Some(slab) = height_slab(o, d) else {
                return ShapeSpans::NONE;
            };
            let radial = if d.x == 0.0 && d.y == 0.0 {
                if o.x * o.x + o.y * o.y > 1.0 {
                    return ShapeSpans::NONE;
                }
                (f32::NEG_INFINITY, WALL, f32::INFINITY, WALL)
            } else {
                match cylinder_wall_roots(o, d) {
                    Some((t0, t1)) => (t0, WALL, t1, WALL),
                    None => return ShapeSpans::NONE,
                }
            };
            one(clip(radial, slab))
        }
        Canonical::Cone { r0, r1, .. } => {
            let Some(slab) = height_slab(o, d) else {
                return ShapeSpans::NONE;
            };
            let (a, h, c) = cone_coefficients(o, d, r0, r1);
            let inf = f32::INFINITY;
            let mut pieces = [None, None];
            match quadratic_f64(a, h, c) {
                None => {
                    let inside = if a != 0.0 { a < 0.0 } else { c < 0.0 };
                    if inside {
                        pieces[0] = Some((-inf, WALL, inf, WALL));
                    }
                }
                Some((t0, t1)) => {
                    let (t0, t1) = (t0 as f32, t1 as f32);
                    if a > 0.0 {
                        pieces[0] = Some((t0, WALL, t1, WALL));
                    } else if a < 0.0 {
                        pieces[0] = Some((-inf, WALL, t0, WALL));
                        pieces[1] = Some((t1, WALL, inf, WALL));
                    } else {
                        let root = if t0.is_finite() { t0 } else { t1 };
                        pieces[0] = Some(if h > 0.0 {
                            (-inf, WALL, root, WALL)
                        } else {
                            (root, WALL, inf, WALL)
                        });
                    }
                }
            }
            // Within the slab the truncated cone is convex, so at most one piece survives;
            // should rounding keep both (at a pointed tip), their hull is the answer.
            let mut result: Option<(f32, Part, f32, Part)> = None;
            for piece in pieces.into_iter().flatten() {
                if let Some(clipped) = clip(piece, slab) {
                    result = Some(match result {
                        None => clipped,
                        Some(previous) => (previous.0, previous.1, clipped.2, clipped.3),
                    });
                }
            }
            one(result)
        }
        Canonical::Disk => ShapeSpans::NONE,
        Canonical::Torus { minor } => {
            let (spans, n) = crate::torus::spans(
                o.as_dvec3().to_array(),
                d.as_dvec3().to_array(),
                f64::from(minor),
            );
            let mut out = ShapeSpans::NONE;
            for &(t_in, t_out) in &spans[..n] {
                out.spans[out.len as usize] = RawSpan {
                    t_in: t_in as f32,
                    part_in: WALL,
                    t_out: t_out as f32,
                    part_out: WALL,
                };
                out.len += 1;
            }
            out
        }
    }
}

fn cube_span(o: Vec3A, d: Vec3A) -> Option<(f32, Part, f32, Part)> {
    let mut t_near = f32::NEG_INFINITY;
    let mut t_far = f32::INFINITY;
    let (mut near_part, mut far_part) = (0, 0);
    for axis in 0..3 {
        let (oi, di) = (o[axis], d[axis]);
        if di == 0.0 {
            if oi.abs() > 1.0 {
                return None;
            }
            continue;
        }
        let to_low = (-1.0 - oi) / di;
        let to_high = (1.0 - oi) / di;
        let side = axis as Part * 2;
        let (enter, enter_part, exit, exit_part) = if di > 0.0 {
            (to_low, side, to_high, side + 1)
        } else {
            (to_high, side + 1, to_low, side)
        };
        if enter > t_near {
            t_near = enter;
            near_part = enter_part;
        }
        if exit < t_far {
            t_far = exit;
            far_part = exit_part;
        }
    }
    (t_near <= t_far).then_some((t_near, near_part, t_far, far_part))
}

fn canonical_normal(shape: Canonical, p: Vec3A, part: Part) -> Vec3A {
    match shape {
        Canonical::Sphere => p,
        Canonical::Cube => {
            let axis = (part / 2) as usize;
            let mut n = Vec3A::ZERO;
            n[axis] = if part % 2 == 1 { 1.0 } else { -1.0 };
            n
        }
        Canonical::Disk => Vec3A::Z,
        Canonical::Torus { minor } => {
            let n = crate::torus::normal(p.as_dvec3().to_array(), f64::from(minor));
            Vec3A::new(n[0] as f32, n[1] as f32, n[2] as f32)
        }
        Canonical::Cylinder { .. } | Canonical::Cone { .. } if part == BASE_CAP => -Vec3A::Z,
        Canonical::Cylinder { .. } | Canonical::Cone { .. } if part == APEX_CAP => Vec3A::Z,
        Canonical::Cylinder { .. } => Vec3A::new(p.x, p.y, 0.0),
        Canonical::Cone { r0, r1, .. } => {
            let k = r1 - r0;
            Vec3A::new(p.x, p.y, -k * (r0 + k * p.z))
        }
    }
}

/// The scale factor when the linear part is a similarity (rotation, reflection and
/// uniform scale), in which case spheres and disks stay spheres and disks.
/// A stored `Vec3` and the number stored after it (a sphere's radius, a plane's offset) as
/// one `Vec3A`, the number in the fourth lane, which no `Vec3A` operation reads (glam's own
/// constructor fills it with `z`). The four floats lie together, so this is one unaligned
/// load, where building a `Vec3A` from the `Vec3` alone went lane by lane through memory
/// (+2% of the classic scene's instructions).
#[inline(always)]
pub(crate) fn with_fourth(v: Vec3, w: f32) -> Vec3A {
    Vec3A::from_vec4(Vec4::new(v.x, v.y, v.z, w))
}

fn uniform_scale(m: &DAffine3) -> Option<f64> {
    // Most objects of a large scene are only moved: what the general test gives for the
    // identity, exactly, without its matrix product (3% of preparing a million spheres).
    if m.matrix3 == DMat3::IDENTITY {
        return Some(1.0);
    }
    uniform_scale_of_any(m)
}

fn uniform_scale_of_any(m: &DAffine3) -> Option<f64> {
    let gram = m.matrix3.transpose() * m.matrix3;
    let s2 = (gram.x_axis.x + gram.y_axis.y + gram.z_axis.z) / 3.0;
    let tolerance = 1e-9 * s2;
    let identity = DMat3::IDENTITY * s2;
    let off = (gram - identity).to_cols_array();
    off.iter().all(|v| v.abs() <= tolerance).then(|| s2.sqrt())
}

/// The inverse transpose of the linear part: how normals transform.
fn normal_matrix(m: &DAffine3) -> DMat3 {
    m.matrix3.inverse().transpose()
}

/// The frame taking the canonical axis `z ∈ [0, 1]` with radius 1 to `base → apex` with
/// the given radius.
fn axis_frame(base: DVec3, apex: DVec3, radius: f64) -> DAffine3 {
    let axis = apex - base;
    let (u, v) = axis.normalize().any_orthonormal_pair();
    DAffine3::from_cols(u * radius, v * radius, axis, base)
}

/// The exact axis-aligned bound of the image of the unit sphere: row norms of the matrix.
fn ellipsoid_bound(world_from_canonical: &DAffine3) -> Bound {
    let m = world_from_canonical.matrix3.transpose();
    let extent = DVec3::new(m.x_axis.length(), m.y_axis.length(), m.z_axis.length());
    let c = world_from_canonical.translation;
    Bound::from_f64(c - extent, c + extent)
}

/// The symmetric 4×4 matrix of a quadric polynomial.
fn quadric_matrix(q: &Quadric) -> DMat4 {
    DMat4::from_cols(
        DVec4::new(q.a, q.d / 2.0, q.e / 2.0, q.g / 2.0),
        DVec4::new(q.d / 2.0, q.b, q.f / 2.0, q.h / 2.0),
        DVec4::new(q.e / 2.0, q.f / 2.0, q.c, q.i / 2.0),
        DVec4::new(q.g / 2.0, q.h / 2.0, q.i / 2.0, q.j),
    )
}

enum QuadricExtent {
    Empty,
    Unbounded,
    Box(DVec3, DVec3),
}

/// The object-space box of a quadric's inside when it is an ellipsoid (positive definite
/// quadratic part); otherwise the solid is unbounded (or empty).
fn quadric_object_box(q: &Quadric) -> QuadricExtent {
    let a = DMat3::from_cols(
        DVec3::new(q.a, q.d / 2.0, q.e / 2.0),
        DVec3::new(q.d / 2.0, q.b, q.f / 2.0),
        DVec3::new(q.e / 2.0, q.f / 2.0, q.c),
    );
    // Sylvester's criterion for positive definiteness.
    let minor1 = a.x_axis.x;
    let minor2 = a.x_axis.x * a.y_axis.y - a.x_axis.y * a.y_axis.x;
    let minor3 = a.determinant();
    if !(minor1 > 0.0 && minor2 > 0.0 && minor3 > 0.0) {
        return QuadricExtent::Unbounded;
    }
    let inverse = a.inverse();
    let g = DVec3::new(q.g, q.h, q.i);
    let center = -0.5 * (inverse * g);
    let lowest = q.j - 0.25 * g.dot(inverse * g);
    if lowest >= 0.0 {
        return QuadricExtent::Empty;
    }
    let diagonal = DVec3::new(inverse.x_axis.x, inverse.y_axis.y, inverse.z_axis.z);
    let extent = (diagonal * -lowest).map(f64::sqrt);
    QuadricExtent::Box(center - extent, center + extent)
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::QuadricForm;

    /// The identity's shortcut gives what the general test gives, for any translation, and
    /// the general test still decides every other matrix.
    #[test]
    fn the_identity_shortcut_is_the_general_answer() {
        for t in [
            DVec3::ZERO,
            DVec3::new(1e9, -0.0, 3.5),
            DVec3::splat(-1e-12),
        ] {
            let m = DAffine3::from_translation(t);
            assert_eq!(uniform_scale(&m), uniform_scale_of_any(&m));
            assert_eq!(uniform_scale(&m), Some(1.0));
        }
        let scaled = DAffine3::from_scale(DVec3::splat(2.0));
        assert_eq!(uniform_scale(&scaled), Some(2.0));
        let stretched = DAffine3::from_scale(DVec3::new(1.0, 2.0, 1.0));
        assert_eq!(uniform_scale(&stretched), None);
    }

    fn prepare(shape: Shape, m: DMat4) -> (Geometry, Bound) {
        Geometry::new(&shape, &DAffine3::from_mat4(m))
    }

    fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
        Ray::new(Vec3A::from(o), Vec3A::from(d).normalize())
    }

    fn spans_of(g: &Geometry, r: &Ray) -> Vec<(f32, f32)> {
        g.spans(r)
            .as_slice()
            .iter()
            .map(|s| (s.t_in, s.t_out))
            .collect()
    }

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() <= 1e-5 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn sphere_hits_front_then_back() {
        let (g, bound) = prepare(
            Shape::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
            },
            DMat4::from_translation(DVec3::new(0.0, 0.0, -5.0)),
        );
        assert!(matches!(g, Geometry::Sphere { .. }));
        assert!(matches!(bound, Bound::Finite(_)));
        let r = ray([0.0, 0.0, 0.0], [0.0, 0.0, -1.0]);
        assert_eq!(g.first_hit(&r, 0.0, f32::INFINITY), Some((4.0, WALL)));
        assert_eq!(g.first_hit(&r, 4.5, f32::INFINITY), Some((6.0, WALL)));
        assert_eq!(g.first_hit(&r, 0.0, 3.0), None);
        assert_eq!(spans_of(&g, &r), vec![(4.0, 6.0)]);
        assert!(g
            .normal(&r, 4.0, WALL)
            .abs_diff_eq(Vec3A::new(0.0, 0.0, 1.0), 1e-6));
    }

    #[test]
    fn distant_sphere_roots_stay_accurate() {
        let (g, _) = prepare(
            Shape::Sphere {
                center: DVec3::new(0.0, 0.0, -10_000.0),
                radius: 1.0,
            },
            DMat4::IDENTITY,
        );
        let r = ray([0.0, 0.5, 0.0], [0.0, 0.0, -1.0]);
        let (t, _) = g.first_hit(&r, 0.0, f32::INFINITY).unwrap_or((0.0, 0));
        let exact = 10_000.0 - (0.75f64).sqrt();
        assert!((f64::from(t) - exact).abs() < 2e-3, "{t}");
    }

    #[test]
    fn normals_under_non_uniform_scale_use_the_inverse_transpose() {
        // A unit sphere squashed to an ellipsoid with semi-axes (2, 1, 1).
        let (g, bound) = prepare(
            Shape::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
            },
            DMat4::from_scale(DVec3::new(2.0, 1.0, 1.0)),
        );
        assert!(matches!(g, Geometry::Local(_)));
        // Its bound is the exact box [-2, 2] × [-1, 1] × [-1, 1].
        let Bound::Finite(aabb) = bound else {
            panic!("an ellipsoid is bounded")
        };
        assert!(aabb.max.abs_diff_eq(Vec3A::new(2.0, 1.0, 1.0), 1e-4));
        // Hit the surface point (1, ½, √½) of x²/4 + y² + z² = 1 from above; the true normal
        // is along the gradient (x/4, y, z).
        let p = Vec3A::new(1.0, 0.5, 0.5f32.sqrt());
        let r = Ray::new(p + Vec3A::new(0.0, 0.0, 3.0), -Vec3A::Z);
        let (t, part) = g.first_hit(&r, 0.0, f32::INFINITY).unwrap_or((0.0, 9));
        assert!(close(t, 3.0), "{t}");
        let n = g.normal(&r, t, part);
        let expected = Vec3A::new(p.x / 4.0, p.y, p.z).normalize();
        assert!(n.abs_diff_eq(expected, 1e-5), "{n} vs {expected}");
        // Transforming the normal like a point would have given the wrong answer.
        let wrong = Vec3A::new(p.x * 2.0, p.y, p.z).normalize();
        assert!(!n.abs_diff_eq(wrong, 1e-2));
    }

    #[test]
    fn box_faces_and_normals() {
        let (g, _) = prepare(
            Shape::Box {
                min: DVec3::new(-1.0, 0.0, -1.0),
                max: DVec3::new(1.0, 2.0, 1.0),
            },
            DMat4::IDENTITY,
        );
        let r = ray([0.0, 1.0, 5.0], [0.0, 0.0, -1.0]);
        assert_eq!(spans_of(&g, &r), vec![(4.0, 6.0)]);
        let (t, part) = g.first_hit(&r, 0.0, f32::INFINITY).unwrap_or((0.0, 0));
        assert!(g.normal(&r, t, part).abs_diff_eq(Vec3A::Z, 1e-6));
        // From above onto the top face.
        let down = ray([0.3, 5.0, 0.2], [0.0, -1.0, 0.0]);
        let (t, part) = g.first_hit(&down, 0.0, f32::INFINITY).unwrap_or((0.0, 0));
        assert!(close(t, 3.0));
        assert!(g.normal(&down, t, part).abs_diff_eq(Vec3A::Y, 1e-6));
        // Parallel to a face and outside it: a miss.
        let beside = ray([0.0, 2.5, 5.0], [0.0, 0.0, -1.0]);
        assert!(g.first_hit(&beside, 0.0, f32::INFINITY).is_none());
    }

    #[test]
    fn capped_cylinder_along_an_arbitrary_axis() {
        // From (0,0,0) to (0,2,0), radius 0.5: the axis is y.
        let (g, _) = prepare(
            Shape::Cylinder {
                base: DVec3::ZERO,
                apex: DVec3::new(0.0, 2.0, 0.0),
                radius: 0.5,
                capped: true,
            },
            DMat4::IDENTITY,
        );
        let side = ray([-5.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
        assert_eq!(spans_of(&g, &side).len(), 1);
        let (t, part) = g.first_hit(&side, 0.0, f32::INFINITY).unwrap_or((0.0, 9));
        assert!(close(t, 4.5));
        assert!(g.normal(&side, t, part).abs_diff_eq(-Vec3A::X, 1e-5));
        let top = ray([0.1, 5.0, 0.1], [0.0, -1.0, 0.0]);
        let (t, part) = g.first_hit(&top, 0.0, f32::INFINITY).unwrap_or((0.0, 9));
        assert!(close(t, 3.0));
        assert_eq!(part, APEX_CAP);
        assert!(g.normal(&top, t, part).abs_diff_eq(Vec3A::Y, 1e-5));
        let span = spans_of(&g, &top)[0];
        assert!(close(span.0, 3.0) && close(span.1, 5.0));
        // The open cylinder has no caps: the same ray goes down the tube.
        let (open, _) = prepare(
            Shape::Cylinder {
                base: DVec3::ZERO,
                apex: DVec3::new(0.0, 2.0, 0.0),
                radius: 0.5,
                capped: false,
            },
            DMat4::IDENTITY,
        );
        assert!(!open.is_solid());
        assert!(open.first_hit(&top, 0.0, f32::INFINITY).is_none());
        // ... but a slanted ray hits the inside of the far wall.
        let slanted = ray([0.0, 2.5, 0.0], [0.3, -1.0, 0.0]);
        let (t, part) = open
            .first_hit(&slanted, 0.0, f32::INFINITY)
            .unwrap_or((0.0, 9));
        let p = slanted.at(t);
        assert!(close(p.x, 0.5) && p.y > 0.0 && p.y < 2.0, "{p}");
        // The outward normal of that wall points away from the axis.
        assert!(open.normal(&slanted, t, part).abs_diff_eq(Vec3A::X, 1e-4));
    }

    #[test]
    fn truncated_cone_spans_and_normal() {
        // Radius 1 at y = 0 narrowing to 0.5 at y = 1.
        let (g, _) = prepare(
            Shape::Cone {
                base: DVec3::ZERO,
                base_radius: 1.0,
                apex: DVec3::Y,
                apex_radius: 0.5,
                capped: true,
            },
            DMat4::IDENTITY,
        );
        // At y = 0.5 the radius is 0.75.
        let r = ray([-5.0, 0.5, 0.0], [1.0, 0.0, 0.0]);
        let spans = spans_of(&g, &r);
        assert_eq!(spans.len(), 1);
        assert!(
            close(spans[0].0, 4.25) && close(spans[0].1, 5.75),
            "{spans:?}"
        );
        let (t, part) = g.first_hit(&r, 0.0, f32::INFINITY).unwrap_or((0.0, 9));
        // The wall leans inwards by atan(0.5): the normal is (−1, 0.5, 0)/√1.25.
        let n = g.normal(&r, t, part);
        assert!(
            n.abs_diff_eq(Vec3A::new(-1.0, 0.5, 0.0).normalize(), 1e-5),
            "{n}"
        );
        // Straight down the axis: apex cap then base cap.
        let down = ray([0.0, 3.0, 0.0], [0.0, -1.0, 0.0]);
        let spans = spans_of(&g, &down);
        assert!(
            close(spans[0].0, 2.0) && close(spans[0].1, 3.0),
            "{spans:?}"
        );
        // A pointed cone: a ray passing beside the tip misses.
        let (pointed, _) = prepare(
            Shape::Cone {
                base: DVec3::ZERO,
                base_radius: 1.0,
                apex: DVec3::Y,
                apex_radius: 0.0,
                capped: true,
            },
            DMat4::IDENTITY,
        );
        let beside_tip = ray([-5.0, 0.95, 0.0], [1.0, 0.0, 0.0]);
        let spans = spans_of(&pointed, &beside_tip);
        assert!(
            close(spans[0].0, 4.95) && close(spans[0].1, 5.05),
            "{spans:?}"
        );
        let above_tip = ray([-5.0, 1.05, 0.0], [1.0, 0.0, 0.0]);
        assert!(spans_of(&pointed, &above_tip).is_empty());
    }

    #[test]
    fn plane_half_space() {
        let (g, bound) = prepare(
            Shape::Plane {
                normal: DVec3::Y,
                offset: 1.0,
            },
            DMat4::IDENTITY,
        );
        assert_eq!(bound, Bound::Infinite);
        let down = ray([0.0, 3.0, 0.0], [0.0, -1.0, 0.0]);
        assert_eq!(g.first_hit(&down, 0.0, f32::INFINITY), Some((2.0, WALL)));
        assert_eq!(spans_of(&g, &down), vec![(2.0, f32::INFINITY)]);
        let up = ray([0.0, -3.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(spans_of(&g, &up), vec![(f32::NEG_INFINITY, 4.0)]);
        // A transformed plane: rotated so that its normal is +x, then moved by 2 along x.
        let (moved, _) = prepare(
            Shape::Plane {
                normal: DVec3::Y,
                offset: 1.0,
            },
            DMat4::from_translation(DVec3::new(2.0, 0.0, 0.0))
                * DMat4::from_rotation_z(-std::f64::consts::FRAC_PI_2),
        );
        let along_x = ray([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let (t, _) = moved
            .first_hit(&along_x, 0.0, f32::INFINITY)
            .unwrap_or((0.0, 0));
        assert!(close(t, 3.0), "{t}");
    }

    #[test]
    fn disk_and_triangle() {
        let (disk, _) = prepare(
            Shape::Disk {
                center: DVec3::ZERO,
                normal: DVec3::Z,
                radius: 1.0,
            },
            DMat4::from_scale(DVec3::new(2.0, 1.0, 1.0)),
        );
        // Stretched along x: (1.5, 0) is inside the ellipse, (0, 1.5) is not.
        let inside = ray([1.5, 0.0, 5.0], [0.0, 0.0, -1.0]);
        let outside = ray([0.0, 1.5, 5.0], [0.0, 0.0, -1.0]);
        assert!(disk.first_hit(&inside, 0.0, f32::INFINITY).is_some());
        assert!(disk.first_hit(&outside, 0.0, f32::INFINITY).is_none());
        let (triangle, _) = prepare(
            Shape::Triangle {
                a: DVec3::ZERO,
                b: DVec3::X,
                c: DVec3::Y,
            },
            DMat4::IDENTITY,
        );
        let hit = ray([0.25, 0.25, 1.0], [0.0, 0.0, -1.0]);
        let miss = ray([0.75, 0.75, 1.0], [0.0, 0.0, -1.0]);
        assert_eq!(
            triangle.first_hit(&hit, 0.0, f32::INFINITY),
            Some((1.0, WALL))
        );
        assert!(triangle.first_hit(&miss, 0.0, f32::INFINITY).is_none());
        assert!(triangle.normal(&hit, 1.0, WALL).abs_diff_eq(Vec3A::Z, 1e-6));
    }

    fn quadric(c: [f64; 10]) -> Shape {
        Shape::Quadric {
            form: QuadricForm::General,
            quadric: Quadric::from_coefficients(c),
        }
    }

    #[test]
    fn quadric_ellipsoid_matches_the_sphere() {
        // x² + y² + z² − 1 = 0 moved to z = −5 by the transform.
        let (g, bound) = prepare(
            quadric([1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0]),
            DMat4::from_translation(DVec3::new(0.0, 0.0, -5.0)),
        );
        let Bound::Finite(aabb) = bound else {
            panic!("an ellipsoid is bounded")
        };
        assert!(aabb.min.abs_diff_eq(Vec3A::new(-1.0, -1.0, -6.0), 1e-4));
        let r = ray([0.0, 0.0, 0.0], [0.0, 0.0, -1.0]);
        assert_eq!(spans_of(&g, &r), vec![(4.0, 6.0)]);
        assert!(g.normal(&r, 4.0, WALL).abs_diff_eq(Vec3A::Z, 1e-6));
    }

    #[test]
    fn hyperboloid_of_two_sheets_has_two_spans() {
        // x² + y² − z² + 1 < 0, i.e. z² > x² + y² + 1: the insides of both sheets.
        let (g, bound) = prepare(
            quadric([1.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
            DMat4::IDENTITY,
        );
        assert_eq!(bound, Bound::Infinite);
        let along_z = ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]);
        // Inside for z < −1 and z > 1: t ∈ (−∞, 4) ∪ (6, ∞).
        assert_eq!(
            spans_of(&g, &along_z),
            vec![(f32::NEG_INFINITY, 4.0), (6.0, f32::INFINITY)]
        );
        assert_eq!(g.first_hit(&along_z, 0.0, f32::INFINITY), Some((4.0, WALL)));
        assert_eq!(g.first_hit(&along_z, 4.5, f32::INFINITY), Some((6.0, WALL)));
        // Along x the line stays between the sheets: never inside.
        let along_x = ray([-5.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
        assert!(spans_of(&g, &along_x).is_empty());
    }

    #[test]
    fn paraboloid_along_its_axis_is_linear() {
        // x² + z² − y < 0: the bowl opening upwards. Straight down the axis a = 0.
        let (g, bound) = prepare(
            quadric([1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
            DMat4::IDENTITY,
        );
        assert_eq!(bound, Bound::Infinite);
        let down = ray([0.0, 5.0, 0.0], [0.0, -1.0, 0.0]);
        assert_eq!(spans_of(&g, &down), vec![(f32::NEG_INFINITY, 5.0)]);
        let (t, part) = g.first_hit(&down, 0.0, f32::INFINITY).unwrap_or((0.0, 9));
        assert_eq!(t, 5.0);
        assert!(g.normal(&down, t, part).abs_diff_eq(-Vec3A::Y, 1e-6));
    }

    #[test]
    fn quadric_under_non_uniform_scale_equals_the_scaled_sphere() {
        let m = DMat4::from_scale(DVec3::new(2.0, 1.0, 0.5));
        let (as_quadric, _) = prepare(
            quadric([1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0]),
            m,
        );
        let (as_sphere, _) = prepare(
            Shape::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
            },
            m,
        );
        for (i, d) in [[1.0, 0.2, -0.3], [0.1, -1.0, 0.4], [-0.3, 0.3, 1.0]]
            .into_iter()
            .enumerate()
        {
            let r = ray([-3.0 * d[0], -3.0 * d[1], -3.0 * d[2]], d);
            let a = as_quadric.first_hit(&r, 0.0, f32::INFINITY);
            let b = as_sphere.first_hit(&r, 0.0, f32::INFINITY);
            let ((ta, pa), (tb, pb)) = (a.unwrap_or((0.0, 0)), b.unwrap_or((1.0, 0)));
            assert!(close(ta, tb), "case {i}: {ta} vs {tb}");
            let (na, nb) = (as_quadric.normal(&r, ta, pa), as_sphere.normal(&r, tb, pb));
            assert!(na.abs_diff_eq(nb, 1e-4), "case {i}: {na} vs {nb}");
        }
    }

    #[test]
    fn empty_ellipsoid_has_an_empty_bound() {
        let (_, bound) = prepare(
            quadric([1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
            DMat4::IDENTITY,
        );
        assert_eq!(bound, Bound::Empty);
    }
}
