//! Converts the binary BVH into obvhs's compressed wide nodes exactly as obvhs's
//! `bvh2_to_cwbvh(bvh2, 3, true, false)` does (same nodes, same `primitive_indices`), in
//! less memory and time.
//!
//! The walk must visit primitives in obvhs's order (see `walk.rs`), so this is a transcription
//! of obvhs's converter (the cost table of Ylitie et al. 2017, the greedy octant ordering of
//! children, the quantisation), with the same f32 and glam operations in the same order.
//! What differs is what is kept: obvhs keeps a 56-byte cost table per binary node (7
//! decisions with their costs) for the whole conversion, 112 MB for a million primitives.
//! Here the binary build computes each inner node's costs on its way back up ([`decide`],
//! from its children's, which are then dropped) and keeps only its 7 decisions, a byte
//! each. Each wide node is handed to a caller's function as soon as it is complete, so the
//! caller can store the node in the form it likes (the build keeps obvhs's 80-byte nodes,
//! so that the binary tree is freed before the walk's 256-byte ones are made; see `walk`).
//! Large trees are converted on several threads: the conversion is depth first, so each of
//! the root's subtrees fills a contiguous range of the nodes and of the primitives; they are
//! counted, then converted in parallel straight into their ranges (no copies, the same
//! result).
//! The test in `tests` compares the two converters node for node on many inputs.

use glam::Vec3A;
use obvhs::aabb::Aabb;
#[cfg(test)]
use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::node::CwBvhNode;
use rayon::prelude::*;

/// What the converter reads of a binary BVH whose leaves hold one primitive each, with
/// obvhs's conversion decisions for each node (see [`decide`]).
pub trait BinaryTree {
    /// Node ids are below this; the root is 0.
    fn node_count(&self) -> usize;
    fn aabb(&self, node: u32) -> Aabb;
    /// The two children of an inner node; `None` for a leaf.
    fn children(&self, node: u32) -> Option<[u32; 2]>;
    /// The input index of a leaf's primitive.
    fn primitive(&self, leaf: u32) -> u32;
    /// Decision `i` of `node` ([`Decision::LEAF`] for a leaf).
    fn decision(&self, node: u32, i: u8) -> Decision;
}

/// An obvhs `Bvh2` with its decisions, for converting trees made by other builders (the
/// tests' reference build).
#[cfg(test)]
pub struct DecidedBvh2<'a> {
    bvh2: &'a Bvh2,
    decisions: Vec<[Decision; 7]>,
}

#[cfg(test)]
impl DecidedBvh2<'_> {
    pub fn new(bvh2: &Bvh2) -> DecidedBvh2<'_> {
        let mut tree = DecidedBvh2 {
            bvh2,
            decisions: vec![[Decision::LEAF; 7]; bvh2.nodes.len()],
        };
        if !bvh2.nodes.is_empty() {
            tree.costs(0);
        }
        tree
    }

    /// obvhs's `calculate_cost_impl` over the subtree of `node`: the decisions of its
    /// nodes, and its costs and primitive count.
    fn costs(&mut self, node: u32) -> ([f32; 7], u32) {
        let half_area = self.aabb(node).half_area();
        let Some([first, second]) = self.children(node) else {
            return (leaf_costs(half_area), 1);
        };
        let (first_costs, first_count) = self.costs(first);
        let (second_costs, second_count) = self.costs(second);
        let count = first_count + second_count;
        let (costs, decisions) = decide(half_area, &first_costs, &second_costs, count);
        self.decisions[node as usize] = decisions;
        (costs, count)
    }
}

