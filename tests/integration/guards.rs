//! The command line against careless or hostile input (issue 10): files that never end or
//! block, outputs that would overwrite the scene, escape sequences in names, exit codes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn whitted() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_whitted"));
    command.current_dir(env!("CARGO_MANIFEST_DIR"));
    command.env("NO_COLOR", "1");
    command
}

/// Runs `whitted args` and kills it if it is still running after `limit`: a hang is a
/// failure of the test, not of the test run.
fn run_within(args: &[&str], limit: Duration) -> Output {
    let mut child = whitted()
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the whitted binary runs");
    let started = Instant::now();
    while child.try_wait().expect("wait for whitted").is_none() {
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("whitted {args:?} still runs after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("collect the output")
}

fn run(args: &[&str]) -> Output {
    run_within(args, Duration::from_secs(120))
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write a file");
    path
}

fn text(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 path")
}

#[cfg(unix)]
#[test]
fn devices_fifos_and_directories_are_refused_by_name_without_reading_or_blocking() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let fifo = dir.path().join("pipe.scene");
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let folder = dir.path().join("folder.scene");
    std::fs::create_dir(&folder).expect("make a directory");
    let cases = [
        ("/dev/zero", "a device"),
        (text(&fifo), "a FIFO"),
        (text(&folder), "a directory"),
    ];
    for (path, kind) in cases {
        // As the scene itself.
        let output = run_within(&["check", path], Duration::from_secs(30));
        assert_eq!(output.status.code(), Some(1), "{path}: {}", stderr(&output));
        let message = stderr(&output);
        assert!(message.contains(path), "names the file: {message}");
        assert!(
            message.contains(&format!("it is {kind}, not a regular file")),
            "{message}"
        );
        // As an import.
        let scene = write(dir.path(), "imports.scene", &format!("import \"{path}\"\n"));
        let output = run_within(&["check", text(&scene)], Duration::from_secs(30));
        assert_eq!(output.status.code(), Some(1), "{path}: {}", stderr(&output));
        let message = stderr(&output);
        assert!(message.contains(path), "names the file: {message}");
        assert!(message.contains("not a regular file"), "{message}");
    }
}

#[test]
fn a_file_over_the_source_size_limit_is_refused_after_reading_at_most_the_limit() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let big = dir.path().join("big.scene");
    // Sparse: no disk space, but a regular file longer than the limit.
    let file = std::fs::File::create(&big).expect("create a file");
    file.set_len(whitted_ir::limits::MAX_SOURCE_BYTES as u64 * 4)
        .expect("extend the file");
    drop(file);
    let output = run_within(&["check", text(&big)], Duration::from_secs(60));
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    let message = stderr(&output);
    assert!(
        message.contains(&format!(
            "more than {} bytes, the source size limit",
            whitted_ir::limits::MAX_SOURCE_BYTES
        )),
        "{message}"
    );
}

#[test]
fn escape_sequences_in_names_never_reach_the_terminal_raw() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let scene = write(
        dir.path(),
        "esc.scene",
        "camera perspective { eye <0, 0, -5> look_at <0, 0, 0> fov 45 }\n\
         light point \"l\x1b[2J\" { position <0, 5, -5> }\n\
         material m { diffuse 0.5 }\n\
         sphere \"ball\x1b]0;owned\x07\" { radius 1 material m }\n",
    );
    let output = run(&["ir", text(&scene)]);
    assert!(output.status.success(), "{}", stderr(&output));
    let printed = stdout(&output);
    assert!(
        !printed.contains('\x1b') && !printed.contains('\x07'),
        "{printed:?}"
    );
    assert!(printed.contains(r"ball\u{1b}]0;owned\u{7}"), "{printed}");

    let output = run(&["trace", text(&scene), "--pixel", "320,240"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let printed = stdout(&output);
    assert!(
        !printed.contains('\x1b') && !printed.contains('\x07'),
        "{printed:?}"
    );
    assert!(printed.contains(r"ball\u{1b}]0;owned\u{7}"), "{printed}");
    assert!(printed.contains(r"light l\u{1b}[2J"), "{printed}");
}
