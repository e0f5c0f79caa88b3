//! Moves arrays into a given order in place: how the build puts a million boxes in Morton
//! order and the caller's items in the BVH's order, without a second copy of either.

/// Positions a bucket of [`permute_in_place`] covers, as a power of two: 4,096 items with
/// their destinations (under 150 KB for the build's pairs) stay in a core's cache while
/// they are put in place, and a million items make 245 buckets, whose write positions
/// stay in cache too.
const BUCKET_BITS: u32 = 12;

/// What [`permute_in_place`] moves: a slice, or two slices of the same length moved
/// together (the items and their destinations, inside it).
pub trait Swap {
    fn swap_at(&mut self, a: usize, b: usize);
}

impl<T> Swap for [T] {
    #[inline(always)]
    fn swap_at(&mut self, a: usize, b: usize) {
        self.swap(a, b);
    }
}

impl<A: Swap + ?Sized, B: Swap + ?Sized> Swap for (&mut A, &mut B) {
    #[inline(always)]
    fn swap_at(&mut self, a: usize, b: usize) {
        self.0.swap_at(a, b);
        self.1.swap_at(a, b);
    }
}

/// [`permute_in_place`] when `order` is a permutation of `items`' indices; otherwise
/// `false`, with the items untouched.
pub fn permute_checked<T>(items: &mut [T], order: &mut [u32]) -> bool {
    let applies = is_permutation(order, items.len());
    if applies {
        permute_in_place(items, order);
    }
    applies
}

/// Whether `order` is a permutation of `0..len`.
fn is_permutation(order: &[u32], len: usize) -> bool {
    let mut seen = vec![false; len];
    order.len() == len
        && order.iter().all(|&i| {
            seen.get_mut(i as usize)
                .is_some_and(|s| !std::mem::replace(s, true))
        })
}

