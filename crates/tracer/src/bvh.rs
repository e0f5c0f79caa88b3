//! The BVH over bounded objects: obvhs builds a compressed wide BVH (`CwBvh`, eight children
//! per node, child boxes quantised to bytes); this module walks it.
//!
//! The walk is obvhs's own traversal order (its `traverse!` macro: the same node groups,
//! octant-sorted child order and hit masks), with two changes that matter to a Whitted
//! tracer. Child boxes are dequantised once at build time into f32 planes, rounded outwards
//! so they stay conservative, which makes the per-node test a handful of SIMD operations
//! instead of 48 byte-to-float conversions. And the node test honours the query's own
//! `tmin` (obvhs clamps to a fixed 1e-4), so scenes modelled at small scales still work.
//! The traversal stack is a per-thread `Vec` reused across rays: no depth limit and no
//! per-ray allocation or zeroing.

use glam::{UVec2, Vec3A, Vec4};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::node::{extract_byte64, CwBvhNode};
use obvhs::cwbvh::CwBvh;

use crate::bounds::inverse_direction;
use crate::ray::Ray;

/// Children's box planes of one node, four children per half: `halves[h][axis * 2]` holds
/// the minima along `axis` of children `4h..4h + 4`, `halves[h][axis * 2 + 1]` the maxima.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct NodePlanes {
    halves: [[Vec4; 6]; 2],
}

impl NodePlanes {
    #[cfg(test)]
    fn get(&self, slot: usize, child: usize) -> f32 {
        self.halves[child / 4][slot][child % 4]
    }
}

/// A node's dequantised child planes next to obvhs's node (child and primitive indices,
/// ordering metadata), so one node is one contiguous read.
#[derive(Clone, Debug)]
struct WideNode {
    planes: NodePlanes,
    node: CwBvhNode,
}

#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<WideNode>,
}

/// What the visitor wants after testing a primitive.
pub enum Step {
    Continue,
    /// A hit at this distance: nothing farther matters any more.
    Shrink(f32),
    Stop,
}

/// How many primitives a finished build may hold in total before ids overflow u32.
pub const MAX_PRIMITIVES: usize = u32::MAX as usize;

