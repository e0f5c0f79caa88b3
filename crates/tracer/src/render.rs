//! Rendering: tiles in parallel on the current rayon pool, each pixel the mean of its
//! samples, and the single-sample entry point that ray trees use.
//!
//! Every pixel is a pure function of the scene, the options and its coordinates: samples
//! come from a hashed pattern, samples are summed in index order, and tiles only decide who
//! computes a pixel, never its value. So the image is bit-identical on any thread count.
//!
//! Memory is part of the speed: each worker keeps its tracer and tile buffers for the whole
//! render, and a finished tile is copied straight into its band of the image (one lock per
//! band of tile rows), so a render allocates the image once and nothing per tile. Keeping
//! every tile alive until the end, as a first version did, touched twice the image's memory
//! and cost a tenth of a render in page faults.

use std::sync::{Mutex, PoisonError};
use std::time::Instant;

use glam::Vec3A;
use rayon::prelude::*;
use whitted_ir::{Camera, Sampling, Settings};

use crate::camera::PreparedCamera;
use crate::filter::{Film, PixelFilter};
use crate::query::Hit;
use crate::recorder::{NoRecord, PixelStats, Recorder};
use crate::sampling::sample_offset;
use crate::scene::PreparedScene;
use crate::trace::{PathState, RayCounters, Tracer};
use whitted_bvh::Ray;
use whitted_bvh::PACKET;

/// Side of the square tiles that workers take one at a time.
pub const TILE_SIZE: u32 = 16;

