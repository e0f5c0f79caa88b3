//! The source pane: the scene text around the definition of the selected ray's object (or,
//! with `m`, its material), the definition highlighted, titled with its file:line; under it,
//! for an object made inside a loop, a call or an imported file, its instantiation stack.
//! Focused (Tab), it scrolls the file by lines and columns; the scroll belongs to the
//! definition shown, so another ray's starts unscrolled.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget, Wrap};
use whitted_ir::{SourceMap, Span as SourceSpan};
use whitted_tracer::ray_tree::{ShadowOutcome, StackStep};

use crate::action::Focus;
use crate::app::{App, SourceScroll, SourceTarget};

use super::pane_block;

/// What the pane shows: a definition's span, what to call it and, for an object, the
/// loops, calls and imports that made it (innermost first).
struct Target<'a> {
    span: SourceSpan,
    what: String,
    made_by: &'a [StackStep],
}

pub fn draw(app: &App, pane: Rect, buf: &mut Buffer) {
    let focused = app.focus == Focus::Source;
    let (target, note) = target(app);
    let Some(target) = target else {
        let block = pane_block(Line::from(" Source "), focused);
        Paragraph::new(Line::from(note))
            .style(Style::new().fg(Color::Gray))
            .wrap(Wrap { trim: true })
            .block(block)
            .render(pane, buf);
        return;
    };
    let sources = &app.loaded.scene.sources;
    let location = sources.location(target.span);
    let title = format!(" Source · {location} · {} ", target.what);
    let block = pane_block(Line::from(title), focused);
    let mut area = block.inner(pane);
    block.render(pane, buf);
    // The stack goes under the excerpt, which keeps at least a third of the pane.
    let stack = stack_lines(target.made_by);
    let stack_height = (stack.len() as u16).min(area.height.saturating_sub(area.height / 3));
    if stack_height > 0 {
        let below = Rect {
            y: area.y + area.height - stack_height,
            height: stack_height,
            ..area
        };
        area.height -= stack_height;
        Paragraph::new(stack).render(below, buf);
    }
    // The user's scroll belongs to the definition it was made on.
    let scroll = Some(app.source_scroll)
        .filter(|s| s.span == Some(target.span))
        .unwrap_or_default();
    let lines = excerpt(sources, target.span, area.height, scroll);
    match lines {
        Some(lines) => Paragraph::new(lines).render(area, buf),
        None => Paragraph::new(format!("{} was not written in a scene file.", target.what))
            .style(Style::new().fg(Color::Gray))
            .wrap(Wrap { trim: true })
            .render(area, buf),
    }
}

/// The definition the pane shows now, if any: what its scroll belongs to.
pub fn target_span(app: &App) -> Option<SourceSpan> {
    target(app).0.map(|t| t.span)
}

/// The definition to show for the selected ray, or a note saying why there is none.
fn target(app: &App) -> (Option<Target<'_>>, String) {
    // A finding's line, after Enter in the explanation.
    if let Some((span, what)) = &app.source_focus {
        let target = Target {
            span: *span,
            what: what.clone(),
            made_by: &[],
        };
        return (Some(target), String::new());
    }
    let Some(picked) = &app.picked else {
        return (
            None,
            "The definition of what the selected ray hit shows here.".into(),
        );
    };
    let Some(node) = picked.tree.selected_node() else {
        return (None, String::new());
    };
    if let Some(shadow) = &node.shadow {
        let blocker = shadow
            .blocker
            .as_ref()
            .filter(|_| shadow.result == ShadowOutcome::Blocked);
        let target = match blocker {
            Some(blocker) => Target {
                span: blocker.leaf.span,
                what: format!("blocker {}", blocker.leaf.label),
                made_by: &blocker.leaf.made_by,
            },
            None => Target {
                span: shadow.light.span,
                what: format!("light {}", shadow.light.label),
                made_by: &[],
            },
        };
        return (Some(target), String::new());
    }
    let Some(hit) = &node.hit else {
        return (
            None,
            "The ray hit nothing: it returns the scene's background colour.".into(),
        );
    };
    let target = match app.source_target {
        SourceTarget::Object => Target {
            span: hit.leaf.span,
            what: hit.leaf.label.clone(),
            made_by: &hit.leaf.made_by,
        },
        SourceTarget::Material => Target {
            span: hit.material.span,
            what: format!("material {}", hit.material.label),
            made_by: &[],
        },
    };
    (Some(target), String::new())
}

