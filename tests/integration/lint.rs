//! The scene linter (`whitted check`'s warnings, docs/explain.md "Lints"): each lint fires on
//! its scene in tests/lint/ with the right kind, location and fix, every shipped scene stays
//! quiet, and `--no-lint` silences them.

use std::path::PathBuf;
use std::process::{Command, Output};

use whitted_explain::lint::{lint, Lint, LintKind};

use crate::ray_trees::load;

fn check(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")))
        .env("NO_COLOR", "1")
        .arg("check")
        .args(args)
        .output()
        .expect("the whitted binary runs")
}

fn lints_of(path: &str) -> (Vec<Lint>, whitted_ir::ValidScene) {
    let loaded = load(path);
    (lint(&loaded.prepared, &loaded.scene), loaded.scene)
}

/// Issue 27: after `--width 10 --height 8` a lint named a pixel of the scene's own 40x30,
/// which `trace` at that size then refused. The pixel is in the image being made, and
/// tracing it at that size shows the cut the warning is about.
#[test]
fn lint_pixels_are_pixels_of_the_image_being_rendered() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("small.png");
    let render = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")))
        .env("NO_COLOR", "1")
        .args([
            "render",
            "tests/lint/max-depth.scene",
            "--width",
            "10",
            "--height",
            "8",
        ])
        .arg("-o")
        .arg(&out)
        .output()
        .expect("the whitted binary runs");
    let stderr = String::from_utf8_lossy(&render.stderr);
    let at = stderr
        .split("at pixel (")
        .nth(1)
        .unwrap_or_else(|| panic!("{stderr}"));
    let (x, rest) = at.split_once(", ").expect("x, y");
    let y = rest.split(')').next().expect("y)");
    let (x, y): (u32, u32) = (x.parse().expect("x"), y.parse().expect("y"));
    assert!(
        x < 10 && y < 8,
        "pixel ({x}, {y}) is outside the 10x8 image"
    );
    let trace = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")))
        .args([
            "trace",
            "tests/lint/max-depth.scene",
            "--width",
            "10",
            "--height",
            "8",
        ])
        .arg("--pixel")
        .arg(format!("{x},{y}"))
        .output()
        .expect("the whitted binary runs");
    assert!(
        trace.status.success(),
        "{}",
        String::from_utf8_lossy(&trace.stderr)
    );
    assert!(
        String::from_utf8_lossy(&trace.stdout).contains("(max depth)"),
        "the traced pixel shows no depth cut"
    );
}

