//! Diagnostics as text, with ariadne: the message, `file:line:column`, the source lines with
//! the span underlined and labelled, secondary labels, and hints.

use std::ops::Range;

use std::collections::HashMap;

use ariadne::{CharSet, Color, Config, IndexType, Label, Report, ReportKind};
use whitted_ir::{Diagnostic, FileId, Severity, SourceMap, Span};

/// Renders diagnostics the way rustc does (ariadne): `error: message`, `--> file:line:col`,
/// the source line(s) with the span underlined and labelled, secondary labels, `= hint: ...`.
/// `color` = ANSI colours or plain text (tests and non-terminals use plain).
///
/// Control characters in the source, in file names and in messages (an ESC in a string or an
/// object's name) are shown escaped, as `\u{1b}`, so that no diagnostic can move the cursor
/// or recolour the terminal. Each file's text is prepared once, however many diagnostics
/// point into it.
pub fn render_diagnostics(sources: &SourceMap, diagnostics: &[Diagnostic], color: bool) -> String {
    let mut files = Files::default();
    // Long lines are shown only around the places diagnostics point at.
    for diagnostic in diagnostics {
        let spans = diagnostic
            .span
            .iter()
            .chain(diagnostic.secondary.iter().map(|l| &l.span));
        for span in spans {
            let places = files.places.entry(span.file).or_default();
            places.push(span.start as usize);
            places.push(span.end as usize);
        }
    }
    for places in files.places.values_mut() {
        places.sort_unstable();
    }
    let mut out = String::new();
    for diagnostic in diagnostics {
        out.push_str(&render_one(sources, &mut files, diagnostic, color));
    }
    out
}

// How many times a file's text was prepared for ariadne, over all renders on this thread:
// tests count it to prove the work per file is done once, not once per diagnostic.
#[cfg(test)]
thread_local! {
    pub(crate) static PREPARED_FILES: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Lines longer than this many bytes are shown only around the places diagnostics point at
/// (a one-line 64 MiB expression would otherwise be printed whole).
const LONG_LINE: usize = 400;

/// Bytes kept on each side of a place in a long line.
const CONTEXT: usize = 80;

/// A file's text as ariadne shows it: control characters escaped, long lines cut down to the
/// parts around the places diagnostics point at. `deltas` says how offsets moved.
struct Escaped {
    /// The name ariadne shows (the path, escaped).
    name: String,
    /// From each original offset on (until the next entry), the shown offset is the original
    /// plus this.
    deltas: Vec<(usize, isize)>,
}

impl Escaped {
    /// An original byte offset in the shown text.
    fn map(&self, offset: usize) -> usize {
        let before = self.deltas.partition_point(|&(at, _)| at <= offset);
        match before {
            0 => offset,
            n => offset.saturating_add_signed(self.deltas[n - 1].1),
        }
    }
}

/// The files prepared so far, and ariadne's line index of each.
#[derive(Default)]
struct Files {
    /// Sorted offsets that diagnostics point at, per file: long lines keep these parts.
    places: HashMap<FileId, Vec<usize>>,
    escaped: HashMap<FileId, Escaped>,
    ariadne: HashMap<String, ariadne::Source<String>>,
}

impl Files {
    fn prepare(&mut self, sources: &SourceMap, file: FileId) -> Option<&Escaped> {
        if !self.escaped.contains_key(&file) {
            let source = sources.get(file)?;
            #[cfg(test)]
            PREPARED_FILES.with(|n| n.set(n.get() + 1));
            let original: &str = &source.text;
            let places = self.places.remove(&file).unwrap_or_default();
            // Offsets only grow, so the first place not yet behind us moves forward only.
            let mut next_place = 0;
            let mut text = String::with_capacity(original.len().min(1 << 20));
            let mut deltas = Vec::new();
            let mut delta: isize = 0;
            let mut line_start = 0;
            while line_start < original.len() {
                let line_end = original[line_start..]
                    .find('\n')
                    .map_or(original.len(), |i| line_start + i + 1);
                let long = line_end - line_start > LONG_LINE;
                let mut eliding = false;
                let mut chars = original[line_start..line_end].char_indices().peekable();
                while let Some((i, c)) = chars.next() {
                    let at = line_start + i;
                    while places.get(next_place).is_some_and(|&p| p + CONTEXT < at) {
                        next_place += 1;
                    }
                    let near = places.get(next_place).is_some_and(|&p| p <= at + CONTEXT);
                    if long && c != '\n' && !near {
                        // Offsets inside an elided run point at nothing shown; no entry.
                        if !eliding {
                            text.push('…');
                            eliding = true;
                        }
                        continue;
                    }
                    eliding = false;
                    let here = text.len() as isize - at as isize;
                    if here != delta {
                        delta = here;
                        deltas.push((at, delta));
                    }
                    let crlf = c == '\r' && matches!(chars.peek(), Some((_, '\n')));
                    if !needs_escape(c) || crlf {
                        text.push(c);
                    } else {
                        text.push_str(&escape_char(c));
                    }
                    let moved = text.len() as isize - (at + c.len_utf8()) as isize;
                    if moved != delta {
                        delta = moved;
                        deltas.push((at + c.len_utf8(), delta));
                    }
                }
                line_start = line_end;
            }
            let here = text.len() as isize - original.len() as isize;
            if here != delta {
                deltas.push((original.len(), here));
            }
            let name = escape_text(&source.path);
            self.ariadne
                .entry(name.clone())
                .or_insert_with(|| ariadne::Source::from(text));
            self.escaped.insert(file, Escaped { name, deltas });
        }
        self.escaped.get(&file)
    }

    /// A span clamped to its file's text and moved into the shown text.
    fn clamp(&mut self, sources: &SourceMap, span: Span) -> Option<(String, Range<usize>)> {
        let file = sources.get(span.file)?;
        let text = file.text.clone();
        let len = text.len();
        let mut start = (span.start as usize).min(len);
        let mut end = (span.end as usize).clamp(start, len);
        while !text.is_char_boundary(start) {
            start -= 1;
        }
        while !text.is_char_boundary(end) {
            end += 1;
        }
        let escaped = self.prepare(sources, span.file)?;
        let (start, end) = (escaped.map(start), escaped.map(end));
        Some((escaped.name.clone(), start..end.max(start)))
    }
}

impl ariadne::Cache<String> for &mut Files {
    type Storage = String;

    fn fetch(&mut self, id: &String) -> Result<&ariadne::Source<String>, impl std::fmt::Debug> {
        self.ariadne
            .get(id)
            .ok_or_else(|| format!("no source `{id}`"))
    }

    fn display<'a>(&self, id: &'a String) -> Option<impl std::fmt::Display + 'a> {
        Some(id)
    }
}

