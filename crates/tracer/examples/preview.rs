//! Renders one of the built-in test scenes to a binary PPM (sRGB-encoded), for looking at
//! the tracer's output before the CLI exists.
//!
//! `cargo run -p whitted-tracer --example preview -- SCENE OUT.ppm [WIDTH HEIGHT SPP]`
//! where SCENE is `whitted`, `spheres` or `grid`.
// A program, not a library: it prints its results and sets its exit status.
#![allow(clippy::print_stdout, clippy::print_stderr, clippy::exit)]

use std::io::Write;

use whitted_tracer::testing::{reflective_spheres, sphere_grid, whitted_classic};
use whitted_tracer::{render, NoObserver, RenderOptions};

fn srgb(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let encoded = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (encoded * 255.0 + 0.5) as u8
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map(String::as_str).unwrap_or("whitted");
    let out = args.get(1).map(String::as_str).unwrap_or("preview.ppm");
    let number = |i: usize, default: u32| -> u32 {
        args.get(i).and_then(|s| s.parse().ok()).unwrap_or(default)
    };
    let builder = match name {
        "whitted" => whitted_classic(),
        "spheres" => reflective_spheres(),
        "grid" => sphere_grid(100),
        other => return Err(format!("unknown scene {other}").into()),
    };
    let scene = builder.prepare()?;
    let mut options = RenderOptions::from_settings(scene.settings());
    options.width = number(2, 640);
    options.height = number(3, 480);
    options.samples_per_pixel = number(4, 1);
    let (image, stats) = render(&scene, &options, &NoObserver).ok_or("cancelled")?;
    let mut file = std::io::BufWriter::new(std::fs::File::create(out)?);
    write!(file, "P6\n{} {}\n255\n", image.width, image.height)?;
    for p in &image.pixels {
        file.write_all(&[srgb(p[0]), srgb(p[1]), srgb(p[2])])?;
    }
    eprintln!(
        "{name}: {} rays in {:.3} s",
        stats.total_rays(),
        stats.render_seconds
    );
    Ok(())
}
