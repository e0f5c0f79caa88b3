//! The BVH over bounded objects, in obvhs's compressed wide layout (`CwBvh`, eight children
//! per node, child boxes quantised to bytes); this module builds it through `binary` and
//! `wide` and walks it.
//!
//! The walk visits primitives in exactly obvhs's traversal order (its `traverse!` macro: the
//! same node groups, octant-sorted child order and hit masks; a test compares the two visit
//! by visit), because the order decides which of two equally near hits wins, which blocker a
//! shadow ray reports and in what order filtered shadows multiply. What differs is the cost
//! of each step, which is most of a render of a large scene:
//!
//! - Child boxes are dequantised once at build time into f32 planes, rounded outwards so
//!   they stay conservative: the per-node test is a handful of SIMD operations instead of 48
//!   byte-to-float conversions. It honours the query's own `tmin` (obvhs clamps to a fixed
//!   1e-4), so scenes modelled at small scales still work.
//! - The metadata is decoded at build time too: a touched inner child in slot `c` is bit `c`
//!   of `imask`, so the inner-child byte of the hit mask is one table lookup (`INNER_ORDER`,
//!   for the octant order), and only touched leaves are looked at for primitive bits; a
//!   child's position among the node's children is another lookup (`INNER_BELOW`) instead of
//!   a popcount, which the x86-64 baseline lacks.
//! - The walk is compiled once per ray octant, so the near and far plane of each axis and
//!   the child order are constants; a node is 64-byte aligned, four cache lines.
//!
//! Each step sits on the chain of dependent loads and compares from one node to the next,
//! which is what bounds the speed of a walk. The traversal stack is a per-thread `Vec`
//! reused across rays: no depth limit and no per-ray allocation or zeroing.
//!
//! The build frees each of its arrays once it is done with it, so that the largest never
//! coexist: the binary tree (64 bytes a primitive) is converted into obvhs's 80-byte nodes
//! (about 9 bytes a primitive), then freed, and only then are those expanded into the
//! walk's 256-byte nodes (about 30 bytes a primitive). For the 1M-sphere grid this took
//! the conversion's plateau from 152 to 134 MiB (129 with `binary`'s 36-byte inner nodes).
//!
//! Up to eight rays of one octant can also walk together ([`Bvh::traverse_packet`]), each
//! seeing exactly its single walk's visits; camera rays use it.
//!
//! The child test has three implementations with bit-identical results
//! ([`TraversalPath`]): two 4-lane SSE2 halves, which every x86-64 has, and AVX2 and
//! AVX-512 ones (`simd`). Each BVH takes the fastest the CPU offers when it is built
//! (or the one [`force_traversal_path`] names), so one binary runs anywhere.

use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};

use glam::{UVec2, Vec3A, Vec4};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::cwbvh::CwBvh;
use rayon::prelude::*;

use crate::binary::{
    boxes_of, build_boxes, build_boxes_with, round_down, round_up, BuildScale, Built, PrimitiveBox,
};
use crate::bounds::inverse_direction;
use crate::permute::permute_checked;
use crate::ray::Ray;
use crate::simd::{self, SimdPath};
use crate::wide;

/// Children's box planes of one node, a row of eight children per plane: `rows[axis * 2]`
/// holds the minima along `axis`, `rows[axis * 2 + 1]` the maxima. A row is two 16-byte
/// loads for the baseline's 4-lane test and one 32-byte load for the 8-lane tests
/// (`simd`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub(crate) struct NodePlanes {
    pub(crate) rows: [[f32; 8]; 6],
}

impl NodePlanes {
    #[cfg(test)]
    fn get(&self, slot: usize, child: usize) -> f32 {
        self.rows[slot][child]
    }

    /// Children `4·half..4·half + 4` of row `slot`.
    #[inline(always)]
    fn quarter(&self, slot: usize, half: usize) -> Vec4 {
        let row = &self.rows[slot];
        Vec4::new(
            row[half * 4],
            row[half * 4 + 1],
            row[half * 4 + 2],
            row[half * 4 + 3],
        )
    }
}

/// A node's dequantised child planes next to what the walk needs of obvhs's node, so one
/// node is one contiguous read: 256 bytes, aligned to cache lines (the node index becomes a
/// shift, and a node never straddles a fifth line).
#[derive(Clone, Debug, Default, PartialEq)]
#[repr(align(64))]
pub(crate) struct WideNode {
    pub(crate) planes: NodePlanes,
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
    fn new(node: &CwBvhNode, scale: BuildScale) -> Option<WideNode> {
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
            planes: dequantise(node, scale),
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
    /// The child test this BVH's walks use, fixed when it is built.
    path: ChildTestPath,
}

/// How a walk tests a node's eight children against a ray. Every path computes each
/// child's slab test with the same operations on the same operands in the same order, so
/// they touch the same children: the same visits, hits and image, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraversalPath {
    /// Two 4-lane halves with SSE2, which every x86-64 has.
    Baseline,
    /// All eight children in one 8-lane register (AVX2).
    Avx2,
    /// The AVX2 test's eight lanes with AVX-512's compare into a mask register, in a walk
    /// compiled for AVX-512 F and VL (32 vector registers) but never using 512-bit ones,
    /// which slow the other vector work and, on some CPUs, the clock.
    Avx512,
}

impl TraversalPath {
    pub const ALL: [TraversalPath; 3] = [
        TraversalPath::Baseline,
        TraversalPath::Avx2,
        TraversalPath::Avx512,
    ];

    /// The fastest path this CPU runs (asked at run time), which new BVHs use unless a
    /// path is forced ([`force_traversal_path`]).
    pub fn fastest() -> TraversalPath {
        ChildTestPath::fastest().public()
    }

    /// The path BVHs built now get: the forced one ([`force_traversal_path`]), else the
    /// fastest.
    pub fn chosen() -> TraversalPath {
        ChildTestPath::choose().public()
    }

    /// Whether this CPU can run the path.
    pub fn available(self) -> bool {
        ChildTestPath::of(self).is_some()
    }

