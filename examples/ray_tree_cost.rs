//! What recording a ray tree costs (issue 4, item 5): compiles a scene (default
//! scenes/whitted.scene), then, at maximum depth 8 (or the second argument), records the ray
//! tree of 1000 pixels spread over the image with `trace_pixel` and traces the same pixels
//! with the no-op recorder, and prints the mean and worst time per pixel of each; then
//! records the biggest of those trees 1000 times.
//!
//! `cargo run --release --example ray_tree_cost [-- SCENE [MAX_DEPTH]]`
// A program, not a library: it prints its results and sets its exit status.
#![allow(clippy::print_stdout, clippy::print_stderr, clippy::exit)]

use std::path::Path;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use whitted_lang::{compile_file, CompileOptions, SourceLoader};
use whitted_tracer::ray_tree::{trace_pixel, SampleChoice};
use whitted_tracer::{trace_pixel_with, NoRecord, PreparedScene, RenderOptions};

struct DiskLoader;

impl SourceLoader for DiskLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        std::fs::read(path)
    }
}

const PIXELS: u32 = 1000;

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let path = args
        .next()
        .unwrap_or_else(|| "scenes/whitted.scene".to_string());
    let max_depth = args.next().and_then(|d| d.parse().ok()).unwrap_or(8);
    let compilation = compile_file(
        Path::new(&path),
        &mut DiskLoader,
        &CompileOptions::default(),
    );
    let Some(scene) = compilation.scene else {
        eprintln!("{path} does not compile");
        return ExitCode::from(1);
    };
    let prepared = PreparedScene::new(&scene);
    let options = RenderOptions {
        max_depth,
        ..RenderOptions::from_settings(&scene.settings)
    };
    // A fixed spread of pixels: a golden-ratio walk over the image.
    let total = u64::from(options.width) * u64::from(options.height);
    let pixels: Vec<(u32, u32)> = (0..u64::from(PIXELS))
        .map(|i| {
            let index = (i * 2_654_435_761) % total;
            (
                (index % u64::from(options.width)) as u32,
                (index / u64::from(options.width)) as u32,
            )
        })
        .collect();

    for round in 0..2 {
        // The first round warms caches and is not reported.
        let mut recorded = Timing::default();
        let mut plain = Timing::default();
        let mut rays = 0usize;
        for &(x, y) in &pixels {
            let started = Instant::now();
            let tree = match trace_pixel(&prepared, &scene, &options, x, y, SampleChoice::All) {
                Ok(tree) => tree,
                Err(error) => {
                    eprintln!("{error}");
                    return ExitCode::from(1);
                }
            };
            recorded.add(started.elapsed());
            rays += tree
                .samples
                .iter()
                .map(|s| s.root.ray_count())
                .sum::<usize>();

            let started = Instant::now();
            for sample in 0..options.samples_per_pixel.max(1) {
                std::hint::black_box(trace_pixel_with(
                    &prepared,
                    &options,
                    x,
                    y,
                    sample,
                    &mut NoRecord,
                ));
            }
            plain.add(started.elapsed());
        }
        if round == 1 {
            println!(
                "{path}, {}x{}, max depth {max_depth}, {PIXELS} pixels, {:.1} rays per tree",
                options.width,
                options.height,
                rays as f64 / f64::from(PIXELS)
            );
            println!("recorded tree: {}", recorded.summary());
            println!("no recorder:   {}", plain.summary());
        }
    }

    // The biggest tree among those pixels, recorded again and again.
    let biggest = pixels.iter().copied().max_by_key(|&(x, y)| {
        trace_pixel(&prepared, &scene, &options, x, y, SampleChoice::All)
            .map_or(0, |t| t.samples.iter().map(|s| s.root.ray_count()).sum())
    });
    if let Some((x, y)) = biggest {
        let mut timing = Timing::default();
        let mut rays = 0;
        for _ in 0..PIXELS {
            let started = Instant::now();
            let tree = trace_pixel(&prepared, &scene, &options, x, y, SampleChoice::All);
            timing.add(started.elapsed());
            rays = tree.map_or(0, |t| t.samples.iter().map(|s| s.root.ray_count()).sum());
        }
        println!(
            "biggest tree, pixel ({x}, {y}), {rays} rays, {PIXELS} times: {}",
            timing.summary()
        );
    }
    ExitCode::SUCCESS
}

#[derive(Default)]
struct Timing {
    total: Duration,
    worst: Duration,
    count: u32,
}

impl Timing {
    fn add(&mut self, elapsed: Duration) {
        self.total += elapsed;
        self.worst = self.worst.max(elapsed);
        self.count += 1;
    }

    fn summary(&self) -> String {
        let mean = self.total.as_secs_f64() / f64::from(self.count.max(1));
        format!(
            "mean {:.1} µs, worst {:.1} µs per pixel",
            mean * 1e6,
            self.worst.as_secs_f64() * 1e6
        )
    }
}
