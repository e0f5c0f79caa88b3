//! Hover: a property's documentation from the compiler's property table (for a setting,
//! the IR's settings table), found from the syntax tree's index when the text compiled that
//! far, or from the words around the cursor when it did not parse.

use lsp_types::{Hover, HoverContents, MarkupContent, MarkupKind, Range};
use whitted_lang::editor::{cursor, BlockKind, PropertyDoc};

use crate::documents::Document;

pub fn hover(document: &Document, offset: usize) -> Option<Hover> {
    if let Some(name) = crate::names::hover(document, offset) {
        return Some(name);
    }
    let (block, property, span) =
        from_index(document, offset).or_else(|| from_text(document, offset))?;
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: describe(block, &property),
        }),
        range: Some(Range::new(
            document.lines.position(&document.text, span.start),
            document.lines.position(&document.text, span.end),
        )),
    })
}

/// The hover text: the doc line, what it takes and its default, and the block it is in.
pub fn describe(block: BlockKind, property: &PropertyDoc) -> String {
    let mut text = format!(
        "**{}**: {}\n\n{}",
        property.name, property.doc, property.kind
    );
    if !property.default.is_empty() {
        text.push_str(&format!("; default `{}`", property.default));
    }
    text.push_str(&format!(" (in {})", block.describe()));
    text
}

type Found = (BlockKind, PropertyDoc, std::ops::Range<usize>);

fn from_index(document: &Document, offset: usize) -> Option<Found> {
    let index = document.analysis.as_ref()?.index.as_ref()?;
    let inside = |span: whitted_ir::Span| {
        span.file.0 == 0 && (span.start as usize) <= offset && offset <= span.end as usize
    };
    index
        .blocks
        .iter()
        .filter(|block| inside(block.span))
        .find_map(|block| {
            let (name, span) = block.properties.iter().find(|(_, span)| inside(*span))?;
            Some((block.kind, block.kind.property(name)?, span.range()))
        })
}

/// The word under the cursor, if the words before it make it a property name in its block.
fn from_text(document: &Document, offset: usize) -> Option<Found> {
    let text = &document.text;
    let is_word = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let start = text
        .get(..offset)?
        .rfind(|c| !is_word(c))
        .map_or(0, |i| i + 1);
    let end = text
        .get(offset..)?
        .find(|c| !is_word(c))
        .map_or(text.len(), |i| offset + i);
    let word = text.get(start..end).filter(|w| !w.is_empty())?;
    match cursor::place_at(text, end).place {
        cursor::Place::PropertyName { block, .. } => {
            Some((block, block.property(word)?, start..end))
        }
        _ => None,
    }
}
