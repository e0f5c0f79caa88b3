//! Diagnostics as text, with ariadne: the message, `file:line:column`, the source lines with
//! the span underlined and labelled, secondary labels, and hints.

use std::ops::Range;

use ariadne::{CharSet, Color, Config, IndexType, Label, Report, ReportKind};
use whitted_ir::{Diagnostic, Severity, SourceMap, Span};

/// Renders diagnostics the way rustc does (ariadne): `error: message`, `--> file:line:col`,
/// the source line(s) with the span underlined and labelled, secondary labels, `= hint: ...`.
/// `color` = ANSI colours or plain text (tests and non-terminals use plain).
pub fn render_diagnostics(sources: &SourceMap, diagnostics: &[Diagnostic], color: bool) -> String {
    let mut out = String::new();
    for diagnostic in diagnostics {
        out.push_str(&render_one(sources, diagnostic, color));
    }
    out
}

/// The name ariadne shows for a file: its path (unique within a compilation).
fn file_name(sources: &SourceMap, span: Span) -> Option<String> {
    sources.get(span.file).map(|f| f.path.clone())
}

/// A span clamped to its file's text, so no bad span can upset the renderer.
fn clamp(sources: &SourceMap, span: Span) -> Option<(String, Range<usize>)> {
    let file = sources.get(span.file)?;
    let len = file.text.len();
    let mut start = (span.start as usize).min(len);
    let mut end = (span.end as usize).clamp(start, len);
    while !file.text.is_char_boundary(start) {
        start -= 1;
    }
    while !file.text.is_char_boundary(end) {
        end += 1;
    }
    Some((file.path.clone(), start..end))
}

fn render_one(sources: &SourceMap, diagnostic: &Diagnostic, color: bool) -> String {
    // rustc's lower-case words, in ariadne's layout.
    let (kind, label_color) = match diagnostic.severity {
        Severity::Error => (ReportKind::Custom("error", Color::Red), Color::Red),
        Severity::Warning => (ReportKind::Custom("warning", Color::Yellow), Color::Yellow),
        Severity::Note => (ReportKind::Custom("note", Color::Cyan), Color::Cyan),
    };
    let primary = diagnostic.span.and_then(|span| clamp(sources, span));
    let Some(primary) = primary else {
        return render_without_source(diagnostic, color);
    };
    let config = Config::default()
        .with_color(color)
        .with_index_type(IndexType::Byte)
        .with_char_set(if color {
            CharSet::Unicode
        } else {
            CharSet::Ascii
        })
        .with_compact(false);
    let mut report = Report::build(kind, primary.clone())
        .with_config(config)
        .with_message(&diagnostic.message);
    // ariadne underlines only labels with a message.
    let text = diagnostic.label.as_deref().unwrap_or("here");
    let mut labels = vec![(primary.clone(), text, label_color)];
    for secondary in &diagnostic.secondary {
        if let Some(span) = clamp(sources, secondary.span) {
            labels.push((span, secondary.message.as_str(), Color::Blue));
        }
    }
    // ariadne starts a new snippet whenever a label is above the previous one; in file and
    // line order, each file is one snippet (the primary's file first).
    labels.sort_by_key(|((file, range), _, _)| (*file != primary.0, file.clone(), range.start));
    for (span, text, label_color) in labels {
        let mut label = Label::new(span).with_message(text);
        if color {
            label = label.with_color(label_color);
        }
        report = report.with_label(label);
    }
    for hint in &diagnostic.hints {
        report = report.with_help(hint);
    }
    let mut files: Vec<(String, String)> = Vec::new();
    let spans = diagnostic
        .span
        .iter()
        .chain(diagnostic.secondary.iter().map(|l| &l.span));
    for span in spans {
        if let Some(name) = file_name(sources, *span) {
            if !files.iter().any(|(n, _)| *n == name) {
                if let Some(file) = sources.get(span.file) {
                    files.push((name, file.text.to_string()));
                }
            }
        }
    }
    let mut buffer = Vec::new();
    match report.finish().write(ariadne::sources(files), &mut buffer) {
        Ok(()) => {
            let text = String::from_utf8_lossy(&buffer).into_owned();
            // ariadne colours a custom report kind even with colour off.
            if color {
                text
            } else {
                strip_ansi(&text)
            }
        }
        Err(_) => render_without_source(diagnostic, color),
    }
}

/// Removes ANSI colour sequences (`ESC [ ... m`).
fn strip_ansi(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        if c == '\x1b' {
            for c in chars.by_ref() {
                if c == 'm' {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// Diagnostics that no source text made (a bad `-D` name, a file that cannot be read).
fn render_without_source(diagnostic: &Diagnostic, color: bool) -> String {
    let (word, code) = match diagnostic.severity {
        Severity::Error => ("error", "31"),
        Severity::Warning => ("warning", "33"),
        Severity::Note => ("note", "36"),
    };
    let mut out = if color {
        format!("\x1b[{code}m{word}:\x1b[0m {}\n", diagnostic.message)
    } else {
        format!("{word}: {}\n", diagnostic.message)
    };
    for hint in &diagnostic.hints {
        out.push_str(&format!("    Help: {hint}\n"));
    }
    out
}
