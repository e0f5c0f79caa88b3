//! Helpers shared by the tests: an in-memory loader, compile shortcuts, and the snapshot
//! `check` functions (IR dump for successes, rendered diagnostics for failures).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use whitted_ir::{DVec3, Scene, Shape};
use whitted_lang::{compile_source, render_diagnostics, Compilation, CompileOptions, SourceLoader};

/// Files by path, for imports; anything else is "not found".
#[derive(Default)]
pub struct MapLoader {
    pub files: HashMap<PathBuf, String>,
}

impl MapLoader {
    pub fn with(files: &[(&str, &str)]) -> Self {
        MapLoader {
            files: files
                .iter()
                .map(|(path, text)| (PathBuf::from(path), text.to_string()))
                .collect(),
        }
    }
}

impl SourceLoader for MapLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        self.files
            .get(path)
            .map(|text| text.clone().into_bytes())
            .ok_or_else(|| {
                std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory")
            })
    }
}

pub fn compile_with(input: &str, loader: &mut MapLoader, options: &CompileOptions) -> Compilation {
    compile_source("test.scene", input, loader, options)
}

pub fn compile(input: &str) -> Compilation {
    compile_with(input, &mut MapLoader::default(), &CompileOptions::default())
}

/// The IR dump when the scene compiles, then any rendered warnings and notes; or the
/// rendered diagnostics when it does not.
pub fn output(compilation: &Compilation) -> String {
    let mut out = String::new();
    if let Some(scene) = &compilation.scene {
        out.push_str(&whitted_ir::print(scene));
    }
    let rendered = render_diagnostics(&compilation.sources, &compilation.diagnostics, false);
    if !rendered.is_empty() {
        if !out.is_empty() {
            out.push_str("---\n");
        }
        out.push_str(&rendered);
    }
    // ariadne pads some lines with spaces; trim them so snapshots are stable and readable.
    out.lines()
        .map(str::trim_end)
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

/// Snapshot of the IR (or diagnostics) of one input.
pub fn check(name: &str, input: &str) {
    let compilation = compile(input);
    let text = format!("{input}\n=====\n{}", output(&compilation));
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!(name, text);
    });
}

/// Snapshot of several failing inputs, each with its rendered diagnostics. Every case must
/// fail (or at least warn): a case that compiles silently is a broken test.
pub fn check_errors(name: &str, cases: &[(&str, &str)]) {
    check_errors_with(name, cases, &[], &CompileOptions::default());
}

/// Like [`check_errors`], with files for imports and options (defines, limits).
pub fn check_errors_with(
    name: &str,
    cases: &[(&str, &str)],
    files: &[(&str, &str)],
    options: &CompileOptions,
) {
    let mut out = String::new();
    for (title, input) in cases {
        let compilation = compile_with(input, &mut MapLoader::with(files), options);
        assert!(
            !compilation.diagnostics.is_empty(),
            "case `{title}` gave no diagnostic:\n{input}"
        );
        out.push_str(&format!(
            "=== {title}\n{input}\n---\n{}\n",
            output(&compilation)
        ));
    }
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!(name, out);
    });
}

/// The compiled scene, or a panic showing the diagnostics.
pub fn scene(input: &str) -> Scene {
    let compilation = compile(input);
    match compilation.scene {
        Some(scene) => scene.into_inner(),
        None => panic!("did not compile:\n{}", output(&compilation)),
    }
}

/// The centre of the first sphere in a scene.
pub fn first_center(scene: &Scene) -> DVec3 {
    for (_, object) in scene.objects.iter() {
        if let Some(Shape::Sphere { center, .. }) = object.kind.shape() {
            return center;
        }
    }
    panic!("no sphere in the scene")
}

/// Evaluates a vector expression by compiling `sphere { center EXPR }`.
pub fn vector(expr: &str) -> DVec3 {
    first_center(&scene(&format!("sphere {{ center {expr} }}")))
}

/// Evaluates a number expression.
pub fn number(expr: &str) -> f64 {
    vector(&format!("<{expr}, 0, 0>")).x
}

/// Evaluates a boolean expression.
pub fn boolean(expr: &str) -> bool {
    let scene = scene(&format!(
        "if {expr} {{ sphere {{ }} }} else {{ box {{ }} }}"
    ));
    let is_sphere = matches!(
        scene
            .objects
            .iter()
            .next()
            .and_then(|(_, o)| o.kind.shape()),
        Some(Shape::Sphere { .. })
    );
    is_sphere
}