/// A rectangle of pixels: columns `x..x + width`, rows `y..y + height`, counted from the
/// image's top-left corner.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PixelRect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl PixelRect {
    /// The whole `width` x `height` image.
    pub fn whole(width: u32, height: u32) -> Self {
        PixelRect {
            x: 0,
            y: 0,
            width,
            height,
        }
    }

    /// Rows `rows` of a `width`-wide image.
    pub fn rows(width: u32, rows: std::ops::Range<u32>) -> Self {
        PixelRect {
            x: 0,
            y: rows.start,
            width,
            height: rows.end.saturating_sub(rows.start),
        }
    }

    pub fn pixel_count(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    pub fn is_empty(&self) -> bool {
        self.width == 0 || self.height == 0
    }

    /// The part of this rectangle inside a `width` x `height` image (empty if none).
    pub fn clipped(&self, width: u32, height: u32) -> Self {
        let x = self.x.min(width);
        let y = self.y.min(height);
        PixelRect {
            x,
            y,
            width: self.x.saturating_add(self.width).min(width) - x,
            height: self.y.saturating_add(self.height).min(height) - y,
        }
    }

    /// This rectangle grown by `margin` pixels on every side, then clipped to the image.
    pub fn grown(&self, margin: u32, width: u32, height: u32) -> Self {
        let x = self.x.saturating_sub(margin);
        let y = self.y.saturating_sub(margin);
        PixelRect {
            x,
            y,
            width: self.x.saturating_add(self.width).saturating_add(margin) - x,
            height: self.y.saturating_add(self.height).saturating_add(margin) - y,
        }
        .clipped(width, height)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// At least 1 (0 is treated as 1).
    pub samples_per_pixel: u32,
    /// Rays deeper than this are not traced; the camera ray has depth 0. Clamped to
    /// [`whitted_ir::limits::MAX_DEPTH`]: each level is a stack frame and worker threads have
    /// finite stacks (validation and the command line refuse deeper requests; options built
    /// in code are clamped).
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
        self.max_depth.min(whitted_ir::limits::MAX_DEPTH)
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
    /// Camera rays whose first hit was found in a packet of neighbouring rays.
    pub camera_rays_in_packets: u64,
    /// Wall-clock seconds of [`render`] (not including scene preparation).
    pub render_seconds: f64,
    /// The deepest ray traced (0 when only camera rays were traced).
    pub deepest_ray: u32,
    /// The rayon threads the render ran on.
    pub threads: usize,
    /// Pixels with a sample that reached the ray budget
    /// ([`whitted_ir::limits::MAX_RAYS_PER_SAMPLE`]): their recursion was cut short.
    pub pixels_cut_at_ray_budget: u64,
    /// The first such pixel in row-major order, `[x, y]`.
    pub first_pixel_cut_at_ray_budget: Option<[u32; 2]>,
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
    /// A finished tile. With a filter that reaches past the pixel (the `filter` setting),
    /// a tile shows each pixel's own samples averaged, a preview: the image is filtered
    /// once every sample is in, and [`RenderObserver::image_filtered`] brings it.
    fn tile_done(&self, _tile: &TileResult) {}
    /// The whole filtered image as one tile, after every [`RenderObserver::tile_done`] of
    /// a render whose filter reaches past the pixel (never for the default box filter).
    fn image_filtered(&self, _image: &TileResult) {}
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
/// Each pixel is made from its samples by the scene's `filter` (by default the mean of the
/// pixel's own samples; see [`PixelFilter`]).
pub fn render(
    scene: &PreparedScene,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
) -> Option<(Image, RenderStats)> {
    render_filtered::<NoRecord>(scene, &scene.camera, options, observer)
        .map(|(image, stats, _)| (image, stats))
}

/// [`render`] from another camera than the scene's: the same tracing code, for views of the
/// scene from elsewhere (the debugger's 3D ray view). Preparing the camera is cheap; the
/// scene (and its BVH) is used as it is.
pub fn render_from(
    scene: &PreparedScene,
    camera: &Camera,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
) -> Option<(Image, RenderStats)> {
    let camera = PreparedCamera::new(camera);
    render_filtered::<NoRecord>(scene, &camera, options, observer)
        .map(|(image, stats, _)| (image, stats))
}

/// [`render`], also gathering [`PixelStats`] for every pixel (row-major, like the image),
/// through the same tracing code. A pixel's statistics are those of its own samples.
pub fn render_with_pixel_stats(
    scene: &PreparedScene,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
) -> Option<(Image, RenderStats, Vec<PixelStats>)> {
    render_filtered::<PixelStats>(scene, &scene.camera, options, observer)
}

/// [`render`], keeping every sample: the [`Film`] (for pictures of the samples) beside the
/// image, which is the film filtered as [`render`] filters it, bit for bit. The film holds
/// 12 bytes per sample; the caller bounds its size (`limits::MAX_FILTERED_SAMPLES`).
pub fn render_film(
    scene: &PreparedScene,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
) -> Option<(Film, Image, RenderStats)> {
    let filter = PixelFilter::from_settings(scene.settings());
    let whole = PixelRect::whole(options.width, options.height);
    let (image, stats, _, film) =
        render_recorded::<NoRecord>(scene, &scene.camera, options, observer, true, whole)?;
    let film = film?;
    if filter.is_own_pixel() {
        return Some((film, image, stats));
    }
    // The filtered image replaces the sample pass's: one image in memory at a time.
    drop(image);
    let (image, stats) = filter_image(&film, whole, &filter, (options, whole), stats, observer)?;
    Some((film, image, stats))
}

/// [`render`] of only the pixels of `region` (clipped to the image): an image of the
/// region's size whose pixels are those of the whole render at the same places, bit for
/// bit, whatever the filter. A filter that reaches past the pixel takes samples from a
/// margin of [`PixelFilter::reach`] pixels around the region (inside the image), as the whole
/// render does. Tiles shown to the observer are placed in the whole image's coordinates.
pub fn render_region(
    scene: &PreparedScene,
    options: &RenderOptions,
    region: PixelRect,
    observer: &dyn RenderObserver,
) -> Option<(Image, RenderStats)> {
    let region = region.clipped(options.width, options.height);
    render_region_filtered::<NoRecord>(scene, &scene.camera, options, observer, region)
        .map(|(image, stats, _)| (image, stats))
}

/// The render, then, for a filter that reaches past the pixel, the filtering pass over the
/// samples it kept.
fn render_filtered<R: Recorder + Default + Send>(
    scene: &PreparedScene,
    camera: &PreparedCamera,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
) -> Option<(Image, RenderStats, Vec<R>)> {
    let whole = PixelRect::whole(options.width, options.height);
    render_region_filtered(scene, camera, options, observer, whole)
}

/// [`render_filtered`] of the pixels of `region` (inside the image): the whole render is
/// the region of the whole image. With a filter that reaches past the pixel, the sample
/// pass covers the region and a margin of the filter's reach (the recorders are then
/// those of the margin's pixels too, so only the whole image asks for them).
fn render_region_filtered<R: Recorder + Default + Send>(
    scene: &PreparedScene,
    camera: &PreparedCamera,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
    region: PixelRect,
) -> Option<(Image, RenderStats, Vec<R>)> {
    let filter = PixelFilter::from_settings(scene.settings());
    if filter.is_own_pixel() {
        let (image, stats, recorders, _) =
            render_recorded::<R>(scene, camera, options, observer, false, region)?;
        return Some((image, stats, recorders));
    }
    let sampled = region.grown(filter.reach(), options.width, options.height);
    let (_, stats, recorders, film) =
        render_recorded::<R>(scene, camera, options, observer, true, sampled)?;
    let film = film?;
    let (image, stats) = filter_image(&film, sampled, &filter, (options, region), stats, observer)?;
    Some((image, stats, recorders))
}

/// The filtering pass: every pixel of `region` made from `film` (the samples of the pixels
/// of `sampled`, which holds the region and the filter's reach around it inside the
/// image) by `filter`, rows in parallel (each pixel a pure function of the film, so the
/// thread count changes nothing), then shown to the observer whole. The render's time
/// includes it.
fn filter_image(
    film: &Film,
    sampled: PixelRect,
    filter: &PixelFilter,
    (options, region): (&RenderOptions, PixelRect),
    mut stats: RenderStats,
    observer: &dyn RenderObserver,
) -> Option<(Image, RenderStats)> {
    let started = Instant::now();
    let mut image = Image {
        width: region.width,
        height: region.height,
        pixels: vec![[0.0f32; 3]; region.pixel_count() as usize],
    };
    let width = image.width as usize;
    image
        .pixels
        .par_chunks_mut(width.max(1))
        .enumerate()
        .try_for_each(|(row_index, row)| {
            if observer.should_stop() {
                return None;
            }
            let y = region.y + row_index as u32;
            for (column, pixel) in row.iter_mut().enumerate() {
                let x = region.x + column as u32;
                // The film's pixel (0, 0) is the image's (sampled.x, sampled.y); the
                // filter sees whole-image coordinates and sizes, so its neighbourhood is
                // clipped at the image's borders, never the region's.
                *pixel = filter.filter_pixel(
                    (x, y),
                    (options.width, options.height),
                    (film.samples_per_pixel, film.sampling),
                    |nx, ny, k| film.color(nx - sampled.x, ny - sampled.y, k),
                );
            }
            Some(())
        })?;
    stats.render_seconds += started.elapsed().as_secs_f64();
    let tile = TileResult {
        x: region.x,
        y: region.y,
        width: image.width,
        height: image.height,
        pixels: std::mem::take(&mut image.pixels),
    };
    observer.image_filtered(&tile);
    image.pixels = tile.pixels;
    Some((image, stats))
}

/// Traces sample `sample` of pixel `(x, y)` with `rec` attached, running exactly the code
/// [`render`] runs for it, and returns that sample's colour. With one sample per pixel this
/// is the rendered pixel, bit for bit; with more, the pixel is the [`PixelAccumulator`]
/// mean of samples `0..samples_per_pixel` (with the default filter; with another, it is
/// [`PixelFilter::filter_pixel`] over the samples of the pixel and its neighbours). Coordinates outside the image still trace a
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

/// The colour of sample `sample` of pixel (x, y) had the camera ray met `object`'s surface
/// where it meets another in the same place (z-fighting: what the pixel shows with the
/// other surface in front), through the one code path. `None` when the camera ray has no
/// such surface of `object` within its first hit's error bound.
pub fn trace_pixel_preferring<R: Recorder>(
    scene: &PreparedScene,
    options: &RenderOptions,
    (x, y, sample): (u32, u32, u32),
    object: whitted_ir::Handle<whitted_ir::Object>,
    rec: &mut R,
) -> Option<[f32; 3]> {
    let mut tracer = Tracer::new(scene, options.depth_limit(), options.min_weight);
    let ray = camera_ray(
        &scene.camera,
        scene.settings().sampling,
        options,
        x,
        y,
        sample,
    );
    tracer
        .trace_preferring(&ray, object, rec)
        .map(|c| c.to_array())
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
    let ray = camera_ray(
        &scene.camera,
        scene.settings().sampling,
        options,
        x,
        y,
        sample,
    );
    tracer.trace(&ray, &PathState::camera(), rec)
}

/// The camera ray of sample `sample` of pixel `(x, y)`, the sample placed by `sampling`.
#[inline]
fn camera_ray(
    camera: &PreparedCamera,
    sampling: Sampling,
    options: &RenderOptions,
    x: u32,
    y: u32,
    sample: u32,
) -> Ray {
    let (dx, dy) = sample_offset(x, y, sample, options.samples(), sampling);
    camera.ray(x as f32 + dx, y as f32 + dy, options.width, options.height)
}

/// A worker's reusable state: a tracer (with its query scratch space) and the buffers of
/// the tile being rendered, so that a render allocates per worker, not per tile.
struct Worker<'a, R> {
    tracer: Tracer<'a>,
    /// The camera rays of one tile row, made before any of them is traced: a camera ray
    /// ends in a square root and a division, and made back to back these overlap instead
    /// of each stalling the start of its trace.
    rays: Vec<Ray>,
    /// The first hit of each of `rays`, found a packet at a time (`Tracer::camera_hits`);
    /// `None` for rays of a packet that could not walk together, which find their own.
    first_hits: Vec<Option<Option<Hit>>>,
    pixels: Vec<[f32; 3]>,
    /// Every sample's colour of the tile, pixel by pixel, when the render keeps them.
    samples: Vec<[f32; 3]>,
    recorders: Vec<R>,
}

/// The rows of the image (and of the per-pixel recorders) that one row of tiles covers.
/// Workers copy finished tiles in under its lock; tiles of one band only ever wait for
/// each other for the length of a copy.
struct Band<'i, R> {
    pixels: &'i mut [[f32; 3]],
    recorders: &'i mut [R],
    /// The band's samples in the film (empty when the render keeps none).
    samples: &'i mut [[f32; 3]],
}

