//! Go to definition (the resolver's links from a name to what it means: materials, `let`s
//! and constants, functions, parameters) and the document's outline.

use lsp_types::{DocumentSymbol, Location, SymbolKind as LspKind, Url};
use whitted_lang::editor::{Symbol, SymbolKind};

use crate::analysis::Locator;
use crate::documents::Document;

pub fn definition(uri: &Url, document: &Document, offset: usize) -> Option<Location> {
    let analysis = document.analysis.as_ref()?;
    let index = analysis.index.as_ref()?;
    let (_, to) = index.links.iter().find(|(from, _)| {
        from.file.0 == 0 && (from.start as usize) <= offset && offset <= from.end as usize
    })?;
    Locator::new(uri, &analysis.sources, &document.lines).location(*to)
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
