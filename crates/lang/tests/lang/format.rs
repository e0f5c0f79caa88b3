//! `whitted fmt` (`format_source`) is safe: every scene in scenes/, every ```scene example of
//! the docs and thousands of re-spaced and mutated variants of them compile to the same IR
//! after formatting as before (locations aside), formatting is idempotent, every comment
//! survives, and a messy file's layout is pinned by a snapshot.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use whitted_lang::{
    compile_file, compile_source, format_source, CompileOptions, Limits, SourceLoader,
};

fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Reads files from the disk, formatted when `formatted` (imports included).
struct Loader {
    formatted: bool,
}

impl SourceLoader for Loader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        let bytes = std::fs::read(path)?;
        let is_scene = path.extension().is_some_and(|e| e == "scene");
        match (self.formatted && is_scene, String::from_utf8(bytes)) {
            (true, Ok(text)) => match format_source(&path.display().to_string(), &text) {
                Ok(formatted) => Ok(formatted.into_bytes()),
                Err(_) => Ok(text.into_bytes()),
            },
            (_, Ok(text)) => Ok(text.into_bytes()),
            (_, Err(error)) => Ok(error.into_bytes()),
        }
    }
}

/// Texts by name, each formatted when `formatted`.
struct MapLoader {
    files: HashMap<PathBuf, String>,
}

impl SourceLoader for MapLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        self.files
            .get(path)
            .map(|text| text.clone().into_bytes())
            .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "not found"))
    }
}

/// `file:line:column` and `line N` replaced: a formatted scene's objects are made at other
/// places of the text.
fn without_locations(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        out.push(c);
        if c == ':' && chars.peek().is_some_and(char::is_ascii_digit) {
            while chars
                .peek()
                .is_some_and(|d| d.is_ascii_digit() || *d == ':')
            {
                chars.next();
            }
            out.push('#');
        }
    }
    out
}

/// What a compilation produced, without locations: the IR as `whitted ir` prints it, or
/// the diagnostics' severities and messages.
fn outcome(compilation: &whitted_lang::Compilation) -> String {
    let mut out = match &compilation.scene {
        Some(scene) => whitted_ir::print(scene),
        None => String::from("no scene\n"),
    };
    for d in &compilation.diagnostics {
        out.push_str(&format!("{:?}: {}\n", d.severity, d.message));
    }
    without_locations(&out)
}

/// The comments of a scene text, in order (line comments without trailing whitespace): an
/// independent reading, so a comment the formatter lost or split shows here.
fn comments(text: &str) -> Vec<String> {
    let mut found = Vec::new();
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
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

/// Formats `text`; checks idempotence and comments, and returns the formatted text (None
/// when the text does not parse, which must then be refused).
fn format_checked(name: &str, text: &str) -> Option<String> {
    let formatted = format_source(name, text).ok()?;
    assert_eq!(
        comments(&formatted),
        comments(text),
        "{name}: the comments changed"
    );
    let again = format_source(name, &formatted)
        .unwrap_or_else(|f| panic!("{name}: the formatted text is refused: {:?}", f.diagnostics));
    assert_eq!(again, formatted, "{name}: formatting is not idempotent");
    assert!(
        !formatted
            .lines()
            .any(|l| l.ends_with(' ') || l.ends_with('\t')),
        "{name}: trailing whitespace"
    );
    Some(formatted)
}

fn scene_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            scene_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "scene") {
            out.push(path);
        }
    }
}

/// Every scene file of the repository that the formatter is meant for: scenes/ and the
/// scenes the tests keep.
fn repository_scenes() -> Vec<PathBuf> {
    let mut files = Vec::new();
    scene_files(&repository().join("scenes"), &mut files);
    scene_files(&repository().join("tests"), &mut files);
    files
}

/// The ```scene examples of every docs/*.md page.
fn docs_examples() -> Vec<(String, String)> {
    let mut examples = Vec::new();
    let mut pages: Vec<PathBuf> = std::fs::read_dir(repository().join("docs"))
        .expect("docs/ is readable")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    pages.sort();
    for page in pages {
        let markdown = std::fs::read_to_string(&page).expect("docs page is readable");
        let mut current: Option<(String, usize)> = None;
        for (number, line) in markdown.lines().enumerate() {
            match (&mut current, line.strip_prefix("```")) {
                (None, Some(info)) if info.trim() == "scene" => {
                    current = Some((String::new(), number + 1))
                }
                (Some((body, at)), Some(_)) => {
                    let name = format!("{}:{at}", page.display());
                    examples.push((name, std::mem::take(body)));
                    current = None;
                }
                (Some((body, _)), None) => {
                    body.push_str(line);
                    body.push('\n');
                }
                _ => {}
            }
        }
    }
    examples
}

