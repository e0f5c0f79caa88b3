//! The BVH over bounded objects: obvhs builds a compressed wide BVH (`CwBvh`, eight children
//! per node, child boxes quantised to bytes); this module walks it.
//!
//! The walk is obvhs's own traversal order (its `traverse!` macro: the same node groups,
//! octant-sorted child order and hit masks), with two changes that matter to a Whitted
//! tracer. Child boxes are dequantised once at build time into f32 planes, rounded outwards
//! so they stay conservative, which makes the per-node test a handful of SIMD operations
//! instead of 48 byte-to-float conversions. The children's contributions to the hit mask
//! are decoded from the metadata once at build time too, so that a node's hit mask is an OR
//! over the touched children and one table lookup for the octant order of inner children.
//! And the node test honours the query's own
//! `tmin` (obvhs clamps to a fixed 1e-4), so scenes modelled at small scales still work.
//! The traversal stack is a per-thread `Vec` reused across rays: no depth limit and no
//! per-ray allocation or zeroing.

use glam::{UVec2, Vec3A, Vec4};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::node::CwBvhNode;
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

/// A node's dequantised child planes next to what the walk needs of obvhs's node, so one
/// node is one contiguous read.
#[derive(Clone, Debug, PartialEq)]
struct WideNode {
    planes: NodePlanes,
    /// What leaf child `c` adds to obvhs's hit mask when the segment touches its box: its
    /// unary primitive count shifted to its primitive offset (below bit 24); 0 for inner
    /// and empty children.
    leaf_bits: [u32; 8],
    child_base: u32,
    primitive_base: u32,
    /// Which child slots hold inner nodes. obvhs gives the inner child in slot `c` the
    /// hit-mask bit `24 + c` (before the octant ordering), so the touched inner children
    /// are simply the touched slots that are in `imask`.
    imask: u32,
}

impl WideNode {
    /// `None` when the metadata is not laid out as obvhs's converter writes it (inner child
    /// `c` with metadata `0b001` and `24 + c`; leaves with at most three primitives within
    /// the node's 24), where the decoded bits would not give obvhs's hit mask.
    fn new(node: &CwBvhNode) -> Option<WideNode> {
        let mut leaf_bits = [0u32; 8];
        for (slot, (bits, &meta)) in leaf_bits.iter_mut().zip(&node.child_meta).enumerate() {
            let inner = node.imask & (1 << slot) != 0;
            // obvhs's `get_child_and_index_bits`, one byte at a time and without the octant.
            let count_bits = u32::from(meta >> 5) & 0b111;
            let index = u32::from(meta) & 0b1_1111;
            let fits = if inner {
                u32::from(meta) == 0b0010_0000 | (24 + slot as u32)
            } else {
                *bits = count_bits << index;
                // Not an inner child to obvhs's decoding either.
                meta & (meta << 1) & 0b1_0000 == 0 && *bits < 1 << 24
            };
            if !fits {
                return None;
            }
        }
        Some(WideNode {
            planes: dequantise(node),
            leaf_bits,
            child_base: node.child_base_idx,
            primitive_base: node.primitive_base_idx,
            imask: u32::from(node.imask),
        })
    }
}

#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<WideNode>,
}

/// `INNER_BELOW[imask][slot]`: how many of the inner-child slots in `imask` are below
/// `slot`, which is where that child sits among the node's children.
static INNER_BELOW: [[u8; 8]; 256] = inner_below_table();

const fn inner_below_table() -> [[u8; 8]; 256] {
    let mut table = [[0u8; 8]; 256];
    let mut imask = 0;
    while imask < 256 {
        let mut slot = 0;
        while slot < 8 {
            table[imask][slot] = (imask & ((1 << slot) - 1)).count_ones() as u8;
            slot += 1;
        }
        imask += 1;
    }
    table
}

/// `INNER_ORDER[o][b]`: the inner-child byte `b` of a hit mask with every bit `i` moved to
/// `i ^ o`, which is how obvhs orders inner children for a ray in octant `o`.
static INNER_ORDER: [[u8; 256]; 8] = inner_order_table();

