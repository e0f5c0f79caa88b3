//! Builds the binary BVH that obvhs converts into its wide `CwBvh`: a binned SAH build with
//! a median fallback, in O(n log n) for any finite input.
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

use glam::Vec3A;
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::bvh2::Bvh2;

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
    fn for_boxes(aabbs: &[Aabb]) -> BuildScale {
        let largest = aabbs
            .iter()
            .map(|b| b.min.abs().max(b.max.abs()).max_element())
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
        let s = self.factor();
        let lo = aabb.min.to_array().map(|v| round_down(f64::from(v) * s));
        let hi = aabb.max.to_array().map(|v| round_up(f64::from(v) * s));
        Aabb::new(Vec3A::from(lo), Vec3A::from(hi))
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

/// What a build did: its result and how much work it took, for tests that bound both.
pub struct Built {
    pub bvh2: Bvh2,
    pub scale: BuildScale,
    /// Primitives looked at over all splits: O(n log n) when the depth is O(log n). Only
    /// tests read the counts; counting costs one addition per node.
    #[cfg_attr(not(test), allow(dead_code))]
    pub steps: u64,
    #[cfg_attr(not(test), allow(dead_code))]
    pub depth: u32,
}

/// Builds the binary BVH over `aabbs` (one primitive per leaf, as obvhs's converter wants).
/// The boxes are scaled in place, so that handing over a `Vec` costs no second copy.
pub fn build_bvh2(aabbs: impl Into<Vec<Aabb>>) -> Built {
    let mut boxes: Vec<Aabb> = aabbs.into();
    let scale = BuildScale::for_boxes(&boxes);
    for b in &mut boxes {
        *b = scale.scale_box(b);
    }
    let centroids: Vec<Vec3A> = boxes.iter().map(|b| (b.min + b.max) * 0.5).collect();
    let mut prims: Vec<u32> = (0..boxes.len() as u32).collect();
    let mut nodes = vec![Bvh2Node::default(); (2 * boxes.len()).saturating_sub(1)];
    let mut steps = 0;
    let mut depth = 0;
    if let Some((root, region)) = nodes.split_first_mut() {
        let input = Input {
            boxes: &boxes,
            centroids: &centroids,
        };
        let (node, work) = input.build(&mut prims, 0, region, 1, 0);
        *root = node;
        steps = work.steps;
        depth = work.depth;
    }
    let bvh2 = Bvh2 {
        nodes,
        primitive_indices: prims,
        ..Bvh2::default()
    };
    Built {
        bvh2,
        scale,
        steps,
        depth,
    }
}

/// Steps taken and depth reached below one node.
#[derive(Clone, Copy, Default)]
struct Work {
    steps: u64,
    depth: u32,
}

struct Input<'a> {
    boxes: &'a [Aabb],
    centroids: &'a [Vec3A],
}