#[test]
fn fmt_keeps_the_ir_of_every_repository_scene() {
    let files = repository_scenes();
    assert!(files.len() > 30, "only {} scenes found", files.len());
    for file in &files {
        let text = std::fs::read_to_string(file).expect("scene is readable");
        let name = file.display().to_string();
        // The benchmark scenes at a small size: the same code, a fraction of the objects.
        let defines = [("N", "10"), ("LEVEL", "1"), ("COUNT", "100")]
            .into_iter()
            .filter(|(constant, _)| text.contains(&format!("const {constant} =")))
            .map(|(constant, value)| (constant.to_string(), value.to_string()))
            .collect();
        let options = CompileOptions {
            defines,
            ..CompileOptions::default()
        };
        // Scenes the tests keep broken on purpose are refused; the rest are formatted. The
        // fuzzer's finds are formatted but not compiled: some take seconds by design.
        if format_checked(&name, &text).is_none() {
            assert!(
                compile_file(file, &mut Loader { formatted: false }, &options).has_errors(),
                "{name} compiles, but the formatter refused it"
            );
            continue;
        }
        if name.contains("fuzz-regressions") {
            continue;
        }
        let before = compile_file(file, &mut Loader { formatted: false }, &options);
        let after = compile_file(file, &mut Loader { formatted: true }, &options);
        assert_eq!(
            outcome(&after),
            outcome(&before),
            "{name}: formatting changed what it compiles to"
        );
    }
}

#[test]
fn fmt_keeps_the_ir_of_every_docs_example() {
    let examples = docs_examples();
    assert!(
        examples.len() > 20,
        "only {} examples found",
        examples.len()
    );
    for (name, text) in &examples {
        check_same_ir(name, text);
    }
}

/// The text and its formatted form compile alike (scene or diagnostics).
fn check_same_ir(name: &str, text: &str) -> bool {
    let Some(formatted) = format_checked(name, text) else {
        let mut loader = MapLoader {
            files: HashMap::new(),
        };
        let compiled = compile_source("example.scene", text, &mut loader, &small_limits());
        assert!(
            compiled.has_errors(),
            "{name} compiles, but the formatter refused it"
        );
        return false;
    };
    let options = small_limits();
    let mut loader = MapLoader {
        files: HashMap::new(),
    };
    let before = compile_source("example.scene", text, &mut loader, &options);
    let after = compile_source("example.scene", &formatted, &mut loader, &options);
    assert_eq!(
        outcome(&after),
        outcome(&before),
        "{name}: formatting changed what it compiles to\n--- before\n{text}\n--- after\n{formatted}"
    );
    before.scene.is_some()
}

/// A mutation can leave a loop without its end: the same small budgets on both sides keep
/// such a text quick, and it must stop the same way after formatting.
fn small_limits() -> CompileOptions {
    CompileOptions {
        limits: Limits {
            max_evaluation_steps: 100_000,
            max_objects: 20_000,
            ..Limits::default()
        },
        ..CompileOptions::default()
    }
}

/// A tiny fixed-seed generator (splitmix64), so every run checks the same variants.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// Where whitespace may change without changing the meaning: between two characters at
/// least one of which is whitespace, outside strings and comments.
fn respace(text: &str, rng: &mut Rng) -> String {
    const GAPS: &[&str] = &[
        " ",
        "  ",
        "\n",
        "\n\n",
        "\n\n\n",
        "\t",
        " \n    ",
        " /* c */ ",
        " // c\n",
        "\r\n",
    ];
    let mut out = String::with_capacity(text.len() * 2);
    let mut in_string = false;
    let mut in_line_comment = false;
    let mut in_block_comment = false;
    let mut chars = text.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        let rest = &text[i..];
        if in_line_comment {
            in_line_comment = c != '\n';
        } else if in_block_comment {
            if rest.starts_with("*/") {
                out.push_str("*/");
                chars.next();
                in_block_comment = false;
                continue;
            }
        } else if in_string {
            if c == '\\' {
                out.push(c);
                if let Some((_, escaped)) = chars.next() {
                    out.push(escaped);
                }
                continue;
            }
            in_string = c != '"';
        } else if c == '"' {
            in_string = true;
        } else if rest.starts_with("//") {
            in_line_comment = true;
        } else if rest.starts_with("/*") {
            in_block_comment = true;
        } else if (c == ' ' || c == '\n') && rng.below(4) == 0 {
            out.push_str(GAPS[rng.below(GAPS.len())]);
            continue;
        }
        out.push(c);
    }
    out
}

