//! Budgets that bound work and memory (evaluation steps, lights, materials, imports), and the
//! messages of issue 10: text that is not UTF-8, control characters, `-D` given twice.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use whitted_lang::{
    compile_bytes, compile_source, render_diagnostics, Compilation, CompileOptions, Limits,
    SourceLoader,
};

use crate::support::*;

fn with_limits(limits: Limits) -> CompileOptions {
    CompileOptions {
        limits,
        ..CompileOptions::default()
    }
}

/// The errors of a compilation; each must have a place.
fn errors_in(compilation: &Compilation) -> Vec<String> {
    let errors: Vec<_> = compilation
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .collect();
    for error in &errors {
        assert!(error.span.is_some(), "no place: {}", error.message);
    }
    errors.iter().map(|d| d.message.clone()).collect()
}

#[test]
fn doubling_recursion_stops_at_the_evaluation_steps_limit() {
    // Issue 10: this ran for days, since calls counted against no limit (2^41 calls).
    let input = "fn f(n) { if n > 0 { f(n-1) f(n-1) } }\nf(40)";
    let options = with_limits(Limits {
        max_evaluation_steps: 5_000,
        ..Limits::default()
    });
    let compilation = compile_with(input, &mut MapLoader::default(), &options);
    let errors = errors_in(&compilation);
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].starts_with("the evaluation steps limit (5000 loop iterations and calls in total) was reached when calling `f`"),
        "{}",
        errors[0]
    );
    let place = compilation.diagnostics[0]
        .span
        .map(|s| compilation.sources.location(s));
    // The second call of some level is the one that crosses the budget.
    assert_eq!(place.as_deref(), Some("test.scene:1:29"));
}

#[test]
fn loops_and_calls_share_one_budget() {
    let options = with_limits(Limits {
        max_evaluation_steps: 100,
        ..Limits::default()
    });
    // Iterations count when their loop starts, calls as they are made: 51 + 51 steps.
    let input = "fn g() { sphere { } }\nfor i in 0..51 { g() }";
    let errors = errors_in(&compile_with(input, &mut MapLoader::default(), &options));
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].contains("evaluation steps limit (100"),
        "{}",
        errors[0]
    );
    // 50 + 50 steps is exactly the budget.
    let fine = "fn g() { sphere { } }\nfor i in 0..50 { g() }";
    let compilation = compile_with(fine, &mut MapLoader::default(), &options);
    assert_eq!(compilation.scene.map(|s| s.objects.len()), Some(50));
}

#[test]
fn lights_stop_at_the_lights_limit() {
    // Issue 10: 100M lights aborted the process. At the default limits this stops after
    // 10,000 lights.
    let input = "for i in 0..100000000 { light point { position <i, 0, 0> } }";
    let compilation = compile(input);
    let errors = errors_in(&compilation);
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0], "the lights limit (10000) was reached");
    let options = with_limits(Limits {
        max_lights: 3,
        ..Limits::default()
    });
    let three = "for i in 0..3 { light point { position <i, 0, 0> } }";
    assert!(compile_with(three, &mut MapLoader::default(), &options)
        .scene
        .is_some());
    let four = "for i in 0..4 { light point { position <i, 0, 0> } }";
    let errors = errors_in(&compile_with(four, &mut MapLoader::default(), &options));
    assert_eq!(errors, ["the lights limit (3) was reached"]);
}

#[test]
fn materials_stop_at_the_materials_limit() {
    // Issue 10: 20M materials passed at 6.6 GiB. Inline materials, named materials in a
    // loop, and the two materials a colour pattern makes all count.
    let options = with_limits(Limits {
        max_materials: 10,
        ..Limits::default()
    });
    for input in [
        "for i in 0..20000000 { sphere { material { diffuse <1, 0, 0> } } }",
        "for i in 0..20000000 { let m = material { diffuse <1, 0, 0> }; }",
        "for i in 0..20000000 { sphere { material { diffuse checker(red, blue, 1) } } }",
    ] {
        let errors = errors_in(&compile_with(input, &mut MapLoader::default(), &options));
        assert_eq!(errors, ["the materials limit (10) was reached"], "{input}");
    }
    let ten = "for i in 0..10 { sphere { material { diffuse <1, 0, 0> } } }";
    assert!(compile_with(ten, &mut MapLoader::default(), &options)
        .scene
        .is_some());
}

