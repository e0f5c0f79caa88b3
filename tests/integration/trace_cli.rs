//! `whitted trace` and `whitted render --stats-image` as a user runs them: exit codes, one-line
//! errors, JSON that matches docs/ray-tree.schema.json, and a trace that follows a render made
//! at the same reduced size.

use std::path::PathBuf;
use std::process::{Command, Output};

use serde_json::Value;

use crate::json_schema::validate;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(workspace())
        .env("NO_COLOR", "1")
        .args(args)
        .output()
        .expect("the whitted binary runs")
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn schema() -> Value {
    let text = std::fs::read_to_string(workspace().join("docs/ray-tree.schema.json"))
        .expect("docs/ray-tree.schema.json");
    serde_json::from_str(&text).expect("the schema is JSON")
}

fn trace_json(args: &[&str]) -> Value {
    let mut all = vec!["trace"];
    all.extend_from_slice(args);
    all.push("--json");
    let output = run(&all);
    assert!(output.status.success(), "{}", stderr(&output));
    serde_json::from_str(&stdout(&output)).expect("trace --json prints JSON")
}

#[test]
fn json_matches_the_documented_schema_on_varied_scenes() {
    let schema = schema();
    let cases: [&[&str]; 9] = [
        &["scenes/whitted.scene", "--pixel", "400,270"],
        // A spot cone that misses (`outside_cone` with its `cone`), and the ray budget.
        &[
            "scenes/spotlight.scene",
            "--pixel",
            "32,30",
            "--width",
            "64",
            "--height",
            "48",
        ],
        // (At depth 24: a tree 64 deep passes serde_json's nesting limit when read back.)
        &[
            "scenes/ray-explosion.scene",
            "--pixel",
            "32,24",
            "--max-depth",
            "24",
        ],
        &[
            "scenes/csg-difference.scene",
            "--pixel",
            "22,16",
            "--width",
            "48",
            "--height",
            "36",
        ],
        // A 6.837 scene: the course's model, `energy_clamp` off in the tree's model.
        &["scenes/mit6837/glass-gem.txt", "--pixel", "100,100"],
        // The course's `Marble`: a blend of two materials.
        &[
            "scenes/mit6837/procedural.txt",
            "--pixel",
            "100,110",
            "--width",
            "200",
            "--height",
            "200",
        ],
        &[
            "scenes/transparent-shadows.scene",
            "--pixel",
            "27,18",
            "--width",
            "48",
            "--height",
            "32",
        ],
        &[
            "scenes/antialiasing.scene",
            "--pixel",
            "3,3",
            "--width",
            "16",
            "--height",
            "12",
        ],
        &[
            "scenes/spotlight.scene",
            "--pixel",
            "30,30",
            "--width",
            "64",
            "--height",
            "48",
            "--max-depth",
            "1",
        ],
    ];
    let mut words = String::new();
    for args in cases {
        let document = trace_json(args);
        words.push_str(&document.to_string());
        let errors = validate(&schema, &document);
        assert!(errors.is_empty(), "{args:?}: {errors:#?}");
        assert_eq!(document["version"], 2);
        assert_eq!(document["root"], document["samples"][0]["root"]);
        assert_eq!(document["root"]["kind"], "camera");
    }
    // The new words were among what the schema checked.
    for word in [
        "\"outside_cone\"",
        "\"facing_away\"",
        "\"ray_budget\"",
        "\"cone\":{",
        "\"blend\":{",
    ] {
        assert!(words.contains(word), "no {word} in the documents checked");
    }
    // The antialiasing scene has 16 samples: all are recorded unless one is asked for.
    let all = trace_json(&[
        "scenes/antialiasing.scene",
        "--pixel",
        "3,3",
        "--width",
        "16",
        "--height",
        "12",
    ]);
    assert_eq!(all["samples"].as_array().map(Vec::len), Some(16));
    let one = trace_json(&[
        "scenes/antialiasing.scene",
        "--pixel",
        "3,3",
        "--width",
        "16",
        "--height",
        "12",
        "--sample",
        "7",
    ]);
    assert_eq!(one["samples"].as_array().map(Vec::len), Some(1));
    assert_eq!(one["root_sample"], 7);
    assert_eq!(one["color"], all["color"]);
    assert_eq!(one["samples"][0], all["samples"][7]);
}

