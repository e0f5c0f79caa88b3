//! `whitted diff` and `whitted trace --against` (issue 12, item 3): two scenes that differ
//! only in an ior are told apart by that ior, a lowered `max_depth` shows rays in one tree
//! only (and the divergences account for the whole change of the pixel), and
//! `--against-image` finds regions planted in a render and explains a pixel of each.

use crate::support::run;
use serde_json::Value;

fn json(args: &[&str]) -> Value {
    let output = run(args);
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("--json prints JSON")
}

/// `--json` output checked against its documented schema.
fn checked(schema: &str, document: &Value) {
    let text = std::fs::read_to_string(schema).unwrap();
    let schema: Value = serde_json::from_str(&text).unwrap();
    let errors = crate::json_schema::validate(&schema, document);
    assert!(errors.is_empty(), "{errors:#?}");
}

fn color(v: &Value) -> [f64; 3] {
    std::array::from_fn(|i| v[i].as_f64().expect("a number"))
}

#[test]
fn two_scenes_differing_in_an_ior_diverge_at_that_ior() {
    let (a, b) = ("tests/diff/glass-a.scene", "tests/diff/glass-b.scene");
    // The middle of the image sees the ball.
    let diff = json(&["diff", a, b, "--pixel", "20,13", "--json"]);
    checked("docs/diff.schema.json", &diff);
    let mut broken = diff.clone();
    broken["divergences"][0]["kind"] = "ior".into();
    assert!(!crate::json_schema::validate(
        &serde_json::from_str(&std::fs::read_to_string("docs/diff.schema.json").unwrap()).unwrap(),
        &broken
    )
    .is_empty());
    assert_eq!(diff["settings"], serde_json::json!([]));
    let first = &diff["divergences"][0];
    assert_eq!(first["kind"], "material", "{diff:#}");
    assert!(first["what"]
        .as_str()
        .unwrap()
        .starts_with("ior of material glass"));
    assert_eq!(first["values"], serde_json::json!(["1.5", "1.33"]));
    assert_eq!(
        first["location"],
        serde_json::json!([
            "tests/diff/glass-a.scene:8:20",
            "tests/diff/glass-b.scene:8:20"
        ])
    );
    assert_eq!(
        first["source_line"][0],
        "transmissive 1 ior 1.5 fresnel schlick"
    );
    assert_eq!(
        first["source_line"][1],
        "transmissive 1 ior 1.33 fresnel schlick"
    );
    assert_eq!(first["route"], serde_json::json!(["camera"]));
    // The camera ray's subtree is the whole pixel, in A and in B.
    for side in 0..2 {
        let (sum, pixel) = (
            color(&first["contribution"][side]),
            color(&diff["color"][side]),
        );
        for c in 0..3 {
            assert!((sum[c] - pixel[c]).abs() < 1e-5, "{sum:?} {pixel:?}");
        }
    }
    // Where the camera sees only the floor, nothing diverges.
    let floor = json(&["diff", a, b, "--pixel", "2,28", "--json"]);
    assert_eq!(floor["divergences"], serde_json::json!([]), "{floor:#}");

    let text = run(&["trace", a, "--pixel", "20,13", "--against", b]);
    assert!(text.status.success());
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("ior of material glass (at ball): 1.5 in A, 1.33 in B"),
        "{text}"
    );
    assert!(
        text.contains("A at tests/diff/glass-a.scene:8:20"),
        "{text}"
    );
    assert!(
        text.contains("| transmissive 1 ior 1.33 fresnel schlick"),
        "{text}"
    );
}

#[test]
fn a_lower_max_depth_leaves_rays_in_one_tree_only() {
    let scene = "tests/diff/glass-a.scene";
    let diff = json(&[
        "diff",
        scene,
        "--pixel",
        "20,13",
        "--against-set",
        "max_depth=2",
        "--json",
    ]);
    assert_eq!(
        diff["settings"],
        serde_json::json!([["max_depth", "6", "2"]])
    );
    let divergences = diff["divergences"].as_array().unwrap();
    assert!(!divergences.is_empty());
    for d in divergences {
        assert_eq!(d["kind"], "only_in_a", "{d:#}");
        assert_eq!(d["values"][1], "not traced (max_depth)");
        assert_eq!(d["depth"], 3);
    }
    // Above the divergences the trees are the same, so the rays present in one tree only
    // make the whole change of the pixel.
    let [a, b] = [0, 1].map(|side| color(&diff["color"][side]));
    let mut change = [0.0; 3];
    for d in divergences {
        let (ca, cb) = (color(&d["contribution"][0]), color(&d["contribution"][1]));
        for c in 0..3 {
            change[c] += cb[c] - ca[c];
        }
    }
    for c in 0..3 {
        assert!(
            ((b[c] - a[c]) - change[c]).abs() < 1e-5,
            "{change:?} vs {a:?} -> {b:?}"
        );
    }
    // The other way round, the rays exist in B only; the same through `trace`.
    let raised = run(&[
        "trace",
        scene,
        "--pixel",
        "20,13",
        "--set",
        "max_depth=2",
        "--against-set",
        "max_depth=6",
    ]);
    let text = String::from_utf8_lossy(&raised.stdout);
    assert!(text.contains("max_depth: 2 in A, 6 in B"), "{text}");
    assert!(text.contains("not traced (max_depth) in A"), "{text}");
}

