//! Where each anti-aliasing sample falls inside its pixel: a pure function of
//! (pixel, sample index, sample count), so renders are identical on any thread count.
//!
//! One sample sits at the pixel centre. More samples use Kensler's correlated multi-jittered
//! pattern (Pixar technical memo 13-01): stratified on a jittered grid and in each axis on
//! its own, for any count (not only squares), with hashing instead of random state; or, with
//! `sampling grid`, the centres of a regular grid's cells, the same in every pixel.

use whitted_ir::Sampling;

/// The sample's offset inside the pixel, each coordinate in `[0, 1)`.
#[inline]
pub fn sample_offset(x: u32, y: u32, sample: u32, samples: u32, sampling: Sampling) -> (f32, f32) {
    if samples <= 1 {
        return (0.5, 0.5);
    }
    match sampling {
        Sampling::Jittered => {
            let pattern = pixel_seed(x, y);
            correlated_multi_jitter(sample % samples, samples, pattern)
        }
        Sampling::Grid => grid(sample % samples, samples),
        Sampling::Random => {
            let pattern = pixel_seed(x, y);
            let s = sample % samples;
            (
                random_unit(s, pattern.wrapping_mul(0x2545_f491)),
                random_unit(s, pattern.wrapping_mul(0x9e37_79b9)),
            )
        }
    }
}

/// The centre of cell `sample` of a grid of `columns` x `rows` cells, row by row: as square
/// as the count allows (4 is 2 x 2, 8 is 2 x 4); a count that is not a product of its
/// columns leaves the last row short (5 is 2 x 3 with one cell empty).
fn grid(sample: u32, samples: u32) -> (f32, f32) {
    let columns = ((samples as f32).sqrt() as u32).max(1);
    let rows = samples.div_ceil(columns);
    let (column, row) = (sample % columns, sample / columns);
    (
        (column as f32 + 0.5) / columns as f32,
        (row as f32 + 0.5) / rows as f32,
    )
}

/// A well-mixed 32-bit seed per pixel.
fn pixel_seed(x: u32, y: u32) -> u32 {
    let mut h = x.wrapping_mul(0x9E37_79B1) ^ y.wrapping_mul(0x85EB_CA77).rotate_left(16);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297A_2D39);
    h ^= h >> 15;
    h
}

/// Kensler's `permute`: a hashed permutation of `0..len` evaluated at `i`, by cycle walking.
fn permute(mut i: u32, len: u32, pattern: u32) -> u32 {
    let mut w = len - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        i ^= pattern;
        i = i.wrapping_mul(0xe170_893d);
        i ^= pattern >> 16;
        i ^= (i & w) >> 4;
        i ^= pattern >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= pattern >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | pattern >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < len {
            break;
        }
    }
    (i.wrapping_add(pattern)) % len
}

