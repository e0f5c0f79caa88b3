//! The server in-process: completion in every kind of place (the cursor marked `|` in the
//! text), hover on text that does not parse, diagnostics across an open import and for a
//! 6.837 scene, and a fixed-seed run of random edits and requests that must never fail (and
//! whose every semantic tokens range must be the whole document's tokens there).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use lsp_server::Notification;
use lsp_types::{Position, Url};
use serde_json::{json, Value};

use crate::position::LineIndex;
use crate::{Files, Server};

/// Files in memory: what the server may read besides the open documents.
#[derive(Default)]
struct Memory(HashMap<PathBuf, Vec<u8>>);

impl Files for Memory {
    fn read(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        self.0
            .get(path)
            .cloned()
            .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::NotFound))
    }
}

fn uri(name: &str) -> Url {
    Url::parse(&format!("file:///project/{name}")).expect("a URI")
}

fn open(server: &mut Server, name: &str, text: &str) -> Vec<Notification> {
    server.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri(name), "languageId": "whitted", "version": 1, "text": text}}),
    );
    server.analyze_changed()
}

fn request(server: &mut Server, method: &str, params: Value) -> Value {
    let (result, _) = server.request(method, params);
    result.unwrap_or_else(|e| panic!("{method}: {}", e.message))
}

fn position_params(name: &str, text: &str, offset: usize) -> Value {
    let position = LineIndex::new(text).position(text, offset);
    json!({"textDocument": {"uri": uri(name)}, "position": position})
}

/// The labels completion offers at `|` in `marked`.
fn completions(marked: &str) -> Vec<String> {
    let offset = marked.find('|').expect("a cursor");
    let text = marked.replacen('|', "", 1);
    let mut server = Server::new(Box::new(Memory::default()));
    open(&mut server, "a.scene", &text);
    let result = request(
        &mut server,
        "textDocument/completion",
        position_params("a.scene", &text, offset),
    );
    result
        .as_array()
        .expect("a list")
        .iter()
        .map(|item| item["label"].as_str().expect("a label").to_string())
        .collect()
}

fn has(labels: &[String], name: &str) -> bool {
    labels.iter().any(|l| l == name)
}

#[test]
fn an_object_offers_its_own_properties_then_transforms_and_material() {
    let labels = completions("sphere { | }");
    assert_eq!(labels[..2], ["center", "radius"]);
    for name in ["translate", "rotate", "scale", "matrix", "material"] {
        assert!(has(&labels, name), "{name} in {labels:?}");
    }
    assert!(
        !has(&labels, "ambient") && !has(&labels, "open"),
        "{labels:?}"
    );
    assert!(has(&completions("cone { | }"), "open"));
}

#[test]
fn written_properties_are_left_out_but_transforms_repeat() {
    let labels = completions("sphere { radius 1 translate <1, 0, 0> | center <0, 0, 0> }");
    assert!(
        !has(&labels, "radius") && !has(&labels, "center"),
        "{labels:?}"
    );
    assert!(has(&labels, "translate"), "{labels:?}");
}

#[test]
fn a_material_block_offers_a_materials_properties_only() {
    for text in [
        "material m { | }",
        "material t : m { | }",
        "sphere { material { | } }",
        "sphere { material : m { reflective 1 | } }",
    ] {
        let labels = completions(text);
        assert!(
            has(&labels, "diffuse") && has(&labels, "ior"),
            "{text}: {labels:?}"
        );
        assert!(
            !has(&labels, "radius") && !has(&labels, "translate"),
            "{text}: {labels:?}"
        );
    }
}

