//! `whitted render`: compile, build the BVH, render in parallel with a progress bar, write.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use whitted_ir::{limits, Settings};
use whitted_tracer::{PreparedScene, RenderObserver, RenderOptions, RenderStats, TileResult};

use crate::cli::{ImageFormat, RenderArgs, RenderOverrides, StatsFormat};
use crate::image_output::write_image;
use crate::scene_input::{load_scene, write_stdout};
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

/// The scene's render settings with the command line's overrides applied: shared by
/// `render` and `trace`, so that a trace at a given size follows the render at that size.
pub fn render_options(settings: &Settings, overrides: &RenderOverrides) -> RenderOptions {
    let mut options = RenderOptions::from_settings(settings);
    options.width = overrides.width.unwrap_or(options.width);
    options.height = overrides.height.unwrap_or(options.height);
    options.samples_per_pixel = overrides.spp.unwrap_or(options.samples_per_pixel);
    options.max_depth = overrides.max_depth.unwrap_or(options.max_depth);
    options
}

/// Refuses image sizes that cannot be held in memory, before any work starts: at most
/// [`limits::MAX_PIXELS`] (about 11,585 x 11,585, 1.5 GiB of linear RGB). Larger sizes are
/// almost always a typo (`--width 30000 --height 30000`) and would exhaust memory.
pub fn check_image_size(width: u32, height: u32) -> Result<(), Failure> {
    let pixels = u64::from(width) * u64::from(height);
    if pixels > limits::MAX_PIXELS {
        return Err(Failure::Message(format!(
            "a {width}x{height} image has {pixels} pixels, more than the pixels limit ({}, about 11585x11585)",
            limits::MAX_PIXELS
        )));
    }
    Ok(())
}

/// `scenes/whitted.scene` renders to `whitted.png` in the current directory by default.
fn default_output(scene: &Path) -> PathBuf {
    let stem = scene.file_stem().map(|s| s.to_string_lossy().into_owned());
    PathBuf::from(format!(
        "{}.png",
        stem.unwrap_or_else(|| "render".to_string())
    ))
}

pub fn render(args: &RenderArgs) -> Result<(), Failure> {
    let started = Instant::now();
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.scene.scene));
    let format = ImageFormat::from_path(&output).unwrap_or(ImageFormat::Png);
    // Fail before a long render, not after it, when the output cannot be written there.
    for path in std::iter::once(&output).chain(&args.stats_image) {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            if !dir.is_dir() {
                return Err(Failure::Message(format!(
                    "cannot write {}: the directory {} does not exist",
                    path.display(),
                    dir.display()
                )));
            }
        }
    }

    let loaded = load_scene(&args.scene, args.quiet)?;
    let compile_seconds = started.elapsed().as_secs_f64();
    let prepared = PreparedScene::new(&loaded.scene);

    let options = render_options(&loaded.scene.settings, &args.overrides);
    check_image_size(options.width, options.height)?;

    let threads = match args.threads {
        Some(n) => n as usize,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Failure::Message(format!("cannot start {threads} worker threads: {e}")))?;

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
    // Per-pixel statistics are gathered only when asked for: the plain render records nothing.
    let rendered = pool.install(|| match &args.stats_image {
        Some(_) => whitted_tracer::render_with_pixel_stats(&prepared, &options, &observer)
            .map(|(image, stats, pixel_stats)| (image, stats, Some(pixel_stats))),
        None => whitted_tracer::render(&prepared, &options, &observer)
            .map(|(image, stats)| (image, stats, None)),
    });
    if let Some(bar) = &observer.bar {
        bar.finish_and_clear();
    }
    let Some((image, stats, pixel_stats)) = rendered else {
        return Err(Failure::Message(
            "the render was cancelled; nothing was written".into(),
        ));
    };

    write_image(&output, format, image.width, image.height, &image.pixels)
        .map_err(Failure::Message)?;
    if let (Some(path), Some(pixel_stats)) = (&args.stats_image, &pixel_stats) {
        let heat_maps = StatsImage::new(image.width, image.height, pixel_stats, &options);
        let format = ImageFormat::from_path(path).unwrap_or(ImageFormat::Png);
        write_image(
            path,
            format,
            heat_maps.width,
            heat_maps.height,
            &heat_maps.pixels,
        )
        .map_err(Failure::Message)?;
    }

    let summary = Summary {
        scene: &args.scene.scene,
        output: &output,
        options: &options,
        threads,
        objects: loaded.scene.objects.len(),
        compile_seconds,
        build_seconds: prepared.build_seconds(),
        stats: &stats,
        wall_seconds: started.elapsed().as_secs_f64(),
    };
    match args.stats {
        Some(StatsFormat::Text) => write_stdout(&summary.text())?,
        Some(StatsFormat::Json) => write_stdout(&(summary.json().to_string() + "\n"))?,
        None => {}
    }
    if !args.quiet && args.stats.is_none() && std::io::stderr().is_terminal() {
        eprintln!(
            "wrote {} ({}x{}) in {:.2} s",
            output.display(),
            image.width,
            image.height,
            summary.wall_seconds
        );
    }
    Ok(())
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
    stats: &'a RenderStats,
    wall_seconds: f64,
}

impl Summary<'_> {
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
            format!("bvh build        {:.3} s", self.build_seconds),
            format!(
                "render           {:.3} s on {} threads",
                s.render_seconds, self.threads
            ),
            format!("camera rays      {}", s.camera_rays),
            format!("shadow rays      {}", s.shadow_rays),
            format!("reflected rays   {}", s.reflected_rays),
            format!("transmitted rays {}", s.transmitted_rays),
            format!("total rays       {}", s.total_rays()),
            format!(
                "speed            {mrays:.2} Mrays/s ({:.2} per thread)",
                mrays / self.threads as f64
            ),
            format!("wall             {:.3} s", self.wall_seconds),
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
            "render_seconds": s.render_seconds,
            "camera_rays": s.camera_rays,
            "shadow_rays": s.shadow_rays,
            "reflected_rays": s.reflected_rays,
            "transmitted_rays": s.transmitted_rays,
            "total_rays": s.total_rays(),
            "rays_per_second": self.stats.rays_per_second(),
            "wall_seconds": self.wall_seconds,
        })
    }
}
