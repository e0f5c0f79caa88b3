//! Rendering: tiles in parallel on the current rayon pool, each pixel the mean of its
//! samples, and the single-sample entry point that ray trees use.
//!
//! Every pixel is a pure function of the scene, the options and its coordinates: samples
//! come from a hashed pattern, samples are summed in index order, and tiles only decide who
//! computes a pixel, never its value. So the image is bit-identical on any thread count.

use std::time::Instant;

use glam::Vec3A;
use rayon::prelude::*;
use whitted_ir::Settings;

use crate::recorder::{NoRecord, PixelStats, Recorder};
use crate::sampling::sample_offset;
use crate::scene::PreparedScene;
use crate::trace::{PathState, RayCounters, Tracer};

/// Side of the square tiles that workers take one at a time.
pub const TILE_SIZE: u32 = 16;

/// The deepest recursion the tracer allows, whatever the options say: each level is a
/// stack frame, and worker threads have finite stacks. Deeper requests are clamped.
pub const MAX_DEPTH_LIMIT: u32 = 256;

#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// At least 1 (0 is treated as 1).
    pub samples_per_pixel: u32,
    /// Rays deeper than this are not traced; the camera ray has depth 0. Clamped to
    /// [`MAX_DEPTH_LIMIT`].
    pub max_depth: u32,
    /// A secondary ray whose path weight is below this on every channel is not traced.
    pub min_weight: f32,
}

impl RenderOptions {
    pub fn from_settings(s: &Settings) -> Self {
        RenderOptions {
            width: s.width,
            height: s.height,
            samples_per_pixel: s.samples_per_pixel,
            max_depth: s.max_depth,
            min_weight: s.min_weight as f32,
        }
    }

    pub(crate) fn samples(&self) -> u32 {
        self.samples_per_pixel.max(1)
    }

    pub(crate) fn depth_limit(&self) -> u32 {
        self.max_depth.min(MAX_DEPTH_LIMIT)
    }
}

/// Linear RGB, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl Image {
    pub fn pixel(&self, x: u32, y: u32) -> Option<[f32; 3]> {
        if x >= self.width || y >= self.height {
            return None;
        }
        self.pixels
            .get(y as usize * self.width as usize + x as usize)
            .copied()
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderStats {
    pub camera_rays: u64,
    pub shadow_rays: u64,
    pub reflected_rays: u64,
    pub transmitted_rays: u64,
    /// Wall-clock seconds of [`render`] (not including scene preparation).
    pub render_seconds: f64,
    /// The deepest ray traced (0 when only camera rays were traced).
    pub deepest_ray: u32,
    /// The rayon threads the render ran on.
    pub threads: usize,
}

impl RenderStats {
    pub fn total_rays(&self) -> u64 {
        self.camera_rays + self.shadow_rays + self.reflected_rays + self.transmitted_rays
    }

    /// Rays per second of wall-clock time (0 when nothing was timed).
    pub fn rays_per_second(&self) -> f64 {
        if self.render_seconds > 0.0 {
            self.total_rays() as f64 / self.render_seconds
        } else {
            0.0
        }
    }
}

/// A finished tile: `pixels` holds `width × height` linear RGB values, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct TileResult {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

/// Receives finished tiles as they complete (from worker threads), e.g. for a progress bar
/// or a progressive display; `should_stop` lets a caller cancel a render.
pub trait RenderObserver: Sync {
    fn tile_done(&self, _tile: &TileResult) {}
    fn should_stop(&self) -> bool {
        false
    }
}

/// An observer that watches nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoObserver;

impl RenderObserver for NoObserver {}

/// Averages a pixel's samples exactly as [`render`] does: summed in sample order in f32,
/// then divided by the count. Use it to reproduce a rendered pixel bit for bit from
/// [`trace_pixel_with`] results.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelAccumulator {
    sum: Vec3A,
    count: u32,
}

impl PixelAccumulator {
    pub fn new() -> Self {
        Self::default()
    }

    #[inline]
    pub fn add(&mut self, color: [f32; 3]) {
        self.sum += Vec3A::from(color);
        self.count += 1;
    }

    #[inline]
    pub fn mean(&self) -> [f32; 3] {
        match self.count {
            0 => [0.0; 3],
            // Dividing by one is exact; skipping it only saves time.
            1 => self.sum.to_array(),
            n => (self.sum / n as f32).to_array(),
        }
    }
}

/// Renders with rayon over tiles on the *current* rayon pool. Output is bit-identical
/// whatever the thread count and from run to run. Returns `None` if the observer cancels.
pub fn render(
    scene: &PreparedScene,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
) -> Option<(Image, RenderStats)> {
    render_recorded::<NoRecord>(scene, options, observer).map(|(image, stats, _)| (image, stats))
}

/// [`render`], also gathering [`PixelStats`] for every pixel (row-major, like the image),
/// through the same tracing code.
pub fn render_with_pixel_stats(
    scene: &PreparedScene,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
) -> Option<(Image, RenderStats, Vec<PixelStats>)> {
    render_recorded::<PixelStats>(scene, options, observer)
}