#[cfg(test)]
impl BinaryTree for DecidedBvh2<'_> {
    fn node_count(&self) -> usize {
        self.bvh2.nodes.len()
    }

    fn aabb(&self, node: u32) -> Aabb {
        *self.bvh2.nodes[node as usize].aabb()
    }

    fn children(&self, node: u32) -> Option<[u32; 2]> {
        let node = &self.bvh2.nodes[node as usize];
        (node.prim_count == 0).then_some([node.first_index, node.first_index + 1])
    }

    fn primitive(&self, leaf: u32) -> u32 {
        self.bvh2.primitive_indices[self.bvh2.nodes[leaf as usize].first_index as usize]
    }

    fn decision(&self, node: u32, i: u8) -> Decision {
        self.decisions[node as usize][usize::from(i)]
    }
}

/// obvhs's cost of a primitive relative to a node visit.
const PRIM_COST: f32 = 0.3;
/// Most primitives in one wide leaf (the converter's `max_prims_per_leaf`).
const MAX_PRIMS_PER_LEAF: u32 = 3;
/// obvhs's `DENOM`: one over the quantisation's 255 steps.
const DENOM: f32 = 1.0 / 255.0;

/// One of obvhs's decisions in a byte: what the node is when it gets `i + 1` of a wide
/// node's slots (`kind`), and how the slots are shared between its children (`left` and
/// `right`, each below 7, or [`NONE`] when no finite cost chose them).
#[derive(Clone, Copy, Default, PartialEq, Eq, Debug)]
pub struct Decision(u8);

const LEAF: u8 = 0;
const INTERNAL: u8 = 1;
const DISTRIBUTE: u8 = 2;
/// obvhs's `INVALID` distribution, which it would use as an index if it ever read it.
const NONE: u8 = 7;

impl Decision {
    /// A leaf's decisions: it stays a leaf whatever it gets.
    pub const LEAF: Decision = Decision(0);

    fn new(kind: u8, left: u8, right: u8) -> Decision {
        Decision(kind << 6 | right.min(NONE) << 3 | left.min(NONE))
    }

    fn kind(self) -> u8 {
        self.0 >> 6
    }

    fn left(self) -> u8 {
        self.0 & 0b111
    }

    fn right(self) -> u8 {
        (self.0 >> 3) & 0b111
    }
}

/// Converts `tree` (rooted at node 0) into wide nodes, each turned into a `T` by `make` as
/// soon as it is complete. Returns the nodes and `primitive_indices`, or `None` where
/// obvhs's converter would read outside its tables (no finite cost chose a distribution)
/// or `make` refuses a node.
pub fn convert<T: Clone + Default + Send + Sync>(
    tree: &(impl BinaryTree + Sync),
    make: impl Fn(&CwBvhNode) -> Option<T> + Sync,
) -> Option<(Vec<T>, Vec<u32>)> {
    convert_with(tree, make, tree.node_count() >= PARALLEL_NODES)
}

/// Trees of at least this many binary nodes have the subtrees below their root converted
/// in parallel.
const PARALLEL_NODES: usize = 1 << 16;

/// [`convert`], with the root's inner children's subtrees converted in parallel (on the
/// current rayon pool) when `parallel`. Each is first counted (its wide nodes and
/// primitives), so that it can be written straight to where the depth-first conversion
/// would put it: the result is the same either way, and no subtree is copied.
pub fn convert_with<T: Clone + Default + Send + Sync>(
    tree: &(impl BinaryTree + Sync),
    make: impl Fn(&CwBvhNode) -> Option<T> + Sync,
    parallel: bool,
) -> Option<(Vec<T>, Vec<u32>)> {
    if tree.node_count() == 0 {
        return Some((Vec::new(), Vec::new()));
    }
    let converter = Converter { tree, make: &make };
    let mut out = Appended {
        nodes: vec![T::default()],
        primitives: Vec::new(),
    };
    let root = converter.node(&mut out, 0, 0)?;
    if parallel {
        converter.subtrees_in_parallel(&mut out, &root)?;
    } else {
        for (offset, &child) in root.inner_children().iter().enumerate() {
            converter.subtree(&mut out, root.child_base + offset, child)?;
        }
    }
    Some((out.nodes, out.primitives))
}