/// Kensler's `randfloat`: a hashed value in `[0, 1)`.
fn random_unit(mut i: u32, pattern: u32) -> f32 {
    i ^= pattern;
    i ^= i >> 17;
    i ^= i >> 10;
    i = i.wrapping_mul(0xb365_34e5);
    i ^= i >> 12;
    i ^= i >> 21;
    i = i.wrapping_mul(0x93fc_4795);
    i ^= 0xdf6e_307f;
    i ^= i >> 17;
    i = i.wrapping_mul(1 | pattern >> 18);
    // The top 24 bits, so the result is exactly representable and below 1.
    (i >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

fn correlated_multi_jitter(sample: u32, samples: u32, pattern: u32) -> (f32, f32) {
    let columns = ((samples as f32).sqrt() as u32).max(1);
    let rows = samples.div_ceil(columns);
    let s = permute(sample, samples, pattern.wrapping_mul(0x5163_3e2d));
    let sx = permute(s % columns, columns, pattern.wrapping_mul(0x68bc_21eb));
    let sy = permute(s / columns, rows, pattern.wrapping_mul(0x02e5_be93));
    let jx = random_unit(s, pattern.wrapping_mul(0x967a_889b));
    let jy = random_unit(s, pattern.wrapping_mul(0x368c_c8b7));
    let x = (sx as f32 + (sy as f32 + jx) / rows as f32) / columns as f32;
    let y = (s as f32 + jy) / samples as f32;
    // Guard the half-open interval against rounding up to 1.
    (
        x.min(1.0 - f32::EPSILON / 2.0),
        y.min(1.0 - f32::EPSILON / 2.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sample_is_the_pixel_centre() {
        assert_eq!(sample_offset(3, 7, 0, 1, Sampling::Jittered), (0.5, 0.5));
        assert_eq!(sample_offset(3, 7, 0, 1, Sampling::Grid), (0.5, 0.5));
    }

    #[test]
    fn samples_are_stratified_in_each_axis() {
        for samples in [2u32, 4, 5, 9, 16, 17] {
            let (x, y) = (12, 34);
            let mut x_strata = vec![0; samples as usize];
            let mut y_strata = vec![0; samples as usize];
            for k in 0..samples {
                let (sx, sy) = sample_offset(x, y, k, samples, Sampling::Jittered);
                assert!((0.0..1.0).contains(&sx) && (0.0..1.0).contains(&sy));
                y_strata[(sy * samples as f32) as usize] += 1;
                x_strata[((sx * samples as f32) as usize).min(samples as usize - 1)] += 1;
            }
            // Every horizontal stratum of height 1/n holds exactly one sample.
            assert!(y_strata.iter().all(|&c| c == 1), "{samples}: {y_strata:?}");
            // Columns: the n samples are spread, never more than the rows per column.
            let rows = samples.div_ceil(((samples as f32).sqrt() as u32).max(1));
            assert!(
                x_strata.iter().all(|&c| c <= rows),
                "{samples}: {x_strata:?}"
            );
        }
    }

    #[test]
    fn pattern_is_a_pure_function_and_differs_between_pixels() {
        let jittered = |x, y| sample_offset(x, y, 3, 8, Sampling::Jittered);
        assert_eq!(jittered(5, 6), jittered(5, 6));
        assert_ne!(jittered(5, 6), jittered(6, 5));
    }

    /// Random samples: in the pixel, different from sample to sample and pixel to pixel,
    /// and not stratified (two may share a row of a 2 x 2 grid, which jittered never does).
    #[test]
    fn random_samples_fall_anywhere_in_the_pixel() {
        let random = |x, y, k| sample_offset(x, y, k, 16, Sampling::Random);
        let mut shared_quadrant = false;
        for pixel in 0..50 {
            let offsets: Vec<_> = (0..16).map(|k| random(pixel, 3, k)).collect();
            assert!(offsets
                .iter()
                .all(|(x, y)| (0.0..1.0).contains(x) && (0.0..1.0).contains(y)));
            let quadrants: Vec<_> = offsets[..4]
                .iter()
                .map(|(x, y)| ((x * 2.0) as u32, (y * 2.0) as u32))
                .collect();
            shared_quadrant |= (0..4).any(|i| quadrants[..i].contains(&quadrants[i]));
            assert_ne!(random(pixel, 3, 0), random(pixel + 1, 3, 0));
        }
        assert!(shared_quadrant, "random, not stratified");
        assert_eq!(random(7, 7, 5), random(7, 7, 5));
    }

    /// The grid, worked by hand: 4 samples are the centres of a 2 x 2 grid, 8 of 2 x 4, the
    /// same in every pixel.
    #[test]
    fn a_grid_puts_samples_at_the_centres_of_equal_cells() {
        let grid = |x, y, k, n| sample_offset(x, y, k, n, Sampling::Grid);
        let four: Vec<_> = (0..4).map(|k| grid(0, 0, k, 4)).collect();
        assert_eq!(
            four,
            [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]
        );
        assert_eq!(grid(0, 0, 5, 8), (0.75, 0.625));
        assert_eq!(grid(9, 4, 5, 8), grid(0, 0, 5, 8));
        assert_eq!(
            grid(0, 0, 2, 3),
            (0.5, 2.5 / 3.0),
            "3 samples: one column of three"
        );
        assert_eq!(
            grid(0, 0, 4, 5),
            (0.25, 2.5 / 3.0),
            "5: 2 x 3, one cell empty"
        );
    }
}
