//! `cargo xtask bench`: builds the release binary and times the benchmark scenes.
//!
//! Prints figures; asserts nothing about time (machines are noisy and shared). Each render
//! runs with one thread (the honest per-core figure) and with every core, alternately with
//! the base revision's binary (`base.rs`) when there is one, so that each figure is printed
//! beside the base's from the same minutes of the same machine.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use anyhow::{bail, Context};
use serde::Deserialize;

use crate::{run_cargo, run_cargo_with, workspace_root};

mod base;
mod compare;
mod dragon;
mod mesh;
mod options;
mod programs;

use compare::{change, is_regression, noise, spread, Better};

/// One benchmark render: a scene, its `-D` overrides and what to print it as.
struct Case {
    label: &'static str,
    /// Relative to the workspace root.
    scene: &'static str,
    defines: &'static [&'static str],
    /// The equivalent POV-Ray scene, for a side-by-side figure when `povray` is installed.
    pov: Option<&'static str>,
    /// What writes the scene under target/bench/ before it is rendered (`--mesh` rows).
    generated: Option<Generated>,
}

/// The scenes the bench writes itself rather than keeps in `scenes/bench/`.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Generated {
    /// `mesh.rs`: the 1,000,000-triangle sphere.
    Sphere,
    /// `dragon.rs`: the Stanford dragon, fetched from the npm registry.
    Dragon,
}

const RENDERS: &[Case] = &[
    Case {
        label: "classic (Whitted 1980)",
        scene: "scenes/bench/classic.scene",
        defines: &[],
        pov: Some("scenes/bench/pov/classic.pov"),
        generated: None,
    },
    Case {
        label: "1,000 spheres",
        scene: "scenes/bench/spheres1000.scene",
        defines: &[],
        pov: Some("scenes/bench/pov/spheres1000.pov"),
        generated: None,
    },
    Case {
        label: "grid 10,000 spheres",
        scene: "scenes/bench/grid.scene",
        defines: &["N=100"],
        pov: None,
        generated: None,
    },
    Case {
        label: "grid 1,000,000 spheres",
        scene: "scenes/bench/grid.scene",
        defines: &["N=1000"],
        pov: Some("scenes/bench/pov/grid.pov"),
        generated: None,
    },
    Case {
        label: "mesh 1M triangles, matte",
        scene: "target/bench/mesh1m-matte.scene",
        defines: &[],
        pov: None,
        generated: Some(Generated::Sphere),
    },
    Case {
        label: "mesh 1M triangles, glass",
        scene: "target/bench/mesh1m-glass.scene",
        defines: &[],
        pov: None,
        generated: Some(Generated::Sphere),
    },
    Case {
        label: "dragon, 202,520 triangles",
        scene: "target/bench/dragon.scene",
        defines: &[],
        pov: None,
        generated: Some(Generated::Dragon),
    },
];

/// CSG against the same shapes without it (issue 14): a union should cost about what a
/// group of its children costs, and bounded CSG should cost nothing to rays that miss it.
const CSG_RENDERS: &[Case] = &[
    Case {
        label: "union of 10,000 spheres",
        scene: "scenes/bench/union10k.scene",
        defines: &[],
        pov: None,
        generated: None,
    },
    Case {
        label: "group of the same spheres",
        scene: "scenes/bench/union10k.scene",
        defines: &["UNION=0"],
        pov: None,
        generated: None,
    },
    Case {
        label: "Menger sponge, level 3",
        scene: "scenes/bench/menger.scene",
        defines: &[],
        pov: None,
        generated: None,
    },
    Case {
        label: "1,000 box-and-plane crystals",
        scene: "scenes/bench/crystals.scene",
        defines: &[],
        pov: None,
        generated: None,
    },
];

const COMPILES: &[Case] = &[
    Case {
        label: "grid N=316 (99,856 spheres)",
        scene: "scenes/bench/grid.scene",
        defines: &["N=316"],
        pov: None,
        generated: None,
    },
    Case {
        label: "grid N=1000 (1,000,000 spheres)",
        scene: "scenes/bench/grid.scene",
        defines: &["N=1000"],
        pov: None,
        generated: None,
    },
];

