//! The BVH walk's child test has a baseline (SSE2) path and AVX2 and AVX-512 paths chosen
//! at run time: every golden scene and the benchmark scenes must render bit for bit the same
//! on each path this CPU runs, on one thread and on several; the binary reports and honours
//! a forced path, and runs with the same image on older CPUs emulated by qemu.

use std::process::Command;

use whitted_tracer::{
    force_traversal_path, render, NoObserver, PreparedScene, RenderOptions, TraversalPath,
};

use crate::ray_trees::load;

/// The scenes of `tests/golden/manifest.toml`, and the benchmark scenes that need no `-D`.
fn scene_paths() -> Vec<String> {
    let manifest = std::fs::read_to_string("tests/golden/manifest.toml")
        .unwrap_or_else(|e| panic!("tests/golden/manifest.toml: {e}"));
    let mut paths: Vec<String> = manifest
        .lines()
        .filter_map(|line| line.strip_prefix("path = \""))
        .filter_map(|rest| rest.strip_suffix('"'))
        .map(str::to_string)
        .collect();
    assert!(
        paths.len() > 20,
        "the manifest lists {} scenes",
        paths.len()
    );
    paths.extend(
        [
            "classic",
            "spheres1000",
            "grid",
            "menger",
            "union10k",
            "crystals",
        ]
        .map(|name| format!("scenes/bench/{name}.scene")),
    );
    paths
}

/// The image's pixels as bits, rendered with `path` on `threads` threads.
fn render_bits(
    scene: &whitted_ir::ValidScene,
    path: TraversalPath,
    threads: usize,
) -> Vec<[u32; 3]> {
    // A BVH keeps the path it was built with, so prepare the scene again under the forced
    // one. (Other tests building BVHs meanwhile get it too, which cannot change their
    // results: that is what this test checks.)
    force_traversal_path(Some(path)).unwrap_or_else(|e| panic!("{e}"));
    let prepared = PreparedScene::new(scene);
    force_traversal_path(None).unwrap_or_else(|e| panic!("{e}"));
    image_bits(&prepared, scene, threads)
}

/// The pixels as bits of `prepared` (made from `scene`) rendered at 96x72 on `threads`
/// threads.
fn image_bits(
    prepared: &PreparedScene,
    scene: &whitted_ir::ValidScene,
    threads: usize,
) -> Vec<[u32; 3]> {
    let options = RenderOptions {
        width: 96,
        height: 72,
        ..RenderOptions::from_settings(&scene.settings)
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap_or_else(|e| panic!("no pool: {e}"));
    let (image, _) = pool
        .install(|| render(prepared, &options, &NoObserver))
        .unwrap_or_else(|| panic!("cancelled"));
    image.pixels.iter().map(|p| p.map(f32::to_bits)).collect()
}

#[test]
fn every_traversal_path_renders_the_same_bits() {
    let paths: Vec<TraversalPath> = TraversalPath::ALL
        .into_iter()
        .filter(|p| p.available())
        .collect();
    if paths.len() == 1 {
        eprintln!("SKIPPED: this CPU runs only the baseline BVH walk");
        return;
    }
    for scene in scene_paths() {
        let loaded = load(&scene);
        let baseline = render_bits(&loaded.scene, TraversalPath::Baseline, 1);
        for &path in &paths {
            for threads in [1, 3] {
                if (path, threads) == (TraversalPath::Baseline, 1) {
                    continue;
                }
                let image = render_bits(&loaded.scene, path, threads);
                let differing = baseline.iter().zip(&image).filter(|(a, b)| a != b).count();
                assert!(
                    differing == 0 && image.len() == baseline.len(),
                    "{scene}: {differing} pixels differ between the baseline walk on one \
                     thread and the {} walk on {threads}",
                    path.name()
                );
            }
        }
    }
}

/// `whitted render` with `WHITTED_TRAVERSAL` set to `value` (unset when `None`), of the
/// 1,000 spheres: its exit code, its stdout (the text stats) and stderr, and the PNG's
/// bytes (empty when none was written).
fn render_with_env(value: Option<&str>, png: &std::path::Path) -> (i32, String, String, Vec<u8>) {
    render_scene_with_env(
        "scenes/bench/spheres1000.scene",
        ("WHITTED_TRAVERSAL", value),
        png,
    )
}

/// [`render_with_env`] of `scene` with `variable` set to `value` (unset when `None`).
fn render_scene_with_env(
    scene: &str,
    (variable, value): (&str, Option<&str>),
    png: &std::path::Path,
) -> (i32, String, String, Vec<u8>) {
    let mut command = Command::new(env!("CARGO_BIN_EXE_whitted"));
    command
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["render", scene, "--stats", "-o"])
        .arg(png)
        .env_remove(variable);
    if let Some(value) = value {
        command.env(variable, value);
    }
    let output = command.output().unwrap_or_else(|e| panic!("whitted: {e}"));
    let bytes = std::fs::read(png).unwrap_or_default();
    (
        output.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&output.stdout).into_owned(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
        bytes,
    )
}