/// Characters a terminal would act on rather than show: C0 and C1 controls (ESC, CR,
/// backspace, CSI, ...) and the line and paragraph separators. Newlines and tabs stay.
fn needs_escape(c: char) -> bool {
    (c.is_control() && c != '\n' && c != '\t') || c == '\u{2028}' || c == '\u{2029}'
}

fn escape_char(c: char) -> String {
    format!("\\u{{{:x}}}", c as u32)
}

/// `text` with every character a terminal would act on written as `\u{..}`.
pub(crate) fn escape_text(text: &str) -> String {
    if !text
        .chars()
        .any(|c| needs_escape(c) || c == '\n' || c == '\t')
    {
        return text.to_string();
    }
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        // In a one-line message a newline or tab is as misleading as any other control.
        if needs_escape(c) || c == '\n' || c == '\t' {
            out.push_str(&escape_char(c));
        } else {
            out.push(c);
        }
    }
    out
}

fn render_one(
    sources: &SourceMap,
    files: &mut Files,
    diagnostic: &Diagnostic,
    color: bool,
) -> String {
    // rustc's lower-case words, in ariadne's layout.
    let (kind, label_color) = match diagnostic.severity {
        Severity::Error => (ReportKind::Custom("error", Color::Red), Color::Red),
        Severity::Warning => (ReportKind::Custom("warning", Color::Yellow), Color::Yellow),
        Severity::Note => (ReportKind::Custom("note", Color::Cyan), Color::Cyan),
    };
    let primary = diagnostic.span.and_then(|span| files.clamp(sources, span));
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
        .with_message(escape_text(&diagnostic.message));
    // ariadne underlines only labels with a message.
    let text = escape_text(diagnostic.label.as_deref().unwrap_or("here"));
    let mut labels = vec![(primary.clone(), text, label_color)];
    for secondary in &diagnostic.secondary {
        if let Some(span) = files.clamp(sources, secondary.span) {
            labels.push((span, escape_text(&secondary.message), Color::Blue));
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
        report = report.with_help(escape_text(hint));
    }
    let mut buffer = Vec::new();
    match report.finish().write(&mut *files, &mut buffer) {
        Ok(()) => {
            let mut text = String::from_utf8_lossy(&buffer).into_owned();
            // ariadne counts columns in the escaped line; the header shows the file's own.
            if let Some(span) = diagnostic.span {
                if let Some(lc) = sources.line_col(span) {
                    let shown = format!(" {}:", primary.0);
                    if let Some(at) = text.find(&shown) {
                        let rest = at + shown.len();
                        let end = text[rest..].find(' ').map_or(text.len(), |e| rest + e);
                        text.replace_range(rest..end, &format!("{}:{}", lc.line, lc.column));
                    }
                }
            }
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
        format!(
            "\x1b[{code}m{word}:\x1b[0m {}\n",
            escape_text(&diagnostic.message)
        )
    } else {
        format!("{word}: {}\n", escape_text(&diagnostic.message))
    };
    for hint in &diagnostic.hints {
        out.push_str(&format!("    Help: {}\n", escape_text(hint)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::SourceFile;

    #[test]
    fn each_file_is_prepared_once_however_many_diagnostics_point_into_it() {
        // Issue 10: 40k objects without a material took 70-118 s to `check`, because every
        // note copied and re-indexed the whole file: quadratic in the number of objects.
        let text = "sphere { }\n".repeat(2_000);
        let mut sources = SourceMap::new();
        let file = sources.add(SourceFile::new("many.scene", text.as_str()));
        let notes: Vec<Diagnostic> = (0..2_000)
            .map(|i| Diagnostic::note("no material", Span::new(file, i * 11, i * 11 + 6)))
            .collect();
        let before = PREPARED_FILES.with(|n| n.get());
        let rendered = render_diagnostics(&sources, &notes, false);
        let prepared = PREPARED_FILES.with(|n| n.get()) - before;
        assert_eq!(prepared, 1);
        assert!(
            rendered.contains("many.scene:2000:1"),
            "the last note is located"
        );
    }
}
