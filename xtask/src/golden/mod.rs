//! `cargo xtask golden`: render every golden scene, compare with the reviewed references in
//! tests/golden/, compare the stored ray trees, and write a report a person can review.
//!
//! `--bless [NAME...]` is the only way references are created or changed.

mod compare;
mod manifest;
mod report;

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context};
use image::RgbImage;

use crate::{run_cargo, workspace_root};
use manifest::{GoldenScene, Manifest, Thresholds};
use report::SceneReport;

struct Options {
    /// `Some(names)` blesses those scenes (all of them when empty); `None` compares.
    bless: Option<Vec<String>>,
    scenes_dir: Option<PathBuf>,
    refs_dir: Option<PathBuf>,
}

const USAGE: &str = "usage: cargo xtask golden [--bless [NAME...]] [--scenes DIR --refs DIR]";

fn parse_options(args: &[String]) -> anyhow::Result<Options> {
    let mut options = Options {
        bless: None,
        scenes_dir: None,
        refs_dir: None,
    };
    let mut iter = args.iter().peekable();
    while let Some(arg) = iter.next() {
        match arg.as_str() {
            "--bless" => {
                let mut names = Vec::new();
                while let Some(name) = iter.next_if(|a| !a.starts_with("--")) {
                    names.push(name.clone());
                }
                options.bless = Some(names);
            }
            "--scenes" => options.scenes_dir = Some(iter.next().context(USAGE)?.into()),
            "--refs" => options.refs_dir = Some(iter.next().context(USAGE)?.into()),
            other => bail!("unknown golden option `{other}`\n{USAGE}"),
        }
    }
    if options.scenes_dir.is_some() != options.refs_dir.is_some() {
        bail!("--scenes and --refs go together\n{USAGE}");
    }
    Ok(options)
}

pub fn run(args: &[String]) -> anyhow::Result<()> {
    let options = parse_options(args)?;
    let root = workspace_root();
    let (manifest, refs_dir) = load_manifest(&root, &options)?;
    let selected: Vec<&GoldenScene> = match &options.bless {
        Some(names) if !names.is_empty() => {
            for name in names {
                if !manifest.scenes.iter().any(|s| &s.name == name) {
                    bail!("there is no golden scene named `{name}`");
                }
            }
            manifest
                .scenes
                .iter()
                .filter(|s| names.contains(&s.name))
                .collect()
        }
        _ => manifest.scenes.iter().collect(),
    };
    if selected.is_empty() {
        bail!("no golden scenes to run");
    }

    // Scene paths are relative to the workspace for the project's own manifest, and to the
    // directory the user ran the command from for `--scenes DIR`.
    let base = match &options.scenes_dir {
        Some(_) => std::env::current_dir()?,
        None => root.clone(),
    };
    // Built as `cargo test --workspace` builds it (same profile and the same unified
    // features, dev-dependencies included), so that after the tests of `cargo xtask ci` this
    // is a no-op instead of a second build of five crates with other features. The target is
    // the integration tests, because building them builds `target/debug/whitted` itself:
    // `--bin whitted` built only the binary's unit-test harness, so after a source change the
    // executable run below was stale, and two references were blessed from old code (blinn
    // as Phong; marble before its veins changed) until a later build refreshed it.
    run_cargo(&[
        "test",
        "--workspace",
        "--locked",
        "--no-run",
        "--test",
        "integration",
    ])?;
    let exe = root.join("target/debug/whitted");
    let out_dir = root.join("target/golden");
    if out_dir.exists() {
        std::fs::remove_dir_all(&out_dir)
            .with_context(|| format!("cannot clear {}", out_dir.display()))?;
    }
    std::fs::create_dir_all(&out_dir)?;
    std::fs::create_dir_all(&refs_dir)?;

    if options.bless.is_some() {
        return bless(&exe, &base, &refs_dir, &out_dir, &selected);
    }

    let mut reports = Vec::new();
    for scene in &selected {
        reports.push(check_scene(&exe, &base, &refs_dir, &out_dir, scene));
    }
    print_table(&reports);
    let report_path = out_dir.join("report.html");
    std::fs::write(&report_path, report::html(&reports))?;
    let failed: Vec<&SceneReport> = reports.iter().filter(|r| !r.passed()).collect();
    if failed.is_empty() {
        println!(
            "golden: all {} scenes match their references",
            reports.len()
        );
        return Ok(());
    }
    println!(
        "\ngolden: {} of {} scenes FAILED; review:",
        failed.len(),
        reports.len()
    );
    for r in &failed {
        if let Some(images) = &r.images {
            for file in images {
                println!("  {}", out_dir.join(file).display());
            }
        }
        if let Some(problem) = &r.problem {
            println!("  {}: {problem}", r.name);
        }
        for (pixel, _) in &r.tree_diffs {
            println!("  {}: the ray tree of pixel {pixel} changed", r.name);
        }
    }
    println!("  report: {}", report_path.display());
    println!(
        "If the change is intended, look at every image, then: cargo xtask golden --bless NAME..."
    );
    bail!("golden comparison failed")
}