    /// The name `--stats` and the bench print, and `WHITTED_TRAVERSAL` takes.
    pub fn name(self) -> &'static str {
        match self {
            TraversalPath::Baseline => "baseline",
            TraversalPath::Avx2 => "avx2",
            TraversalPath::Avx512 => "avx512",
        }
    }

    /// The path named `name` ([`TraversalPath::name`]).
    pub fn from_name(name: &str) -> Option<TraversalPath> {
        TraversalPath::ALL.into_iter().find(|p| p.name() == name)
    }
}

/// The CPU lacks what a forced [`TraversalPath`] needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PathUnavailable(pub TraversalPath);

impl std::fmt::Display for PathUnavailable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "this CPU cannot run the {} BVH traversal (it lacks the instructions)",
            self.0.name()
        )
    }
}

impl std::error::Error for PathUnavailable {}

/// The path [`force_traversal_path`] asked for: 0 for none, else 1 + its index in
/// [`TraversalPath::ALL`] (its discriminant).
static FORCED_PATH: AtomicU8 = AtomicU8::new(0);

/// Makes every BVH built from now on in this process walk with `path`, or with the fastest
/// the CPU runs when `None` (the default); BVHs already built keep theirs. For tests and for
/// comparing the paths' speed: the image does not depend on the choice.
pub fn force_traversal_path(path: Option<TraversalPath>) -> Result<(), PathUnavailable> {
    let code = match path {
        None => 0,
        Some(path) if path.available() => 1 + path as u8,
        Some(path) => return Err(PathUnavailable(path)),
    };
    FORCED_PATH.store(code, Ordering::Relaxed);
    Ok(())
}

/// A [`TraversalPath`] with the proof that this CPU can run it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ChildTestPath {
    Baseline,
    Simd(SimdPath),
}

impl ChildTestPath {
    fn of(path: TraversalPath) -> Option<ChildTestPath> {
        match path {
            TraversalPath::Baseline => Some(ChildTestPath::Baseline),
            _ => SimdPath::detect(path).map(ChildTestPath::Simd),
        }
    }

    fn fastest() -> ChildTestPath {
        [TraversalPath::Avx512, TraversalPath::Avx2]
            .into_iter()
            .find_map(ChildTestPath::of)
            .unwrap_or(ChildTestPath::Baseline)
    }

    /// The forced path, else the fastest; asked once per BVH, not per ray.
    fn choose() -> ChildTestPath {
        let forced = usize::from(FORCED_PATH.load(Ordering::Relaxed));
        forced
            .checked_sub(1)
            .and_then(|i| TraversalPath::ALL.get(i))
            .and_then(|&path| ChildTestPath::of(path))
            .unwrap_or_else(ChildTestPath::fastest)
    }

    fn public(self) -> TraversalPath {
        match self {
            ChildTestPath::Baseline => TraversalPath::Baseline,
            ChildTestPath::Simd(simd) => simd.path(),
        }
    }
}

/// A node's child test, with the ray prepared once per query: which children's boxes the
/// segment `(tmin, tmax)` touches, a bit per slot. Along an axis the ray travels towards
/// −axis (`OCT` has a zero bit), the max plane is met first.
pub(crate) trait ChildTest {
    fn touched<const OCT: u32>(&self, node: &WideNode, tmax: f32) -> u32;
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

/// Our binary BVH (see `binary`) converted by obvhs, with leaves of up to three
/// primitives as `BvhBuildParams::medium_build()` would make them; the boxes it holds are
/// in build space, `scale` times the world. The walk's tests compare with obvhs's nodes;
/// builds convert with `wide`, which makes the same nodes.
#[cfg(test)]
fn build_cwbvh(aabbs: &[Aabb]) -> (CwBvh, BuildScale) {
    let built = crate::binary::build_bvh2(aabbs);
    let cwbvh = obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(&built.tree.to_bvh2(), 3, true, false);
    (cwbvh, built.scale)
}

/// Wide nodes expanded per parallel task.
const EXPAND_CHUNK: usize = 1024;

/// How many primitives a finished build may hold in total before ids overflow u32.
pub const MAX_PRIMITIVES: usize = u32::MAX as usize;

impl Bvh {
    /// Builds the binary BVH (`binary`, parallel on the current rayon pool) and converts
    /// it into obvhs's wide nodes (`wide`). Returns the BVH and `primitive_indices`: the input index of each
    /// BVH primitive id.
    pub fn build(aabbs: &[Aabb]) -> (Bvh, Vec<u32>) {
        let mut input_index: Vec<u32> = (0..aabbs.len() as u32).collect();
        match Self::build_ordering(boxes_of(aabbs), &mut input_index) {
            Some(bvh) => (bvh, input_index),
            None => (Bvh::new(Vec::new()), Vec::new()),
        }
    }

    /// Builds the BVH over `boxes` (see [`PrimitiveBox`]), one for each of `items`, and
    /// puts the items in its primitive order: primitive id `k` is `items[k]` afterwards.
    /// The boxes become the binary tree's leaves in place and the items are moved in place
    /// ([`permute_in_place`]), so that a million of either are never copied. `None` when
    /// no BVH could be made (a node the walk cannot read, which obvhs's layout rules out,
    /// or not one box for each item); the items are then as they were.
    ///
    /// [`permute_in_place`]: crate::permute::permute_in_place
    pub fn build_ordering<T>(boxes: Vec<PrimitiveBox>, items: &mut [T]) -> Option<Bvh> {
        if boxes.len() != items.len() {
            return None;
        }
        let (bvh, mut order) = Self::from_built(build_boxes(boxes));
        (!bvh.nodes.is_empty() && permute_checked(items, &mut order)).then_some(bvh)
    }

    /// [`Bvh::build`] with the binned SAH at every size, never a Morton-ordered top: for a
    /// mesh, whose triangles vary in size and orientation, the binned SAH's tree rendered
    /// the 1,000,000-triangle bench mesh 7% faster (0.44 against 0.47 CPU-seconds, one
    /// thread), which is worth its 0.3 s more build (the spheres of a big scene render as
    /// fast either way).
    pub fn build_binned_sah(aabbs: &[Aabb]) -> (Bvh, Vec<u32>) {
        Self::from_built(build_boxes_with(boxes_of(aabbs), usize::MAX))
    }