#[test]
fn blocks_of_every_kind_offer_their_rows() {
    let settings = completions("settings { | }");
    assert!(has(&settings, "max_depth") && has(&settings, "shadows") && !has(&settings, "radius"));
    let spot = completions("light spot { | }");
    assert!(
        has(&spot, "position") && has(&spot, "direction"),
        "{spot:?}"
    );
    let point = completions("light point { | }");
    assert!(!has(&point, "direction"), "{point:?}");
    let camera = completions("camera perspective { | }");
    assert!(has(&camera, "eye") && has(&camera, "fov"), "{camera:?}");
    let union = completions("union { sphere { } | }");
    assert!(
        has(&union, "translate") && !has(&union, "radius"),
        "{union:?}"
    );
    let pattern = completions("material m { diffuse checker(1, 0, 1) { | } }");
    assert_eq!(pattern, ["translate", "rotate", "scale", "matrix"]);
    let call = completions("fn f() { sphere { } } f() { | }");
    assert!(has(&call, "translate") && has(&call, "material") && !has(&call, "radius"));
    let in_loop = completions("for i in 0..3 { sphere { | } }");
    assert!(has(&in_loop, "radius"), "{in_loop:?}");
}

#[test]
fn values_offer_materials_and_words() {
    let text = "material glass { }\nmaterial red { }\nsphere { material | }";
    assert_eq!(completions(text), ["glass", "red"]);
    assert_eq!(
        completions("material glass { }\nmaterial t : | { }"),
        ["glass"]
    );
    assert_eq!(
        completions("settings { shadows | }"),
        ["opaque", "filtered", "none"]
    );
    assert_eq!(
        completions("settings { shadows fil| }"),
        ["opaque", "filtered", "none"]
    );
}

#[test]
fn a_statement_starts_with_a_keyword_or_an_object_kind() {
    let top = completions("sphere { } |");
    assert_eq!(top[..4], ["import", "settings", "camera", "light"]);
    assert!(has(&top, "sphere") && has(&top, "group") && !has(&top, "return"));
    assert_eq!(completions("|"), top);
    assert_eq!(completions("let n = 3; |"), top);
    let in_function = completions("fn f() { | }");
    assert!(has(&in_function, "return") && has(&in_function, "sphere"));
    assert!(!has(&in_function, "settings") && !has(&in_function, "import"));
    let in_loop = completions("for i in 0..3 { | }");
    assert!(!has(&in_loop, "return") && !has(&in_loop, "camera") && has(&in_loop, "box"));
}

#[test]
fn half_typed_text_still_knows_its_block() {
    let labels = completions("camera perspective { eye <0, 0, -5> }\nsphere { rad|");
    assert!(has(&labels, "radius"), "{labels:?}");
    let labels = completions("sphere { radius 1 }\nmaterial m { di|");
    assert!(
        has(&labels, "diffuse") && !has(&labels, "radius"),
        "{labels:?}"
    );
}

#[test]
fn nothing_is_offered_where_no_property_goes() {
    for text in [
        "sphere { center <0, | }",
        "// sphere { |",
        "sphere \"a | b\" { }",
        "sphere { radius 1 + | }",
        "blob { | }",
        "let x = |",
        "for i in 0..| { }",
    ] {
        assert_eq!(completions(text), Vec::<String>::new(), "{text}");
    }
}

#[test]
fn hover_reads_the_words_when_the_text_does_not_parse() {
    let text = "material m { ior 1.5\nsphere { radius";
    let mut server = Server::new(Box::new(Memory::default()));
    let published = open(&mut server, "a.scene", text);
    assert!(!published.is_empty());
    let offset = text.find("ior").expect("ior") + 1;
    let hover = request(
        &mut server,
        "textDocument/hover",
        position_params("a.scene", text, offset),
    );
    let value = hover["contents"]["value"].as_str().expect("markdown");
    assert!(value.starts_with("**ior**: "), "{value}");
    assert!(value.ends_with("(in a material)"), "{value}");
}