fn load_manifest(root: &Path, options: &Options) -> anyhow::Result<(Manifest, PathBuf)> {
    if let (Some(scenes_dir), Some(refs_dir)) = (&options.scenes_dir, &options.refs_dir) {
        let manifest_path = refs_dir.join("manifest.toml");
        let manifest = if manifest_path.exists() {
            let text = std::fs::read_to_string(&manifest_path)?;
            manifest::parse(&text, &manifest_path)?
        } else {
            manifest::from_folder(scenes_dir)?
        };
        return Ok((manifest, refs_dir.clone()));
    }
    let refs_dir = root.join("tests/golden");
    let manifest_path = refs_dir.join("manifest.toml");
    let text = std::fs::read_to_string(&manifest_path)
        .with_context(|| format!("cannot read {}", manifest_path.display()))?;
    let manifest = manifest::parse(&text, &manifest_path)?;
    // Every scene in scenes/ and scenes/mit6837/ must be golden or excluded with a reason, so
    // none is forgotten.
    let listed: Vec<PathBuf> = manifest
        .scenes
        .iter()
        .map(|s| s.path.clone())
        .chain(manifest.exclusions.iter().map(|e| e.path.clone()))
        .collect();
    let mut missing = Vec::new();
    let scene_files = manifest::scene_files(&root.join("scenes"))?
        .into_iter()
        .chain(manifest::scene_files(&root.join("scenes/mit6837"))?);
    for file in scene_files {
        let relative = file.strip_prefix(root).unwrap_or(&file).to_path_buf();
        if !listed.contains(&relative) {
            missing.push(relative.display().to_string());
        }
    }
    for exclusion in &manifest.exclusions {
        println!(
            "not golden: {} ({})",
            exclusion.path.display(),
            exclusion.reason
        );
    }
    if !missing.is_empty() {
        bail!(
            "{} is missing from {} (add a [[scene]] entry, or an [[exclude]] with a reason)",
            missing.join(", "),
            manifest_path.display()
        );
    }
    Ok((manifest, refs_dir))
}

/// `whitted SUBCOMMAND SCENE -D ... --width W --height H`, run from `root` with the scene's
/// relative path, so that locations in stored ray trees do not depend on where the checkout
/// lives.
fn scene_command(exe: &Path, root: &Path, subcommand: &str, scene: &GoldenScene) -> Command {
    let mut command = Command::new(exe);
    command.current_dir(root).arg(subcommand).arg(&scene.path);
    for define in &scene.defines {
        command.args(["-D", define]);
    }
    if let Some(frame) = scene.frame {
        command.args(["--frame", &frame.to_string()]);
    }
    command.args([
        "--width",
        &scene.width.to_string(),
        "--height",
        &scene.height.to_string(),
    ]);
    command.env("NO_COLOR", "1");
    command
}

/// `whitted mit6837 -input SCENE -size W H -output OUT FLAGS...`: the course's command line.
fn course_command(
    exe: &Path,
    root: &Path,
    scene: &GoldenScene,
    flags: &[String],
    out: &Path,
) -> Command {
    let mut command = Command::new(exe);
    command
        .current_dir(root)
        .args(["mit6837", "-input"])
        .arg(&scene.path)
        .args([
            "-size",
            &scene.width.to_string(),
            &scene.height.to_string(),
            "-output",
        ])
        .arg(out)
        .args(flags);
    command
}

/// Renders a scene at its golden size into `out` (with the course's command line for a
/// 6.837 scene that names its flags).
fn render(exe: &Path, root: &Path, scene: &GoldenScene, out: &Path) -> anyhow::Result<RgbImage> {
    let mut command = match &scene.course {
        Some(flags) => course_command(exe, root, scene, flags, out),
        None => {
            let mut command = scene_command(exe, root, "render", scene);
            command.args(["--quiet", "-o"]).arg(out);
            command
        }
    };
    let result = command
        .output()
        .with_context(|| format!("cannot run {}", exe.display()))?;
    if !result.status.success() {
        bail!(
            "the render failed:\n{}",
            String::from_utf8_lossy(&result.stderr)
        );
    }
    Ok(image::open(out)
        .with_context(|| format!("cannot read {}", out.display()))?
        .into_rgb8())
}

