//! docs/language.md cannot rot: every ```scene block in it is compiled here and must compile
//! without errors, and the rendered error it shows must be what the compiler prints.

use std::path::PathBuf;

use whitted_lang::{compile_source, render_diagnostics, CompileOptions};

use crate::support::MapLoader;

fn language_md() -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../docs/language.md");
    match std::fs::read_to_string(&path) {
        Ok(text) => text,
        Err(error) => panic!("cannot read {}: {error}", path.display()),
    }
}

/// The fenced blocks of a Markdown text: (info string, body, line of the opening fence).
fn fenced_blocks(markdown: &str) -> Vec<(String, String, usize)> {
    let mut blocks = Vec::new();
    let mut current: Option<(String, String, usize)> = None;
    for (number, line) in markdown.lines().enumerate() {
        match (&mut current, line.strip_prefix("```")) {
            (None, Some(info)) => {
                current = Some((info.trim().to_string(), String::new(), number + 1))
            }
            (Some(_), Some(_)) => blocks.extend(current.take()),
            (Some((_, body, _)), None) => {
                body.push_str(line);
                body.push('\n');
            }
            (None, None) => {}
        }
    }
    blocks
}

#[test]
fn every_scene_example_compiles() {
    let markdown = language_md();
    let mut loader = MapLoader::default();
    let mut compiled = 0;
    for (info, body, line) in fenced_blocks(&markdown) {
        let mut words = info.split_whitespace();
        if words.next() != Some("scene") {
            continue;
        }
        // ```scene NAME: a file that later examples import.
        if let Some(name) = words.next() {
            loader.files.insert(PathBuf::from(name), body.clone());
        }
        let name = format!("language.md:{line}");
        let compilation = compile_source(&name, &body, &mut loader, &CompileOptions::default());
        let errors: Vec<_> = compilation
            .diagnostics
            .iter()
            .filter(|d| d.is_error())
            .cloned()
            .collect();
        assert!(
            errors.is_empty(),
            "the example at docs/language.md line {line} does not compile:\n{}",
            render_diagnostics(&compilation.sources, &errors, false)
        );
        compiled += 1;
    }
    assert!(
        compiled >= 25,
        "only {compiled} examples found; is the fence syntax right?"
    );
}

#[test]
fn the_rendered_error_in_the_docs_is_what_the_compiler_prints() {
    let compilation = compile_source(
        "scene.scene",
        "sphere { centre <0, 0, 0> radius 1 }\n",
        &mut MapLoader::default(),
        &CompileOptions::default(),
    );
    let rendered = render_diagnostics(&compilation.sources, &compilation.diagnostics, false);
    let trim = |text: &str| {
        text.lines()
            .map(str::trim_end)
            .collect::<Vec<_>>()
            .join("\n")
    };
    let markdown = language_md();
    let shown = fenced_blocks(&markdown)
        .into_iter()
        .find(|(info, body, _)| info == "text" && body.contains("centre"))
        .map(|(_, body, _)| body)
        .expect("the docs show a rendered error");
    assert_eq!(trim(&shown), trim(&rendered));
}
