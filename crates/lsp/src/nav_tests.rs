//! References, rename, quick fixes and hover on names, in-process with exact answers: across
//! an import read from the disk, objects' names and files' strings, every refusal of rename,
//! and every request at every place of a scene (and of one that does not parse) answering
//! without failing.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use lsp_server::ResponseError;
use lsp_types::Url;
use serde_json::{json, Value};

use crate::position::LineIndex;
use crate::{Files, Server};

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

fn server_with(disk: &[(&str, &str)], open: &[(&str, &str)]) -> Server {
    let mut memory = Memory::default();
    for (name, text) in disk {
        memory.0.insert(
            PathBuf::from(format!("/project/{name}")),
            text.as_bytes().to_vec(),
        );
    }
    let mut server = Server::new(Box::new(memory));
    for (name, text) in open {
        server.notify(
            "textDocument/didOpen",
            json!({"textDocument": {"uri": uri(name), "languageId": "whitted", "version": 1, "text": text}}),
        );
    }
    server.analyze_changed();
    server
}

/// The position of the `nth` (from 0) occurrence of `word` in `text`, plus `into` bytes.
fn at(name: &str, text: &str, word: &str, nth: usize, into: usize) -> Value {
    let offset = text
        .match_indices(word)
        .nth(nth)
        .map(|(i, _)| i + into)
        .expect("the word is in the text");
    let position = LineIndex::new(text).position(text, offset);
    json!({"textDocument": {"uri": uri(name)}, "position": position})
}

fn ask(server: &mut Server, method: &str, params: Value) -> Result<Value, ResponseError> {
    server.request(method, params).0
}

/// Locations as `file:line:start-end` (one line each), sorted.
fn places(value: &Value) -> Vec<String> {
    let mut out: Vec<String> = value
        .as_array()
        .expect("a list")
        .iter()
        .map(|l| {
            let file = l["uri"].as_str().unwrap_or_default();
            let file = file.rsplit('/').next().unwrap_or_default();
            let r = &l["range"];
            assert_eq!(r["start"]["line"], r["end"]["line"]);
            format!(
                "{file}:{}:{}-{}",
                r["start"]["line"], r["start"]["character"], r["end"]["character"]
            )
        })
        .collect();
    out.sort();
    out
}

/// A workspace edit's edits as `file:line:start-end=text`, sorted.
fn edits(value: &Value) -> Vec<String> {
    let mut out = Vec::new();
    for (file, list) in value["changes"].as_object().expect("changes") {
        let file = file.rsplit('/').next().unwrap_or_default();
        for edit in list.as_array().expect("edits") {
            let r = &edit["range"];
            out.push(format!(
                "{file}:{}:{}-{}:{}={}",
                r["start"]["line"],
                r["start"]["character"],
                r["end"]["line"],
                r["end"]["character"],
                edit["newText"].as_str().unwrap_or_default()
            ));
        }
    }
    out.sort();
    out
}

const LIB: &str = "material steel { reflective 0.8 }\nconst size = 2;\n";
const MAIN: &str = "import \"lib.scene\"\nlet r = size;\nr = r + 1;\nsphere { radius r material steel }\nsphere { center <0, 3, 0> material steel }\n";

#[test]
fn references_reach_into_an_import_and_back() {
    let mut server = server_with(&[("lib.scene", LIB)], &[("main.scene", MAIN)]);
    let found = ask(
        &mut server,
        "textDocument/references",
        json!({"textDocument": {"uri": uri("main.scene")},
               "position": at("main.scene", MAIN, "steel", 1, 2)["position"],
               "context": {"includeDeclaration": true}}),
    )
    .expect("an answer");
    assert_eq!(
        places(&found),
        [
            "lib.scene:0:9-14",
            "main.scene:3:27-32",
            "main.scene:4:35-40"
        ]
    );
    // Without the declaration; and a `let` with its assignment and uses.
    let mut params = at("main.scene", MAIN, "r =", 1, 0);
    params["context"] = json!({"includeDeclaration": false});
    let found = ask(&mut server, "textDocument/references", params).expect("an answer");
    assert_eq!(
        places(&found),
        ["main.scene:2:0-1", "main.scene:2:4-5", "main.scene:3:16-17"]
    );
}

