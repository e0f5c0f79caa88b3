//! CSG by interval lists along the ray (Roth, 1982).
//!
//! Every leaf solid reports the spans of the ray parameter where the ray is inside it; an
//! operation combines its children's sorted span lists by a sweep over their boundaries;
//! the first surviving boundary after `tmin` is the hit, and it remembers which leaf made
//! it and whether that leaf's normal must be flipped (surfaces of subtracted solids are
//! seen from outside the subtrahend, so their outward normal points the other way).
//!
//! Evaluation is iterative over an explicit stack and works in a per-thread [`CsgScratch`]
//! whose buffers grow to the largest tree seen and are then reused: no allocation per ray,
//! no recursion limit, and no fixed cap on the number of spans.
//!
//! A union or difference with many children carries a BVH over its children's bounds
//! ([`ChildAccel`]): a ray then evaluates only the children whose boxes its window touches
//! (for a difference, the first child and the subtracted ones it touches), in source order,
//! which is exactly what the plain loop computes, since an untouched child adds no span.
//! At the root, the first hit narrows the window further ([`CsgTree::first_hit`]): an
//! accelerated union walks that BVH for the nearest crossing of any child, as a group's
//! nearest-hit query would, and a difference looks at its first child's first crossing.

use glam::{UVec2, Vec3A};
use obvhs::aabb::Aabb;
use whitted_ir::CsgOp;

use crate::scene::Leaf;
use crate::shapes::{Geometry, Part, RawSpan};
use whitted_bvh::Ray;
use whitted_bvh::{inverse_direction, Bound};
use whitted_bvh::{Bvh, Step};

/// A point where the ray crosses into or out of a solid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary {
    pub t: f32,
    /// The index of the leaf in its tree whose surface this is.
    pub leaf: u32,
    pub part: Part,
    /// Whether the leaf's outward normal must be reversed to point out of the result.
    pub flip: bool,
}

/// An interval of the ray parameter inside a solid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    pub enter: Boundary,
    pub exit: Boundary,
}

#[derive(Clone, Debug, PartialEq)]
pub enum CsgNode {
    Leaf {
        leaf: u32,
        bound: Bound,
    },
    Op {
        op: CsgOp,
        /// Range into [`CsgTree::children`].
        first_child: u32,
        child_count: u32,
        bound: Bound,
        /// Index into [`CsgTree::accels`], or [`NO_ACCEL`].
        accel: u32,
    },
}

/// An operation without a BVH over its children.
pub const NO_ACCEL: u32 = u32::MAX;

/// From this many children on, a union or difference gets a BVH over its children.
pub const ACCEL_MIN_CHILDREN: usize = 8;

/// The BVH over an operation's children, and the children it cannot hold.
#[derive(Clone, Debug)]
pub struct ChildAccel {
    bvh: Bvh,
    /// The child position (0-based among the node's children) of each BVH primitive id.
    positions: Vec<u32>,
    /// Positions evaluated for every ray: unbounded children, and a difference's first.
    always: Vec<u32>,
}

impl ChildAccel {
    /// The BVH over the children at `bounds` (positions in order); `None` when it would not
    /// help (an intersection, too few children, or too few bounded ones).
    pub fn new(op: CsgOp, bounds: &[Bound]) -> Option<ChildAccel> {
        if op == CsgOp::Intersection || bounds.len() < ACCEL_MIN_CHILDREN {
            return None;
        }
        let mut always = Vec::new();
        let mut boxed: Vec<(u32, Aabb)> = Vec::new();
        for (position, bound) in bounds.iter().enumerate() {
            let position = position as u32;
            match bound {
                _ if op == CsgOp::Difference && position == 0 => always.push(position),
                Bound::Infinite => always.push(position),
                // An empty child adds no span to a union or a difference.
                Bound::Empty => {}
                Bound::Finite(aabb) => boxed.push((position, *aabb)),
            }
        }
        if boxed.len() < ACCEL_MIN_CHILDREN {
            return None;
        }
        let aabbs: Vec<Aabb> = boxed.iter().map(|&(_, aabb)| aabb).collect();
        let (bvh, indices) = Bvh::build(&aabbs);
        if bvh.node_count() == 0 || indices.len() != boxed.len() {
            return None;
        }
        let positions = indices
            .iter()
            .map(|&i| boxed.get(i as usize).map_or(0, |&(p, _)| p))
            .collect();
        Some(ChildAccel {
            bvh,
            positions,
            always,
        })
    }

