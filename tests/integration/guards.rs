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

const SMALL_SCENE: &str = "settings { width 8 height 6 }\n\
    camera perspective { eye <0, 0, -5> look_at <0, 0, 0> fov 45 }\n\
    light point { position <0, 5, -5> }\n\
    sphere { radius 1 }\n";

#[test]
fn an_output_that_is_the_scene_an_import_or_the_other_output_is_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let in_dir = |args: &[&str]| {
        whitted()
            .current_dir(dir.path())
            .args(args)
            .output()
            .expect("the whitted binary runs")
    };
    let refused = |output: &Output, what: &str| {
        assert_eq!(output.status.code(), Some(2), "{}", stderr(output));
        assert!(stderr(output).contains(what), "{}", stderr(output));
    };
    // A scene whose name looks like an image, as the output or as the default output.
    write(dir.path(), "s.ppm", SMALL_SCENE);
    refused(&in_dir(&["render", "s.ppm", "-o", "s.ppm"]), "is the scene");
    refused(
        &in_dir(&["render", "s.ppm", "-o", "./s.ppm"]),
        "is the scene",
    );
    write(dir.path(), "x.png", SMALL_SCENE);
    refused(&in_dir(&["render", "x.png"]), "is the scene");
    // An imported file.
    write(dir.path(), "part.png", "sphere { center <2, 0, 0> }\n");
    write(
        dir.path(),
        "main.scene",
        &format!("{SMALL_SCENE}import \"part.png\"\n"),
    );
    refused(
        &in_dir(&["render", "main.scene", "-o", "part.png"]),
        "is a file the scene imports",
    );
    refused(
        &in_dir(&["render", "main.scene", "--stats-image", "part.png"]),
        "is a file the scene imports",
    );
    // The two outputs of one command, also spelled differently.
    refused(
        &in_dir(&[
            "render",
            "main.scene",
            "-o",
            "a.png",
            "--stats-image",
            "./a.png",
        ]),
        "the same file as the output",
    );
    for (name, text) in [
        ("s.ppm", SMALL_SCENE),
        ("x.png", SMALL_SCENE),
        ("part.png", "sphere { center <2, 0, 0> }\n"),
    ] {
        let kept = std::fs::read_to_string(dir.path().join(name)).expect("the file is still there");
        assert_eq!(kept, text, "{name} was overwritten");
    }
    assert!(!dir.path().join("a.png").exists());
    // A legitimate render next to them still works.
    let output = in_dir(&[
        "render",
        "main.scene",
        "-o",
        "out.png",
        "--stats-image",
        "st.png",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
}

/// The `.whitted-*.tmp` files in `dir`.
fn temporary_files(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .expect("list the directory")
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|p| p.to_string_lossy().ends_with(".tmp"))
        .collect()
}

#[cfg(unix)]
#[test]
fn a_signal_during_the_write_removes_the_temporary_file() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    // Nothing to hit: the render is quick, the PNG encoding of a big image is not.
    let scene = write(
        dir.path(),
        "empty.scene",
        "camera perspective { eye <0, 0, -5> look_at <0, 0, 0> fov 45 }\n",
    );
    let out = dir.path().join("big.png");
    for (signal, code) in [("TERM", 143), ("INT", 130)] {
        let mut child = whitted()
            .args(["render", text(&scene), "-o", text(&out), "--quiet"])
            .args(["--width", "4000", "--height", "4000"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("the whitted binary runs");
        let started = Instant::now();
        // Wait for the temporary file to appear, then interrupt the write.
        let seen = loop {
            if !temporary_files(dir.path()).is_empty() {
                break true;
            }
            if child.try_wait().expect("poll whitted").is_some()
                || started.elapsed() > Duration::from_secs(300)
            {
                break false;
            }
            std::thread::sleep(Duration::from_millis(2));
        };
        assert!(seen, "the temporary file never appeared");
        let killed = Command::new("kill")
            .arg(format!("-{signal}"))
            .arg(child.id().to_string())
            .status()
            .expect("kill runs");
        assert!(killed.success());
        let status = child.wait().expect("wait for whitted");
        assert_eq!(
            temporary_files(dir.path()),
            Vec::<PathBuf>::new(),
            "SIG{signal}"
        );
        assert_eq!(status.code(), Some(code), "SIG{signal}: {status:?}");
        assert!(!out.exists(), "no half image");
    }
}

#[test]
fn a_render_over_the_memory_limit_is_refused_before_any_work() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let scene = write(dir.path(), "small.scene", SMALL_SCENE);
    let out = dir.path().join("big.png");
    let heat_maps = dir.path().join("big-stats.exr");
    // The most pixels allowed, with heat maps as floats: about 10 GiB.
    let output = run_within(
        &[
            "render",
            text(&scene),
            "--width",
            "32768",
            "--height",
            "4096",
            "-o",
            text(&out),
            "--stats-image",
            text(&heat_maps),
        ],
        Duration::from_secs(60),
    );
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    assert!(
        stderr(&output).contains("more than the render memory limit of 8 GiB"),
        "{}",
        stderr(&output)
    );
    assert!(!out.exists() && !heat_maps.exists());
}
