//! `whitted render`: compile, build the BVH, render in parallel with a progress bar, write.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use whitted_ir::{limits, SourceMap};
use whitted_tracer::{
    PreparedScene, RenderObserver, RenderOptions, RenderStats, TileResult, TraversalPath,
};

use crate::cli::{ImageFormat, RenderArgs, StatsFormat};
use crate::image_output::{write_image, Pixels};
use crate::scene_input::{load_scene, write_stdout};
use crate::setting_flags::apply_render_flags;
use crate::stats_image::StatsImage;
use crate::Failure;

/// Advances a progress bar by the pixels of each finished tile.
struct ProgressObserver {
    bar: Option<ProgressBar>,
}

impl RenderObserver for ProgressObserver {
    fn tile_done(&self, tile: &TileResult) {
        if let Some(bar) = &self.bar {
            bar.inc(u64::from(tile.width) * u64::from(tile.height));
        }
    }
}

/// Refuses image sizes that cannot be held in memory, before any work starts: at most
/// [`limits::MAX_PIXELS`] (about 11,585 x 11,585, 1.5 GiB of linear RGB). Larger sizes are
/// almost always a typo (`--width 30000 --height 30000`) and would exhaust memory.
pub fn check_image_size(width: u32, height: u32) -> Result<(), Failure> {
    // A side worked out from the other one (`--height` alone of a very wide scene) may
    // pass the side limit that the flags check.
    if width.max(height) > limits::MAX_IMAGE_SIDE {
        return Err(Failure::Message(format!(
            "a {width}x{height} image has a side over the image side limit ({}): give both \
             --width and --height",
            limits::MAX_IMAGE_SIDE
        )));
    }
    let pixels = u64::from(width) * u64::from(height);
    if pixels > limits::MAX_PIXELS {
        return Err(Failure::Message(format!(
            "a {width}x{height} image has {pixels} pixels, more than the pixels limit ({}, about 11585x11585)",
            limits::MAX_PIXELS
        )));
    }
    Ok(())
}

/// What one render will need in memory, estimated before any work so that a render too big
/// for the machine is refused with a message rather than killed half-way.
struct MemoryEstimate {
    pixels: u64,
    output: ImageFormat,
    /// The format of `--stats-image`, when asked for.
    stats_image: Option<ImageFormat>,
    objects: u64,
}

/// Bytes per object of the prepared scene (shapes, inverse transforms, BVH nodes), beyond
/// the compiled scene already in memory; generous for spheres, about right for CSG.
const PREPARED_BYTES_PER_OBJECT: u64 = 256;

impl MemoryEstimate {
    /// Bytes per pixel for encoding in `format`: the 8-bit formats make 3 bytes of sRGB, the
    /// float formats a copy of 12 bytes of floats and the encoder's own buffer of as much.
    fn encoding(format: ImageFormat) -> u64 {
        match format {
            ImageFormat::Png | ImageFormat::Ppm | ImageFormat::Tga => 3,
            ImageFormat::Exr | ImageFormat::Hdr => 24,
        }
    }

    /// The peak: while rendering and writing the image, the image (12 bytes of linear RGB
    /// per pixel) and the per-pixel statistics (12) are held with the encoded image; then,
    /// for `--stats-image`, the statistics and the heat maps (3 panels of 3 sRGB bytes), and
    /// then the heat maps with their encoding.
    fn bytes(&self) -> u64 {
        let stats = if self.stats_image.is_some() { 12 } else { 0 };
        let render = 12 + stats + Self::encoding(self.output);
        let heat_maps = self
            .stats_image
            .map_or(0, |format| (12 + 9).max(9 + 3 * Self::encoding(format)));
        self.pixels
            .saturating_mul(render.max(heat_maps))
            .saturating_add(self.objects.saturating_mul(PREPARED_BYTES_PER_OBJECT))
    }