#[test]
fn the_documented_example_matches_the_schema() {
    let doc = std::fs::read_to_string(workspace().join("docs/ray-tree.md")).expect("the doc");
    let start = doc.find("```json\n").expect("a JSON example") + "```json\n".len();
    let end = start + doc[start..].find("```").expect("the end of the example");
    let example: Value = serde_json::from_str(&doc[start..end]).expect("the example is JSON");
    assert_eq!(validate(&schema(), &example), Vec::<String>::new());
}

#[test]
fn the_schema_rejects_a_document_that_breaks_it() {
    let schema = schema();
    let mut document = trace_json(&["scenes/whitted.scene", "--pixel", "400,270"]);
    document["root"]["children"][0]
        .as_object_mut()
        .expect("a child node")
        .remove("termination");
    document["root"]["kind"] = Value::from("primary");
    let errors = validate(&schema, &document);
    assert!(
        errors
            .iter()
            .any(|e| e.contains("missing required `termination`")),
        "{errors:#?}"
    );
    assert!(
        errors.iter().any(|e| e.contains("\"primary\"")),
        "{errors:#?}"
    );
}

#[test]
fn a_trace_at_a_reduced_size_follows_the_render_at_that_size_bit_for_bit() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let exr = dir.path().join("small.exr");
    let exr_arg = exr.to_str().expect("a UTF-8 path");
    let size = ["--width", "32", "--height", "24", "--max-depth", "3"];
    let mut render = vec!["render", "scenes/whitted.scene", "-o", exr_arg, "--quiet"];
    render.extend_from_slice(&size);
    let output = run(&render);
    assert!(output.status.success(), "{}", stderr(&output));
    let image = image::open(&exr).expect("the EXR decodes").into_rgb32f();
    for (x, y) in [(20, 13), (5, 5), (31, 23), (12, 14)] {
        let pixel = format!("{x},{y}");
        let mut args = vec!["scenes/whitted.scene", "--pixel", pixel.as_str()];
        args.extend_from_slice(&size);
        let document = trace_json(&args);
        assert_eq!(document["image_size"], serde_json::json!([32, 24]));
        assert_eq!(document["max_depth"], 3);
        let traced: Vec<f32> = (0..3)
            .map(|c| document["color"][c].as_f64().expect("a number") as f32)
            .collect();
        let rendered = image.get_pixel(x, y).0;
        assert_eq!(traced, rendered.to_vec(), "pixel ({x}, {y})");
    }
}

