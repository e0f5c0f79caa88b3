//! The debugger's write-back on scenes the language compiled: the scene's table of written
//! properties decides where a value goes (never a search of the text, which comments and
//! strings fool), a default is added to its block or a new `settings` block, and the edited
//! text compiles to the changed value (the oracle: the compiler, not the edit's own idea).

use whitted_debugger::what_if::write_back::{write_back, WriteBack};
use whitted_debugger::what_if::Param;
use whitted_ir::properties::{material_color, IOR};
use whitted_ir::setting_rows::{MAX_DEPTH, MIN_WEIGHT};
use whitted_ir::{Color, Handle, Material, Scene};
use whitted_lang::{compile_source, CompileOptions, SourceLoader};

struct NoFiles;

impl SourceLoader for NoFiles {
    fn load(&mut self, path: &std::path::Path) -> std::io::Result<Vec<u8>> {
        Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            path.display().to_string(),
        ))
    }
}

fn compiled(text: &str) -> Scene {
    let compilation = compile_source("edit.scene", text, &mut NoFiles, &CompileOptions::default());
    match compilation.scene {
        Some(scene) => scene.into_inner(),
        None => panic!("{:?}", compilation.diagnostics),
    }
}

fn material(scene: &Scene, name: &str) -> Handle<Material> {
    scene
        .materials
        .iter()
        .find(|(_, m)| m.name.as_deref() == Some(name))
        .map(|(h, _)| h)
        .expect("the material")
}

/// The edited text and its one changed line.
fn edited(outcome: WriteBack) -> (String, String) {
    match outcome {
        WriteBack::Edit {
            contents, new_line, ..
        } => (contents, new_line),
        WriteBack::Refused(why) => panic!("refused: {why}"),
    }
}

#[test]
fn comments_and_strings_that_mention_a_setting_are_not_where_it_is_written() {
    let text = "/* settings { max_depth 1 } */\n\
                let note = \"max_depth 4\";\n\
                settings {\n  width 64 height 48 // max_depth 7\n  max_depth 2\n}\n\
                sphere { }\n";
    let scene = compiled(text);
    let (contents, new_line) = edited(write_back(&scene, Param::setting(&MAX_DEPTH), "3"));
    assert_eq!(new_line, "max_depth 3");
    assert_eq!(contents, text.replace("  max_depth 2\n", "  max_depth 3\n"));
    assert_eq!(compiled(&contents).settings.max_depth, 3);

    let (contents, new_line) = edited(write_back(&scene, Param::setting(&MIN_WEIGHT), "0.01"));
    assert_eq!(new_line, "min_weight 0.01");
    let changed = compiled(&contents);
    assert_eq!(
        (changed.settings.min_weight, changed.settings.max_depth),
        (0.01, 2)
    );
}

#[test]
fn a_setting_not_written_anywhere_creates_the_settings_block() {
    let scene = compiled("// a bare scene\nsphere { }\n");
    let (contents, new_line) = edited(write_back(&scene, Param::setting(&MAX_DEPTH), "2"));
    assert_eq!(new_line, "settings { max_depth 2 }");
    assert_eq!(compiled(&contents).settings.max_depth, 2);
}

#[test]
fn a_material_default_goes_into_its_block_and_compiles_to_the_value() {
    let text = "material glass { ior 1.5 }\nmaterial tall {\n    diffuse 0.5\n}\n\
                sphere { material glass }\nsphere { center <3, 0, 0> material tall }\n";
    let scene = compiled(text);
    let glass = material(&scene, "glass");
    let reflective = material_color("reflective").expect("a row");
    let (contents, new_line) = edited(write_back(
        &scene,
        Param::material_color(glass, reflective),
        "0.5",
    ));
    assert_eq!(new_line, "material glass { ior 1.5 reflective 0.5 }");
    assert_eq!(
        compiled(&contents).materials[glass].reflective,
        Color::gray(0.5)
    );

    let tall = material(&scene, "tall");
    let (contents, new_line) = edited(write_back(
        &scene,
        Param::material_number(tall, &IOR),
        "1.33",
    ));
    assert_eq!(new_line, "ior 1.33");
    assert!(
        contents.contains("    diffuse 0.5\n    ior 1.33\n}"),
        "{contents}"
    );
    assert_eq!(compiled(&contents).materials[tall].ior, 1.33);
}

#[test]
fn a_setting_given_with_set_is_not_written_into_the_file() {
    let options = CompileOptions {
        settings: vec![("max_depth".into(), "7".into())],
        ..CompileOptions::default()
    };
    let compilation = compile_source(
        "edit.scene",
        "settings { max_depth 2 }\nsphere { }\n",
        &mut NoFiles,
        &options,
    );
    let scene = compilation.scene.expect("compiles").into_inner();
    let WriteBack::Refused(why) = write_back(&scene, Param::setting(&MAX_DEPTH), "3") else {
        panic!("refused");
    };
    assert!(why.contains("(--set max_depth=7)"), "{why}");
}