    fn new(nodes: Vec<WideNode>) -> Bvh {
        Bvh {
            nodes,
            path: ChildTestPath::choose(),
        }
    }

    /// Converts the binary tree into obvhs's 80-byte wide nodes, frees the binary tree,
    /// and only then expands the nodes into the walk's 256-byte ones: the binary tree (44
    /// bytes a primitive) and the walk's nodes (about 30) are never alive together.
    fn from_built(built: Built) -> (Bvh, Vec<u32>) {
        let scale = built.scale;
        match wide::convert(&built.tree, |node| Some(*node)) {
            Some((nodes, primitive_indices)) => {
                drop(built);
                Self::from_wide_nodes(nodes, primitive_indices, scale)
            }
            // A tree obvhs's converter reads outside its tables on: whatever obvhs makes of
            // it, as before.
            None => {
                let bvh2 = built.tree.to_bvh2();
                drop(built);
                let cwbvh = obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh(&bvh2, 3, true, false);
                Self::from_cwbvh(cwbvh, scale)
            }
        }
    }

    fn from_cwbvh(cwbvh: CwBvh, scale: BuildScale) -> (Bvh, Vec<u32>) {
        Self::from_wide_nodes(cwbvh.nodes, cwbvh.primitive_indices, scale)
    }

    /// The walk's nodes from obvhs's (in parallel, straight into their array), or no BVH
    /// when a node's metadata is not laid out as obvhs documents (see [`WideNode::new`]).
    fn from_wide_nodes(
        cwbvh_nodes: Vec<CwBvhNode>,
        primitive_indices: Vec<u32>,
        scale: BuildScale,
    ) -> (Bvh, Vec<u32>) {
        let refused = AtomicBool::new(false);
        let nodes: Vec<WideNode> = cwbvh_nodes
            .par_iter()
            .with_min_len(EXPAND_CHUNK)
            .map(|node| {
                WideNode::new(node, scale).unwrap_or_else(|| {
                    refused.store(true, Ordering::Relaxed);
                    WideNode::default()
                })
            })
            .collect();
        drop(cwbvh_nodes);
        if refused.into_inner() {
            // The caller then tests every item.
            return (Bvh::new(Vec::new()), Vec::new());
        }
        (Bvh::new(nodes), primitive_indices)
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
        self.traverse_groups(ray, tmin, tmax, stack, one_by_one(visit));
    }

    /// [`Bvh::traverse`] a node at a time: `visit_group(base, bits, tmax)` is shown the
    /// primitives of the leaves the segment touches at one node, `base + i` for each set
    /// bit `i` of `bits`, which [`Bvh::traverse`] visits from the highest bit down. A
    /// visitor that tests them together (several in SIMD lanes) and then takes their
    /// results in that order sees exactly what `traverse`'s visitor sees. It returns
    /// `Step::Shrink` with the last `tmax` it shrank to, or `Step::Stop`.
    #[inline]
    pub fn traverse_groups(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        stack: &mut Vec<UVec2>,
        visit_group: impl FnMut(u32, u32, f32) -> Step,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        match self.path {
            ChildTestPath::Baseline => {
                self.traverse_with(&NodeQuery::new(ray, tmin), ray, tmax, stack, visit_group);
            }
            ChildTestPath::Simd(simd) => {
                simd::traverse(simd, self, ray, tmin, tmax, stack, visit_group);
            }
        }
    }

    /// [`Bvh::traverse`] with a given child test, whose query holds the ray and `tmin`.
    #[inline(always)]
    pub(crate) fn traverse_with(
        &self,
        query: &impl ChildTest,
        ray: &Ray,
        tmax: f32,
        stack: &mut Vec<UVec2>,
        visit_group: impl FnMut(u32, u32, f32) -> Step,
    ) {
        // One walk per octant of the direction, so that the near and far planes of each
        // axis and the order of inner children are constants inside the loop.
        match octant_inv4(ray.direction) & 0b111 {
            0 => self.traverse_octant::<0>(query, tmax, stack, visit_group),
            1 => self.traverse_octant::<1>(query, tmax, stack, visit_group),
            2 => self.traverse_octant::<2>(query, tmax, stack, visit_group),
            3 => self.traverse_octant::<3>(query, tmax, stack, visit_group),
            4 => self.traverse_octant::<4>(query, tmax, stack, visit_group),
            5 => self.traverse_octant::<5>(query, tmax, stack, visit_group),
            6 => self.traverse_octant::<6>(query, tmax, stack, visit_group),
            _ => self.traverse_octant::<7>(query, tmax, stack, visit_group),
        }
    }

