//! A mesh's triangles as columns, tested four at a time against one ray (SIMD lanes): the
//! mesh walk's leaf test ([`PreparedMesh::first_hit`](super::PreparedMesh::first_hit)).
//!
//! The columns hold the triangles in BVH order, so the triangles of a node's leaves are
//! neighbours and any four in a row load as lanes with nine loads (gathering them from an
//! array of triangles took 36, and tested no faster than one at a time).
//!
//! Every lane does the one-triangle test's arithmetic (`Triangle::hit`: Möller–Trumbore,
//! then the padded box check) with the same operations in the same order as glam's
//! `Vec3A` does them one triangle at a time (a dot product is `(x·x' + y·y') + z·z'`, a
//! cross product's components are `a.y·b.z − a.z·b.y` and so on, `min`/`max` are the same
//! SSE instructions with the same operand first, no fused multiply-add), so each lane's
//! `t`, and whether it is a hit, are bit for bit the single test's (`tests.rs` compares
//! the walk's hits with those of the one-at-a-time walk on awkward rays and meshes).

use glam::{BVec4A, Vec3, Vec3A, Vec4};

use super::{Triangle, HIT_ABSOLUTE_PAD, HIT_ERROR_ROUNDINGS, HIT_RELATIVE_PAD};
use crate::hit_error;
use whitted_bvh::Ray;

/// Three coordinates of four points or vectors, one per lane.
#[derive(Clone, Copy)]
struct Lanes {
    x: Vec4,
    y: Vec4,
    z: Vec4,
}

impl Lanes {
    #[inline(always)]
    fn splat(v: Vec3A) -> Lanes {
        Lanes {
            x: Vec4::splat(v.x),
            y: Vec4::splat(v.y),
            z: Vec4::splat(v.z),
        }
    }

    #[inline(always)]
    fn dot(self, o: Lanes) -> Vec4 {
        (self.x * o.x + self.y * o.y) + self.z * o.z
    }

    #[inline(always)]
    fn cross(self, b: Lanes) -> Lanes {
        Lanes {
            x: self.y * b.z - self.z * b.y,
            y: self.z * b.x - self.x * b.z,
            z: self.x * b.y - self.y * b.x,
        }
    }

    #[inline(always)]
    fn map2(self, o: Lanes, f: impl Fn(Vec4, Vec4) -> Vec4) -> Lanes {
        Lanes {
            x: f(self.x, o.x),
            y: f(self.y, o.y),
            z: f(self.z, o.z),
        }
    }

    #[inline(always)]
    fn map(self, f: impl Fn(Vec4) -> Vec4) -> Lanes {
        Lanes {
            x: f(self.x),
            y: f(self.y),
            z: f(self.z),
        }
    }

    /// Lanes where every coordinate of `self` is `>=` `o`'s (false where any is NaN).
    #[inline(always)]
    fn all_ge(self, o: Lanes) -> BVec4A {
        self.x.cmpge(o.x) & self.y.cmpge(o.y) & self.z.cmpge(o.z)
    }

    #[inline(always)]
    fn all_le(self, o: Lanes) -> BVec4A {
        self.x.cmple(o.x) & self.y.cmple(o.y) & self.z.cmple(o.z)
    }
}

/// A mesh's triangles as nine arrays of coordinates (structure of arrays), padded with
/// three copies of the last so that any four in a row load as lanes.
#[derive(Debug, PartialEq)]
pub(super) struct TriangleColumns {
    /// `a.x, a.y, a.z, edge1.x, ..., edge2.z` of every triangle.
    columns: [Vec<f32>; 9],
}

impl TriangleColumns {
    pub(super) fn new(triangles: impl Iterator<Item = Triangle>) -> TriangleColumns {
        let len = triangles.size_hint().0;
        let mut columns: [Vec<f32>; 9] = std::array::from_fn(|_| Vec::with_capacity(len + 3));
        let mut push = |t: &Triangle| {
            let values = [
                t.a.x, t.a.y, t.a.z, t.edge1.x, t.edge1.y, t.edge1.z, t.edge2.x, t.edge2.y,
                t.edge2.z,
            ];
            for (column, value) in columns.iter_mut().zip(values) {
                column.push(value);
            }
        };
        let mut last = None;
        for t in triangles {
            push(&t);
            last = Some(t);
        }
        if let Some(t) = last {
            for _ in 0..3 {
                push(&t);
            }
        }
        TriangleColumns { columns }
    }