    /// `asked` says what made the image's size, for the message. Objects alone stay far
    /// below the limit (`limits::MAX_OBJECTS`), so a refusal is always the size and formats
    /// the command line asked for: a usage error.
    fn check(&self, asked: &str) -> Result<(), Failure> {
        let bytes = self.bytes();
        let limit = whitted_ir::limits::MAX_RENDER_MEMORY_BYTES;
        if bytes > limit {
            let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
            return Err(Failure::Usage(format!(
                "{asked} would need about {:.1} GiB of memory to render, more than the render \
                 memory limit of {:.0} GiB: make the image smaller, or write 8-bit images \
                 (.png, .ppm) rather than .exr or .hdr",
                gib(bytes),
                gib(limit)
            )));
        }
        Ok(())
    }
}

/// `scenes/whitted.scene` renders to `whitted.png` in the current directory by default.
fn default_output(scene: &Path) -> PathBuf {
    let stem = scene.file_stem().map(|s| s.to_string_lossy().into_owned());
    PathBuf::from(format!(
        "{}.png",
        stem.unwrap_or_else(|| "render".to_string())
    ))
}

/// Refuses an output that is the scene or one of the files it imports: rendering
/// `s.ppm -o s.ppm` would replace the scene with its picture.
fn refuse_outputs_over_sources(
    scene: &Path,
    sources: &SourceMap,
    output: &Path,
) -> Result<(), Failure> {
    let imports = sources.files().map(|(_, file)| PathBuf::from(&file.path));
    for source in std::iter::once(scene.to_path_buf()).chain(imports) {
        if same_file(output, &source) {
            let role = if source == scene {
                "the scene"
            } else {
                "a file the scene imports"
            };
            return Err(Failure::Usage(format!(
                "the output {} is {role} ({}): choose another output with -o",
                output.display(),
                source.display()
            )));
        }
    }
    Ok(())
}

/// The rayon pool for `threads` workers (`None`: one per core), for `render` and `query`.
pub fn thread_pool(threads: Option<u32>) -> Result<rayon::ThreadPool, Failure> {
    let threads = match threads {
        Some(n) => n as usize,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Failure::Message(format!("cannot start {threads} worker threads: {e}")))
}

/// Refuses an output whose folder does not exist, before a long render rather than after.
pub fn check_output_folder(path: &Path) -> Result<(), Failure> {
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) if !dir.is_dir() => Err(Failure::Message(format!(
            "cannot write {}: the directory {} does not exist",
            path.display(),
            dir.display()
        ))),
        _ => Ok(()),
    }
}

/// Whether two paths name the same file: the same device and inode when both exist (this
/// sees through links and `..`), otherwise the same canonical folder and file name.
pub fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(a), Ok(b)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return a.dev() == b.dev() && a.ino() == b.ino();
        }
    }
    match (canonical_location(a), canonical_location(b)) {
        (Some(a), Some(b)) => a == b,
        _ => a == b,
    }
}

/// The canonical folder of `path` joined with its file name (the file itself need not exist).
fn canonical_location(path: &Path) -> Option<PathBuf> {
    let name = path.file_name()?;
    let folder = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(folder).ok()?.join(name))
}

