//! Times one compilation, as `cargo xtask bench` does: reads a scene, applies `-D` values,
//! compiles (parse, resolve, evaluate, validate) and prints seconds and object count.
//!
//! `cargo run --release -p whitted-lang --example compile_bench -- scenes/bench/grid.scene N=316`
// A program, not a library: it prints its results and sets its exit status.
#![allow(clippy::print_stdout, clippy::print_stderr, clippy::exit)]

use std::path::Path;
use std::time::Instant;

use whitted_lang::{compile_file, render_diagnostics, CompileOptions, SourceLoader};

struct DiskLoader;

impl SourceLoader for DiskLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        std::fs::read(path)
    }
}

fn main() -> std::process::ExitCode {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: compile_bench SCENE [NAME=VALUE]...");
        return std::process::ExitCode::from(2);
    };
    let defines = args
        .filter_map(|a| {
            a.split_once('=')
                .map(|(n, v)| (n.to_string(), v.to_string()))
        })
        .collect();
    let options = CompileOptions {
        defines,
        ..CompileOptions::default()
    };
    let start = Instant::now();
    let compilation = compile_file(Path::new(&path), &mut DiskLoader, &options);
    let seconds = start.elapsed().as_secs_f64();
    eprint!(
        "{}",
        render_diagnostics(&compilation.sources, &compilation.diagnostics, false)
    );
    let Some(scene) = &compilation.scene else {
        return std::process::ExitCode::FAILURE;
    };
    println!(
        "{path}: {seconds:.3} s, {} objects, {} materials, {} lights",
        scene.objects.len(),
        scene.materials.len(),
        scene.lights.len()
    );
    std::process::ExitCode::SUCCESS
}
