//! Folding ranges: every `{ ... }` over more than one line (its `}` left showing when it
//! starts a line), each block comment over more than one line, and each run of two or more
//! lines that hold only a `//` comment.

use lsp_types::{FoldingRange, FoldingRangeKind, Position};
use whitted_lang::editor::view::outline_parts;

use crate::documents::Document;

pub fn folding_ranges(document: &Document) -> Vec<FoldingRange> {
    let text = &document.text;
    let lines = &document.lines;
    let line_of = |offset: usize| lines.line(offset);
    // Whether only whitespace comes before `offset` on its line.
    let starts_line = |offset: usize| {
        let start = lines.offset(text, Position::new(line_of(offset), 0));
        text.get(start..offset).is_some_and(|s| s.trim().is_empty())
    };
    let mut out = Vec::new();
    // One reading of the tokens gives the braces and the comments.
    let parts = outline_parts(text);
    for &(open, close) in &parts.braces {
        let start = line_of(open);
        let end = line_of(close).saturating_sub(u32::from(starts_line(close)));
        if end > start {
            out.push(range(start, end, None));
        }
    }
    // The run of line comments being read: its first and last lines.
    let mut run: Option<(u32, u32)> = None;
    let mut comments = Vec::new();
    for comment in &parts.comments {
        let (start, end) = (line_of(comment.start), line_of(comment.end));
        if !text[comment.clone()].starts_with("//") {
            if end > start {
                comments.push(range(start, end, Some(FoldingRangeKind::Comment)));
            }
            continue;
        }
        if !starts_line(comment.start) {
            continue;
        }
        run = match run {
            Some((first, last)) if last + 1 == start => Some((first, start)),
            Some((first, last)) => {
                if last > first {
                    comments.push(range(first, last, Some(FoldingRangeKind::Comment)));
                }
                Some((start, start))
            }
            None => Some((start, start)),
        };
    }
    if let Some((first, last)) = run.filter(|(first, last)| last > first) {
        comments.push(range(first, last, Some(FoldingRangeKind::Comment)));
    }
    out.extend(comments);
    out.sort_by_key(|r| (r.start_line, r.end_line));
    out
}

fn range(start_line: u32, end_line: u32, kind: Option<FoldingRangeKind>) -> FoldingRange {
    FoldingRange {
        start_line,
        end_line,
        kind,
        ..FoldingRange::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lsp_types::Url;

    fn folds(text: &str) -> Vec<(u32, u32, bool)> {
        let uri = Url::parse("file:///a.scene").expect("a URI");
        folding_ranges(&Document::new(&uri, text.to_string(), 1))
            .into_iter()
            .map(|r| {
                (
                    r.start_line,
                    r.end_line,
                    r.kind == Some(FoldingRangeKind::Comment),
                )
            })
            .collect()
    }

    #[test]
    fn blocks_and_comment_runs_fold() {
        let text = "// one\n// two\nfn f() {\n  sphere { radius 1\n    center <0, 0, 0> }\n  // alone\n}\nplane { }\n/* a\n b */ x // trailing\n// not a run with the trailing one\n";
        assert_eq!(
            folds(text),
            [
                // The comment run on lines 0 and 1.
                (0, 1, true),
                // The function, its `}` (line 6) left showing.
                (2, 5, false),
                // The sphere: its `}` ends line 4, which folds with it.
                (3, 4, false),
                // The block comment.
                (8, 9, true),
            ]
        );
    }
}