#[test]
fn text_output_is_an_indented_tree_without_colour_codes_when_piped() {
    let output = run(&[
        "trace",
        "scenes/whitted.scene",
        "--pixel",
        "400,270",
        "--max-depth",
        "2",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(
        text.starts_with("pixel (400, 270) of 640x480: rgb("),
        "{text}"
    );
    assert!(text.contains("camera depth 0: hit glass sphere"), "{text}");
    assert!(
        text.contains("└─ transmitted depth 1: hit glass sphere"),
        "{text}"
    );
    assert!(text.contains("ior 1 -> 1.5"), "{text}");
    assert!(!text.contains('\x1b'), "no escape codes in a pipe: {text}");
}

#[test]
fn bad_requests_are_one_clear_line() {
    let cases: [(&[&str], i32, &str); 5] = [
        (
            &["trace", "scenes/whitted.scene", "--pixel", "640,10"],
            2,
            "error: `--pixel 640,10` is outside the 640x480 image (x must be 0 to 639, y 0 to 479)",
        ),
        (
            &[
                "trace",
                "scenes/whitted.scene",
                "--pixel",
                "10,10",
                "--width",
                "8",
                "--height",
                "8",
            ],
            2,
            "error: `--pixel 10,10` is outside the 8x8 image (x must be 0 to 7, y 0 to 7)",
        ),
        (
            &[
                "trace",
                "scenes/whitted.scene",
                "--pixel",
                "1,1",
                "--sample",
                "1",
            ],
            2,
            "error: `--sample 1` is not a sample of the pixel: the image has 1 sample per pixel (sample 0)",
        ),
        (
            &[
                "trace",
                "scenes/antialiasing.scene",
                "--pixel",
                "1,1",
                "--sample",
                "16",
            ],
            2,
            "error: `--sample 16` is not a sample of the pixel: the image has 16 samples per pixel (0 to 15)",
        ),
        (
            &["trace", "no/such.scene", "--pixel", "1,1"],
            1,
            "error: cannot read no/such.scene",
        ),
    ];
    for (args, code, message) in cases {
        let output = run(args);
        assert_eq!(
            output.status.code(),
            Some(code),
            "{args:?}: {}",
            stderr(&output)
        );
        let text = stderr(&output);
        assert!(text.starts_with(message), "{args:?}: {text}");
        assert_eq!(text.lines().count(), 1, "{args:?}: {text}");
        assert!(stdout(&output).is_empty(), "{args:?}");
    }
}

#[test]
fn a_scene_with_errors_or_a_malformed_pixel_fails_with_the_right_code() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let bad = dir.path().join("bad.scene");
    std::fs::write(&bad, "sphere { radius foo }\n").expect("write a scene");
    let output = run(&[
        "trace",
        bad.to_str().expect("a UTF-8 path"),
        "--pixel",
        "1,1",
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("bad.scene:1:"),
        "{}",
        stderr(&output)
    );

    for pixel in ["10", "a,b", "-1,3", "1,2,3"] {
        let output = run(&["trace", "scenes/whitted.scene", "--pixel", pixel]);
        assert_eq!(output.status.code(), Some(2), "--pixel {pixel}");
        assert!(
            stderr(&output).contains("is not a pixel"),
            "{}",
            stderr(&output)
        );
    }
    let output = run(&["trace", "scenes/whitted.scene"]);
    assert_eq!(output.status.code(), Some(2), "--pixel is required");
}

#[test]
fn render_writes_the_stats_heat_maps_beside_the_image() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let out = dir.path().join("tir.png");
    let stats = dir.path().join("tir-stats.png");
    let output = run(&[
        "render",
        "scenes/tir.scene",
        "--width",
        "40",
        "--height",
        "30",
        "-o",
        out.to_str().expect("a UTF-8 path"),
        "--stats-image",
        stats.to_str().expect("a UTF-8 path"),
        "--quiet",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let image = image::open(&stats)
        .expect("the stats image decodes")
        .into_rgb8();
    assert_eq!(image.dimensions(), (40 * 3 + 8, 30));
    // The glass cube needs many rays and deep recursion: the hottest ray count is the top of
    // the ramp, and the cut-off panel shows total internal reflection (green) somewhere.
    let left: Vec<[u8; 3]> = (0..30)
        .flat_map(|y| (0..40).map(move |x| (x, y)))
        .map(|(x, y)| image.get_pixel(x, y).0)
        .collect();
    assert!(
        left.contains(&[255, 250, 180]),
        "the busiest pixel is at the top of the ramp"
    );
    let green = (0..30)
        .flat_map(|y| (88..128).map(move |x| (x, y)))
        .any(|(x, y)| image.get_pixel(x, y).0[1] == 255);
    assert!(
        green,
        "total internal reflection shows in the cut-off panel"
    );

    let output = run(&["render", "scenes/tir.scene", "--stats-image", "stats.jpg"]);
    assert_eq!(output.status.code(), Some(2));
    let output = run(&[
        "render",
        "scenes/tir.scene",
        "-o",
        out.to_str().expect("a UTF-8 path"),
        "--stats-image",
        "/no/such/dir/stats.png",
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("/no/such/dir does not exist"),
        "{}",
        stderr(&output)
    );
}