/// obvhs's costs of a leaf of one primitive with this half area (the same for any number
/// of wide slots).
pub fn leaf_costs(half_area: f32) -> [f32; 7] {
    [half_area * 1.0 * PRIM_COST; 7]
}

/// obvhs's `calculate_cost_impl` for an inner node of `num_primitives` primitives, from
/// its children's costs: its costs and its decisions. Entry `i` is for the node getting
/// `i + 1` slots of a wide node: a leaf or a wide node of its own (`i = 0`), or the slots
/// shared between its children.
pub fn decide(
    half_area: f32,
    first_costs: &[f32; 7],
    second_costs: &[f32; 7],
    num_primitives: u32,
) -> ([f32; 7], [Decision; 7]) {
    let mut cost = [0.0f32; 7];
    let mut decided = [Decision::default(); 7];

    let cost_leaf = if num_primitives <= MAX_PRIMS_PER_LEAF {
        (num_primitives as f32) * half_area * PRIM_COST
    } else {
        f32::INFINITY
    };
    let mut cost_distribute = f32::INFINITY;
    let (mut left, mut right) = (NONE, NONE);
    for k in 0..7 {
        let c = first_costs[k] + second_costs[6 - k];
        if c < cost_distribute {
            cost_distribute = c;
            left = k as u8;
            right = 6 - k as u8;
        }
    }
    let cost_internal = cost_distribute + half_area;
    if cost_leaf < cost_internal {
        cost[0] = cost_leaf;
        decided[0] = Decision::new(LEAF, left, right);
    } else {
        cost[0] = cost_internal;
        decided[0] = Decision::new(INTERNAL, left, right);
    }

    // obvhs scans each entry's shares starting from the previous entry's cost, taking a
    // share only when strictly cheaper. That is: the first least share (NaN never taken),
    // if it is below the previous cost. The least shares do not depend on one another, so
    // they are found first, all six scans free to overlap, and only the comparisons with
    // the previous costs are left in a chain (a tenth of the million-object build).
    let mut least = [(f32::INFINITY, None); 7];
    for (i, entry) in least.iter_mut().enumerate().skip(1) {
        for k in 0..i {
            let c = first_costs[k] + second_costs[i - k - 1];
            if c < entry.0 {
                *entry = (c, Some((k as u8, (i - k - 1) as u8)));
            }
        }
    }
    for i in 1..7 {
        let (c, share) = least[i];
        (cost[i], decided[i]) = match share {
            Some((left, right)) if c < cost[i - 1] => (c, Decision::new(DISTRIBUTE, left, right)),
            _ => (cost[i - 1], decided[i - 1]),
        };
    }
    (cost, decided)
}

/// Where the converter writes: wide nodes by their index in the whole tree, and the
/// primitives in order.
trait Output<T> {
    /// The index the next block of nodes gets.
    fn node_len(&self) -> usize;
    /// Reserves the next `count` nodes (a node's block of inner children).
    fn grow(&mut self, count: usize);
    fn set(&mut self, index: usize, node: T) -> Option<()>;
    /// How many primitives precede the next one.
    fn primitive_len(&self) -> usize;
    fn push_primitive(&mut self, primitive: u32) -> Option<()>;
}

/// The whole tree's arrays, grown as the conversion goes.
struct Appended<T> {
    nodes: Vec<T>,
    primitives: Vec<u32>,
}

impl<T: Clone + Default> Output<T> for Appended<T> {
    fn node_len(&self) -> usize {
        self.nodes.len()
    }
    fn grow(&mut self, count: usize) {
        self.nodes.resize(self.nodes.len() + count, T::default());
    }
    fn set(&mut self, index: usize, node: T) -> Option<()> {
        *self.nodes.get_mut(index)? = node;
        Some(())
    }
    fn primitive_len(&self) -> usize {
        self.primitives.len()
    }
    fn push_primitive(&mut self, primitive: u32) -> Option<()> {
        self.primitives.push(primitive);
        Some(())
    }
}

