//! Speed figures for the tracer alone (no scene language): builds the benchmark scenes in
//! Rust (the same scenes as `scenes/bench/`), renders them at 640×480, depth 5, on one
//! thread and on all threads, and prints rays, seconds and Mrays/s.
//!
//! `cargo run --release -p whitted-tracer --example bench [-- WHICH [GRID_N]]` where WHICH is
//! `whitted`, `spheres`, `grid` or `all` (the default), and GRID_N defaults to 1000.
//!
//! `WHITTED_TRAVERSAL=baseline` (or `avx2`, `avx512`) forces the BVH walk's child test, to
//! compare the paths; by default the fastest the CPU runs is used.
//!
//! Besides the best wall time it prints rays per CPU-second (process CPU time over at least
//! a second of repeated renders), which stays honest when other work shares the machine.
// A program, not a library: it prints its results and sets its exit status.
#![allow(clippy::print_stdout, clippy::print_stderr, clippy::exit)]

use std::time::Instant;

use whitted_tracer::testing::{reflective_spheres, sphere_grid, whitted_classic, SceneBuilder};
use whitted_tracer::{
    force_traversal_path, render, NoObserver, PreparedScene, RenderOptions, RenderStats,
    TraversalPath,
};

fn options(scene: &PreparedScene) -> RenderOptions {
    let mut options = RenderOptions::from_settings(scene.settings());
    options.width = 640;
    options.height = 480;
    options.samples_per_pixel = 1;
    options.max_depth = 5;
    options
}

/// CPU seconds used by this process so far (all threads), from /proc/self/stat; `None`
/// where that file does not exist.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command name, which is in parentheses and may hold spaces.
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let user: f64 = fields.get(11)?.parse().ok()?;
    let system: f64 = fields.get(12)?.parse().ok()?;
    Some((user + system) / 100.0)
}

struct Measured {
    stats: RenderStats,
    /// CPU seconds per render, averaged over all runs.
    cpu: Option<f64>,
}

fn run(scene: &PreparedScene, threads: usize) -> Result<Measured, Box<dyn std::error::Error>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let options = options(scene);
    // Repeat for at least a second so that CPU time (counted in 10 ms ticks) is precise;
    // keep the best wall time.
    let mut best: Option<RenderStats> = None;
    let cpu_start = cpu_seconds();
    let started = Instant::now();
    let mut runs = 0u32;
    while runs < 3 || started.elapsed().as_secs_f64() < 1.0 {
        let (_, stats) = pool
            .install(|| render(scene, &options, &NoObserver))
            .ok_or("cancelled")?;
        runs += 1;
        if best
            .as_ref()
            .is_none_or(|b| stats.render_seconds < b.render_seconds)
        {
            best = Some(stats);
        }
    }
    let cpu = match (cpu_start, cpu_seconds()) {
        (Some(a), Some(b)) => Some((b - a) / f64::from(runs)),
        _ => None,
    };
    Ok(Measured {
        stats: best.ok_or("no run")?,
        cpu,
    })
}

fn report(name: &str, scene: &PreparedScene) -> Result<(), Box<dyn std::error::Error>> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    for threads in [1, cores] {
        let Measured { stats, cpu } = run(scene, threads)?;
        let rays = stats.total_rays() as f64;
        let wall = stats.render_seconds;
        let per_cpu = cpu.map_or_else(|| "n/a".to_string(), |c| format!("{:.1}", rays / c / 1e6));
        println!(
            "{name:<22} 640x480 d5 threads {threads}: {} rays (camera {}, shadow {}, reflected {}, transmitted {}); best wall {wall:.4} s = {:.1} Mrays/s = {:.1} Mrays/s/core; {per_cpu} Mrays per CPU-second",
            stats.total_rays(),
            stats.camera_rays,
            stats.shadow_rays,
            stats.reflected_rays,
            stats.transmitted_rays,
            rays / wall / 1e6,
            rays / wall / 1e6 / threads as f64,
        );
    }
    Ok(())
}

fn prepare(builder: SceneBuilder) -> Result<(PreparedScene, f64), Box<dyn std::error::Error>> {
    let started = Instant::now();
    let scene = builder.prepare()?;
    Ok((scene, started.elapsed().as_secs_f64()))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let which = std::env::args().nth(1).unwrap_or_else(|| "all".to_string());
    let grid_n: u32 = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000);
    let wanted = |name: &str| which == "all" || which == name;
    // Unset or empty: the fastest path, as for the `whitted` binary.
    if let Some(name) = std::env::var("WHITTED_TRAVERSAL")
        .ok()
        .filter(|n| !n.is_empty())
    {
        let path = TraversalPath::from_name(&name).ok_or_else(|| {
            let names = TraversalPath::ALL.map(TraversalPath::name).join(", ");
            format!("WHITTED_TRAVERSAL={name:?} names no BVH walk; use one of {names}")
        })?;
        if let Err(unavailable) = force_traversal_path(Some(path)) {
            println!("BVH walk {name}: skipped, {unavailable}");
            return Ok(());
        }
    }
    println!("BVH walk: {}", TraversalPath::chosen().name());

    if wanted("whitted") {
        let (whitted, _) = prepare(whitted_classic())?;
        report("classic (whitted)", &whitted)?;
    }
    if wanted("spheres") {
        let (spheres, _) = prepare(reflective_spheres())?;
        report("1000 spheres (lattice)", &spheres)?;
    }
    if !wanted("grid") {
        return Ok(());
    }
    // The grid: building the IR in Rust stands in for the compiler; then validation,
    // preparation and the BVH, then one render on all cores, timed end to end.
    let ir_started = Instant::now();
    let builder = sphere_grid(grid_n);
    let ir_seconds = ir_started.elapsed().as_secs_f64();
    let total_started = Instant::now();
    let (grid, prepare_seconds) = prepare(builder)?;
    let options = options(&grid);
    let (_, stats) = render(&grid, &options, &NoObserver).ok_or("cancelled")?;
    let total = total_started.elapsed().as_secs_f64();
    println!(
        "grid {n}x{n} ({count} spheres, {nodes} BVH nodes): IR built in Rust {ir_seconds:.3} s; validate + prepare + BVH {prepare_seconds:.3} s (PreparedScene::new {:.3} s); render {:.3} s ({} rays, {} threads); prepare + render {total:.3} s",
        grid.build_seconds(),
        stats.render_seconds,
        stats.total_rays(),
        stats.threads,
        n = grid_n,
        count = u64::from(grid_n) * u64::from(grid_n),
        nodes = grid.bvh_node_count(),
    );
    // The steady-state figures too, as for the other scenes.
    report(&format!("grid N={grid_n}"), &grid)?;
    Ok(())
}