/// A file system with one folder `dir` holding `a.scene` and a link `dir/loop` back to
/// `dir`, as `ln -s . dir/loop` makes: any number of `loop/` segments name the same file.
struct LinkLoopLoader {
    loads: usize,
    follow_links: bool,
}

fn unlooped(path: &Path) -> PathBuf {
    path.components()
        .filter(|c| c.as_os_str() != "loop")
        .collect()
}

impl SourceLoader for LinkLoopLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        self.loads += 1;
        if unlooped(path) == Path::new("dir/a.scene") {
            Ok(b"import \"loop/a.scene\"\nimport \"loop/loop/a.scene\"\nsphere { }\n".to_vec())
        } else {
            Err(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "not found",
            ))
        }
    }

    fn identify(&mut self, path: &Path) -> PathBuf {
        if self.follow_links {
            unlooped(path)
        } else {
            path.to_path_buf()
        }
    }
}

#[test]
fn an_import_through_a_folder_link_loop_is_one_cycle() {
    let mut loader = LinkLoopLoader {
        loads: 0,
        follow_links: true,
    };
    let text = "import \"dir/a.scene\"";
    let compilation = compile_source("main.scene", text, &mut loader, &CompileOptions::default());
    let errors = errors_in(&compilation);
    // One cycle per import line in a.scene, each once.
    assert_eq!(errors.len(), 2, "{errors:?}");
    assert!(
        errors.iter().all(|e| e.starts_with("import cycle")),
        "{errors:?}"
    );
    assert_eq!(loader.loads, 1);
    // The proof that the identity is what stops the fan-out: without it, every path is a
    // new file and each file imports two more (issue 10: 1.3M errors). The imports limit
    // still bounds that case.
    let mut blind = LinkLoopLoader {
        loads: 0,
        follow_links: false,
    };
    let options = with_limits(Limits {
        max_imports: 50,
        ..Limits::default()
    });
    let compilation = compile_source("main.scene", text, &mut blind, &options);
    let errors = errors_in(&compilation);
    assert!(blind.loads <= 50, "{} loads", blind.loads);
    assert!(
        errors
            .iter()
            .any(|e| e.starts_with("the imports limit (50 files in one compilation)")),
        "{errors:?}"
    );
    assert!(errors.len() <= 3, "{errors:?}");
}

#[test]
fn text_that_is_not_utf8_is_an_error_at_the_first_bad_byte() {
    let bytes = b"sphere { }\nbox { }\n// caf\xe9\nsphere { }\n";
    let compilation = compile_bytes(
        "latin1.scene",
        bytes,
        &mut MapLoader::default(),
        &CompileOptions::default(),
    );
    let error = compilation
        .diagnostics
        .iter()
        .find(|d| d.is_error())
        .expect("an error");
    assert_eq!(
        error.message,
        "`latin1.scene` is not UTF-8 text: byte 0xe9 here is not part of a character"
    );
    let place = error.span.map(|s| compilation.sources.location(s));
    assert_eq!(place.as_deref(), Some("latin1.scene:3:7"));
    // An imported file too, at its own line.
    let mut loader = Bytes(HashMap::from([(
        PathBuf::from("lib.scene"),
        b"\n\n  \xff".to_vec(),
    )]));
    let compilation = compile_source(
        "main.scene",
        "import \"lib.scene\"",
        &mut loader,
        &CompileOptions::default(),
    );
    let error = compilation
        .diagnostics
        .iter()
        .find(|d| d.is_error())
        .expect("an error");
    let place = error.span.map(|s| compilation.sources.location(s));
    assert_eq!(place.as_deref(), Some("lib.scene:3:3"));
}

struct Bytes(HashMap<PathBuf, Vec<u8>>);

impl SourceLoader for Bytes {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        self.0
            .get(path)
            .cloned()
            .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "not found"))
    }
}

