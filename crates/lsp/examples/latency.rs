//! What the server's answers cost on a big scene (issue 29): a generated scene of 100,000
//! literal sphere statements (the bench's "scenes written by programs" form), then the time
//! from a one-character `didChange` to its diagnostics, and the time of a hover, a
//! completion and a definition near its end, of the semantic tokens of one screen (60
//! lines) in its middle and at its end, and of the whole document's semantic tokens,
//! folding ranges, colours and inlay hints. Prints the figures; measures, asserts nothing.
//! `cargo xtask bench` runs it in a release build.
#![allow(clippy::print_stdout)]

use std::fmt::Write as _;
use std::time::Instant;

use serde_json::json;
use whitted_lsp::position::LineIndex;
use whitted_lsp::{Files, Server};

struct NoFiles;

impl Files for NoFiles {
    fn read(&mut self, _: &std::path::Path) -> std::io::Result<Vec<u8>> {
        Err(std::io::ErrorKind::NotFound.into())
    }
}

struct NoImports;

impl whitted_lang::SourceLoader for NoImports {
    fn load(&mut self, _: &std::path::Path) -> std::io::Result<Vec<u8>> {
        Err(std::io::ErrorKind::NotFound.into())
    }
}

fn main() {
    let statements: usize = std::env::args()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .unwrap_or(100_000);
    let text = scene(statements);
    // What the editor's index adds to a compile: the same text with and without it.
    for index in [false, true] {
        let options = whitted_lang::CompileOptions {
            index,
            ..Default::default()
        };
        let started = Instant::now();
        let compilation =
            whitted_lang::compile_source("big.scene", &text, &mut NoImports, &options);
        println!(
            "compile with index {index}: {:.0} ms ({} diagnostics)",
            ms(started),
            compilation.diagnostics.len()
        );
    }
    let uri = "file:///big.scene";
    let mut server = Server::new(Box::new(NoFiles));
    let started = Instant::now();
    server.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri, "languageId": "whitted", "version": 1, "text": text}}),
    );
    server.analyze_changed();
    println!(
        "{statements} statements, {} bytes: open to diagnostics {:.0} ms",
        text.len(),
        ms(started)
    );
    let lines = LineIndex::new(&text);
    // `radius 0.05` → `radius 0.06` on the last line, then back.
    let digit = text.rfind("0.05").expect("a radius") + 3;
    let at = lines.position(&text, digit);
    let after = lines.position(&text, digit + 1);
    for (version, new) in [(2, "6"), (3, "5")] {
        let started = Instant::now();
        server.notify(
            "textDocument/didChange",
            json!({"textDocument": {"uri": uri, "version": version},
                   "contentChanges": [{"range": {"start": at, "end": after}, "text": new}]}),
        );
        let published = server.analyze_changed();
        println!(
            "didChange to diagnostics: {:.0} ms ({} notification)",
            ms(started),
            published.len()
        );
    }
    let on_radius = text.rfind("radius").expect("radius");
    let on_red = text.rfind("red }").expect("red");
    for (what, method, offset) in [
        (
            "hover on the last `radius`",
            "textDocument/hover",
            on_radius,
        ),
        (
            "completion in the last sphere",
            "textDocument/completion",
            on_radius - 1,
        ),
        (
            "definition of the last `red`",
            "textDocument/definition",
            on_red,
        ),
    ] {
        let position = lines.position(&text, offset);
        let started = Instant::now();
        let (result, _) = server.request(
            method,
            json!({"textDocument": {"uri": uri}, "position": position}),
        );
        println!(
            "{what}: {:.1} ms (answered: {})",
            ms(started),
            result.is_ok_and(|v| !v.is_null())
        );
    }
    // One screen: the semantic tokens of 60 lines in the middle and at the end.
    let line_count = lines.position(&text, text.len()).line;
    for (what, first) in [("middle", line_count / 2), ("end", line_count - 60)] {
        let range = json!({"start": {"line": first, "character": 0},
                           "end": {"line": first + 60, "character": 0}});
        let started = Instant::now();
        let (result, _) = server.request(
            "textDocument/semanticTokens/range",
            json!({"textDocument": {"uri": uri}, "range": range}),
        );
        println!(
            "semantic tokens of 60 lines at the {what}: {:.1} ms (answered: {})",
            ms(started),
            result.is_ok_and(|v| !v.is_null())
        );
    }
    for (what, method) in [
        ("semantic tokens", "textDocument/semanticTokens/full"),
        ("folding ranges", "textDocument/foldingRange"),
        ("document colours", "textDocument/documentColor"),
        ("inlay hints", "textDocument/inlayHint"),
    ] {
        let whole = lines.range(&text, 0..text.len());
        let started = Instant::now();
        let (result, _) = server.request(
            method,
            json!({"textDocument": {"uri": uri}, "range": whole}),
        );
        println!(
            "{what} of the whole document: {:.1} ms (answered: {})",
            ms(started),
            result.is_ok_and(|v| !v.is_null())
        );
    }
}

/// The bench's literal spheres: a header, then one `sphere` statement a line at coordinates
/// from a fixed LCG.
fn scene(statements: usize) -> String {
    let mut text = String::from(
        "camera perspective { eye <0, 5, -60> look_at <0, 0, 0> fov 60 }\n\
         light point { position <10, 40, -30> color <1, 1, 1> }\n\
         material red { diffuse <0.8, 0.2, 0.2> }\n",
    );
    let mut seed = 17u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 40.0 - 20.0
    };
    for _ in 0..statements {
        let (x, y, z) = (next(), next(), next());
        let _ = writeln!(
            text,
            "sphere {{ center <{x:.3}, {y:.3}, {z:.3}> radius 0.05 material red }}"
        );
    }
    text
}

fn ms(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1000.0
}