/// Puts `items[order[i]]` at `i` for every `i` in place, `order` being a permutation of
/// `items`' indices (each slice of a pair as long as `order`); `order` is left as the
/// identity.
///
/// Following the permutation's cycles one item at a time is a chain of dependent loads
/// that jump anywhere in the arrays: for a million items a cache miss each, 40-50 ms on one
/// thread, however the look-ups are batched (the tracer's items; moving the build's boxes
/// and the items together, tried, took 70). Instead each item's destination is found first (one pass of
/// independent writes), then two passes of swaps, each swap putting one item where it
/// belongs: the first moves every item into its bucket (the [`BUCKET_BITS`]-sized range
/// of positions its destination lies in), writing at each bucket's next free position as
/// an American flag sort does, so that the writes go to a few hundred places that stay in
/// cache; the second puts each bucket's items in place, within the bucket, in cache.
pub fn permute_in_place(items: &mut (impl Swap + ?Sized), order: &mut [u32]) {
    let n = order.len();
    let mut destination = vec![0u32; n];
    for (position, &source) in order.iter().enumerate() {
        destination[source as usize] = position as u32;
    }
    let mut both = (items, &mut destination[..]);
    let bucket_of = |destination: u32| (destination >> BUCKET_BITS) as usize;
    let bucket_end = |bucket: usize| ((bucket + 1) << BUCKET_BITS).min(n);
    let mut next_free: Vec<usize> = (0..n.div_ceil(1 << BUCKET_BITS))
        .map(|bucket| bucket << BUCKET_BITS)
        .collect();
    for bucket in 0..next_free.len() {
        let end = bucket_end(bucket);
        while next_free[bucket] < end {
            let at = next_free[bucket];
            let belongs = bucket_of(both.1[at]);
            if belongs != bucket {
                // The item that was there comes to `at` and is looked at next.
                both.swap_at(at, next_free[belongs]);
            }
            next_free[belongs] += 1;
        }
    }
    for position in 0..n {
        loop {
            let to = both.1[position] as usize;
            if to == position {
                break;
            }
            both.swap_at(position, to);
        }
    }
    for (position, entry) in order.iter_mut().enumerate() {
        *entry = position as u32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The in-place moves give what a plain gather gives, and leave the order as the
    /// identity, on awkward permutations: none, one item, already in order, reversed, long
    /// cycles across buckets, lengths just under, at and just over a bucket's (and
    /// several), buckets swapped whole, and shuffles.
    #[test]
    fn permuting_in_place_is_a_gather() {
        let bucket = 1u32 << BUCKET_BITS;
        let mut orders: Vec<Vec<u32>> = vec![
            vec![],
            vec![0],
            (0..10).collect(),
            (0..9).rev().collect(),
            (0..10).rev().collect(),
            (0..5000).map(|i| (i + 1) % 5000).collect(),
            (0..5000).map(|i| (i + 4999) % 5000).collect(),
            (0..3 * bucket).map(|i| (i * 7) % (3 * bucket)).collect(),
            // The last bucket's items first, the first's last: every item changes bucket.
            (0..3 * bucket + 5).rev().collect(),
            (0..2 * bucket)
                .map(|i| (i + bucket) % (2 * bucket))
                .collect(),
        ];
        // One cycle of each length around a bucket's, with a fixed point between them.
        for len in [bucket - 1, bucket, bucket + 1, 2 * bucket, 2 * bucket + 1] {
            let mut order: Vec<u32> = (0..len).map(|i| (i + 1) % len).collect();
            order.push(len);
            let shifted = order.iter().map(|&i| i + len + 1);
            order.extend(shifted.collect::<Vec<_>>());
            orders.push(order);
        }
        // Shuffles (Fisher-Yates with a fixed LCG), mixing every cycle length.
        let mut state = 0x2545_f491_u64;
        for len in [2u32, 3, 100, bucket + 1, 5 * bucket + 17] {
            let mut order: Vec<u32> = (0..len).collect();
            for i in (1..order.len()).rev() {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                order.swap(i, (state >> 33) as usize % (i + 1));
            }
            orders.push(order);
        }
        for order in orders {
            let n = order.len() as u32;
            // Items that own heap memory, so that a lost or doubled item would show.
            let items: Vec<String> = (0..n).map(|i| format!("item {i}")).collect();
            let gathered: Vec<String> = order.iter().map(|&i| items[i as usize].clone()).collect();
            let mut moved = items;
            let mut marks = order.clone();
            permute_in_place(&mut moved[..], &mut marks);
            assert!(moved == gathered, "{n} items moved wrongly");
            assert!(
                marks.iter().copied().eq(0..n),
                "{n} items' order left marked"
            );
        }
    }

    /// Two slices moved together end where each would alone.
    #[test]
    fn pairs_move_together() {
        let order: Vec<u32> = (0..1000).map(|i| (i * 7 + 3) % 1000).collect();
        let numbers: Vec<u32> = (0..1000).collect();
        let names: Vec<String> = (0..1000).map(|i| format!("item {i}")).collect();
        let (mut a, mut b) = (numbers.clone(), names.clone());
        permute_in_place(&mut (&mut a[..], &mut b[..]), &mut order.clone());
        let (mut a_alone, mut b_alone) = (numbers, names);
        permute_in_place(&mut a_alone[..], &mut order.clone());
        permute_in_place(&mut b_alone[..], &mut order.clone());
        assert_eq!(a, a_alone);
        assert_eq!(b, b_alone);
        assert!(a.iter().copied().eq(order.iter().copied()));
    }

    /// A repeated index, an index out of range, a short order: each is refused and leaves
    /// the items as they were; a permutation is applied.
    #[test]
    fn only_permutations_are_applied() {
        let items: Vec<String> = (0..4).map(|i| format!("item {i}")).collect();
        for order in [vec![0, 0, 1, 2], vec![0, 1, 2, 4], vec![0, 1]] {
            let mut kept = items.clone();
            assert!(!permute_checked(&mut kept, &mut order.clone()), "{order:?}");
            assert_eq!(kept, items);
        }
        let mut moved = items.clone();
        assert!(permute_checked(&mut moved, &mut [3, 0, 2, 1]));
        assert_eq!(moved, ["item 3", "item 0", "item 2", "item 1"]);
    }
}
