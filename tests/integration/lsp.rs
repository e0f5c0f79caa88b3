//! `whitted lsp` as an editor runs it: the real binary over stdio, one whole session with
//! exact answers (diagnostics appearing at their range and going away, hover, completion in a
//! material block, go to definition here and into an import, the outline, a quick fix,
//! references and rename across an import, of an object's name and of an import's file,
//! semantic tokens of a range), and exit status 0
//! after `shutdown` and `exit`. The Content-Length framing is written here by hand: it is the
//! protocol, not the server under test.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use lsp_types::Url;
use serde_json::{json, Value};

/// Far longer than any answer takes; a server that hangs fails the test instead of hanging it.
const PATIENCE: Duration = Duration::from_secs(60);

struct Session {
    child: std::process::Child,
    stdin: std::process::ChildStdin,
    incoming: mpsc::Receiver<Value>,
    next_id: i64,
}

impl Session {
    fn start() -> Session {
        let mut child = Command::new(env!("CARGO_BIN_EXE_whitted"))
            .arg("lsp")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("whitted lsp starts");
        let stdin = child.stdin.take().expect("stdin");
        let stdout = child.stdout.take().expect("stdout");
        let (sender, incoming) = mpsc::channel();
        std::thread::spawn(move || {
            let mut reader = BufReader::new(stdout);
            while let Some(message) = read_message(&mut reader) {
                if sender.send(message).is_err() {
                    break;
                }
            }
        });
        Session {
            child,
            stdin,
            incoming,
            next_id: 0,
        }
    }

    fn send(&mut self, message: Value) {
        let body = message.to_string();
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).expect("write");
        self.stdin.flush().expect("flush");
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(json!({"jsonrpc": "2.0", "method": method, "params": params}));
    }

    /// Sends a request and returns its result, skipping notifications on the way.
    fn request(&mut self, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = self.next_id;
        self.send(json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}));
        loop {
            let message = self.receive();
            if message["id"] == json!(id) {
                assert!(message.get("error").is_none(), "{method}: {message}");
                return message["result"].clone();
            }
        }
    }

    /// Sends a request that must fail and returns its error's message.
    fn refused(&mut self, method: &str, params: Value) -> String {
        self.next_id += 1;
        let id = self.next_id;
        self.send(json!({"jsonrpc": "2.0", "id": id, "method": method, "params": params}));
        loop {
            let message = self.receive();
            if message["id"] == json!(id) {
                assert!(message.get("result").is_none(), "{method}: {message}");
                return message["error"]["message"]
                    .as_str()
                    .unwrap_or_default()
                    .to_string();
            }
        }
    }

    fn receive(&mut self) -> Value {
        self.incoming
            .recv_timeout(PATIENCE)
            .expect("the server answers within the time")
    }

    /// The next diagnostics published for `uri`.
    fn diagnostics(&mut self, uri: &Url) -> Value {
        loop {
            let message = self.receive();
            if message["method"] == "textDocument/publishDiagnostics"
                && message["params"]["uri"] == json!(uri)
            {
                return message["params"].clone();
            }
        }
    }
}

fn read_message(reader: &mut impl BufRead) -> Option<Value> {
    let mut length = None;
    loop {
        let mut line = String::new();
        if reader.read_line(&mut line).ok()? == 0 {
            return None;
        }
        let line = line.trim_end();
        if line.is_empty() {
            break;
        }
        if let Some(value) = line.strip_prefix("Content-Length: ") {
            length = value.parse::<usize>().ok();
        }
    }
    let mut body = vec![0; length?];
    reader.read_exact(&mut body).ok()?;
    serde_json::from_slice(&body).ok()
}

fn at(uri: &Url, line: u32, character: u32) -> Value {
    json!({"textDocument": {"uri": uri}, "position": {"line": line, "character": character}})
}

fn range(start: (u32, u32), end: (u32, u32)) -> Value {
    json!({"start": {"line": start.0, "character": start.1},
           "end": {"line": end.0, "character": end.1}})
}

/// Line 4 has a name with characters outside ASCII before the material's name, so its
/// columns differ in bytes, characters and UTF-16 units (`é` is 2 bytes and 1 unit, `😀` 4
/// bytes and 2 units).
const MAIN: &str = "import \"lib.scene\"
camera perspective { eye <0, 1, -5> look_at <0, 0, 0> }
light point { position <5, 5, -5> }
material glass { transmissive 0.9 ior 1.5 }
sphere \"ballé😀\" { radius 1 material glass }
sphere { center <2, 0, 0> material chrome }
material mirror { reflective 0.9  }
plane { normal <0, 1, 0> material mirror }
";