#[test]
fn control_characters_are_escaped_in_diagnostics() {
    // Issue 10: an ESC in a string reached the terminal (and the plain-text renderer then
    // ate the sequence, mangling the message).
    let input = "sphere \"red\x1b[31mname\x07\r\x08\" { radius -1 }";
    let compilation = compile(input);
    for color in [false, true] {
        let raw = render_diagnostics(&compilation.sources, &compilation.diagnostics, color);
        // With colour on, ariadne colours each character: read the text between colours.
        let text = strip_colours(&raw);
        assert!(!raw.contains(['\x07', '\r', '\x08']), "{raw:?}");
        assert!(
            text.contains("sphere \"red\\u{1b}[31mname\\u{7}\\u{d}\\u{8}\""),
            "{text}"
        );
        // The place is the one in the file, not in the escaped line.
        assert!(text.contains("test.scene:1:35 ]"), "{text}");
        for control in ['\x07', '\r', '\x08'] {
            assert!(!text.contains(control), "{text:?}");
        }
        if !color {
            assert!(!text.contains('\x1b'), "{text:?}");
        }
        // The underline still sits under the value it points at, after the escapes.
        assert!(text.contains("radius -1"), "{text}");
    }
}

#[test]
fn a_define_given_twice_is_an_error_naming_both() {
    let options = CompileOptions {
        defines: vec![("N".into(), "5".into()), ("N".into(), "6".into())],
        ..CompileOptions::default()
    };
    let compilation = compile_with(
        "const N = 1;\nsphere { radius N }",
        &mut MapLoader::default(),
        &options,
    );
    let errors = errors_in(&compilation);
    assert_eq!(errors, ["`-D N` is given twice: `-D N=5` and `-D N=6`"]);
}

#[test]
fn a_flat_sum_of_a_million_terms_is_refused_by_the_lexical_pass() {
    // Issue 10: a 64 MiB sum took 93 s and 7.7 GB in pest before the depth limit refused it.
    // The message is the lexical pass's, so pest never ran.
    let input = format!("sphere {{ radius 1{} }}", " + 1".repeat(1_000_000));
    let errors = errors_in(&compile(&input));
    assert_eq!(errors.len(), 1);
    assert!(
        errors[0].starts_with("this expression is too long: more than 4096 operators"),
        "{}",
        errors[0]
    );
    // Many short expressions in one block are not a run.
    let many = format!(
        "sphere {{ {} }}",
        "center <1 + 1, 2 * 2, -3> ".to_string() + &"rotate <1 + 2, 0, 0> ".repeat(3000)
    );
    assert!(errors_of_ok(&many));
}

fn errors_of_ok(input: &str) -> bool {
    !compile(input).has_errors()
}

/// `text` without ANSI colour sequences (`ESC [ ... m`).
fn strip_colours(text: &str) -> String {
    let mut out = String::new();
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        if c == '\x1b' {
            for c in chars.by_ref() {
                if c == 'm' {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

#[test]
fn a_long_line_is_shown_only_around_the_error() {
    // A one-line 4 MB sum used to be printed whole under its error; 64 MiB would be too.
    let input = format!("sphere {{ radius 1{} }}", " + 1".repeat(1_000_000));
    let compilation = compile(&input);
    let text = render_diagnostics(&compilation.sources, &compilation.diagnostics, false);
    assert!(text.len() < 2_000, "{} bytes", text.len());
    assert!(text.contains("test.scene:1:16403 ]"), "{text}");
    assert!(text.contains("…"), "{text}");
    // The underline sits under the `+` it names: same column in the shown line.
    let lines: Vec<&str> = text.lines().collect();
    let row = lines
        .iter()
        .position(|l| l.starts_with(" 1 |"))
        .expect("the source line");
    let marker = lines[row + 1];
    // Past the gutter (`   |`), the one-character span is marked with `|`.
    let column = marker
        .chars()
        .skip(4)
        .position(|c| c == '|')
        .expect("a marker")
        + 4;
    assert_eq!(lines[row].chars().nth(column), Some('+'), "{text}");
}
