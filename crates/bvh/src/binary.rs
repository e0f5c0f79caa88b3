//! Builds the binary BVH that `wide` converts into obvhs's wide nodes: a binned SAH
//! build with a median fallback, in O(n log n) for any finite input.
//!
//! obvhs's own PLOC builder is not used, because two kinds of input break it:
//!
//! - Ties. PLOC merges two clusters only when each is the other's cheapest neighbour, and
//!   its search takes the *last* of equally cheap neighbours (`<=`), so in a run of equal
//!   costs (coincident objects, a regular row) neighbours never agree and each pass merges
//!   one pair: quadratic time and a tree as deep as the input (40,000 `sphere { }`: 35 s).
//! - Overflow. Surface areas are f32; boxes wider than about 1e19 give infinite costs, the
//!   wide-BVH converter then finds no finite split and panics (`distribute_left < 7`).
//!
//! Here boxes are first scaled by a power of two so that the largest coordinate is about
//! 2^32 (rounded outwards, so every scaled box still contains its object's scaled box; the
//! walk scales the planes back, see [`BuildScale`]): areas cannot overflow and tiny scenes
//! keep their precision. The split of a range is the best of 16 bins per axis by the
//! surface area heuristic; when the centroids coincide, or no bin split separates them, or
//! the depth passes [`SAH_DEPTH_LIMIT`], the range is split at its median instead, so the
//! depth stays below `SAH_DEPTH_LIMIT + log2(n) + 1` and every level costs O(n).
//!
//! Scenes of [`MORTON_MIN_PRIMITIVES`] or more get a cheaper top instead (a fast build for a
//! large scene, as the issue on performance asks): the primitives are sorted by the Morton
//! codes of their boxes' centroids (a 30-bit code, three radix passes) and made as leaves
//! in that order; each range is halved at the highest bit in which its codes differ (one
//! binary search, no pass over the range) until it holds at most [`MORTON_SWEEP_RANGE`]
//! primitives, and those are split where the surface area heuristic is lowest along the
//! Morton order (an exact sweep of at most 63 positions). A range whose codes are all
//! equal (coincident objects, a dense cell) goes to the binned SAH below. The nodes' bounds
//! are gathered on the way up. Measured on one thread: the 1M-sphere grid sorts and builds
//! its binary tree in 0.15 s instead of 0.50 s and renders as fast; 300,000 random spheres
//! of mixed sizes seen from inside build their BVH in 0.13 s instead of 0.35 s and render
//! within 2% (a pure Morton split down to pairs rendered 18% slower).
//!
//! For a million objects the build is bound by memory traffic, so the primitives' boxes
//! (with their input index) are moved through the partitions rather than indices to them:
//! every pass reads memory in order. Each split's partition pass also gathers the two
//! children's bounds, and each inner node gets obvhs's wide-conversion decisions on the way
//! back up (its costs need only its children's), so no pass over the tree is left for the
//! converter but the one that writes the wide nodes. The tree is the one the earlier
//! index-moving build made (the test `builds_the_tree_of_the_index_build` keeps that one):
//! the primitives of a range lie in the order its indices did. A node's bounds are
//! gathered in another order, which can change only the sign of a zero bound, and no wide
//! node keeps that (the conversion's origin does; the walk's planes do not).

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::Bvh2;
use rayon::prelude::*;
use std::sync::Mutex;

use crate::permute::permute_in_place;
use crate::wide::{decide, leaf_costs, BinaryTree, Decision};

/// Bins per axis for the surface area heuristic.
const BINS: usize = 16;

/// Below this depth splits follow the surface area heuristic; deeper ones are medians.
pub const SAH_DEPTH_LIMIT: u32 = 40;

/// Ranges at least this large are split on two threads.
const PARALLEL_RANGE: usize = 4096;

/// The power of two that boxes were multiplied by before the build: `2^exponent`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildScale {
    pub exponent: i32,
}

impl BuildScale {
    /// The scale that brings the largest coordinate of `aabbs` to about 2^32.
    fn for_boxes(boxes: &[PrimitiveBox]) -> BuildScale {
        let largest = boxes
            .iter()
            .map(|b| {
                Vec3A::from(b.min)
                    .abs()
                    .max(Vec3A::from(b.max).abs())
                    .max_element()
            })
            .fold(0.0f32, f32::max);
        if !(largest.is_finite() && largest > 0.0) {
            return BuildScale::default();
        }
        BuildScale {
            exponent: 32 - f64::from(largest).log2().ceil() as i32,
        }
    }

    /// `2^exponent` in f64 (exact for every exponent f32 boxes can need).
    pub fn factor(self) -> f64 {
        2f64.powi(self.exponent)
    }

    /// A box scaled into build space, rounded outwards.
    fn scale_box(self, aabb: &Aabb) -> Aabb {
        // Multiplying by a power of two is exact in f32 whenever the product is a normal
        // number (or the input a zero): then there is nothing to round, and the f64 path
        // below would give the same bits. Most boxes take this path (3% of building a
        // million objects' BVH went to the f64 one).
        let exact =
            |v: Vec3A, scaled: Vec3A| (0..3).all(|axis| scaled[axis].is_normal() || v[axis] == 0.0);
        if let Some(f) = self.f32_factor() {
            let (lo, hi) = (aabb.min * f, aabb.max * f);
            if exact(aabb.min, lo) && exact(aabb.max, hi) {
                return Aabb::new(lo, hi);
            }
        }
        self.scale_box_f64(aabb)
    }

    /// [`BuildScale::scale_box`] through f64, for every box.
    fn scale_box_f64(self, aabb: &Aabb) -> Aabb {
        let s = self.factor();
        let lo = aabb.min.to_array().map(|v| round_down(f64::from(v) * s));
        let hi = aabb.max.to_array().map(|v| round_up(f64::from(v) * s));
        Aabb::new(Vec3A::from(lo), Vec3A::from(hi))
    }

    /// `2^exponent` as an f32, when it is a normal one.
    fn f32_factor(self) -> Option<f32> {
        (-126..=127)
            .contains(&self.exponent)
            .then(|| f32::from_bits(((self.exponent + 127) as u32) << 23))
    }
}

/// The largest f32 not above `v`.
pub fn round_down(v: f64) -> f32 {
    let r = v as f32;
    if f64::from(r) > v {
        r.next_down()
    } else {
        r
    }
}

/// The smallest f32 not below `v`.
pub fn round_up(v: f64) -> f32 {
    let r = v as f32;
    if f64::from(r) < v {
        r.next_up()
    } else {
        r
    }
}

/// A primitive's box, as a caller hands it to the build (see [`Bvh::build_ordering`]), and
/// then in build space with its input index, as a leaf of the tree. 28 bytes (an `Aabb`
/// takes 32): the boxes are alive through the whole build and conversion, and the build
/// turns the caller's into its leaves in place.
///
/// [`Bvh::build_ordering`]: crate::Bvh::build_ordering
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrimitiveBox {
    min: [f32; 3],
    index: u32,
    max: [f32; 3],
}

impl PrimitiveBox {
    /// A box to build over; its input index is its position in what is handed over.
    pub fn new(aabb: &Aabb) -> PrimitiveBox {
        PrimitiveBox::with_index(aabb, 0)
    }

    fn with_index(aabb: &Aabb, index: u32) -> PrimitiveBox {
        PrimitiveBox {
            min: aabb.min.to_array(),
            index,
            max: aabb.max.to_array(),
        }
    }

    #[inline(always)]
    pub fn aabb(&self) -> Aabb {
        Aabb::new(Vec3A::from(self.min), Vec3A::from(self.max))
    }

    #[inline(always)]
    fn centroid(&self) -> Vec3A {
        (Vec3A::from(self.min) + Vec3A::from(self.max)) * 0.5
    }
}

