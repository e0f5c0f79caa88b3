//! `whitted fmt` over the fuzzer's scenes: thousands of generated and mutated scenes (with
//! the mesh files they read) compile to the same IR, locations aside, after formatting as
//! before; formatting them is idempotent and keeps every comment; a scene the formatter
//! refuses is one that does not compile.

use std::path::Path;

use whitted_lang::{compile_source, format_source, Compilation, CompileOptions, SourceLoader};
use xtask::fuzz::{self, case, Case};

/// About 10 ms a case in a debug build (two formats and two compilations): 12 s.
const CASES: u64 = 1200;
const SEED: u64 = 0xf0e7_5eed;

/// The case's own files by name; anything else is missing, before and after alike.
struct Files<'a>(&'a [(String, Vec<u8>)]);

impl SourceLoader for Files<'_> {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        self.0
            .iter()
            .find(|(file, _)| file == name)
            .map(|(_, bytes)| bytes.clone())
            .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"))
    }
}

fn compile(text: &str, case: &Case) -> Compilation {
    let options = CompileOptions {
        limits: case::limits(),
        ..CompileOptions::default()
    };
    compile_source("fuzz.scene", text, &mut Files(&case.files), &options)
}

/// The IR as `whitted ir` prints it, or the diagnostics, with `:line:column` removed.
fn outcome(compilation: &Compilation) -> String {
    let mut out = match &compilation.scene {
        Some(scene) => whitted_ir::print(scene),
        None => String::from("no scene\n"),
    };
    for d in &compilation.diagnostics {
        out.push_str(&format!("{:?}: {}\n", d.severity, d.message));
    }
    let mut plain = String::with_capacity(out.len());
    let mut chars = out.chars().peekable();
    while let Some(c) = chars.next() {
        plain.push(c);
        if c == ':' && chars.peek().is_some_and(char::is_ascii_digit) {
            while chars
                .peek()
                .is_some_and(|d| d.is_ascii_digit() || *d == ':')
            {
                chars.next();
            }
            plain.push('#');
        }
    }
    plain
}

/// Comments in order, read independently of the formatter.
fn comments(text: &str) -> Vec<String> {
    let (bytes, mut found, mut i) = (text.as_bytes(), Vec::new(), 0);
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' && bytes[i] != b'\n' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                let end = text[i..].find('\n').map_or(text.len(), |n| i + n);
                found.push(text[i..end].trim_end().to_string());
                i = end;
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                let end = text[i + 2..].find("*/").map_or(text.len(), |n| i + 4 + n);
                found.push(text[i..end].to_string());
                i = end;
            }
            _ => i += 1,
        }
    }
    found
}

#[test]
fn fmt_keeps_the_ir_of_generated_and_mutated_scenes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    let corpus = fuzz::corpus(&root);
    let (mut formatted_count, mut scenes) = (0, 0);
    for index in 0..CASES {
        let case = fuzz::make_case(SEED, index, &corpus);
        let name = format!("case {index} ({})", case.origin);
        let before = compile(&case.text, &case);
        let Ok(formatted) = format_source("fuzz.scene", &case.text) else {
            assert!(
                before.has_errors(),
                "{name} compiles, but the formatter refused it:\n{}",
                case.text
            );
            continue;
        };
        formatted_count += 1;
        assert_eq!(
            comments(&formatted),
            comments(&case.text),
            "{name}: the comments changed"
        );
        let again = format_source("fuzz.scene", &formatted).expect("formatted text parses");
        assert_eq!(again, formatted, "{name}: formatting is not idempotent");
        let after = compile(&formatted, &case);
        assert_eq!(
            outcome(&after),
            outcome(&before),
            "{name}: formatting changed what it compiles to\n--- before\n{}\n--- after\n{formatted}",
            case.text
        );
        scenes += usize::from(before.scene.is_some());
    }
    // With this seed 1,076 parse and 888 compile to a scene.
    assert!(
        formatted_count >= 1000,
        "only {formatted_count} cases parsed"
    );
    assert!(scenes >= 600, "only {scenes} cases compiled to a scene");
}