#[test]
fn each_lint_fires_on_its_scene_with_its_location_and_fix() {
    // (scene, kind, where the warning points, words its fix must contain, how many)
    let cases: [(&str, LintKind, &str, &str, usize); 10] = [
        (
            "tests/lint/nothing-to-see.scene",
            LintKind::NothingToSee,
            "tests/lint/nothing-to-see.scene:5:1",
            "add a light",
            1,
        ),
        (
            "tests/lint/coincident-thin.scene",
            LintKind::CoincidentSurfaces,
            "tests/lint/coincident-thin.scene:9:1",
            "move disk \"coaster\" off box \"table\" by more than a hair",
            1,
        ),
        (
            "tests/lint/light-inside-solid.scene",
            LintKind::LightInsideSolid,
            "tests/lint/light-inside-solid.scene:6:1",
            "move light \"lamp\" out of sphere \"shade\"",
            1,
        ),
        (
            "tests/lint/coincident.scene",
            LintKind::CoincidentSurfaces,
            "tests/lint/coincident.scene:5:1",
            "move box \"wall\" off box \"poster\" by more than a hair",
            1,
        ),
        (
            "tests/lint/max-depth.scene",
            LintKind::MaxDepthTooLow,
            "tests/lint/max-depth.scene:6:1",
            "raise max_depth to 2 (`max_depth 2` in the settings, or --set max_depth=2)",
            1,
        ),
        (
            "tests/lint/material-gain.txt",
            LintKind::MaterialGain,
            "tests/lint/material-gain.txt:18:5",
            "lower reflective or transmissive so that they sum to 1 at most",
            1,
        ),
        (
            "tests/lint/unseen.scene",
            LintKind::UnseenObject,
            "tests/lint/unseen.scene:6:1",
            "so that it is in view, or remove it",
            2,
        ),
        (
            "tests/lint/facing-away.scene",
            LintKind::FacingAwayFromLights,
            "tests/lint/facing-away.scene:6:1",
            "move a light to the camera's side of plane \"floor\"",
            2,
        ),
        (
            "tests/lint/facing-away.scene",
            LintKind::FacingAwayFromLights,
            "tests/lint/facing-away.scene:7:1",
            "turn the triangle around (swap two of its corners), or set `shade_back on`",
            2,
        ),
        (
            "tests/lint/ray-budget.scene",
            LintKind::RayBudget,
            "tests/lint/ray-budget.scene:3:44",
            "raise min_weight (0.001 is usual) so that weak paths end, or lower max_depth to 12",
            1,
        ),
    ];
    for (path, kind, location, fix, count) in cases {
        let (lints, scene) = lints_of(path);
        let kinds: Vec<LintKind> = lints.iter().map(|l| l.kind).collect();
        assert_eq!(kinds, vec![kind; count], "{path}: {lints:#?}");
        let at = |l: &Lint| l.diagnostic.span.map(|s| scene.sources.location(s));
        let Some(found) = lints.iter().find(|l| at(l).as_deref() == Some(location)) else {
            panic!(
                "{path}: no {} warning at {location}: {lints:#?}",
                kind.name()
            );
        };
        assert!(
            found.diagnostic.message.starts_with(kind.name()),
            "{path}: {}",
            found.diagnostic.message
        );
        assert!(
            found.diagnostic.hints.iter().any(|h| h.contains(fix)),
            "{path}: the fix should say `{fix}`: {:?}",
            found.diagnostic.hints
        );
    }
}

#[test]
fn the_warnings_say_which_way_an_object_is_out_of_view_and_the_depth_cut() {
    let (lints, _) = lints_of("tests/lint/unseen.scene");
    let messages: Vec<&str> = lints
        .iter()
        .map(|l| l.diagnostic.message.as_str())
        .collect();
    assert_eq!(
        messages,
        [
            "unseen_object: the camera cannot see sphere \"behind\": it is behind the camera, \
             and no sampled reflection, refraction or shadow shows it",
            "unseen_object: the camera cannot see sphere \"above\": it is above the view \
             (outside the field of view), and no sampled reflection, refraction or shadow \
             shows it",
        ]
    );
    let (lints, _) = lints_of("tests/lint/max-depth.scene");
    assert!(
        lints[0]
            .diagnostic
            .message
            .starts_with("max_depth_too_low: max_depth 1 is too low for sphere \"ball\""),
        "{}",
        lints[0].diagnostic.message
    );
}

/// Every scene the project ships, benchmarks and 6.837 scenes included.
fn shipped_scenes() -> Vec<PathBuf> {
    let mut scenes = Vec::new();
    for (dir, extension) in [
        ("scenes", "scene"),
        ("scenes/mit6837", "txt"),
        ("scenes/bench", "scene"),
    ] {
        let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{dir}: {e}"));
        scenes.extend(
            entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == extension)),
        );
    }
    scenes.sort();
    scenes
}