/// The fields of `whitted render --stats=json` that the table needs.
#[derive(Deserialize)]
struct Stats {
    width: u32,
    height: u32,
    max_depth: u32,
    objects: u64,
    compile_seconds: f64,
    build_seconds: f64,
    /// The part of `build_seconds` that prepared the shapes.
    shapes_seconds: f64,
    /// The part that built the light buffers (0 from a binary before them); the rest built
    /// the BVH.
    #[serde(default)]
    light_buffer_seconds: f64,
    render_seconds: f64,
    /// The render threads' own CPU time, summed (`CLOCK_THREAD_CPUTIME_ID`).
    render_cpu_seconds: f64,
    total_rays: u64,
    peak_memory_kib: Option<u64>,
    /// The BVH walk's child test the binary chose (`baseline`, `avx2`, `avx512`).
    bvh_walk: String,
}

pub fn run(args: &[String]) -> anyhow::Result<()> {
    let options = options::parse(args)?;
    if options.lsp {
        return lsp_latency();
    }
    run_cargo(&["build", "--release", "--locked", "--bin", "whitted"])?;
    let root = workspace_root();
    let exe = root.join("target/release/whitted");
    let out_dir = root.join("target/bench");
    std::fs::create_dir_all(&out_dir)?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if options.programs {
        return programs::run(&exe, &out_dir, RUNS);
    }
    let size = (options.width, options.height);
    let wanted = |case: &&Case| {
        options
            .only
            .as_deref()
            .is_none_or(|text| case.label.contains(text))
            && (!options.mesh || case.generated.is_some())
    };
    let cases: Vec<&Case> = if options.csg {
        CSG_RENDERS.iter().filter(wanted).collect()
    } else {
        RENDERS.iter().chain(CSG_RENDERS).filter(wanted).collect()
    };
    if cases.is_empty() {
        bail!(
            "no render row's label contains `{}`",
            options.only.as_deref().unwrap_or("")
        );
    }
    let cases = write_generated(&out_dir, cases)?;
    if cases.is_empty() {
        // The only rows asked for were skipped, and a line above said why.
        return Ok(());
    }
    let base = match base::choose(&options.base, base::work_tree_changed(&root)?) {
        None => {
            println!("(no base: --no-base)");
            None
        }
        Some(choice) => match base::build(&root, &out_dir, &choice.revision) {
            Ok(base) => {
                println!(
                    "(base: {} = {}, {}; its binary is {})",
                    choice.revision,
                    base.short_sha,
                    choice.why,
                    base.exe.display()
                );
                Some(base)
            }
            Err(error) => {
                println!("(no base: {error:#}; the table shows the work tree alone)");
                None
            }
        },
    };
    match &base {
        Some(base) => comparison_table(&exe, base, &out_dir, cases, size, cores)?,
        None => render_table(&exe, &out_dir, cases, size, cores)?,
    }
    if options.mesh || options.csg || options.only.is_some() {
        return Ok(());
    }
    let (width, height) = size;
    // One render per process pays for cold caches, first-touch page faults on the image and
    // thread start-up: on a 40 ms render that is a fifth of the time. The tracer's own bench
    // example renders the same scenes (built in Rust) repeatedly in one process: the
    // steady-state speed per core.
    println!("\nsteady state (same scenes rendered repeatedly in one process: crates/tracer/examples/bench.rs)");
    run_bench_example(&["whitted"], None)?;
    run_bench_example(&["spheres"], None)?;

    // The BVH walk's child test on each path (issue 14): the default is the fastest the CPU
    // runs; every path renders the same bits (tests/integration/traversal_paths.rs).
    println!("\nBVH walk paths (steady state, one thread and all cores; the same images)");
    for path in ["baseline", "avx2", "avx512"] {
        run_bench_example(&["spheres"], Some(path))?;
        run_bench_example(&["grid", "100"], Some(path))?;
    }

    if Path::new(POVRAY).exists() {
        println!("\nPOV-Ray 3.7 on the equivalent scenes ({width}x{height}, max_trace_level 5, no anti-aliasing)");
        println!(
            "{:<26} {:>7} {:>8} {:>8} {:>8} {:>10} {:>9}",
            "scene", "threads", "parse", "trace", "wall", "rays", "Mrays/s/core"
        );
        for case in RENDERS {
            let Some(pov) = case.pov else { continue };
            for threads in [1, cores] {
                let mut figures = run_povray(&root.join(pov), &out_dir, width, height, threads)?;
                for _ in 1..RUNS {
                    let again = run_povray(&root.join(pov), &out_dir, width, height, threads)?;
                    if again.trace_seconds < figures.trace_seconds {
                        figures = again;
                    }
                }
                let per_core =
                    figures.rays as f64 / figures.trace_seconds.max(1e-9) / threads as f64 / 1e6;
                println!(
                    "{:<26} {:>7} {:>7.3}s {:>7.3}s {:>7.3}s {:>10} {:>9.2}",
                    case.label,
                    threads,
                    figures.parse_seconds,
                    figures.trace_seconds,
                    figures.wall_seconds,
                    figures.rays,
                    per_core
                );
            }
        }
    } else {
        println!(
            "\n(POV-Ray not installed: `apt-get install povray` adds a side-by-side comparison)"
        );
    }

    println!("\ncompile only (`whitted check`, one core; wall includes process start)");
    println!("{:<34} {:>8} {:>12}", "scene", "wall", "peak memory");
    for case in COMPILES {
        let mut args = vec!["check"];
        for define in case.defines {
            args.extend(["-D", define]);
        }
        let (wall, peak_kib) = measure(&exe, &args, &root.join(case.scene))?;
        let memory = peak_kib.map_or("n/a".to_string(), |k| {
            format!("{:.0} MiB", k as f64 / 1024.0)
        });
        println!("{:<34} {:>7.3}s {:>12}", case.label, wall, memory);
    }
    programs::run(&exe, &out_dir, RUNS)?;
    lsp_latency()
}