/// The binary says which walk it used, honours a forced one with the same image, and
/// refuses a name that is no walk (or one this CPU cannot run) with a message naming the
/// variable.
#[test]
fn the_binary_reports_and_honours_a_forced_walk() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let (code, stats, _, default_png) = render_with_env(None, &dir.path().join("default.png"));
    assert_eq!(code, 0);
    let fastest = TraversalPath::fastest().name();
    assert!(
        stats.contains(&format!("bvh walk         {fastest}\n")),
        "{stats}"
    );
    for path in TraversalPath::ALL {
        let png = dir.path().join(format!("{}.png", path.name()));
        let (code, stats, stderr, bytes) = render_with_env(Some(path.name()), &png);
        if path.available() {
            assert_eq!(code, 0, "{stderr}");
            assert!(stats.contains(&format!("bvh walk         {}\n", path.name())));
            assert!(bytes == default_png, "{}: the image differs", path.name());
        } else {
            assert_eq!(code, 1);
            assert!(stderr.contains("WHITTED_TRAVERSAL=") && stderr.contains("cannot run"));
        }
    }
    let (code, _, stderr, _) = render_with_env(Some("sse9"), &dir.path().join("bad.png"));
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("WHITTED_TRAVERSAL=\"sse9\" names no BVH walk")
            && stderr.contains("baseline, avx2, avx512"),
        "{stderr}"
    );
    assert!(!dir.path().join("bad.png").exists());
    // Empty is unset: the fastest walk.
    let (code, stats, _, _) = render_with_env(Some(""), &dir.path().join("empty.png"));
    assert_eq!(code, 0);
    assert!(
        stats.contains(&format!("bvh walk         {fastest}\n")),
        "{stats}"
    );
}

/// The one binary runs on a CPU without AVX, and on one with AVX2 but not AVX-512: under
/// qemu's user-mode emulation of an older CPU (Nehalem: SSE4.2, no AVX; Haswell: AVX2) it
/// picks the baseline and the AVX2 walk, renders the same bytes as natively, and refuses a
/// forced walk the emulated CPU lacks. Skipped with a message where qemu-x86_64 is not
/// installed (`.ci/run` installs it).
#[test]
fn the_binary_runs_on_older_cpus_with_the_same_image() {
    let qemu = "qemu-x86_64";
    if Command::new(qemu).arg("--version").output().is_err() {
        eprintln!("SKIPPED: {qemu} is not installed (apt-get install qemu-user)");
        return;
    }
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let exe = env!("CARGO_BIN_EXE_whitted");
    let render = |cpu: Option<&str>, force: Option<&str>, name: &str| {
        let png = dir.path().join(name);
        let mut command = match cpu {
            Some(cpu) => {
                let mut command = Command::new(qemu);
                command.args(["-cpu", cpu, exe]);
                command
            }
            None => Command::new(exe),
        };
        command
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(["render", "scenes/bench/spheres1000.scene", "--width", "64"])
            .args(["--height", "48", "--stats", "-o"])
            .arg(&png)
            .env_remove("WHITTED_TRAVERSAL");
        if let Some(force) = force {
            command.env("WHITTED_TRAVERSAL", force);
        }
        let output = command.output().unwrap_or_else(|e| panic!("{e}"));
        let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
        let bytes = std::fs::read(&png).unwrap_or_default();
        (output.status.code(), stdout, stderr, bytes)
    };
    let (code, _, stderr, native) = render(None, None, "native.png");
    assert_eq!(code, Some(0), "{stderr}");
    for (cpu, walk) in [("Nehalem", "baseline"), ("Haswell", "avx2")] {
        let (code, stats, stderr, bytes) = render(Some(cpu), None, &format!("{cpu}.png"));
        assert_eq!(code, Some(0), "{cpu}: {stderr}");
        assert!(
            stats.contains(&format!("bvh walk         {walk}\n")),
            "{cpu}: {stats}"
        );
        assert!(
            bytes == native,
            "{cpu}: the image differs from the native one"
        );
    }
    let (code, _, stderr, _) = render(Some("Nehalem"), Some("avx2"), "forced.png");
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("WHITTED_TRAVERSAL=avx2: this CPU cannot run the avx2 BVH traversal"),
        "{stderr}"
    );
    assert!(!dir.path().join("forced.png").exists());
}