impl Input<'_> {
    /// Builds the subtree over `prims` (which start at `prim_offset` in the final order) and
    /// returns its root. Its descendants go into `region`, which starts at node index
    /// `region_offset` and holds exactly `2·len − 2` nodes: the two children first, then the
    /// left child's descendants, then the right child's. The layout depends only on the
    /// input, so the result is the same on any number of threads.
    fn build(
        &self,
        prims: &mut [u32],
        prim_offset: u32,
        region: &mut [Bvh2Node],
        region_offset: u32,
        depth: u32,
    ) -> (Bvh2Node, Work) {
        // One pass for the node's box and the bounds of its centroids.
        let mut bounds = Aabb::empty();
        let mut centroid_bounds = Aabb::empty();
        for &p in prims.iter() {
            bounds = bounds.union(&self.boxes[p as usize]);
            let c = self.centroids[p as usize];
            centroid_bounds = centroid_bounds.union(&Aabb::new(c, c));
        }
        if prims.len() <= 1 {
            let work = Work { steps: 1, depth };
            return (Bvh2Node::new(bounds, 1, prim_offset), work);
        }
        let len = prims.len();
        let left_len = self.split(prims, &centroid_bounds, depth);
        let (left_prims, right_prims) = prims.split_at_mut(left_len);
        let (children, below) = region.split_at_mut(2);
        let (left_region, right_region) = below.split_at_mut(2 * left_len - 2);
        let left_offset = region_offset + 2;
        let right_offset = left_offset + left_region.len() as u32;
        let right_prim_offset = prim_offset + left_len as u32;
        let mut build_left =
            move || self.build(left_prims, prim_offset, left_region, left_offset, depth + 1);
        let mut build_right = move || {
            self.build(
                right_prims,
                right_prim_offset,
                right_region,
                right_offset,
                depth + 1,
            )
        };
        let ((left, left_work), (right, right_work)) = if len >= PARALLEL_RANGE {
            rayon::join(build_left, build_right)
        } else {
            (build_left(), build_right())
        };
        children[0] = left;
        children[1] = right;
        let work = Work {
            steps: len as u64 + left_work.steps + right_work.steps,
            depth: left_work.depth.max(right_work.depth),
        };
        (Bvh2Node::new(bounds, 0, region_offset), work)
    }

    /// Reorders `prims` into two non-empty parts and returns the length of the first.
    fn split(&self, prims: &mut [u32], centroid_bounds: &Aabb, depth: u32) -> usize {
        let lo = centroid_bounds.min;
        let extent = centroid_bounds.max - lo;
        let axis = extent.max_position();
        if extent[axis] > 0.0 && depth < SAH_DEPTH_LIMIT {
            if let Some(left_len) = self.sah_split(prims, lo, extent) {
                return left_len;
            }
        }
        self.median_split(prims, axis)
    }

    /// The cheapest bin boundary over the three axes, applied; `None` when no boundary
    /// leaves both sides non-empty.
    fn sah_split(&self, prims: &mut [u32], lo: Vec3A, extent: Vec3A) -> Option<usize> {
        let bin_of = |c: Vec3A, axis: usize| -> usize {
            let x = (c[axis] - lo[axis]) / extent[axis] * BINS as f32;
            // `as` saturates, and NaN becomes 0.
            (x as usize).min(BINS - 1)
        };
        // One pass bins every primitive on all three axes.
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
                let cost = left_box.half_area() * left_count as f32
                    + right_area[b + 1] * right_count as f32;
                if best.is_none_or(|(c, ..)| cost < c) {
                    best = Some((cost, axis, b));
                }
            }
        }
        let (_, axis, last_left_bin) = best?;
        let left_len = partition(prims, |p| {
            bin_of(self.centroids[p as usize], axis) <= last_left_bin
        });
        (left_len > 0 && left_len < prims.len()).then_some(left_len)
    }

    /// Halves `prims` at the median centroid along `axis` (ties by index, so the result is
    /// a function of the input alone).
    fn median_split(&self, prims: &mut [u32], axis: usize) -> usize {
        let mid = prims.len() / 2;
        prims.select_nth_unstable_by(mid, |&a, &b| {
            let (ca, cb) = (self.centroids[a as usize], self.centroids[b as usize]);
            ca[axis].total_cmp(&cb[axis]).then(a.cmp(&b))
        });
        mid
    }
}

/// Moves the elements for which `left` holds to the front (in place); returns their count.
fn partition(prims: &mut [u32], left: impl Fn(u32) -> bool) -> usize {
    let mut first_right = 0;
    for i in 0..prims.len() {
        if left(prims[i]) {
            prims.swap(i, first_right);
            first_right += 1;
        }
    }
    first_right
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(built.bvh2.primitive_indices.len(), n);
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
    /// primitive's scaled box), and every primitive is in exactly one leaf.
    #[test]
    fn large_builds_are_valid_trees() {
        let n = 50_000;
        let aabbs = scattered(n);
        let built = build_bvh2(&aabbs[..]);
        assert_n_log_n(&built, n);
        let bvh2 = &built.bvh2;
        let contains = |outer: &Aabb, inner: &Aabb| {
            outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
        };
        let mut seen = vec![false; n];
        for node in &bvh2.nodes {
            if node.prim_count == 0 {
                for child in [node.first_index, node.first_index + 1] {
                    let child = &bvh2.nodes[child as usize];
                    assert!(contains(node.aabb(), child.aabb()));
                }
            } else {
                let prim = bvh2.primitive_indices[node.first_index as usize] as usize;
                assert!(!std::mem::replace(&mut seen[prim], true), "{prim} twice");
                assert!(contains(node.aabb(), &built.scale.scale_box(&aabbs[prim])));
            }
        }
        assert!(seen.iter().all(|&s| s));
    }

    /// A large build must not depend on the thread count either (the image depends on the
    /// tree through ties).
    #[test]
    fn large_builds_are_the_same_on_any_thread_count() {
        let aabbs = scattered(50_000);
        let build_on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap_or_else(|e| panic!("no pool: {e}"));
            pool.install(|| build_bvh2(&aabbs[..])).bvh2
        };
        let one = build_on(1);
        let three = build_on(3);
        assert_eq!(one.primitive_indices, three.primitive_indices);
        let key = |b: &Bvh2| -> Vec<_> {
            b.nodes
                .iter()
                .map(|n| {
                    (
                        n.aabb().min.to_array(),
                        n.aabb().max.to_array(),
                        n.prim_count,
                        n.first_index,
                    )
                })
                .collect()
        };
        assert!(
            key(&one) == key(&three),
            "1 and 3 threads build different trees"
        );
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
            let scale = BuildScale::for_boxes(&boxes);
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
}