impl Bvh {
    /// Builds with obvhs (`build_cwbvh`, `BvhBuildParams::medium_build()`, parallel on the
    /// current rayon pool). Returns the BVH and `primitive_indices`: the input index of
    /// each BVH primitive id.
    pub fn build(aabbs: &[Aabb]) -> (Bvh, Vec<u32>) {
        let cwbvh: CwBvh = obvhs::cwbvh::builder::build_cwbvh(
            aabbs,
            obvhs::BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        let nodes = cwbvh
            .nodes
            .iter()
            .map(|node| WideNode {
                planes: dequantise(node),
                node: *node,
            })
            .collect();
        let bvh = Bvh { nodes };
        (bvh, cwbvh.primitive_indices)
    }

    /// Visits every primitive whose leaf box the segment `(tmin, tmax)` touches, nearer
    /// node groups first; the visitor sees the current `tmax` and may shrink it or stop.
    #[inline]
    pub fn traverse(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        stack: &mut Vec<UVec2>,
        mut visit: impl FnMut(u32, f32) -> Step,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let query = NodeQuery::new(ray, tmin);
        let mut tmax = tmax;
        let oct_inv4 = octant_inv4(ray.direction);
        stack.clear();
        let mut current_group = UVec2::new(0, 0x8000_0000);
        let mut primitive_group = UVec2::ZERO;
        loop {
            while primitive_group.y != 0 {
                let local = first_bit_high(primitive_group.y);
                primitive_group.y &= !(1u32 << local);
                match visit(primitive_group.x + local, tmax) {
                    Step::Continue => {}
                    Step::Shrink(t) => tmax = t,
                    Step::Stop => return,
                }
            }
            primitive_group = UVec2::ZERO;

            if current_group.y & 0xff00_0000 != 0 {
                let hits_imask = current_group.y;
                let child_index_offset = first_bit_high(hits_imask);
                current_group.y &= !(1u32 << child_index_offset);
                if current_group.y & 0xff00_0000 != 0 {
                    stack.push(current_group);
                }
                let slot_index = (child_index_offset - 24) ^ (oct_inv4 & 0xff);
                let relative_index = (hits_imask & !(0xffff_ffffu32 << slot_index)).count_ones();
                let index = (current_group.x + relative_index) as usize;
                let Some(WideNode { planes, node }) = self.nodes.get(index) else {
                    return;
                };
                let hitmask = query.intersect(node, planes, tmax, oct_inv4);
                current_group.x = node.child_base_idx;
                primitive_group.x = node.primitive_base_idx;
                current_group.y = (hitmask & 0xff00_0000) | u32::from(node.imask);
                primitive_group.y = hitmask & 0x00ff_ffff;
            } else {
                current_group = UVec2::ZERO;
            }

            if primitive_group.y == 0 && current_group.y & 0xff00_0000 == 0 {
                match stack.pop() {
                    Some(group) => current_group = group,
                    None => return,
                }
            }
        }
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }
}

/// The ray, prepared once per query for the slab tests.
struct NodeQuery {
    origin: [Vec4; 3],
    inv_direction: [Vec4; 3],
    /// Whether the max plane is met first along each axis (the ray goes towards −axis).
    backwards: [bool; 3],
    tmin: Vec4,
}

impl NodeQuery {
    fn new(ray: &Ray, tmin: f32) -> NodeQuery {
        let inv = inverse_direction(ray.direction);

        NodeQuery {
            origin: [
                Vec4::splat(ray.origin.x),
                Vec4::splat(ray.origin.y),
                Vec4::splat(ray.origin.z),
            ],
            inv_direction: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
            backwards: [
                ray.direction.x < 0.0,
                ray.direction.y < 0.0,
                ray.direction.z < 0.0,
            ],
            tmin: Vec4::splat(tmin),
        }
    }

