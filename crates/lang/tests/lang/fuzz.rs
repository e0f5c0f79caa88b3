//! Thousands of broken inputs — mutated valid scenes, token soup, random bytes — and every one
//! must end in a scene or in diagnostics that point into the source, without a panic.

use proptest::prelude::*;
use whitted_ir::Severity;
use whitted_lang::{render_diagnostics, CompileOptions, Limits};

use crate::support::{compile_with, MapLoader};

/// Valid scenes to mutate: a few that use everything, plus the examples of the docs.
fn corpus() -> Vec<String> {
    let mut scenes = vec![
        include_str!("../../../../scenes/bench/grid.scene").to_string(),
        r#"settings { width 64 height 48 samples 2 shadows filtered background #102040 }
camera perspective { eye <0, 2, -6> look_at <0, 1, 0> fov 45 }
light point "key" { position <5, 8, -5> color white attenuation <1, 0, 0.01> }
light spot { position <0, 5, 0> direction <0, -1, 0> inner 15 outer 25 }
material glass { diffuse black specular 0.8 shininess 200 transmissive 0.9 ior 1.5 fresnel schlick }
material tinted : glass { absorption <0.3, 0.1, 0.1> }
material floor { diffuse checker(white, #202020, 1) { rotate <0, 45, 0> } }
fn ring(n, r) { for i in 0..n { sphere { center <r * cos(i * 360 / n), 0, r * sin(i * 360 / n)> radius 0.1 } } }
fn lerp(a, b, t) { return a + (b - a) * t; }
plane { normal <0, 1, 0> offset 0 material floor }
ring(6, lerp(1, 2, 0.5)) { material tinted translate <0, 1, 0> }
difference "d" { box { } sphere { radius 1.3 } cylinder { base <0, -2, 0> apex <0, 2, 0> radius 0.4 } rotate 30 about <1, 1, 0> }
group { disk { radius 2 } triangle { vertices <0, 0, 0>, <1, 0, 0>, <0, 1, 0> } scale <1, 2, 1> }
quadric { coefficients <1, 1, 1>, <0, 0, 0>, <0, 0, 0>, -1 matrix 1,0,0,1, 0,1,0,0, 0,0,1,0, 0,0,0,1 }
if 1 < 2 && !false { ellipsoid { radii <2, 1, 1> } } else { hyperboloid2 { } }
"#
        .to_string(),
    ];
    let docs = include_str!("../../../../docs/language.md");
    let mut inside = false;
    let mut current = String::new();
    for line in docs.lines() {
        if line.starts_with("```scene") {
            inside = true;
            current.clear();
        } else if line.starts_with("```") && inside {
            inside = false;
            scenes.push(current.clone());
        } else if inside {
            current.push_str(line);
            current.push('\n');
        }
    }
    scenes
}

const TOKENS: &[&str] = &[
    "[",
    "]",
    "step",
    "while",
    "\"{i}\"",
    "\"{",
    "len",
    "rand",
    "sphere",
    "box",
    "union",
    "difference",
    "group",
    "plane",
    "cone",
    "quadric",
    "{",
    "}",
    "(",
    ")",
    "<",
    ">",
    ",",
    ";",
    ".",
    "..",
    "..=",
    "=",
    "==",
    "+",
    "-",
    "*",
    "/",
    "%",
    "!",
    "&&",
    "||",
    "let",
    "const",
    "fn",
    "for",
    "in",
    "if",
    "else",
    "return",
    "import",
    "material",
    "light",
    "camera",
    "settings",
    "point",
    "perspective",
    "radius",
    "center",
    "translate",
    "rotate",
    "scale",
    "matrix",
    "about",
    "open",
    "diffuse",
    "checker(",
    "x",
    "n",
    "i",
    "0",
    "1",
    "2.5",
    "-1",
    "1e308",
    "0.0",
    "#ff8000",
    "\"name\"",
    "\"",
    "/*",
    "*/",
    "//",
    "\n",
    " ",
    "red",
    "pi",
    "sqrt(",
    "f(",
    "ring(",
    "glass",
    "true",
    "false",
    "ior",
    "vertices",
    "coefficients",
    "→",
    "é",
    "日本",
    "\u{0}",
    "\t",
    "\\",
    "#",
    "@",
    "'",
];

/// Small limits, so that a mutation that makes a huge loop ends quickly.
fn options() -> CompileOptions {
    CompileOptions {
        defines: Vec::new(),
        settings: Vec::new(),
        frame: None,
        // The editor's index is built for every fuzzed text too: it must not panic either.
        index: true,
        limits: Limits {
            max_objects: 5_000,
            max_evaluation_steps: 20_000,
            max_call_depth: 64,
            max_nesting: 64,
            max_import_depth: 8,
            max_imports: 100,
            max_source_bytes: 1 << 20,
            max_lights: 100,
            max_materials: 1_000,
            max_mesh_triangles: 10_000,
            max_scene_triangles: 100_000,
        },
    }
}

/// Compiles `input` and checks the outcome is a scene or located diagnostics.
fn check_outcome(input: &str) -> Result<(), TestCaseError> {
    let files = [("materials.scene", "material chrome { reflective 0.8 }\n")];
    let compilation = compile_with(input, &mut MapLoader::with(&files), &options());
    let errors = compilation
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .count();
    prop_assert_eq!(
        compilation.scene.is_some(),
        errors == 0,
        "scene iff no errors"
    );
    for diagnostic in &compilation.diagnostics {
        match diagnostic.span {
            Some(span) => {
                let file = compilation.sources.get(span.file);
                prop_assert!(
                    file.is_some(),
                    "span in an unknown file: {}",
                    diagnostic.message
                );
                let len = file.map_or(0, |f| f.text.len());
                prop_assert!(
                    span.start <= span.end && span.end as usize <= len,
                    "span {:?} outside its file ({} bytes): {}",
                    span,
                    len,
                    diagnostic.message
                );
            }
            // The only diagnostics that no source text made.
            None => prop_assert!(
                diagnostic.severity == Severity::Error
                    && diagnostic.message.starts_with("too many errors"),
                "a diagnostic without a span: {}",
                diagnostic.message
            ),
        }
    }
    // Rendering must cope with every span, too.
    let _ = render_diagnostics(&compilation.sources, &compilation.diagnostics, false);
    // So must an editor's questions: the index's spans are in their files, and the cursor
    // reader answers at every character of the text (a few, for a long one).
    if let Some(index) = &compilation.index {
        let spans = index
            .blocks
            .iter()
            .map(|b| b.span)
            .chain(index.links.iter().flat_map(|(from, to)| [*from, *to]));
        for span in spans {
            let len = compilation
                .sources
                .get(span.file)
                .map_or(0, |f| f.text.len());
            prop_assert!(
                span.start <= span.end && span.end as usize <= len,
                "{span:?}"
            );
        }
    }
    let step = (input.len() / 64).max(1);
    for offset in (0..=input.len()).step_by(step) {
        let _ = whitted_lang::editor::cursor::place_at(input, offset);
    }
    let _ = whitted_lang::editor::cursor::material_names(input);
    let _ = whitted_lang::editor::cursor::imports(input);
    Ok(())
}

#[derive(Debug, Clone)]
enum Mutation {
    Delete { at: usize, len: usize },
    Insert { at: usize, token: usize },
    Replace { at: usize, byte: u8 },
    Duplicate { at: usize, len: usize },
    Truncate { at: usize },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1usize..12).prop_map(|(at, len)| Mutation::Delete { at, len }),
        (any::<usize>(), 0..TOKENS.len()).prop_map(|(at, token)| Mutation::Insert { at, token }),
        (any::<usize>(), any::<u8>()).prop_map(|(at, byte)| Mutation::Replace { at, byte }),
        (any::<usize>(), 1usize..40).prop_map(|(at, len)| Mutation::Duplicate { at, len }),
        any::<usize>().prop_map(|at| Mutation::Truncate { at }),
    ]
}