/// The ray tree of one pixel as `whitted trace` prints it (plain text).
fn trace(exe: &Path, root: &Path, scene: &GoldenScene, [x, y]: [u32; 2]) -> anyhow::Result<String> {
    let result = scene_command(exe, root, "trace", scene)
        .args(["--pixel", &format!("{x},{y}")])
        .output()
        .with_context(|| format!("cannot run {}", exe.display()))?;
    if !result.status.success() {
        bail!(
            "whitted trace failed:\n{}",
            String::from_utf8_lossy(&result.stderr)
        );
    }
    Ok(String::from_utf8_lossy(&result.stdout).into_owned())
}

fn tree_file(refs_dir: &Path, scene: &GoldenScene, [x, y]: [u32; 2]) -> PathBuf {
    refs_dir.join(format!("{}.{x}-{y}.tree", scene.name))
}

fn check_scene(
    exe: &Path,
    root: &Path,
    refs_dir: &Path,
    out_dir: &Path,
    scene: &GoldenScene,
) -> SceneReport {
    let actual_path = out_dir.join(format!("{}.actual.png", scene.name));
    let mut report = match render(exe, root, scene, &actual_path) {
        Ok(actual) => {
            let reference = refs_dir.join(format!("{}.png", scene.name));
            match image::open(&reference) {
                Ok(expected) => evaluate_image(
                    &scene.name,
                    &expected.into_rgb8(),
                    &actual,
                    &scene.thresholds,
                    out_dir,
                ),
                Err(_) if !reference.exists() => problem(
                    scene,
                    format!(
                        "there is no reference {} yet: look at {}, then `cargo xtask golden --bless {}`",
                        reference.display(),
                        actual_path.display(),
                        scene.name
                    ),
                ),
                Err(e) => problem(scene, format!("cannot read the reference {}: {e}", reference.display())),
            }
        }
        Err(e) => problem(scene, format!("{e:#}")),
    };
    for &pixel in &scene.pixels {
        let expected = std::fs::read_to_string(tree_file(refs_dir, scene, pixel));
        let label = format!("{},{}", pixel[0], pixel[1]);
        match (trace(exe, root, scene, pixel), expected) {
            (Ok(actual), Ok(expected)) => {
                if let Some(diff) = tree_difference(&expected, &actual) {
                    report.tree_diffs.push((label, diff));
                }
            }
            (Err(e), _) => report
                .tree_diffs
                .push((label, format!("trace failed: {e:#}"))),
            (_, Err(_)) => report
                .tree_diffs
                .push((label, "no stored ray tree: bless it".to_string())),
        }
    }
    report
}

fn problem(scene: &GoldenScene, message: String) -> SceneReport {
    SceneReport {
        name: scene.name.clone(),
        figures: None,
        images: None,
        problem: Some(message),
        tree_diffs: Vec::new(),
    }
}

/// Compares one image and, when it fails, writes the four review images into `out_dir`.
fn evaluate_image(
    name: &str,
    expected: &RgbImage,
    actual: &RgbImage,
    thresholds: &Thresholds,
    out_dir: &Path,
) -> SceneReport {
    let figures = compare::compare(expected, actual, thresholds);
    let mut report = SceneReport {
        name: name.to_string(),
        figures: None,
        images: None,
        problem: None,
        tree_diffs: Vec::new(),
    };
    if !figures.passed {
        let files = [
            format!("{name}.expected.png"),
            format!("{name}.actual.png"),
            format!("{name}.diff.png"),
            format!("{name}.flip.png"),
        ];
        let diff = compare::difference_image(expected, actual, thresholds.pixel_tolerance);
        let flip = if figures.mismatch.is_none() {
            compare::flip_error_map(expected, actual).0
        } else {
            RgbImage::new(1, 1)
        };
        let written = [expected, actual, &diff, &flip]
            .iter()
            .zip(&files)
            .try_for_each(|(image, file)| image.save(out_dir.join(file)));
        match written {
            Ok(()) => report.images = Some(files),
            Err(e) => report.problem = Some(format!("cannot write the review images: {e}")),
        }
    }
    report.figures = Some(figures);
    report
}

/// A unified diff of two ray-tree texts, or None when they are equal.
fn tree_difference(expected: &str, actual: &str) -> Option<String> {
    if expected == actual {
        return None;
    }
    let diff = similar::TextDiff::from_lines(expected, actual);
    Some(
        diff.unified_diff()
            .context_radius(3)
            .header("expected", "actual")
            .to_string(),
    )
}