#[test]
fn the_same_scene_twice_does_not_diverge() {
    let scene = "tests/diff/glass-a.scene";
    let output = run(&["diff", scene, scene, "--pixel", "20,13"]);
    assert!(output.status.success());
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        text.contains("the two ray trees are the same, ray by ray"),
        "{text}"
    );
}

#[test]
fn against_image_finds_the_regions_planted_in_a_render() {
    let dir = tempfile::tempdir().unwrap();
    let scene = "tests/diff/glass-a.scene";
    let rendered = dir.path().join("whitted.png");
    let rendered_arg = rendered.to_str().unwrap();
    let output = run(&["render", scene, "-o", rendered_arg, "--quiet"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    // Its own render matches: decoding reads back exactly what `render` encoded.
    let same = json(&[
        "diff",
        scene,
        "--against-image",
        rendered_arg,
        "--tolerance",
        "0",
        "--json",
    ]);
    assert_eq!(same["differing_pixels"], 0, "{same:#}");
    assert_eq!(same["regions"], serde_json::json!([]));

    let mut student = image::open(&rendered).unwrap().to_rgb8();
    // Two planted mistakes: a black patch on the ball and a brightened strip of floor.
    for y in 10..=15 {
        for x in 17..=22 {
            student.put_pixel(x, y, image::Rgb([0, 0, 0]));
        }
    }
    for y in 26..=27 {
        for x in 2..=11 {
            let p = student.get_pixel_mut(x, y);
            p.0 = p.0.map(|c| c.saturating_add(60));
        }
    }
    // One pixel changed by less than the tolerance is not a region.
    let p = student.get_pixel_mut(35, 3);
    p.0[0] = p.0[0].saturating_sub(3);
    let student_path = dir.path().join("student.png");
    student.save(&student_path).unwrap();
    let report = json(&[
        "diff",
        scene,
        "--against-image",
        student_path.to_str().unwrap(),
        "--json",
    ]);
    checked("docs/diff-image.schema.json", &report);
    let regions = report["regions"].as_array().unwrap();
    assert_eq!(regions.len(), 2, "{report:#}");
    for region in regions {
        checked("docs/explain.schema.json", &region["explanation"]);
    }
    assert_eq!(regions[0]["min"], serde_json::json!([17, 10]));
    assert_eq!(regions[0]["max"], serde_json::json!([22, 15]));
    assert_eq!(regions[0]["pixels"], 36);
    assert_eq!(regions[1]["min"], serde_json::json!([2, 26]));
    assert_eq!(regions[1]["max"], serde_json::json!([11, 27]));
    for region in regions {
        let sample = &region["sample"];
        assert_eq!(region["explanation"]["pixel"], *sample);
        assert_eq!(region["reference"].as_array().unwrap().len(), 3);
    }
    // The ball's region is explained through the ball; the text names it too.
    let ball = &regions[0]["explanation"]["contributions"][0]["path"][0]["object"];
    assert_eq!(ball, "ball");
    let text = run(&[
        "diff",
        scene,
        "--against-image",
        student_path.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("in 2 regions"), "{text}");
    assert!(
        text.contains("region 1: x 17..22, y 10..15 (36 pixels)"),
        "{text}"
    );
    assert!(text.contains("main light:"), "{text}");
}

#[test]
fn bad_diff_requests_are_usage_errors() {
    let scene = "tests/diff/glass-a.scene";
    for args in [
        vec!["diff", scene, "--pixel", "20,13"],
        vec!["diff", scene, scene],
        vec!["diff", scene, scene, "--pixel", "40,0"],
        vec![
            "diff",
            scene,
            "--against-image",
            "tests/diff/glass-a.scene",
            "--pixel",
            "1,1",
        ],
        vec![
            "trace",
            scene,
            "--pixel",
            "1,1",
            "--against",
            scene,
            "--sample",
            "0",
        ],
    ] {
        let output = run(&args);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    }
    let dir = tempfile::tempdir().unwrap();
    let small = dir.path().join("small.png");
    image::RgbImage::new(8, 8).save(&small).unwrap();
    let output = run(&["diff", scene, "--against-image", small.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("--width 8 --height 8"));
}
