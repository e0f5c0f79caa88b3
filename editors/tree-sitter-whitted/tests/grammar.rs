//! The tree-sitter grammar against the real language: every scene in scenes/ and every scene example of docs/language.md parses without an error node, broken scenes get an error node on the line whitted reports, and the queries compile and capture what they should.

use std::path::{Path, PathBuf};

use tree_sitter::{Node, Parser, Query, QueryCursor, StreamingIterator, Tree};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn parse(text: &str) -> Tree {
    let mut parser = Parser::new();
    parser
        .set_language(&tree_sitter_whitted::LANGUAGE.into())
        .expect("the generated parser's ABI is one the runtime reads");
    parser.parse(text, None).expect("a parse tree")
}

/// The first leaf after `node` in the text, if any.
fn next_leaf(node: Node<'_>) -> Option<Node<'_>> {
    let mut current = node;
    let mut next = loop {
        match current.next_sibling() {
            Some(sibling) => break sibling,
            None => current = current.parent()?,
        }
    };
    while let Some(child) = next.child(0) {
        next = child;
    }
    Some(next)
}

/// Every ERROR or MISSING node: (1-based line, what it is). A MISSING node is an empty node
/// at the end of what came before (`eye <0, 1, -5` lacks its `>`); it is located, as whitted
/// locates the error, at the token that could not follow, which is the next leaf.
fn error_nodes(tree: &Tree) -> Vec<(usize, String)> {
    fn walk(node: Node<'_>, found: &mut Vec<(usize, String)>) {
        if node.is_error() {
            found.push((node.start_position().row + 1, node.to_sexp()));
        }
        if node.is_missing() {
            let at = next_leaf(node).unwrap_or(node);
            found.push((at.start_position().row + 1, node.to_sexp()));
        }
        if node.has_error() {
            let mut cursor = node.walk();
            for child in node.children(&mut cursor) {
                walk(child, found);
            }
        }
    }
    let mut found = Vec::new();
    walk(tree.root_node(), &mut found);
    found
}

fn scene_files(dir: &Path, found: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir)
        .expect("scenes/ is readable")
        .flatten()
    {
        let path = entry.path();
        if path.is_dir() {
            scene_files(&path, found);
        } else if path.extension().is_some_and(|e| e == "scene") {
            found.push(path);
        }
    }
}

/// The ```scene blocks of docs/language.md: (line of the first line of the body, body).
/// Fences are read as crates/lang/tests/lang/docs.rs reads them.
fn docs_examples() -> Vec<(usize, String)> {
    let markdown = std::fs::read_to_string(root().join("docs/language.md")).expect("docs");
    let mut blocks = Vec::new();
    let mut current: Option<(usize, String)> = None;
    for (number, line) in markdown.lines().enumerate() {
        match (&mut current, line.strip_prefix("```")) {
            (None, Some(info)) => {
                if info.split_whitespace().next() == Some("scene") {
                    current = Some((number + 2, String::new()));
                }
            }
            (Some(_), Some(_)) => blocks.extend(current.take()),
            (Some((_, body)), None) => {
                body.push_str(line);
                body.push('\n');
            }
            (None, None) => {}
        }
    }
    blocks
}

#[test]
fn every_scene_parses_without_error_nodes() {
    let mut files = Vec::new();
    scene_files(&root().join("scenes"), &mut files);
    files.sort();
    assert!(files.len() >= 30, "only {} scenes found", files.len());
    let mut failures = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("a scene is readable");
        let errors = error_nodes(&parse(&text));
        if let Some((line, node)) = errors.first() {
            failures.push(format!("{}:{line}: {node}", file.display()));
        }
    }
    assert!(failures.is_empty(), "error nodes:\n{}", failures.join("\n"));
}

#[test]
fn every_docs_example_parses_without_error_nodes() {
    let examples = docs_examples();
    assert!(examples.len() >= 25, "only {} examples", examples.len());
    let mut failures = Vec::new();
    for (first_line, body) in &examples {
        let errors = error_nodes(&parse(body));
        if let Some((line, node)) = errors.first() {
            failures.push(format!(
                "docs/language.md:{}: {node}",
                first_line + line - 1
            ));
        }
    }
    assert!(failures.is_empty(), "error nodes:\n{}", failures.join("\n"));
}

/// The line of whitted's first error for `text` (its own parser, pest).
fn whitted_error_line(text: &str) -> u32 {
    struct NoFiles;
    impl whitted_lang::SourceLoader for NoFiles {
        fn load(&mut self, _: &Path) -> std::io::Result<Vec<u8>> {
            Err(std::io::ErrorKind::NotFound.into())
        }
    }
    let compilation = whitted_lang::compile_source(
        "broken.scene",
        text,
        &mut NoFiles,
        &whitted_lang::CompileOptions::default(),
    );
    let error = compilation
        .diagnostics
        .iter()
        .find(|d| d.is_error())
        .unwrap_or_else(|| panic!("whitted accepts the broken scene:\n{text}"));
    let span = error.span.expect("a syntax error has a place");
    compilation
        .sources
        .line_col(span)
        .expect("in the file")
        .line
}

