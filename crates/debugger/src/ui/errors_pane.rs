//! The scene's errors after a failed reload, in place of the source pane: each message with
//! its file:line:col, the source line underlined, and the compiler's hints. The image and
//! tree stay those of the last scene that compiled.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Widget};
use whitted_ir::{Diagnostic, Severity, SourceMap};

use crate::app::SceneErrors;
use crate::ui::format::wrap_words;

pub fn draw(errors: &SceneErrors, pane: Rect, buf: &mut Buffer) {
    let count = errors.error_count();
    let title = format!(
        " {count} error{} · last good image shown · fix the file or press r ",
        if count == 1 { "" } else { "s" }
    );
    let block = Block::bordered()
        .border_style(Style::new().fg(Color::LightRed))
        .title(
            Line::from(title).style(
                Style::new()
                    .fg(Color::LightRed)
                    .add_modifier(Modifier::BOLD),
            ),
        );
    let width = usize::from(block.inner(pane).width);
    let mut lines = Vec::new();
    for diagnostic in &errors.diagnostics {
        lines.extend(diagnostic_lines(&errors.sources, diagnostic, width));
        lines.push(Line::default());
    }
    Paragraph::new(lines).block(block).render(pane, buf);
}

/// A diagnostic as rustc-like lines fitted to `width` columns: severity and message
/// (wrapped), location, the source line with a caret underline and label (scrolled sideways
/// so the caret shows), then hints (wrapped).
pub fn diagnostic_lines(
    sources: &SourceMap,
    diagnostic: &Diagnostic,
    width: usize,
) -> Vec<Line<'static>> {
    let (word, color) = match diagnostic.severity {
        Severity::Error => ("error", Color::LightRed),
        Severity::Warning => ("warning", Color::Yellow),
        Severity::Note => ("note", Color::LightBlue),
    };
    let head = format!("{word}: ");
    let mut lines = Vec::new();
    for (index, piece) in wrap_words(&diagnostic.message, width.saturating_sub(head.len()).max(8))
        .into_iter()
        .enumerate()
    {
        let lead = if index == 0 {
            Span::styled(
                head.clone(),
                Style::new().fg(color).add_modifier(Modifier::BOLD),
            )
        } else {
            Span::raw(" ".repeat(head.len()))
        };
        lines.push(Line::from(vec![
            lead,
            Span::styled(piece, Style::new().add_modifier(Modifier::BOLD)),
        ]));
    }
    let dim = Style::new().fg(Color::DarkGray);
    if let Some(span) = diagnostic.span {
        lines.push(Line::from(Span::styled(
            format!("  --> {}", sources.location(span)),
            dim,
        )));
        if let Some(file) = sources.get(span.file) {
            let start = file.line_col(span.start);
            let end = file.line_col(span.end);
            let text: Vec<char> = file
                .line_text(start.line)
                .replace('\t', " ")
                .chars()
                .collect();
            let number = start.line.to_string();
            let gutter = number.len() + 3;
            let from = (start.column as usize - 1).min(text.len());
            let underline_width = if end.line == start.line {
                (end.column as usize)
                    .saturating_sub(start.column as usize)
                    .max(1)
            } else {
                text.len().saturating_sub(from).max(1)
            };
            // Scroll a long line so that the underlined part starts a third of the way in.
            let room = width.saturating_sub(gutter).max(1);
            let shift = if from + underline_width > room {
                from.saturating_sub(room / 3)
            } else {
                0
            };
            let shown: String = text.iter().skip(shift).take(room).collect();
            lines.push(Line::from(vec![
                Span::styled(format!("{number} │ "), dim),
                Span::raw(shown),
            ]));
            let mut underline = format!(
                "{}{}",
                " ".repeat(from - shift),
                "^".repeat(underline_width)
            );
            if let Some(label) = &diagnostic.label {
                underline.push(' ');
                underline.push_str(label);
            }
            lines.push(Line::from(vec![
                Span::styled(format!("{} │ ", " ".repeat(number.len())), dim),
                Span::styled(underline, Style::new().fg(color)),
            ]));
        }
    }
    let help = "  = help: ";
    for hint in &diagnostic.hints {
        for (index, piece) in wrap_words(hint, width.saturating_sub(help.len()).max(8))
            .into_iter()
            .enumerate()
        {
            let lead = if index == 0 {
                Span::styled(help, Style::new().fg(Color::LightCyan))
            } else {
                Span::raw(" ".repeat(help.len()))
            };
            lines.push(Line::from(vec![lead, Span::raw(piece)]));
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::{SourceFile, Span as SourceSpan};

    #[test]
    fn a_diagnostic_shows_its_line_and_underlines_the_span() {
        let mut sources = SourceMap::new();
        let text = "sphere { radius -1 }\n";
        let file = sources.add(SourceFile::new("bad.scene", text));
        let start = text.find("-1").unwrap();
        let diagnostic = Diagnostic::error(
            "radius must be positive",
            SourceSpan::new(file, start, start + 2),
        )
        .with_label("this is negative")
        .with_hint("use a radius above 0");
        let lines: Vec<String> = diagnostic_lines(&sources, &diagnostic, 60)
            .iter()
            .map(|l| l.to_string())
            .collect();
        assert_eq!(
            lines,
            [
                "error: radius must be positive",
                "  --> bad.scene:1:17",
                "1 │ sphere { radius -1 }",
                "  │                 ^^ this is negative",
                "  = help: use a radius above 0",
            ]
        );
    }

    #[test]
    fn long_lines_scroll_to_the_error_and_messages_wrap() {
        let mut sources = SourceMap::new();
        let text = format!("{}radius -1\n", "x ".repeat(40));
        let file = sources.add(SourceFile::new("long.scene", text.as_str()));
        let start = text.find("-1").unwrap();
        let diagnostic = Diagnostic::error(
            "a radius must be positive and this message is long enough to wrap",
            SourceSpan::new(file, start, start + 2),
        );
        let lines: Vec<String> = diagnostic_lines(&sources, &diagnostic, 30)
            .iter()
            .map(|l| l.to_string())
            .collect();
        assert!(lines.iter().all(|l| l.chars().count() <= 30), "{lines:#?}");
        let caret = lines.iter().position(|l| l.contains("^^")).unwrap();
        let column = lines[caret].find("^^").unwrap();
        assert_eq!(&lines[caret - 1][column..column + 2], "-1", "{lines:#?}");
    }

    #[test]
    fn wrapping_breaks_at_spaces() {}
}
