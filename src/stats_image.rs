//! `render --stats-image`: per-pixel statistics drawn as three heat maps side by side.
//!
//! Left: rays per pixel (camera, reflected, transmitted and shadow rays over all samples),
//! scaled from 0 to the image's maximum. Middle: the deepest level a ray reached, scaled
//! from 0 to the maximum depth. Both use one ramp: black, purple, red, orange, pale yellow
//! (the debugger's heat-map ramp). Right: the cut-offs that happened in the pixel, one
//! channel each: red = a ray wanted to go deeper than the maximum depth, green = total
//! internal reflection, blue = a ray was dropped under the minimum weight (so yellow is
//! red and green together, and so on); black when nothing was cut short. The panels are
//! separated by 4 columns of grey. docs/ray-tree.md describes the same.

use whitted_tracer::display::{heat_color, srgb_to_linear};
use whitted_tracer::{PixelStats, RenderOptions, Termination};

/// Columns of grey between two panels.
const GAP: u32 = 4;
const GAP_COLOR: [f32; 3] = [0.2; 3];

/// The heat maps as a linear-RGB image, ready for `write_image`.
pub struct StatsImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl StatsImage {
    /// `stats` is row-major like the image (`width × height` entries); missing entries
    /// count as empty statistics.
    pub fn new(width: u32, height: u32, stats: &[PixelStats], options: &RenderOptions) -> Self {
        let max_rays = stats.iter().map(|s| s.rays).max().unwrap_or(0);
        let max_depth = options.max_depth;
        let panel_width = width as usize;
        let total_width = width * 3 + GAP * 2;
        let mut pixels = Vec::with_capacity(total_width as usize * height as usize);
        let empty = PixelStats::default();
        for y in 0..height as usize {
            let row = |x: usize| stats.get(y * panel_width + x).unwrap_or(&empty);
            let gap = std::iter::repeat_n(GAP_COLOR, GAP as usize);
            pixels.extend((0..panel_width).map(|x| ramp(fraction(row(x).rays, max_rays))));
            pixels.extend(gap.clone());
            pixels.extend((0..panel_width).map(|x| ramp(fraction(row(x).deepest, max_depth))));
            pixels.extend(gap);
            pixels.extend((0..panel_width).map(|x| cut_offs(row(x))));
        }
        StatsImage {
            width: total_width,
            height,
            pixels,
        }
    }
}

fn fraction(value: u32, max: u32) -> f32 {
    if max == 0 {
        0.0
    } else {
        (value as f32 / max as f32).min(1.0)
    }
}

/// The heat-map colour of `fraction` (0 to 1), the debugger's ramp, made linear for the image
/// writer (which encodes sRGB again).
fn ramp(fraction: f32) -> [f32; 3] {
    heat_color(fraction).map(|c| srgb_to_linear(f32::from(c) / 255.0))
}

fn cut_offs(stats: &PixelStats) -> [f32; 3] {
    let channel = |t: Termination| {
        if stats.terminations.contains(t) {
            1.0
        } else {
            0.0
        }
    };
    [
        channel(Termination::MaxDepth),
        channel(Termination::TotalInternalReflection),
        channel(Termination::WeightCutoff),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image_output::to_srgb8;
    use whitted_tracer::TerminationSet;

    #[test]
    fn ramp_colours_survive_the_srgb_round_trip() {
        assert_eq!(to_srgb8(&[ramp(0.0)]), vec![0, 0, 0]);
        assert_eq!(to_srgb8(&[ramp(0.25)]), vec![90, 20, 140]);
        assert_eq!(to_srgb8(&[ramp(1.0)]), vec![255, 250, 180]);
    }

    #[test]
    fn panels_show_rays_depth_and_cut_offs_side_by_side() {
        let mut deep = TerminationSet::default();
        deep.insert(Termination::MaxDepth);
        deep.insert(Termination::TotalInternalReflection);
        let stats = [
            PixelStats {
                rays: 2,
                deepest: 0,
                terminations: TerminationSet::default(),
            },
            PixelStats {
                rays: 8,
                deepest: 4,
                terminations: deep,
            },
        ];
        let options = RenderOptions {
            width: 2,
            height: 1,
            samples_per_pixel: 1,
            max_depth: 4,
            min_weight: 0.001,
        };
        let image = StatsImage::new(2, 1, &stats, &options);
        assert_eq!((image.width, image.height), (2 * 3 + 2 * GAP, 1));
        let bytes = to_srgb8(&image.pixels);
        let at = |x: usize| &bytes[x * 3..x * 3 + 3];
        // Rays: 2 of 8 is a quarter of the ramp; 8 of 8 is its top.
        assert_eq!(at(0), [90, 20, 140]);
        assert_eq!(at(1), [255, 250, 180]);
        assert_eq!(at(2), [124, 124, 124], "the grey gap");
        // Depth: 0 and the maximum.
        assert_eq!(at(2 + GAP as usize), [0, 0, 0]);
        assert_eq!(at(3 + GAP as usize), [255, 250, 180]);
        // Cut-offs: nothing, then max depth (red) and total internal reflection (green).
        assert_eq!(at(4 + 2 * GAP as usize), [0, 0, 0]);
        assert_eq!(at(5 + 2 * GAP as usize), [255, 255, 0]);
    }
}
