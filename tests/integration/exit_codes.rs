//! The exit-code rule (README, "Exit codes"), held for every subcommand: 2 when the command
//! line is wrong, 1 when the scene or a file is, 0 on success; and the message names what
//! to fix (the flag, or the file). One table, each row run as a user runs the binary.

use std::path::Path;
use std::process::{Command, Output, Stdio};

/// A command line, the exit code it must give and a text its stderr must contain.
struct Row {
    args: Vec<String>,
    code: i32,
    names: String,
}

fn row(args: &[&str], code: i32, names: &str) -> Row {
    Row {
        args: args.iter().map(|a| a.to_string()).collect(),
        code,
        names: names.to_string(),
    }
}

fn run(args: &[String]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("NO_COLOR", "1")
        .env_remove("WHITTED_TRAVERSAL")
        // `debug` must fail on its arguments before it looks for a terminal.
        .stdin(Stdio::null())
        .args(args)
        .output()
        .expect("the whitted binary runs")
}

fn text(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 path")
}

/// What each subcommand needs besides the scene to get as far as its own checks, and
/// whether it takes `--width`/`--height`.
const COMMANDS: &[(&str, &[&str], bool)] = &[
    ("check", &[], false),
    ("ir", &[], false),
    ("render", &["-o", "{dir}/out.png"], true),
    ("trace", &["--pixel", "1,1"], true),
    ("explain", &["--pixel", "1,1"], true),
    (
        "diff",
        &["--pixel", "1,1", "--against-set", "max_depth=2"],
        true,
    ),
    ("query", &["tir"], true),
    ("debug", &[], false),
];

