//! `trace_pixel`: one pixel's ray tree, recorded from the same code path `render` runs, with
//! the pixel's colour averaged exactly as `render` averages it (with a filter that reaches
//! past the pixel, filtered from its own samples and its neighbours', which are traced again
//! unrecorded: the tree holds the pixel's own samples).

use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};

use whitted_ir::Scene;

use super::model::{RayTree, SampleChoice, SampleTree, ShadingModel};
use super::tree_recorder::TreeRecorder;
use crate::filter::PixelFilter;
use crate::recorder::NoRecord;
use crate::render::{trace_pixel_with, PixelAccumulator, RenderOptions};
use crate::scene::PreparedScene;

/// Why a pixel's tree could not be recorded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TraceError {
    PixelOutOfRange {
        x: u32,
        y: u32,
        width: u32,
        height: u32,
    },
    SampleOutOfRange {
        sample: u32,
        samples_per_pixel: u32,
    },
    /// The caller cancelled the trace before it finished.
    Cancelled,
}

impl fmt::Display for TraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TraceError::Cancelled => write!(f, "the trace was cancelled"),
            TraceError::PixelOutOfRange {
                x,
                y,
                width,
                height,
            } => write!(
                f,
                "pixel ({x}, {y}) is outside the {width}x{height} image \
                 (x must be 0 to {}, y 0 to {})",
                width.saturating_sub(1),
                height.saturating_sub(1)
            ),
            TraceError::SampleOutOfRange {
                sample,
                samples_per_pixel: 1,
            } => write!(
                f,
                "there is no sample {sample}: the image has 1 sample per pixel (sample 0)"
            ),
            TraceError::SampleOutOfRange {
                sample,
                samples_per_pixel,
            } => write!(
                f,
                "there is no sample {sample}: the image has {samples_per_pixel} samples per \
                 pixel (0 to {})",
                samples_per_pixel - 1
            ),
        }
    }
}

impl std::error::Error for TraceError {}

/// Checks that pixel `(x, y)` and the chosen sample exist at these options, as
/// [`trace_pixel`] does: callers can fail fast before preparing a big scene.
pub fn check_request(
    options: &RenderOptions,
    x: u32,
    y: u32,
    which: SampleChoice,
) -> Result<(), TraceError> {
    if x >= options.width || y >= options.height {
        return Err(TraceError::PixelOutOfRange {
            x,
            y,
            width: options.width,
            height: options.height,
        });
    }
    let samples_per_pixel = options.samples();
    match which {
        SampleChoice::One(sample) if sample >= samples_per_pixel => {
            Err(TraceError::SampleOutOfRange {
                sample,
                samples_per_pixel,
            })
        }
        _ => Ok(()),
    }
}

/// Records the ray tree of pixel `(x, y)`: every sample, or only `which`. Samples that are
/// not recorded are still traced (without a recorder) so that `RayTree::color` is the pixel
/// exactly as `render` computes it, bit for bit.
///
/// `scene` must be the scene `prepared` was made from: it supplies names and locations.
/// The tree holds at most [`whitted_ir::limits::MAX_RAY_TREE_NODES`] nodes.
pub fn trace_pixel(
    prepared: &PreparedScene,
    scene: &Scene,
    options: &RenderOptions,
    x: u32,
    y: u32,
    which: SampleChoice,
) -> Result<RayTree, TraceError> {
    let request = TraceRequest {
        x,
        y,
        which,
        node_budget: whitted_ir::limits::MAX_RAY_TREE_NODES,
        cancel: None,
    };
    trace_pixel_request(prepared, scene, options, &request)
}

/// One pixel to trace, with the tree's node budget and an optional cancel flag.
#[derive(Clone, Copy, Debug)]
pub struct TraceRequest<'c> {
    pub x: u32,
    pub y: u32,
    pub which: SampleChoice,
    /// The most nodes to record; past it the tree is cut (see `RayNode::unrecorded`).
    pub node_budget: usize,
    /// When set (from another thread) the trace stops soon and returns `Cancelled`.
    pub cancel: Option<&'c AtomicBool>,
}

/// [`trace_pixel`] with a chosen node budget and a way to cancel.
pub fn trace_pixel_request(
    prepared: &PreparedScene,
    scene: &Scene,
    options: &RenderOptions,
    request: &TraceRequest<'_>,
) -> Result<RayTree, TraceError> {
    let TraceRequest {
        x,
        y,
        which,
        node_budget,
        cancel,
    } = *request;
    check_request(options, x, y, which)?;
    let cancelled = || cancel.is_some_and(|c| c.load(Ordering::Relaxed));
    let samples_per_pixel = options.samples();
    let mut recorder = TreeRecorder::with_budget(scene, node_budget, cancel);
    let mut accumulator = PixelAccumulator::new();
    let mut samples = Vec::new();
    let mut own_colors = Vec::with_capacity(samples_per_pixel as usize);
    for index in 0..samples_per_pixel {
        let recorded = match which {
            SampleChoice::All => true,
            SampleChoice::One(k) => k == index,
        };
        let color = if recorded {
            let color = trace_pixel_with(prepared, options, x, y, index, &mut recorder);
            // The tracer always finishes the camera ray it started, so a root exists.
            if let Some(root) = recorder.take_root() {
                samples.push(SampleTree { index, color, root });
            }
            color
        } else {
            trace_pixel_with(prepared, options, x, y, index, &mut NoRecord)
        };
        accumulator.add(color);
        own_colors.push(color);
        if cancelled() {
            return Err(TraceError::Cancelled);
        }
    }
    // A filter that reaches past the pixel weighs the neighbours' samples too: they are
    // traced again (not recorded), and the pixel's colour is what the render filtered.
    let filter = PixelFilter::from_settings(prepared.settings());
    let color = if filter.is_own_pixel() {
        accumulator.mean()
    } else {
        let mut neighbours_cancelled = false;
        let color = filter.filter_pixel(
            (x, y),
            (options.width, options.height),
            (samples_per_pixel, prepared.settings().sampling),
            |nx, ny, k| {
                if (nx, ny) == (x, y) {
                    own_colors[k as usize]
                } else {
                    neighbours_cancelled |= cancelled();
                    trace_pixel_with(prepared, options, nx, ny, k, &mut NoRecord)
                }
            },
        );
        if neighbours_cancelled {
            return Err(TraceError::Cancelled);
        }
        color
    };
    Ok(RayTree {
        pixel: [x, y],
        image_size: [options.width, options.height],
        color,
        samples_per_pixel,
        max_depth: options.depth_limit(),
        min_weight: options.min_weight,
        model: ShadingModel::of(prepared.settings()),
        node_budget,
        unrecorded: recorder.unrecorded(),
        samples,
    })
}
