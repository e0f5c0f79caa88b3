//! Reconstruction filters (the `filter` setting, MIT 6.837's assignment 7): a pixel's value
//! as the weighted mean of every sample, of this pixel and its neighbours, within the
//! filter's reach, and the [`Film`] of every sample a filtered render keeps.
//!
//! A sample's position is its pixel's corner plus its offset (`sample_offset`, a pure
//! function of pixel and index), measured from the filtered pixel's centre in pixels. Weights
//! and sums are f32 in one fixed order (neighbour rows top to bottom, each left to right,
//! samples in index order), so a filtered pixel is the same whoever computes it: the render's
//! filtering pass over its film, or a ray tree tracing the neighbourhood again.

use glam::Vec3A;
use whitted_ir::{Filter, Sampling, Settings};

use crate::render::PixelAccumulator;
use crate::sampling::sample_offset;

/// A filter with its radius (the gaussian's σ), in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelFilter {
    pub filter: Filter,
    pub radius: f32,
}

impl PixelFilter {
    pub fn from_settings(settings: &Settings) -> Self {
        PixelFilter {
            filter: settings.filter,
            radius: settings.filter_radius as f32,
        }
    }

    /// The box of radius 0.5: each pixel is the mean of its own samples, and nothing else.
    pub fn is_own_pixel(&self) -> bool {
        self.filter == Filter::Box && self.radius == 0.5
    }

    /// How far from the centre a sample can have weight: the radius, or 2σ for the gaussian.
    pub fn support(&self) -> f32 {
        match self.filter {
            Filter::Box | Filter::Tent => self.radius,
            Filter::Gaussian => 2.0 * self.radius,
        }
    }

    /// The neighbouring pixels on each side whose samples can have weight. A sample lies
    /// in `[0, 1)` of its pixel, so a pixel `k` away has samples from `k - 0.5` on.
    pub fn reach(&self) -> u32 {
        (self.support() - 0.5).ceil().max(0.0) as u32
    }

    /// The weight of a sample at `(dx, dy)` pixels from the pixel's centre.
    #[inline]
    pub fn weight(&self, dx: f32, dy: f32) -> f32 {
        let r = self.radius;
        match self.filter {
            Filter::Box => {
                let inside = |d: f32| -r <= d && d < r;
                if inside(dx) && inside(dy) {
                    1.0
                } else {
                    0.0
                }
            }
            Filter::Tent => {
                let d = (dx * dx + dy * dy).sqrt();
                (1.0 - d / r).max(0.0)
            }
            Filter::Gaussian => {
                let d2 = dx * dx + dy * dy;
                if d2 >= 4.0 * r * r {
                    0.0
                } else {
                    (-d2 / (2.0 * r * r)).exp()
                }
            }
        }
    }

    /// Pixel `(x, y)`'s value from the samples around it, `color(nx, ny, k)` giving sample
    /// `k` of pixel `(nx, ny)`. Neighbours outside the `width` x `height` image are left
    /// out (and their weights with them). When no sample has weight, the pixel is the mean
    /// of its own samples.
    pub fn filter_pixel(
        &self,
        (x, y): (u32, u32),
        (width, height): (u32, u32),
        (samples, sampling): (u32, Sampling),
        mut color: impl FnMut(u32, u32, u32) -> [f32; 3],
    ) -> [f32; 3] {
        let samples = samples.max(1);
        let reach = self.reach();
        let rows = y.saturating_sub(reach)..=y.saturating_add(reach).min(height - 1);
        let columns = x.saturating_sub(reach)..=x.saturating_add(reach).min(width - 1);
        let mut sum = Vec3A::ZERO;
        let mut total = 0.0f32;
        for ny in rows {
            for nx in columns.clone() {
                for k in 0..samples {
                    let (ox, oy) = sample_offset(nx, ny, k, samples, sampling);
                    let dx = (nx as f32 - x as f32) + ox - 0.5;
                    let dy = (ny as f32 - y as f32) + oy - 0.5;
                    let w = self.weight(dx, dy);
                    if w > 0.0 {
                        sum += w * Vec3A::from(color(nx, ny, k));
                        total += w;
                    }
                }
            }
        }
        if total > 0.0 {
            (sum / total).to_array()
        } else {
            let mut own = PixelAccumulator::new();
            for k in 0..samples {
                own.add(color(x, y, k));
            }
            own.mean()
        }
    }
}

