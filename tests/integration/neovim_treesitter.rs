//! The tree-sitter grammar in a real editor: the generated parser compiled with `cc`, loaded by
//! headless Neovim (Debian's 0.7.2), its queries run on real scenes: exact captures, no
//! error node on a good scene, an error on a broken one's line, the folds' line ranges.

use std::path::Path;
use std::process::Command;

/// What the probe asks Neovim: load the parser, parse a good and a broken scene, run the
/// highlight and fold queries, write everything as JSON, quit. Runs on 0.7 and on 0.9+.
const PROBE: &str = r#"
local so, queries = vim.env.WHITTED_TS_SO, vim.env.WHITTED_TS_QUERIES
vim.treesitter.require_language("whitted", so)
local parse = vim.treesitter.query.parse or vim.treesitter.parse_query
local function query(name)
  return parse("whitted", table.concat(vim.fn.readfile(queries .. "/" .. name), "\n"))
end
local function tree(path)
  local buf = vim.fn.bufadd(path)
  vim.fn.bufload(buf)
  return buf, vim.treesitter.get_parser(buf, "whitted"):parse()[1]:root()
end
local function errors(node, out)
  if node:type() == "ERROR" or node:missing() then
    local row = node:range()
    table.insert(out, row)
  end
  for child in node:iter_children() do errors(child, out) end
  return out
end
local good, root = tree("good.scene")
local captures, folds = {}, {}
local hl = query("highlights.scm")
for id, node in hl:iter_captures(root, good, 0, -1) do
  local row, col = node:range()
  table.insert(captures, { row = row, col = col, name = hl.captures[id],
    text = vim.treesitter.get_node_text and vim.treesitter.get_node_text(node, good)
      or vim.treesitter.query.get_node_text(node, good) })
end
local fq = query("folds.scm")
for _, node in fq:iter_captures(root, good, 0, -1) do
  local start, _, stop = node:range()
  table.insert(folds, { start, stop })
end
local _, broken = tree("broken.scene")
vim.fn.writefile({ vim.fn.json_encode({
  captures = captures, folds = folds, good_errors = errors(root, {}),
  broken_errors = errors(broken, {}),
}) }, "treesitter.json")
vim.cmd("qa!")
"#;

#[test]
fn neovim_highlights_and_folds_a_scene_with_the_tree_sitter_grammar() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let grammar = root.join("editors/tree-sitter-whitted");
    let dir = tempfile::tempdir().expect("a temporary directory");
    let so = dir.path().join("whitted.so");
    let built = Command::new("cc")
        .args(["-shared", "-fPIC", "-O1", "-I"])
        .arg(grammar.join("src"))
        .arg(grammar.join("src/parser.c"))
        .arg("-o")
        .arg(&so)
        .status()
        .expect("a C compiler (`cc`) runs");
    assert!(built.success(), "cc compiles src/parser.c");
    std::fs::copy(
        root.join("scenes/attenuation.scene"),
        dir.path().join("good.scene"),
    )
    .expect("copied");
    // `radius = 1` on the third line (0-based 2): the error node is there.
    std::fs::write(
        dir.path().join("broken.scene"),
        "material m { diffuse 0.5 }\nsphere { radius 1 material m }\nsphere { radius = 1 }\n",
    )
    .expect("writable");
    std::fs::write(dir.path().join("probe.lua"), PROBE).expect("writable");
    let status = Command::new("nvim")
        .current_dir(dir.path())
        .env("WHITTED_TS_SO", &so)
        .env("WHITTED_TS_QUERIES", grammar.join("queries"))
        .env("XDG_STATE_HOME", dir.path())
        .env("XDG_CACHE_HOME", dir.path())
        .args(["--clean", "--headless", "-c", "luafile probe.lua"])
        .status()
        .expect("Neovim runs");
    assert!(status.success());
    let written = std::fs::read_to_string(dir.path().join("treesitter.json"))
        .expect("the probe wrote its JSON (a Lua error stops it before)");
    let report: serde_json::Value = serde_json::from_str(&written).expect("JSON");
    // The capture Neovim shows for a node is the last pattern's: find it by position.
    let capture = |row: u64, col: u64| -> (String, String) {
        let last = report["captures"]
            .as_array()
            .expect("captures")
            .iter()
            .rfind(|c| c["row"] == row && c["col"] == col)
            .unwrap_or_else(|| panic!("no capture at {row}:{col}: {written}"));
        (
            last["name"].as_str().expect("name").to_owned(),
            last["text"].as_str().expect("text").to_owned(),
        )
    };
    let expected = [
        ((0, 0), ("comment", "// Light attenuation: a row of posts lit by a low point light with quadratic fall-off, so the")),
        ((2, 0), ("keyword", "settings")),
        ((2, 17), ("number", "640")),
        ((4, 0), ("keyword", "light")),
        ((4, 12), ("string", "\"fading\"")),
        ((6, 0), ("keyword", "material")),
        ((6, 9), ("type.definition", "floor")),
        ((8, 0), ("type.builtin", "plane")),
        ((9, 0), ("keyword.repeat", "for")),
    ];
    for ((row, col), (name, text)) in expected {
        assert_eq!(
            capture(row, col),
            (name.to_owned(), text.to_owned()),
            "at {row}:{col}"
        );
    }
    assert_eq!(report["good_errors"], serde_json::json!([]), "{written}");
    assert_eq!(report["broken_errors"], serde_json::json!([2]), "{written}");
    // Every block is a fold; Neovim folds only those spanning lines: the `for` loop's.
    let multi_line: Vec<&serde_json::Value> = report["folds"]
        .as_array()
        .expect("folds")
        .iter()
        .filter(|f| f[0] != f[1])
        .collect();
    assert_eq!(multi_line, [&serde_json::json!([9, 12])], "{written}");
}