/// An inner node: its two children (node ids, see [`BinaryBvh`]), where its box is, and
/// obvhs's seven conversion decisions for it. 16 bytes: one child id is kept, and the other
/// follows from the layout the builds make (see [`Inner::children`]); and only a node over
/// more than [`SMALL_SUBTREE`] primitives keeps its box (in [`BinaryBvh`]'s `boxes`), a
/// smaller one's is the union of its leaves' boxes, which lie together in the leaves. A
/// million primitives' build holds a million inner nodes through the build and the
/// conversion: 36 bytes each with their boxes, 16 without.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inner {
    /// The second child when the first is an inner node, else the first.
    link: u32,
    /// The node's first leaf (an index into the leaves) when it is small, else where its
    /// box is in `boxes`.
    place: u32,
    decisions: [Decision; 7],
    /// Bit 0: the first child is an inner node; bit 1: the second is. Bits 2 to 7: how
    /// many primitives a small node holds, 0 for a large one.
    bits: u8,
}

/// Inner nodes over at most this many primitives keep no box: it is gathered from their
/// leaves when the conversion asks. It is at most 63 (the count's six bits in
/// [`Inner::bits`]). On the 1M-sphere grid (one thread, alternated) 8, 16 and 32 built the
/// tree in the same time within the runs' spread (0.251-0.257 s); 32 keeps the fewest
/// boxes (fewer than 2n/33 unless the top of the tree has long chains).
pub const SMALL_SUBTREE: usize = 32;
const _: () = assert!(SMALL_SUBTREE <= 63, "the count has six bits");

/// A large inner node's box, as plain floats: 24 bytes (an `Aabb` takes 32).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodeBox {
    min: [f32; 3],
    max: [f32; 3],
}

impl Inner {
    /// The primitives below a small node (see [`Inner::place`]); `None` for a large one.
    fn small_count(&self) -> Option<usize> {
        let count = usize::from(self.bits >> 2);
        (count > 0).then_some(count)
    }

    /// `[first, second]` stored as [`Inner::children`] reads them back, in a tree whose
    /// leaves' ids start at `leaf_base`.
    fn link([first, second]: [u32; 2], leaf_base: u32) -> (u32, u8) {
        let first_inner = first < leaf_base;
        let second_inner = second < leaf_base;
        let link = if first_inner { second } else { first };
        (link, u8::from(first_inner) | u8::from(second_inner) << 1)
    }

    /// The children of this node, `id`. Both builds lay a subtree's inner nodes out as its
    /// root, then the first child's inner nodes, then the second's, and its leaves in
    /// order: so an inner first child is `id + 1`; when the first child is a leaf, an inner
    /// second child is `id + 1` and a leaf second child is the next leaf.
    fn children(&self, id: u32) -> [u32; 2] {
        match self.bits & 0b11 {
            0b01 | 0b11 => [id + 1, self.link],
            0b10 => [self.link, id + 1],
            _ => [self.link, self.link + 1],
        }
    }
}

/// The binary BVH: node ids below `inner.len()` are inner nodes (the root is 0 when there
/// are two primitives or more), id `inner.len() + k` is the leaf of `leaves[k]`, one
/// primitive each, in tree order; `boxes` holds the large inner nodes' boxes (in the order
/// the build's threads finished them, which only [`Inner::place`] needs to know).
#[derive(Clone, Debug, Default)]
pub struct BinaryBvh {
    inner: Vec<Inner>,
    leaves: Vec<PrimitiveBox>,
    boxes: Vec<NodeBox>,
}

impl BinaryBvh {
    fn leaf(&self, node: u32) -> &PrimitiveBox {
        &self.leaves[node as usize - self.inner.len()]
    }

    /// An inner node's box: the one kept for a large node, the union of its leaves' for a
    /// small one (a union in another order than the build's, which can differ from it only
    /// in the sign of a zero bound, as the note at the top of this module says).
    fn inner_aabb(&self, inner: &Inner) -> Aabb {
        let place = inner.place as usize;
        match inner.small_count() {
            Some(count) => self
                .leaves
                .get(place..place + count)
                .unwrap_or_default()
                .iter()
                .fold(Aabb::empty(), |bounds, leaf| bounds.union(&leaf.aabb())),
            None => self.boxes.get(place).map_or(Aabb::empty(), |b| {
                Aabb::new(Vec3A::from(b.min), Vec3A::from(b.max))
            }),
        }
    }

    /// The same tree as obvhs's `Bvh2` (children in adjacent nodes), for obvhs's converter.
    pub fn to_bvh2(&self) -> Bvh2 {
        let mut nodes = Vec::with_capacity(self.node_count());
        if self.node_count() > 0 {
            nodes.push(Bvh2Node::default());
        }
        // (obvhs node, our node) pairs whose obvhs node is still to be filled in.
        let mut pending = vec![(0usize, 0u32)];
        while let Some((at, node)) = pending.pop() {
            let filled = match self.children(node) {
                Some([first, second]) => {
                    let first_index = nodes.len();
                    nodes.push(Bvh2Node::default());
                    nodes.push(Bvh2Node::default());
                    pending.push((first_index + 1, second));
                    pending.push((first_index, first));
                    Bvh2Node::new(self.aabb(node), 0, first_index as u32)
                }
                None => {
                    let leaf = node - self.inner.len() as u32;
                    Bvh2Node::new(self.aabb(node), 1, leaf)
                }
            };
            if let Some(slot) = nodes.get_mut(at) {
                *slot = filled;
            }
        }
        Bvh2 {
            nodes,
            primitive_indices: self.leaves.iter().map(|p| p.index).collect(),
            ..Bvh2::default()
        }
    }
}

impl BinaryTree for BinaryBvh {
    fn node_count(&self) -> usize {
        self.inner.len() + self.leaves.len()
    }

    fn aabb(&self, node: u32) -> Aabb {
        match self.inner.get(node as usize) {
            Some(inner) => self.inner_aabb(inner),
            None => self.leaf(node).aabb(),
        }
    }

    fn children(&self, node: u32) -> Option<[u32; 2]> {
        self.inner
            .get(node as usize)
            .map(|inner| inner.children(node))
    }

    fn primitive(&self, leaf: u32) -> u32 {
        self.leaf(leaf).index
    }

    fn decision(&self, node: u32, i: u8) -> Decision {
        match self.inner.get(node as usize) {
            Some(inner) => inner.decisions[usize::from(i)],
            None => Decision::LEAF,
        }
    }
}

/// What a build did: its result and how much work it took, for tests that bound both.
pub struct Built {
    pub tree: BinaryBvh,
    pub scale: BuildScale,
    /// Primitives looked at over all splits: O(n log n) when the depth is O(log n). Only
    /// tests read the counts; counting costs one addition per node.
    #[cfg_attr(not(test), allow(dead_code))]
    pub steps: u64,
    #[cfg_attr(not(test), allow(dead_code))]
    pub depth: u32,
}

/// Builds the binary BVH over `aabbs` (one primitive per leaf, as obvhs's converter wants).
#[cfg(test)]
pub fn build_bvh2(aabbs: &[Aabb]) -> Built {
    build_bvh2_with(aabbs, morton_min_primitives())
}

/// [`build_boxes_with`] over `aabbs`.
#[cfg(test)]
pub fn build_bvh2_with(aabbs: &[Aabb], morton_min: usize) -> Built {
    build_boxes_with(boxes_of(aabbs), morton_min)
}

/// The boxes to build over `aabbs`.
pub fn boxes_of(aabbs: &[Aabb]) -> Vec<PrimitiveBox> {
    aabbs.iter().map(PrimitiveBox::new).collect()
}

/// Builds the binary BVH over boxes handed over (one primitive per leaf, as obvhs's
/// converter wants), which become the tree's leaves in place; see [`build_boxes_with`].
pub fn build_boxes(boxes: Vec<PrimitiveBox>) -> Built {
    build_boxes_with(boxes, morton_min_primitives())
}

