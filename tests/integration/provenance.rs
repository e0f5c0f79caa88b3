//! The instantiation stack (issue 12, item 2) through the real binary: a sphere made by a
//! loop inside a function from an imported file, called inside a loop, shows its loop value,
//! the call with its arguments and line, the outer loop's value and the import line in
//! `whitted ir` (text and JSON) and in `whitted trace` (text and JSON).

use std::path::PathBuf;
use std::process::{Command, Output};

use serde_json::{json, Value};

use crate::json_schema::validate;

const SCENE: &str = "scenes/provenance/main.scene";
/// Where bead 7 (i = 7) of the middle ring (k = 1), object #19, is seen.
const PIXEL: &str = "38,27";
/// The stack of bead 7 of the middle ring, as the text forms write it.
const STACK: &str = "i = 7 at scenes/provenance/lib.scene:6:5, \
    import at scenes/provenance/main.scene:5:1, \
    ring(12, 2) at scenes/provenance/main.scene:12:5, \
    k = 1 at scenes/provenance/main.scene:11:1";

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(args: &[&str]) -> String {
    let output: Output = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(workspace())
        .env("NO_COLOR", "1")
        .args(args)
        .output()
        .expect("the whitted binary runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The JSON steps of bead 7 of the middle ring, innermost first.
fn expected_steps() -> Value {
    json!([
        { "kind": "loop", "text": "i = 7", "location": "scenes/provenance/lib.scene:6:5",
          "var": "i", "value": 7.0 },
        { "kind": "import", "text": "import", "location": "scenes/provenance/main.scene:5:1" },
        { "kind": "call", "text": "ring(12, 2)", "location": "scenes/provenance/main.scene:12:5",
          "function": "ring", "args": [{ "name": "n", "value": "12" }, { "name": "r", "value": "2" }] },
        { "kind": "loop", "text": "k = 1", "location": "scenes/provenance/main.scene:11:1",
          "var": "k", "value": 1.0 },
    ])
}

/// Drops the keys that are `null` (the ray tree writes every key; `whitted ir` only those
/// that apply), so both forms compare with one expectation.
fn without_nulls(steps: &Value) -> Value {
    let steps = steps.as_array().expect("made_by is an array");
    Value::Array(
        steps
            .iter()
            .map(|step| {
                let object = step.as_object().expect("a step is an object");
                Value::Object(
                    object
                        .iter()
                        .filter(|(_, value)| !value.is_null())
                        .map(|(key, value)| (key.clone(), value.clone()))
                        .collect(),
                )
            })
            .collect(),
    )
}

#[test]
fn ir_text_shows_the_stack_of_every_object_made_in_a_loop_call_or_import() {
    let text = run(&["ir", SCENE]);
    let line = text
        .lines()
        .find(|line| line.starts_with("object #19 \"bead 7\""))
        .expect("object #19 is bead 7");
    assert!(line.ends_with(&format!("  made by {STACK}")), "{line}");
    // The first ring's bead 7 differs only in the outer loop's value.
    let first = text
        .lines()
        .find(|line| line.starts_with("object #7 \"bead 7\""))
        .expect("object #7 is bead 7 of the first ring");
    assert!(
        first.ends_with("k = 0 at scenes/provenance/main.scene:11:1"),
        "{first}"
    );
}

#[test]
fn objects_at_the_top_level_of_the_root_file_have_no_stack() {
    let text = run(&["ir", "scenes/whitted.scene"]);
    assert!(text.lines().any(|line| line.starts_with("object ")));
    assert!(!text.contains("made by"), "{text}");
    let json: Value = serde_json::from_str(&run(&["ir", "--json", "scenes/whitted.scene"]))
        .expect("ir --json prints JSON");
    let objects = json["objects"].as_array().expect("objects");
    assert!(objects.iter().all(|o| o.get("made_by").is_none()));
}

#[test]
fn ir_json_gives_the_object_its_made_by_steps() {
    let json: Value =
        serde_json::from_str(&run(&["ir", "--json", SCENE])).expect("ir --json prints JSON");
    let object = &json["objects"][19];
    assert_eq!(object["name"], "bead 7");
    assert_eq!(object["made_by"], expected_steps());
}

#[test]
fn trace_text_shows_the_stack_of_the_hit_object() {
    let text = run(&["trace", SCENE, "--pixel", PIXEL]);
    let lines: Vec<&str> = text.lines().collect();
    let object = lines
        .iter()
        .position(|line| line.contains("object     bead 7 (sphere #19,"))
        .unwrap_or_else(|| panic!("the camera ray hits bead 7 of the middle ring:\n{text}"));
    let made_by = lines[object + 1];
    assert!(
        made_by.ends_with(&format!("made by    {STACK}")),
        "{made_by}"
    );
    // docs/ray-tree.md shows this very line.
    let doc = std::fs::read_to_string(workspace().join("docs/ray-tree.md")).expect("the doc");
    assert!(
        doc.contains(&format!("\n{made_by}\n")),
        "docs/ray-tree.md's `made by` example is out of date: it should be\n{made_by}"
    );
}

#[test]
fn trace_json_gives_the_hit_object_its_stack_and_matches_the_schema() {
    let text = run(&["trace", SCENE, "--pixel", PIXEL, "--json"]);
    let json: Value = serde_json::from_str(&text).expect("trace --json prints JSON");
    let schema: Value = serde_json::from_str(
        &std::fs::read_to_string(workspace().join("docs/ray-tree.schema.json"))
            .expect("docs/ray-tree.schema.json"),
    )
    .expect("the schema is JSON");
    let errors = validate(&schema, &json);
    assert!(errors.is_empty(), "{errors:#?}");
    let object = &json["root"]["hit"]["object"];
    assert_eq!(object["label"], "bead 7");
    assert_eq!(object["handle"], 19);
    assert_eq!(without_nulls(&object["made_by"]), expected_steps());
    // Keys that do not apply are null, never absent.
    assert_eq!(object["made_by"][1]["var"], Value::Null);
    assert_eq!(object["made_by"][0]["args"], Value::Null);
}

/// `whitted explain` names the bead it explains by where it came from: a `made by` line in
/// the text, and `made_by` on the path's step in the JSON.
#[test]
fn explain_shows_the_stack_of_the_object_it_names() {
    let text = run(&["explain", SCENE, "--pixel", PIXEL]);
    assert!(
        text.contains(&format!("made by:\n  bead 7: {STACK}\n")),
        "{text}"
    );
    let json: Value = serde_json::from_str(&run(&["explain", SCENE, "--pixel", PIXEL, "--json"]))
        .expect("explain --json is JSON");
    let schema: Value = serde_json::from_str(
        &std::fs::read_to_string(workspace().join("docs/explain.schema.json"))
            .expect("the explain schema"),
    )
    .expect("the explain schema is JSON");
    let errors = validate(&schema, &json);
    assert!(errors.is_empty(), "{errors:?}");
    let first_step = &json["contributions"][0]["path"][0];
    assert_eq!(first_step["object"], json!("bead 7"));
    assert_eq!(
        first_step["made_by"],
        json!([
            "i = 7 at scenes/provenance/lib.scene:6:5",
            "import at scenes/provenance/main.scene:5:1",
            "ring(12, 2) at scenes/provenance/main.scene:12:5",
            "k = 1 at scenes/provenance/main.scene:11:1"
        ])
    );
}
