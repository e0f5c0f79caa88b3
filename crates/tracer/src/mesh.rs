//! Triangle meshes, two levels deep: each mesh of the IR is prepared once (its triangles in
//! the order of a BVH of its own), and every object that instances it holds a shared
//! reference and its transform. The scene's BVH sees an instance as one item with its
//! world bound; a ray that reaches it is carried into the mesh's space (`t` keeps its
//! meaning there, since the direction is not renormalised) and the mesh's BVH is walked.
//!
//! A hit's [`Part`] is the triangle's index (in BVH order), so the normal is worked out for
//! the nearest hit only. The geometric normal is the triangle's own (outward for a solid
//! mesh, which the IR winds outward), and decides entering and leaving; a smooth mesh's
//! shading normal interpolates the file's vertex normals by the hit's barycentrics.
//!
//! CSG needs a solid mesh's spans along the whole line ([`MeshInstance::push_spans`]):
//! every crossing is collected, sorted by `t`, and paired by the faces' orientation (a
//! crossing against the outward normal enters). Two hits at one `t` in the same direction
//! (a ray through an edge or a vertex, shared by several triangles) count once.

use std::cell::RefCell;
use std::sync::Arc;

use glam::{Affine3A, DAffine3, DVec3, Mat3A, UVec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use whitted_ir::Mesh;

use crate::hit_error::{self, BoundedPoint};
use crate::shapes::{triangle_hit, triangle_hit_uv, Part, RawSpan};
use four::TriangleColumns;
use whitted_bvh::Bound;
use whitted_bvh::Ray;
use whitted_bvh::{Bvh, Step};

/// Up to this many triangles a loop beats building and walking a BVH.
const LINEAR_LIMIT: usize = 4;

/// One triangle, ready for Möller–Trumbore: a corner and the two edges from it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Triangle {
    a: Vec3,
    edge1: Vec3,
    edge2: Vec3,
}

/// A mesh of the IR, prepared once however many objects instance it.
#[derive(Debug)]
pub struct PreparedMesh {
    /// Its triangles in BVH primitive order, so that BVH ids index them directly, as
    /// columns that load four at a time.
    triangles: TriangleColumns,
    /// The corners of each triangle (same order), into `normals`: only for meshes whose
    /// file gave vertex normals.
    corners: Vec<[u32; 3]>,
    normals: Vec<Vec3>,
    bvh: Option<Bvh>,
    solid: bool,
    min: DVec3,
    max: DVec3,
}