    /// obvhs's hit mask for the node's children that the segment touches: child node bits
    /// in the top byte, leaf primitive bits below, in the ray's octant order.
    #[inline(always)]
    fn intersect(&self, node: &CwBvhNode, planes: &NodePlanes, tmax: f32, oct_inv4: u32) -> u32 {
        let tmax = Vec4::splat(tmax);
        let mut touched = 0u32;
        for (half, planes) in planes.halves.iter().enumerate() {
            let mut enter = self.tmin;
            let mut exit = tmax;
            for axis in 0..3 {
                let backwards = usize::from(self.backwards[axis]);
                let near_plane = planes[axis * 2 + backwards];
                let far_plane = planes[axis * 2 + 1 - backwards];
                let t_near = (near_plane - self.origin[axis]) * self.inv_direction[axis];
                let t_far = (far_plane - self.origin[axis]) * self.inv_direction[axis];
                enter = enter.max(t_near);
                exit = exit.min(t_far);
            }
            touched |= enter.cmple(exit).bitmask() << (half * 4);
        }
        if touched == 0 {
            return 0;
        }
        let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
        let mut hit_mask = 0u32;
        while touched != 0 {
            let child = touched.trailing_zeros() as usize;
            touched &= touched - 1;
            hit_mask |= extract_byte64(child_bits8, child) << extract_byte64(bit_index8, child);
        }
        hit_mask
    }
}

#[inline(always)]
fn first_bit_high(value: u32) -> u32 {
    31 - value.leading_zeros()
}

/// obvhs's octant code for child ordering.
#[inline(always)]
fn octant_inv4(direction: Vec3A) -> u32 {
    (if direction.x < 0.0 { 0 } else { 0x0404_0404 })
        | (if direction.y < 0.0 { 0 } else { 0x0202_0202 })
        | (if direction.z < 0.0 { 0 } else { 0x0101_0101 })
}

/// The world-space f32 planes of a node's children, rounded outwards. The quantised plane
/// is `p + 2^e·q` exactly (a power of two times a byte), computed in f64 and then moved to
/// the f32 on the conservative side.
fn dequantise(node: &CwBvhNode) -> NodePlanes {
    let mut out = NodePlanes::default();
    let quantised = [
        &node.child_min_x,
        &node.child_max_x,
        &node.child_min_y,
        &node.child_max_y,
        &node.child_min_z,
        &node.child_max_z,
    ];
    for (slot, bytes) in quantised.iter().enumerate() {
        let axis = slot / 2;
        let is_max = slot % 2 == 1;
        let origin = f64::from(node.p[axis]);
        let scale = f64::from(f32::from_bits(u32::from(node.e[axis]) << 23));
        for child in 0..8 {
            let exact = origin + scale * f64::from(bytes[child]);
            let mut rounded = exact as f32;
            if is_max && f64::from(rounded) < exact {
                rounded = rounded.next_up();
            } else if !is_max && f64::from(rounded) > exact {
                rounded = rounded.next_down();
            }
            out.halves[child / 4][slot][child % 4] = rounded;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn boxes(n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|i| {
                let c = Vec3A::new(i as f32 * 3.0, (i % 7) as f32, (i % 5) as f32 * 2.0);
                Aabb::new(c - 0.5, c + 0.5)
            })
            .collect()
    }

    /// Every box the segment touches must be visited (no false misses), whatever the size.
    #[test]
    fn traversal_visits_every_touched_box() {
        for n in [1usize, 2, 3, 9, 100, 1000] {
            let aabbs = boxes(n);
            let (bvh, indices) = Bvh::build(&aabbs);
            assert_eq!(indices.len(), n);
            let mut stack = Vec::new();
            for k in 0..50 {
                let origin = Vec3A::new(-5.0 + k as f32, 3.0 - (k % 3) as f32, -4.0);
                let direction = Vec3A::new(1.0, 0.05 * (k % 4) as f32, 0.4).normalize();
                let ray = Ray::new(origin, direction);
                let inv = inverse_direction(direction);
                let mut visited = vec![false; n];
                bvh.traverse(&ray, 0.0, f32::INFINITY, &mut stack, |id, _| {
                    visited[indices[id as usize] as usize] = true;
                    Step::Continue
                });
                for (i, aabb) in aabbs.iter().enumerate() {
                    if crate::bounds::segment_touches_box(aabb, &ray, inv, 0.0, f32::INFINITY) {
                        assert!(visited[i], "n {n}, ray {k}: box {i} not visited");
                    }
                }
            }
        }
    }

    /// The build must not depend on the thread count: traversal order decides which of two
    /// equally near hits wins and the order in which filtered shadows multiply.
    #[test]
    fn build_is_the_same_on_any_thread_count() {
        let aabbs = boxes(5000);
        let build_on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap_or_else(|e| panic!("no pool: {e}"));
            pool.install(|| Bvh::build(&aabbs))
        };
        let (one, one_indices) = build_on(1);
        for threads in [2, 3, 4] {
            let (other, other_indices) = build_on(threads);
            let metadata = |bvh: &Bvh| bvh.nodes.iter().map(|n| n.node).collect::<Vec<_>>();
            assert_eq!(metadata(&one), metadata(&other), "{threads} threads");
            assert_eq!(one_indices, other_indices, "{threads} threads");
        }
    }

    #[test]
    fn dequantised_planes_contain_the_boxes() {
        let aabbs = boxes(300);
        let (bvh, _) = Bvh::build(&aabbs);
        assert!(bvh.node_count() > 1);
        // The root's children together cover every box.
        let root = &bvh.nodes[0].planes;
        for aabb in &aabbs {
            let covered = (0..8).any(|c| {
                (0..3).all(|axis| {
                    root.get(axis * 2, c) <= aabb.min[axis]
                        && root.get(axis * 2 + 1, c) >= aabb.max[axis]
                })
            });
            assert!(covered, "{aabb:?}");
        }
    }
}