#[test]
fn hover_on_a_setting_reads_the_ir_settings_table() {
    let text = "settings { max_depth 4 }\n";
    let mut server = Server::new(Box::new(Memory::default()));
    open(&mut server, "a.scene", text);
    let hover = request(
        &mut server,
        "textDocument/hover",
        position_params("a.scene", text, 12),
    );
    let row = whitted_ir::setting_rows::SETTINGS
        .iter()
        .find(|row| row.name == "max_depth")
        .expect("a row");
    let value = hover["contents"]["value"].as_str().expect("markdown");
    assert!(
        value.starts_with(&format!("**max_depth**: {}\n\n", row.doc)),
        "{value}"
    );
    assert!(
        value.contains(&format!("default `{}`", row.default)),
        "{value}"
    );
}

/// Where go to definition lands from the name at `|` (the marker removed): the range's
/// start, as (line, character).
fn definition(marked: &str) -> Option<(u64, u64)> {
    let offset = marked.find('|').expect("a cursor");
    let text = marked.replacen('|', "", 1);
    let mut server = Server::new(Box::new(Memory::default()));
    open(&mut server, "a.scene", &text);
    let found = request(
        &mut server,
        "textDocument/definition",
        position_params("a.scene", &text, offset),
    );
    let start = &found.get("range")?["start"];
    Some((start["line"].as_u64()?, start["character"].as_u64()?))
}

#[test]
fn definitions_of_lets_functions_parameters_and_materials() {
    let text = "const n = 3;\nmaterial red { }\nfn ring(k) { for i in 0..k { sphere { center <i, 0, 0> material red } } }\n";
    assert_eq!(definition(&format!("{text}ring(|n)")), Some((0, 6)));
    assert_eq!(definition(&format!("{text}r|ing(n)")), Some((2, 3)));
    let inside = text.replace("0..k", "0..|k");
    assert_eq!(definition(&format!("{inside}ring(n)")), Some((2, 8)));
    let material = text.replace("material red }", "material r|ed }");
    assert_eq!(definition(&format!("{material}ring(n)")), Some((1, 9)));
    let loop_variable = text.replace("<i,", "<|i,");
    assert_eq!(
        definition(&format!("{loop_variable}ring(n)")),
        Some((2, 17))
    );
    // A number is no name.
    assert_eq!(
        definition(&format!("{text}ring(n) sphere {{ radius |1 }}")),
        None
    );
}

/// The diagnostics published for `name` among `published`.
fn published_for(published: &[Notification], name: &str) -> Option<Vec<Value>> {
    published
        .iter()
        .rev()
        .find(|n| n.params["uri"] == json!(uri(name)))
        .map(|n| {
            n.params["diagnostics"]
                .as_array()
                .cloned()
                .unwrap_or_default()
        })
}