#[test]
fn broken_scenes_get_an_error_node_on_whitteds_line() {
    let broken = [
        // A property written with `=`.
        "material m { diffuse 0.5 }\nsphere { radius = 1 material m }\n",
        // A missing `;` after a `let`.
        "let r = 1\nsphere { radius r }\n",
        // An unclosed vector.
        "camera perspective {\n    eye <0, 1, -5\n    look_at <0, 0, 0>\n}\n",
        // Not "a keyword as a name" (`let light = 2;`): reserved words need ABI 15, and the
        // parser is generated at ABI 14 for Neovim 0.7; the server still reports it.
        // A comparison inside a vector needs brackets.
        "let a = 1;\nsphere {\n    center <a > 0, 0, 0>\n}\n",
        // A `for` without `in`.
        "for i 0..3 {\n    sphere { }\n}\n",
        // An unclosed argument list.
        "sphere {\n    center <0, 0, 0>\n    radius max(1, 2\n}\nlight point { position <0, 5, 0> }\n",
        // A stray operator.
        "settings { width 64 }\nsphere { radius 1 * }\n",
    ];
    let mut failures = Vec::new();
    for text in broken {
        let line = whitted_error_line(text) as usize;
        let errors = error_nodes(&parse(text));
        if !errors.iter().any(|(l, _)| *l == line) {
            failures.push(format!(
                "whitted reports line {line}, tree-sitter's error nodes are {errors:?}, in:\n{text}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The captures of `query` in `text`: (capture name, captured text).
fn captures(query_source: &str, text: &str) -> Vec<(String, String)> {
    let language = tree_sitter_whitted::LANGUAGE.into();
    let query = Query::new(&language, query_source).expect("the query compiles");
    let tree = parse(text);
    let mut cursor = QueryCursor::new();
    let mut matches = cursor.matches(&query, tree.root_node(), text.as_bytes());
    let mut found = Vec::new();
    while let Some(m) = matches.next() {
        for capture in m.captures() {
            let name = query.capture_names()[capture.index as usize].to_string();
            let node_text = capture.node.utf8_text(text.as_bytes()).expect("utf-8");
            found.push((name, node_text.to_string()));
        }
    }
    found
}

const SAMPLE: &str = r#"// A sample.
import "lib.scene"
/* two
   lines */
const N = 3;
fn ring(n, r) {
    for i in 0..n step 1 {
        sphere "bead {i}" { center <r * cos(i * 360 / n), 0, 0> radius 0.35 }
    }
}
settings { shadows filtered }
material glass : base { ior 1.5 }
if N > 2 && true { cylinder { open rotate 30 about <0, 1, 0> } } else { ring(N, 2) }
"#;

#[test]
fn the_highlight_query_captures_keywords_numbers_strings_and_comments() {
    let found = captures(tree_sitter_whitted::HIGHLIGHTS_QUERY, SAMPLE);
    let has = |capture: &str, text: &str| {
        found
            .iter()
            .any(|(c, t)| c.as_str() == capture && t.as_str() == text)
    };
    let expected = [
        ("comment", "// A sample."),
        ("comment", "/* two\n   lines */"),
        ("keyword.import", "import"),
        ("string", "\"lib.scene\""),
        ("keyword", "const"),
        ("constant", "N"),
        ("number", "3"),
        ("keyword.function", "fn"),
        ("function", "ring"),
        ("variable.parameter", "n"),
        ("keyword.repeat", "for"),
        ("keyword.repeat", "in"),
        ("keyword.repeat", "step"),
        ("operator", ".."),
        ("type.builtin", "sphere"),
        ("string", "\"bead {i}\""),
        ("string.special", "{i}"),
        ("property", "center"),
        ("function.builtin", "cos"),
        ("number", "360"),
        ("number", "0.35"),
        ("constant.builtin", "filtered"),
        ("type.definition", "glass"),
        ("type", "base"),
        ("keyword.conditional", "if"),
        ("keyword.conditional", "else"),
        ("boolean", "true"),
        ("constant.builtin", "open"),
        ("keyword", "about"),
        ("function.call", "ring"),
        ("punctuation.bracket", "<"),
        ("operator", ">"),
    ];
    let missing: Vec<_> = expected.iter().filter(|(c, t)| !has(c, t)).collect();
    assert!(
        missing.is_empty(),
        "not captured: {missing:?}\ncaptures: {found:?}"
    );
    assert!(error_nodes(&parse(SAMPLE)).is_empty());
}

#[test]
fn the_fold_and_indent_queries_compile_and_capture_blocks() {
    let folds = captures(tree_sitter_whitted::FOLDS_QUERY, SAMPLE);
    assert!(folds
        .iter()
        .any(|(c, t)| c == "fold" && t.starts_with("{\n    for i")));
    assert!(folds
        .iter()
        .any(|(c, t)| c == "fold" && t.starts_with("/* two")));
    let indents = captures(tree_sitter_whitted::INDENTS_QUERY, SAMPLE);
    assert!(indents
        .iter()
        .any(|(c, t)| c == "indent.begin" && t.starts_with("{ shadows")));
    assert!(indents.iter().any(|(c, t)| c == "indent.end" && t == "}"));
}

#[test]
fn node_types_name_the_statements() {
    let types = tree_sitter_whitted::NODE_TYPES;
    for kind in [
        "\"object\"",
        "\"property\"",
        "\"function_definition\"",
        "\"for_statement\"",
        "\"vector\"",
        "\"call\"",
    ] {
        assert!(types.contains(kind), "node-types.json lacks {kind}");
    }
}