#[test]
fn rename_edits_the_import_and_every_user() {
    let mut server = server_with(&[("lib.scene", LIB)], &[("main.scene", MAIN)]);
    let prepared = ask(
        &mut server,
        "textDocument/prepareRename",
        at("main.scene", MAIN, "size", 0, 1),
    )
    .expect("an answer");
    assert_eq!(
        prepared,
        json!({"range": {"start": {"line": 1, "character": 8}, "end": {"line": 1, "character": 12}},
               "placeholder": "size"})
    );
    let mut params = at("main.scene", MAIN, "size", 0, 1);
    params["newName"] = json!("radius_big");
    let edit = ask(&mut server, "textDocument/rename", params).expect("an edit");
    assert_eq!(
        edits(&edit),
        [
            "lib.scene:1:6-1:10=radius_big",
            "main.scene:1:8-1:12=radius_big"
        ]
    );
    // From the definition in an open lib, every open user is edited too.
    let mut server = server_with(&[], &[("main.scene", MAIN), ("lib.scene", LIB)]);
    let mut params = at("lib.scene", LIB, "steel", 0, 0);
    params["newName"] = json!("iron");
    let edit = ask(&mut server, "textDocument/rename", params).expect("an edit");
    assert_eq!(
        edits(&edit),
        [
            "lib.scene:0:9-0:14=iron",
            "main.scene:3:27-3:32=iron",
            "main.scene:4:35-4:40=iron"
        ]
    );
}

fn refusal(text: &str, word: &str, nth: usize, new_name: &str) -> String {
    let mut server = server_with(&[], &[("a.scene", text)]);
    let mut params = at("a.scene", text, word, nth, 0);
    params["newName"] = json!(new_name);
    match ask(&mut server, "textDocument/rename", params) {
        Ok(value) => panic!("renamed to {new_name}: {value}"),
        Err(e) => e.message,
    }
}

#[test]
fn rename_refuses_what_would_break_the_scene() {
    let text = "const n = 1;\nlet a = 2;\nlet b = 3;\nfn f(k) { return k + n; }\nsphere { radius f(a) + b }\n";
    assert_eq!(
        refusal(text, "a =", 0, "2a"),
        "`2a` is not a name: a name starts with a letter or `_` and goes on with letters, digits and `_`"
    );
    assert_eq!(
        refusal(text, "a =", 0, "light"),
        "`light` is a keyword of the language, not a name"
    );
    assert_eq!(
        refusal(text, "a =", 0, "b"),
        "renaming `a` to `b` would clash with another definition: `b` is already defined here (defined a second time)"
    );
    // The parameter would hide the constant its function uses.
    assert_eq!(
        refusal(text, "k)", 0, "n"),
        "renaming `k` to `n` would change what the scene means: another name's use would then mean it (a.scene line 4)"
    );
    let broken = "let a = 2;\nsphere { radius a \n";
    assert_eq!(
        refusal(broken, "a", 1, "c"),
        "a.scene does not parse: fix its syntax error before renaming"
    );
    assert_eq!(
        refusal(text, "sphere", 0, "c"),
        "there is no name of a definition here to rename"
    );
}

/// The quick fixes offered over the whole of `text`: (title, edit) pairs.
fn quick_fixes(text: &str) -> Vec<String> {
    let mut server = server_with(&[], &[("a.scene", text)]);
    let end = LineIndex::new(text).position(text, text.len());
    let found = ask(
        &mut server,
        "textDocument/codeAction",
        json!({"textDocument": {"uri": uri("a.scene")},
               "range": {"start": {"line": 0, "character": 0}, "end": end},
               "context": {"diagnostics": []}}),
    )
    .expect("an answer");
    found
        .as_array()
        .expect("a list")
        .iter()
        .map(|action| {
            assert_eq!(action["kind"], json!("quickfix"));
            let fixed = &action["diagnostics"][0];
            let edit = edits(&action["edit"]);
            assert_eq!(edit.len(), 1);
            // Linked to its diagnostic, at the edit's place.
            assert_eq!(
                fixed["range"],
                action["edit"]["changes"][uri("a.scene").as_str()][0]["range"]
            );
            format!(
                "{} {}",
                action["title"].as_str().unwrap_or_default(),
                edit[0]
            )
        })
        .collect()
}