#[test]
fn an_open_import_is_read_instead_of_the_disk() {
    let mut disk = Memory::default();
    disk.0.insert(
        PathBuf::from("/project/lib.scene"),
        b"material chrome { reflective 0.8 }\n".to_vec(),
    );
    let mut server = Server::new(Box::new(disk));
    // main.scene uses `steel`, which only the editor's unsaved lib.scene defines.
    let main = "import \"lib.scene\"\nsphere { material steel }\n";
    let published = open(&mut server, "main.scene", main);
    let errors = published_for(&published, "main.scene").expect("main's diagnostics");
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(errors[0]["message"]
        .as_str()
        .is_some_and(|m| m.starts_with("unknown name `steel`")));
    // Nothing to say about lib.scene from main's compile (an unused material of an
    // import is no warning).
    assert_eq!(published_for(&published, "lib.scene"), None);

    // Opening lib.scene recompiles main, which now reads the editor's text.
    let published = open(
        &mut server,
        "lib.scene",
        "material steel { reflective 0.8 }\n",
    );
    assert_eq!(published_for(&published, "main.scene"), Some(Vec::new()));
    // lib.scene's diagnostics are its own compile's (where `steel` is unused), however
    // many times main is compiled after.
    let own = published_for(&published, "lib.scene").expect("lib's diagnostics");
    assert_eq!(own.len(), 1, "{own:?}");
    assert_eq!(own[0]["severity"], json!(2));
    server.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri("main.scene"), "version": 2},
               "contentChanges": [{"text": main}]}),
    );
    let published = server.analyze_changed();
    assert_eq!(published_for(&published, "main.scene"), Some(Vec::new()));
    assert_eq!(published_for(&published, "lib.scene"), None);

    // An error typed into lib.scene is reported there, at its place, and main (which
    // imports it) is compiled again.
    server.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri("lib.scene"), "version": 2},
               "contentChanges": [{"text": "material steel { reflectiv 0.8 }\n"}]}),
    );
    let published = server.analyze_changed();
    let in_lib = published_for(&published, "lib.scene").expect("lib.scene's diagnostics");
    assert_eq!(in_lib.len(), 1, "{in_lib:?}");
    assert_eq!(
        in_lib[0]["range"],
        json!({"start": {"line": 0, "character": 17}, "end": {"line": 0, "character": 26}})
    );
    // main.scene says so on its import line, pointing at the error.
    let in_main = published_for(&published, "main.scene").expect("main's diagnostics");
    assert_eq!(in_main.len(), 1, "{in_main:?}");
    assert_eq!(
        in_main[0]["range"],
        json!({"start": {"line": 0, "character": 0}, "end": {"line": 0, "character": 18}})
    );
    let message = in_main[0]["message"].as_str().expect("a message");
    assert!(
        message.starts_with("`lib.scene` has an error: "),
        "{message}"
    );
    let related = &in_main[0]["relatedInformation"][0]["location"];
    assert_eq!(related["uri"], json!(uri("lib.scene")));
    assert_eq!(related["range"], in_lib[0]["range"]);
}

#[test]
fn a_course_scene_gets_the_converters_diagnostics() {
    let text = "OrthographicCamera {\n    center 0 0 10\n    direction 0 0 -1\n    up 0 1 0\n    size 5\n}\nGroup {\n    numObjects x\n}\n";
    let mut server = Server::new(Box::new(Memory::default()));
    let published = open(&mut server, "scene.txt", text);
    let diagnostics = published_for(&published, "scene.txt").expect("diagnostics");
    assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
    assert_eq!(
        diagnostics[0]["range"]["start"],
        json!({"line": 7, "character": 15})
    );
}