/// What [`build_boxes`] takes for [`MORTON_MIN_PRIMITIVES`]: the constant, except that tests
/// may lower it on their thread (`testing::with_morton_top`).
fn morton_min_primitives() -> usize {
    #[cfg(any(test, feature = "testing"))]
    return crate::testing::MORTON_MIN.get();
    #[cfg(not(any(test, feature = "testing")))]
    MORTON_MIN_PRIMITIVES
}

/// [`build_boxes`] with a Morton-ordered top when there are at least `morton_min` boxes
/// (tests lower it to reach the Morton build with small inputs). The boxes are scaled,
/// numbered by their input positions and put in order where they lie: no second array of
/// a million boxes.
pub fn build_boxes_with(mut prims: Vec<PrimitiveBox>, morton_min: usize) -> Built {
    let scale = BuildScale::for_boxes(&prims);
    let codes = if prims.len() >= morton_min {
        Some(morton_sort(&mut prims, scale))
    } else {
        scale_in_place(&mut prims, scale);
        None
    };
    // Filled in parallel too: for a million objects this is 16 MB of fresh pages.
    let mut inner: Vec<Inner> = (0..prims.len().saturating_sub(1))
        .into_par_iter()
        .with_min_len(PARALLEL_RANGE)
        .map(|_| Inner::default())
        .collect();
    let mut steps = 0;
    let mut depth = 0;
    let mut boxes = Vec::new();
    if !prims.is_empty() {
        // Large nodes form the top of the tree; its lowest ones hold disjoint sets of more
        // than `SMALL_SUBTREE` primitives, so there are fewer than this many unless the
        // top has long chains of nodes that split off a few primitives each (the vector
        // then grows).
        let expected = 2 * prims.len() / (SMALL_SUBTREE + 1);
        let builder = Builder {
            leaf_base: inner.len() as u32,
            boxes: Mutex::new(Vec::with_capacity(expected)),
        };
        let (_, _, work) = match codes {
            Some(codes) => {
                let (id, costs, work, _) =
                    builder.build_morton(&mut prims, &codes, &mut inner, 0, 0, 0);
                (id, costs, work)
            }
            None => {
                let (bounds, centroid_bounds) = bounds_of(&prims);
                let range = Range {
                    bounds,
                    centroid_bounds,
                    first_leaf: 0,
                    first_inner: 0,
                    depth: 0,
                };
                builder.build(&mut prims, &mut inner, range)
            }
        };
        steps = work.steps;
        depth = work.depth;
        // A worker that panicked has taken the build down with it already.
        boxes = builder
            .boxes
            .into_inner()
            .unwrap_or_else(|e| e.into_inner());
    }
    Built {
        tree: BinaryBvh {
            inner,
            leaves: prims,
            boxes,
        },
        scale,
        steps,
        depth,
    }
}

/// The bounds of the boxes and of their centroids, in one pass.
fn bounds_of(prims: &[PrimitiveBox]) -> (Aabb, Aabb) {
    let mut bounds = Aabb::empty();
    let mut centroid_bounds = Aabb::empty();
    for p in prims {
        bounds = bounds.union(&p.aabb());
        let c = p.centroid();
        centroid_bounds = centroid_bounds.union(&Aabb::new(c, c));
    }
    (bounds, centroid_bounds)
}

/// Steps taken and depth reached below one node.
#[derive(Clone, Copy, Default)]
struct Work {
    steps: u64,
    depth: u32,
}

/// A range of primitives to build a subtree over, with what its parent knows of it.
#[derive(Clone, Copy)]
struct Range {
    bounds: Aabb,
    centroid_bounds: Aabb,
    /// Where the range starts among the leaves, and where its inner nodes start.
    first_leaf: u32,
    first_inner: u32,
    depth: u32,
}

struct Builder {
    /// The node id of leaf 0: the number of inner nodes.
    leaf_base: u32,
    /// The large inner nodes' boxes, each pushed as its node is made (on any thread: the
    /// order does not matter, each node keeps its box's place).
    boxes: Mutex<Vec<NodeBox>>,
}

impl Builder {
    /// Builds the subtree over `prims` (the range's primitives) and returns its root's node
    /// id and its seven conversion costs. Its inner nodes go into `inner`, which holds
    /// exactly `len − 1` nodes: the root, then the left child's inner nodes, then the
    /// right child's. The layout depends only on the input, so the result is the same on
    /// any number of threads.
    fn build(
        &self,
        prims: &mut [PrimitiveBox],
        inner: &mut [Inner],
        range: Range,
    ) -> (u32, [f32; 7], Work) {
        let len = prims.len();
        if len <= 1 {
            let work = Work {
                steps: 1,
                depth: range.depth,
            };
            let id = self.leaf_base + range.first_leaf;
            return (id, leaf_costs(range.bounds.half_area()), work);
        }
        let split = split(prims, &range.centroid_bounds, range.depth);
        let left_len = split.left_len;
        let (left_prims, right_prims) = prims.split_at_mut(left_len);
        let Some((node, below)) = inner.split_first_mut() else {
            unreachable!("a range of two or more has an inner node");
        };
        let (left_inner, right_inner) = below.split_at_mut(left_len - 1);
        let left = Range {
            bounds: split.left_bounds,
            centroid_bounds: split.left_centroids,
            first_leaf: range.first_leaf,
            first_inner: range.first_inner + 1,
            depth: range.depth + 1,
        };
        let right = Range {
            bounds: split.right_bounds,
            centroid_bounds: split.right_centroids,
            first_leaf: range.first_leaf + left_len as u32,
            first_inner: left.first_inner + left_inner.len() as u32,
            depth: range.depth + 1,
        };
        let mut build_left = move || self.build(left_prims, left_inner, left);
        let mut build_right = move || self.build(right_prims, right_inner, right);
        let ((first, first_costs, left_work), (second, second_costs, right_work)) =
            if len >= PARALLEL_RANGE {
                rayon::join(build_left, build_right)
            } else {
                (build_left(), build_right())
            };
        let (costs, work) = self.join(
            (range.first_inner, node),
            (range.first_leaf, &range.bounds),
            (first, &first_costs, left_work),
            (second, &second_costs, right_work),
            len,
            len as u64,
        );
        (range.first_inner, costs, work)
    }

    /// Builds the subtree over a Morton-sorted range (`codes` are its primitives' codes):
    /// halves it at the highest bit its codes differ in until it is small enough for the
    /// SAH (or its codes are all equal), and returns, beside what [`Builder::build`]
    /// returns, the subtree's bounds (gathered on the way up: no pass over the range but
    /// the one at the switch). The node layout is [`Builder::build`]'s.
    fn build_morton(
        &self,
        prims: &mut [PrimitiveBox],
        codes: &[u32],
        inner: &mut [Inner],
        first_leaf: u32,
        first_inner: u32,
        depth: u32,
    ) -> (u32, [f32; 7], Work, Aabb) {
        let len = prims.len();
        let sweep = len <= MORTON_SWEEP_RANGE;
        if len <= 2 || (!sweep && codes[0] == codes[len - 1]) {
            let (bounds, centroid_bounds) = bounds_of(prims);
            let range = Range {
                bounds,
                centroid_bounds,
                first_leaf,
                first_inner,
                depth,
            };
            let (id, costs, mut work) = self.build(prims, inner, range);
            work.steps += len as u64;
            return (id, costs, work, bounds);
        }
        let left_len = if sweep {
            sweep_split(prims)
        } else {
            morton_split(codes)
        };
        let (left_prims, right_prims) = prims.split_at_mut(left_len);
        let (left_codes, right_codes) = codes.split_at(left_len);
        let Some((node, below)) = inner.split_first_mut() else {
            unreachable!("a range of two or more has an inner node");
        };
        let (left_inner, right_inner) = below.split_at_mut(left_len - 1);
        let left_first_inner = first_inner + 1;
        let right_first_inner = left_first_inner + left_inner.len() as u32;
        let right_first_leaf = first_leaf + left_len as u32;
        let mut build_left = move || {
            self.build_morton(
                left_prims,
                left_codes,
                left_inner,
                first_leaf,
                left_first_inner,
                depth + 1,
            )
        };
        let mut build_right = move || {
            self.build_morton(
                right_prims,
                right_codes,
                right_inner,
                right_first_leaf,
                right_first_inner,
                depth + 1,
            )
        };
        let (
            (first, first_costs, left_work, left_bounds),
            (second, second_costs, right_work, right_bounds),
        ) = if len >= PARALLEL_RANGE {
            rayon::join(build_left, build_right)
        } else {
            (build_left(), build_right())
        };
        let bounds = left_bounds.union(&right_bounds);
        let (costs, work) = self.join(
            (first_inner, node),
            (first_leaf, &bounds),
            (first, &first_costs, left_work),
            (second, &second_costs, right_work),
            len,
            1,
        );
        (first_inner, costs, work, bounds)
    }
}

