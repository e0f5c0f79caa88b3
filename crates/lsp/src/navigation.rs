//! Go to definition (the resolver's links from a name to what it means: materials, `let`s
//! and constants, functions, parameters; and the file an `import` or a mesh's `file` names)
//! and the document's outline.

use lsp_types::{DocumentSymbol, Location, SymbolKind as LspKind, Url};
use whitted_lang::editor::{Symbol, SymbolKind};

use crate::analysis::Locator;
use crate::documents::Document;

pub fn definition(uri: &Url, document: &Document, offset: usize) -> Option<Location> {
    if let Some(file) = named_file(uri, &document.text, offset) {
        return Some(file);
    }
    let analysis = document.analysis.as_ref()?;
    let index = analysis.index.as_ref()?;
    let (_, to) = index.links.iter().find(|(from, _)| {
        from.file.0 == 0 && (from.start as usize) <= offset && offset <= from.end as usize
    })?;
    Locator::new(uri, &analysis.sources, &document.lines).location(*to)
}

/// The file a string names when the cursor is in it and it follows `import` or a mesh's
/// `file`: its start, the path relative to the document as the compiler reads it. Read off
/// the line's text, so it works while the file does not parse; whether the file exists is
/// the editor's to say when it opens it.
fn named_file(uri: &Url, text: &str, offset: usize) -> Option<Location> {
    let offset = offset.min(text.len());
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let line = &text[line_start..line_end];
    let at = offset - line_start;
    // The quoted strings of the line, and the word before each.
    let quotes: Vec<usize> = line.match_indices('"').map(|(i, _)| i).collect();
    for pair in quotes.chunks_exact(2) {
        let (open, close) = (pair[0], pair[1]);
        if !(open < at && at <= close) {
            continue;
        }
        let before = line[..open].trim_end();
        let word = before
            .rsplit(|c: char| !(c.is_alphanumeric() || c == '_'))
            .next()
            .unwrap_or("");
        if word != "import" && word != "file" {
            return None;
        }
        let path = &line[open + 1..close];
        if path.is_empty() || path.contains('{') {
            return None;
        }
        let target = uri.join(path).ok()?;
        return Some(Location::new(target, lsp_types::Range::default()));
    }
    None
}

pub fn symbols(document: &Document) -> Vec<DocumentSymbol> {
    let Some(index) = document.analysis.as_ref().and_then(|a| a.index.as_ref()) else {
        return Vec::new();
    };
    index
        .symbols
        .iter()
        .filter(|s| s.span.file.0 == 0)
        .map(|s| convert(document, s))
        .collect()
}

#[allow(deprecated)] // `deprecated` is a field the type requires; `tags` replaces it.
fn convert(document: &Document, symbol: &Symbol) -> DocumentSymbol {
    let range = |span: whitted_ir::Span| document.lines.range(&document.text, span.range());
    let children: Vec<DocumentSymbol> = symbol
        .children
        .iter()
        .filter(|s| s.span.file.0 == 0)
        .map(|s| convert(document, s))
        .collect();
    DocumentSymbol {
        name: symbol.name.clone(),
        detail: None,
        kind: match symbol.kind {
            SymbolKind::Material => LspKind::STRUCT,
            SymbolKind::Light => LspKind::EVENT,
            SymbolKind::Object => LspKind::OBJECT,
            SymbolKind::Function => LspKind::FUNCTION,
            SymbolKind::Settings => LspKind::NAMESPACE,
            SymbolKind::Camera => LspKind::CLASS,
            SymbolKind::Constant => LspKind::CONSTANT,
            SymbolKind::Variable => LspKind::VARIABLE,
        },
        tags: None,
        deprecated: None,
        range: range(symbol.span),
        selection_range: range(symbol.selection),
        children: (!children.is_empty()).then_some(children),
    }
}