/// A tiny seeded generator (splitmix64), so every run makes the same edits.
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
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Random edits (inserted pieces of scene text and stray characters, deleted runs) and
/// requests at random positions, some past the end of the text: every request answers
/// without an error, and the server never panics.
#[test]
fn random_edits_and_requests_never_fail() {
    const PIECES: &[&str] = &[
        "{",
        "}",
        "(",
        ")",
        "<",
        ">",
        ",",
        "\"",
        "\n",
        " ",
        "/",
        "*",
        ":",
        ";",
        "=",
        "é",
        "😀",
        "sphere",
        "material",
        "glass",
        "radius",
        "1",
        "0.5",
        "settings",
        "shadows",
        "filtered",
        "light",
        "point",
        "camera",
        "let",
        "fn",
        "for",
        "import",
        "\"lib.scene\"",
        "#ff0000",
        "\"ball\"",
        "/*",
    ];
    const START: &str = "import \"lib.scene\"\nsettings { shadows filtered }\nmaterial glass { ior 1.5 diffuse <1, 0, 0> }\nfn ring(n) {\n  for i in 0..n {\n    sphere { center <i, 0, 0> radius 0.5 material glass }\n  }\n}\n/* a\n b */\nring(3) { translate <0, 1, 0> }\nsphere \"ball\" { }\nmesh { file \"bunny.obj\" }\n";
    let mut disk = Memory::default();
    disk.0.insert(
        PathBuf::from("/project/lib.scene"),
        b"material chrome { reflective 0.8 }\n".to_vec(),
    );
    let mut server = Server::new(Box::new(disk));
    open(&mut server, "a.scene", START);
    let mut text = START.to_string();
    let mut rng = Rng(29);
    let mut answered: HashMap<&str, usize> = HashMap::new();
    // The id and data of the last whole-document semantic tokens, for deltas.
    let mut sent: Option<(String, Vec<Value>)> = None;
    for version in 2..600 {
        let lines = LineIndex::new(&text);
        let at = |rng: &mut Rng, text: &str| {
            let offset = rng.below(text.len() + 1);
            let mut position = lines.position(text, offset);
            if rng.below(10) == 0 {
                position =
                    Position::new(position.line + rng.below(3) as u32, rng.below(200) as u32);
            }
            position
        };
        let start = at(&mut rng, &text);
        let end = if rng.below(3) == 0 {
            at(&mut rng, &text)
        } else {
            start
        };
        let (start, end) = if (start.line, start.character) <= (end.line, end.character) {
            (start, end)
        } else {
            (end, start)
        };
        let piece = if rng.below(4) == 0 {
            ""
        } else {
            PIECES[rng.below(PIECES.len())]
        };
        let from = lines.offset(&text, start);
        let to = lines.offset(&text, end).max(from);
        text.replace_range(from..to, piece);
        server.notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": uri("a.scene"), "version": version},
                   "contentChanges": [{"range": {"start": start, "end": end}, "text": piece}]}),
        );
        if rng.below(8) == 0 {
            // Back to the scene that compiles, so that the syntax tree's answers (hover,
            // definitions, the outline) are asked at random places too.
            text = START.to_string();
            server.notify(
                "textDocument/didChange",
                json!({"textDocument": {"uri": uri("a.scene"), "version": version},
                       "contentChanges": [{"text": START}]}),
            );
        }
        if rng.below(4) == 0 {
            server.analyze_changed();
        }
        let lines = LineIndex::new(&text);
        for _ in 0..5 {
            let offset = rng.below(text.len() + 1);
            let mut position = lines.position(&text, offset);
            if rng.below(10) == 0 {
                position =
                    Position::new(position.line + rng.below(3) as u32, rng.below(200) as u32);
            }
            let methods = [
                "textDocument/hover",
                "textDocument/completion",
                "textDocument/definition",
                "textDocument/documentSymbol",
                "textDocument/semanticTokens/full",
                "textDocument/semanticTokens/range",
                "textDocument/semanticTokens/full/delta",
                "textDocument/foldingRange",
                "textDocument/documentColor",
                "textDocument/colorPresentation",
                "textDocument/inlayHint",
                "textDocument/references",
                "textDocument/prepareRename",
                "textDocument/codeAction",
                "textDocument/rename",
                "workspace/willRenameFiles",
            ];
            let method = methods[rng.below(methods.len())];
            let end = Position::new(position.line + rng.below(4) as u32, rng.below(80) as u32);
            let new_name = ["b", "n2", "light", "9x", "m"][rng.below(5)];
            let params = json!({"textDocument": {"uri": uri("a.scene")}, "position": position,
                "range": {"start": position, "end": end},
                "color": {"red": 0.5, "green": 2.0, "blue": -1.0, "alpha": 1.0},
                "newName": new_name});
            // Each request's own context (completion's would need a trigger kind).
            let mut params = params;
            match method {
                "textDocument/references" => {
                    params["context"] = json!({"includeDeclaration": rng.below(2) == 0});
                }
                "textDocument/codeAction" => params["context"] = json!({"diagnostics": []}),
                "workspace/willRenameFiles" => {
                    let (old, new) = [
                        ("lib.scene", "l2.scene"),
                        ("bunny.obj", "m/b.obj"),
                        ("", "x"),
                    ][rng.below(3)];
                    params["files"] = json!([{"oldUri": uri(old), "newUri": uri(new)}]);
                }
                "textDocument/semanticTokens/full/delta" => {
                    // The last id sent, or an old one, which gets the whole document's.
                    let id = match &sent {
                        Some((id, _)) if rng.below(4) != 0 => id.clone(),
                        _ => "0".to_string(),
                    };
                    params["previousResultId"] = json!(id);
                }
                _ => {}
            }
            let (result, _) = server.request(method, params.clone());
            if method.starts_with("textDocument/semanticTokens/full") {
                let answer = result.clone().expect("tokens");
                let data: Vec<Value> = match answer.get("edits") {
                    // A delta: its edits applied to the tokens last sent.
                    Some(edits) => {
                        let mut data = sent.clone().expect("tokens were sent").1;
                        for edit in edits.as_array().expect("edits").iter().rev() {
                            let start = edit["start"].as_u64().expect("start") as usize;
                            let deleted = edit["deleteCount"].as_u64().expect("count") as usize;
                            let inserted = edit["data"].as_array().cloned().unwrap_or_default();
                            data.splice(start..start + deleted, inserted);
                        }
                        data
                    }
                    None => answer["data"].as_array().cloned().unwrap_or_default(),
                };
                let (whole, _) = server.request(
                    "textDocument/semanticTokens/full",
                    json!({"textDocument": {"uri": uri("a.scene")}}),
                );
                let whole = whole.expect("the whole document's");
                assert_eq!(data, whole["data"].as_array().cloned().unwrap_or_default());
                let id = whole["resultId"].as_str().unwrap_or_default().to_string();
                sent = Some((id, data));
            }
            if method == "textDocument/semanticTokens/range" {
                // A range's tokens are the pieces of the whole document's that overlap it.
                let (whole, _) = server.request("textDocument/semanticTokens/full", params);
                let clamp = |p: Position| lines.position(&text, lines.offset(&text, p));
                let from = clamp(position);
                let to = clamp(end).max(from);
                let (from, to) = ((from.line, from.character), (to.line, to.character));
                let expected: Vec<[u64; 5]> = absolute(&whole.expect("the whole document's"))
                    .into_iter()
                    .filter(|t| (t[0], t[1] + t[2]) > (from.0 as u64, from.1 as u64))
                    .filter(|t| (t[0], t[1]) < (to.0 as u64, to.1 as u64))
                    .collect();
                let found = absolute(result.as_ref().expect("the range's"));
                assert_eq!(found, expected, "{position:?}..{end:?} of {text:?}");
            }
            if result
                .as_ref()
                .is_ok_and(|v| !v.is_null() && *v != json!([]))
            {
                *answered.entry(method).or_insert(0) += 1;
            }
            // A rename may be refused (a keyword, a clash, a file that does not parse);
            // every other request answers.
            assert!(
                result.is_ok() || method == "textDocument/rename",
                "{method} at {position:?} after edit {version} of {text:?}"
            );
        }
    }
    // Every kind of request was asked where it has an answer, some of the time (quick
    // fixes need a diagnostic that offers one, which random edits seldom make).
    assert!(answered.len() >= 15, "{answered:?}");
    // The server's text is the text the edits make.
    server.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": uri("a.scene"), "version": 999}, "contentChanges": []}),
    );
    let published = server.analyze_changed();
    assert!(published_for(&published, "a.scene").is_some());
}

