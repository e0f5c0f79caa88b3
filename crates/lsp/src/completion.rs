//! Completion that knows where it is (`whitted_lang::editor::cursor`): a block's properties
//! (those it does not have yet, transforms always), a material's name after `material`, a
//! property's words (`shadows` → `opaque`, `filtered`, `none`), and at the start of a
//! statement the keywords and object kinds that may start one there.

use lsp_types::{CompletionItem, CompletionItemKind, Documentation, MarkupContent, MarkupKind};
use whitted_lang::editor::cursor::{self, Place};
use whitted_lang::editor::SymbolKind;

use crate::documents::Document;

pub fn complete(document: &Document, offset: usize) -> Vec<CompletionItem> {
    match cursor::place_at(&document.text, offset).place {
        Place::PropertyName { block, written } => block
            .properties()
            .into_iter()
            .filter(|p| p.repeatable || !written.contains(&p.name))
            .map(|p| {
                let mut detail = p.kind.clone();
                if !p.default.is_empty() {
                    detail.push_str(&format!("; default {}", p.default));
                }
                CompletionItem {
                    label: p.name.to_string(),
                    kind: Some(CompletionItemKind::PROPERTY),
                    detail: Some(detail),
                    documentation: Some(Documentation::MarkupContent(MarkupContent {
                        kind: MarkupKind::Markdown,
                        value: p.doc.to_string(),
                    })),
                    ..CompletionItem::default()
                }
            })
            .collect(),
        Place::Value { property, .. } if property.is_material => materials(document, None),
        Place::Value { property, .. } => property
            .words
            .unwrap_or(&[])
            .iter()
            .map(|word| CompletionItem {
                label: word.to_string(),
                kind: Some(CompletionItemKind::ENUM_MEMBER),
                detail: Some(format!("{} {word}", property.name)),
                ..CompletionItem::default()
            })
            .collect(),
        Place::ParentMaterial { child } => materials(document, child.as_deref()),
        Place::Statement { statements } => statements
            .into_iter()
            .map(|(word, what)| CompletionItem {
                label: word.to_string(),
                kind: Some(CompletionItemKind::KEYWORD),
                detail: Some(what.to_string()),
                ..CompletionItem::default()
            })
            .collect(),
        Place::Other => Vec::new(),
    }
}

/// The materials the text defines (read from the text, so that one typed a moment ago is
/// offered), then those its imports define (from the last analysis); never `except`, the
/// material being defined.
fn materials(document: &Document, except: Option<&str>) -> Vec<CompletionItem> {
    let mut names = cursor::material_names(&document.text);
    if let Some(index) = document.analysis.as_ref().and_then(|a| a.index.as_ref()) {
        for symbol in &index.symbols {
            if symbol.kind == SymbolKind::Material
                && symbol.span.file.0 != 0
                && !names.contains(&symbol.name)
            {
                names.push(symbol.name.clone());
            }
        }
    }
    names
        .into_iter()
        .filter(|name| Some(name.as_str()) != except)
        .map(|name| CompletionItem {
            label: name,
            kind: Some(CompletionItemKind::VALUE),
            detail: Some("material".to_string()),
            ..CompletionItem::default()
        })
        .collect()
}
