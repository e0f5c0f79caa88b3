//! Inlay hints from the compiler's own data: after a `settings` block or a material, the
//! properties it leaves at their defaults (from the property table, the settings' from the
//! IR's settings table), and before a `for` loop's body the number of objects it made (from
//! the IR's provenance: every object whose stack holds the loop).

use lsp_types::{InlayHint, InlayHintKind, InlayHintLabel, InlayHintTooltip, Range};
use whitted_ir::{Scene, Span, Step};

use crate::documents::Document;

/// For each loop that made objects, its span (the whole `for` statement) and how many it
/// made, in the order of the loops' spans.
pub fn loop_counts(scene: &Scene) -> Vec<(Span, usize)> {
    let provenance = &scene.provenance;
    if provenance.is_empty() {
        return Vec::new();
    }
    let mut counts: Vec<(Span, usize)> = Vec::new();
    let mut seen: Vec<Span> = Vec::new();
    for (handle, _) in scene.objects.iter() {
        seen.clear();
        for step in provenance.stack(handle) {
            let Step::Loop { span, .. } = step else {
                continue;
            };
            if seen.contains(&span) {
                continue;
            }
            seen.push(span);
            match counts.iter_mut().find(|(s, _)| *s == span) {
                Some((_, n)) => *n += 1,
                None => counts.push((span, 1)),
            }
        }
    }
    counts.sort_by_key(|(span, _)| (span.file.0, span.range().start));
    counts
}

/// How many defaults a hint shows before `…`.
const SHOWN: usize = 4;

/// The hints inside `range` of the document's last analysis.
pub fn hints(document: &Document, range: Range) -> Vec<InlayHint> {
    let Some(analysis) = document.analysis.as_ref() else {
        return Vec::new();
    };
    let text = &document.text;
    let mut out = Vec::new();
    if let Some(index) = &analysis.index {
        for block in index.blocks.iter().filter(|b| b.span.file.0 == 0) {
            if !(block.kind.is_settings() || block.kind.is_material()) {
                continue;
            }
            let defaults: Vec<String> = block
                .kind
                .properties()
                .into_iter()
                .filter(|p| !p.default.is_empty() && !p.is_flag && !p.repeatable)
                .filter(|p| !block.properties.iter().any(|(name, _)| *name == p.name))
                .map(|p| format!("{} {}", p.name, p.default))
                .collect();
            if defaults.is_empty() {
                continue;
            }
            // A readable line: the first few, the whole list in the tooltip.
            let shown = if defaults.len() > SHOWN {
                format!("{}, …", defaults[..SHOWN].join(", "))
            } else {
                defaults.join(", ")
            };
            let mut hint = hint(
                document,
                block.span.range().end,
                format!("defaults: {shown}"),
                None,
            );
            hint.tooltip = Some(InlayHintTooltip::String(format!(
                "left at their defaults: {}",
                defaults.join(", ")
            )));
            out.push(hint);
        }
    }
    for (span, count) in analysis.loops.iter().filter(|(s, _)| s.file.0 == 0) {
        let statement = text.get(span.range()).unwrap_or_default();
        if !statement.starts_with("for") {
            continue;
        }
        // Before the body's `{` (the header holds no brace: a range, a step).
        let Some(brace) = statement.find('{') else {
            continue;
        };
        let header_end = span.range().start + statement[..brace].trim_end().len();
        let label = match count {
            1 => "1 object".to_string(),
            n => format!("{n} objects"),
        };
        out.push(hint(document, header_end, label, Some(InlayHintKind::TYPE)));
    }
    let inside = |h: &InlayHint| {
        let at = (h.position.line, h.position.character);
        (range.start.line, range.start.character) <= at
            && at <= (range.end.line, range.end.character)
    };
    out.retain(inside);
    out.sort_by_key(|h| (h.position.line, h.position.character));
    out
}

fn hint(
    document: &Document,
    offset: usize,
    label: String,
    kind: Option<InlayHintKind>,
) -> InlayHint {
    InlayHint {
        position: document.lines.position(&document.text, offset),
        label: InlayHintLabel::String(label),
        kind,
        text_edits: None,
        tooltip: None,
        padding_left: Some(true),
        padding_right: None,
        data: None,
    }
}