/// Formatting is `whitted fmt` on the editor's text: one edit over the whole document,
/// none when it is formatted already, and no answer for text that does not parse.
#[test]
fn formatting_is_whitted_fmt_on_the_editors_text() {
    let mut server = Server::new(Box::new(Memory::default()));
    let messy = "material m {diffuse 0.5}\nsphere {   radius 2 material m }\n";
    open(&mut server, "messy.scene", messy);
    let params = |name: &str| json!({"textDocument": {"uri": uri(name)}, "options": {"tabSize": 4, "insertSpaces": true}});
    let edits = request(
        &mut server,
        "textDocument/formatting",
        params("messy.scene"),
    );
    let expected = whitted_lang::format_source("messy.scene", messy).expect("formats");
    assert_ne!(expected, messy);
    assert_eq!(edits[0]["newText"], expected.as_str());
    assert_eq!(
        edits[0]["range"]["start"],
        json!({"line": 0, "character": 0})
    );
    assert_eq!(edits[0]["range"]["end"], json!({"line": 2, "character": 0}));
    assert_eq!(edits.as_array().map(Vec::len), Some(1));

    open(&mut server, "tidy.scene", &expected);
    let none = request(&mut server, "textDocument/formatting", params("tidy.scene"));
    assert_eq!(none, json!([]));

    open(&mut server, "broken.scene", "sphere { radius = 1 }\n");
    let refused = request(
        &mut server,
        "textDocument/formatting",
        params("broken.scene"),
    );
    assert_eq!(refused, Value::Null);
}

