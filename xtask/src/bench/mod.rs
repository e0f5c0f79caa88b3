//! `cargo xtask bench`: builds the release binary and times the benchmark scenes.
//!
//! Prints figures; asserts nothing about time (machines are noisy and shared). Each render
//! runs with one thread (the honest per-core figure) and with every core.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use anyhow::{bail, Context};
use serde::Deserialize;

use crate::{run_cargo, run_cargo_with, workspace_root};

mod mesh;
mod programs;

/// One benchmark render: a scene, its `-D` overrides and what to print it as.
struct Case {
    label: &'static str,
    /// Relative to the workspace root.
    scene: &'static str,
    defines: &'static [&'static str],
    /// The equivalent POV-Ray scene, for a side-by-side figure when `povray` is installed.
    pov: Option<&'static str>,
}

const RENDERS: &[Case] = &[
    Case {
        label: "classic (Whitted 1980)",
        scene: "scenes/bench/classic.scene",
        defines: &[],
        pov: Some("scenes/bench/pov/classic.pov"),
    },
    Case {
        label: "1,000 spheres",
        scene: "scenes/bench/spheres1000.scene",
        defines: &[],
        pov: Some("scenes/bench/pov/spheres1000.pov"),
    },
    Case {
        label: "grid 10,000 spheres",
        scene: "scenes/bench/grid.scene",
        defines: &["N=100"],
        pov: None,
    },
    Case {
        label: "grid 1,000,000 spheres",
        scene: "scenes/bench/grid.scene",
        defines: &["N=1000"],
        pov: Some("scenes/bench/pov/grid.pov"),
    },
    Case {
        label: "mesh 1,000,000 triangles",
        // Written by `mesh::write` before the renders.
        scene: "target/bench/mesh1m.scene",
        defines: &[],
        pov: None,
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
    },
    Case {
        label: "group of the same spheres",
        scene: "scenes/bench/union10k.scene",
        defines: &["UNION=0"],
        pov: None,
    },
    Case {
        label: "Menger sponge, level 3",
        scene: "scenes/bench/menger.scene",
        defines: &[],
        pov: None,
    },
    Case {
        label: "1,000 box-and-plane crystals",
        scene: "scenes/bench/crystals.scene",
        defines: &[],
        pov: None,
    },
];