/// The sample pass over the pixels of `region` (inside the image): every pixel the mean of
/// its own samples, and, when `keep_samples`, the film of every sample. The image, the
/// recorders and the film are the region's size (the film's pixel (0, 0) is the region's
/// corner); tiles are laid from the region's corner, which changes no pixel (tiles only
/// decide who computes a pixel).
#[allow(clippy::type_complexity)]
fn render_recorded<R: Recorder + Default + Send>(
    scene: &PreparedScene,
    camera: &PreparedCamera,
    options: &RenderOptions,
    observer: &dyn RenderObserver,
    keep_samples: bool,
    region: PixelRect,
) -> Option<(Image, RenderStats, Vec<R>, Option<Film>)> {
    let started = Instant::now();
    let (width, height) = (region.width, region.height);
    let tiles_x = width.div_ceil(TILE_SIZE);
    let tiles_y = height.div_ceil(TILE_SIZE);
    let tile_count = tiles_x as usize * tiles_y as usize;
    let pixel_count = width as usize * height as usize;
    let mut pixels = vec![[0.0f32; 3]; pixel_count];
    let mut recorders: Vec<R> = Vec::with_capacity(pixel_count);
    recorders.resize_with(pixel_count, R::default);
    let band_len = (width as usize * TILE_SIZE as usize).max(1);
    let samples = options.samples() as usize;
    let mut film = if keep_samples {
        vec![[0.0f32; 3]; pixel_count * samples]
    } else {
        Vec::new()
    };
    let mut film_bands = film.chunks_mut(band_len * samples);
    let bands: Vec<Mutex<Band<'_, R>>> = pixels
        .chunks_mut(band_len)
        .zip(recorders.chunks_mut(band_len))
        .map(|(pixels, recorders)| {
            let samples = film_bands.next().unwrap_or_default();
            Mutex::new(Band {
                pixels,
                recorders,
                samples,
            })
        })
        .collect();
    let counters = (0..tile_count)
        .into_par_iter()
        .map_init(
            || Worker {
                tracer: Tracer::new(scene, options.depth_limit(), options.min_weight),
                rays: Vec::new(),
                first_hits: Vec::new(),
                pixels: Vec::new(),
                samples: Vec::new(),
                recorders: Vec::new(),
            },
            |worker, index| {
                let x0 = (index as u32 % tiles_x) * TILE_SIZE;
                let y0 = (index as u32 / tiles_x) * TILE_SIZE;
                let band = bands.get((y0 / TILE_SIZE) as usize)?;
                let view = (camera, scene.settings().sampling);
                let keep = keep_samples;
                let corner = (region.x + x0, region.y + y0);
                render_tile::<R>(
                    worker,
                    view,
                    (options, region),
                    observer,
                    band,
                    corner,
                    keep,
                )
            },
        )
        .try_reduce(RayCounters::default, |mut a, b| {
            a.add(&b);
            Some(a)
        })?;
    drop(bands);
    let stats = RenderStats {
        camera_rays: counters.camera,
        shadow_rays: counters.shadow,
        reflected_rays: counters.reflected,
        transmitted_rays: counters.transmitted,
        camera_rays_in_packets: counters.camera_in_packets,
        render_seconds: started.elapsed().as_secs_f64(),
        deepest_ray: counters.deepest,
        threads: rayon::current_num_threads(),
        pixels_cut_at_ray_budget: counters.pixels_cut,
        first_pixel_cut_at_ray_budget: counters.first_pixel_cut,
    };
    let image = Image {
        width,
        height,
        pixels,
    };
    let film = keep_samples.then(|| Film {
        width,
        height,
        samples_per_pixel: samples as u32,
        sampling: scene.settings().sampling,
        colors: film,
    });
    Some((image, stats, recorders, film))
}