pub fn render(args: &RenderArgs) -> Result<(), Failure> {
    if args.task.is_some() || args.task_from_env {
        return crate::farm::task::render_task(args);
    }
    let started = Instant::now();
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.scene.scene));
    let format = ImageFormat::from_path(&output).unwrap_or(ImageFormat::Png);
    // Fail before a long render, not after it, when the output cannot be written there.
    for path in std::iter::once(&output).chain(&args.stats_image) {
        check_output_folder(path)?;
    }

    if let Some(stats_image) = &args.stats_image {
        if same_file(stats_image, &output) {
            return Err(Failure::Usage(format!(
                "--stats-image {} is the same file as the output {}: the heat maps would replace the render",
                stats_image.display(),
                output.display()
            )));
        }
    }
    crate::interrupt::install();

    let loaded = load_scene(&args.scene, args.quiet)?;
    if crate::animation::is_animation_job(args, &loaded) {
        return crate::animation::render_animation(args, loaded);
    }
    let (loaded, options) = apply_render_flags(loaded, &args.overrides)?;
    let compile_seconds = started.elapsed().as_secs_f64();
    refuse_outputs_over_sources(&args.scene.scene, &loaded.scene.sources, &output)?;
    if let Some(stats_image) = &args.stats_image {
        refuse_outputs_over_sources(&args.scene.scene, &loaded.scene.sources, stats_image)?;
    }
    let estimate = MemoryEstimate {
        pixels: u64::from(options.width) * u64::from(options.height),
        output: format,
        stats_image: args
            .stats_image
            .as_ref()
            .map(|path| ImageFormat::from_path(path).unwrap_or(ImageFormat::Png)),
        objects: loaded.scene.objects.len() as u64,
    };
    let asked = crate::request::size_flags(&args.overrides).map_or_else(
        || format!("a {}x{} image", options.width, options.height),
        |flags| format!("`{flags}`"),
    );
    estimate.check(&asked)?;
    let objects = loaded.scene.objects.len();
    // What would make samples reach the ray budget, said while the IR (and its sources) is
    // at hand: the report after the render needs it only if pixels were cut.
    let budget_cause = whitted_explain::lint::ray_budget_cause(
        &loaded.scene,
        loaded.scene.settings.min_weight,
        options.max_depth,
    );
    // A scene too big to lint by default is rendered without its lints (`check --lint`
    // has them): they would add about a second per million objects to the render.
    let lint =
        !args.quiet && !args.no_lint && whitted_explain::lint::lints_by_default(&loaded.scene);
    // The scene is prepared (shapes, BVH) on the render's threads too, so that `--threads`
    // bounds the whole run.
    let pool = thread_pool(args.threads)?;
    let prepared = if lint {
        let prepared = pool.install(|| PreparedScene::new(&loaded.scene));
        crate::scene_input::print_lints(&loaded, &prepared, &options);
        prepared
    } else {
        // Nothing below needs the IR (names, spans, provenance): it is freed while the
        // shapes are prepared, before the BVH build.
        let scene = loaded.scene;
        pool.install(|| PreparedScene::new_releasing_ir(scene))
    };

    let show_progress = !args.quiet && std::io::stderr().is_terminal();
    let bar = show_progress.then(|| {
        let bar = ProgressBar::new(u64::from(options.width) * u64::from(options.height));
        let style = ProgressStyle::with_template(
            "{spinner} rendering [{bar:40}] {percent:>3}%  {elapsed_precise} elapsed, ETA {eta}",
        )
        .map(|s| s.progress_chars("=> "))
        .unwrap_or_else(|_| ProgressStyle::default_bar());
        bar.set_style(style);
        bar
    });
    let observer = ProgressObserver { bar };
    let cpu_before = crate::cpu_time::pool_cpu_seconds(&pool);
    // Per-pixel statistics are gathered only when asked for: the plain render records nothing.
    let rendered = pool.install(|| match &args.stats_image {
        Some(_) => whitted_tracer::render_with_pixel_stats(&prepared, &options, &observer)
            .map(|(image, stats, pixel_stats)| (image, stats, Some(pixel_stats))),
        None => whitted_tracer::render(&prepared, &options, &observer)
            .map(|(image, stats)| (image, stats, None)),
    });
    let render_cpu_seconds = crate::cpu_time::pool_cpu_seconds(&pool) - cpu_before;
    if let Some(bar) = &observer.bar {
        bar.finish_and_clear();
    }
    let Some((image, stats, pixel_stats)) = rendered else {
        return Err(Failure::Message(
            "the render was cancelled; nothing was written".into(),
        ));
    };

    let (width, height) = (image.width, image.height);
    write_image(
        &output,
        format,
        width,
        height,
        Pixels::Linear(&image.pixels),
    )
    .map_err(Failure::Message)?;
    // Each buffer goes as soon as it is no longer needed: at the largest sizes they are
    // gigabytes each (see `MemoryEstimate`).
    drop(image);
    if let (Some(path), Some(pixel_stats)) = (&args.stats_image, pixel_stats) {
        let heat_maps = StatsImage::new(width, height, &pixel_stats, &options);
        drop(pixel_stats);
        let format = ImageFormat::from_path(path).unwrap_or(ImageFormat::Png);
        write_image(
            path,
            format,
            heat_maps.width,
            heat_maps.height,
            Pixels::Srgb8(heat_maps.srgb),
        )
        .map_err(Failure::Message)?;
    }

    let summary = Summary {
        scene: &args.scene.scene,
        output: &output,
        options: &options,
        threads: pool.current_num_threads(),
        objects,
        compile_seconds,
        build_seconds: prepared.build_seconds(),
        shapes_seconds: prepared.shapes_seconds(),
        light_buffer_seconds: prepared.light_buffer_seconds(),
        traversal: TraversalPath::chosen(),
        light_buffers: prepared.light_buffer_sizes(),
        lights: prepared.light_count(),
        stats: &stats,
        render_cpu_seconds,
        wall_seconds: started.elapsed().as_secs_f64(),
        peak_memory_kib: crate::cpu_time::peak_memory_kib(),
    };
    if !args.quiet && stats.pixels_cut_at_ray_budget > 0 {
        eprintln!(
            "{}",
            ray_budget_report(&stats, width, height, &budget_cause)
        );
    }
    match args.stats {
        Some(StatsFormat::Text) => write_stdout(&summary.text())?,
        Some(StatsFormat::Json) => write_stdout(&(summary.json().to_string() + "\n"))?,
        None => {}
    }
    if !args.quiet && args.stats.is_none() && std::io::stderr().is_terminal() {
        eprintln!(
            "wrote {} ({}x{}) in {:.2} s",
            output.display(),
            width,
            height,
            summary.wall_seconds
        );
    }
    Ok(())
}

