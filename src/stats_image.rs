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

use whitted_tracer::display::{heat_color, linear_to_srgb8_rgb};
use whitted_tracer::{PixelStats, RenderOptions, Termination};

/// Columns of grey between two panels.
const GAP: u32 = 4;
const GAP_COLOR: [f32; 3] = [0.2; 3];

/// The heat maps as 8-bit sRGB bytes, three per pixel, ready for `write_image`. Every colour
/// here is an 8-bit one (the ramp is defined in sRGB bytes), so bytes lose nothing and take a
/// quarter of the memory of linear floats: at the largest image size that is 3.6 GB less.
pub struct StatsImage {
    pub width: u32,
    pub height: u32,
    pub srgb: Vec<u8>,
}

impl StatsImage {
    /// `stats` is row-major like the image (`width × height` entries); missing entries
    /// count as empty statistics.
    pub fn new(width: u32, height: u32, stats: &[PixelStats], options: &RenderOptions) -> Self {
        let max_rays = stats.iter().map(|s| s.rays).max().unwrap_or(0);
        let max_depth = options.max_depth;
        let panel_width = width as usize;
        let total_width = width * 3 + GAP * 2;
        let mut srgb = Vec::with_capacity(total_width as usize * height as usize * 3);
        let empty = PixelStats::default();
        let gap_color = linear_to_srgb8_rgb(GAP_COLOR);
        for y in 0..height as usize {
            let row = |x: usize| stats.get(y * panel_width + x).unwrap_or(&empty);
            let gap = std::iter::repeat_n(gap_color, GAP as usize);
            let panels = (0..panel_width)
                .map(|x| heat_color(fraction(row(x).rays, max_rays)))
                .chain(gap.clone())
                .chain((0..panel_width).map(|x| heat_color(fraction(row(x).deepest, max_depth))))
                .chain(gap)
                .chain((0..panel_width).map(|x| cut_offs(row(x))));
            srgb.extend(panels.flatten());
        }
        StatsImage {
            width: total_width,
            height,
            srgb,
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

fn cut_offs(stats: &PixelStats) -> [u8; 3] {
    let channel = |t: Termination| {
        if stats.terminations.contains(t) {
            255
        } else {
            0
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
    use whitted_tracer::TerminationSet;

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
        let bytes = &image.srgb;
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