/// Traces sample `sample` of pixel `(x, y)` with `rec` attached, running exactly the code
/// [`render`] runs for it, and returns that sample's colour. With one sample per pixel this
/// is the rendered pixel, bit for bit; with more, the pixel is the [`PixelAccumulator`]
/// mean of samples `0..samples_per_pixel`. Coordinates outside the image still trace a
/// ray (through the extended image plane); callers check ranges.
pub fn trace_pixel_with<R: Recorder>(
    scene: &PreparedScene,
    options: &RenderOptions,
    x: u32,
    y: u32,
    sample: u32,
    rec: &mut R,
) -> [f32; 3] {
    let mut tracer = Tracer::new(scene, options.depth_limit(), options.min_weight);
    trace_sample(&mut tracer, scene, options, x, y, sample, rec).to_array()
}

#[inline]
pub(crate) fn trace_sample<R: Recorder>(
    tracer: &mut Tracer<'_>,
    scene: &PreparedScene,
    options: &RenderOptions,
    x: u32,
    y: u32,
    sample: u32,
    rec: &mut R,
) -> Vec3A {
    let (dx, dy) = sample_offset(x, y, sample, options.samples());
    let ray = scene
        .camera
        .ray(x as f32 + dx, y as f32 + dy, options.width, options.height);
    tracer.trace(&ray, &PathState::camera(), rec)
}

struct TileOutput<R> {
    tile: TileResult,
    recorders: Vec<R>,
    counters: RayCounters,
}

fn render_recorded<R: Recorder + Default + Send>(
    scene: &PreparedScene,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
) -> Option<(Image, RenderStats, Vec<R>)> {
    let started = Instant::now();
    let (width, height) = (options.width, options.height);
    let tiles_x = width.div_ceil(TILE_SIZE);
    let tiles_y = height.div_ceil(TILE_SIZE);
    let tile_count = tiles_x as usize * tiles_y as usize;
    let outputs: Vec<Option<TileOutput<R>>> = (0..tile_count)
        .into_par_iter()
        .map(|index| {
            let x0 = (index as u32 % tiles_x) * TILE_SIZE;
            let y0 = (index as u32 / tiles_x) * TILE_SIZE;
            render_tile::<R>(scene, options, observer, x0, y0)
        })
        .collect();

    let pixel_count = width as usize * height as usize;
    let mut pixels = vec![[0.0f32; 3]; pixel_count];
    let mut recorders: Vec<R> = Vec::with_capacity(pixel_count);
    recorders.resize_with(pixel_count, R::default);
    let mut counters = RayCounters::default();
    for output in outputs {
        let output = output?;
        counters.add(&output.counters);
        let tile = &output.tile;
        let tile_width = tile.width as usize;
        let mut recorder_iter = output.recorders.into_iter();
        for (row, tile_row) in tile.pixels.chunks(tile_width.max(1)).enumerate() {
            let start = (tile.y as usize + row) * width as usize + tile.x as usize;
            let end = start + tile_row.len();
            pixels[start..end].copy_from_slice(tile_row);
            for slot in &mut recorders[start..end] {
                if let Some(recorder) = recorder_iter.next() {
                    *slot = recorder;
                }
            }
        }
    }
    let stats = RenderStats {
        camera_rays: counters.camera,
        shadow_rays: counters.shadow,
        reflected_rays: counters.reflected,
        transmitted_rays: counters.transmitted,
        render_seconds: started.elapsed().as_secs_f64(),
        deepest_ray: counters.deepest,
        threads: rayon::current_num_threads(),
    };
    let image = Image {
        width,
        height,
        pixels,
    };
    Some((image, stats, recorders))
}

fn render_tile<R: Recorder + Default>(
    scene: &PreparedScene,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
    x0: u32,
    y0: u32,
) -> Option<TileOutput<R>> {
    let width = TILE_SIZE.min(options.width - x0);
    let height = TILE_SIZE.min(options.height - y0);
    let samples = options.samples();
    let mut tracer = Tracer::new(scene, options.depth_limit(), options.min_weight);
    let mut pixels = Vec::with_capacity(width as usize * height as usize);
    let mut recorders = Vec::with_capacity(width as usize * height as usize);
    for y in y0..y0 + height {
        if observer.should_stop() {
            return None;
        }
        for x in x0..x0 + width {
            let mut rec = R::default();
            let mut accumulator = PixelAccumulator::new();
            for sample in 0..samples {
                let color = trace_sample(&mut tracer, scene, options, x, y, sample, &mut rec);
                accumulator.add(color.to_array());
            }
            pixels.push(accumulator.mean());
            recorders.push(rec);
        }
    }
    let tile = TileResult {
        x: x0,
        y: y0,
        width,
        height,
        pixels,
    };
    observer.tile_done(&tile);
    Some(TileOutput {
        tile,
        recorders,
        counters: tracer.counters,
    })
}