/// Statement-level mutations that keep most texts parseable: a line dropped, repeated or
/// joined to the next.
fn mutate(text: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    if lines.is_empty() {
        return String::new();
    }
    for _ in 0..=rng.below(3) {
        let at = rng.below(lines.len());
        match rng.below(3) {
            0 => {
                lines.remove(at);
            }
            1 => {
                let copy = lines[at].clone();
                lines.insert(at, copy);
            }
            _ if at + 1 < lines.len() && !lines[at].contains("//") => {
                let next = lines.remove(at + 1);
                lines[at] = format!("{} {}", lines[at], next.trim());
            }
            _ => {}
        }
        if lines.is_empty() {
            break;
        }
    }
    lines.join("\n")
}

#[test]
fn fmt_keeps_the_ir_of_thousands_of_respaced_and_mutated_scenes() {
    let mut corpus: Vec<(String, String)> = docs_examples();
    for file in repository_scenes() {
        let text = std::fs::read_to_string(&file).expect("scene is readable");
        // Files with imports compile differently alone; their texts still exercise layout.
        corpus.push((file.display().to_string(), text));
    }
    let mut rng = Rng(0x5eed_f0e7);
    let (mut formatted, mut with_scene) = (0, 0);
    for round in 0..60 {
        for (name, text) in &corpus {
            // Scenes made to be slow to compile (the benchmarks, the linter's big scene, the
            // fuzzer's finds) would take most of the time for no more layout.
            if text.len() > 20_000
                || ["bench", "big-scene", "fuzz-regressions"]
                    .iter()
                    .any(|s| name.contains(s))
            {
                continue;
            }
            let variant = if round % 2 == 0 {
                respace(text, &mut rng)
            } else {
                {
                    let mutated = mutate(text, &mut rng);
                    respace(&mutated, &mut rng)
                }
            };
            let label = format!("{name} (variant {round})");
            if format_source(&label, &variant).is_ok() {
                formatted += 1;
                with_scene += usize::from(check_same_ir(&label, &variant));
            }
        }
    }
    assert!(formatted >= 5000, "only {formatted} variants parsed");
    assert!(
        with_scene >= 2000,
        "only {with_scene} variants compiled to a scene"
    );
}

/// A file written carelessly, with every kind of comment in awkward places, and its layout.
const MESSY: &str = r#"// A messy scene.
settings{width 320 height 240   background #102040}
camera perspective {eye <0,2,-6> look_at<0 ,1,0>fov 45}   // aligned
light point "key"{position <5,8,-5>}     /* block */ light point { position <-5, 8, -5> color 0.3 }



material glass : base_glass {diffuse 0 specular 0.8 shininess 200 transmissive 0.9 ior 1.5 reflective 0.1 fresnel schlick}
fn ring(n,r){
for i in 0..n step 1{ sphere "bead {i}"{center <r*cos(i*360/n),0,r*sin(i*360/n)> radius 0.1
material { diffuse -(1 - 0.5) } }
}
}
fn sq(x)=x*x;
let colours=[red,blue,];
  // before the if
if sq(2)>=4&&!false{group{ box{ } scale <1, 2, 1> }}else if 1<2 {disk{radius colours[0].x}}
else{ /* empty */ }
ring(6, 2) { translate <0, - 1, 0>   // up
    rotate 30 about <1 , 1 , 0>
}
quadric { coefficients <1, 1, 1>,
  <0, 0, 0>, <0, 0, 0>, -1 }
"#;

#[test]
fn fmt_lays_out_a_messy_file() {
    let formatted = format_checked("messy.scene", MESSY).expect("the messy file parses");
    insta::assert_snapshot!(formatted);
}
