//! `cargo xtask`: the project's own automation (ci, bench, golden), in Rust so it runs anywhere
//! cargo does.
// A program, not a library: it prints its results and sets its exit status.
#![allow(clippy::print_stdout, clippy::print_stderr, clippy::exit)]

mod bench;
mod ci;
mod fuzz_cmd;
mod golden;

use std::process::ExitCode;

use xtask::fuzz::memory::CountingAllocator;

/// Counts live bytes, for the fuzzer's memory budget.
#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

const USAGE: &str = "\
usage: cargo xtask <command>

commands:
  ci       fmt check, clippy -D warnings, every test, dependency directions, golden
  deps     only the dependency-direction checks
  golden   render the golden scenes and compare with tests/golden/ (--bless to update;
           --scenes DIR --refs DIR for your own folders)
  bench    release build, then time the benchmark scenes (prints Mrays/s), each run
           alternately with the base revision's binary and printed beside it;
           --size WxH, --only TEXT (only the render rows whose label has TEXT),
           --base REV (default HEAD~1 on a clean work tree, HEAD on a changed one),
           --no-base, --mesh (only the mesh rows), --csg (only the CSG rows),
           --programs (only the scenes-written-by-programs table), --lsp
  fuzz     the whole-pipeline fuzzer: --cases N (1000), --seed S (from the clock),
           --case K (only case K of the seed), --save (shrink new failures into
           tests/fuzz-regressions/), --replay (only the regression inputs)";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(command) = args.first() else {
        eprintln!("{USAGE}");
        return ExitCode::from(2);
    };
    let rest = &args[1..];
    let result = match command.as_str() {
        "ci" => ci::run(rest),
        "deps" => ci::check_dependency_directions(),
        "golden" => golden::run(rest),
        "bench" => bench::run(rest),
        "fuzz" => fuzz_cmd::run(rest),
        "-h" | "--help" | "help" => {
            println!("{USAGE}");
            Ok(())
        }
        other => {
            eprintln!("unknown command `{other}`\n\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("xtask: {error:#}");
            ExitCode::FAILURE
        }
    }
}

/// The workspace root (xtask lives one level below it).
pub fn workspace_root() -> std::path::PathBuf {
    let manifest_dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    manifest_dir
        .parent()
        .map(|p| p.to_path_buf())
        .unwrap_or(manifest_dir)
}

/// Runs a command in the workspace root, echoing it, and fails if it fails.
pub fn run_cargo(args: &[&str]) -> anyhow::Result<()> {
    run_cargo_with(args, &[])
}

/// [`run_cargo`] with environment variables set for the command.
pub fn run_cargo_with(args: &[&str], env: &[(&str, &str)]) -> anyhow::Result<()> {
    let shown: Vec<String> = env.iter().map(|(k, v)| format!("{k}={v} ")).collect();
    eprintln!("$ {}cargo {}", shown.concat(), args.join(" "));
    let status = std::process::Command::new(cargo())
        .args(args)
        .envs(env.iter().copied())
        .current_dir(workspace_root())
        .status()?;
    anyhow::ensure!(
        status.success(),
        "`cargo {}` failed ({status})",
        args.join(" ")
    );
    Ok(())
}

/// The cargo that runs us, so a rustup toolchain override is honoured.
pub fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string())
}
