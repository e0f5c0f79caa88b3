//! `whitted query` (issue 12, item 4): the streaming answer over a whole image equals the
//! predicate evaluated on every pixel's full recorded ray tree (the oracle), on scenes where
//! each predicate fires; known pixels are in or out; the mask and list agree; and a query
//! that cannot be read is a located usage error.

use whitted_explain::query::{run as run_query, Query};
use whitted_tracer::ray_tree::{trace_pixel, SampleChoice};
use whitted_tracer::RenderOptions;

use crate::ray_trees::load;
use crate::support::run;

/// Each scene with the predicates to try on it (a name per scene for the named ones).
const CASES: &[(&str, &[&str])] = &[
    (
        "scenes/glass.scene",
        &[
            "hit(\"fixed glass\")",
            "shadow_blocked",
            "shadow_blocked_by(\"fresnel glass\")",
            "shadow_blocked_by_transparent and not hit(\"fresnel glass\")",
            "depth >= 3",
            "depth == 0 or nan",
            "weight_cutoff",
        ],
    ),
    (
        "scenes/tir.scene",
        &[
            "tir",
            "tir and depth > 5",
            "not tir and hit(\"glass cube\")",
        ],
    ),
    (
        "tests/explain/max-depth.scene",
        &["max_depth", "max_depth and not hit(\"wall\")"],
    ),
    (
        "tests/explain/weight-cutoff.scene",
        &["weight_cutoff", "(weight_cutoff or tir) and depth <= 1"],
    ),
    (
        "tests/explain/self-hit.scene",
        &["self_hit", "self_hit and shadow_blocked_by(\"ball\")"],
    ),
    (
        "tests/explain/shadow-blocked-transparent.scene",
        &[
            "shadow_blocked_by_transparent",
            "shadow_blocked_by(\"wall\") and hit(\"floor\")",
        ],
    ),
];

#[test]
fn the_query_matches_exactly_the_pixels_whose_recorded_trees_match() {
    let (width, height) = (24, 18);
    // Which predicates matched somewhere, so that none is checked only on empty answers.
    let mut fired = std::collections::BTreeSet::new();
    for (path, queries) in CASES {
        let loaded = load(path);
        let options = RenderOptions {
            width,
            height,
            ..RenderOptions::from_settings(&loaded.scene.settings)
        };
        let trees: Vec<_> = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| {
                trace_pixel(
                    &loaded.prepared,
                    &loaded.scene,
                    &options,
                    x,
                    y,
                    SampleChoice::All,
                )
                .unwrap()
            })
            .collect();
        for text in *queries {
            let query =
                Query::compile(text, &loaded.scene).unwrap_or_else(|e| panic!("{text}: {e}"));
            let result = run_query(&loaded.prepared, &options, &query);
            let mut count = 0;
            for tree in &trees {
                let [x, y] = tree.pixel;
                let expected = query.matches_tree(tree);
                assert_eq!(
                    result.mask[(y * width + x) as usize],
                    expected,
                    "{path}: `{text}` at ({x}, {y})"
                );
                count += usize::from(expected);
            }
            assert_eq!(result.matches.len(), count);
            for m in &result.matches {
                let [x, y] = m.pixel;
                let tree = &trees[(y * width + x) as usize];
                let deepest = tree.samples.iter().map(|s| s.root.deepest()).max();
                assert_eq!(Some(m.deepest), deepest, "{path}: `{text}` at ({x}, {y})");
            }
            // A matching pixel names the ray that shows it, unless it matches through `not`.
            for m in &result.matches {
                if !text.starts_with("not") && !text.starts_with("depth") {
                    assert!(m.witness.is_some(), "{path}: `{text}` at {:?}", m.pixel);
                }
            }
            if count > 0 {
                fired.insert(*text);
            }
            // `not` is the complement, pixel for pixel.
            let negated = Query::compile(&format!("not ({text})"), &loaded.scene).unwrap();
            let complement = run_query(&loaded.prepared, &options, &negated);
            assert!(result
                .mask
                .iter()
                .zip(&complement.mask)
                .all(|(a, b)| a != b));
        }
    }
    for needed in [
        "hit(\"fixed glass\")",
        "shadow_blocked",
        "shadow_blocked_by(\"fresnel glass\")",
        "depth >= 3",
        "tir",
        "max_depth",
        "weight_cutoff",
        "self_hit",
        "shadow_blocked_by_transparent",
        "self_hit and shadow_blocked_by(\"ball\")",
        "shadow_blocked_by(\"wall\") and hit(\"floor\")",
    ] {
        assert!(
            fired.contains(needed),
            "`{needed}` matched no pixel: {fired:?}"
        );
    }
}