fn rows(dir: &Path) -> Vec<Row> {
    let bad = dir.join("bad.scene");
    std::fs::write(&bad, "sphere { center <0, 0, 0> radius oops }\n").expect("writable");
    let course = dir.join("course.txt");
    std::fs::copy("scenes/mit6837/spheres-orthographic.txt", &course).expect("copied");
    // A scene whose name has an image's extension, to be named as its own output.
    let ppm_scene = dir.join("scene.ppm");
    std::fs::copy("scenes/whitted.scene", &ppm_scene).expect("copied");
    let imports = dir.join("imports.scene");
    std::fs::write(&imports, "import \"no-such-part.scene\"\n").expect("writable");
    let small_ref = dir.join("ref.png");
    image::RgbImage::new(8, 8)
        .save(&small_ref)
        .expect("a reference image");
    let dir_text = text(dir);
    let ok = "scenes/whitted.scene";
    let missing = "scenes/no-such.scene";

    let mut rows = Vec::new();
    for &(command, extra, sized) in COMMANDS {
        let extra: Vec<String> = extra.iter().map(|a| a.replace("{dir}", dir_text)).collect();
        let with = |scene: &str, flags: &[&str]| -> Vec<String> {
            let mut args = vec![command.to_string(), scene.to_string()];
            args.extend(extra.iter().cloned());
            args.extend(flags.iter().map(|f| f.to_string()));
            args
        };
        let mut add = |args: Vec<String>, code: i32, names: &str| {
            rows.push(Row {
                args,
                code,
                names: names.to_string(),
            })
        };
        // The scene or a file: 1, naming the file.
        add(with(missing, &[]), 1, "scenes/no-such.scene");
        add(with(text(&bad), &[]), 1, "bad.scene");
        // The command line: 2, naming the flag.
        add(with(ok, &["--bogus"]), 2, "--bogus");
        add(with(ok, &["--set", "foo=1"]), 2, "`--set foo=1`");
        add(with(ok, &["--set", "max_depth"]), 2, "--set");
        add(
            with(ok, &["--set", "max_depth=abc"]),
            2,
            "`--set max_depth=abc`",
        );
        add(with(ok, &["-D", "NOPE=3"]), 2, "`-D NOPE`");
        add(with(ok, &["-D", "1N=3"]), 2, "-D");
        add(
            with(ok, &["--set", "width=30000", "--set", "height=30000"]),
            2,
            "`--set height=30000`",
        );
        add(with(text(&course), &["-D", "N=3"]), 2, "-D N");
        if sized {
            add(
                with(ok, &["--width", "30000", "--height", "30000"]),
                2,
                "`--width 30000 --height 30000`",
            );
            add(with(ok, &["--height", "32000"]), 2, "`--height 32000`");
            add(with(ok, &["--width", "100000"]), 2, "--width");
            add(with(ok, &["--width", "abc"]), 2, "--width");
            add(with(ok, &["--max-depth", "999"]), 2, "--max-depth");
        }
    }
    let out = format!("{dir_text}/out.png");
    let nowhere = format!("{dir_text}/no/such/dir/out.png");
    let nowhere_tga = format!("{dir_text}/no/such/dir/out.tga");
    let exr = format!("{dir_text}/big.exr");
    let heat_exr = format!("{dir_text}/heat.exr");
    let ppm = text(&ppm_scene);
    let ok = "scenes/whitted.scene";
    let course = text(&course);
    rows.extend([
        // Files that cannot be read as a scene.
        row(&["check", dir_text], 1, dir_text),
        row(&["check", text(&imports)], 1, "no-such-part.scene"),
        // A pixel outside the image.
        row(
            &["trace", ok, "--pixel", "9999,9999"],
            2,
            "`--pixel 9999,9999`",
        ),
        row(
            &["explain", ok, "--pixel", "9999,9999"],
            2,
            "`--pixel 9999,9999`",
        ),
        row(
            &[
                "diff",
                ok,
                "--pixel",
                "9999,9999",
                "--against-set",
                "max_depth=2",
            ],
            2,
            "`--pixel 9999,9999`",
        ),
        row(
            &["debug", ok, "--pixel", "9999,9999"],
            2,
            "`--pixel 9999,9999`",
        ),
        row(&["trace", ok, "--pixel", "x"], 2, "--pixel"),
        row(
            &["trace", ok, "--pixel", "1,1", "--sample", "9"],
            2,
            "`--sample 9`",
        ),
        // Outputs: a folder that does not exist is a file problem (1), an output that
        // would replace the scene is the command line's (2).
        row(&["render", ok, "-o", &nowhere], 1, "no/such/dir"),
        row(
            &["render", ok, "-o", &out, "--stats-image", &nowhere],
            1,
            "no/such/dir",
        ),
        row(&["render", ok, "-o", "out.jpg"], 2, "out.jpg"),
        row(&["render", ppm, "-o", ppm], 2, "-o"),
        row(
            &["render", ok, "-o", &out, "--stats-image", &out],
            2,
            "--stats-image",
        ),
        row(&["query", ok, "tir", "--mask", &nowhere], 1, "no/such/dir"),
        // A render too big for memory: the size and formats asked for.
        row(
            &[
                "render",
                ok,
                "--width",
                "32768",
                "--height",
                "4096",
                "-o",
                &exr,
                "--stats-image",
                &heat_exr,
            ],
            2,
            "--width 32768 --height 4096",
        ),
        // Commands' own arguments.
        row(&["diff", ok, "--against-set", "max_depth=2"], 2, "--pixel"),
        row(
            &["diff", ok, "--against-image", "no-such.png"],
            1,
            "no-such.png",
        ),
        row(
            &["diff", ok, "--against-image", text(&small_ref)],
            2,
            "--width 8 --height 8",
        ),
        row(
            &[
                "trace",
                ok,
                "--pixel",
                "1,1",
                "--against",
                "scenes/no-such.scene",
            ],
            1,
            "no-such.scene",
        ),
        row(&["query", ok, "nonsense(("], 2, "query"),
        // The language server takes no arguments, and a client that goes away without
        // `exit` (here stdin is empty) is a failure: the protocol's exit code 1.
        row(&["lsp", ok], 2, "unexpected argument"),
        row(&["lsp"], 1, "language server"),
        // The 6.837 command line.
        row(
            &[
                "mit6837",
                "-input",
                "no-such.txt",
                "-size",
                "8",
                "8",
                "-output",
                &out,
            ],
            1,
            "no-such.txt",
        ),
        row(
            &[
                "mit6837", "-input", course, "-size", "8", "8", "-output", &out, "-bogus",
            ],
            2,
            "-bogus",
        ),
        row(
            &[
                "mit6837", "-input", course, "-size", "30000", "30000", "-output", &out,
            ],
            2,
            "-size 30000 30000",
        ),
        row(
            &[
                "mit6837", "-input", course, "-size", "100000", "8", "-output", &out,
            ],
            2,
            "-size",
        ),
        row(
            &[
                "mit6837",
                "-input",
                course,
                "-size",
                "8",
                "8",
                "-output",
                &nowhere_tga,
            ],
            1,
            "no/such/dir",
        ),
        // No command, or an unknown one.
        row(&[], 2, "Usage"),
        row(&["frobnicate"], 2, "frobnicate"),
        // Success.
        row(&["check", ok], 0, ""),
        row(&["check", course], 0, ""),
    ]);
    rows
}

#[test]
fn every_subcommand_follows_the_exit_code_rule() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let mut wrong = Vec::new();
    for row in rows(dir.path()) {
        let output = run(&row.args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        let code = output.status.code();
        if code != Some(row.code) || !stderr.contains(&row.names) {
            let last = stderr.lines().rev().find(|l| !l.trim().is_empty());
            wrong.push(format!(
                "whitted {}: exit {code:?}, expected {} naming `{}`; stderr ends: {}",
                row.args.join(" "),
                row.code,
                row.names,
                last.unwrap_or("")
            ));
        }
    }
    assert!(
        wrong.is_empty(),
        "{} rows break the rule:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
    // Nothing was written by the failing renders.
    assert!(!dir.path().join("big.exr").exists());
}

/// Output that cannot be written is an IO error: exit 1, saying where.
#[test]
fn an_unwritable_stdout_is_an_io_error() {
    let Ok(full) = std::fs::File::create("/dev/full") else {
        eprintln!("skipped: no /dev/full");
        return;
    };
    let output = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["ir", "scenes/whitted.scene"])
        .stdout(full)
        .output()
        .expect("the whitted binary runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("cannot write to stdout"), "{stderr}");
}