/// The language server's latency on the 100,000-statement generated scene
/// (`crates/lsp/examples/latency.rs`, release build): keystroke to diagnostics, hover,
/// semantic tokens and the other whole-document answers.
fn lsp_latency() -> anyhow::Result<()> {
    println!("\nlanguage server on 100,000 generated statements (crates/lsp/examples/latency.rs)");
    run_cargo(&[
        "run",
        "--quiet",
        "--release",
        "--locked",
        "-p",
        "whitted-lsp",
        "--example",
        "latency",
    ])
}

/// Runs the tracer's bench example (`crates/tracer/examples/bench.rs`) with `args`, its BVH
/// walk forced to `path` when given.
fn run_bench_example(args: &[&str], path: Option<&str>) -> anyhow::Result<()> {
    let mut command = vec![
        "run",
        "--quiet",
        "--release",
        "--locked",
        "-p",
        "whitted-tracer",
        "--example",
        "bench",
        "--",
    ];
    command.extend_from_slice(args);
    let env: Vec<(&str, &str)> = path.map(|p| ("WHITTED_TRAVERSAL", p)).into_iter().collect();
    run_cargo_with(&command, &env)
}

/// Writes the scenes the selected cases need under `out_dir` (the sphere mesh once, the
/// dragon fetched when missing) and returns the cases that can run: a dragon that cannot
/// be had is one line saying why its row is skipped, never a failed bench.
fn write_generated<'c>(out_dir: &Path, cases: Vec<&'c Case>) -> anyhow::Result<Vec<&'c Case>> {
    let needs = |what| cases.iter().any(|case| case.generated == Some(what));
    if needs(Generated::Sphere) {
        let started = Instant::now();
        mesh::write(out_dir)?;
        println!(
            "(the 1,000,000-triangle sphere is in {}, written in {:.1}s)",
            out_dir.display(),
            started.elapsed().as_secs_f64()
        );
    }
    let mut dragon_ready = true;
    if needs(Generated::Dragon) {
        if let Err(error) = dragon::prepare(out_dir) {
            println!("(dragon row skipped: {error:#})");
            dragon_ready = false;
        }
    }
    Ok(cases
        .into_iter()
        .filter(|case| dragon_ready || case.generated != Some(Generated::Dragon))
        .collect())
}

/// The command that renders `case` at `size` on `threads` threads into `output`, printing
/// `--stats=json` (the same for the work tree's binary and the base's).
fn render_command(
    exe: &Path,
    case: &Case,
    (width, height): (u32, u32),
    threads: usize,
    output: &Path,
) -> Command {
    let mut command = Command::new(exe);
    command.arg("render").arg(workspace_root().join(case.scene));
    for define in case.defines {
        command.args(["-D", define]);
    }
    command
        .args([
            "--width",
            &width.to_string(),
            "--height",
            &height.to_string(),
        ])
        .args([
            "--max-depth",
            "5",
            "--spp",
            "1",
            "--threads",
            &threads.to_string(),
        ])
        .args(["--stats=json", "--quiet", "-o"])
        .arg(output);
    command
}