#[test]
fn known_pixels_are_in_or_out_and_the_mask_is_the_list() {
    let dir = tempfile::tempdir().unwrap();
    let mask = dir.path().join("mask.png");
    // At 64x32 the fixed glass ball (on the image's left half) covers the left half's middle.
    let output = run(&[
        "query",
        "scenes/glass.scene",
        "hit(\"fixed glass\")",
        "--width",
        "64",
        "--height",
        "32",
        "--mask",
        mask.to_str().unwrap(),
        "--limit",
        "100000",
        "--json",
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let document: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let schema: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("docs/query.schema.json").unwrap()).unwrap();
    let errors = crate::json_schema::validate(&schema, &document);
    assert!(errors.is_empty(), "{errors:#?}");
    let mut broken = document.clone();
    broken["pixels"][0]["witness"]["ray"] = "sideways".into();
    assert!(!crate::json_schema::validate(&schema, &broken).is_empty());
    assert_eq!(document["image_size"], serde_json::json!([64, 32]));
    let listed: Vec<[u64; 2]> = document["pixels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            [
                p["pixel"][0].as_u64().unwrap(),
                p["pixel"][1].as_u64().unwrap(),
            ]
        })
        .collect();
    assert_eq!(document["count"].as_u64(), Some(listed.len() as u64));
    let image = image::open(&mask).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (64, 32));
    let white: Vec<[u64; 2]> = image
        .enumerate_pixels()
        .filter(|(_, _, p)| p.0 == [255, 255, 255])
        .map(|(x, y, _)| [u64::from(x), u64::from(y)])
        .collect();
    assert_eq!(white, listed);
    // Where the trace of a pixel hits the ball first, it is listed; the top corners see sky.
    let trace = |pixel: &str| {
        let output = run(&[
            "trace",
            "scenes/glass.scene",
            "--pixel",
            pixel,
            "--width",
            "64",
            "--height",
            "32",
            "--json",
        ]);
        let tree: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        tree["samples"][0]["root"]["hit"]["object"]["label"].clone()
    };
    let witness = &document["pixels"][0]["witness"];
    assert_eq!(witness["predicate"], "hit");
    assert_eq!(witness["object"], "fixed glass");
    let centre = listed[listed.len() / 2];
    assert_eq!(
        trace(&format!("{},{}", centre[0], centre[1])),
        "fixed glass"
    );
    assert!(!listed.contains(&[0, 0]) && !listed.contains(&[63, 0]));
    assert_eq!(trace("0,0"), serde_json::Value::Null);
}

#[test]
fn a_query_that_cannot_be_read_is_located_with_a_caret() {
    for (query, message, caret) in [
        (
            "tir and shadow_blokced",
            "did you mean `shadow_blocked`?",
            "          ^^^^^^^^^^^^^^",
        ),
        (
            "hit(\"fixed glas\")",
            "did you mean \"fixed glass\"?",
            "      ^^^^^^^^^^^^",
        ),
        ("depth >= ", "expected a whole number here", "           ^"),
        ("tir && nan", "write `and`", "      ^^"),
    ] {
        let output = run(&[
            "query",
            "scenes/glass.scene",
            query,
            "--width",
            "8",
            "--height",
            "8",
        ]);
        assert_eq!(output.status.code(), Some(2), "{query}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.starts_with("error: in the query: "), "{stderr}");
        assert!(stderr.contains(message), "{query}: {stderr}");
        assert_eq!(stderr.lines().last(), Some(caret), "{query}: {stderr}");
        assert!(output.stdout.is_empty());
    }
}

/// The debugger's query overlay (`:` in `whitted debug`) marks exactly the pixels that
/// `whitted query --mask` paints white, on the same scene.
#[test]
fn the_debuggers_query_overlay_is_the_mask_of_whitted_query() {
    use whitted_debugger::app::LoadedScene;
    use whitted_debugger::query_job::QueryState;

    let expr = "hit(\"mirror sphere\") and depth >= 3";
    let dir = tempfile::tempdir().unwrap();
    let mask = dir.path().join("mask.png");
    let output = run(&[
        "query",
        "scenes/whitted.scene",
        expr,
        "--width",
        "160",
        "--height",
        "120",
        "--mask",
        mask.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let image = image::open(&mask).unwrap().to_rgb8();

    let loaded = load("scenes/whitted.scene");
    let scene = LoadedScene::new(loaded.scene);
    let mut options = RenderOptions::from_settings(&scene.scene.settings);
    (options.width, options.height) = (160, 120);
    let mut state = QueryState::default();
    state
        .start(expr, &scene, &options, &scene.scene)
        .expect("the query compiles");
    let job = state.take_job().expect("a job");
    let overlay = job.run(&|| {}).expect("no crash").expect("not cancelled");
    let painted: Vec<bool> = image.pixels().map(|p| p.0 == [255, 255, 255]).collect();
    assert_eq!(overlay.mask, painted);
    let count = painted.iter().filter(|&&m| m).count();
    assert!(count > 0, "the query matches somewhere");
    assert_eq!(overlay.matches.len(), count);
}