fn apply(text: &str, mutations: &[Mutation]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for m in mutations {
        let n = bytes.len().max(1);
        match *m {
            Mutation::Delete { at, len } => {
                let at = at % n;
                let end = (at + len).min(bytes.len());
                if at < end {
                    bytes.drain(at..end);
                }
            }
            Mutation::Insert { at, token } => {
                let at = at % (bytes.len() + 1);
                let token = format!(" {} ", TOKENS[token]);
                bytes.splice(at..at, token.bytes());
            }
            Mutation::Replace { at, byte } => {
                if !bytes.is_empty() {
                    let at = at % bytes.len();
                    bytes[at] = byte;
                }
            }
            Mutation::Duplicate { at, len } => {
                let at = at % n;
                let end = (at + len).min(bytes.len());
                if at < end {
                    let copy: Vec<u8> = bytes[at..end].to_vec();
                    bytes.splice(end..end, copy);
                }
            }
            Mutation::Truncate { at } => bytes.truncate(at % n),
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_scenes_end_in_a_scene_or_located_errors(
        pick in any::<usize>(),
        mutations in proptest::collection::vec(mutation(), 1..6),
    ) {
        let corpus = corpus();
        let text = apply(&corpus[pick % corpus.len()], &mutations);
        check_outcome(&text)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn token_soup_ends_in_a_scene_or_located_errors(
        tokens in proptest::collection::vec(0..TOKENS.len(), 0..60),
    ) {
        let text: Vec<&str> = tokens.iter().map(|&t| TOKENS[t]).collect();
        check_outcome(&text.join(" "))?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_end_in_located_errors(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        check_outcome(&String::from_utf8_lossy(&bytes))?;
    }
}

#[test]
fn every_truncation_of_a_full_scene_ends_in_a_scene_or_located_errors() {
    let corpus = corpus();
    let text = &corpus[1];
    for end in 0..=text.len() {
        if text.is_char_boundary(end) {
            if let Err(failure) = check_outcome(&text[..end]) {
                panic!("truncated at byte {end}: {failure}");
            }
        }
    }
}
