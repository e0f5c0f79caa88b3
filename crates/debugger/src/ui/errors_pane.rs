//! The scene's errors after a failed reload, in place of the source pane: each message with
//! its file:line:col, the source line underlined, and the compiler's hints. The image and
//! tree stay those of the last scene that compiled.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Widget, Wrap};
use whitted_ir::{Diagnostic, Severity, SourceMap};

use crate::app::SceneErrors;

pub fn draw(errors: &SceneErrors, pane: Rect, buf: &mut Buffer) {
    let count = errors.error_count();
    let title = format!(
        " {count} error{} · last good image shown · fix the file or press r ",
        if count == 1 { "" } else { "s" }
    );
    let block = Block::bordered()
        .border_style(Style::new().fg(Color::LightRed))
        .title(Line::from(title).style(Style::new().fg(Color::LightRed).add_modifier(Modifier::BOLD)));
    let mut lines = Vec::new();
    for diagnostic in &errors.diagnostics {
        lines.extend(diagnostic_lines(&errors.sources, diagnostic));
        lines.push(Line::default());
    }
    Paragraph::new(lines)
        .wrap(Wrap { trim: false })
        .block(block)
        .render(pane, buf);
}

/// A diagnostic as rustc-like lines: severity and message, location, the source line with a
/// caret underline and label, then hints.
pub fn diagnostic_lines(sources: &SourceMap, diagnostic: &Diagnostic) -> Vec<Line<'static>> {
    let (word, color) = match diagnostic.severity {
        Severity::Error => ("error", Color::LightRed),
        Severity::Warning => ("warning", Color::Yellow),
        Severity::Note => ("note", Color::LightBlue),
    };
    let mut lines = vec![Line::from(vec![
        Span::styled(
            format!("{word}: "),
            Style::new().fg(color).add_modifier(Modifier::BOLD),
        ),
        Span::styled(
            diagnostic.message.clone(),
            Style::new().add_modifier(Modifier::BOLD),
        ),
    ])];
    let dim = Style::new().fg(Color::DarkGray);
    if let Some(span) = diagnostic.span {
        lines.push(Line::from(Span::styled(
            format!("  --> {}", sources.location(span)),
            dim,
        )));
        if let Some(file) = sources.get(span.file) {
            let start = file.line_col(span.start);
            let end = file.line_col(span.end);
            let text = file.line_text(start.line).replace('\t', " ");
            let number = start.line.to_string();
            let pad = " ".repeat(number.len());
            lines.push(Line::from(vec![
                Span::styled(format!("{number} │ "), dim),
                Span::raw(text.clone()),
            ]));
            let from = start.column as usize - 1;
            let width = if end.line == start.line {
                (end.column as usize).saturating_sub(start.column as usize).max(1)
            } else {
                text.chars().count().saturating_sub(from).max(1)
            };
            let mut underline = format!("{}{}", " ".repeat(from), "^".repeat(width));
            if let Some(label) = &diagnostic.label {
                underline.push(' ');
                underline.push_str(label);
            }
            lines.push(Line::from(vec![
                Span::styled(format!("{pad} │ "), dim),
                Span::styled(underline, Style::new().fg(color)),
            ]));
        }
    }
    for hint in &diagnostic.hints {
        lines.push(Line::from(vec![
            Span::styled("  = help: ", Style::new().fg(Color::LightCyan)),
            Span::raw(hint.clone()),
        ]));
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
        let lines: Vec<String> = diagnostic_lines(&sources, &diagnostic)
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
}