/// The instantiation stack as the pane shows it: a heading, then one line per step,
/// innermost first, each with its `file:line:col`; nothing for an object without one.
fn stack_lines(made_by: &[StackStep]) -> Vec<Line<'static>> {
    if made_by.is_empty() {
        return Vec::new();
    }
    let place = Style::new().fg(Color::DarkGray);
    let mut lines = vec![Line::styled("made by", Style::new().fg(Color::Cyan))];
    lines.extend(made_by.iter().map(|step| {
        Line::from(vec![
            Span::raw(format!("  {}", step.text)),
            Span::styled(format!("  {}", step.location), place),
        ])
    }));
    lines
}

/// Up to `height` numbered lines around `span`, its text highlighted, moved by the user's
/// `scroll` (lines within the file; columns of text, the line numbers staying); `None` when
/// the span points into no file (a built-in default).
fn excerpt(
    sources: &SourceMap,
    span: SourceSpan,
    height: u16,
    scroll: SourceScroll,
) -> Option<Vec<Line<'static>>> {
    let file = sources.get(span.file)?;
    let start = file.line_col(span.start);
    let end = file.line_col(span.end);
    let height = u32::from(height.max(1));
    // The definition's first line a third of the way down, when the file allows.
    let last_first = file.line_count().saturating_sub(height - 1).max(1);
    let first = start.line.saturating_sub(height / 3).max(1).min(last_first);
    let first = (i64::from(first) + i64::from(scroll.lines)).clamp(1, i64::from(last_first)) as u32;
    let skip = usize::from(scroll.columns);
    let last = (first + height - 1).min(file.line_count());
    let gutter = last.to_string().len();
    let highlight = Style::new().fg(Color::Yellow).add_modifier(Modifier::BOLD);
    let mut lines = Vec::new();
    for number in first..=last {
        let text = file.line_text(number).replace('\t', "    ");
        let mut spans = vec![Span::styled(
            format!("{number:>gutter$} │ "),
            Style::new().fg(Color::DarkGray),
        )];
        let in_span = number >= start.line && number <= end.line;
        let text: String = text.chars().skip(skip).collect();
        if in_span {
            // Columns are 1-based characters; the end column is exclusive.
            let from = if number == start.line {
                (start.column as usize - 1).saturating_sub(skip)
            } else {
                0
            };
            let to = if number == end.line {
                (end.column as usize - 1).saturating_sub(skip)
            } else {
                usize::MAX
            };
            let chars: Vec<char> = text.chars().collect();
            let from = from.min(chars.len());
            let to = to.min(chars.len()).max(from);
            spans.push(Span::raw(chars[..from].iter().collect::<String>()));
            spans.push(Span::styled(
                chars[from..to].iter().collect::<String>(),
                highlight,
            ));
            spans.push(Span::raw(chars[to..].iter().collect::<String>()));
        } else {
            spans.push(Span::raw(text));
        }
        lines.push(Line::from(spans));
    }
    Some(lines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::SourceFile;

    #[test]
    fn the_excerpt_highlights_exactly_the_span() {
        let mut sources = SourceMap::new();
        let text = "a\nb\nsphere \"s\" {\n  radius 1\n}\nc\n";
        let file = sources.add(SourceFile::new("x.scene", text));
        let start = text.find("sphere").unwrap();
        let end = text.find("}").unwrap() + 1;
        let span = whitted_ir::Span::new(file, start, end);
        let lines = excerpt(&sources, span, 4, SourceScroll::default()).unwrap();
        let rendered: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        assert_eq!(
            rendered,
            ["2 │ b", "3 │ sphere \"s\" {", "4 │   radius 1", "5 │ }"]
        );
        // Line 3: gutter, nothing before, the highlighted definition, nothing after.
        assert_eq!(lines[1].spans[2].content, "sphere \"s\" {");
        assert_eq!(lines[1].spans[2].style.fg, Some(Color::Yellow));
        assert_eq!(lines[0].spans.len(), 2, "line 2 is outside the span");
        assert!(excerpt(
            &sources,
            whitted_ir::Span::detached(),
            4,
            SourceScroll::default()
        )
        .is_none());
    }
}