/// One subtree's share of the whole tree's arrays: its root's slot (in its parent's
/// block), the nodes below it (from index `node_base`) and its primitives (from
/// `primitive_base`), filled in order.
struct InPlace<'a, T> {
    root_index: usize,
    root: &'a mut T,
    nodes: &'a mut [T],
    node_base: usize,
    nodes_used: usize,
    primitives: &'a mut [u32],
    primitive_base: usize,
    primitives_used: usize,
}

impl<T> Output<T> for InPlace<'_, T> {
    fn node_len(&self) -> usize {
        self.node_base + self.nodes_used
    }
    fn grow(&mut self, count: usize) {
        self.nodes_used += count;
    }
    fn set(&mut self, index: usize, node: T) -> Option<()> {
        if index == self.root_index {
            *self.root = node;
        } else {
            // Only a reserved node: a count that fell short gives no tree, never a panic.
            let local = index
                .checked_sub(self.node_base)
                .filter(|&i| i < self.nodes_used)?;
            *self.nodes.get_mut(local)? = node;
        }
        Some(())
    }
    fn primitive_len(&self) -> usize {
        self.primitive_base + self.primitives_used
    }
    fn push_primitive(&mut self, primitive: u32) -> Option<()> {
        *self.primitives.get_mut(self.primitives_used)? = primitive;
        self.primitives_used += 1;
        Some(())
    }
}

/// A wide node just made: where its block of inner children starts, and the binary nodes
/// that become them, in slot order.
struct Made {
    child_base: usize,
    inner_children: [u32; 8],
    inner_count: usize,
}

impl Made {
    fn inner_children(&self) -> &[u32] {
        &self.inner_children[..self.inner_count]
    }
}

struct Converter<'a, Tree, Make> {
    tree: &'a Tree,
    make: &'a Make,
}