    /// How many triangles there are.
    pub(super) fn len(&self) -> usize {
        self.columns[0].len().saturating_sub(3)
    }

    /// Triangle `index`, when there is one.
    pub(super) fn get(&self, index: usize) -> Option<Triangle> {
        if index >= self.len() {
            return None;
        }
        let [ax, ay, az, bx, by, bz, cx, cy, cz] =
            std::array::from_fn(|c| self.columns[c].get(index).copied().unwrap_or(0.0));
        Some(Triangle {
            a: Vec3::new(ax, ay, az),
            edge1: Vec3::new(bx, by, bz),
            edge2: Vec3::new(cx, cy, cz),
        })
    }

    /// Triangles `first` to `first + 3` in lanes 0 to 3 (`None` past the end).
    #[inline(always)]
    pub(super) fn four(&self, first: usize) -> Option<FourTriangles> {
        // Nine fixed columns: only the window itself can be out of range.
        let lane = |c: usize| Some(Vec4::from_slice(self.columns[c].get(first..first + 4)?));
        Some(FourTriangles {
            a: Lanes {
                x: lane(0)?,
                y: lane(1)?,
                z: lane(2)?,
            },
            edge1: Lanes {
                x: lane(3)?,
                y: lane(4)?,
                z: lane(5)?,
            },
            edge2: Lanes {
                x: lane(6)?,
                y: lane(7)?,
                z: lane(8)?,
            },
        })
    }
}

/// Four triangles, lane by lane: a corner and the two edges from it.
pub(super) struct FourTriangles {
    a: Lanes,
    edge1: Lanes,
    edge2: Lanes,
}

impl FourTriangles {
    /// Each lane's `Triangle::hit`: the distance, and whether it is a hit (where it is not,
    /// the distance means nothing).
    #[inline(always)]
    pub(super) fn hit(&self, ray: &Ray) -> (Vec4, BVec4A) {
        let origin = Lanes::splat(ray.origin);
        let direction = Lanes::splat(ray.direction);
        let (a, edge1, edge2) = (self.a, self.edge1, self.edge2);
        // Möller–Trumbore (`shapes::triangle_hit`).
        let p = direction.cross(edge2);
        let determinant = edge1.dot(p);
        let mut hit = determinant.cmpne(Vec4::ZERO);
        let inverse = Vec4::ONE / determinant;
        let s = origin.map2(a, |o, a| o - a);
        let u = s.dot(p) * inverse;
        hit &= u.cmpge(Vec4::ZERO) & u.cmple(Vec4::ONE);
        let q = s.cross(edge1);
        let v = direction.dot(q) * inverse;
        hit &= !(v.cmplt(Vec4::ZERO) | (u + v).cmpgt(Vec4::ONE));
        let t = edge2.dot(q) * inverse;
        // The padded box check (`Triangle::hit`).
        let b = a.map2(edge1, |a, e| a + e);
        let c = a.map2(edge2, |a, e| a + e);
        let lo = a.map2(b, Vec4::min).map2(c, Vec4::min);
        let hi = a.map2(b, Vec4::max).map2(c, Vec4::max);
        let along = direction.map(|d| t * d);
        let point = origin.map2(along, |o, l| o + l);
        let gamma = hit_error::gamma(HIT_ERROR_ROUNDINGS);
        let size = lo.map(Vec4::abs).map2(hi.map(Vec4::abs), Vec4::max);
        let size = size.map2(hi.map2(lo, |h, l| h - l), Vec4::max);
        let rounding = origin
            .map(Vec4::abs)
            .map2(along.map(Vec4::abs), |o, l| o + l);
        let pad = size
            .map(|e| e * HIT_RELATIVE_PAD + Vec4::splat(HIT_ABSOLUTE_PAD))
            .map2(rounding, |e, r| e + gamma * r);
        hit &= point.all_ge(lo.map2(pad, |l, p| l - p));
        hit &= point.all_le(hi.map2(pad, |h, p| h + p));
        (t, hit)
    }
}