/// Runs one render; its stats and wall seconds, or the first line of its error (a base
/// binary may not know a newer scene's syntax: the caller decides what that means).
fn render_once(command: &mut Command, case: &Case) -> Result<(Stats, f64), String> {
    let started = Instant::now();
    let result = command
        .output()
        .map_err(|error| format!("cannot run it: {error}"))?;
    let wall = started.elapsed().as_secs_f64();
    if !result.status.success() {
        let stderr = String::from_utf8_lossy(&result.stderr);
        let first = stderr
            .lines()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("no message");
        return Err(format!("{} failed: {first}", case.scene));
    }
    let stats: Stats = serde_json::from_slice(&result.stdout)
        .map_err(|error| format!("cannot read the stats of {}: {error}", case.scene))?;
    Ok((stats, wall))
}

/// What RUNS renders of one case on one binary and thread count come to.
///
/// The CPU figures come from the run that used the least CPU time, the wall figures (what
/// more threads buy) from the fastest run by the clock, the build time is the least of the
/// runs'; each spread is (most − least) / least over the runs, the noise a change must
/// exceed to be marked.
struct Summary {
    stats: Stats,
    least_cpu: f64,
    cpu_spread: f64,
    best_render: f64,
    best_wall: f64,
    /// Shapes and BVH, seconds.
    least_build: f64,
    build_spread: f64,
    peak_mib: Option<f64>,
    peak_spread: f64,
}

impl Summary {
    fn of(runs: Vec<(Stats, f64)>) -> Option<Summary> {
        let least = |values: &mut dyn Iterator<Item = f64>| values.fold(f64::INFINITY, f64::min);
        let least_cpu = least(&mut runs.iter().map(|(s, _)| s.render_cpu_seconds));
        let cpu_spread = spread(runs.iter().map(|(s, _)| s.render_cpu_seconds));
        let best_render = least(&mut runs.iter().map(|(s, _)| s.render_seconds));
        let best_wall = least(&mut runs.iter().map(|&(_, wall)| wall));
        let least_build = least(&mut runs.iter().map(|(s, _)| s.build_seconds));
        let build_spread = spread(runs.iter().map(|(s, _)| s.build_seconds));
        let peaks: Vec<f64> = runs
            .iter()
            .filter_map(|(s, _)| s.peak_memory_kib)
            .map(|k| k as f64 / 1024.0)
            .collect();
        let peak_spread = spread(peaks.iter().copied());
        let (stats, _) = runs
            .into_iter()
            .min_by(|a, b| a.0.render_cpu_seconds.total_cmp(&b.0.render_cpu_seconds))?;
        let peak_mib = stats.peak_memory_kib.map(|k| k as f64 / 1024.0);
        Some(Summary {
            stats,
            least_cpu,
            cpu_spread,
            best_render,
            best_wall,
            least_build,
            build_spread,
            peak_mib,
            peak_spread,
        })
    }

    fn mrays_per_cpu_second(&self) -> f64 {
        self.stats.total_rays as f64 / self.least_cpu.max(1e-9) / 1e6
    }
}

