//! `whitted debug` outside a terminal and with bad input: clear one-line errors and the
//! documented exit codes, before the terminal would be taken over.

use std::process::{Command, Output, Stdio};

fn debug(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("NO_COLOR", "1")
        .arg("debug")
        .args(args)
        .stdin(Stdio::null())
        .output()
        .expect("the whitted binary runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

#[test]
fn without_a_terminal_it_says_so_and_exits_2() {
    let output = debug(&["scenes/whitted.scene"]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    assert_eq!(
        stderr(&output),
        "error: whitted debug needs an interactive terminal (stdin and stdout)\n"
    );
    assert!(output.stdout.is_empty(), "no escape codes on a pipe");
}

#[test]
fn a_pixel_outside_the_image_is_an_error() {
    let output = debug(&["scenes/whitted.scene", "--pixel", "640,10"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("`--pixel 640,10` is outside the 640x480 image"),
        "{}",
        stderr(&output)
    );
}

/// `debug` takes the render's size flags, so a pixel named for a render at `--width 100`
/// (by a lint, or `render`'s report) is the same pixel in the debugger.
#[test]
fn the_debugger_opens_at_the_size_the_flags_give() {
    let output = debug(&[
        "scenes/whitted.scene",
        "--width",
        "100",
        "--pixel",
        "150,10",
    ]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("`--pixel 150,10` is outside the 100x75 image"),
        "{}",
        stderr(&output)
    );
}

#[test]
fn a_scene_with_errors_prints_them_and_never_starts() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let scene = dir.path().join("bad.scene");
    std::fs::write(&scene, "sphere { radius }\n").expect("writable");
    let output = debug(&[scene.to_str().expect("a UTF-8 path")]);
    assert_eq!(output.status.code(), Some(1));
    assert!(stderr(&output).contains("bad.scene"), "{}", stderr(&output));
    assert!(output.stdout.is_empty());
}

#[test]
fn a_missing_scene_is_one_line() {
    let output = debug(&["scenes/no-such.scene"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).starts_with("error: cannot read scenes/no-such.scene"),
        "{}",
        stderr(&output)
    );
    assert_eq!(stderr(&output).lines().count(), 1);
}
