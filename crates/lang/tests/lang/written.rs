//! The scene's table of where settings and properties were written (`Scene::written`): the
//! spans explain and the debugger's write-back use instead of searching the text, checked
//! against the text itself in the places a text search is fooled (comments, strings, names
//! that contain a setting's name, loops, `--set`).

use whitted_ir::{BlockKind, Scene, Span};
use whitted_lang::CompileOptions;

use crate::support::*;

fn text(scene: &Scene, span: Span) -> &str {
    let file = scene.sources.get(span.file).expect("the span's file");
    &file.text[span.start as usize..span.end as usize]
}

const SCENE: &str = r#"// max_depth 1 in a line comment
/* settings { max_depth 2 } in a block comment */
let my_max_depth = 3;
settings {
    width 320 height 240
    max_depth my_max_depth + 1 // max_depth 9
    background rgb(0, 0, 0.1)
    shadows filtered
}
camera perspective { eye <0, 0, 5> fov 40 }
for i in 0..3 {
    light point { position <i, 4, 0> color 0.5 }
}
material glass { transmissive 0.9 ior 1.5 }
sphere { material glass }
"#;

#[test]
fn settings_and_properties_are_found_by_their_spans_not_by_their_text() {
    let compilation = compile_with(SCENE, &mut MapLoader::default(), &CompileOptions::default());
    let Some(scene) = compilation.scene else {
        panic!("{}", output(&compilation));
    };
    let depth = scene
        .written
        .setting("max_depth")
        .expect("max_depth is written");
    assert_eq!(text(&scene, depth.name_span), "max_depth");
    assert_eq!(text(&scene, depth.value_span), "my_max_depth + 1");
    assert_eq!(scene.sources.location(depth.name_span), "test.scene:6:5");
    let background = scene.written.setting("background").expect("written");
    assert_eq!(text(&scene, background.value_span), "rgb(0, 0, 0.1)");
    assert_eq!(
        text(
            &scene,
            scene
                .written
                .setting("shadows")
                .expect("written")
                .value_span
        ),
        "filtered"
    );
    assert!(
        scene.written.setting("min_weight").is_none(),
        "a default is not written"
    );
    let settings: Vec<_> = scene.written.settings_blocks().collect();
    assert_eq!(settings.len(), 1, "the commented-out block is not a block");
    let body = text(&scene, settings[0].body);
    assert!(body.starts_with('{') && body.ends_with('}'), "{body:?}");

    // The loop's light block is recorded once, with its one `color`.
    let (light, _) = scene.lights.iter().next().expect("lights");
    let header = scene.lights.span(light);
    let colors: Vec<_> = scene
        .written
        .properties_in(BlockKind::Light, header, "color")
        .collect();
    assert_eq!(colors.len(), 1);
    assert_eq!(text(&scene, colors[0].value_span), "0.5");

    let (glass, _) = scene
        .materials
        .iter()
        .find(|(_, m)| m.name.as_deref() == Some("glass"))
        .expect("glass");
    let ior: Vec<_> = scene
        .written
        .properties_in(BlockKind::Material, scene.materials.span(glass), "ior")
        .collect();
    assert_eq!(ior.len(), 1);
    assert_eq!(text(&scene, ior[0].value_span), "1.5");
    let fov = scene
        .written
        .properties_in(BlockKind::Camera, scene.camera_span, "fov")
        .next()
        .expect("fov");
    assert_eq!(text(&scene, fov.value_span), "40");
}

#[test]
fn a_setting_on_the_command_line_is_the_one_that_took_effect() {
    let options = CompileOptions {
        settings: vec![("max_depth".to_string(), "7".to_string())],
        ..CompileOptions::default()
    };
    let compilation = compile_with(SCENE, &mut MapLoader::default(), &options);
    let Some(scene) = compilation.scene else {
        panic!("{}", output(&compilation));
    };
    assert_eq!(scene.settings.max_depth, 7);
    let depth = scene.written.setting("max_depth").expect("written");
    assert_eq!(text(&scene, depth.value_span), "7");
    assert_eq!(text(&scene, depth.name_span), "max_depth");
    let file = scene.sources.get(depth.value_span.file).expect("file");
    assert!(file.path.starts_with("<--set"), "{}", file.path);
}