/// Renders each case RUNS times on one thread and on every core (at least two) and prints
/// the best runs with the spread of the CPU times: the table without a base (`--no-base`,
/// or no base could be built), with every figure the stats give.
///
/// The honest per-core figure is rays per CPU-second of the render threads on one thread:
/// a thread's own CPU clock does not count the time other programs take on a shared
/// machine, where wall time does. Scaling is the best one-thread render time over the best
/// many-thread one (by the clock, since that is what more threads buy, so it means
/// something only on an otherwise idle machine). Peak memory is the process's, scene and
/// image included.
fn render_table(
    exe: &Path,
    out_dir: &Path,
    cases: Vec<&Case>,
    (width, height): (u32, u32),
    cores: usize,
) -> anyhow::Result<()> {
    println!(
        "\nrenders ({width}x{height}, max depth 5, 1 spp; release build; best of {RUNS} runs: \
         render and wall by the clock, cpu = the render threads' CPU time with its spread \
         (most - least) / least, Mray/cpu = rays per CPU-second, scaling = best 1-thread \
         render / best many-thread render; shapes = preparing the shapes for the BVH, bvh = \
         building it, light buffers not counted)"
    );
    println!(
        "{:<30} {:>3} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>6} {:>8} {:>10} {:>8} {:>7} {:>8}",
        "scene",
        "thr",
        "objects",
        "compile",
        "shapes",
        "bvh",
        "render",
        "cpu",
        "spread",
        "wall",
        "rays",
        "Mray/cpu",
        "scaling",
        "peak MiB"
    );
    let mut walk = String::from("none");
    for case in cases {
        let mut one_thread_render = None;
        for threads in [1, cores.max(2)] {
            let output = out_dir.join(format!("{}.png", case.scene.replace(['/', '.'], "_")));
            let mut command = render_command(exe, case, (width, height), threads, &output);
            // Best of RUNS: single-shot timings on a shared machine are noisy, and the
            // fastest run is the one least disturbed by other work; the spread says how
            // noisy they were.
            let mut runs: Vec<(Stats, f64)> = Vec::with_capacity(RUNS);
            for _ in 0..RUNS {
                let run = render_once(&mut command, case).map_err(anyhow::Error::msg)?;
                debug_assert!(
                    run.0.width == width && run.0.height == height && run.0.max_depth == 5
                );
                runs.push(run);
            }
            let Some(summary) = Summary::of(runs) else {
                bail!("no run of {}", case.scene);
            };
            let scaling = match one_thread_render {
                None => {
                    one_thread_render = Some(summary.best_render);
                    String::new()
                }
                Some(one) => format!("{:.2}x", one / summary.best_render.max(1e-9)),
            };
            let peak = summary
                .peak_mib
                .map_or("n/a".to_string(), |m| format!("{m:.0}"));
            let stats = &summary.stats;
            println!(
                "{:<30} {:>3} {:>7} {:>6.3}s {:>6.3}s {:>6.3}s {:>6.3}s {:>6.3}s {:>5.0}% {:>7.3}s {:>10} {:>8.2} {:>7} {:>8}",
                case.label,
                threads,
                stats.objects,
                stats.compile_seconds,
                stats.shapes_seconds,
                stats.build_seconds - stats.shapes_seconds - stats.light_buffer_seconds,
                summary.best_render,
                summary.least_cpu,
                summary.cpu_spread * 100.0,
                summary.best_wall,
                stats.total_rays,
                summary.mrays_per_cpu_second(),
                scaling,
                peak
            );
            walk.clone_from(&stats.bvh_walk);
        }
    }
    println!("(BVH walk: {walk}; `WHITTED_TRAVERSAL=baseline|avx2|avx512` forces one)");
    Ok(())
}