#[test]
fn did_you_mean_and_remove_this_are_quick_fixes() {
    assert_eq!(
        quick_fixes("let width = 2;\nsphere { radus widht }\n"),
        [
            "Replace `radus` with `radius` a.scene:1:9-1:14=radius",
            "Replace `widht` with `width` a.scene:1:15-1:20=width"
        ]
    );
    assert_eq!(
        quick_fixes("let v = <1, 2, 3>;\nsphere { radius v.w }\n"),
        ["Replace `w` with `x` a.scene:1:18-1:19=x"]
    );
    assert_eq!(
        quick_fixes("sphere { radius = 1 }\n"),
        ["Remove `=` a.scene:0:16-0:17="]
    );
    assert_eq!(quick_fixes("sphere { radius 1 }\n"), Vec::<String>::new());
}

fn hover_text(text: &str, word: &str, nth: usize) -> String {
    let mut server = server_with(&[], &[("a.scene", text)]);
    let found = ask(
        &mut server,
        "textDocument/hover",
        at("a.scene", text, word, nth, 0),
    )
    .expect("an answer");
    found["contents"]["value"]
        .as_str()
        .unwrap_or_default()
        .to_string()
}

#[test]
fn hover_on_a_name_shows_what_the_compiler_found() {
    let text = "const n = 2 * 3;\nmaterial red { diffuse <1, 0, 0.5> specular 0.2 }\nfn ring(k, r) { for i in 0..k step 2 { let x = i * r; sphere { center <x, 0, 0> material red } } }\nring(n, 1.5)\n";
    assert_eq!(
        hover_text(text, "n,", 0),
        "**`n`**: a constant (defined at line 1)\n\nvalue `6`"
    );
    assert_eq!(
        hover_text(text, "ring", 1),
        "**`ring`**: a function (defined at line 3)\n\n```\nfn ring(k, r)\n```"
    );
    assert_eq!(
        hover_text(text, "i *", 0),
        "**`i`**: a loop variable (defined at line 3)\n\ntakes 0 to 4 by 2 (3 values)"
    );
    assert_eq!(
        hover_text(text, "x =", 0),
        "**`x`**: a `let` binding (defined at line 3)\n\nvalue `0` (then 2 other values)"
    );
    assert_eq!(
        hover_text(text, "red }", 0),
        "**`red`**: a material (defined at line 2)\n\n```\ndiffuse rgb(255, 0, 128) <1, 0, 0.5>\nambient rgb(26, 26, 26) <0.1, 0.1, 0.1>\nspecular rgb(51, 51, 51) <0.2, 0.2, 0.2>\nshininess 32\nreflective rgb(0, 0, 0) <0, 0, 0>\ntransmissive rgb(0, 0, 0) <0, 0, 0>\nior 1\n```"
    );
    // A property keeps its documentation.
    assert!(hover_text(text, "diffuse", 0).starts_with("**diffuse**"));
}

