//! Asking the tracer what another setting would do for this pixel: the pixel is traced
//! again through the one code path (`trace_pixel_with`) with a small recorder of its own,
//! never by a tracer of this crate's.

use whitted_tracer::optics::max_channel;
use whitted_tracer::{
    trace_pixel_with, PixelAccumulator, PreparedScene, RayStart, Recorder, RenderOptions,
    SkippedRay, Termination, Vec3A,
};

/// The most rays one question to the tracer may trace, over all its traces, before it gives
/// up (a hall of mirrors with no weight cut-off doubles its rays at every level).
pub const PROBE_RAY_BUDGET: u64 = 2_000_000;

/// Watches one pixel's trace for rays the depth limit cut, and counts rays.
struct DepthWatch {
    /// The largest channel of the heaviest path weight cut by the depth limit.
    cut: f32,
    rays: u64,
    /// The most rays this trace may start.
    budget: u64,
}

impl DepthWatch {
    fn new(budget: u64) -> DepthWatch {
        DepthWatch {
            cut: 0.0,
            rays: 0,
            budget,
        }
    }
}

impl Recorder for DepthWatch {
    fn should_stop(&self) -> bool {
        self.rays > self.budget
    }

    fn ray_started(&mut self, _ray: &RayStart) {
        self.rays += 1;
    }

    fn secondary_skipped(&mut self, skipped: &SkippedRay) {
        if skipped.reason == Termination::MaxDepth {
            self.cut = self.cut.max(max_channel(skipped.weight));
        }
    }
}

/// What raising `max_depth` does for the pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DepthSearch {
    /// At this `max_depth` no path heavier than the threshold is cut; the pixel is then
    /// `color`.
    Found { max_depth: u32, color: [f32; 3] },
    /// Up to `tried` (the limit, or [`MAX_EXTRA_DEPTH`] more than now) some path is still cut.
    NotFound { tried: u32 },
    /// A probe traced more than [`PROBE_RAY_BUDGET`] rays at `max_depth`.
    TooManyRays { max_depth: u32 },
}

/// How far beyond the current `max_depth` the search looks.
pub const MAX_EXTRA_DEPTH: u32 = 64;

/// The smallest `max_depth` above the current one at which no path weight of at least
/// `threshold` (largest channel) is cut by the depth limit at pixel `(x, y)`. The whole
/// search traces at most [`PROBE_RAY_BUDGET`] rays.
pub fn depth_needed(
    prepared: &PreparedScene,
    options: &RenderOptions,
    x: u32,
    y: u32,
    threshold: f32,
) -> DepthSearch {
    let current = options.max_depth.min(whitted_ir::limits::MAX_DEPTH);
    let last = current
        .saturating_add(MAX_EXTRA_DEPTH)
        .min(whitted_ir::limits::MAX_DEPTH);
    let mut spent = 0u64;
    for max_depth in current + 1..=last {
        let probe_options = RenderOptions {
            max_depth,
            ..options.clone()
        };
        let mut accumulator = PixelAccumulator::new();
        let mut cut = 0.0f32;
        for sample in 0..options.samples_per_pixel.max(1) {
            let mut watch = DepthWatch::new(PROBE_RAY_BUDGET.saturating_sub(spent));
            let color = trace_pixel_with(prepared, &probe_options, x, y, sample, &mut watch);
            if watch.should_stop() {
                return DepthSearch::TooManyRays { max_depth };
            }
            spent += watch.rays;
            cut = cut.max(watch.cut);
            accumulator.add(color);
        }
        if cut < threshold {
            return DepthSearch::Found {
                max_depth,
                color: accumulator.mean(),
            };
        }
    }
    DepthSearch::NotFound { tried: last }
}

/// The pixel's colour with other options (a lower `min_weight`), or `None` when it takes
/// more than [`PROBE_RAY_BUDGET`] rays.
pub fn color_with(
    prepared: &PreparedScene,
    options: &RenderOptions,
    x: u32,
    y: u32,
) -> Option<[f32; 3]> {
    let mut accumulator = PixelAccumulator::new();
    let mut spent = 0u64;
    for sample in 0..options.samples_per_pixel.max(1) {
        let mut watch = DepthWatch::new(PROBE_RAY_BUDGET.saturating_sub(spent));
        let color = trace_pixel_with(prepared, options, x, y, sample, &mut watch);
        if watch.should_stop() {
            return None;
        }
        spent += watch.rays;
        accumulator.add(color);
    }
    Some(accumulator.mean())
}

/// `max_channel` for the findings, on recorded `[f32; 3]` colours.
pub(crate) fn largest(c: [f32; 3]) -> f32 {
    max_channel(Vec3A::from(c))
}