/// What the view features show: a comment run and a multi-line block to fold, a colour, a
/// material's defaults and a loop's object count.
const VIEW: &str = "// view
// features
material red {
  diffuse <1, 0, 0>
}
camera perspective { }
light point { position <0, 5, 0> }
for i in 0..3 { sphere { center <i, 0, 0> material red } }
";

const LIB: &str = "material chrome { reflective 0.8 }\n";

#[test]
fn a_whole_session_over_stdio() {
    let dir = tempfile::tempdir().expect("temporary folder");
    std::fs::write(dir.path().join("lib.scene"), LIB).expect("lib.scene");
    let main = Url::from_file_path(dir.path().join("main.scene")).expect("a file URI");
    let lib = Url::from_file_path(dir.path().join("lib.scene")).expect("a file URI");

    let mut session = Session::start();
    let init = session.request("initialize", json!({"capabilities": {}}));
    let capabilities = &init["capabilities"];
    assert_eq!(capabilities["hoverProvider"], json!(true));
    assert_eq!(capabilities["definitionProvider"], json!(true));
    assert_eq!(capabilities["textDocumentSync"], json!(2));
    session.notify("initialized", json!({}));

    session.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": main, "languageId": "whitted", "version": 1, "text": MAIN}}),
    );
    let published = session.diagnostics(&main);
    assert_eq!(published["version"], json!(1));
    assert_eq!(published["diagnostics"], json!([]), "a clean scene");

    // `glass` → `glas` on line 4: the name starts at byte 40, character 36, UTF-16 unit 37.
    let glass = range((4, 37), (4, 42));
    session.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": main, "version": 2},
               "contentChanges": [{"range": glass, "text": "glas"}]}),
    );
    let published = session.diagnostics(&main);
    assert_eq!(published["version"], json!(2));
    let diagnostics = published["diagnostics"].as_array().expect("a list");
    assert_eq!(diagnostics.len(), 1, "{diagnostics:?}");
    assert_eq!(diagnostics[0]["range"], range((4, 37), (4, 41)));
    assert_eq!(diagnostics[0]["severity"], json!(1));
    assert_eq!(
        diagnostics[0]["message"],
        json!(EXPECTED_UNKNOWN_NAME),
        "the compiler's message, label and help"
    );

    // The "did you mean" is a quick fix with its exact edit, linked to the diagnostic.
    let actions = session.request(
        "textDocument/codeAction",
        json!({"textDocument": {"uri": main}, "range": range((4, 38), (4, 38)),
               "context": {"diagnostics": []}}),
    );
    assert_eq!(actions.as_array().map(Vec::len), Some(1), "{actions}");
    assert_eq!(actions[0]["kind"], json!("quickfix"));
    assert_eq!(actions[0]["title"], json!("Replace `glas` with `glass`"));
    assert_eq!(
        actions[0]["diagnostics"][0]["message"],
        json!(EXPECTED_UNKNOWN_NAME)
    );
    assert_eq!(
        actions[0]["edit"]["changes"][main.as_str()],
        json!([{"range": range((4, 37), (4, 41)), "newText": "glass"}])
    );

    session.notify(
        "textDocument/didChange",
        json!({"textDocument": {"uri": main, "version": 3},
               "contentChanges": [{"range": range((4, 37), (4, 41)), "text": "glass"}]}),
    );
    let published = session.diagnostics(&main);
    assert_eq!(published["version"], json!(3));
    assert_eq!(published["diagnostics"], json!([]), "fixed again");

    // Hover on `radius` (line 4, after the name with the wide characters).
    let hover = session.request("textDocument/hover", at(&main, 4, 21));
    assert_eq!(
        hover["contents"]["value"],
        json!("**radius**: the radius\n\na value the shape checks with its other parameters; default `1` (in a sphere)")
    );
    assert_eq!(hover["range"], range((4, 19), (4, 25)));

    // Completion in `material mirror { reflective 0.9 | }`: a material's properties but
    // `reflective`, which it has, and nothing of a sphere's.
    let completion = session.request("textDocument/completion", at(&main, 6, 33));
    let labels: Vec<&str> = completion
        .as_array()
        .expect("a list")
        .iter()
        .map(|item| item["label"].as_str().expect("a label"))
        .collect();
    assert_eq!(labels, EXPECTED_MATERIAL_PROPERTIES);

    // `glass` in the sphere goes to its definition on line 3; `chrome` into lib.scene.
    let definition = session.request("textDocument/definition", at(&main, 4, 39));
    assert_eq!(
        definition,
        json!({"uri": main, "range": range((3, 9), (3, 14))})
    );
    let definition = session.request("textDocument/definition", at(&main, 5, 37));
    assert_eq!(
        definition,
        json!({"uri": lib, "range": range((0, 9), (0, 15))})
    );

    // References of `chrome`, from its use: the definition in lib.scene and the use.
    let mut params = at(&main, 5, 37);
    params["context"] = json!({"includeDeclaration": true});
    let references = session.request("textDocument/references", params);
    assert_eq!(
        references,
        json!([{"uri": lib, "range": range((0, 9), (0, 15))},
               {"uri": main, "range": range((5, 35), (5, 41))}])
    );
    // Renaming it edits lib.scene (not open) and main.scene.
    let mut params = at(&main, 5, 37);
    params["newName"] = json!("steel");
    let edit = session.request("textDocument/rename", params);
    assert_eq!(
        edit["changes"],
        json!({lib.as_str(): [{"range": range((0, 9), (0, 15)), "newText": "steel"}],
               main.as_str(): [{"range": range((5, 35), (5, 41)), "newText": "steel"}]})
    );
    // `glass` (after the wide characters) may not become a keyword nor `mirror`.
    let mut params = at(&main, 4, 39);
    params["newName"] = json!("light");
    assert_eq!(
        session.refused("textDocument/rename", params),
        "`light` is a keyword of the language, not a name"
    );
    let mut params = at(&main, 4, 39);
    params["newName"] = json!("mirror");
    assert_eq!(
        session.refused("textDocument/rename", params),
        "renaming `glass` to `mirror` would clash with another definition: `mirror` is already defined here (defined a second time)"
    );

    // The sphere's name (wide characters counted in UTF-16 units): its only object, and
    // a rename between its quotes.
    let mut params = at(&main, 4, 10);
    params["context"] = json!({"includeDeclaration": true});
    assert_eq!(
        session.request("textDocument/references", params),
        json!([{"uri": main, "range": range((4, 7), (4, 16))}])
    );
    assert_eq!(
        session.request("textDocument/prepareRename", at(&main, 4, 10)),
        json!({"range": range((4, 8), (4, 15)), "placeholder": "ballé😀"})
    );
    let mut params = at(&main, 4, 10);
    params["newName"] = json!("ball");
    assert_eq!(
        session.request("textDocument/rename", params)["changes"],
        json!({main.as_str(): [{"range": range((4, 8), (4, 15)), "newText": "ball"}]})
    );
    // The import's string: every string naming lib.scene (here one) and the file.
    let mut params = at(&main, 0, 10);
    params["context"] = json!({"includeDeclaration": true});
    assert_eq!(
        session.request("textDocument/references", params),
        json!([{"uri": lib, "range": range((0, 0), (0, 0))},
               {"uri": main, "range": range((0, 7), (0, 18))}])
    );
    // Moving lib.scene into a folder rewrites the import.
    assert_eq!(
        capabilities["workspace"]["fileOperations"]["willRename"]["filters"][0]["scheme"],
        json!("file")
    );
    let moved = Url::from_file_path(dir.path().join("parts/lib.scene")).expect("a file URI");
    let edit = session.request(
        "workspace/willRenameFiles",
        json!({"files": [{"oldUri": lib, "newUri": moved}]}),
    );
    assert_eq!(
        edit["changes"],
        json!({main.as_str(): [{"range": range((0, 8), (0, 17)), "newText": "parts/lib.scene"}]})
    );

    let outline = session.request(
        "textDocument/documentSymbol",
        json!({"textDocument": {"uri": main}}),
    );
    let names: Vec<&str> = outline
        .as_array()
        .expect("a list")
        .iter()
        .map(|symbol| symbol["name"].as_str().expect("a name"))
        .collect();
    assert_eq!(
        names,
        [
            "camera perspective",
            "light point",
            "glass",
            "sphere \"ballé😀\"",
            "sphere",
            "mirror",
            "plane"
        ]
    );

    // The view features, on a scene that has what they show.
    assert_eq!(capabilities["foldingRangeProvider"], json!(true));
    assert_eq!(capabilities["colorProvider"], json!(true));
    assert_eq!(capabilities["inlayHintProvider"], json!(true));
    assert_eq!(
        capabilities["semanticTokensProvider"]["legend"]["tokenModifiers"],
        json!(["definition"])
    );
    let view = Url::from_file_path(dir.path().join("view.scene")).expect("a file URI");
    session.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": view, "languageId": "whitted", "version": 1, "text": VIEW}}),
    );
    let document = json!({"textDocument": {"uri": view}});
    let tokens = session.request("textDocument/semanticTokens/full", document.clone());
    let data = tokens["data"].as_array().expect("token data");
    // `// view`, `// features` (comments), `material` (keyword), `red` (a variable, defined).
    assert_eq!(
        data[..20],
        json!([0, 0, 7, 8, 0, 1, 0, 11, 8, 0, 1, 0, 8, 0, 0, 0, 9, 3, 3, 1])
            .as_array()
            .expect("numbers")[..]
    );
    // One line's tokens, by range: the same numbers, the first relative to the start.
    assert_eq!(capabilities["semanticTokensProvider"]["range"], json!(true));
    assert_eq!(
        capabilities["semanticTokensProvider"]["full"],
        json!({"delta": true})
    );
    // A delta from the tokens just sent, with nothing changed since: no edit.
    let id = tokens["resultId"]
        .as_str()
        .expect("a result id")
        .to_string();
    let delta = session.request(
        "textDocument/semanticTokens/full/delta",
        json!({"textDocument": {"uri": view}, "previousResultId": id}),
    );
    assert_eq!(delta["edits"], json!([]));
    assert_ne!(delta["resultId"], json!(id));
    let tokens = session.request(
        "textDocument/semanticTokens/range",
        json!({"textDocument": {"uri": view}, "range": range((2, 0), (3, 0))}),
    );
    assert_eq!(tokens["data"], json!([2, 0, 8, 0, 0, 0, 9, 3, 3, 1]));
    let folds = session.request("textDocument/foldingRange", document.clone());
    assert_eq!(
        folds,
        json!([{"startLine": 0, "endLine": 1, "kind": "comment"},
               {"startLine": 2, "endLine": 3}])
    );
    let colors = session.request("textDocument/documentColor", document.clone());
    assert_eq!(
        colors,
        json!([{"range": range((3, 10), (3, 19)),
                "color": {"red": 1.0, "green": 0.0, "blue": 0.0, "alpha": 1.0}}])
    );
    let presentations = session.request(
        "textDocument/colorPresentation",
        json!({"textDocument": {"uri": view},
               "color": {"red": 0.5, "green": 0.25, "blue": 1.0, "alpha": 1.0},
               "range": range((3, 10), (3, 19))}),
    );
    assert_eq!(presentations[0]["label"], json!("rgb(0.5, 0.25, 1)"));
    assert_eq!(
        presentations[0]["textEdit"],
        json!({"range": range((3, 10), (3, 19)), "newText": "rgb(0.5, 0.25, 1)"})
    );
    let hints = session.request(
        "textDocument/inlayHint",
        json!({"textDocument": {"uri": view}, "range": range((0, 0), (8, 0))}),
    );
    let hints: Vec<(Value, Value)> = hints
        .as_array()
        .expect("hints")
        .iter()
        .map(|h| (h["position"].clone(), h["label"].clone()))
        .collect();
    assert_eq!(
        hints,
        [
            (
                json!({"line": 4, "character": 1}),
                json!("defaults: ambient 0.1, specular 0, shininess 32, reflective 0, …")
            ),
            (json!({"line": 7, "character": 13}), json!("3 objects")),
        ]
    );

    assert_eq!(session.request("shutdown", Value::Null), Value::Null);
    session.notify("exit", Value::Null);
    let status = session.child.wait().expect("the server exits");
    assert!(status.success(), "exit status {status}");
}

const EXPECTED_UNKNOWN_NAME: &str =
    "unknown name `glas` (nothing with this name is defined here)\nhelp: did you mean `glass`?";

/// Every property of a material in the docs' order, but `reflective`, already written.
const EXPECTED_MATERIAL_PROPERTIES: &[&str] = &[
    "ambient",
    "diffuse",
    "specular",
    "shininess",
    "transmissive",
    "ior",
    "fresnel",
    "absorption",
    "emission",
    "priority",
];