impl<Tree: BinaryTree + Sync, Make> Converter<'_, Tree, Make> {
    /// Converts the subtree of wide nodes rooted at binary node `node` into slot `wide`,
    /// depth first.
    fn subtree<T: Clone + Default>(
        &self,
        out: &mut impl Output<T>,
        wide: usize,
        node: u32,
    ) -> Option<()>
    where
        Make: Fn(&CwBvhNode) -> Option<T>,
    {
        let made = self.node(out, wide, node)?;
        for (offset, &child) in made.inner_children().iter().enumerate() {
            self.subtree(out, made.child_base + offset, child)?;
        }
        Some(())
    }

    /// The subtrees of `root`'s inner children, each counted and then converted in place,
    /// in parallel.
    fn subtrees_in_parallel<T: Clone + Default + Send + Sync>(
        &self,
        out: &mut Appended<T>,
        root: &Made,
    ) -> Option<()>
    where
        Make: Fn(&CwBvhNode) -> Option<T> + Sync,
    {
        let counts: Vec<Option<(usize, usize)>> = root
            .inner_children()
            .par_iter()
            .map(|&child| self.count(child))
            .collect();
        let counts: Vec<(usize, usize)> = counts.into_iter().collect::<Option<_>>()?;
        let (node_start, primitive_start) = (out.nodes.len(), out.primitives.len());
        let below: usize = counts.iter().map(|&(nodes, _)| nodes - 1).sum();
        let primitives: usize = counts.iter().map(|&(_, primitives)| primitives).sum();
        out.nodes.resize(node_start + below, T::default());
        out.primitives.resize(primitive_start + primitives, 0);
        // Hands each subtree its root's slot and its disjoint ranges of both arrays.
        let (head, mut nodes_left) = out.nodes.split_at_mut(node_start);
        let mut roots = head.get_mut(root.child_base..)?.iter_mut();
        let mut primitives_left = &mut out.primitives[primitive_start..];
        let (mut node_base, mut primitive_base) = (node_start, primitive_start);
        let mut jobs = Vec::with_capacity(counts.len());
        for (offset, (&child, &(node_count, primitive_count))) in
            root.inner_children().iter().zip(&counts).enumerate()
        {
            let (nodes, rest) = std::mem::take(&mut nodes_left).split_at_mut(node_count - 1);
            nodes_left = rest;
            let (primitives, rest) =
                std::mem::take(&mut primitives_left).split_at_mut(primitive_count);
            primitives_left = rest;
            let place = InPlace {
                root_index: root.child_base + offset,
                root: roots.next()?,
                nodes,
                node_base,
                nodes_used: 0,
                primitives,
                primitive_base,
                primitives_used: 0,
            };
            jobs.push((child, place));
            node_base += node_count - 1;
            primitive_base += primitive_count;
        }
        jobs.into_par_iter()
            .map(|(child, mut place)| {
                let wide = place.root_index;
                self.subtree(&mut place, wide, child)?;
                // The count and the conversion must agree to the node.
                (place.nodes_used == place.nodes.len()
                    && place.primitives_used == place.primitives.len())
                .then_some(())
            })
            .collect::<Option<()>>()
    }

    /// The wide nodes and primitives of the subtree rooted at binary node `node`, as
    /// [`Converter::subtree`] would write them.
    fn count(&self, node: u32) -> Option<(usize, usize)> {
        let mut children = [u32::MAX; 8];
        let mut child_count = 0;
        self.children(node, &mut children, &mut child_count, 0)?;
        let (mut nodes, mut primitives) = (1, 0);
        for &child in &children[..child_count] {
            if self.tree.decision(child, 0).kind() == LEAF {
                primitives += self.leaf_count(child);
            } else {
                let (n, p) = self.count(child)?;
                nodes += n;
                primitives += p;
            }
        }
        Some((nodes, primitives))
    }

    /// The primitives below binary node `node`.
    fn leaf_count(&self, node: u32) -> usize {
        match self.tree.children(node) {
            None => 1,
            Some([first, second]) => self.leaf_count(first) + self.leaf_count(second),
        }
    }

    /// obvhs's `convert_to_cwbvh_impl` for one node: wide node `wide` from binary node
    /// `node`, its leaf children's primitives appended, its inner children's block
    /// reserved (for the caller to fill).
    fn node<T: Clone + Default>(
        &self,
        output: &mut impl Output<T>,
        wide: usize,
        node: u32,
    ) -> Option<Made>
    where
        Make: Fn(&CwBvhNode) -> Option<T>,
    {
        let aabb = self.tree.aabb(node);
        let mut out = CwBvhNode::default();
        let node_p = aabb.min;
        out.p = node_p.into();
        let e = ((aabb.max - aabb.min).max(Vec3A::splat(1e-20)) * DENOM)
            .log2()
            .ceil()
            .exp2();
        let rcp_e = 1.0 / e;
        // Only the exponent bits of a power of two are set.
        out.e = [e.x, e.y, e.z].map(|c| (c.to_bits() >> 23) as u8);

        let mut children = [u32::MAX; 8];
        let mut child_count = 0;
        self.children(node, &mut children, &mut child_count, 0)?;
        self.order_children(node, &mut children, child_count);

        out.primitive_base_idx = output.primitive_len() as u32;
        out.child_base_idx = output.node_len() as u32;
        let mut made = Made {
            child_base: output.node_len(),
            inner_children: [u32::MAX; 8],
            inner_count: 0,
        };
        let mut num_primitives = 0u32;
        for (i, &child) in children.iter().enumerate() {
            if child == u32::MAX {
                continue;
            }
            let child_aabb = self.tree.aabb(child);
            const PAD: f32 = 0.0;
            let child_min = ((child_aabb.min - node_p - PAD) * rcp_e)
                .floor()
                .clamp(Vec3A::ZERO, Vec3A::splat(255.0));
            let child_max = ((child_aabb.max - node_p + PAD) * rcp_e)
                .ceil()
                .clamp(Vec3A::ZERO, Vec3A::splat(255.0));
            out.child_min_x[i] = child_min.x as u8;
            out.child_min_y[i] = child_min.y as u8;
            out.child_min_z[i] = child_min.z as u8;
            out.child_max_x[i] = child_max.x as u8;
            out.child_max_y[i] = child_max.y as u8;
            out.child_max_z[i] = child_max.z as u8;
            match self.tree.decision(child, 0).kind() {
                LEAF => {
                    let count = self.push_primitives(output, child)?;
                    out.child_meta[i] = num_primitives as u8
                        | match count {
                            1 => 0b0010_0000,
                            2 => 0b0110_0000,
                            3 => 0b1110_0000,
                            // obvhs panics here; no wide tree.
                            _ => return None,
                        };
                    num_primitives += count;
                }
                _ => {
                    out.imask |= 1 << i;
                    out.child_meta[i] = (24 + i as u8) | 0b0010_0000;
                    made.inner_children[made.inner_count] = child;
                    made.inner_count += 1;
                }
            }
        }
        let wide_node = (self.make)(&out)?;
        output.grow(made.inner_count);
        output.set(wide, wide_node)?;
        Some(made)
    }

    /// obvhs's `count_primitives`: appends the primitives below `node`, left first, and
    /// returns how many.
    fn push_primitives<T>(&self, output: &mut impl Output<T>, node: u32) -> Option<u32> {
        match self.tree.children(node) {
            None => {
                output.push_primitive(self.tree.primitive(node))?;
                Some(1)
            }
            Some([first, second]) => {
                Some(self.push_primitives(output, first)? + self.push_primitives(output, second)?)
            }
        }
    }

    /// obvhs's `get_children`: the binary nodes that become the slots of a wide node when
    /// `node` gets `i + 1` of them.
    fn children(&self, node: u32, children: &mut [u32; 8], count: &mut usize, i: u8) -> Option<()> {
        let Some([first, second]) = self.tree.children(node) else {
            *children.get_mut(*count)? = node;
            *count += 1;
            return Some(());
        };
        let decision = self.tree.decision(node, i);
        for (child, share) in [(first, decision.left()), (second, decision.right())] {
            if share == NONE {
                return None;
            }
            if self.tree.decision(child, share).kind() == DISTRIBUTE {
                self.children(child, children, count, share)?;
            } else {
                *children.get_mut(*count)? = child;
                *count += 1;
            }
        }
        Some(())
    }

    /// obvhs's `order_children`: children to slots by a greedy assignment of the octant
    /// directions, so that a ray's octant gives the order of visits.
    fn order_children(&self, node: u32, children: &mut [u32; 8], child_count: usize) {
        let p = self.tree.aabb(node).center();
        // Each child's offset once (obvhs recomputes it for each of the 8 directions; the
        // value is the same).
        let mut offsets = [Vec3A::ZERO; 8];
        for (offset, &child) in offsets.iter_mut().zip(&children[..child_count]) {
            *offset = self.tree.aabb(child).center() - p;
        }
        let mut cost = [[f32::MAX; 8]; 8];
        for (s, direction) in DIRECTIONS.iter().enumerate() {
            for c in 0..child_count {
                cost[c][s] = direction.dot(offsets[c]);
            }
        }
        let mut assignment = [usize::MAX; 8];
        let mut slot_filled = [false; 8];
        loop {
            let mut min_cost = f32::MAX;
            let mut min_slot = usize::MAX;
            let mut min_index = usize::MAX;
            for c in 0..child_count {
                if assignment[c] == usize::MAX {
                    for (s, &filled) in slot_filled.iter().enumerate() {
                        if !filled && cost[c][s] < min_cost {
                            min_cost = cost[c][s];
                            min_slot = s;
                            min_index = c;
                        }
                    }
                }
            }
            if min_slot == usize::MAX {
                break;
            }
            slot_filled[min_slot] = true;
            assignment[min_index] = min_slot;
        }
        let original = std::mem::replace(children, [u32::MAX; 8]);
        for c in 0..child_count {
            // obvhs asserts every child found a slot (costs are never NaN for finite boxes).
            if let Some(slot) = children.get_mut(assignment[c]) {
                *slot = original[c];
            }
        }
    }
}