const fn inner_order_table() -> [[u8; 256]; 8] {
    let mut table = [[0u8; 256]; 8];
    let mut octant = 0;
    while octant < 8 {
        let mut byte = 0;
        while byte < 256 {
            let mut moved = 0u8;
            let mut bit = 0;
            while bit < 8 {
                if byte & (1 << bit) != 0 {
                    moved |= 1 << (bit ^ octant);
                }
                bit += 1;
            }
            table[octant][byte] = moved;
            byte += 1;
        }
        octant += 1;
    }
    table
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
        let nodes: Option<Vec<WideNode>> = cwbvh.nodes.iter().map(WideNode::new).collect();
        match nodes {
            Some(nodes) => (Bvh { nodes }, cwbvh.primitive_indices),
            // Not the layout obvhs documents: no BVH, so the caller tests every item.
            None => (Bvh { nodes: Vec::new() }, Vec::new()),
        }
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
        visit: impl FnMut(u32, f32) -> Step,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        // One walk per octant of the direction, so that the near and far planes of each
        // axis and the order of inner children are constants inside the loop.
        match octant_inv4(ray.direction) & 0b111 {
            0 => self.traverse_octant::<0>(ray, tmin, tmax, stack, visit),
            1 => self.traverse_octant::<1>(ray, tmin, tmax, stack, visit),
            2 => self.traverse_octant::<2>(ray, tmin, tmax, stack, visit),
            3 => self.traverse_octant::<3>(ray, tmin, tmax, stack, visit),
            4 => self.traverse_octant::<4>(ray, tmin, tmax, stack, visit),
            5 => self.traverse_octant::<5>(ray, tmin, tmax, stack, visit),
            6 => self.traverse_octant::<6>(ray, tmin, tmax, stack, visit),
            _ => self.traverse_octant::<7>(ray, tmin, tmax, stack, visit),
        }
    }

    /// [`Bvh::traverse`] for rays whose `octant_inv4` code is `OCT` in every byte.
    #[inline(always)]
    fn traverse_octant<const OCT: u32>(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        stack: &mut Vec<UVec2>,
        mut visit: impl FnMut(u32, f32) -> Step,
    ) {
        let query = NodeQuery::new(ray, tmin);
        let mut tmax = tmax;
        let inner_order = &INNER_ORDER[OCT as usize];
        stack.clear();
        let mut stack = GroupStack::new(stack);
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

            if current_group.y & 0xff00_0000 != 0 {
                let hits_imask = current_group.y;
                let child_index_offset = first_bit_high(hits_imask);
                current_group.y &= !(1u32 << child_index_offset);
                if current_group.y & 0xff00_0000 != 0 {
                    stack.push(current_group);
                }
                // The child's slot, and how many inner children the parent keeps in the
                // slots below it (obvhs's popcount of the masked imask).
                let slot_index = (child_index_offset - 24) ^ OCT;
                let below = INNER_BELOW[(hits_imask & 0xff) as usize][(slot_index & 7) as usize];
                let index = (current_group.x + u32::from(below)) as usize;
                let Some(node) = self.nodes.get(index) else {
                    return;
                };
                let touched = query.touched::<OCT>(node, tmax);
                current_group.x = node.child_base;
                primitive_group.x = node.primitive_base;
                current_group.y =
                    (u32::from(inner_order[(touched & node.imask) as usize]) << 24) | node.imask;
                primitive_group.y = leaf_primitive_bits(node, touched & !node.imask);
            } else {
                current_group.y = 0;
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

/// The walk's stack of node groups: the top entries in a local array (kept in registers
/// and the machine stack), the rest in the per-thread `Vec` when a walk goes deeper.
struct GroupStack<'s> {
    top: [UVec2; GroupStack::LOCAL],
    len: usize,
    deeper: &'s mut Vec<UVec2>,
}

impl<'s> GroupStack<'s> {
    const LOCAL: usize = 16;

    #[inline(always)]
    fn new(deeper: &'s mut Vec<UVec2>) -> Self {
        GroupStack {
            top: [UVec2::ZERO; Self::LOCAL],
            len: 0,
            deeper,
        }
    }

    #[inline(always)]
    fn push(&mut self, group: UVec2) {
        if self.len == Self::LOCAL {
            self.deeper.extend_from_slice(&self.top);
            self.len = 0;
        }
        if let Some(slot) = self.top.get_mut(self.len) {
            *slot = group;
        }
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<UVec2> {
        if self.len == 0 {
            let refill = self.deeper.len().checked_sub(Self::LOCAL)?;
            self.top.copy_from_slice(&self.deeper[refill..]);
            self.deeper.truncate(refill);
            self.len = Self::LOCAL;
        }
        self.len -= 1;
        self.top.get(self.len).copied()
    }
}

/// The ray, prepared once per query for the slab tests.
struct NodeQuery {
    origin: [Vec4; 3],
    inv_direction: [Vec4; 3],
    tmin: Vec4,
}

impl NodeQuery {
    #[inline(always)]
    fn new(ray: &Ray, tmin: f32) -> NodeQuery {
        let inv = inverse_direction(ray.direction);
        NodeQuery {
            origin: [
                Vec4::splat(ray.origin.x),
                Vec4::splat(ray.origin.y),
                Vec4::splat(ray.origin.z),
            ],
            inv_direction: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
            tmin: Vec4::splat(tmin),
        }
    }

    /// The node's children (a bit per slot) whose boxes the segment touches. Along an
    /// axis the ray travels towards −axis (`OCT` has a zero bit), the max plane is met first.
    #[inline(always)]
    fn touched<const OCT: u32>(&self, node: &WideNode, tmax: f32) -> u32 {
        let tmax = Vec4::splat(tmax);
        let mut touched = 0u32;
        for (half, planes) in node.planes.halves.iter().enumerate() {
            let mut enter = self.tmin;
            let mut exit = tmax;
            for axis in 0..3 {
                let backwards = usize::from(OCT & (4 >> axis) == 0);
                let near_plane = planes[axis * 2 + backwards];
                let far_plane = planes[axis * 2 + 1 - backwards];
                let t_near = (near_plane - self.origin[axis]) * self.inv_direction[axis];
                let t_far = (far_plane - self.origin[axis]) * self.inv_direction[axis];
                enter = enter.max(t_near);
                exit = exit.min(t_far);
            }
            touched |= enter.cmple(exit).bitmask() << (half * 4);
        }
        touched
    }
}

/// The primitive bits of obvhs's hit mask: those of the touched leaf children.
#[inline(always)]
fn leaf_primitive_bits(node: &WideNode, mut leaves: u32) -> u32 {
    let mut bits = 0u32;
    while leaves != 0 {
        bits |= node.leaf_bits[leaves.trailing_zeros() as usize & 7];
        leaves &= leaves - 1;
    }
    bits
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
            assert_eq!(one.nodes, other.nodes, "{threads} threads");
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