    /// Appends to `out` the positions of the children the window may touch, ascending.
    fn touched(&self, ray: &Ray, tmin: f32, tmax: f32, stack: &mut Vec<UVec2>, out: &mut Vec<u32>) {
        let start = out.len();
        out.extend_from_slice(&self.always);
        self.bvh.traverse(ray, tmin, tmax, stack, |id, _| {
            if let Some(&position) = self.positions.get(id as usize) {
                out.push(position);
            }
            Step::Continue
        });
        out[start..].sort_unstable();
    }
}

/// One top-level CSG object: nodes in bottom-up order (the root is last) and its leaves.
#[derive(Clone, Debug, Default)]
pub struct CsgTree {
    pub nodes: Vec<CsgNode>,
    pub children: Vec<u32>,
    pub leaves: Vec<Leaf>,
    pub accels: Vec<ChildAccel>,
}

/// What an accelerated union's nearest child crossing says about its first boundary.
#[derive(Clone, Copy, Debug)]
enum Nearest {
    /// No child crosses the window: neither does the union.
    Nothing,
    /// The ray starts outside every child: the union's first boundary is this entry.
    Exact(Boundary),
    /// The union's first boundary is no nearer than this.
    AtLeast(f32),
}

/// A child's first crossing inside a window, and whether the ray starts inside it.
#[derive(Clone, Copy, Debug)]
struct Crossing {
    first: Option<Boundary>,
    inside: bool,
}

#[derive(Clone, Copy, Debug)]
struct Frame {
    node: u32,
    /// How many children have been started.
    next: u32,
    /// Where this node's accumulated spans begin in the scratch list.
    start: u32,
    /// Where the most recent child's spans begin.
    middle: u32,
    /// With a [`ChildAccel`]: where this node's touched child positions begin in
    /// `CsgScratch::touched`, and how many there are.
    touched_start: u32,
    touched_len: u32,
}

/// Reusable buffers for CSG evaluation; one per worker thread (or per tile).
#[derive(Clone, Debug, Default)]
pub struct CsgScratch {
    spans: Vec<Span>,
    merged: Vec<Span>,
    stack: Vec<Frame>,
    /// Child positions touched by the ray, one run per accelerated node on the stack.
    touched: Vec<u32>,
    bvh_stack: Vec<UVec2>,
    /// The stack of the walk for an accelerated union's nearest child crossing.
    nearest_stack: Vec<UVec2>,
    /// The child positions that walk looked at, for evaluating the window up to the
    /// crossing it found (sorted before that).
    preset: Vec<u32>,
    /// A solid mesh's crossings along the ray, before they are paired into spans.
    mesh_hits: Vec<(f32, Part, bool)>,
}

impl CsgTree {
    /// The same tree with every operation evaluated by the plain loop over its children:
    /// the oracle for the accelerated evaluation.
    #[cfg(test)]
    pub fn without_acceleration(&self) -> CsgTree {
        let mut plain = self.clone();
        plain.accels.clear();
        for node in &mut plain.nodes {
            if let CsgNode::Op { accel, .. } = node {
                *accel = NO_ACCEL;
            }
        }
        plain
    }