/// The table beside the base (issue 31): each case on one thread and on every core, the
/// work tree's binary and the base's run alternately (new, base, new, base, ...: RUNS each)
/// so that a load that comes and goes on the shared machine falls on both, and each figure
/// printed beside the base's with the change, marked `!` when worse and `*` when better by
/// more than the runs' spread (and 1%; 4 MiB for memory). Rows a regression marks are
/// listed again at the end.
fn comparison_table(
    exe: &Path,
    base: &base::Base,
    out_dir: &Path,
    cases: Vec<&Case>,
    (width, height): (u32, u32),
    cores: usize,
) -> anyhow::Result<()> {
    println!(
        "\nrenders beside the base {} ({width}x{height}, max depth 5, 1 spp; release builds, \
         run alternately, {RUNS} runs each)\n\
         Mray per CPU-second: of the render threads, in the run with the least CPU time; build: \
         shapes + BVH, least of the runs;\n\
         peak: the process's peak memory; change: ! worse, * better, by more than the \
         new and base spreads added (and 1%, and 4 MiB);\n\
         spread: (most - least) / least CPU time, new/base; scale: best 1-thread render / \
         best many-thread render (new)",
        base.short_sha
    );
    println!(
        "{:<32}  {:^22}  {:^22}  {:^22}",
        "", "Mray per CPU-second", "build seconds", "peak MiB"
    );
    println!(
        "{:<28} {:>3}  {:>6} {:>6} {:>7}   {:>6} {:>6} {:>7}   {:>6} {:>6} {:>7}  {:>8} {:>6}",
        "scene",
        "thr",
        "new",
        "base",
        "change",
        "new",
        "base",
        "change",
        "new",
        "base",
        "change",
        "spread",
        "scale"
    );
    let mut regressions = Vec::new();
    let mut base_failures = 0;
    let mut walk = String::from("none");
    for case in cases {
        let mut one_thread_render = None;
        for threads in [1, cores.max(2)] {
            let stem = case.scene.replace(['/', '.'], "_");
            let size = (width, height);
            let mut new_command = render_command(
                exe,
                case,
                size,
                threads,
                &out_dir.join(format!("{stem}.png")),
            );
            let mut base_command = render_command(
                &base.exe,
                case,
                size,
                threads,
                &out_dir.join(format!("{stem}-base.png")),
            );
            let mut new_runs = Vec::with_capacity(RUNS);
            let mut base_runs = Vec::with_capacity(RUNS);
            let mut base_failure = None;
            for _ in 0..RUNS {
                new_runs.push(render_once(&mut new_command, case).map_err(anyhow::Error::msg)?);
                if base_failure.is_none() {
                    match render_once(&mut base_command, case) {
                        Ok(run) => base_runs.push(run),
                        Err(message) => base_failure = Some(message),
                    }
                }
            }
            let Some(new) = Summary::of(new_runs) else {
                bail!("no run of {}", case.scene);
            };
            let old = if base_failure.is_none() {
                Summary::of(base_runs)
            } else {
                None
            };
            let scaling = match one_thread_render {
                None => {
                    one_thread_render = Some(new.best_render);
                    String::new()
                }
                Some(one) => format!("{:.2}x", one / new.best_render.max(1e-9)),
            };
            let or_dash = |value: Option<f64>, decimals: usize| {
                value.map_or("-".to_string(), |v| format!("{v:.decimals$}"))
            };
            let beside = |new: f64, old: Option<f64>, noise: f64, better| match old {
                Some(old) => change(new, old, noise, better),
                None => format!("{:>8}", "-"),
            };
            let rays = beside(
                new.mrays_per_cpu_second(),
                old.as_ref().map(Summary::mrays_per_cpu_second),
                old.as_ref().map_or(0.0, |o| o.cpu_spread + new.cpu_spread),
                Better::Higher,
            );
            // A build of a few hundred objects takes well under a millisecond, where the
            // clock's own jitter is tens of percent (Menger 0.000 s was marked +53%): a
            // build change counts only beyond a few milliseconds.
            let build = beside(
                new.least_build,
                old.as_ref().map(|o| o.least_build),
                old.as_ref().map_or(0.0, |o| {
                    noise(
                        o.build_spread + new.build_spread,
                        BUILD_NOISE_SECONDS,
                        o.least_build,
                    )
                }),
                Better::Lower,
            );
            let peak = match (new.peak_mib, old.as_ref().and_then(|o| o.peak_mib)) {
                // Two binaries of the same source (the work tree's and its HEAD's, built in
                // two folders) peaked at 44-46 and 47 MiB on the dragon, run after run: a
                // few MiB are the process's noise (thread stacks, allocator arenas, the
                // binary's own pages), not a change of the renderer.
                (Some(n), Some(o)) => change(
                    n,
                    o,
                    noise(
                        old.as_ref()
                            .map_or(0.0, |o| o.peak_spread + new.peak_spread),
                        PEAK_NOISE_MIB,
                        o,
                    ),
                    Better::Lower,
                ),
                _ => format!("{:>8}", "-"),
            };
            let spreads = format!(
                "{:.0}/{}%",
                new.cpu_spread * 100.0,
                or_dash(old.as_ref().map(|o| o.cpu_spread * 100.0), 0)
            );
            println!(
                "{:<28} {:>3}  {:>6.2} {:>6} {rays}  {:>6.3} {:>6} {build}  {:>6} {:>6} {peak} {:>8} {:>6}",
                case.label,
                threads,
                new.mrays_per_cpu_second(),
                or_dash(old.as_ref().map(Summary::mrays_per_cpu_second), 2),
                new.least_build,
                or_dash(old.as_ref().map(|o| o.least_build), 3),
                or_dash(new.peak_mib, 0),
                or_dash(old.as_ref().and_then(|o| o.peak_mib), 0),
                spreads,
                scaling
            );
            if let Some(message) = &base_failure {
                println!("  base failed: {message}");
                base_failures += 1;
            }
            let what: Vec<&str> = [(&rays, "Mray/cpu"), (&build, "build"), (&peak, "peak")]
                .into_iter()
                .filter(|(c, _)| is_regression(c))
                .map(|(_, name)| name)
                .collect();
            if !what.is_empty() {
                regressions.push(format!(
                    "{} on {threads} thread{}: {}",
                    case.label,
                    if threads == 1 { "" } else { "s" },
                    what.join(", ")
                ));
            }
            walk.clone_from(&new.stats.bvh_walk);
        }
    }
    println!("(BVH walk: {walk}; `WHITTED_TRAVERSAL=baseline|avx2|avx512` forces one)");
    if base_failures > 0 {
        println!("the base failed on {base_failures} row(s): those have nothing to compare");
    }
    if regressions.is_empty() {
        println!("no figure is worse than the base's by more than its runs' spread");
    } else {
        println!("WORSE than the base by more than the runs' spread:");
        for line in regressions {
            println!("  {line}");
        }
    }
    Ok(())
}