impl Builder {
    /// Writes inner node `id` over `len` primitives from leaf `first_leaf` on, within
    /// `bounds`, whose children are built, each as (node id, conversion costs, work), with
    /// its conversion decisions; returns its costs and the work below it (`steps` of its
    /// own).
    fn join(
        &self,
        (id, node): (u32, &mut Inner),
        (first_leaf, bounds): (u32, &Aabb),
        (first, first_costs, left_work): (u32, &[f32; 7], Work),
        (second, second_costs, right_work): (u32, &[f32; 7], Work),
        len: usize,
        steps: u64,
    ) -> ([f32; 7], Work) {
        let (costs, decisions) = decide(bounds.half_area(), first_costs, second_costs, len as u32);
        let (link, inner_children) = Inner::link([first, second], self.leaf_base);
        let (place, count) = if len <= SMALL_SUBTREE {
            (first_leaf, len as u8)
        } else {
            let mut boxes = self.boxes.lock().unwrap_or_else(|e| e.into_inner());
            boxes.push(NodeBox {
                min: bounds.min.to_array(),
                max: bounds.max.to_array(),
            });
            (boxes.len() as u32 - 1, 0)
        };
        *node = Inner {
            link,
            place,
            decisions,
            bits: inner_children | count << 2,
        };
        // The layout `Inner::children` relies on (the tests build every kind of tree).
        debug_assert_eq!(node.children(id), [first, second]);
        let work = Work {
            steps: steps + left_work.steps + right_work.steps,
            depth: left_work.depth.max(right_work.depth),
        };
        (costs, work)
    }
}

/// Where a range was split and the bounds of its two parts.
struct Split {
    left_len: usize,
    left_bounds: Aabb,
    left_centroids: Aabb,
    right_bounds: Aabb,
    right_centroids: Aabb,
}

/// Reorders `prims` into two non-empty parts.
fn split(prims: &mut [PrimitiveBox], centroid_bounds: &Aabb, depth: u32) -> Split {
    let lo = centroid_bounds.min;
    let extent = centroid_bounds.max - lo;
    let axis = extent.max_position();
    if extent[axis] > 0.0 && depth < SAH_DEPTH_LIMIT {
        if prims.len() == 2 {
            return pair_split(prims, extent);
        }
        if let Some(split) = sah_split(prims, lo, extent) {
            return split;
        }
    }
    median_split(prims, axis)
}

/// [`sah_split`] of two primitives whose centroids differ, in closed form (half the
/// ranges are pairs, and binning them costs far more than the pair): on every axis where
/// the centroids differ the two fall into the first and the last bin, and the cost is the
/// sum of their two half areas whatever the axis, so the first such axis wins and the
/// primitive with the lower centroid on it goes first.
fn pair_split(prims: &mut [PrimitiveBox], extent: Vec3A) -> Split {
    let axis = (0..3).find(|&a| extent[a] > 0.0).unwrap_or(0);
    if prims[1].centroid()[axis] < prims[0].centroid()[axis] {
        prims.swap(0, 1);
    }
    let side = |p: &PrimitiveBox| {
        let c = p.centroid();
        (
            Aabb::empty().union(&p.aabb()),
            Aabb::empty().union(&Aabb::new(c, c)),
        )
    };
    let (left_bounds, left_centroids) = side(&prims[0]);
    let (right_bounds, right_centroids) = side(&prims[1]);
    Split {
        left_len: 1,
        left_bounds,
        left_centroids,
        right_bounds,
        right_centroids,
    }
}