fn print_table(reports: &[SceneReport]) {
    println!(
        "\n{:<28} {:>9} {:>10} {:>9} {:>9} {:>7}",
        "scene", "max err", "mean err", "over tol", "FLIP", "result"
    );
    for r in reports {
        let figures = match &r.figures {
            Some(f) => format!(
                "{:>9.4} {:>10.5} {:>8.3}% {:>9.4}",
                f.max_error,
                f.mean_error,
                f.failing_share * 100.0,
                f.mean_flip
            ),
            None => format!("{:>9} {:>10} {:>9} {:>9}", "-", "-", "-", "-"),
        };
        let trees = if r.tree_diffs.is_empty() {
            ""
        } else {
            " (ray tree changed)"
        };
        println!(
            "{:<28} {figures} {:>7}{trees}",
            r.name,
            if r.passed() { "pass" } else { "FAIL" }
        );
    }
}

fn bless(
    exe: &Path,
    root: &Path,
    refs_dir: &Path,
    out_dir: &Path,
    scenes: &[&GoldenScene],
) -> anyhow::Result<()> {
    for scene in scenes {
        let actual_path = out_dir.join(format!("{}.actual.png", scene.name));
        let actual = render(exe, root, scene, &actual_path).with_context(|| scene.name.clone())?;
        let reference = refs_dir.join(format!("{}.png", scene.name));
        let verdict = match image::open(&reference) {
            Ok(old) => {
                let figures = compare::compare(&old.into_rgb8(), &actual, &scene.thresholds);
                if let Some(mismatch) = &figures.mismatch {
                    format!("updated ({mismatch})")
                } else if figures.max_error == 0.0 {
                    "unchanged".to_string()
                } else {
                    format!(
                        "updated (max error {:.4}, {:.3}% of pixels over tolerance, FLIP {:.4})",
                        figures.max_error,
                        figures.failing_share * 100.0,
                        figures.mean_flip
                    )
                }
            }
            Err(_) => "created".to_string(),
        };
        std::fs::copy(&actual_path, &reference)?;
        println!("{:<28} {verdict}: {}", scene.name, reference.display());
        for &pixel in &scene.pixels {
            let text = trace(exe, root, scene, pixel)?;
            let path = tree_file(refs_dir, scene, pixel);
            let verdict = match std::fs::read_to_string(&path) {
                Ok(old) if old == text => "unchanged",
                Ok(_) => "updated",
                Err(_) => "created",
            };
            std::fs::write(&path, text)?;
            println!(
                "{:<28} ray tree {},{} {verdict}: {}",
                scene.name,
                pixel[0],
                pixel[1],
                path.display()
            );
        }
    }
    println!("Look at every reference image before you commit it.");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    fn scene_image() -> RgbImage {
        RgbImage::from_fn(40, 30, |x, y| Rgb([(x * 6) as u8, (y * 8) as u8, 90]))
    }

    #[test]
    fn a_perturbed_render_fails_and_writes_its_review_images_and_report() {
        let dir = tempfile::tempdir().unwrap();
        let expected = scene_image();
        let mut actual = expected.clone();
        for x in 0..40 {
            actual.put_pixel(x, 12, Rgb([255, 255, 255])); // a bright scanline, as a sign flip might make
        }
        let report = evaluate_image(
            "perturbed",
            &expected,
            &actual,
            &Thresholds::default(),
            dir.path(),
        );
        assert!(!report.passed());
        let files = report
            .images
            .clone()
            .expect("a failure writes review images");
        for file in &files {
            assert!(dir.path().join(file).exists(), "{file} was not written");
        }
        let html = report::html(&[report]);
        assert!(html.contains("perturbed.diff.png") && html.contains("FAIL"));
    }

    #[test]
    fn an_unchanged_render_passes_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let report = evaluate_image(
            "same",
            &scene_image(),
            &scene_image(),
            &Thresholds::default(),
            dir.path(),
        );
        assert!(report.passed());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn a_changed_ray_tree_shows_as_a_readable_diff() {
        let expected = "camera depth 0\n  hit sphere t=4.5\n  shadow -> light 0: clear\n";
        let actual = "camera depth 0\n  hit sphere t=4.5\n  shadow -> light 0: blocked by plane\n";
        assert_eq!(tree_difference(expected, expected), None);
        let diff = tree_difference(expected, actual).unwrap();
        assert!(diff.contains("-  shadow -> light 0: clear"));
        assert!(diff.contains("+  shadow -> light 0: blocked by plane"));
    }

    #[test]
    fn options_parse_bless_names_and_folders() {
        let args: Vec<String> = ["--bless", "a", "b", "--scenes", "s", "--refs", "r"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let o = parse_options(&args).unwrap();
        assert_eq!(o.bless, Some(vec!["a".to_string(), "b".to_string()]));
        assert_eq!(o.scenes_dir, Some(PathBuf::from("s")));
        assert!(parse_options(&["--scenes".to_string(), "s".to_string()]).is_err());
        assert!(parse_options(&["--frobnicate".to_string()]).is_err());
    }
}