/// Wall seconds and, where /usr/bin/time exists, peak resident KiB of one `whitted ARGS SCENE`
/// run (the compile table here and the table of scenes written by programs).
pub(super) fn measure(
    exe: &Path,
    args: &[&str],
    scene: &Path,
) -> anyhow::Result<(f64, Option<u64>)> {
    let gnu_time = Path::new("/usr/bin/time");
    let mut command = if gnu_time.exists() {
        let mut c = Command::new(gnu_time);
        c.args(["-f", "%M"]).arg(exe);
        c
    } else {
        Command::new(exe)
    };
    command.args(args).arg(scene);
    let started = Instant::now();
    let result = command.output()?;
    let wall = started.elapsed().as_secs_f64();
    if !result.status.success() {
        bail!(
            "whitted {} {} failed:\n{}",
            args.join(" "),
            scene.display(),
            String::from_utf8_lossy(&result.stderr)
        );
    }
    let peak = String::from_utf8_lossy(&result.stderr)
        .lines()
        .last()
        .and_then(|line| line.trim().parse::<u64>().ok());
    Ok((wall, peak))
}

const POVRAY: &str = "/usr/bin/povray";

/// Peak-memory changes this small (MiB) are never marked: see `comparison_table`.
const PEAK_NOISE_MIB: f64 = 4.0;

/// Build times closer than this are the clock's jitter, not a change (see the table).
const BUILD_NOISE_SECONDS: f64 = 0.005;

/// Each render is run this many times and the fastest run reported, for whitted and POV-Ray alike.
const RUNS: usize = 3;

/// What POV-Ray reports about one render.
struct PovFigures {
    parse_seconds: f64,
    trace_seconds: f64,
    wall_seconds: f64,
    /// Camera, reflected and refracted rays plus shadow-ray tests: the same rays whitted counts.
    rays: u64,
}

fn run_povray(
    scene: &Path,
    out_dir: &Path,
    width: u32,
    height: u32,
    threads: usize,
) -> anyhow::Result<PovFigures> {
    let started = Instant::now();
    let output = Command::new(POVRAY)
        .arg(format!("+I{}", scene.display()))
        .arg(format!("+O{}", out_dir.join("povray.png").display()))
        .args([
            format!("+W{width}"),
            format!("+H{height}"),
            format!("+WT{threads}"),
        ])
        .args(["-A", "+FN", "-D", "-P", "+V"])
        .output()
        .context("cannot run povray")?;
    let wall_seconds = started.elapsed().as_secs_f64();
    let log = String::from_utf8_lossy(&output.stderr).into_owned();
    if !output.status.success() {
        bail!("povray failed on {}:\n{log}", scene.display());
    }
    // "Parse Time:  0 hours  0 minutes  5 seconds (5.123 seconds)" and likewise "Trace Time:".
    let seconds_after = |label: &str| -> f64 {
        log.lines()
            .find(|l| l.trim_start().starts_with(label))
            .and_then(|l| l.rsplit('(').next())
            .and_then(|l| l.split_whitespace().next())
            .and_then(|n| n.parse().ok())
            .unwrap_or(0.0)
    };
    // "Rays:  643263  Saved: ..." and "Shadow Ray Tests:  452395  Succeeded: ...".
    let count_after = |label: &str| -> u64 {
        log.lines()
            .find(|l| l.trim_start().starts_with(label))
            .and_then(|l| l.split(':').nth(1))
            .and_then(|l| l.split_whitespace().next())
            .and_then(|n| n.parse().ok())
            .unwrap_or(0)
    };
    Ok(PovFigures {
        parse_seconds: seconds_after("Parse Time:"),
        trace_seconds: seconds_after("Trace Time:"),
        wall_seconds,
        rays: count_after("Rays:") + count_after("Shadow Ray Tests:"),
    })
}
