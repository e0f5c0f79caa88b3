//! Heat-map overlays drawn from the render's per-pixel statistics: rays per pixel and the
//! deepest recursion level, each scaled to the image's own maximum.

use whitted_tracer::display::heat_color;
use whitted_tracer::PixelStats;

use crate::image::PixelSource;

/// Which statistic an overlay shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeatMapKind {
    RaysPerPixel,
    DeepestLevel,
}

impl HeatMapKind {
    pub fn title(self) -> &'static str {
        match self {
            HeatMapKind::RaysPerPixel => "rays per pixel",
            HeatMapKind::DeepestLevel => "deepest level",
        }
    }

    fn value(self, stats: &PixelStats) -> u32 {
        match self {
            HeatMapKind::RaysPerPixel => stats.rays,
            HeatMapKind::DeepestLevel => stats.deepest,
        }
    }
}

/// One statistic for every pixel, ready to draw.
#[derive(Clone, Debug, PartialEq)]
pub struct HeatMap {
    pub kind: HeatMapKind,
    width: u32,
    height: u32,
    values: Vec<u32>,
    pub min: u32,
    pub max: u32,
}

impl HeatMap {
    /// `stats` is row-major like the image; `None` when its length does not match the size.
    pub fn new(kind: HeatMapKind, width: u32, height: u32, stats: &[PixelStats]) -> Option<Self> {
        if stats.len() != width as usize * height as usize {
            return None;
        }
        let values: Vec<u32> = stats.iter().map(|s| kind.value(s)).collect();
        let min = values.iter().copied().min().unwrap_or(0);
        let max = values.iter().copied().max().unwrap_or(0);
        Some(HeatMap {
            kind,
            width,
            height,
            values,
            min,
            max,
        })
    }

    pub fn value(&self, x: u32, y: u32) -> Option<u32> {
        if x >= self.width || y >= self.height {
            return None;
        }
        self.values
            .get(y as usize * self.width as usize + x as usize)
            .copied()
    }
}

impl PixelSource for HeatMap {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn srgb(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        let value = self.value(x, y)?;
        let span = self.max.saturating_sub(self.min);
        let fraction = if span == 0 {
            0.0
        } else {
            (value - self.min) as f32 / span as f32
        };
        Some(heat_color(fraction))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(rays: u32, deepest: u32) -> PixelStats {
        PixelStats {
            rays,
            deepest,
            ..PixelStats::default()
        }
    }

    #[test]
    fn values_scale_between_the_image_minimum_and_maximum() {
        let all = [stats(2, 0), stats(5, 1), stats(8, 4), stats(2, 0)];
        let rays = HeatMap::new(HeatMapKind::RaysPerPixel, 2, 2, &all).unwrap();
        assert_eq!((rays.min, rays.max), (2, 8));
        assert_eq!(rays.value(0, 1), Some(8));
        assert_eq!(rays.srgb(0, 0), Some(heat_color(0.0)));
        assert_eq!(rays.srgb(0, 1), Some(heat_color(1.0)));
        assert_eq!(rays.srgb(1, 0), Some(heat_color(0.5)));
        let depth = HeatMap::new(HeatMapKind::DeepestLevel, 2, 2, &all).unwrap();
        assert_eq!(depth.value(1, 0), Some(1));
        assert_eq!(depth.value(2, 0), None);
    }

    #[test]
    fn mismatched_statistics_are_refused() {
        assert!(HeatMap::new(HeatMapKind::RaysPerPixel, 3, 3, &[stats(1, 0)]).is_none());
    }
}
