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
        let kind = words.next();
        // ```obj NAME: a mesh file that later examples read; not a scene.
        if kind == Some("obj") {
            if let Some(name) = words.next() {
                loader.files.insert(PathBuf::from(name), body.clone());
            }
            continue;
        }
        if kind != Some("scene") {
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

/// The Limits table as `whitted_ir::limits::ALL` says it should read.
fn limits_table() -> String {
    let mut table =
        String::from("| Limit | Value | What it bounds |\n|-------|-------|----------------|\n");
    for limit in whitted_ir::limits::ALL {
        table.push_str(&format!(
            "| {} | {} | {} |\n",
            limit.name, limit.value, limit.what
        ));
    }
    table
}

#[test]
fn the_limits_section_lists_every_limit_once_with_its_value() {
    let markdown = language_md();
    let begin =
        "<!-- limits:begin (generated from whitted_ir::limits::ALL; a test checks it) -->\n";
    let end = "<!-- limits:end -->";
    let (Some(start), Some(stop)) = (markdown.find(begin), markdown.find(end)) else {
        panic!("docs/language.md has no limits table between `{begin}` and `{end}`");
    };
    let table = &markdown[start + begin.len()..stop];
    assert_eq!(
        table,
        limits_table(),
        "the limits table in docs/language.md is stale; replace it with:\n{}",
        limits_table()
    );
    // Anywhere else, a limit's value would be a second copy that could go stale: the rest
    // of the page refers to limits by name.
    let elsewhere = format!("{}{}", &markdown[..start], &markdown[stop..]);
    for limit in whitted_ir::limits::ALL {
        let value = limit.value.to_string();
        let plain = value.replace(',', "");
        for written in [value.as_str(), plain.as_str()] {
            // Small values (1, 256 as a colour channel) are too common to mean the limit.
            if plain.len() < 4 && !written.contains('e') {
                continue;
            }
            let found = elsewhere.match_indices(written).find(|&(at, _)| {
                let before = elsewhere[..at].chars().next_back();
                let after = elsewhere[at + written.len()..].chars().next();
                let digit =
                    |c: Option<char>| c.is_some_and(|c| c.is_ascii_digit() || c == '.' || c == ',');
                !digit(before) && !digit(after)
            });
            assert!(
                found.is_none(),
                "docs/language.md writes the {} limit's value {written} outside the Limits table",
                limit.name
            );
        }
    }
}

/// The settings table in docs/language.md has a line for every setting of the IR's table,
/// with the row's default: a setting added to the table and not to the docs fails here.
#[test]
fn the_settings_table_lists_every_setting_with_its_default() {
    let markdown = language_md();
    let start = markdown.find("## Settings").expect("a Settings section");
    let section = &markdown[start..];
    let section = &section[..section[3..].find("\n## ").map_or(section.len(), |i| i + 3)];
    let lines: Vec<&str> = section.lines().filter(|l| l.starts_with("| `")).collect();
    for row in whitted_ir::setting_rows::SETTINGS {
        let name = format!("`{}`", row.name);
        let line = lines
            .iter()
            .find(|l| l.split('|').nth(1).is_some_and(|cell| cell.contains(&name)))
            .unwrap_or_else(|| panic!("docs/language.md's settings table has no {name}"));
        assert!(
            line.split('|')
                .nth(2)
                .is_some_and(|d| d.contains(row.default)),
            "{name}'s default is {} but the docs say: {line}",
            row.default
        );
    }
}