/// The warning after a render whose samples reached the ray budget: how many pixels, the
/// first one, and the settings that made it happen.
fn ray_budget_report(stats: &RenderStats, width: u32, height: u32, cause: &str) -> String {
    let pixels = u64::from(width) * u64::from(height);
    let first = match stats.first_pixel_cut_at_ray_budget {
        Some([x, y]) => format!(", the first at ({x}, {y})"),
        None => String::new(),
    };
    format!(
        "warning: {} of {pixels} pixels were cut at the ray budget of {} rays per sample{first}: \
         their recursion stopped there and they keep the colour gathered so far\n  = cause: \
         {cause}\n  = help: raise min_weight (0.001 is usual) so that weak paths end, or lower \
         max_depth; `whitted trace --pixel X,Y` shows where a pixel was cut",
        stats.pixels_cut_at_ray_budget,
        whitted_ir::limits::MAX_RAYS_PER_SAMPLE
    )
}

/// Everything `--stats` reports about one render.
struct Summary<'a> {
    scene: &'a Path,
    output: &'a Path,
    options: &'a RenderOptions,
    threads: usize,
    objects: usize,
    compile_seconds: f64,
    build_seconds: f64,
    /// The part of `build_seconds` that prepared the shapes.
    shapes_seconds: f64,
    /// The part that built the light buffers; the rest built the BVH.
    light_buffer_seconds: f64,
    /// The BVH walk's child test (every path gives the same image).
    traversal: TraversalPath,
    /// How many lights have a light buffer, the candidates in them, and their bytes.
    light_buffers: (usize, usize, usize),
    lights: usize,
    stats: &'a RenderStats,
    /// The CPU time the render's threads spent on it, summed over the threads (each
    /// thread's own clock, so time other programs took on the machine is not counted).
    render_cpu_seconds: f64,
    wall_seconds: f64,
    /// The process's peak resident memory, when the system reports it.
    peak_memory_kib: Option<u64>,
}

