//! The `whitted` command line: the only place that reads files, prints and exits.
//!
//! Exit codes: 0 success; 1 the scene or a file; 2 the command line; 128 + N a signal
//! (the rule is in `failure.rs`).
// A program, not a library: it prints its results and sets its exit status.
#![allow(clippy::print_stdout, clippy::print_stderr, clippy::exit)]

mod against_image;
mod allocator;
mod animation;
mod cli;
mod cpu_time;
mod debug_cmd;
mod diff_cmd;
mod explain_cmd;
mod failure;
mod farm;
mod fmt_cmd;
mod front_end;
mod grade_class;
mod grade_cmd;
mod image_output;
mod interrupt;
mod lsp_cmd;
mod material_thumbnail;
mod mit6837_cmd;
mod mit6837_pictures;
mod query_cmd;
mod render_cmd;
mod request;
mod scene_input;
mod setting_flags;
mod stats_image;
mod student_image;
mod trace_cmd;

use std::io::Write;
use std::process::ExitCode;

use clap::Parser;
use whitted_tracer::TraversalPath;

use cli::{Cli, Command};
pub use failure::Failure;

/// Where the BVH walk's child test may be forced, to compare the paths' speed or to rule
/// one out: every path renders the same image.
const TRAVERSAL_VARIABLE: &str = "WHITTED_TRAVERSAL";

/// Forces the BVH walk named by `WHITTED_TRAVERSAL` (baseline, avx2 or avx512), if set.
fn force_traversal_from_env() -> Result<(), Failure> {
    // Unset or empty (`WHITTED_TRAVERSAL= whitted …`): the fastest path.
    let Some(value) = std::env::var_os(TRAVERSAL_VARIABLE).filter(|v| !v.is_empty()) else {
        return Ok(());
    };
    let names = TraversalPath::ALL.map(TraversalPath::name).join(", ");
    let name = value.to_string_lossy();
    let path = TraversalPath::from_name(&name).ok_or_else(|| {
        Failure::Usage(format!(
            "{TRAVERSAL_VARIABLE}={name:?} names no BVH walk; use one of {names}"
        ))
    })?;
    whitted_tracer::force_traversal_path(Some(path))
        .map_err(|e| Failure::Message(format!("{TRAVERSAL_VARIABLE}={name}: {e}")))
}

/// Set to `off`, shadow rays walk the BVH instead of using the lights' light buffers, to
/// compare their speed: the image is the same.
const LIGHT_BUFFERS_VARIABLE: &str = "WHITTED_LIGHT_BUFFERS";

/// Honours `WHITTED_LIGHT_BUFFERS` (`on`, the default, or `off`), if set.
fn light_buffers_from_env() -> Result<(), Failure> {
    let Some(value) = std::env::var_os(LIGHT_BUFFERS_VARIABLE).filter(|v| !v.is_empty()) else {
        return Ok(());
    };
    match value.to_string_lossy().as_ref() {
        "on" => whitted_tracer::use_light_buffers(true),
        "off" => whitted_tracer::use_light_buffers(false),
        other => {
            return Err(Failure::Usage(format!(
                "{LIGHT_BUFFERS_VARIABLE}={other:?}: use on or off"
            )))
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    allocator::configure();
    let cli = Cli::parse();
    let result = force_traversal_from_env()
        .and_then(|()| light_buffers_from_env())
        .and_then(|()| match cli.command {
            Command::Check(args) => scene_input::check(&args),
            Command::Ir(args) => scene_input::ir(&args),
            Command::Render(args) => render_cmd::render(&args),
            Command::Trace(args) if args.against.is_some() || !args.against_set.is_empty() => {
                diff_cmd::trace_against(&args)
            }
            Command::Trace(args) => trace_cmd::trace(&args),
            Command::Diff(args) => diff_cmd::diff(&args),
            Command::Query(args) => query_cmd::query(&args),
            Command::Grade(args) => grade_cmd::grade(&args),
            Command::Explain(args) => explain_cmd::explain_pixel(&args),
            Command::Debug(args) => debug_cmd::debug(&args),
            Command::Fmt(args) => fmt_cmd::fmt(&args),
            Command::Mit6837(args) => mit6837_cmd::mit6837(&args.args),
            Command::Lsp => lsp_cmd::lsp(),
            Command::Farm(args) => farm::farm(&args),
        });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            if let Some(message) = failure.message() {
                let _ = writeln!(std::io::stderr(), "error: {message}");
            }
            ExitCode::from(failure.exit_code())
        }
    }
}