    /// The same tree evaluated by brute force: every child of every operation, with no
    /// bound to skip any: the oracle for bounds and acceleration together.
    #[cfg(test)]
    pub fn brute_force(&self) -> CsgTree {
        let mut plain = self.without_acceleration();
        for node in &mut plain.nodes {
            match node {
                CsgNode::Leaf { bound, .. } | CsgNode::Op { bound, .. } => {
                    *bound = Bound::Infinite;
                }
            }
        }
        plain
    }

    /// The first boundary from evaluating the whole window, with none of the narrower
    /// windows [`CsgTree::first_hit`] tries first: with [`CsgTree::brute_force`], the
    /// oracle.
    #[cfg(test)]
    pub fn first_hit_in_whole_window(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut CsgScratch,
    ) -> Option<Boundary> {
        self.evaluate(ray, tmin, tmax, scratch);
        first_boundary(&scratch.spans, tmin, tmax)
    }

    fn root(&self) -> u32 {
        self.nodes.len().saturating_sub(1) as u32
    }

    /// The nearest boundary of the whole solid strictly inside `(tmin, tmax)`.
    ///
    /// An accelerated union first looks for its nearest child crossing, as a group would,
    /// which is the hit when the ray starts outside every child and otherwise bounds a
    /// narrower window to evaluate first ([`CsgTree::nearest_child_crossing`]); a difference
    /// evaluates first the window up to its first child's first crossing
    /// ([`CsgTree::minuend_crossings`]). Either way the whole window is the last resort.
    pub fn first_hit(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut CsgScratch,
    ) -> Option<Boundary> {
        if let Some(nearest) = self.nearest_child_crossing(ray, tmin, tmax, scratch) {
            let end = match nearest {
                Nearest::Nothing => return None,
                Nearest::Exact(boundary) => return Some(boundary),
                Nearest::AtLeast(t) => {
                    scratch.preset.sort_unstable();
                    t.next_up()
                }
            };
            if end < tmax {
                self.evaluate_from(self.root(), true, ray, tmin, end, scratch);
                if let Some(boundary) = first_boundary(&scratch.spans, tmin, end) {
                    return Some(boundary);
                }
            }
        } else if let Some(minuend) = self.minuend_crossings(ray, tmin, tmax) {
            let (first, last) = minuend?;
            let end = first.next_up();
            if end < tmax {
                self.evaluate(ray, tmin, end, scratch);
                let found = first_boundary(&scratch.spans, tmin, end);
                // Nothing of the difference lies beyond its first child's last exit.
                if found.is_some() || last < end {
                    return found;
                }
            }
        }
        self.evaluate(ray, tmin, tmax, scratch);
        first_boundary(&scratch.spans, tmin, tmax)
    }