impl PreparedMesh {
    /// Prepares a validated mesh: its triangles, and its BVH when it has more than a few.
    pub fn new(mesh: &Mesh) -> PreparedMesh {
        let point = |i: u32| Vec3::from_array(mesh.positions[i as usize]);
        let triangles: Vec<Triangle> = mesh
            .triangles
            .iter()
            .map(|t| {
                let a = point(t[0]);
                Triangle {
                    a,
                    edge1: point(t[1]) - a,
                    edge2: point(t[2]) - a,
                }
            })
            .collect();
        let mut corners = if mesh.normals.is_empty() {
            Vec::new()
        } else {
            mesh.triangles.clone()
        };
        let (min, max) = mesh.bounds().unwrap_or((DVec3::ZERO, DVec3::ZERO));
        let mut bvh = None;
        // The triangles' order in the BVH, when it has one: the columns are written in it
        // straight from `triangles` (a reordered copy first cost a million triangles 30 ms).
        let mut bvh_order: Option<Vec<u32>> = None;
        if triangles.len() > LINEAR_LIMIT {
            // Padded as every box of the scene is: a ray through a corner or along an edge
            // meets a tight box only at its boundary, where rounding may miss it.
            let aabbs: Vec<Aabb> = triangles
                .iter()
                .map(|t| {
                    let (b, c) = (t.a + t.edge1, t.a + t.edge2);
                    let lo = t.a.min(b).min(c).as_dvec3();
                    let hi = t.a.max(b).max(c).as_dvec3();
                    match Bound::from_f64(lo, hi) {
                        Bound::Finite(aabb) => aabb,
                        _ => Aabb::new(lo.as_vec3a(), hi.as_vec3a()),
                    }
                })
                .collect();
            let (built, order) = Bvh::build_binned_sah(&aabbs);
            if built.node_count() > 0 && order.len() == triangles.len() {
                if !corners.is_empty() {
                    corners = order.iter().map(|&i| corners[i as usize]).collect();
                }
                bvh = Some(built);
                bvh_order = Some(order);
            }
        }
        let columns = match &bvh_order {
            Some(order) => TriangleColumns::new(
                order
                    .iter()
                    .filter_map(|&i| triangles.get(i as usize).copied()),
            ),
            None => TriangleColumns::new(triangles.iter().copied()),
        };
        PreparedMesh {
            triangles: columns,
            corners,
            normals: mesh.normals.iter().map(|n| Vec3::from_array(*n)).collect(),
            bvh,
            solid: mesh.solid,
            min,
            max,
        }
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Nodes of the mesh's own BVH (0 when it has none).
    pub fn bvh_node_count(&self) -> usize {
        self.bvh.as_ref().map_or(0, Bvh::node_count)
    }

    /// Visits every triangle whose box the segment touches (every triangle, for a small
    /// mesh); `visit` gets the triangle's index and the current `tmax`.
    #[inline]
    fn each_candidate(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        mut visit: impl FnMut(u32, f32) -> Step,
    ) {
        match &self.bvh {
            Some(bvh) => with_stack(|stack| bvh.traverse(ray, tmin, tmax, stack, &mut visit)),
            None => {
                let mut tmax = tmax;
                for i in 0..self.triangles.len() as u32 {
                    match visit(i, tmax) {
                        Step::Continue => {}
                        Step::Shrink(t) => tmax = t,
                        Step::Stop => return,
                    }
                }
            }
        }
    }

    /// The nearest triangle crossed strictly inside `(tmin, tmax)`, in mesh space. Through
    /// the BVH, the triangles of the leaves a ray reaches at a node are tested four at a
    /// time ([`four::FourTriangles`]) and their hits taken in the walk's order: the same hit,
    /// bit for bit, as testing them one by one.
    pub(crate) fn first_hit(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<(f32, Part)> {
        let mut best = None;
        if let Some(bvh) = &self.bvh {
            with_stack(|stack| {
                bvh.traverse_groups(ray, tmin, tmax, stack, |base, bits, tmax| {
                    self.nearest_in_group(ray, (tmin, tmax), base, bits, &mut best)
                })
            });
            return best;
        }
        self.first_hit_one_at_a_time(ray, tmin, tmax)
    }

    /// The nearest of the triangles `base + i` (for each set bit `i` of `bits`) crossed
    /// inside `(tmin, tmax)`, taken from the highest bit down as the walk would show them
    /// one at a time: into `best`, with the step the walk takes.
    #[inline(always)]
    fn nearest_in_group(
        &self,
        ray: &Ray,
        (tmin, mut tmax): (f32, f32),
        base: u32,
        bits: u32,
        best: &mut Option<(f32, Part)>,
    ) -> Step {
        // Every window of four triangles in a row that holds one of the group's, tested
        // at once (a node's leaves hold neighbours: a group of three usually takes one
        // window); then the hits taken from the highest bit down. `ts` has room for a
        // window starting at any of the 32 bits.
        let mut ts = [0.0f32; 36];
        let mut hits = 0u32;
        let mut window = bits;
        while window != 0 {
            let first = window.trailing_zeros();
            let lanes = ts.get_mut(first as usize..first as usize + 4);
            if let (Some(four), Some(lanes)) = (self.triangles.four((base + first) as usize), lanes)
            {
                let (t, hit) = four.hit(ray);
                t.write_to_slice(lanes);
                hits |= hit.bitmask() << first;
            }
            window &= !(0xF << first);
        }
        hits &= bits;
        let mut step = Step::Continue;
        while hits != 0 {
            let local = 31 - hits.leading_zeros();
            hits &= !(1u32 << local);
            let t = ts.get(local as usize).copied().unwrap_or(f32::NAN);
            if t > tmin && t < tmax {
                *best = Some((t, base + local));
                tmax = t;
                step = Step::Shrink(t);
            }
        }
        step
    }

    /// The nearest hit with the triangles shown one by one (by the BVH walk, or all of
    /// them for a mesh without one): [`PreparedMesh::first_hit`] of a small mesh, and the
    /// oracle of its grouped test, which must give the same hit, bit for bit.
    pub(crate) fn first_hit_one_at_a_time(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, Part)> {
        let mut best = None;
        self.each_candidate(ray, tmin, tmax, |i, tmax| {
            let Some(t) = self.triangles.get(i as usize).and_then(|tri| tri.hit(ray)) else {
                return Step::Continue;
            };
            if t > tmin && t < tmax {
                best = Some((t, i));
                Step::Shrink(t)
            } else {
                Step::Continue
            }
        });
        best
    }

    /// Brute force over every triangle: the oracle for [`PreparedMesh::first_hit`].
    #[cfg(test)]
    pub(crate) fn first_hit_brute_force(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, Part)> {
        let mut best: Option<(f32, Part)> = None;
        for (i, tri) in (0..self.triangles.len()).filter_map(|i| Some((i, self.triangles.get(i)?)))
        {
            if let Some(t) = tri.hit(ray) {
                if t > tmin && t < best.map_or(tmax, |b| b.0) {
                    best = Some((t, i as Part));
                }
            }
        }
        best
    }

    /// The triangle's own normal, `(b - a) × (c - a)`, in mesh space (not unit length).
    fn face_normal(&self, part: Part) -> Vec3A {
        self.triangles
            .get(part as usize)
            .map_or(Vec3A::Z, |t| Vec3A::from(t.edge1.cross(t.edge2)))
    }

    /// The vertex normals interpolated at the point of the triangle `part` that `ray`
    /// reaches, in mesh space; `None` without vertex normals (or off the triangle).
    fn interpolated_normal(&self, ray: &Ray, part: Part) -> Option<Vec3A> {
        let corners = self.corners.get(part as usize)?;
        let tri = self.triangles.get(part as usize)?;
        let (u, v) = triangle_hit_uv(ray, tri.a.into(), tri.edge1.into(), tri.edge2.into())?;
        let n = |k: usize| {
            Vec3A::from(
                self.normals
                    .get(corners[k] as usize)
                    .copied()
                    .unwrap_or(Vec3::ZERO),
            )
        };
        let normal = (1.0 - u - v) * n(0) + u * n(1) + v * n(2);
        (normal.length_squared() > 0.0 && normal.is_finite()).then_some(normal)
    }
}

impl Triangle {
    /// Möller–Trumbore, keeping only hits whose point lies in the triangle's box, padded by
    /// the point's own error bound. A ray nearly in the triangle's plane gets a `t` that may
    /// be anywhere along it; such a "hit" off the triangle is rounding, not a crossing, and
    /// lands far outside the box. A true crossing lands inside it up to the rounding of
    /// `t` and of `origin + t·direction`, which grows with the distance the ray travelled:
    /// a flat face (a box of zero thickness) seen from afar needs that much room, where a
    /// pad scaled by the triangle's coordinates alone dropped a fifth of its hits.
    #[inline(always)]
    fn hit(&self, ray: &Ray) -> Option<f32> {
        let t = triangle_hit(ray, self.a.into(), self.edge1.into(), self.edge2.into())?;
        let (a, b, c) = (
            Vec3A::from(self.a),
            Vec3A::from(self.a + self.edge1),
            Vec3A::from(self.a + self.edge2),
        );
        let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
        let along = t * ray.direction;
        let p = ray.origin + along;
        let pad = lo.abs().max(hi.abs()).max(hi - lo) * HIT_RELATIVE_PAD
            + Vec3A::splat(HIT_ABSOLUTE_PAD)
            + hit_error::gamma(HIT_ERROR_ROUNDINGS) * (ray.origin.abs() + along.abs());
        (p.cmpge(lo - pad).all() && p.cmple(hi + pad).all()).then_some(t)
    }
}

/// Half of whitted-bvh's `bounds.rs` padding of BVH boxes (2⁻²⁰ of the magnitude, plus 1e-6): the room
/// a vertex's own rounding needs.
const HIT_RELATIVE_PAD: f32 = 1.0 / (1u32 << 21) as f32;
const HIT_ABSOLUTE_PAD: f32 = 5e-7;

/// The roundings in a hit point `origin + t·direction` from Möller–Trumbore: the few of
/// the sum itself and those of `t` (a cross product, two dot products and a division, each
/// relative to the ray's distance from the triangle), with a margin for rays that cross
/// the face at a slant.
const HIT_ERROR_ROUNDINGS: u32 = 32;

thread_local! {
    /// The mesh BVH walk's stack, one per thread: the walk runs inside the scene BVH's
    /// walk (which has its own stack), and rays must not allocate.
    static MESH_STACK: RefCell<Vec<UVec2>> = const { RefCell::new(Vec::new()) };
}

fn with_stack(walk: impl FnOnce(&mut Vec<UVec2>)) {
    MESH_STACK.with(|cell| match cell.try_borrow_mut() {
        Ok(mut stack) => walk(&mut stack),
        // Never re-entered (a mesh walk calls no other walk); a fresh stack would still
        // be right.
        Err(_) => walk(&mut Vec::new()),
    });
}

/// One object's instance of a mesh: the shared mesh and the object's transform.
#[derive(Clone, Debug)]
pub struct MeshInstance {
    mesh: Arc<PreparedMesh>,
    mesh_from_world: Affine3A,
    /// Its inverse: hit points placed on a triangle in mesh space come back through it.
    world_from_mesh: Affine3A,
    /// The transpose of `mesh_from_world`'s linear part: carries mesh-space normals to
    /// world space correctly under non-uniform scale.
    normal_from_mesh: Mat3A,
    smooth: bool,
}

/// Two instances are equal when they share one prepared mesh under the same transform.
impl PartialEq for MeshInstance {
    fn eq(&self, other: &MeshInstance) -> bool {
        Arc::ptr_eq(&self.mesh, &other.mesh)
            && self.mesh_from_world == other.mesh_from_world
            && self.smooth == other.smooth
    }
}

impl MeshInstance {
    /// The instance and its world bound (the mesh's box under the transform).
    pub fn new(
        mesh: Arc<PreparedMesh>,
        smooth: bool,
        world_from_object: &DAffine3,
    ) -> (MeshInstance, Bound) {
        let bound = Bound::transformed_box(world_from_object, mesh.min, mesh.max);
        let mesh_from_world = world_from_object.inverse();
        let instance = MeshInstance {
            mesh_from_world: mesh_from_world.as_affine3a(),
            world_from_mesh: world_from_object.as_affine3a(),
            normal_from_mesh: Mat3A::from(mesh_from_world.matrix3.transpose().as_mat3()),
            mesh,
            smooth,
        };
        (instance, bound)
    }

    pub fn is_solid(&self) -> bool {
        self.mesh.solid
    }

    /// The shared mesh (tests count its owners).
    #[cfg(test)]
    pub(crate) fn mesh(&self) -> &Arc<PreparedMesh> {
        &self.mesh
    }

    #[inline]
    fn local_ray(&self, ray: &Ray) -> Ray {
        Ray {
            origin: self.mesh_from_world.transform_point3a(ray.origin),
            direction: self.mesh_from_world.transform_vector3a(ray.direction),
        }
    }

    pub fn first_hit(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<(f32, Part)> {
        self.mesh.first_hit(&self.local_ray(ray), tmin, tmax)
    }

    /// The hit point at `t` on triangle `part`, from its barycentric coordinates in mesh
    /// space and carried to world space, with its error bound (`hit_error.rs`).
    pub fn bounded_point(&self, ray: &Ray, t: f32, part: Part) -> BoundedPoint {
        let local = self.local_ray(ray);
        let on_triangle = self.mesh.triangles.get(part as usize).and_then(|tri| {
            let (a, edge1, edge2) = (tri.a.into(), tri.edge1.into(), tri.edge2.into());
            let uv = triangle_hit_uv(&local, a, edge1, edge2)?;
            Some(hit_error::on_triangle(a, edge1, edge2, uv))
        });
        match on_triangle {
            Some(point) => hit_error::transformed(&self.world_from_mesh, point),
            None => hit_error::along_ray(ray.origin, ray.direction, t),
        }
    }

    /// The triangle's outward normal in world space (not unit length).
    pub fn geometric_normal(&self, part: Part) -> Vec3A {
        self.normal_from_mesh * self.mesh.face_normal(part)
    }

    /// The smooth shading normal in world space (not unit length), for smooth instances
    /// of meshes with vertex normals; `None` otherwise.
    pub fn shading_normal(&self, ray: &Ray, part: Part) -> Option<Vec3A> {
        if !self.smooth {
            return None;
        }
        let local = self.mesh.interpolated_normal(&self.local_ray(ray), part)?;
        Some(self.normal_from_mesh * local)
    }

    /// Appends the spans of the whole line inside this solid mesh to `out`, using `hits`
    /// as the buffer for its crossings: `(t, triangle, entering)`.
    pub fn push_spans(
        &self,
        ray: &Ray,
        hits: &mut Vec<(f32, Part, bool)>,
        mut out: impl FnMut(RawSpan),
    ) {
        let local = self.local_ray(ray);
        let mesh = &self.mesh;
        hits.clear();
        mesh.each_candidate(&local, f32::NEG_INFINITY, f32::INFINITY, |i, _| {
            if let Some(tri) = mesh.triangles.get(i as usize) {
                if let Some(t) = tri.hit(&local) {
                    let outward = tri.edge1.cross(tri.edge2);
                    hits.push((t, i, Vec3A::from(outward).dot(local.direction) < 0.0));
                }
            }
            Step::Continue
        });
        hits.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // Paired by orientation: an entry while inside, or an exit while outside, is the
        // same crossing seen again through a neighbouring triangle (or a stray hit), except
        // that an exit before any entry means the line started inside.
        let mut open: Option<(f32, Part)> = None;
        let mut any = false;
        for &(t, part, entering) in hits.iter() {
            match (entering, open) {
                (true, None) => open = Some((t, part)),
                (false, Some((t_in, part_in))) => {
                    out(span(t_in, part_in, t, part));
                    open = None;
                    any = true;
                }
                (false, None) if !any => {
                    out(span(f32::NEG_INFINITY, part, t, part));
                    any = true;
                }
                _ => {}
            }
        }
        if let Some((t_in, part_in)) = open {
            out(span(t_in, part_in, f32::INFINITY, part_in));
        }
    }
}

fn span(t_in: f32, part_in: Part, t_out: f32, part_out: Part) -> RawSpan {
    RawSpan {
        t_in,
        part_in,
        t_out,
        part_out,
    }
}

mod four;
#[cfg(test)]
mod tests;