impl Summary<'_> {
    /// Which lights answer shadow rays from a light buffer, and what the buffers hold.
    fn light_buffer_line(&self) -> String {
        let (buffered, candidates, bytes) = self.light_buffers;
        if buffered == 0 {
            return "light buffers    none (every shadow ray walks the BVH)".to_string();
        }
        format!(
            "light buffers    {buffered} of {} lights, {candidates} candidates ({:.1} MiB)",
            self.lights,
            bytes as f64 / (1024.0 * 1024.0)
        )
    }

    /// The build's time and its parts: shapes, the BVH, and the light buffers when built.
    fn build_line(&self) -> String {
        let tree = self.build_seconds - self.shapes_seconds - self.light_buffer_seconds;
        let buffers = if self.light_buffers.0 > 0 {
            format!(", light buffers {:.3} s", self.light_buffer_seconds)
        } else {
            String::new()
        };
        format!(
            "bvh build        {:.3} s (shapes {:.3} s, tree {:.3} s{buffers})",
            self.build_seconds, self.shapes_seconds, tree
        )
    }

    fn text(&self) -> String {
        let s = self.stats;
        let o = self.options;
        let mrays = self.stats.rays_per_second() / 1e6;
        [
            format!("scene            {}", self.scene.display()),
            format!("output           {}", self.output.display()),
            format!(
                "image            {}x{}, {} spp, max depth {}",
                o.width, o.height, o.samples_per_pixel, o.max_depth
            ),
            format!("objects          {}", self.objects),
            format!("compile          {:.3} s", self.compile_seconds),
            self.build_line(),
            format!("bvh walk         {}", self.traversal.name()),
            self.light_buffer_line(),
            format!(
                "render           {:.3} s on {} threads",
                s.render_seconds, self.threads
            ),
            // Packets need a BVH: a scene of a few objects traces every ray alone.
            match s.camera_rays_in_packets {
                0 => format!("camera rays      {}", s.camera_rays),
                packed => format!("camera rays      {} ({packed} in packets)", s.camera_rays),
            },
            format!("shadow rays      {}", s.shadow_rays),
            format!("reflected rays   {}", s.reflected_rays),
            format!("transmitted rays {}", s.transmitted_rays),
            format!("total rays       {}", s.total_rays()),
            match s.first_pixel_cut_at_ray_budget {
                Some([x, y]) => format!(
                    "ray budget       {} pixels cut at {} rays per sample, the first at ({x}, {y})",
                    s.pixels_cut_at_ray_budget,
                    whitted_ir::limits::MAX_RAYS_PER_SAMPLE
                ),
                None => format!(
                    "ray budget       no pixel cut ({} rays per sample)",
                    whitted_ir::limits::MAX_RAYS_PER_SAMPLE
                ),
            },
            format!(
                "speed            {mrays:.2} Mrays/s ({:.2} per thread)",
                mrays / self.threads as f64
            ),
            format!(
                "render cpu       {:.3} s over all threads, {:.2} Mrays per cpu-second",
                self.render_cpu_seconds,
                self.rays_per_cpu_second() / 1e6
            ),
            format!("wall             {:.3} s", self.wall_seconds),
            match self.peak_memory_kib {
                Some(kib) => format!("peak memory      {:.1} MiB", kib as f64 / 1024.0),
                None => "peak memory      unknown".to_string(),
            },
        ]
        .join("\n")
            + "\n"
    }

    fn json(&self) -> serde_json::Value {
        let s = self.stats;
        let o = self.options;
        serde_json::json!({
            "scene": self.scene.display().to_string(),
            "output": self.output.display().to_string(),
            "width": o.width,
            "height": o.height,
            "samples_per_pixel": o.samples_per_pixel,
            "max_depth": o.max_depth,
            "threads": self.threads,
            "objects": self.objects,
            "compile_seconds": self.compile_seconds,
            "build_seconds": self.build_seconds,
            "shapes_seconds": self.shapes_seconds,
            "light_buffer_seconds": self.light_buffer_seconds,
            "bvh_walk": self.traversal.name(),
            "light_buffers": self.light_buffers.0,
            "light_buffer_candidates": self.light_buffers.1,
            "light_buffer_bytes": self.light_buffers.2,
            "render_seconds": s.render_seconds,
            "camera_rays": s.camera_rays,
            "shadow_rays": s.shadow_rays,
            "camera_rays_in_packets": s.camera_rays_in_packets,
            "reflected_rays": s.reflected_rays,
            "transmitted_rays": s.transmitted_rays,
            "total_rays": s.total_rays(),
            "ray_budget_per_sample": whitted_ir::limits::MAX_RAYS_PER_SAMPLE,
            "pixels_cut_at_ray_budget": s.pixels_cut_at_ray_budget,
            "first_pixel_cut_at_ray_budget": s.first_pixel_cut_at_ray_budget,
            "rays_per_second": self.stats.rays_per_second(),
            "render_cpu_seconds": self.render_cpu_seconds,
            "rays_per_cpu_second": self.rays_per_cpu_second(),
            "wall_seconds": self.wall_seconds,
            "peak_memory_kib": self.peak_memory_kib,
        })
    }

    /// Rays per second of the render threads' CPU time (0 when none was measured).
    fn rays_per_cpu_second(&self) -> f64 {
        if self.render_cpu_seconds > 0.0 {
            self.stats.total_rays() as f64 / self.render_cpu_seconds
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MAX: u64 = whitted_ir::limits::MAX_PIXELS;

    fn estimate(pixels: u64, output: ImageFormat, stats: Option<ImageFormat>) -> u64 {
        MemoryEstimate {
            pixels,
            output,
            stats_image: stats,
            objects: 0,
        }
        .bytes()
    }

    #[test]
    fn the_memory_estimate_counts_each_phase_by_hand() {
        use ImageFormat::{Exr, Png};
        // A plain PNG: 12 bytes of floats and 3 of sRGB per pixel.
        assert_eq!(estimate(100, Png, None), 100 * 15);
        // An EXR: the floats, their copy and the encoder's.
        assert_eq!(estimate(100, Exr, None), 100 * 36);
        // With heat maps as PNG: the render with its statistics is the peak (12 + 12 + 3).
        assert_eq!(estimate(100, Png, Some(Png)), 100 * 27);
        // Heat maps as EXR: 9 sRGB bytes and 3 panels of 24 bytes of encoding.
        assert_eq!(estimate(100, Png, Some(Exr)), 100 * 81);
        // Objects count on top.
        let with_objects = MemoryEstimate {
            pixels: 100,
            output: Png,
            stats_image: None,
            objects: 1000,
        };
        assert_eq!(
            with_objects.bytes(),
            100 * 15 + 1000 * PREPARED_BYTES_PER_OBJECT
        );
    }

    #[test]
    fn the_largest_images_fit_unless_their_heat_maps_are_float_images() {
        use ImageFormat::{Exr, Hdr, Png, Ppm};
        for output in [Png, Ppm, Exr, Hdr] {
            for stats in [None, Some(Png), Some(Ppm)] {
                let estimate = MemoryEstimate {
                    pixels: MAX,
                    output,
                    stats_image: stats,
                    objects: whitted_ir::limits::MAX_OBJECTS as u64,
                };
                assert!(estimate.check("the size").is_ok(), "{output:?} {stats:?}");
            }
            let estimate = MemoryEstimate {
                pixels: MAX,
                output,
                stats_image: Some(Exr),
                objects: 0,
            };
            assert!(
                estimate.check("the size").is_err(),
                "{output:?} with EXR heat maps"
            );
        }
    }
}