/// The ray budget's warning names the material and says how many rays a sample could
/// take; a scene whose weights fall in time is quiet at any depth.
#[test]
fn the_ray_budget_warning_counts_the_rays_and_names_the_material() {
    let (lints, _) = lints_of("tests/lint/ray-budget.scene");
    assert_eq!(
        lints[0].diagnostic.message,
        "ray_budget: min_weight 0 with material `half_glass`, which reflects and transmits, \
         at max_depth 40: a sample could take up to 2.2e12 rays, past the budget of 10000 \
         rays per sample, so `render` stops each such sample's recursion there and keeps the \
         colour so far"
    );
    // The same glass with the usual minimum weight: 2 + 4 + ... + 2^9 rays at most.
    let output = check(&["tests/lint/ray-budget.scene", "--set", "min_weight=0.001"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(!stderr.contains("ray_budget"), "{stderr}");
}

/// Issue 27: an empty scene, or one whose objects are all behind the camera, rendered a
/// background image with "ok" and no word; it still renders, with a warning that says why.
#[test]
fn a_scene_with_nothing_to_see_warns_and_still_renders() {
    let dir = tempfile::tempdir().unwrap();
    for (text, words) in [
        (
            "settings { width 8 height 6 }\ncamera perspective { eye <0, 0, -5> look_at <0, 0, 0> }\n",
            "the scene has no objects",
        ),
        (
            "settings { width 8 height 6 }\ncamera perspective { eye <0, 0, -5> look_at <0, 0, -10> }\nlight point { position <0, 5, 0> }\nsphere { center <0, 0, 10> }\n",
            "no camera ray meets an object",
        ),
    ] {
        let scene = dir.path().join("nothing.scene");
        std::fs::write(&scene, text).unwrap();
        let out = dir.path().join("nothing.png");
        let render = Command::new(env!("CARGO_BIN_EXE_whitted"))
            .env("NO_COLOR", "1")
            .arg("render")
            .arg(&scene)
            .arg("-o")
            .arg(&out)
            .output()
            .expect("the whitted binary runs");
        let stderr = String::from_utf8_lossy(&render.stderr);
        assert!(render.status.success(), "{stderr}");
        assert!(out.exists(), "the image is still written");
        assert!(stderr.contains("warning: nothing_to_see: "), "{stderr}");
        assert!(stderr.contains(words), "{stderr}");
    }
}

/// The scene that shows the ray budget, and its one expected warning.
const RAY_EXPLOSION: &str = "scenes/ray-explosion.scene";

#[test]
fn every_shipped_scene_is_quiet() {
    let scenes = shipped_scenes();
    assert!(scenes.len() >= 30, "found {} scenes", scenes.len());
    for path in scenes {
        let name = path.display().to_string();
        let output = check(&[&name]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(output.status.success(), "{name}: {stderr}");
        for kind in LintKind::ALL {
            if name == RAY_EXPLOSION && kind == LintKind::RayBudget {
                assert!(stderr.contains("warning: ray_budget: "), "{stderr}");
                continue;
            }
            assert!(
                !stderr.contains(kind.name()),
                "{name} should be quiet, but:\n{stderr}"
            );
        }
    }
}

#[test]
fn check_prints_the_lints_and_no_lint_silences_them() {
    let output = check(&["tests/lint/unseen.scene"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: unseen_object: the camera cannot see sphere \"behind\""),
        "{stderr}"
    );
    assert!(stderr.contains("tests/lint/unseen.scene:6:1"), "{stderr}");
    assert!(
        stderr.contains("Help: move it (or the camera's eye, look_at or fov)"),
        "{stderr}"
    );
    assert!(stdout.ends_with("material, 2 warnings)\n"), "{stdout}");

    let output = check(&["tests/lint/unseen.scene", "--no-lint"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(!stderr.contains("unseen_object"), "{stderr}");
    assert!(stdout.ends_with("1 material)\n"), "{stdout}");
}

#[test]
fn a_lint_the_language_already_gave_is_not_repeated() {
    // The language warns about `reflective + transmissive > 1` itself, at the same place.
    let output = check(&["tests/lint/material-gain.scene"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(
        stderr.matches("reflects and transmits more light").count(),
        1,
        "{stderr}"
    );
    assert!(!stderr.contains("material_gain"), "{stderr}");
}

#[test]
fn render_prints_the_lints_too_unless_quiet_or_no_lint() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let out = dir.path().join("unseen.png");
    let out = out.to_str().expect("a UTF-8 path");
    let render = |extra: &[&str]| {
        let output = Command::new(env!("CARGO_BIN_EXE_whitted"))
            .current_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")))
            .env("NO_COLOR", "1")
            .args(["render", "tests/lint/unseen.scene", "-o", out])
            .args(extra)
            .output()
            .expect("the whitted binary runs");
        assert!(output.status.success());
        String::from_utf8_lossy(&output.stderr).into_owned()
    };
    assert!(render(&[]).contains("warning: unseen_object"));
    assert!(!render(&["--no-lint"]).contains("unseen_object"));
    assert!(!render(&["--quiet"]).contains("unseen_object"));
}

/// docs/explain.md's lint example is what `whitted check` prints.
#[test]
fn the_docs_example_is_what_check_prints() {
    let docs = std::fs::read_to_string("docs/explain.md").expect("docs/explain.md");
    let example = docs
        .split("## Lints")
        .nth(1)
        .and_then(|rest| rest.split("```").nth(1))
        .map(|block| block.trim_start_matches('\n'))
        .unwrap_or_default();
    let output = check(&["tests/lint/light-inside-solid.scene"]);
    assert_eq!(String::from_utf8_lossy(&output.stderr), example);
}

/// Light trapped in glass by total internal reflection: the cut ray is a reflected one,
/// inside the cube, and the warning still names the cube and the depth that lets it out.
#[test]
fn max_depth_too_low_follows_light_reflected_inside_glass() {
    let output = check(&["scenes/tir.scene", "--set", "max_depth=3"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr
            .contains("warning: max_depth_too_low: max_depth 3 is too low for box \"glass cube\""),
        "{stderr}"
    );
    assert!(stderr.contains("scenes/tir.scene:16:1"), "{stderr}");
    assert!(stderr.contains("<--set max_depth=3>:1:1"), "{stderr}");
    assert!(
        stderr.contains(
            "Help: raise max_depth to 5 (`max_depth 5` in the settings, or --set max_depth=5)"
        ),
        "{stderr}"
    );
}

/// Thousands of spheres in one place (a fuzz input): five warnings, the last saying how many
/// pairs were left out, found within the lint's bounded number of shape tests.
#[test]
fn many_coincident_objects_make_five_warnings_and_a_count() {
    let (lints, _) = lints_of("tests/fuzz-regressions/105-coincident-objects-few.scene");
    let coincident: Vec<&Lint> = lints
        .iter()
        .filter(|l| l.kind == LintKind::CoincidentSurfaces)
        .collect();
    assert_eq!(coincident.len(), 5, "{lints:#?}");
    let last = coincident[4].diagnostic.hints.last().expect("a hint");
    assert!(
        last.ends_with("more coincident_surfaces warnings are not shown"),
        "{last}"
    );
}

/// A scene of more than `lint::MAX_OBJECTS` objects is not linted unless asked: `check`
/// says so in a note (the lints would cost more than the check), and `--lint` lints it.
#[test]
fn a_scene_too_big_to_lint_says_so_and_lint_forces_it() {
    let scene = "tests/lint/big-scene.scene";
    let quiet = check(&[scene]);
    let stderr = String::from_utf8_lossy(&quiet.stderr);
    assert!(quiet.status.success(), "{stderr}");
    assert!(
        stderr.contains(
            "note: not linted: 50001 objects is more than 50000 (`--lint` lints it anyway)"
        ),
        "{stderr}"
    );
    assert!(!stderr.contains("light_inside_solid"), "{stderr}");
    let forced = check(&["--lint", scene]);
    let stderr = String::from_utf8_lossy(&forced.stderr);
    assert!(
        stderr.contains("light_inside_solid: light \"lamp\" is inside sphere \"shade\""),
        "{stderr}"
    );
    assert!(!stderr.contains("not linted"), "{stderr}");
}