/// Renders the tile at `(x0, y0)` (image coordinates), shows it to the observer, and copies
/// it into its band of the region's image. Returns the tile's ray counts, or `None` when
/// the observer cancels.
fn render_tile<R: Recorder + Default>(
    worker: &mut Worker<'_, R>,
    (camera, sampling): (&PreparedCamera, Sampling),
    (options, region): (&RenderOptions, PixelRect),
    observer: &dyn RenderObserver,
    band: &Mutex<Band<'_, R>>,
    (x0, y0): (u32, u32),
    keep_samples: bool,
) -> Option<RayCounters> {
    let width = TILE_SIZE.min(region.x + region.width - x0);
    let height = TILE_SIZE.min(region.y + region.height - y0);
    let samples = options.samples();
    let tracer = &mut worker.tracer;
    let mut pixels = std::mem::take(&mut worker.pixels);
    pixels.clear();
    worker.samples.clear();
    worker.recorders.clear();
    let rays = &mut worker.rays;
    for y in y0..y0 + height {
        if observer.should_stop() {
            return None;
        }
        rays.clear();
        for x in x0..x0 + width {
            for sample in 0..samples {
                rays.push(camera_ray(camera, sampling, options, x, y, sample));
            }
        }
        // Neighbouring camera rays find their first hits together: a packet shares the
        // BVH walk and gives each ray exactly the hit it would find alone.
        let first_hits = &mut worker.first_hits;
        first_hits.clear();
        for packet in rays.chunks(PACKET) {
            let mut hits = [None; PACKET];
            if tracer.camera_hits(packet, &mut hits) {
                first_hits.extend(hits.iter().take(packet.len()).map(|hit| Some(*hit)));
            } else {
                first_hits.extend(packet.iter().map(|_| None));
            }
        }
        // The rays in the order they were made: pixel by pixel, sample by sample, exactly
        // as `trace_sample` traces them one at a time.
        let samples = samples as usize;
        for (x, (pixel_rays, pixel_hits)) in
            (x0..).zip(rays.chunks(samples).zip(first_hits.chunks(samples)))
        {
            let mut rec = R::default();
            let cut_before = tracer.counters.samples_cut;
            let mut accumulator = PixelAccumulator::new();
            for (ray, first_hit) in pixel_rays.iter().zip(pixel_hits) {
                let color = match first_hit {
                    Some(hit) => tracer.trace_from_hit(ray, &PathState::camera(), &mut rec, *hit),
                    None => tracer.trace(ray, &PathState::camera(), &mut rec),
                };
                accumulator.add(color.to_array());
                if keep_samples {
                    worker.samples.push(color.to_array());
                }
            }
            pixels.push(accumulator.mean());
            worker.recorders.push(rec);
            if tracer.counters.samples_cut != cut_before {
                tracer.counters.pixel_cut(x, y);
            }
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
    {
        // A worker that panicked while copying cannot have left a row half written in a
        // way that matters: the render is lost either way, so a poisoned lock is used as is.
        let mut band = band.lock().unwrap_or_else(PoisonError::into_inner);
        let band = &mut *band;
        let row_len = region.width as usize;
        let tile_width = width as usize;
        let mut recorders = worker.recorders.drain(..);
        for (row, tile_row) in tile.pixels.chunks(tile_width.max(1)).enumerate() {
            let start = row * row_len + (x0 - region.x) as usize;
            let end = start + tile_row.len();
            if let Some(target) = band.pixels.get_mut(start..end) {
                target.copy_from_slice(tile_row);
            }
            if let Some(targets) = band.recorders.get_mut(start..end) {
                for (target, recorder) in targets.iter_mut().zip(recorders.by_ref()) {
                    *target = recorder;
                }
            }
            if keep_samples {
                let samples = samples as usize;
                let from = row * tile_width * samples;
                let tile_samples = &worker.samples[from..from + tile_row.len() * samples];
                if let Some(target) = band.samples.get_mut(start * samples..end * samples) {
                    target.copy_from_slice(tile_samples);
                }
            }
        }
    }
    worker.pixels = tile.pixels;
    Some(std::mem::take(&mut tracer.counters))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::whitted_classic;

    /// From the scene's own camera `render_from` is `render`, bit for bit; from another
    /// camera it is a different picture of the same scene.
    #[test]
    fn render_from_the_scene_camera_is_render_and_from_elsewhere_differs() {
        let scene = whitted_classic().build().unwrap();
        let prepared = PreparedScene::new(&scene);
        let mut options = RenderOptions::from_settings(&scene.settings);
        options.width = 40;
        options.height = 30;
        let (image, _) = render(&prepared, &options, &NoObserver).unwrap();
        let (same, _) = render_from(&prepared, &scene.camera, &options, &NoObserver).unwrap();
        assert_eq!(image, same);
        let mut above = scene.camera.clone();
        above.eye.y += 5.0;
        let (other, _) = render_from(&prepared, &above, &options, &NoObserver).unwrap();
        assert_ne!(image, other);
    }
}