#[test]
fn every_request_anywhere_answers() {
    let texts = [
        MAIN.to_string(),
        "let a = 2;\nsphere { radius a \n".to_string(),
        "fn f(k) { for i in 0..k { sphere { radius = i } } }\nf(2)\nlet é = 1;".to_string(),
    ];
    for text in &texts {
        let mut server = server_with(&[("lib.scene", LIB)], &[("main.scene", text)]);
        let lines = LineIndex::new(text);
        for (offset, _) in text.char_indices().chain([(text.len(), ' ')]) {
            let position = lines.position(text, offset);
            let doc = json!({"uri": uri("main.scene")});
            let range = json!({"start": position, "end": position});
            for (method, params) in [
                (
                    "textDocument/references",
                    json!({"textDocument": doc, "position": position, "context": {"includeDeclaration": true}}),
                ),
                (
                    "textDocument/prepareRename",
                    json!({"textDocument": doc, "position": position}),
                ),
                (
                    "textDocument/codeAction",
                    json!({"textDocument": doc, "range": range, "context": {"diagnostics": []}}),
                ),
                (
                    "textDocument/hover",
                    json!({"textDocument": doc, "position": position}),
                ),
            ] {
                assert!(
                    ask(&mut server, method, params).is_ok(),
                    "{method} at {offset}"
                );
            }
            // Rename answers an edit or a refusal, never anything else.
            let _ = ask(
                &mut server,
                "textDocument/rename",
                json!({"textDocument": doc, "position": position, "newName": "zz"}),
            );
        }
    }
}

const PARTS: &str = "sphere \"ball\" { radius 1 }\nmesh \"bunny\" { file \"../bunny.obj\" }\n";
const SCENE: &str = "import \"parts/lib.scene\"\nsphere \"ball\" { center <0, 2, 0> }\nplane \"floor\" { }\nfor i in 0..2 { sphere \"ball {i}\" { } }\nmesh { file \"bunny.obj\" }\n";
const OTHER: &str = "import \"parts/../parts/lib.scene\"\nsphere \"ball\" { }\n";

fn references_at(
    server: &mut Server,
    name: &str,
    text: &str,
    word: &str,
    nth: usize,
    declaration: bool,
) -> Vec<String> {
    let mut params = at(name, text, word, nth, 1);
    params["context"] = json!({"includeDeclaration": declaration});
    places(&ask(server, "textDocument/references", params).expect("an answer"))
}

/// An object's name: the objects of that name in the scene (across its import), not the
/// other scene's, and not a name with a hole.
#[test]
fn an_objects_name_finds_the_objects_of_that_name() {
    let mut server = server_with(&[("parts/lib.scene", PARTS)], &[("main.scene", SCENE)]);
    assert_eq!(
        references_at(&mut server, "main.scene", SCENE, "\"ball\"", 0, true),
        ["lib.scene:0:7-13", "main.scene:1:7-13"]
    );
    // The first in the compile is the definition, left out when the client asks so.
    let definition = ask(
        &mut server,
        "textDocument/definition",
        at("main.scene", SCENE, "\"ball\"", 0, 2),
    )
    .expect("an answer");
    assert_eq!(places(&json!([definition])), ["main.scene:1:7-13"]);
    assert_eq!(
        references_at(&mut server, "main.scene", SCENE, "\"ball\"", 0, false),
        ["lib.scene:0:7-13"]
    );
    assert_eq!(
        references_at(&mut server, "main.scene", SCENE, "\"floor\"", 0, true),
        ["main.scene:2:6-13"]
    );
    // With the other scene open, the import's ball is in both scenes, so it finds both
    // scenes' balls; each scene's own ball finds its scene's only.
    let mut server = server_with(
        &[],
        &[
            ("main.scene", SCENE),
            ("parts/lib.scene", PARTS),
            ("other.scene", OTHER),
        ],
    );
    assert_eq!(
        references_at(&mut server, "parts/lib.scene", PARTS, "\"ball\"", 0, true),
        [
            "lib.scene:0:7-13",
            "main.scene:1:7-13",
            "other.scene:1:7-13"
        ]
    );
    assert_eq!(
        references_at(&mut server, "other.scene", OTHER, "\"ball\"", 0, true),
        ["lib.scene:0:7-13", "other.scene:1:7-13"]
    );
}

