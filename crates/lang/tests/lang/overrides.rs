//! `--set NAME=VALUE` (CompileOptions::settings): settings from the command line replace the
//! scene's, read and checked by the same rows of the property table as a `settings` block,
//! with diagnostics that point into the `--set` text.

use whitted_ir::{Highlight, ShadowMode};
use whitted_lang::{Compilation, CompileOptions};

use crate::support::*;

const SCENE: &str = "settings { max_depth 3 highlight phong width 320 }\nsphere { }\n";

fn with_settings(settings: &[(&str, &str)]) -> Compilation {
    let options = CompileOptions {
        settings: settings
            .iter()
            .map(|(name, value)| (name.to_string(), value.to_string()))
            .collect(),
        ..CompileOptions::default()
    };
    compile_with(SCENE, &mut MapLoader::default(), &options)
}

#[test]
fn set_replaces_what_the_scene_set_and_leaves_the_rest() {
    let compilation = with_settings(&[
        ("max_depth", "8"),
        ("highlight", "blinn"),
        ("background", "rgb(0, 0, 0.1 * 2)"),
        ("shadows", "filtered"),
    ]);
    let Some(scene) = compilation.scene else {
        panic!("{}", output(&compilation));
    };
    let s = &scene.settings;
    // The defaults keep the classic model.
    assert!(s.shade_back && s.attenuation_clamp);
    assert_eq!(s.max_depth, 8);
    assert_eq!(s.highlight, Highlight::Blinn);
    assert_eq!(s.shadows, ShadowMode::Filtered);
    assert!((s.background.b - 0.2).abs() < 1e-12 && s.background.r == 0.0);
    // Not overridden: the scene's own value stays.
    assert_eq!(s.width, 320);
}

#[test]
fn the_course_switches_are_settings() {
    let compilation = with_settings(&[
        ("shadows", "none"),
        ("shade_back", "off"),
        ("attenuation_clamp", "off"),
    ]);
    let Some(scene) = compilation.scene else {
        panic!("{}", output(&compilation));
    };
    let s = &scene.settings;
    assert_eq!(s.shadows, ShadowMode::None);
    assert!(!s.shade_back && !s.attenuation_clamp);
    let back_on = with_settings(&[("shade_back", "on")]);
    assert!(back_on.scene.is_some_and(|s| s.settings.shade_back));
    let wrong = with_settings(&[("shade_back", "yes")]);
    assert!(wrong.has_errors(), "shade_back yes was accepted");
}

/// Every setting the table has can be given on the command line, with a value taken from
/// its own row: a setting added to the table gets `--set` without more code.
#[test]
fn every_setting_of_the_docs_can_be_set() {
    let cases = [
        ("width", "100"),
        ("height", "50"),
        ("max_depth", "0"),
        ("min_weight", "0.5"),
        ("samples", "4"),
        ("background", "0.5"),
        ("ambient", "<0.1, 0.2, 0.3>"),
        ("epsilon", "0.01"),
        ("shadows", "filtered"),
        ("highlight", "blinn"),
        ("shade_back", "off"),
        ("attenuation_clamp", "off"),
    ];
    let docs = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/language.md"),
    )
    .unwrap_or_default();
    let settings_table = docs
        .split("| Property | Default | Allowed |")
        .nth(1)
        .and_then(|rest| rest.split("\n\n").next())
        .unwrap_or("");
    assert!(
        !settings_table.is_empty(),
        "no settings table in docs/language.md"
    );
    for (name, value) in cases {
        assert!(
            settings_table.contains(&format!("`{name}`")),
            "`{name}` is not in the docs' settings table"
        );
        let compilation = with_settings(&[(name, value)]);
        assert!(
            !compilation.has_errors(),
            "--set {name}={value}: {}",
            output(&compilation)
        );
    }
}

#[test]
fn bad_settings_on_the_command_line_point_into_their_text() {
    let cases: &[(&str, &[(&str, &str)])] = &[
        ("an unknown setting", &[("max_dept", "8")]),
        ("a property that is not a setting", &[("radius", "1")]),
        (
            "a word that is not one of the setting's",
            &[("highlight", "glossy")],
        ),
        ("a number out of range", &[("max_depth", "1000")]),
        ("not a whole number", &[("samples", "2.5")]),
        ("an unclosed bracket", &[("background", "rgb(0, 0")]),
        ("a name from the scene", &[("background", "sky")]),
        (
            "the same setting twice",
            &[("shadows", "filtered"), ("shadows", "opaque")],
        ),
    ];
    let mut out = String::new();
    for (title, settings) in cases {
        let compilation = with_settings(settings);
        assert!(compilation.has_errors(), "case `{title}` compiled");
        let given: Vec<String> = settings
            .iter()
            .map(|(n, v)| format!("--set {n}={v}"))
            .collect();
        out.push_str(&format!(
            "=== {title}\n{}\n---\n{}\n",
            given.join(" "),
            output(&compilation)
        ));
    }
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!("setting_overrides", out);
    });
}