const COMPILES: &[Case] = &[
    Case {
        label: "grid N=316 (99,856 spheres)",
        scene: "scenes/bench/grid.scene",
        defines: &["N=316"],
        pov: None,
    },
    Case {
        label: "grid N=1000 (1,000,000 spheres)",
        scene: "scenes/bench/grid.scene",
        defines: &["N=1000"],
        pov: None,
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
    /// The part of `build_seconds` that prepared the shapes; the rest built the BVH.
    shapes_seconds: f64,
    render_seconds: f64,
    /// The render threads' own CPU time, summed (`CLOCK_THREAD_CPUTIME_ID`).
    render_cpu_seconds: f64,
    total_rays: u64,
    peak_memory_kib: Option<u64>,
    /// The BVH walk's child test the binary chose (`baseline`, `avx2`, `avx512`).
    bvh_walk: String,
}

pub fn run(args: &[String]) -> anyhow::Result<()> {
    let mut width = 640;
    let mut height = 480;
    let mut only_programs = false;
    let mut only_mesh = false;
    let mut only_csg = false;
    let mut iter = args.iter();
    while let Some(arg) = iter.next() {
        match arg.as_str() {
            "--size" => {
                let value = iter.next().context("--size needs WxH")?;
                let (w, h) = value
                    .split_once('x')
                    .context("--size needs WxH, e.g. 320x240")?;
                width = w.parse().context("bad width")?;
                height = h.parse().context("bad height")?;
            }
            "--programs" => only_programs = true,
            "--mesh" => only_mesh = true,
            "--csg" => only_csg = true,
            "--lsp" => return lsp_latency(),
            other => {
                bail!(
                    "unknown bench option `{other}` (known: --size WxH, --programs, --mesh, --csg, --lsp)"
                )
            }
        }
    }
    run_cargo(&["build", "--release", "--locked", "--bin", "whitted"])?;
    let root = workspace_root();
    let exe = root.join("target/release/whitted");
    let out_dir = root.join("target/bench");
    std::fs::create_dir_all(&out_dir)?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if only_programs {
        return programs::run(&exe, &out_dir, RUNS);
    }
    if only_csg {
        return render_table(&exe, &out_dir, CSG_RENDERS, width, height, cores);
    }
    let started = Instant::now();
    mesh::write(&out_dir)?;
    println!(
        "(the 1,000,000-triangle mesh is in {}, written in {:.1}s)",
        out_dir.display(),
        started.elapsed().as_secs_f64()
    );
    let renders: Vec<&Case> = RENDERS
        .iter()
        .chain(CSG_RENDERS)
        .filter(|case| !only_mesh || case.scene.ends_with("mesh1m.scene"))
        .collect();
    render_table(&exe, &out_dir, renders, width, height, cores)?;
    if only_mesh {
        return Ok(());
    }

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

/// Renders each case RUNS times on one thread and on every core (at least two) and prints
/// the best runs with the spread of the CPU times.
///
/// The honest per-core figure is rays per CPU-second of the render threads on one thread:
/// a thread's own CPU clock does not count the time other programs take on a shared
/// machine, where wall time does. Scaling is the best one-thread render time over the best
/// many-thread one (by the clock, since that is what more threads buy, so it means
/// something only on an otherwise idle machine). Peak memory is the process's, scene and
/// image included.
fn render_table<'c>(
    exe: &Path,
    out_dir: &Path,
    cases: impl IntoIterator<Item = &'c Case>,
    width: u32,
    height: u32,
    cores: usize,
) -> anyhow::Result<()> {
    let root = workspace_root();
    println!(
        "\nrenders ({width}x{height}, max depth 5, 1 spp; release build; best of {RUNS} runs: \
         render and wall by the clock, cpu = the render threads' CPU time with its spread \
         (most - least) / least, Mray/cpu = rays per CPU-second, scaling = best 1-thread \
         render / best many-thread render; shapes = preparing the shapes for the BVH, bvh = \
         building it)"
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
            let mut command = Command::new(exe);
            command.arg("render").arg(root.join(case.scene));
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
                .arg(&output);
            // Best of RUNS: single-shot timings on a shared machine are noisy, and the
            // fastest run is the one least disturbed by other work; the spread says how
            // noisy they were.
            let mut runs: Vec<(Stats, f64)> = Vec::with_capacity(RUNS);
            for _ in 0..RUNS {
                let started = Instant::now();
                let result = command
                    .output()
                    .with_context(|| format!("cannot run {}", exe.display()))?;
                let wall = started.elapsed().as_secs_f64();
                if !result.status.success() {
                    bail!(
                        "{} failed:\n{}",
                        case.scene,
                        String::from_utf8_lossy(&result.stderr)
                    );
                }
                let stats: Stats = serde_json::from_slice(&result.stdout)
                    .with_context(|| format!("cannot read the stats of {}", case.scene))?;
                debug_assert!(
                    stats.width == width && stats.height == height && stats.max_depth == 5
                );
                runs.push((stats, wall));
            }
            // The CPU figures come from the run that used the least CPU time, the wall
            // figures (what more threads buy) from the fastest run by the clock.
            let cpu: Vec<f64> = runs.iter().map(|(s, _)| s.render_cpu_seconds).collect();
            let least_cpu = cpu.iter().copied().fold(f64::INFINITY, f64::min);
            let most_cpu = cpu.iter().copied().fold(0.0, f64::max);
            let spread = (most_cpu - least_cpu) / least_cpu.max(1e-9);
            let best_render = runs
                .iter()
                .map(|(s, _)| s.render_seconds)
                .fold(f64::INFINITY, f64::min);
            let best_wall = runs
                .iter()
                .map(|&(_, wall)| wall)
                .fold(f64::INFINITY, f64::min);
            let Some((stats, _)) = runs
                .into_iter()
                .min_by(|a, b| a.0.render_cpu_seconds.total_cmp(&b.0.render_cpu_seconds))
            else {
                bail!("no run of {}", case.scene);
            };
            let per_cpu = stats.total_rays as f64 / least_cpu.max(1e-9) / 1e6;
            let scaling = match one_thread_render {
                None => {
                    one_thread_render = Some(best_render);
                    String::new()
                }
                Some(one) => format!("{:.2}x", one / best_render.max(1e-9)),
            };
            let peak = stats
                .peak_memory_kib
                .map_or("n/a".to_string(), |k| format!("{:.0}", k as f64 / 1024.0));
            println!(
                "{:<30} {:>3} {:>7} {:>6.3}s {:>6.3}s {:>6.3}s {:>6.3}s {:>6.3}s {:>5.0}% {:>7.3}s {:>10} {:>8.2} {:>7} {:>8}",
                case.label,
                threads,
                stats.objects,
                stats.compile_seconds,
                stats.shapes_seconds,
                stats.build_seconds - stats.shapes_seconds,
                best_render,
                least_cpu,
                spread * 100.0,
                best_wall,
                stats.total_rays,
                per_cpu,
                scaling,
                peak
            );
            walk = stats.bvh_walk;
        }
    }
    println!("(BVH walk: {walk}; `WHITTED_TRAVERSAL=baseline|avx2|avx512` forces one)");
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