#[test]
fn rename_of_an_objects_name_renames_its_objects() {
    let mut server = server_with(&[("parts/lib.scene", PARTS)], &[("main.scene", SCENE)]);
    let prepared = ask(
        &mut server,
        "textDocument/prepareRename",
        at("main.scene", SCENE, "\"ball\"", 0, 3),
    )
    .expect("an answer");
    assert_eq!(
        prepared,
        json!({"range": {"start": {"line": 1, "character": 8}, "end": {"line": 1, "character": 12}},
               "placeholder": "ball"})
    );
    // A name with a hole is not plain text: nothing to rename.
    let prepared = ask(
        &mut server,
        "textDocument/prepareRename",
        at("main.scene", SCENE, "\"ball {", 0, 2),
    )
    .expect("an answer");
    assert_eq!(prepared, Value::Null);
    let mut params = at("main.scene", SCENE, "\"ball\"", 0, 1);
    params["newName"] = json!("glass ball");
    let edit = ask(&mut server, "textDocument/rename", params.clone()).expect("an edit");
    assert_eq!(
        edits(&edit),
        [
            "lib.scene:0:8-0:12=glass ball",
            "main.scene:1:8-1:12=glass ball"
        ]
    );
    params["newName"] = json!("floor");
    assert_eq!(
        ask(&mut server, "textDocument/rename", params.clone()).map_err(|e| e.message),
        Err("renaming \"ball\" to \"floor\" would merge its objects with the ones already named so (main.scene line 3)".to_string())
    );
    params["newName"] = json!("a{b");
    assert_eq!(
        ask(&mut server, "textDocument/rename", params).map_err(|e| e.message),
        Err(
            "an object's new name is plain text: `{` would need an escape or make a `{name}` hole"
                .to_string()
        )
    );
}

/// A file's strings: every `import` and mesh `file` naming it, however written, from every
/// open scene; the file itself is the declaration.
#[test]
fn a_files_string_finds_every_string_naming_that_file() {
    let mut server = server_with(
        &[("parts/lib.scene", PARTS)],
        &[("main.scene", SCENE), ("other.scene", OTHER)],
    );
    assert_eq!(
        references_at(&mut server, "main.scene", SCENE, "\"bunny.obj\"", 0, true),
        ["bunny.obj:0:0-0", "lib.scene:1:20-34", "main.scene:4:12-23"]
    );
    assert_eq!(
        references_at(&mut server, "main.scene", SCENE, "\"parts", 0, false),
        ["main.scene:0:7-24", "other.scene:0:7-33"]
    );
    let mut params = at("main.scene", SCENE, "\"parts", 0, 1);
    params["newName"] = json!("x");
    assert!(ask(&mut server, "textDocument/rename", params).is_err());
}

fn will_rename(server: &mut Server, old: &str, new: &str) -> Vec<String> {
    let edit = ask(
        server,
        "workspace/willRenameFiles",
        json!({"files": [{"oldUri": uri(old), "newUri": uri(new)}]}),
    )
    .expect("an answer");
    if edit.is_null() {
        return Vec::new();
    }
    edits(&edit)
}

/// Moving a file or a folder rewrites the strings that name it, relative to their own file;
/// a string that moves with what it names is left alone.
#[test]
fn moving_a_file_rewrites_the_strings_naming_it() {
    let mut server = server_with(
        &[("parts/lib.scene", PARTS)],
        &[("main.scene", SCENE), ("other.scene", OTHER)],
    );
    assert_eq!(
        will_rename(&mut server, "parts/lib.scene", "lib/base.scene"),
        [
            "main.scene:0:8-0:23=lib/base.scene",
            "other.scene:0:8-0:32=lib/base.scene"
        ]
    );
    assert_eq!(
        will_rename(&mut server, "bunny.obj", "meshes/bunny.obj"),
        [
            "lib.scene:1:21-1:33=../meshes/bunny.obj",
            "main.scene:4:13-4:22=meshes/bunny.obj"
        ]
    );
    assert_eq!(
        will_rename(&mut server, "parts", "pieces"),
        [
            "main.scene:0:8-0:23=pieces/lib.scene",
            "other.scene:0:8-0:32=pieces/lib.scene"
        ]
    );
    assert_eq!(
        will_rename(&mut server, "unused.scene", "x.scene"),
        Vec::<String>::new()
    );
}
