//! `whitted fmt` as a user and CI run it: the repository's scenes are formatted (CI runs
//! this test), `--check` shows a diff and exits 1 on a badly laid out file and 0 on a
//! formatted one, a broken scene is refused with located diagnostics, files are rewritten
//! only when they change, and `-` formats standard input.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn whitted() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_whitted"));
    command.current_dir(workspace());
    command.env("NO_COLOR", "1");
    command
}

fn run(args: &[&str]) -> Output {
    whitted()
        .args(args)
        .output()
        .expect("the whitted binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Scenes left as they are, because other tests pin their line numbers: the golden ray
/// trees (tests/golden/*.tree) and the trace snapshots record `file:line:column`.
/// Formatting one means re-blessing those (`cargo xtask golden --bless`, reviewed) in the
/// same change; until then they are not checked.
const LEFT_AS_THEY_ARE: &[&str] = &[
    "scenes/antialiasing.scene",
    "scenes/mesh.scene",
    "scenes/spotlight.scene",
    "scenes/transparent-shadows.scene",
];

fn scene_files(dir: &Path, out: &mut Vec<String>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(workspace().join(dir))
        .expect("a readable folder")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for path in entries {
        let relative = path
            .strip_prefix(workspace())
            .expect("inside the workspace")
            .to_path_buf();
        if path.is_dir() {
            scene_files(&relative, out);
        } else if path.extension().is_some_and(|e| e == "scene") {
            out.push(relative.to_string_lossy().into_owned());
        }
    }
}

#[test]
fn fmt_check_passes_on_the_repository_scenes() {
    let mut files = Vec::new();
    scene_files(Path::new("scenes"), &mut files);
    let checked: Vec<&str> = files
        .iter()
        .map(String::as_str)
        .filter(|f| !LEFT_AS_THEY_ARE.contains(f))
        .collect();
    assert!(checked.len() > 20, "only {} scenes found", checked.len());
    let mut args = vec!["fmt", "--check"];
    args.extend(&checked);
    let output = run(&args);
    assert_eq!(
        output.status.code(),
        Some(0),
        "scenes are not formatted; run `whitted fmt` on them:\n{}{}",
        text(&output.stdout),
        text(&output.stderr)
    );
    // The exceptions are real: once one is formatted (and its trees re-blessed), it leaves
    // the list.
    for file in LEFT_AS_THEY_ARE {
        let output = run(&["fmt", "--check", file]);
        assert_eq!(
            output.status.code(),
            Some(1),
            "{file} is formatted now: remove it from LEFT_AS_THEY_ARE"
        );
    }
}

const MESSY: &str = "settings{width 64 height 48}\n\n\n\
camera perspective {eye <0,1,-5>   look_at <0, 1, 0> fov 45}\n\
// the ball\n\
sphere \"ball\" { center <0 , 1 , 0>\n      radius 1+0.5 }   // a trailing comment\n";

const TIDY: &str = "settings { width 64 height 48 }\n\n\
camera perspective { eye <0, 1, -5> look_at <0, 1, 0> fov 45 }\n\
// the ball\n\
sphere \"ball\" {\n    center <0, 1, 0>\n    radius 1 + 0.5\n}   // a trailing comment\n";

#[test]
fn fmt_check_shows_a_diff_and_fmt_rewrites_the_file() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = dir.path().join("messy.scene");
    std::fs::write(&path, MESSY).expect("writable");
    let name = path.to_str().expect("a UTF-8 path");

    let output = run(&["fmt", "--check", name]);
    assert_eq!(output.status.code(), Some(1), "{}", text(&output.stderr));
    let diff = text(&output.stdout);
    assert!(diff.contains(&format!("--- {name}")), "{diff}");
    assert!(diff.contains("-settings{width 64 height 48}"), "{diff}");
    assert!(diff.contains("+settings { width 64 height 48 }"), "{diff}");
    assert!(text(&output.stderr).contains("not formatted"));
    // --check writes nothing.
    assert_eq!(std::fs::read_to_string(&path).expect("readable"), MESSY);

    let output = run(&["fmt", name]);
    assert_eq!(output.status.code(), Some(0), "{}", text(&output.stderr));
    assert_eq!(std::fs::read_to_string(&path).expect("readable"), TIDY);
    // No temporary file is left beside it.
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .expect("readable")
        .filter_map(|e| e.ok())
        .collect();
    assert_eq!(left.len(), 1);

    let output = run(&["fmt", "--check", name]);
    assert_eq!(output.status.code(), Some(0), "{}", text(&output.stdout));
    assert!(output.stdout.is_empty());
}

#[test]
fn fmt_refuses_a_broken_scene_with_located_diagnostics() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = dir.path().join("broken.scene");
    let broken = "sphere { center <0, 0, 0> radius 1\nbox { min <0, 0, 0> max <1, 1, 1 }\n";
    std::fs::write(&path, broken).expect("writable");
    let name = path.to_str().expect("a UTF-8 path");
    for args in [vec!["fmt", "--check", name], vec!["fmt", name]] {
        let output = run(&args);
        assert_eq!(output.status.code(), Some(1), "{args:?}");
        let stderr = text(&output.stderr);
        assert!(stderr.contains("broken.scene:2:"), "{stderr}");
        assert_eq!(std::fs::read_to_string(&path).expect("readable"), broken);
    }
}

#[test]
fn fmt_reads_standard_input_and_writes_standard_output() {
    let mut child = whitted()
        .args(["fmt", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the whitted binary runs");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all(MESSY.as_bytes())
        .expect("written");
    let output = child.wait_with_output().expect("it ends");
    assert_eq!(output.status.code(), Some(0));
    assert_eq!(text(&output.stdout), TIDY);
}

#[test]
fn fmt_names_a_missing_file_and_a_bad_flag() {
    let output = run(&["fmt", "scenes/no-such.scene"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(text(&output.stderr).contains("scenes/no-such.scene"));
    let output = run(&["fmt", "--bogus", "scenes/whitted.scene"]);
    assert_eq!(output.status.code(), Some(2));
}