/// The cheapest bin boundary over the three axes, applied; `None` when no boundary leaves
/// both sides non-empty.
fn sah_split(prims: &mut [PrimitiveBox], lo: Vec3A, extent: Vec3A) -> Option<Split> {
    // A centroid's bin on each axis: `((c - lo) / extent * BINS) as usize`, at most the
    // last bin, for the three axes at once. Clamping to [0, BINS − 1] first gives what
    // `as` gives (it saturates, and makes NaN 0: so does `max` with 0, which returns its
    // argument for NaN); the truncated bin plus 2^23 then holds the bin in its low
    // mantissa bits, exactly, which spares three saturating conversions per primitive.
    let bins = Vec3A::splat(BINS as f32);
    let last_bin = Vec3A::splat((BINS - 1) as f32);
    let two_to_23 = Vec3A::splat(8_388_608.0);
    let bins_of = |c: Vec3A| -> [usize; 3] {
        let x = ((c - lo) / extent * bins).max(Vec3A::ZERO).min(last_bin);
        let shifted = x.trunc() + two_to_23;
        shifted.to_array().map(|v| (v.to_bits() & 0xff) as usize)
    };
    // One pass bins every primitive on all three axes.
    let mut counts = [[0u32; BINS]; 3];
    let mut bin_boxes = [[Aabb::empty(); BINS]; 3];
    for p in prims.iter() {
        let (c, aabb) = (p.centroid(), p.aabb());
        for (axis, b) in bins_of(c).into_iter().enumerate() {
            counts[axis][b] += 1;
            bin_boxes[axis][b] = bin_boxes[axis][b].union(&aabb);
        }
    }
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let (counts, boxes) = (&counts[axis], &bin_boxes[axis]);
        // Right-to-left sweep of areas, then left to right for the costs.
        let mut right_area = [0.0f32; BINS];
        let mut acc = Aabb::empty();
        for b in (1..BINS).rev() {
            acc = acc.union(&boxes[b]);
            right_area[b] = acc.half_area();
        }
        let (mut left_box, mut left_count) = (Aabb::empty(), 0u32);
        for b in 0..BINS - 1 {
            left_box = left_box.union(&boxes[b]);
            left_count += counts[b];
            let right_count = prims.len() as u32 - left_count;
            if left_count == 0 || right_count == 0 {
                continue;
            }
            let cost =
                left_box.half_area() * left_count as f32 + right_area[b + 1] * right_count as f32;
            if best.is_none_or(|(c, ..)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    let (_, axis, last_left_bin) = best?;
    // Moves the primitives of the bins up to `last_left_bin` to the front, in the order the
    // index build moved its indices, and gathers the bounds of both sides on the way.
    let mut split = Split {
        left_len: 0,
        left_bounds: Aabb::empty(),
        left_centroids: Aabb::empty(),
        right_bounds: Aabb::empty(),
        right_centroids: Aabb::empty(),
    };
    for i in 0..prims.len() {
        let p = prims[i];
        let c = p.centroid();
        if bins_of(c)[axis] <= last_left_bin {
            split.left_bounds = split.left_bounds.union(&p.aabb());
            split.left_centroids = split.left_centroids.union(&Aabb::new(c, c));
            if i != split.left_len {
                prims.swap(i, split.left_len);
            }
            split.left_len += 1;
        } else {
            split.right_bounds = split.right_bounds.union(&p.aabb());
            split.right_centroids = split.right_centroids.union(&Aabb::new(c, c));
        }
    }
    (split.left_len > 0 && split.left_len < prims.len()).then_some(split)
}

/// Halves `prims` at the median centroid along `axis` (ties by input index, so the result
/// is a function of the input alone).
fn median_split(prims: &mut [PrimitiveBox], axis: usize) -> Split {
    let mid = prims.len() / 2;
    prims.select_nth_unstable_by(mid, |a, b| {
        let (ca, cb) = (a.centroid(), b.centroid());
        ca[axis].total_cmp(&cb[axis]).then(a.index.cmp(&b.index))
    });
    let (left, right) = prims.split_at(mid);
    let (left_bounds, left_centroids) = bounds_of(left);
    let (right_bounds, right_centroids) = bounds_of(right);
    Split {
        left_len: mid,
        left_bounds,
        left_centroids,
        right_bounds,
        right_centroids,
    }
}

/// Scenes of at least this many primitives get a Morton-ordered top (see [`morton_sorted_prims`]):
/// below it every split is the binned SAH's, as the golden scenes and benchmarks were built.
pub const MORTON_MIN_PRIMITIVES: usize = 1 << 17;

/// Below the Morton top, ranges of at most this many primitives are split where the
/// surface area heuristic is lowest along their Morton order ([`sweep_split`]).
const MORTON_SWEEP_RANGE: usize = 64;

/// Bits of a Morton code per axis: three interleaved make a 30-bit code, which sorts in
/// three passes. A cell that holds many primitives is not split further by code: its range
/// goes to the SAH like any small one, so a coarse code costs time, never correctness.
const MORTON_BITS: u32 = 10;

/// Spreads the low 10 bits of `v` out to every third bit of the result.
fn spread_bits(v: u32) -> u32 {
    let mut x = v & 0x3ff;
    x = (x | (x << 16)) & 0x0300_00ff;
    x = (x | (x << 8)) & 0x0300_f00f;
    x = (x | (x << 4)) & 0x030c_30c3;
    x = (x | (x << 2)) & 0x0924_9249;
    x
}

/// The Morton code of centroid `c`, `cells_per_unit` cells per unit of length from `lo`
/// (x in the lowest of each three bits).
fn morton_code(c: Vec3A, lo: Vec3A, cells_per_unit: f32) -> u32 {
    let last = ((1u32 << MORTON_BITS) - 1) as f32;
    // `max` and `min` return the other operand for NaN: a NaN centroid lands in cell 0.
    let q = ((c - lo) * cells_per_unit)
        .max(Vec3A::ZERO)
        .min(Vec3A::splat(last));
    spread_bits(q.x as u32) | spread_bits(q.y as u32) << 1 | spread_bits(q.z as u32) << 2
}

/// Scales each box into build space and numbers it by its position (each alone: in
/// parallel).
fn scale_in_place(prims: &mut [PrimitiveBox], scale: BuildScale) {
    prims
        .par_iter_mut()
        .with_min_len(PARALLEL_RANGE)
        .enumerate()
        .for_each(|(i, p)| *p = PrimitiveBox::with_index(&scale.scale_box(&p.aabb()), i as u32));
}

/// Puts the leaves in the order of the Morton codes of their boxes' centroids (ties in
/// input order), scaled into build space and numbered by their input positions, and
/// returns the sorted codes. The codes are taken from the boxes as given (the order only
/// needs to be a function of the input). The codes divide a cube whose side is the
/// centroids' bounds' longest, so each level of the code halves space evenly whatever the
/// scene's proportions. The boxes move into order in place ([`permute_in_place`]): a
/// gather into a new array holds a million boxes twice, which was the build's peak of
/// memory (104 MiB for the 1M-sphere grid, against 94 for the whole build now), in about
/// the time the sort takes now (77 ms against 75-80, one thread).
fn morton_sort(prims: &mut [PrimitiveBox], scale: BuildScale) -> Vec<u32> {
    // Halves first: the sum of two huge corners would overflow.
    let centroid = |b: &PrimitiveBox| Vec3A::from(b.min) * 0.5 + Vec3A::from(b.max) * 0.5;
    let centroid_bounds = prims.iter().fold(Aabb::empty(), |bounds, b| {
        let c = centroid(b);
        bounds.union(&Aabb::new(c, c))
    });
    let lo = centroid_bounds.min;
    let side = (centroid_bounds.max - lo).max_element();
    let cells_per_unit = if side > 0.0 && side.is_finite() {
        (1u32 << MORTON_BITS) as f32 / side
    } else {
        0.0
    };
    // A key is the code above the box's input index: 8 bytes, sorted by the code alone.
    // Each box is scaled as soon as its code is taken.
    let mut keys: Vec<u64> = prims
        .par_iter_mut()
        .with_min_len(PARALLEL_RANGE)
        .enumerate()
        .map(|(i, b)| {
            let code = morton_code(centroid(b), lo, cells_per_unit);
            *b = PrimitiveBox::with_index(&scale.scale_box(&b.aabb()), i as u32);
            u64::from(code) << 32 | i as u64
        })
        .collect();
    radix_sort_codes(&mut keys);
    let mut order: Vec<u32> = keys.iter().map(|&key| key as u32).collect();
    let codes = keys.into_iter().map(|key| (key >> 32) as u32).collect();
    permute_in_place(prims, &mut order);
    codes
}

/// A stable least-significant-digit radix sort of keys by their upper 32 bits, in which
/// only the 30 bits of a Morton code are set: three passes of 10 bits, with the three
/// histograms counted in one pass first. A pass whose digit is the same for every key is
/// skipped (a flat scene's codes have no y bits).
fn radix_sort_codes(keys: &mut Vec<u64>) {
    const DIGIT: u32 = MORTON_BITS;
    const BUCKETS: usize = 1 << DIGIT;
    const PASSES: usize = 3;
    let digit =
        |key: u64, pass: usize| ((key >> (32 + DIGIT as usize * pass)) as usize) & (BUCKETS - 1);
    let mut counts = vec![[0usize; BUCKETS]; PASSES];
    for &key in keys.iter() {
        for (pass, count) in counts.iter_mut().enumerate() {
            count[digit(key, pass)] += 1;
        }
    }
    let mut spare = vec![0u64; keys.len()];
    for (pass, starts) in counts.iter_mut().enumerate() {
        if starts.contains(&keys.len()) {
            continue;
        }
        let mut sum = 0;
        for count in starts.iter_mut() {
            sum += std::mem::replace(count, sum);
        }
        for &key in keys.iter() {
            let slot = &mut starts[digit(key, pass)];
            spare[*slot] = key;
            *slot += 1;
        }
        std::mem::swap(keys, &mut spare);
    }
}

/// The split of a range in its order (of at least 2 and at most [`MORTON_SWEEP_RANGE`]
/// primitives) with the least surface area cost: the first of equally cheap ones.
fn sweep_split(prims: &[PrimitiveBox]) -> usize {
    let len = prims.len();
    // right_area[i]: the half area of the box of prims[i..].
    let mut right_area = [0.0f32; MORTON_SWEEP_RANGE];
    let mut right = Aabb::empty();
    for i in (1..len).rev() {
        right = right.union(&prims[i].aabb());
        right_area[i] = right.half_area();
    }
    let mut left = Aabb::empty();
    let mut best = (f32::INFINITY, 1);
    for i in 1..len {
        left = left.union(&prims[i - 1].aabb());
        let cost = left.half_area() * i as f32 + right_area[i] * (len - i) as f32;
        if cost < best.0 {
            best = (cost, i);
        }
    }
    best.1
}

/// Where a Morton-sorted range whose first and last codes differ splits: at the first code
/// with their highest differing bit set, so both sides are non-empty.
fn morton_split(codes: &[u32]) -> usize {
    let (first, last) = (codes[0], codes[codes.len() - 1]);
    let bit = 31 - (first ^ last).leading_zeros();
    codes.partition_point(|&c| c & (1 << bit) == 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::Random;
    use crate::wide::{convert, DecidedBvh2};
    use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
    use obvhs::cwbvh::node::CwBvhNode;

    fn unit_boxes_at(centers: impl Iterator<Item = Vec3A>) -> Vec<Aabb> {
        centers.map(|c| Aabb::new(c - 1.0, c + 1.0)).collect()
    }

    /// The depth and the work stay within `SAH_DEPTH_LIMIT + log2(n)` levels of n steps.
    fn assert_n_log_n(built: &Built, n: usize) {
        let log2 = (n as f64).log2().ceil() as u32;
        assert!(
            built.depth <= SAH_DEPTH_LIMIT + log2 + 1,
            "depth {} for {n}",
            built.depth
        );
        let bound = n as u64 * u64::from(SAH_DEPTH_LIMIT + log2 + 2);
        assert!(built.steps <= bound, "{} steps for {n}", built.steps);
        assert_eq!(built.tree.leaves.len(), n);
    }

    /// 40,000 coincident objects (`for i in 0..40000 { sphere { } }`) took 35 s with PLOC
    /// and a tree 40,000 deep; a regular row of objects was just as bad.
    #[test]
    fn coincident_and_regular_inputs_build_in_n_log_n() {
        let n = 40_000;
        let coincident = unit_boxes_at((0..n).map(|_| Vec3A::ZERO));
        let built = build_bvh2(&coincident[..]);
        assert_n_log_n(&built, n);
        // The median split keeps coincident objects balanced: depth log2(n) exactly.
        assert!(built.depth <= 17, "{}", built.depth);
        let row = unit_boxes_at((0..n).map(|i| Vec3A::new(i as f32 * 3.0, 0.0, 0.0)));
        assert_n_log_n(&build_bvh2(&row[..]), n);
        let near = unit_boxes_at((0..n).map(|i| Vec3A::new(i as f32 * 1e-6, 0.0, 0.0)));
        assert_n_log_n(&build_bvh2(&near[..]), n);
        // Exponentially spaced objects, which make every SAH split peel off a few.
        let spread = unit_boxes_at((0..n).map(|i| Vec3A::splat(1.0005f32.powi(i as i32))));
        assert_n_log_n(&build_bvh2(&spread[..]), n);
    }

    /// Boxes of a large, irregular scene (large enough for many levels of parallel splits).
    fn scattered(n: usize) -> Vec<Aabb> {
        (0..n as u32)
            .map(|i| {
                let h = |k: u32| (i.wrapping_mul(2_654_435_761).rotate_left(k) % 1000) as f32;
                let c = Vec3A::new(h(0), h(11) * 0.3, h(22) * 2.0);
                let r = 0.5 + (i % 3) as f32;
                Aabb::new(c - r, c + r)
            })
            .collect()
    }

    /// A large build is a tree: each node's box holds its children's (and a leaf's its
    /// primitive's scaled box), every node but the root is the child of one node, and every
    /// primitive is in exactly one leaf.
    #[test]
    fn large_builds_are_valid_trees() {
        let n = 50_000;
        let aabbs = scattered(n);
        let built = build_bvh2(&aabbs[..]);
        assert_n_log_n(&built, n);
        assert_valid_tree(&built, &aabbs);
    }

    /// The Morton-topped build of a large scene is a valid tree too, and as deep as its
    /// code's bits, the sweep's ranges and the SAH below allow, on inputs that break naive
    /// Morton builders: coincident centroids, a regular row, near-coincident ones, an
    /// exponential spread, one far outlier, a flat scene.
    #[test]
    fn morton_builds_are_valid_trees_of_bounded_depth() {
        let n = 40_000;
        let far = unit_boxes_at((0..n).map(|i| {
            Vec3A::new(
                i as f32 % 200.0,
                (i / 200) as f32,
                if i == 0 { 1e9 } else { 0.0 },
            )
        }));
        let cases = [
            ("scattered", scattered(n)),
            ("coincident", unit_boxes_at((0..n).map(|_| Vec3A::ZERO))),
            (
                "row",
                unit_boxes_at((0..n).map(|i| Vec3A::new(i as f32 * 3.0, 0.0, 0.0))),
            ),
            (
                "near",
                unit_boxes_at((0..n).map(|i| Vec3A::new(i as f32 * 1e-6, 0.0, 0.0))),
            ),
            (
                "spread",
                unit_boxes_at((0..n).map(|i| Vec3A::splat(1.0005f32.powi(i as i32)))),
            ),
            ("far outlier", far),
            ("huge", huge_and_tiny(n)),
        ];
        for (name, aabbs) in cases {
            let built = build_bvh2_with(&aabbs[..], 2);
            assert_valid_tree(&built, &aabbs);
            // 30 code bits, then sweeps of at most 63 levels, then the SAH's own bound.
            let log2 = (n as f64).log2().ceil() as u32;
            let depth_bound = 30 + MORTON_SWEEP_RANGE as u32 + SAH_DEPTH_LIMIT + log2 + 1;
            assert!(built.depth <= depth_bound, "{name}: depth {}", built.depth);
            let steps_bound = n as u64 * u64::from(depth_bound + 2);
            assert!(built.steps <= steps_bound, "{name}: {} steps", built.steps);
        }
    }

    /// Boxes near both ends of f32's range among ordinary ones: their centroids' spread
    /// overflows to infinity, so every code is equal and the SAH takes the whole range.
    fn huge_and_tiny(n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|i| match i % 3 {
                0 => Aabb::new(Vec3A::splat(3e38), Vec3A::splat(3.3e38)),
                1 => Aabb::new(Vec3A::splat(-3.3e38), Vec3A::splat(-3e38)),
                _ => {
                    let c = Vec3A::new(i as f32 * 1e-30, 0.0, 0.0);
                    Aabb::new(c, c + 1e-31)
                }
            })
            .collect()
    }

    fn assert_valid_tree(built: &Built, aabbs: &[Aabb]) {
        let n = aabbs.len();
        let tree = &built.tree;
        let contains = |outer: &Aabb, inner: &Aabb| {
            outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
        };
        let mut parents = vec![0u32; tree.node_count()];
        for node in 0..tree.inner.len() as u32 {
            let Some(children) = tree.children(node) else {
                panic!("inner node {node} without children");
            };
            for child in children {
                assert!(contains(&tree.aabb(node), &tree.aabb(child)));
                parents[child as usize] += 1;
            }
        }
        assert_eq!(parents[0], 0);
        assert!(parents[1..].iter().all(|&p| p == 1));
        let mut seen = vec![false; n];
        for leaf in &tree.leaves {
            let prim = leaf.index as usize;
            assert!(!std::mem::replace(&mut seen[prim], true), "{prim} twice");
            assert_eq!(leaf.aabb(), built.scale.scale_box(&aabbs[prim]));
        }
        assert!(seen.iter().all(|&s| s));
    }

    type NodeAsRead = ([u32; 6], Option<[u32; 2]>, [Decision; 7]);

    /// Each node as the converter reads it: its box (as bits, so that a zero's sign counts),
    /// its children and its decisions.
    fn as_read(tree: &BinaryBvh) -> Vec<NodeAsRead> {
        (0..tree.node_count() as u32)
            .map(|node| {
                let aabb = tree.aabb(node);
                let corners = [aabb.min.to_array(), aabb.max.to_array()];
                let bits: Vec<u32> = corners.concat().iter().map(|v| v.to_bits()).collect();
                let decisions = std::array::from_fn(|i| tree.decision(node, i as u8));
                (
                    bits.try_into().unwrap_or([0; 6]),
                    tree.children(node),
                    decisions,
                )
            })
            .collect()
    }

    /// The union of the leaves' boxes below `node`, found by walking down to them.
    fn union_below(tree: &BinaryBvh, node: u32) -> Aabb {
        match tree.children(node) {
            None => tree.aabb(node),
            Some([first, second]) => union_below(tree, first).union(&union_below(tree, second)),
        }
    }

    /// Every inner node's box, kept (a large node) or gathered from its leaves (a small
    /// one), is the union of the boxes of the leaves below it, found by walking the tree:
    /// in builds with and without the Morton top, of trees with both kinds of node.
    #[test]
    fn inner_boxes_are_their_leaves_union() {
        let tiny_and_huge = huge_and_tiny(3_000);
        for (name, aabbs) in [("scattered", scattered(20_000)), ("huge", tiny_and_huge)] {
            for morton_min in [usize::MAX, 2] {
                let built = build_bvh2_with(&aabbs[..], morton_min);
                let tree = &built.tree;
                let small = tree.inner.iter().filter(|n| n.small_count().is_some());
                assert!(
                    small.count() > 0 && !tree.boxes.is_empty(),
                    "{name}: both kinds"
                );
                for node in 0..tree.inner.len() as u32 {
                    let (kept, walked) = (tree.aabb(node), union_below(tree, node));
                    assert!(
                        kept.min == walked.min && kept.max == walked.max,
                        "{name}, Morton from {morton_min}: node {node} {kept:?} against {walked:?}"
                    );
                }
            }
        }
    }

    /// A large build must not depend on the thread count either (the image depends on the
    /// tree through ties), with either top.
    #[test]
    fn large_builds_are_the_same_on_any_thread_count() {
        let aabbs = scattered(50_000);
        for morton_min in [usize::MAX, 2] {
            let build_on = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap_or_else(|e| panic!("no pool: {e}"));
                pool.install(|| build_bvh2_with(&aabbs[..], morton_min))
                    .tree
            };
            let one = build_on(1);
            let three = build_on(3);
            assert!(
                one.leaves == three.leaves,
                "1 and 3 threads order leaves differently (Morton from {morton_min})"
            );
            // The large nodes' boxes are kept in the order threads finish them: the tree
            // is what the converter reads of it.
            assert!(
                as_read(&one) == as_read(&three),
                "1 and 3 threads build different trees (Morton from {morton_min})"
            );
        }
    }

    /// The Morton code against a bit-by-bit interleaving.
    #[test]
    fn morton_codes_interleave_the_axes() {
        let slow = |x: u32, y: u32, z: u32| {
            (0..MORTON_BITS).fold(0u32, |code, bit| {
                code | ((x >> bit) & 1) << (3 * bit)
                    | ((y >> bit) & 1) << (3 * bit + 1)
                    | ((z >> bit) & 1) << (3 * bit + 2)
            })
        };
        let mut rng = Random(1);
        let mut next = || rng.next_u32() % 1024;
        for _ in 0..10_000 {
            let (x, y, z) = (next(), next(), next());
            let c = Vec3A::new(x as f32, y as f32, z as f32) + 0.5;
            assert_eq!(
                morton_code(c, Vec3A::ZERO, 1.0),
                slow(x, y, z),
                "{x} {y} {z}"
            );
        }
        // Outside the cube, below it and NaN: clamped into it.
        let last = (1 << (3 * MORTON_BITS)) - 1;
        assert_eq!(morton_code(Vec3A::splat(5000.0), Vec3A::ZERO, 1.0), last);
        assert_eq!(morton_code(Vec3A::splat(-5.0), Vec3A::ZERO, 1.0), 0);
        assert_eq!(morton_code(Vec3A::splat(f32::NAN), Vec3A::ZERO, 1.0), 0);
    }

    /// The radix sort against the standard library's stable sort, on keys with many equal
    /// codes and on keys whose digits are all equal in some passes (which it skips).
    #[test]
    fn the_radix_sort_is_a_stable_sort_by_code() {
        let mut rng = Random(7);
        let mut next = || u64::from(rng.next_u32());
        let code_sets: [Box<dyn Fn(u64) -> u64>; 4] = [
            Box::new(|r| r & 0x3fff_ffff),
            Box::new(|r| r % 7),
            Box::new(|r| (r % 5) << 20),
            Box::new(|_| 12345),
        ];
        for codes in code_sets {
            let mut keys: Vec<u64> = (0..20_000u64).map(|i| codes(next()) << 32 | i).collect();
            let mut expected = keys.clone();
            expected.sort_by_key(|key| key >> 32);
            radix_sort_codes(&mut keys);
            assert_eq!(keys, expected);
        }
    }

    /// The sweep's split against every split's cost computed from scratch.
    #[test]
    fn the_sweep_takes_the_first_cheapest_split() {
        let cases: Vec<Vec<Aabb>> = vec![
            scattered(64),
            scattered(2),
            scattered(37),
            unit_boxes_at((0..20).map(|_| Vec3A::ZERO)),
            unit_boxes_at((0..30).map(|i| Vec3A::new(if i < 10 { 0.0 } else { 100.0 }, 0.0, 0.0))),
        ];
        for aabbs in cases {
            let prims: Vec<PrimitiveBox> = aabbs
                .iter()
                .enumerate()
                .map(|(i, b)| PrimitiveBox::with_index(b, i as u32))
                .collect();
            let area = |part: &[PrimitiveBox]| {
                part.iter()
                    .fold(Aabb::empty(), |acc, p| acc.union(&p.aabb()))
                    .half_area()
            };
            let len = prims.len();
            let costs: Vec<f32> = (1..len)
                .map(|i| area(&prims[..i]) * i as f32 + area(&prims[i..]) * (len - i) as f32)
                .collect();
            let least = costs.iter().copied().fold(f32::INFINITY, f32::min);
            let first = costs.iter().position(|&c| c == least).map(|i| i + 1);
            assert_eq!(Some(sweep_split(&prims)), first, "{len} boxes");
        }
    }

    /// The f32 shortcut gives the f64 path's bits for every box, whatever the scale: over
    /// generated coordinates of every magnitude (zeros of both signs, subnormals, near
    /// f32's limits) and every exponent a build can pick and beyond.
    #[test]
    fn the_f32_scaling_is_the_f64_scaling() {
        let mut rng = Random(0x9e37_79b9);
        let mut next = || rng.next_u32();
        let mut values = vec![
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            f32::MIN_POSITIVE,
            1e-45,
            -1e-45,
            3.4e38,
            -3.4e38,
        ];
        for _ in 0..3000 {
            // Any finite f32: random bits with the exponent field kept below all ones.
            let bits = next();
            let v = f32::from_bits(bits & 0xff7f_ffff);
            values.push(v);
        }
        let mut boxes = 0;
        for exponent in (-160..=160).step_by(7).chain([-126, -127, 127, 128, 0, 32]) {
            let scale = BuildScale { exponent };
            for pair in values.chunks_exact(6) {
                let lo = Vec3A::new(pair[0], pair[1], pair[2]);
                let hi = lo.max(Vec3A::new(pair[3], pair[4], pair[5]));
                let aabb = Aabb::new(lo, hi);
                let (fast, slow) = (scale.scale_box(&aabb), scale.scale_box_f64(&aabb));
                let bits = |b: &Aabb| {
                    (
                        b.min.to_array().map(f32::to_bits),
                        b.max.to_array().map(f32::to_bits),
                    )
                };
                assert_eq!(bits(&fast), bits(&slow), "2^{exponent} of {aabb:?}");
                boxes += 1;
            }
        }
        assert!(boxes > 20_000, "{boxes}");
    }

    #[test]
    fn scaled_boxes_contain_the_originals() {
        for boxes in [
            vec![
                Aabb::new(Vec3A::splat(-1e19), Vec3A::splat(1e19)),
                Aabb::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)),
            ],
            vec![
                Aabb::new(Vec3A::splat(-3e38), Vec3A::splat(3e38)),
                Aabb::new(Vec3A::splat(1e-30), Vec3A::splat(2e-30)),
            ],
            vec![Aabb::new(Vec3A::splat(1e-38), Vec3A::splat(3e-38))],
        ] {
            let scale = BuildScale::for_boxes(&boxes_of(&boxes));
            for b in &boxes {
                let scaled = scale.scale_box(b);
                assert!(scaled.min.is_finite() && scaled.max.is_finite());
                assert!(scaled.half_area().is_finite(), "{scaled:?}");
                for axis in 0..3 {
                    assert!(f64::from(scaled.min[axis]) <= f64::from(b.min[axis]) * scale.factor());
                    assert!(f64::from(scaled.max[axis]) >= f64::from(b.max[axis]) * scale.factor());
                }
            }
        }
    }

    /// The wide nodes and primitive order from this build, and from the index-moving build
    /// it replaced through obvhs's own converter: the walk's order must not change.
    #[test]
    fn builds_the_tree_of_the_index_build() {
        for (name, aabbs) in crate::testing::inputs() {
            let tree = build_bvh2(&aabbs[..]).tree;
            let Some((nodes, order)) = convert(&tree, |n: &CwBvhNode| Some(*n)) else {
                panic!("{name}: no conversion");
            };
            let reference = bvh2_to_cwbvh(&index_build::build(&aabbs), 3, true, false);
            assert_eq!(order, reference.primitive_indices, "{name}");
            // `==` on the origin: the two builds gather a node's bounds in different orders,
            // which may differ in the sign of a zero (the walk's planes do not).
            assert!(nodes == reference.nodes, "{name}");
        }
    }

    /// A million objects' build holds a million inner nodes through the build and the
    /// conversion: 16 bytes each, one child id implied by the layout and the box of a
    /// small subtree gathered from its leaves.
    #[test]
    fn inner_nodes_stay_small() {
        assert_eq!(std::mem::size_of::<Inner>(), 16);
    }

    /// obvhs's converter reads the tree given to it in obvhs's layout as this converter
    /// reads it (the fallback when this converter gives up).
    #[test]
    fn the_obvhs_layout_holds_the_same_tree() {
        for (name, aabbs) in crate::testing::inputs() {
            let tree = build_bvh2(&aabbs[..]).tree;
            let bvh2 = tree.to_bvh2();
            let ours = convert(&tree, |n: &CwBvhNode| Some(*n));
            let theirs = convert(&DecidedBvh2::new(&bvh2), |n: &CwBvhNode| Some(*n));
            assert!(ours.is_some() && ours == theirs, "{name}");
        }
    }

    /// The build this module's replaced: indices moved through the partitions, each node's
    /// bounds gathered from its own range, into obvhs's `Bvh2`.
    mod index_build {
        use super::*;

        pub fn build(aabbs: &[Aabb]) -> Bvh2 {
            let scale = BuildScale::for_boxes(&boxes_of(aabbs));
            let boxes: Vec<Aabb> = aabbs.iter().map(|b| scale.scale_box(b)).collect();
            let centroids: Vec<Vec3A> = boxes.iter().map(|b| (b.min + b.max) * 0.5).collect();
            let mut prims: Vec<u32> = (0..boxes.len() as u32).collect();
            let mut nodes = vec![Bvh2Node::default(); (2 * boxes.len()).saturating_sub(1)];
            if let Some((root, region)) = nodes.split_first_mut() {
                let input = Input {
                    boxes: &boxes,
                    centroids: &centroids,
                };
                *root = input.build(&mut prims, 0, region, 1, 0);
            }
            Bvh2 {
                nodes,
                primitive_indices: prims,
                ..Bvh2::default()
            }
        }

        struct Input<'a> {
            boxes: &'a [Aabb],
            centroids: &'a [Vec3A],
        }

        impl Input<'_> {
            fn build(
                &self,
                prims: &mut [u32],
                prim_offset: u32,
                region: &mut [Bvh2Node],
                region_offset: u32,
                depth: u32,
            ) -> Bvh2Node {
                let mut bounds = Aabb::empty();
                let mut centroid_bounds = Aabb::empty();
                for &p in prims.iter() {
                    bounds = bounds.union(&self.boxes[p as usize]);
                    let c = self.centroids[p as usize];
                    centroid_bounds = centroid_bounds.union(&Aabb::new(c, c));
                }
                if prims.len() <= 1 {
                    return Bvh2Node::new(bounds, 1, prim_offset);
                }
                let left_len = self.split(prims, &centroid_bounds, depth);
                let (left_prims, right_prims) = prims.split_at_mut(left_len);
                let (children, below) = region.split_at_mut(2);
                let (left_region, right_region) = below.split_at_mut(2 * left_len - 2);
                let left_offset = region_offset + 2;
                let right_offset = left_offset + left_region.len() as u32;
                children[0] =
                    self.build(left_prims, prim_offset, left_region, left_offset, depth + 1);
                children[1] = self.build(
                    right_prims,
                    prim_offset + left_len as u32,
                    right_region,
                    right_offset,
                    depth + 1,
                );
                Bvh2Node::new(bounds, 0, region_offset)
            }

            fn split(&self, prims: &mut [u32], centroid_bounds: &Aabb, depth: u32) -> usize {
                let lo = centroid_bounds.min;
                let extent = centroid_bounds.max - lo;
                let axis = extent.max_position();
                if extent[axis] > 0.0 && depth < SAH_DEPTH_LIMIT {
                    if let Some(left_len) = self.sah_split(prims, lo, extent) {
                        return left_len;
                    }
                }
                let mid = prims.len() / 2;
                prims.select_nth_unstable_by(mid, |&a, &b| {
                    let (ca, cb) = (self.centroids[a as usize], self.centroids[b as usize]);
                    ca[axis].total_cmp(&cb[axis]).then(a.cmp(&b))
                });
                mid
            }

            fn sah_split(&self, prims: &mut [u32], lo: Vec3A, extent: Vec3A) -> Option<usize> {
                let bin_of = |c: Vec3A, axis: usize| -> usize {
                    let x = (c[axis] - lo[axis]) / extent[axis] * BINS as f32;
                    (x as usize).min(BINS - 1)
                };
                let mut counts = [[0u32; BINS]; 3];
                let mut bin_boxes = [[Aabb::empty(); BINS]; 3];
                for &p in prims.iter() {
                    let (c, aabb) = (self.centroids[p as usize], &self.boxes[p as usize]);
                    for axis in 0..3 {
                        let b = bin_of(c, axis);
                        counts[axis][b] += 1;
                        bin_boxes[axis][b] = bin_boxes[axis][b].union(aabb);
                    }
                }
                let mut best: Option<(f32, usize, usize)> = None;
                for axis in 0..3 {
                    if extent[axis] <= 0.0 {
                        continue;
                    }
                    let (counts, boxes) = (&counts[axis], &bin_boxes[axis]);
                    let mut right_area = [0.0f32; BINS];
                    let mut acc = Aabb::empty();
                    for b in (1..BINS).rev() {
                        acc = acc.union(&boxes[b]);
                        right_area[b] = acc.half_area();
                    }
                    let (mut left_box, mut left_count) = (Aabb::empty(), 0u32);
                    for b in 0..BINS - 1 {
                        left_box = left_box.union(&boxes[b]);
                        left_count += counts[b];
                        let right_count = prims.len() as u32 - left_count;
                        if left_count == 0 || right_count == 0 {
                            continue;
                        }
                        let cost = left_box.half_area() * left_count as f32
                            + right_area[b + 1] * right_count as f32;
                        if best.is_none_or(|(c, ..)| cost < c) {
                            best = Some((cost, axis, b));
                        }
                    }
                }
                let (_, axis, last_left_bin) = best?;
                let mut first_right = 0;
                for i in 0..prims.len() {
                    if bin_of(self.centroids[prims[i] as usize], axis) <= last_left_bin {
                        prims.swap(i, first_right);
                        first_right += 1;
                    }
                }
                (first_right > 0 && first_right < prims.len()).then_some(first_right)
            }
        }
    }
}