/// Opaque shadow rays are answered from their lights' light buffers when the scene has
/// them: every golden and benchmark scene renders the same bits with them and
/// with every shadow ray walking the BVH.
#[test]
fn light_buffers_render_the_same_bits_as_walking_every_shadow_ray() {
    let mut buffered_scenes = 0;
    for scene in scene_paths() {
        let loaded = load(&scene).scene;
        let prepared = PreparedScene::new(&loaded);
        buffered_scenes += usize::from(prepared.light_buffer_sizes().0 > 0);
        let with_buffers = image_bits(&prepared, &loaded, 2);
        let walked = image_bits(&prepared.without_light_buffers(), &loaded, 2);
        assert!(
            with_buffers == walked,
            "{scene}: light buffers changed the image"
        );
    }
    assert!(
        buffered_scenes >= 5,
        "only {buffered_scenes} scenes had light buffers"
    );
}

/// `render --stats` says which lights have light buffers; `WHITTED_LIGHT_BUFFERS=off`
/// turns them off with the same image, and a value that is neither on nor off is refused
/// with a message naming the variable, before anything is written.
/// The seconds of `render --stats`'s "bvh build" line: the whole build, then its parts.
fn build_parts(stats: &str) -> Vec<f64> {
    let line = stats
        .lines()
        .find(|line| line.starts_with("bvh build"))
        .unwrap_or_default();
    line.split([' ', '(', ')', ','])
        .filter_map(|word| word.parse().ok())
        .collect()
}

#[test]
fn the_binary_reports_and_switches_light_buffers() {
    let dir = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let run = |value: Option<&str>, name: &str| {
        render_scene_with_env(
            "scenes/bench/grid.scene",
            ("WHITTED_LIGHT_BUFFERS", value),
            &dir.path().join(name),
        )
    };
    let (code, stats, stderr, on) = run(None, "on.png");
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stats.contains("light buffers    2 of 2 lights, "),
        "{stats}"
    );
    // The build's parts add up: shapes, tree and light buffers.
    let [build, shapes, tree, buffers] = build_parts(&stats)[..] else {
        panic!("no build line with its light buffers: {stats}");
    };
    assert!(
        buffers > 0.0 && (shapes + tree + buffers - build).abs() <= 0.002,
        "{stats}"
    );
    let (code, stats, stderr, off) = run(Some("off"), "off.png");
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stats.contains("light buffers    none (every shadow ray walks the BVH)\n"),
        "{stats}"
    );
    assert_eq!(build_parts(&stats).len(), 3, "{stats}");
    assert!(!on.is_empty() && on == off, "the images differ");
    let (code, _, stderr, bad) = run(Some("maybe"), "bad.png");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("WHITTED_LIGHT_BUFFERS=\"maybe\": use on or off"),
        "{stderr}"
    );
    assert!(bad.is_empty());
}
