//! Where two images differ (`whitted diff SCENE --against-image STUDENT.tga`): pixels whose
//! 8-bit values differ by more than a tolerance in some channel, grouped into connected
//! regions (8-neighbours), each with its bounding box and a sample pixel, the one that
//! differs most, for whitted to read from the student's side (`student`).

use serde::Serialize;

/// The version of `diff --against-image --json` (docs/diff.md): 2 named the sides
/// `student` and `reference` (1 had `whitted` and `reference`, the student's image) and
/// added the space and each region's `reading`.
pub const IMAGE_DIFF_JSON_VERSION: u32 = 2;

/// A connected set of differing pixels.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Region {
    /// Top-left and bottom-right pixels of the bounding box (inclusive).
    pub min: [u32; 2],
    pub max: [u32; 2],
    /// How many pixels differ in it.
    pub pixels: u32,
    /// The pixel that differs most (the first in row order among equals).
    pub sample: [u32; 2],
    /// Its largest channel difference, in 8-bit steps.
    pub largest_difference: u8,
}

/// The regions where `a` and `b` (both `width`×`height`, three bytes a pixel, row-major)
/// differ by more than `tolerance` steps in some channel, largest region first. `None`
/// when the buffers do not have that size.
pub fn differing_regions(
    a: &[u8],
    b: &[u8],
    width: u32,
    height: u32,
    tolerance: u8,
) -> Option<Vec<Region>> {
    let (w, h) = (width as usize, height as usize);
    let n = w.checked_mul(h)?;
    if a.len() != n * 3 || b.len() != n * 3 {
        return None;
    }
    let difference: Vec<u8> = (0..n)
        .map(|i| {
            (0..3)
                .map(|c| a[i * 3 + c].abs_diff(b[i * 3 + c]))
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut seen = vec![false; n];
    let mut regions = Vec::new();
    let mut stack = Vec::new();
    for start in 0..n {
        if seen[start] || difference[start] <= tolerance {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let mut region = Region {
            min: [u32::MAX; 2],
            max: [0; 2],
            pixels: 0,
            sample: [(start % w) as u32, (start / w) as u32],
            largest_difference: difference[start],
        };
        let mut best = start;
        while let Some(i) = stack.pop() {
            let (x, y) = (i % w, i / w);
            region.pixels += 1;
            region.min = [region.min[0].min(x as u32), region.min[1].min(y as u32)];
            region.max = [region.max[0].max(x as u32), region.max[1].max(y as u32)];
            if difference[i] > difference[best] || (difference[i] == difference[best] && i < best) {
                best = i;
            }
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        continue;
                    }
                    let j = ny as usize * w + nx as usize;
                    if !seen[j] && difference[j] > tolerance {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        region.sample = [(best % w) as u32, (best / w) as u32];
        region.largest_difference = difference[best];
        regions.push(region);
    }
    regions.sort_by(|r, s| {
        s.pixels
            .cmp(&r.pixels)
            .then(r.min[1].cmp(&s.min[1]))
            .then(r.min[0].cmp(&s.min[0]))
    });
    Some(regions)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_each_planted_patch_with_its_box() {
        let (w, h) = (20u32, 10u32);
        let a = vec![100u8; (w * h * 3) as usize];
        let mut b = a.clone();
        let mut paint = |x0: u32, y0: u32, x1: u32, y1: u32, v: u8| {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    b[((y * w + x) * 3 + 1) as usize] = v;
                }
            }
        };
        paint(2, 1, 5, 3, 200);
        paint(12, 6, 13, 9, 90); // 10 steps: beyond a tolerance of 4
        paint(18, 0, 18, 0, 102); // 2 steps: within it
        let mut regions = differing_regions(&a, &b, w, h, 4).unwrap();
        assert_eq!(regions.len(), 2);
        assert_eq!(
            (regions[0].min, regions[0].max, regions[0].pixels),
            ([2, 1], [5, 3], 12)
        );
        assert_eq!(regions[0].largest_difference, 100);
        assert_eq!(
            (regions[1].min, regions[1].max, regions[1].pixels),
            ([12, 6], [13, 9], 8)
        );
        // Diagonal neighbours join.
        b[((4 * w + 6) * 3) as usize] = 0;
        regions = differing_regions(&a, &b, w, h, 4).unwrap();
        assert_eq!(regions[0].max, [6, 4]);
        assert_eq!(regions[0].sample, [2, 1]);
        assert!(differing_regions(&a, &b[3..], w, h, 4).is_none());
    }
}
