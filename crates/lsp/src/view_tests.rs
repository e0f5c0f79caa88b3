//! The view requests through the server: colours with their ranges and inlay hints with
//! their positions and labels, from an open document's analysis.

use lsp_types::Url;
use serde_json::{json, Value};

use crate::{Files, Server};

struct NoFiles;

impl Files for NoFiles {
    fn read(&mut self, _: &std::path::Path) -> std::io::Result<Vec<u8>> {
        Err(std::io::ErrorKind::NotFound.into())
    }
}

fn uri() -> Url {
    Url::parse("file:///project/view.scene").expect("a URI")
}

/// A server with `text` open, analysed.
fn server_with(text: &str) -> Server {
    let mut server = Server::new(Box::new(NoFiles));
    server.notify(
        "textDocument/didOpen",
        json!({"textDocument": {"uri": uri(), "languageId": "whitted", "version": 1, "text": text}}),
    );
    server.analyze_changed();
    server
}

fn ask(server: &mut Server, method: &str, extra: Value) -> Value {
    let mut params = json!({"textDocument": {"uri": uri()}});
    if let (Some(params), Some(extra)) = (params.as_object_mut(), extra.as_object()) {
        params.extend(extra.clone());
    }
    let (result, _) = server.request(method, params);
    result.unwrap_or_else(|e| panic!("{method}: {}", e.message))
}

fn range(start: (u32, u32), end: (u32, u32)) -> Value {
    json!({"start": {"line": start.0, "character": start.1},
           "end": {"line": end.0, "character": end.1}})
}

/// A light's colour above 1 is clamped for the swatch; a material's `rgb(…)` is found; a
/// position (`center`) and an expression are not colours.
#[test]
fn colour_literals_of_colour_properties_with_their_ranges() {
    let text = "light point { position <5, 5, -5> color <2, 1, 0.5> }\n\
                material m { diffuse rgb(0.2, 0.4, 0.6) specular <1, 1, 1> * 0.5 }\n\
                sphere { center <0, 0, 0> radius 1 material m }\n";
    let mut server = server_with(text);
    let colors = ask(&mut server, "textDocument/documentColor", json!({}));
    assert_eq!(
        colors,
        json!([
            {"range": range((0, 40), (0, 51)),
             "color": {"red": 1.0, "green": 1.0, "blue": 0.5, "alpha": 1.0}},
            {"range": range((1, 21), (1, 39)),
             "color": {"red": 0.2f32, "green": 0.4f32, "blue": 0.6f32, "alpha": 1.0}},
        ])
    );
}

/// The settings and the material list what they leave at their defaults after their `}`;
/// the loop says how many objects it made before its body.
#[test]
fn inlay_hints_for_defaults_and_loop_counts() {
    let text = "settings { max_depth 3 }\n\
                material m { diffuse 0.5 }\n\
                camera perspective { }\n\
                light point { position <0, 5, 0> }\n\
                for i in 0..4 { sphere { center <i, 0, 0> radius 0.5 material m } }\n";
    let mut server = server_with(text);
    let hints = ask(
        &mut server,
        "textDocument/inlayHint",
        json!({"range": range((0, 0), (9, 0))}),
    );
    let found: Vec<(u64, u64, String)> = hints
        .as_array()
        .expect("hints")
        .iter()
        .map(|h| {
            (
                h["position"]["line"].as_u64().unwrap_or(99),
                h["position"]["character"].as_u64().unwrap_or(99),
                h["label"].as_str().unwrap_or_default().to_string(),
            )
        })
        .collect();
    let expected: Vec<(u64, u64, String)> = vec![
        (
            0,
            24,
            "defaults: width 640, height 480, min_weight 0.001, samples 1, …".to_string(),
        ),
        (
            1,
            26,
            "defaults: ambient 0.1, specular 0, shininess 32, reflective 0, …".to_string(),
        ),
        (4, 13, "4 objects".to_string()),
    ];
    assert_eq!(found, expected);
    // Only the hints inside the range asked for.
    let later = ask(
        &mut server,
        "textDocument/inlayHint",
        json!({"range": range((2, 0), (9, 0))}),
    );
    assert_eq!(later.as_array().map(Vec::len), Some(1));
}
