//! Comparing a rendered image with its reference: per-pixel error, share over tolerance,
//! mean FLIP, and the images a reviewer looks at when they differ.

use image::{Rgb, RgbImage};

use super::manifest::Thresholds;

/// The figures of one comparison.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// Largest channel difference over all pixels (0..1).
    pub max_error: f64,
    /// Mean over pixels of the largest channel difference (0..1).
    pub mean_error: f64,
    /// Share of pixels whose largest channel difference exceeds the tolerance.
    pub failing_share: f64,
    /// Mean FLIP error (0 = identical to the eye, 1 = as different as can be).
    pub mean_flip: f64,
    /// Why the images could not be compared at all (different sizes), if so.
    pub mismatch: Option<String>,
    pub passed: bool,
}

/// Compares `actual` against `expected`.
pub fn compare(expected: &RgbImage, actual: &RgbImage, thresholds: &Thresholds) -> Comparison {
    if expected.dimensions() != actual.dimensions() {
        let (ew, eh) = expected.dimensions();
        let (aw, ah) = actual.dimensions();
        return Comparison {
            max_error: 1.0,
            mean_error: 1.0,
            failing_share: 1.0,
            mean_flip: 1.0,
            mismatch: Some(format!(
                "the reference is {ew}x{eh} but the render is {aw}x{ah}"
            )),
            passed: false,
        };
    }
    let mut max_error = 0.0f64;
    let mut sum_error = 0.0f64;
    let mut failing = 0usize;
    for (e, a) in expected.pixels().zip(actual.pixels()) {
        let error = pixel_error(e, a);
        max_error = max_error.max(error);
        sum_error += error;
        if error > thresholds.pixel_tolerance {
            failing += 1;
        }
    }
    let count = (expected.width() as usize * expected.height() as usize).max(1);
    let mean_flip = flip_error_map(expected, actual).1;
    let failing_share = failing as f64 / count as f64;
    let passed =
        failing_share <= thresholds.max_failing_share && mean_flip <= thresholds.max_mean_flip;
    Comparison {
        max_error,
        mean_error: sum_error / count as f64,
        failing_share,
        mean_flip,
        mismatch: None,
        passed,
    }
}

/// The largest channel difference of two pixels, 0..1.
fn pixel_error(a: &Rgb<u8>, b: &Rgb<u8>) -> f64 {
    (0..3)
        .map(|c| (a.0[c] as i32 - b.0[c] as i32).unsigned_abs())
        .max()
        .unwrap_or(0) as f64
        / 255.0
}

/// FLIP's error map, coloured with the magma LUT, and its mean.
pub fn flip_error_map(expected: &RgbImage, actual: &RgbImage) -> (RgbImage, f64) {
    let (w, h) = expected.dimensions();
    let reference = nv_flip::FlipImageRgb8::with_data(w, h, expected.as_raw());
    let test = nv_flip::FlipImageRgb8::with_data(w, h, actual.as_raw());
    let error = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let pool = nv_flip::FlipPool::from_image(&error);
    let visual = error.apply_color_lut(&nv_flip::magma_lut());
    let map = RgbImage::from_raw(w, h, visual.to_vec()).unwrap_or_else(|| RgbImage::new(w, h));
    (map, f64::from(pool.mean()))
}

/// An amplified difference: the reference dimmed to grey, every differing pixel in red whose
/// brightness grows with the error (x8), pixels over the tolerance in full red.
pub fn difference_image(expected: &RgbImage, actual: &RgbImage, tolerance: f64) -> RgbImage {
    let (w, h) = expected.dimensions();
    let mut out = RgbImage::new(w, h);
    if actual.dimensions() != (w, h) {
        return out;
    }
    for (x, y, e) in expected.enumerate_pixels() {
        let a = actual.get_pixel(x, y);
        let error = pixel_error(e, a);
        let grey = ((e.0[0] as u32 + e.0[1] as u32 + e.0[2] as u32) / 12) as u8;
        let pixel = if error == 0.0 {
            Rgb([grey, grey, grey])
        } else if error > tolerance {
            Rgb([255, 0, 0])
        } else {
            let red = (64.0 + error * 255.0 * 8.0).min(255.0) as u8;
            Rgb([red, grey / 2, grey / 2])
        };
        out.put_pixel(x, y, pixel);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(w: u32, h: u32) -> RgbImage {
        RgbImage::from_fn(w, h, |x, y| {
            Rgb([(x * 255 / w) as u8, (y * 255 / h) as u8, 128])
        })
    }

    #[test]
    fn identical_images_pass_with_zero_error() {
        let image = gradient(64, 48);
        let c = compare(&image, &image.clone(), &Thresholds::default());
        assert!(c.passed);
        assert_eq!(
            (c.max_error, c.mean_error, c.failing_share),
            (0.0, 0.0, 0.0)
        );
        assert!(c.mean_flip < 1e-6);
    }

    #[test]
    fn a_perturbed_block_fails() {
        let expected = gradient(64, 48);
        let mut actual = expected.clone();
        for y in 10..30 {
            for x in 10..30 {
                actual.put_pixel(x, y, Rgb([255, 0, 255]));
            }
        }
        let c = compare(&expected, &actual, &Thresholds::default());
        assert!(!c.passed);
        assert!((c.failing_share - 400.0 / (64.0 * 48.0)).abs() < 1e-9);
        assert!(
            c.mean_flip > 0.01,
            "FLIP should see a magenta block: {}",
            c.mean_flip
        );
        let diff = difference_image(&expected, &actual, 0.02);
        assert_eq!(diff.get_pixel(15, 15), &Rgb([255, 0, 0]));
        assert_ne!(diff.get_pixel(40, 40), &Rgb([255, 0, 0]));
    }

    #[test]
    fn noise_below_the_tolerance_passes() {
        let expected = gradient(64, 48);
        let mut actual = expected.clone();
        for (i, p) in actual.pixels_mut().enumerate() {
            if i % 7 == 0 {
                p.0[2] = p.0[2].saturating_add(2); // under 1% of the range
            }
        }
        let c = compare(&expected, &actual, &Thresholds::default());
        assert!(c.passed, "{c:?}");
    }

    #[test]
    fn different_sizes_fail_with_a_reason() {
        let c = compare(&gradient(4, 4), &gradient(4, 5), &Thresholds::default());
        assert!(!c.passed);
        assert!(c.mismatch.unwrap().contains("4x4"));
    }
}