    /// [`Bvh::traverse`] for rays whose `octant_inv4` code is `OCT` in every byte.
    #[inline(always)]
    fn traverse_octant<const OCT: u32>(
        &self,
        query: &impl ChildTest,
        tmax: f32,
        stack: &mut Vec<UVec2>,
        mut visit_group: impl FnMut(u32, u32, f32) -> Step,
    ) {
        let mut tmax = tmax;
        let inner_order = &INNER_ORDER[OCT as usize];
        stack.clear();
        let mut current_group = UVec2::new(0, 0x8000_0000);
        let mut primitive_group = UVec2::ZERO;
        loop {
            if primitive_group.y != 0 {
                match visit_group(primitive_group.x, primitive_group.y, tmax) {
                    Step::Continue => {}
                    Step::Shrink(t) => tmax = t,
                    Step::Stop => return,
                }
                primitive_group.y = 0;
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

    /// Walks the BVH with up to [`PACKET`] rays at once, each seeing exactly what
    /// [`Bvh::traverse`] would show it, in the same order: `visit(r, id, tmax)` is called
    /// for ray `r` with its own `tmax[r]`, which it may shrink, or stop that ray. Returns
    /// false, having visited nothing, when the rays do not all travel into the same octant
    /// (the walk's child order depends on it); then the caller walks them one by one.
    ///
    /// Why the visits are the same: the single walk is a depth-first walk over a child
    /// order fixed by the octant, in which a ray enters a child when its own test at the
    /// parent (with its `tmax` then) touched it, and looks at a node's primitives before its
    /// children. The packet walks the same order over the union of what its rays touch,
    /// and keeps for every pending node which rays touched it; each ray's tests are the
    /// single walk's, bit for bit. What the packet shares is each node's load and the
    /// walk's bookkeeping, and its rays' box tests, independent of each other, overlap
    /// instead of waiting one behind the other.
    pub fn traverse_packet(
        &self,
        rays: &[Ray],
        tmin: f32,
        tmax: &mut [f32; PACKET],
        stack: &mut Vec<PacketEntry>,
        visit: impl FnMut(usize, u32, f32) -> Step,
    ) -> bool {
        let Some(first) = rays.first() else {
            return true;
        };
        let octant = octant_inv4(first.direction);
        if rays.len() > PACKET || rays.iter().any(|r| octant_inv4(r.direction) != octant) {
            return false;
        }
        if self.nodes.is_empty() {
            return true;
        }
        match self.path {
            ChildTestPath::Baseline => {
                let test = &PerRayTest::new(rays, |ray| NodeQuery::new(ray, tmin));
                self.traverse_packet_with(test, rays, tmax, stack, visit);
            }
            ChildTestPath::Simd(simd) => {
                simd::traverse_packet(simd, self, rays, tmin, tmax, stack, visit);
            }
        }
        true
    }

    /// [`Bvh::traverse_packet`] of rays already checked to share an octant, with a given
    /// child test, whose queries hold the rays and `tmin`.
    #[inline(always)]
    pub(crate) fn traverse_packet_with<Q: ChildTest>(
        &self,
        test: &PerRayTest<Q>,
        rays: &[Ray],
        tmax: &mut [f32; PACKET],
        stack: &mut Vec<PacketEntry>,
        visit: impl FnMut(usize, u32, f32) -> Step,
    ) {
        let Some(first) = rays.first() else {
            return;
        };
        let count = rays.len();
        // As in `traverse`: a walk per octant, its near and far planes constants.
        match octant_inv4(first.direction) & 0b111 {
            0 => self.traverse_packet_octant::<0, Q>(test, count, tmax, stack, visit),
            1 => self.traverse_packet_octant::<1, Q>(test, count, tmax, stack, visit),
            2 => self.traverse_packet_octant::<2, Q>(test, count, tmax, stack, visit),
            3 => self.traverse_packet_octant::<3, Q>(test, count, tmax, stack, visit),
            4 => self.traverse_packet_octant::<4, Q>(test, count, tmax, stack, visit),
            5 => self.traverse_packet_octant::<5, Q>(test, count, tmax, stack, visit),
            6 => self.traverse_packet_octant::<6, Q>(test, count, tmax, stack, visit),
            _ => self.traverse_packet_octant::<7, Q>(test, count, tmax, stack, visit),
        }
    }

    /// [`Bvh::traverse_packet`] for rays whose `octant_inv4` code is `OCT` in every byte.
    #[inline(always)]
    fn traverse_packet_octant<const OCT: u32, Q: ChildTest>(
        &self,
        test: &PerRayTest<Q>,
        count: usize,
        tmax: &mut [f32; PACKET],
        stack: &mut Vec<PacketEntry>,
        mut visit: impl FnMut(usize, u32, f32) -> Step,
    ) {
        let count = count.min(PACKET);
        let inner_order = &INNER_ORDER[OCT as usize];
        // Rays that have not stopped.
        let mut alive = (1u32 << count) - 1;
        stack.clear();
        stack.push(PacketEntry {
            node: 0,
            rays: alive as u8,
        });
        while let Some(entry) = stack.pop() {
            let active = u32::from(entry.rays) & alive;
            if active == 0 {
                continue;
            }
            let Some(node) = self.nodes.get(entry.node as usize) else {
                return;
            };
            // Which active rays touch each child slot (every ray's own single-walk test).
            let child_rays = test.child_rays::<OCT>(node, tmax, active);
            // Each ray's primitives: those of the leaves it touches, in the single walk's
            // order (highest bit first).
            let mut primitives = [0u32; PACKET];
            let mut leaves = !node.imask & 0xff;
            while leaves != 0 {
                let slot = leaves.trailing_zeros() as usize & 7;
                leaves &= leaves - 1;
                let mut rays = u32::from(child_rays[slot]);
                while rays != 0 {
                    let r = rays.trailing_zeros() as usize & (PACKET - 1);
                    rays &= rays - 1;
                    primitives[r] |= node.leaf_bits[slot];
                }
            }
            for (r, bits) in primitives.iter_mut().enumerate() {
                while *bits != 0 {
                    let local = first_bit_high(*bits);
                    *bits &= !(1u32 << local);
                    match visit(r, node.primitive_base + local, tmax[r]) {
                        Step::Continue => {}
                        Step::Shrink(t) => tmax[r] = t,
                        Step::Stop => {
                            alive &= !(1u32 << r);
                            break;
                        }
                    }
                }
            }
            // The inner children that rays still walking touched. The single walk enters
            // the child of the highest ordered bit first: pushed last, it is popped first.
            let mut union = 0u32;
            let mut inner = node.imask & 0xff;
            while inner != 0 {
                let slot = inner.trailing_zeros();
                inner &= inner - 1;
                if u32::from(child_rays[slot as usize & 7]) & alive != 0 {
                    union |= 1 << slot;
                }
            }
            let mut order = u32::from(inner_order[union as usize & 0xff]);
            while order != 0 {
                let bit = order.trailing_zeros();
                order &= order - 1;
                let slot = ((bit ^ OCT) & 7) as usize;
                let below = INNER_BELOW[(node.imask & 0xff) as usize][slot];
                stack.push(PacketEntry {
                    node: node.child_base + u32::from(below),
                    rays: child_rays[slot] & alive as u8,
                });
            }
        }
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }
}

/// At most this many rays walk the BVH together ([`Bvh::traverse_packet`]).
pub const PACKET: usize = 8;

/// A packet's child test: each ray's own single-walk test ([`ChildTest::touched`]), one
/// ray after another. (An AVX2 test of one child against all eight rays at once visits the
/// same and was measured no faster: see ARCHITECTURE.md.)
pub(crate) struct PerRayTest<Q> {
    queries: [Q; PACKET],
}

impl<Q: ChildTest> PerRayTest<Q> {
    /// The queries of up to [`PACKET`] rays (the last repeated to fill the packet; a
    /// packet of no rays walks nothing, so any ray will do for it).
    #[inline(always)]
    pub(crate) fn new(rays: &[Ray], mut query: impl FnMut(&Ray) -> Q) -> PerRayTest<Q> {
        let last = rays.len().clamp(1, PACKET) - 1;
        let spare = Ray::new(Vec3A::ZERO, Vec3A::X);
        PerRayTest {
            queries: std::array::from_fn(|r| query(rays.get(r.min(last)).unwrap_or(&spare))),
        }
    }
}

impl<Q: ChildTest> PerRayTest<Q> {
    /// For each child slot of `node`, which of the `active` rays' segments
    /// `(tmin, tmax[r])` touch its box.
    #[inline(always)]
    fn child_rays<const OCT: u32>(
        &self,
        node: &WideNode,
        tmax: &[f32; PACKET],
        active: u32,
    ) -> [u8; 8] {
        let mut child_rays = [0u8; 8];
        let mut each = active;
        while each != 0 {
            let r = each.trailing_zeros() as usize & (PACKET - 1);
            each &= each - 1;
            let mut touched = self.queries[r].touched::<OCT>(node, tmax[r]);
            while touched != 0 {
                let slot = touched.trailing_zeros() as usize & 7;
                touched &= touched - 1;
                child_rays[slot] |= 1 << r;
            }
        }
        child_rays
    }
}

/// A node the packet walk has still to visit, and which of its rays touched it.
#[derive(Clone, Copy, Debug, Default)]
pub struct PacketEntry {
    node: u32,
    rays: u8,
}

/// The ray, prepared once per query for the baseline's slab tests.
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
}

impl ChildTest for NodeQuery {
    #[inline(always)]
    fn touched<const OCT: u32>(&self, node: &WideNode, tmax: f32) -> u32 {
        let tmax = Vec4::splat(tmax);
        let mut touched = 0u32;
        for half in 0..2 {
            let mut enter = self.tmin;
            let mut exit = tmax;
            for axis in 0..3 {
                let backwards = usize::from(OCT & (4 >> axis) == 0);
                let near_plane = node.planes.quarter(axis * 2 + backwards, half);
                let far_plane = node.planes.quarter(axis * 2 + 1 - backwards, half);
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

/// A group visitor ([`Bvh::traverse_groups`]) that shows `visit` the group's primitives
/// one at a time, from the highest bit down, as the walk always has.
#[inline(always)]
fn one_by_one(mut visit: impl FnMut(u32, f32) -> Step) -> impl FnMut(u32, u32, f32) -> Step {
    #[inline(always)]
    move |base, mut bits, mut tmax| {
        let mut step = Step::Continue;
        while bits != 0 {
            let local = first_bit_high(bits);
            bits &= !(1u32 << local);
            match visit(base + local, tmax) {
                Step::Continue => {}
                Step::Shrink(t) => {
                    tmax = t;
                    step = Step::Shrink(t);
                }
                Step::Stop => return Step::Stop,
            }
        }
        step
    }
}

#[inline(always)]
fn first_bit_high(value: u32) -> u32 {
    31 - value.leading_zeros()
}

/// obvhs's octant code for child ordering, from the sign bits of the direction. The sign
/// bit, not `< 0.0`, must decide: [`inverse_direction`] turns a −0.0 component into −1/ε,
/// and the walk's near and far planes must agree with that sign, or every box is missed
/// (obvhs's own `ray_get_octant_inv4` compares with `< 0.0` and has that bug). For a −0.0
/// component the order is obvhs's order for a direction with a tiny negative component.
#[inline(always)]
fn octant_inv4(direction: Vec3A) -> u32 {
    (if direction.x.is_sign_negative() {
        0
    } else {
        0x0404_0404
    }) | (if direction.y.is_sign_negative() {
        0
    } else {
        0x0202_0202
    }) | (if direction.z.is_sign_negative() {
        0
    } else {
        0x0101_0101
    })
}

/// The world-space f32 planes of a node's children, rounded outwards. The quantised plane
/// is `p + 2^e·q` exactly (a power of two times a byte) in build space; divided by the build
/// scale (a power of two) in f64 it is exact in world space, and then moved to the f32 on
/// the conservative side (infinite where the world plane is beyond f32's range).
fn dequantise(node: &CwBvhNode, build_scale: BuildScale) -> NodePlanes {
    let unscale = build_scale.factor().recip();
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
            let exact = (origin + scale * f64::from(bytes[child])) * unscale;
            out.rows[slot][child] = if is_max {
                round_up(exact)
            } else {
                round_down(exact)
            };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Random;
    use obvhs::cwbvh::node::extract_byte64;

    /// The walk as it was first written, straight from obvhs's `traverse!` (hit masks from
    /// `get_child_and_index_bits`, child indices by popcount, the octant read at run time),
    /// over the same dequantised planes: the fast walk must visit exactly what this visits,
    /// in the same order, whatever the visitor does with `tmax`.
    fn reference_walk(
        bvh: &Bvh,
        cwbvh: &CwBvh,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        mut visit: impl FnMut(u32, f32) -> Step,
    ) {
        if bvh.nodes.is_empty() {
            return;
        }
        let query = NodeQuery::new(ray, tmin);
        let backwards = [
            ray.direction.x.is_sign_negative(),
            ray.direction.y.is_sign_negative(),
            ray.direction.z.is_sign_negative(),
        ];
        let mut tmax = tmax;
        let oct_inv4 = octant_inv4(ray.direction);
        let mut stack = Vec::new();
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
                let node = &cwbvh.nodes[index];
                let planes = &bvh.nodes[index].planes;
                let mut touched = 0u32;
                for half in 0..2 {
                    let mut enter = query.tmin;
                    let mut exit = Vec4::splat(tmax);
                    for (axis, &backwards) in backwards.iter().enumerate() {
                        let b = usize::from(backwards);
                        let t_near = (planes.quarter(axis * 2 + b, half) - query.origin[axis])
                            * query.inv_direction[axis];
                        let t_far = (planes.quarter(axis * 2 + 1 - b, half) - query.origin[axis])
                            * query.inv_direction[axis];
                        enter = enter.max(t_near);
                        exit = exit.min(t_far);
                    }
                    touched |= enter.cmple(exit).bitmask() << (half * 4);
                }
                let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
                let mut hitmask = 0u32;
                while touched != 0 {
                    let child = touched.trailing_zeros() as usize;
                    touched &= touched - 1;
                    hitmask |=
                        extract_byte64(child_bits8, child) << extract_byte64(bit_index8, child);
                }
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

    /// Records a visit; mode 0 sees everything, mode 1 shrinks `tmax` to a distance derived
    /// from the id, mode 2 stops at the fifth primitive.
    fn logging_visit(log: &mut Vec<(u32, u32)>, mode: u32, id: u32, tmax: f32) -> Step {
        log.push((id, tmax.to_bits()));
        match mode {
            1 if id.is_multiple_of(3) => Step::Shrink(tmax.min(5.0 + (id % 50) as f32)),
            2 if log.len() == 5 => Step::Stop,
            _ => Step::Continue,
        }
    }

    /// Visits recorded by the fast walk and by the reference walk agree id for id, for
    /// rays in every octant, with and without a visitor that shrinks `tmax` or stops.
    #[test]
    fn the_walk_visits_in_obvhs_order() {
        let mut rng = Random(0x9e37_79b9);
        let aabbs = rng.cloud(3000);
        let mut random = move || rng.unit();
        let (cwbvh, scale) = build_cwbvh(&aabbs);
        let (bvh, _) = Bvh::from_cwbvh(cwbvh.clone(), scale);
        assert!(bvh.node_count() > 100);
        let mut stack = Vec::new();
        let mut compared = 0;
        for k in 0..600 {
            // From anywhere around the cloud of boxes towards a point inside it.
            let origin = Vec3A::new(random(), random(), random()) * 80.0 - 20.0;
            let target = Vec3A::new(random(), random(), random()) * 40.0;
            let mut direction = target - origin;
            // Some axis-parallel directions, and a negative zero, for the slab edge cases.
            match k % 7 {
                0 => direction.x = 0.0,
                1 => direction.y = -0.0,
                _ => {}
            }
            let ray = Ray::new(origin, direction.normalize());
            for mode in 0..3u32 {
                let mut fast = Vec::new();
                bvh.traverse(&ray, 1e-3, f32::INFINITY, &mut stack, |id, tmax| {
                    logging_visit(&mut fast, mode, id, tmax)
                });
                let mut reference = Vec::new();
                reference_walk(&bvh, &cwbvh, &ray, 1e-3, f32::INFINITY, |id, tmax| {
                    logging_visit(&mut reference, mode, id, tmax)
                });
                assert_eq!(fast, reference, "ray {k}, mode {mode}");
                compared += fast.len();
            }
        }
        assert!(compared > 10_000, "{compared}");
    }

    /// Each ray of a packet sees exactly the visits, with the same `tmax`, that it sees
    /// walking alone, whatever the visitor does: coherent packets (neighbouring camera
    /// rays), incoherent ones (any rays of one octant), partial ones, with axis-parallel
    /// directions and negative zeros among them.
    #[test]
    fn a_packet_walk_shows_each_ray_its_single_walk() {
        let mut rng = Random(0x2545_f491);
        let aabbs = rng.cloud(4000);
        let mut random = move || rng.unit();
        let (bvh, _) = Bvh::build(&aabbs);
        let mut stack = Vec::new();
        let mut packet_stack = Vec::new();
        let (mut compared, mut packets) = (0, 0);
        for k in 0..400 {
            let eye = Vec3A::new(random(), random(), random()) * 80.0 - 20.0;
            let target = Vec3A::new(random(), random(), random()) * 40.0;
            let coherent = k % 2 == 0;
            let count = if k % 5 == 0 { 1 + k % 8 } else { PACKET };
            let mut rays: Vec<Ray> = Vec::new();
            let mut attempt = 0usize;
            while rays.len() < count {
                attempt += 1;
                let (origin, mut direction) = if coherent {
                    let jitter = Vec3A::new(random(), random(), random()) - 0.5;
                    (eye, target + jitter * 2.0 - eye)
                } else {
                    let origin = Vec3A::new(random(), random(), random()) * 80.0 - 20.0;
                    (origin, target - origin)
                };
                match (k + attempt) % 9 {
                    0 => direction.x = 0.0,
                    1 => direction.y = -0.0,
                    2 => direction.z = direction.z.signum() * 0.0,
                    _ => {}
                }
                let ray = Ray::new(origin, direction.normalize_or(Vec3A::X));
                let same_octant = rays
                    .first()
                    .is_none_or(|first| octant_inv4(first.direction) == octant_inv4(ray.direction));
                if same_octant {
                    rays.push(ray);
                }
            }
            for mode in 0..3u32 {
                let mut alone: Vec<Vec<(u32, u32)>> = vec![Vec::new(); count];
                for (log, ray) in alone.iter_mut().zip(&rays) {
                    bvh.traverse(ray, 1e-3, f32::INFINITY, &mut stack, |id, tmax| {
                        logging_visit(log, mode, id, tmax)
                    });
                }
                let mut together: Vec<Vec<(u32, u32)>> = vec![Vec::new(); count];
                let mut tmax = [f32::INFINITY; PACKET];
                let walked =
                    bvh.traverse_packet(&rays, 1e-3, &mut tmax, &mut packet_stack, |r, id, t| {
                        logging_visit(&mut together[r], mode, id, t)
                    });
                assert!(walked, "ray {k}: one octant");
                assert_eq!(together, alone, "packet {k}, mode {mode}");
                compared += alone.iter().map(Vec::len).sum::<usize>();
                packets += 1;
            }
        }
        assert!(compared > 20_000 && packets == 1200, "{compared} visits");
    }

    /// Rays that stress the slab test's edge cases against `aabbs`: from box corners and
    /// face centres along the axes (both signs, and −0.0 in the other components), along a
    /// face (grazing), corner to corner (touching boxes exactly at their edges), and random
    /// rays through the set.
    fn awkward_rays(aabbs: &[Aabb], random: &mut Random) -> Vec<Ray> {
        let axes = [Vec3A::X, Vec3A::Y, Vec3A::Z];
        let mut rays = Vec::new();
        let step = (aabbs.len() / 40).max(1);
        for (i, aabb) in aabbs.iter().enumerate().step_by(step) {
            let (lo, hi) = (aabb.min, aabb.max);
            let centre = (lo + hi) * 0.5;
            let size = (hi - lo).max_element().max(1.0);
            let other = &aabbs[(i * 7 + 3) % aabbs.len()];
            for axis in axes {
                let negative_zeros = Vec3A::select(axis.cmpeq(Vec3A::ZERO), -Vec3A::ZERO, axis);
                let on_face = Vec3A::select(axis.cmpeq(Vec3A::ZERO), centre, lo);
                for direction in [axis, -axis, negative_zeros] {
                    rays.push(Ray::new(on_face, direction));
                    rays.push(Ray::new(centre - direction * size * 4.0, direction));
                }
                let along_face = (Vec3A::ONE - axis).normalize();
                rays.push(Ray::new(lo, along_face));
                rays.push(Ray::new(hi, -along_face));
            }
            rays.push(Ray::new(lo, (other.max - lo).normalize_or(Vec3A::X)));
            rays.push(Ray::new(hi, (other.min - hi).normalize_or(Vec3A::Y)));
            let from = centre + (random.vec() - 0.5) * size * 8.0;
            rays.push(Ray::new(from, (centre - from).normalize_or(Vec3A::Z)));
        }
        rays
    }

    /// Every traversal path this CPU runs visits exactly what the baseline visits, in the
    /// same order with the same `tmax`, alone and in packets, on every kind of box set
    /// (huge and tiny coordinates, flat and coincident boxes, shared faces), with awkward
    /// rays and visitors that shrink `tmax` and stop. (The image test over every golden
    /// scene is the integration test `traversal_paths`.)
    #[test]
    #[allow(clippy::print_stderr)]
    fn every_traversal_path_visits_what_the_baseline_visits() {
        let paths: Vec<ChildTestPath> = TraversalPath::ALL
            .into_iter()
            .filter_map(ChildTestPath::of)
            .filter(|&p| p != ChildTestPath::Baseline)
            .collect();
        if paths.is_empty() {
            eprintln!("SKIPPED: this CPU runs only the baseline BVH walk");
            return;
        }
        let mut random = Random(0x5eed_1234);
        let mut sets = crate::testing::inputs();
        // Boxes sharing faces and edges exactly, and a flat one across them.
        let mut shared: Vec<Aabb> = (0..60)
            .map(|i| {
                let corner = Vec3A::new(i as f32, 20.0, (i % 3) as f32);
                Aabb::new(corner, corner + 1.0)
            })
            .collect();
        shared.push(Aabb::new(
            Vec3A::new(-3.0, 19.0, 1.0),
            Vec3A::new(63.0, 23.0, 1.0),
        ));
        sets.push(("shared faces".to_string(), shared));
        let (mut stack, mut packet_stack) = (Vec::new(), Vec::new());
        let (mut compared, mut packets) = (0usize, 0usize);
        for (name, aabbs) in sets.iter().filter(|(_, a)| !a.is_empty()) {
            let (mut bvh, _) = Bvh::build(aabbs);
            let mut rays = awkward_rays(aabbs, &mut random);
            // Grouped by octant (stably), so that nearly every packet below can walk.
            rays.sort_by_key(|ray| octant_inv4(ray.direction));
            for (mode, tmin) in (0..3u32).flat_map(|m| [(m, 0.0), (m, 1e-3)]) {
                let mut logs = Vec::new();
                for path in std::iter::once(ChildTestPath::Baseline).chain(paths.iter().copied()) {
                    bvh.path = path;
                    let mut alone: Vec<Vec<(u32, u32)>> = vec![Vec::new(); rays.len()];
                    for (log, ray) in alone.iter_mut().zip(&rays) {
                        bvh.traverse(ray, tmin, f32::INFINITY, &mut stack, |id, tmax| {
                            logging_visit(log, mode, id, tmax)
                        });
                    }
                    // The same rays in packets of up to eight neighbours; a packet that
                    // straddles two octants is refused and compares as empty logs.
                    let mut together: Vec<Vec<(u32, u32)>> = vec![Vec::new(); rays.len()];
                    for (start, chunk) in rays.chunks(PACKET).enumerate() {
                        let mut tmax = [f32::INFINITY; PACKET];
                        let logs = &mut together[start * PACKET..];
                        let walked = bvh.traverse_packet(
                            chunk,
                            tmin,
                            &mut tmax,
                            &mut packet_stack,
                            |r, id, t| logging_visit(&mut logs[r], mode, id, t),
                        );
                        if walked {
                            packets += 1;
                        } else {
                            logs[..chunk.len()].iter_mut().for_each(Vec::clear);
                        }
                    }
                    logs.push((path, alone, together));
                }
                let (_, base_alone, base_together) = &logs[0];
                for (path, alone, together) in &logs[1..] {
                    for (k, ray) in rays.iter().enumerate() {
                        assert_eq!(
                            alone[k], base_alone[k],
                            "{name}: {path:?} alone, ray {k} {ray:?}, mode {mode}, tmin {tmin}"
                        );
                        assert_eq!(
                            together[k], base_together[k],
                            "{name}: {path:?} in a packet, ray {k} {ray:?}, mode {mode}"
                        );
                    }
                    compared += alone.iter().chain(together).map(Vec::len).sum::<usize>();
                }
            }
        }
        assert!(compared > 100_000, "{compared} visits compared");
        // Each packet is counted once per path and mode; nearly all of them walked.
        assert!(packets > 30_000, "only {packets} packets walked");
    }

    /// Forcing a path is what BVHs built next get and what `chosen` reports; a path the
    /// CPU lacks is refused; `None` goes back to the fastest.
    #[test]
    fn a_forced_path_is_what_new_bvhs_walk_with() {
        for path in TraversalPath::ALL {
            if !path.available() {
                assert_eq!(force_traversal_path(Some(path)), Err(PathUnavailable(path)));
                continue;
            }
            assert_eq!(force_traversal_path(Some(path)), Ok(()));
            assert_eq!(TraversalPath::chosen(), path);
            assert_eq!(Bvh::build(&boxes(20)).0.path.public(), path);
        }
        assert_eq!(force_traversal_path(None), Ok(()));
        assert_eq!(TraversalPath::chosen(), TraversalPath::fastest());
        assert_eq!(TraversalPath::from_name("avx2"), Some(TraversalPath::Avx2));
        assert_eq!(TraversalPath::from_name("AVX2"), None);
    }

    /// Rays of different octants are refused, untouched, for the caller to walk alone.
    #[test]
    fn a_packet_of_mixed_octants_is_refused() {
        let (bvh, _) = Bvh::build(&boxes(100));
        let rays = [
            Ray::new(Vec3A::ZERO, Vec3A::X),
            Ray::new(Vec3A::ZERO, Vec3A::NEG_X),
        ];
        let mut tmax = [f32::INFINITY; PACKET];
        let mut visits = 0;
        let walked = bvh.traverse_packet(&rays, 0.0, &mut tmax, &mut Vec::new(), |_, _, _| {
            visits += 1;
            Step::Continue
        });
        assert!(!walked);
        assert_eq!(visits, 0);
        assert!(
            bvh.traverse_packet(&rays[..1], 0.0, &mut tmax, &mut Vec::new(), |_, _, _| {
                Step::Continue
            })
        );
    }

    /// The decoded child bits give obvhs's hit masks for every touched set and octant.
    #[test]
    fn decoded_child_bits_give_obvhs_hit_masks() {
        let (cwbvh, scale) = build_cwbvh(&boxes(2000));
        for node in &cwbvh.nodes {
            let Some(wide) = WideNode::new(node, scale) else {
                panic!("obvhs wrote metadata the walk does not expect");
            };
            for oct in 0..8u32 {
                let oct_inv4 = oct * 0x0101_0101;
                let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
                for touched in 0..256u32 {
                    let mut expected = 0u32;
                    for child in (0..8).filter(|c| touched & (1 << c) != 0) {
                        expected |=
                            extract_byte64(child_bits8, child) << extract_byte64(bit_index8, child);
                    }
                    let inner =
                        u32::from(INNER_ORDER[oct as usize][(touched & wide.imask) as usize]);
                    let got = (inner << 24) | leaf_primitive_bits(&wide, touched & !wide.imask);
                    assert_eq!(got, expected, "octant {oct}, touched {touched:08b}");
                }
            }
        }
    }

    /// A build converts into obvhs's nodes, frees the binary tree and only then expands
    /// them into the walk's: what it gives is obvhs's own conversion of the same binary
    /// tree expanded node for node, with the same primitive order, for every kind of input,
    /// with and without a Morton-ordered top, and for a tree large enough to be converted
    /// and expanded in parallel chunks.
    #[test]
    fn a_build_is_obvhs_conversion_expanded() {
        let mut all = crate::testing::inputs();
        all.push(("large".into(), Random(7).cloud(40_000)));
        for (name, aabbs) in all {
            for morton_top in [false, true] {
                let top = |f: &dyn Fn() -> (Bvh, Vec<u32>)| {
                    if morton_top {
                        crate::testing::with_morton_top(f)
                    } else {
                        f()
                    }
                };
                let (bvh, indices) = top(&|| Bvh::build(&aabbs));
                let (cwbvh, scale) = if morton_top {
                    crate::testing::with_morton_top(|| build_cwbvh(&aabbs))
                } else {
                    build_cwbvh(&aabbs)
                };
                let case = format!("{name}, Morton top {morton_top}");
                // Each of obvhs's nodes expanded by itself, in order.
                let expected: Vec<WideNode> = cwbvh
                    .nodes
                    .iter()
                    .map(|node| WideNode::new(node, scale))
                    .collect::<Option<_>>()
                    .unwrap_or_else(|| panic!("{case}: a node refused"));
                assert!(!expected.is_empty(), "{case}");
                assert_eq!(bvh.nodes.len(), expected.len(), "{case}");
                assert!(bvh.nodes == expected, "{case}");
                assert_eq!(indices, cwbvh.primitive_indices, "{case}");
            }
        }
    }

    /// A node whose metadata the walk does not expect gives no BVH (the caller then tests
    /// every item), wherever it is among the nodes expanded in parallel; never a BVH with
    /// a placeholder node.
    #[test]
    fn a_refused_node_gives_no_bvh() {
        let (cwbvh, scale) = build_cwbvh(&Random(3).cloud(20_000));
        assert!(
            cwbvh.nodes.len() > 2 * EXPAND_CHUNK,
            "{}",
            cwbvh.nodes.len()
        );
        let (whole, _) = Bvh::from_cwbvh(cwbvh.clone(), scale);
        assert_eq!(whole.node_count(), cwbvh.nodes.len());
        let with_inner: Vec<usize> = (0..cwbvh.nodes.len())
            .filter(|&i| cwbvh.nodes[i].imask != 0)
            .collect();
        for &at in [with_inner[0], with_inner[with_inner.len() - 1]].iter() {
            let mut broken = cwbvh.clone();
            let node = &mut broken.nodes[at];
            let slot = node.imask.trailing_zeros() as usize;
            // Not obvhs's `24 + slot` for an inner child.
            node.child_meta[slot] = 0b0010_0000 | (24 + (slot as u8 + 1) % 8);
            let (bvh, indices) = Bvh::from_cwbvh(broken, scale);
            assert_eq!(bvh.node_count(), 0, "node {at}");
            assert!(indices.is_empty(), "node {at}");
        }
    }

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

    /// Four cache lines a node: a field more would make every node visit read a fifth.
    #[test]
    fn nodes_fill_four_cache_lines() {
        assert_eq!(std::mem::size_of::<WideNode>(), 256);
        assert_eq!(std::mem::align_of::<WideNode>(), 64);
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