/// obvhs's `direction_lut`: slot `s` stands for the direction with a negative x, y, z
/// where bits 2, 1, 0 of `s` are set.
const DIRECTIONS: [Vec3A; 8] = {
    let mut out = [Vec3A::ZERO; 8];
    let mut s = 0;
    while s < 8 {
        out[s] = Vec3A::new(
            if s & 0b100 != 0 { -1.0 } else { 1.0 },
            if s & 0b010 != 0 { -1.0 } else { 1.0 },
            if s & 0b001 != 0 { -1.0 } else { 1.0 },
        );
        s += 1;
    }
    out
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::binary::{build_bvh2, build_bvh2_with};
    use crate::testing::{inputs, Random};
    use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;

    /// The conversion makes obvhs's `bvh2_to_cwbvh(bvh2, 3, true, false)` exactly: the same
    /// nodes (every field, the origin to the bit) and the same primitive order, for trees
    /// of both builds (the binned SAH's and the Morton-topped), converted in one piece and
    /// with the root's subtrees in parallel, on one thread and on three.
    #[test]
    fn conversion_is_obvhs_conversion() {
        let mut all = inputs();
        let mut random = Random(99);
        let large = (0..40_000)
            .map(|_| {
                let c = random.vec() * 300.0;
                Aabb::new(c, c + random.vec() * 4.0 + 0.01)
            })
            .collect();
        all.push(("large".into(), large));
        for (name, aabbs) in all {
            for morton_min in [usize::MAX, 2] {
                let tree = build_bvh2_with(&aabbs[..], morton_min).tree;
                let expected = bvh2_to_cwbvh(&tree.to_bvh2(), 3, true, false);
                for (threads, parallel) in [(1, false), (1, true), (3, true)] {
                    let case = format!(
                        "{name}, Morton from {morton_min}, {threads} threads, parallel {parallel}"
                    );
                    let pool = rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .unwrap_or_else(|e| panic!("no pool: {e}"));
                    let converted =
                        pool.install(|| convert_with(&tree, |node| Some(*node), parallel));
                    let Some((nodes, primitive_indices)) = converted else {
                        panic!("{case}: no conversion");
                    };
                    assert_eq!(primitive_indices, expected.primitive_indices, "{case}");
                    assert_eq!(nodes.len(), expected.nodes.len(), "{case}");
                    for (i, (ours, theirs)) in nodes.iter().zip(&expected.nodes).enumerate() {
                        assert_eq!(ours, theirs, "{case}: node {i}");
                        assert_eq!(
                            ours.p.to_array().map(f32::to_bits),
                            theirs.p.to_array().map(f32::to_bits),
                            "{case}: node {i}"
                        );
                    }
                }
            }
        }
    }

    /// A refused node stops the conversion (the caller then falls back to obvhs's), in a
    /// subtree converted in parallel too.
    #[test]
    fn a_refused_node_gives_no_conversion() {
        let tree = build_bvh2(&inputs()[10].1[..]).tree;
        for parallel in [false, true] {
            let converted =
                convert_with(&tree, |node| (node.imask == 0).then_some(*node), parallel);
            assert!(converted.is_none());
        }
    }

    #[test]
    fn decisions_keep_their_parts() {
        for kind in [LEAF, INTERNAL, DISTRIBUTE] {
            for left in 0..=NONE {
                for right in 0..=NONE {
                    let d = Decision::new(kind, left, right);
                    assert_eq!((d.kind(), d.left(), d.right()), (kind, left, right));
                }
            }
        }
        assert_eq!(Decision::new(LEAF, u8::MAX, 3).left(), NONE);
    }
}