/// Go to definition on the string of an `import` or a mesh's `file` opens that file,
/// relative to the document, even while the document does not parse.
#[test]
fn definition_of_an_import_or_a_mesh_file_is_the_file() {
    let mut server = Server::new(Box::new(Memory::default()));
    let text = "import \"lib/materials.scene\"\nmesh { file \"models/gem.obj\" }\nlet s = \"x.scene\"\nsphere {";
    open(&mut server, "dir/a.scene", text);
    let mut target = |needle: &str| {
        let offset = text.find(needle).expect("in the text") + 2;
        let answer = request(
            &mut server,
            "textDocument/definition",
            position_params("dir/a.scene", text, offset),
        );
        answer["uri"].as_str().map(str::to_string)
    };
    assert_eq!(
        target("lib/materials").as_deref(),
        Some("file:///project/dir/lib/materials.scene")
    );
    assert_eq!(
        target("models/gem").as_deref(),
        Some("file:///project/dir/models/gem.obj")
    );
    // Any other string is not a file.
    assert_eq!(target("x.scene"), None);
}

/// A material's hover shows the picture the runner's renderer makes of that material (here
/// a stand-in that names the material's diffuse colour); other names get none.
#[test]
fn a_material_hover_shows_its_picture_from_the_runner() {
    struct Named;
    impl crate::Thumbnails for Named {
        fn material(
            &self,
            materials: &whitted_ir::Arena<whitted_ir::Material>,
            material: whitted_ir::Handle<whitted_ir::Material>,
        ) -> Option<String> {
            let m = materials.get(material)?;
            Some(format!("picture:{}", m.diffuse.r))
        }
    }
    let mut server = Server::new(Box::new(Memory::default()));
    server.set_thumbnails(Box::new(Named));
    let text = "material other { diffuse 0.2 }\nmaterial red { diffuse 0.7 }\nlet n = 2;\nsphere { radius n material red }\nsphere { material other }\n";
    open(&mut server, "m.scene", text);
    let hover_at = |server: &mut Server, needle: &str| {
        let offset = text.rfind(needle).expect("in the text") + 1;
        let answer = request(
            server,
            "textDocument/hover",
            position_params("m.scene", text, offset),
        );
        answer["contents"]["value"]
            .as_str()
            .unwrap_or("")
            .to_string()
    };
    let red = hover_at(&mut server, "red }");
    assert!(
        red.contains("![the material on a ball](picture:0.7)"),
        "{red}"
    );
    let at_definition = hover_at(&mut server, "red {");
    assert!(at_definition.contains("(picture:0.7)"), "{at_definition}");
    let name = hover_at(&mut server, "n material");
    assert!(!name.contains("picture:"), "{name}");
}

/// Semantic tokens as (line, column, length, type, modifiers), absolute.
fn absolute(tokens: &Value) -> Vec<[u64; 5]> {
    let data: Vec<u64> = tokens["data"]
        .as_array()
        .map(|d| d.iter().filter_map(Value::as_u64).collect())
        .unwrap_or_default();
    let (mut line, mut column) = (0, 0);
    data.chunks_exact(5)
        .map(|t| {
            line += t[0];
            column = if t[0] == 0 { column + t[1] } else { t[1] };
            [line, column, t[2], t[3], t[4]]
        })
        .collect()
}