    /// For a difference whose first child is a plain leaf: `Some(None)` when the ray is
    /// outside that child all along `(tmin, tmax)`, else `Some(Some((first, last)))`, its
    /// first crossing there and its last exit along the whole line; `None` for any other
    /// tree, or when the window lies inside the child.
    ///
    /// A difference is inside its first child, so its boundaries lie between that child's
    /// crossings: the first is no nearer than `first` when the ray starts outside the
    /// child (its entry), often exactly there (a ray meeting the solid's outer face), and
    /// none is beyond `last`. [`CsgTree::first_hit`] evaluates the window up to `first`;
    /// only the rays that enter through a cut go on to the whole window.
    fn minuend_crossings(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Option<(f32, f32)>> {
        let CsgNode::Op {
            op: CsgOp::Difference,
            first_child,
            child_count,
            ..
        } = self.nodes.last()?
        else {
            return None;
        };
        if *child_count == 0 {
            return None;
        }
        let CsgNode::Leaf { leaf, bound } = self
            .nodes
            .get(*self.children.get(*first_child as usize)? as usize)?
        else {
            return None;
        };
        let geometry = &self.leaves.get(*leaf as usize)?.geometry;
        if matches!(geometry, Geometry::Mesh(_)) {
            return None;
        }
        if !bound.admits(ray, inverse_direction(ray.direction), tmin, tmax) {
            return Some(None);
        }
        let spans = geometry.spans(ray);
        let mut proper = spans.as_slice().iter().filter(|raw| is_proper(raw));
        let Some(span) = proper.clone().find(|raw| raw.t_out > tmin) else {
            return Some(None);
        };
        let outside = span.t_in > tmin;
        let first = if outside { span.t_in } else { span.t_out };
        if first >= tmax {
            // Outside the first child all along the window, the difference is too; inside
            // it, the cuts may still cross the window.
            return outside.then_some(None);
        }
        let last = proper.next_back().map_or(span.t_out, |raw| raw.t_out);
        Some(Some((first, last)))
    }

    /// For a tree whose root is an accelerated union, what its nearest child crossing
    /// tells about its first boundary inside `(tmin, tmax)`; `None` for any other tree.
    ///
    /// Why this is exact: every boundary of a union is a boundary of one of its children,
    /// so with no child crossing there the union has none. A child whose box the segment
    /// misses cannot contain the ray's start, and the walk's limit never falls below the
    /// nearest crossing, so the walk sees every child that could be inside at `tmin`. If
    /// none is, the ray starts outside the union and its first boundary is the nearest
    /// child entry; at a tie, the child first in source order, as the sweep takes the
    /// earlier list first at equal entries. Otherwise the nearest crossing is only a lower
    /// bound, and [`CsgTree::first_hit`] evaluates the window up to it, with the children
    /// the walk visited (spans are exact inside any window, see [`CsgTree::evaluate`]).
    fn nearest_child_crossing(
        &self,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut CsgScratch,
    ) -> Option<Nearest> {
        let CsgNode::Op {
            op: CsgOp::Union,
            first_child,
            child_count,
            bound,
            accel,
        } = self.nodes.last()?
        else {
            return None;
        };
        let accel = self.accels.get(*accel as usize)?;
        let inv_direction = inverse_direction(ray.direction);
        if *child_count == 0 || !bound.admits(ray, inv_direction, tmin, tmax) {
            return Some(Nearest::Nothing);
        }
        let child_at = |position: u32| self.children.get((*first_child + position) as usize);
        // The nearest crossing so far and the position of its child.
        let mut nearest: Option<(Boundary, u32)> = None;
        let mut started_inside = false;
        // Every child the walk looks at: a superset of those whose boxes touch the window
        // up to the nearest crossing.
        let mut visited = std::mem::take(&mut scratch.preset);
        visited.clear();
        let mut consider = |position: u32, scratch: &mut CsgScratch| -> Option<f32> {
            let &child = child_at(position)?;
            visited.push(position);
            // Up to and including the nearest so far, for ties.
            let limit = nearest.map_or(tmax, |(b, _)| b.t.next_up().min(tmax));
            let crossing = self.child_crossing(child, ray, inv_direction, tmin, limit, scratch);
            started_inside |= crossing.inside;
            let found = crossing.first?;
            let nearer = match nearest {
                None => true,
                Some((best, best_position)) => {
                    found.t < best.t || (found.t == best.t && position < best_position)
                }
            };
            if nearer {
                nearest = Some((found, position));
            }
            nearer.then_some(found.t)
        };
        let mut start_limit = tmax;
        for &position in &accel.always {
            if let Some(t) = consider(position, scratch) {
                start_limit = t;
            }
        }
        // The walk's own stack, apart from the one that evaluating a child may use.
        let mut stack = std::mem::take(&mut scratch.nearest_stack);
        accel
            .bvh
            .traverse(ray, tmin, start_limit, &mut stack, |id, _| {
                match accel
                    .positions
                    .get(id as usize)
                    .and_then(|&position| consider(position, scratch))
                {
                    Some(t) => Step::Shrink(t),
                    None => Step::Continue,
                }
            });
        scratch.nearest_stack = stack;
        // Sorted into source order only if the window is evaluated (`AtLeast`).
        scratch.preset = visited;
        Some(match nearest {
            None => Nearest::Nothing,
            Some((boundary, _)) if !started_inside => Nearest::Exact(boundary),
            Some((boundary, _)) => Nearest::AtLeast(boundary.t),
        })
    }

    /// The first crossing of node `child` strictly inside `(tmin, limit)`, and whether the
    /// ray is inside it just after `tmin`. A mesh reports where the ray enters its box (a
    /// lower bound) and counts as inside (unknown), so that the window is evaluated.
    fn child_crossing(
        &self,
        child: u32,
        ray: &Ray,
        inv_direction: Vec3A,
        tmin: f32,
        limit: f32,
        scratch: &mut CsgScratch,
    ) -> Crossing {
        const NONE: Crossing = Crossing {
            first: None,
            inside: false,
        };
        match self.nodes.get(child as usize) {
            Some(CsgNode::Leaf { leaf, bound }) => {
                let Some(geometry) = self.leaves.get(*leaf as usize).map(|l| &l.geometry) else {
                    return NONE;
                };
                if let Geometry::Mesh(_) = geometry {
                    let first = bound
                        .entry(ray, inv_direction, tmin, limit)
                        .map(|t| Boundary {
                            t,
                            leaf: *leaf,
                            part: 0,
                            flip: false,
                        });
                    return Crossing {
                        inside: first.is_some(),
                        first,
                    };
                }
                if !bound.admits(ray, inv_direction, tmin, limit) {
                    return NONE;
                }
                // The first end of a span the evaluation keeps.
                let spans = geometry.spans(ray);
                let Some(span) = spans
                    .as_slice()
                    .iter()
                    .find(|raw| is_proper(raw) && raw.t_out > tmin)
                else {
                    return NONE;
                };
                let inside = span.t_in <= tmin;
                let (t, part) = if inside {
                    (span.t_out, span.part_out)
                } else {
                    (span.t_in, span.part_in)
                };
                Crossing {
                    first: (t < limit).then_some(Boundary {
                        t,
                        leaf: *leaf,
                        part,
                        flip: false,
                    }),
                    inside,
                }
            }
            Some(CsgNode::Op { bound, .. }) => {
                if !bound.admits(ray, inv_direction, tmin, limit) {
                    return NONE;
                }
                self.evaluate_from(child, false, ray, tmin, limit, scratch);
                Crossing {
                    first: first_boundary(&scratch.spans, tmin, limit),
                    inside: scratch
                        .spans
                        .iter()
                        .any(|span| span.enter.t <= tmin && span.exit.t > tmin),
                }
            }
            None => NONE,
        }
    }

    /// Leaves the solid's spans along the ray in `scratch.spans`. Spans are exact inside
    /// the window `(tmin, tmax)`; children whose bound the window misses are skipped, so
    /// outside the window the list may be incomplete (nothing looks there).
    fn evaluate(&self, ray: &Ray, tmin: f32, tmax: f32, scratch: &mut CsgScratch) {
        self.evaluate_from(self.root(), false, ray, tmin, tmax, scratch);
    }

    /// [`CsgTree::evaluate`] for the subtree whose root is node `root`. With
    /// `preset_root`, an accelerated root evaluates the child positions in
    /// `scratch.preset` (ascending, and including every child whose box the window
    /// touches) instead of walking its BVH for them.
    fn evaluate_from(
        &self,
        root: u32,
        preset_root: bool,
        ray: &Ray,
        tmin: f32,
        tmax: f32,
        scratch: &mut CsgScratch,
    ) {
        let inv_direction = inverse_direction(ray.direction);
        scratch.spans.clear();
        scratch.stack.clear();
        scratch.touched.clear();
        if self.nodes.is_empty() {
            return;
        }
        scratch.stack.push(Frame::new(root));
        while let Some(&frame) = scratch.stack.last() {
            let top = scratch.stack.len() - 1;
            match &self.nodes[frame.node as usize] {
                CsgNode::Leaf { leaf, bound } => {
                    if bound.admits(ray, inv_direction, tmin, tmax) {
                        let leaf = *leaf;
                        let to_span = |raw: &RawSpan| {
                            let boundary = |t, part| Boundary {
                                t,
                                leaf,
                                part,
                                flip: false,
                            };
                            Span {
                                enter: boundary(raw.t_in, raw.part_in),
                                exit: boundary(raw.t_out, raw.part_out),
                            }
                        };
                        match &self.leaves[leaf as usize].geometry {
                            // Any number of spans, straight into the list.
                            Geometry::Mesh(mesh) => {
                                let CsgScratch {
                                    spans, mesh_hits, ..
                                } = scratch;
                                mesh.push_spans(ray, mesh_hits, |raw| {
                                    if is_proper(&raw) {
                                        spans.push(to_span(&raw));
                                    }
                                });
                            }
                            geometry => {
                                for raw in geometry.spans(ray).as_slice() {
                                    if is_proper(raw) {
                                        scratch.spans.push(to_span(raw));
                                    }
                                }
                            }
                        }
                    }
                    scratch.stack.pop();
                }
                CsgNode::Op {
                    op,
                    first_child,
                    child_count,
                    bound,
                    accel,
                } => {
                    let len = scratch.spans.len() as u32;
                    let accel = self.accels.get(*accel as usize);
                    if frame.next == 0 {
                        if *child_count == 0 || !bound.admits(ray, inv_direction, tmin, tmax) {
                            scratch.stack.pop();
                            continue;
                        }
                        scratch.stack[top].start = len;
                        if let Some(accel) = accel {
                            let touched_start = scratch.touched.len();
                            if preset_root && frame.node == root {
                                scratch.touched.extend_from_slice(&scratch.preset);
                            } else {
                                accel.touched(
                                    ray,
                                    tmin,
                                    tmax,
                                    &mut scratch.bvh_stack,
                                    &mut scratch.touched,
                                );
                            }
                            scratch.stack[top].touched_start = touched_start as u32;
                            scratch.stack[top].touched_len =
                                (scratch.touched.len() - touched_start) as u32;
                        }
                    } else if frame.next >= 2 {
                        // The child started last has finished: fold it into the accumulator.
                        combine_in_place(*op, frame.start as usize, frame.middle as usize, scratch);
                    }
                    let frame = scratch.stack[top];
                    let accumulated_empty = scratch.spans.len() as u32 == frame.start;
                    let count = match accel {
                        Some(_) => frame.touched_len,
                        None => *child_count,
                    };
                    let finished = frame.next == count
                        || (frame.next > 0 && accumulated_empty && *op != CsgOp::Union);
                    if finished {
                        if accel.is_some() {
                            scratch.touched.truncate(frame.touched_start as usize);
                        }
                        scratch.stack.pop();
                        continue;
                    }
                    let position = match accel {
                        Some(_) => scratch.touched[(frame.touched_start + frame.next) as usize],
                        None => frame.next,
                    };
                    let child = self.children[(*first_child + position) as usize];
                    scratch.stack[top].middle = scratch.spans.len() as u32;
                    scratch.stack[top].next += 1;
                    scratch.stack.push(Frame::new(child));
                }
            }
        }
    }
}

impl Frame {
    fn new(node: u32) -> Frame {
        Frame {
            node,
            next: 0,
            start: 0,
            middle: 0,
            touched_start: 0,
            touched_len: 0,
        }
    }
}

/// Whether a leaf's span has length: a ray that only touches a solid (a tangent, an edge)
/// is never inside it. Combining drops empty results anyway; dropping them at the leaves
/// too means an empty span counts the same whether or not its node has other children
/// with spans along the ray, so that skipping children (bounds, the BVH over them, the
/// union's window) cannot change a result.
#[inline]
fn is_proper(raw: &RawSpan) -> bool {
    raw.t_in < raw.t_out
}

/// Replaces `spans[start..]` (accumulator `[start, middle)` and child `[middle, ..)`) by
/// their combination.
fn combine_in_place(op: CsgOp, start: usize, middle: usize, scratch: &mut CsgScratch) {
    if scratch.spans.len() == middle {
        // The child is empty within the window.
        if op == CsgOp::Intersection {
            scratch.spans.truncate(start);
        }
        return;
    }
    let (accumulated, child) = scratch.spans.split_at(middle);
    scratch.merged.clear();
    combine(op, &accumulated[start..], child, &mut scratch.merged);
    scratch.spans.truncate(start);
    scratch.spans.extend_from_slice(&scratch.merged);
}

/// Combines two sorted, disjoint span lists by a sweep over their boundaries. At equal `t`
/// entries are taken before exits (so solids that touch fuse without a seam) and `a`
/// before `b`; empty results are dropped.
pub fn combine(op: CsgOp, a: &[Span], b: &[Span], out: &mut Vec<Span>) {
    let (mut i, mut j) = (0usize, 0usize);
    let (mut in_a, mut in_b) = (false, false);
    let mut inside = false;
    let mut open: Option<Boundary> = None;
    loop {
        let next_a = a.get(i).map(|s| {
            if in_a {
                (s.exit, true)
            } else {
                (s.enter, false)
            }
        });
        let next_b = b.get(j).map(|s| {
            if in_b {
                (s.exit, true)
            } else {
                (s.enter, false)
            }
        });
        let boundary = match (next_a, next_b) {
            (None, None) => break,
            (Some((boundary_a, exit_a)), other) => {
                let take_a = match other {
                    None => true,
                    Some((boundary_b, exit_b)) => {
                        if boundary_a.t != boundary_b.t {
                            boundary_a.t < boundary_b.t
                        } else {
                            !exit_a || exit_b
                        }
                    }
                };
                if take_a {
                    in_a = !exit_a;
                    i += usize::from(exit_a);
                    boundary_a
                } else {
                    take_b(op, other, &mut in_b, &mut j)
                }
            }
            (None, other) => take_b(op, other, &mut in_b, &mut j),
        };
        let now = match op {
            CsgOp::Union => in_a || in_b,
            CsgOp::Intersection => in_a && in_b,
            CsgOp::Difference => in_a && !in_b,
        };
        if now != inside {
            if now {
                open = Some(boundary);
            } else if let Some(enter) = open {
                if boundary.t > enter.t {
                    out.push(Span {
                        enter,
                        exit: boundary,
                    });
                }
            }
            inside = now;
        }
    }
}

/// Advances through list `b`; in a difference its surfaces bound the result from the
/// other side, so their normals flip.
fn take_b(op: CsgOp, next_b: Option<(Boundary, bool)>, in_b: &mut bool, j: &mut usize) -> Boundary {
    let Some((mut boundary, exit)) = next_b else {
        // Unreachable by construction (the caller has a boundary from `b`); an empty
        // boundary at +∞ is harmless if it ever happened.
        return Boundary {
            t: f32::INFINITY,
            leaf: u32::MAX,
            part: 0,
            flip: false,
        };
    };
    *in_b = !exit;
    *j += usize::from(exit);
    if op == CsgOp::Difference {
        boundary.flip = !boundary.flip;
    }
    boundary
}

fn first_boundary(spans: &[Span], tmin: f32, tmax: f32) -> Option<Boundary> {
    for span in spans {
        if span.enter.t > tmin {
            return (span.enter.t < tmax).then_some(span.enter);
        }
        if span.exit.t > tmin {
            return (span.exit.t < tmax).then_some(span.exit);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn span(t0: f32, t1: f32, leaf: u32) -> Span {
        let boundary = |t| Boundary {
            t,
            leaf,
            part: 0,
            flip: false,
        };
        Span {
            enter: boundary(t0),
            exit: boundary(t1),
        }
    }

    fn run(op: CsgOp, a: &[Span], b: &[Span]) -> Vec<(f32, u32, bool, f32, u32, bool)> {
        let mut out = Vec::new();
        combine(op, a, b, &mut out);
        out.iter()
            .map(|s| {
                (
                    s.enter.t,
                    s.enter.leaf,
                    s.enter.flip,
                    s.exit.t,
                    s.exit.leaf,
                    s.exit.flip,
                )
            })
            .collect()
    }

    #[test]
    fn union_merges_overlaps_and_keeps_gaps() {
        let a = [span(1.0, 3.0, 0), span(6.0, 7.0, 0)];
        let b = [span(2.0, 4.0, 1), span(8.0, 9.0, 1)];
        assert_eq!(
            run(CsgOp::Union, &a, &b),
            vec![
                (1.0, 0, false, 4.0, 1, false),
                (6.0, 0, false, 7.0, 0, false),
                (8.0, 1, false, 9.0, 1, false),
            ]
        );
    }

    #[test]
    fn intersection_keeps_the_common_part() {
        let a = [span(1.0, 3.0, 0), span(6.0, 9.0, 0)];
        let b = [span(2.0, 7.0, 1)];
        assert_eq!(
            run(CsgOp::Intersection, &a, &b),
            vec![
                (2.0, 1, false, 3.0, 0, false),
                (6.0, 0, false, 7.0, 1, false)
            ]
        );
        assert!(run(CsgOp::Intersection, &a, &[]).is_empty());
    }

    #[test]
    fn difference_flips_the_subtracted_surfaces() {
        let a = [span(1.0, 5.0, 0)];
        let b = [span(2.0, 3.0, 1)];
        assert_eq!(
            run(CsgOp::Difference, &a, &b),
            vec![(1.0, 0, false, 2.0, 1, true), (3.0, 1, true, 5.0, 0, false)]
        );
        // Subtracting something that covers the start leaves the flipped exit of b.
        let cover = [span(0.0, 2.0, 1)];
        assert_eq!(
            run(CsgOp::Difference, &a, &cover),
            vec![(2.0, 1, true, 5.0, 0, false)]
        );
        // Subtracting everything leaves nothing.
        assert!(run(CsgOp::Difference, &a, &[span(0.0, 6.0, 1)]).is_empty());
    }

    #[test]
    fn touching_solids_fuse_without_a_seam() {
        let a = [span(1.0, 2.0, 0)];
        let b = [span(2.0, 3.0, 1)];
        assert_eq!(
            run(CsgOp::Union, &a, &b),
            vec![(1.0, 0, false, 3.0, 1, false)]
        );
        // Their intersection is a single point: nothing.
        assert!(run(CsgOp::Intersection, &a, &b).is_empty());
    }

    #[test]
    fn infinite_spans_combine() {
        let half_space = [span(f32::NEG_INFINITY, 4.0, 0)];
        let ball = [span(2.0, 6.0, 1)];
        assert_eq!(
            run(CsgOp::Intersection, &half_space, &ball),
            vec![(2.0, 1, false, 4.0, 0, false)]
        );
        assert_eq!(
            run(CsgOp::Difference, &ball, &half_space),
            vec![(4.0, 0, true, 6.0, 1, false)]
        );
    }

    #[test]
    fn first_boundary_respects_the_window() {
        let spans = [span(-2.0, 1.0, 0), span(3.0, 4.0, 1)];
        assert_eq!(first_boundary(&spans, 0.0, 10.0).map(|b| b.t), Some(1.0));
        assert_eq!(first_boundary(&spans, 1.5, 10.0).map(|b| b.t), Some(3.0));
        assert_eq!(first_boundary(&spans, 1.5, 2.5), None);
    }
}