/// Every sample of a render, with what places it: sample `k` of pixel `(x, y)` is
/// `colors[(y * width + x) * samples + k]`, at offset [`Film::offset`] inside its pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub samples_per_pixel: u32,
    pub sampling: Sampling,
    /// Linear RGB, pixel by pixel (row-major, top row first), each pixel's samples in order.
    pub colors: Vec<[f32; 3]>,
}

impl Film {
    /// Sample `k` of pixel `(x, y)`.
    pub fn color(&self, x: u32, y: u32, k: u32) -> [f32; 3] {
        let index = (y as usize * self.width as usize + x as usize)
            * self.samples_per_pixel as usize
            + k as usize;
        self.colors[index]
    }

    /// Where sample `k` of pixel `(x, y)` lies inside its pixel, each coordinate in
    /// `[0, 1)` from the pixel's top-left corner: where its camera ray went.
    pub fn offset(&self, x: u32, y: u32, k: u32) -> (f32, f32) {
        sample_offset(x, y, k, self.samples_per_pixel, self.sampling)
    }

    /// Pixel `(x, y)` filtered by `filter` from this film's samples.
    pub fn filter_pixel(&self, filter: &PixelFilter, x: u32, y: u32) -> [f32; 3] {
        filter.filter_pixel(
            (x, y),
            (self.width, self.height),
            (self.samples_per_pixel, self.sampling),
            |nx, ny, k| self.color(nx, ny, k),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn filter(filter: Filter, radius: f32) -> PixelFilter {
        PixelFilter { filter, radius }
    }

    #[test]
    fn weights_follow_the_course_s_definitions() {
        let tent = filter(Filter::Tent, 2.0);
        assert_eq!(tent.weight(0.0, 0.0), 1.0);
        assert_eq!(tent.weight(1.0, 0.0), 0.5);
        assert_eq!(tent.weight(0.6, 0.8), 0.5);
        assert_eq!(tent.weight(2.0, 0.0), 0.0);
        let gaussian = filter(Filter::Gaussian, 0.5);
        assert_eq!(gaussian.weight(0.0, 0.0), 1.0);
        assert!((gaussian.weight(0.5, 0.0) - (-0.5f32).exp()).abs() < 1e-7);
        assert_eq!(gaussian.weight(1.0, 0.0), 0.0, "cut at 2 sigma");
        let square = filter(Filter::Box, 1.5);
        assert_eq!(square.weight(-1.5, 1.49), 1.0);
        assert_eq!(square.weight(1.5, 0.0), 0.0, "half-open on the far side");
        assert_eq!(square.weight(1.4, 1.4), 1.0, "a square, not a disc");
    }

    #[test]
    fn the_reach_counts_the_pixels_a_filter_touches() {
        assert_eq!(filter(Filter::Box, 0.5).reach(), 0);
        assert_eq!(filter(Filter::Box, 0.6).reach(), 1);
        assert_eq!(filter(Filter::Tent, 1.5).reach(), 1);
        assert_eq!(filter(Filter::Tent, 1.6).reach(), 2);
        assert_eq!(filter(Filter::Gaussian, 0.5).reach(), 1);
        assert_eq!(filter(Filter::Gaussian, 2.0).reach(), 4);
        assert!(filter(Filter::Box, 0.5).is_own_pixel());
        assert!(!filter(Filter::Box, 0.6).is_own_pixel());
    }
}
