//! Hover on a name: what it is (a constant, a `let`, a loop variable, a parameter, a
//! function, a material), where it is defined, and what the compiler found for it: a
//! binding's evaluated value, a loop variable's range, a function's signature, a material's
//! properties with its colours as `rgb(...)`.

use lsp_types::{Hover, HoverContents, MarkupContent, MarkupKind};
use whitted_ir::Span;
use whitted_lang::editor::DefinitionKind;

use crate::documents::Document;

pub fn hover(document: &Document, offset: usize) -> Option<Hover> {
    let analysis = document.analysis.as_ref()?;
    let index = analysis.index.as_ref()?;
    let at = |span: &Span| {
        span.file.0 == 0 && (span.start as usize) <= offset && offset <= span.end as usize
    };
    let (under, definition) = index
        .links
        .iter()
        .find(|(from, _)| at(from))
        .copied()
        .or_else(|| {
            let d = index.definitions.iter().find(|d| at(&d.span))?;
            Some((d.span, d.span))
        })?;
    let kind = index
        .definitions
        .iter()
        .find(|d| d.span == definition)
        .map(|d| d.kind)?;
    let file = analysis.sources.get(definition.file)?;
    let name = file.text.get(definition.range())?;
    let line = file
        .text
        .get(..definition.start as usize)
        .map_or(1, |t| t.matches('\n').count() + 1);
    let place = if definition.file.0 == 0 {
        format!("line {line}")
    } else {
        let short = std::path::Path::new(&file.path)
            .file_name()
            .map_or(file.path.clone(), |n| n.to_string_lossy().into_owned());
        format!("{short} line {line}")
    };
    let mut text = format!("**`{name}`**: {} (defined at {place})", kind.describe());
    if let Some(shown) = index.shown.get(&definition) {
        let value = &shown.text;
        let more = match shown.others {
            0 => String::new(),
            1 => " (then 1 other value)".to_string(),
            n => format!(" (then {n} other values)"),
        };
        match kind {
            DefinitionKind::Function => text.push_str(&format!("\n\n```\n{value}\n```")),
            DefinitionKind::Material => {
                text.push_str(&format!("\n\n```\n{value}\n```{more}"));
            }
            DefinitionKind::LoopVariable => text.push_str(&format!("\n\ntakes {value}{more}")),
            _ => text.push_str(&format!("\n\nvalue `{value}`{more}")),
        }
    }
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: text,
        }),
        range: Some(document.lines.range(&document.text, under.range())),
    })
}

/// The picture of the material whose name is under the cursor (its definition or a use),
/// made by `thumbnails`; `None` for anything else, or a material the scene never used.
pub fn material_picture(
    document: &Document,
    offset: usize,
    thumbnails: &dyn crate::Thumbnails,
) -> Option<String> {
    let analysis = document.analysis.as_ref()?;
    let index = analysis.index.as_ref()?;
    let at = |span: &Span| {
        span.file.0 == 0 && (span.start as usize) <= offset && offset <= span.end as usize
    };
    let definition = index
        .links
        .iter()
        .find(|(from, _)| at(from))
        .map(|(_, to)| *to)
        .or_else(|| {
            index
                .definitions
                .iter()
                .find(|d| at(&d.span))
                .map(|d| d.span)
        })?;
    let is_material = index
        .definitions
        .iter()
        .any(|d| d.span == definition && d.kind == DefinitionKind::Material);
    if !is_material {
        return None;
    }
    // The IR material made from that definition: its span is the definition's header.
    let materials = analysis.materials.as_ref()?;
    let (handle, _, _) = materials.iter_with_spans().find(|(_, _, span)| {
        span.file == definition.file && span.start <= definition.start && definition.end <= span.end
    })?;
    thumbnails.material(materials, handle)
}
