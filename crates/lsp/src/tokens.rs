//! Semantic tokens for a whole document (or its change since the last answer) or a range
//! of it: the compiler's classes (`editor::view::highlight`, read by the formatter's
//! tokenizer, so a file that does not parse is highlighted as far as it lexes) in the
//! protocol's relative encoding, columns in UTF-16 units, a token that spans lines (a block
//! comment, a string) cut at each line break.
//!
//! A range is highlighted from the last top-level statement that starts before it to the
//! first that starts after it (found by a scan of the bytes for braces, comments and strings,
//! far cheaper than highlighting), so that one screen of a 100,000-statement file does not
//! cost the whole file. Where a statement starts the highlighter is in its first state, so
//! the range's tokens are the whole document's (a test compares them at every range).

use lsp_types::{
    SemanticToken, SemanticTokenModifier, SemanticTokenType, SemanticTokens, SemanticTokensDelta,
    SemanticTokensEdit, SemanticTokensFullDeltaResult, SemanticTokensFullOptions,
    SemanticTokensLegend, SemanticTokensOptions,
};
use whitted_lang::editor::view::{highlight, Class};

use crate::documents::Document;

/// The token types, in the order of [`type_index`].
const TYPES: [SemanticTokenType; 10] = [
    SemanticTokenType::KEYWORD,
    SemanticTokenType::TYPE,
    SemanticTokenType::PROPERTY,
    SemanticTokenType::VARIABLE,
    SemanticTokenType::FUNCTION,
    SemanticTokenType::PARAMETER,
    SemanticTokenType::NUMBER,
    SemanticTokenType::STRING,
    SemanticTokenType::COMMENT,
    SemanticTokenType::OPERATOR,
];

/// Bit 0 of the modifiers: where a name is defined.
const DEFINITION: u32 = 1;

fn type_index(class: Class) -> u32 {
    match class {
        Class::Keyword => 0,
        Class::Type => 1,
        Class::Property => 2,
        Class::Variable => 3,
        Class::Function => 4,
        Class::Parameter => 5,
        Class::Number => 6,
        Class::String => 7,
        Class::Comment => 8,
        Class::Operator => 9,
    }
}

/// The capability: the legend, whole documents (and their changes) and ranges.
pub fn options() -> SemanticTokensOptions {
    SemanticTokensOptions {
        legend: SemanticTokensLegend {
            token_types: TYPES.to_vec(),
            token_modifiers: vec![SemanticTokenModifier::DEFINITION],
        },
        full: Some(SemanticTokensFullOptions::Delta { delta: Some(true) }),
        range: Some(true),
        ..SemanticTokensOptions::default()
    }
}

/// Every token of the document, encoded.
pub fn tokens(document: &Document) -> SemanticTokens {
    encode(document, highlight(&document.text), 0..document.text.len())
}

/// The whole document's tokens with a result id, kept as the last sent (for
/// [`tokens_delta`]).
pub fn tokens_sent(document: &Document) -> SemanticTokens {
    let mut found = tokens(document);
    let mut sent = document.sent_tokens.borrow_mut();
    let id = sent
        .as_ref()
        .and_then(|s| s.result_id.as_deref()?.parse::<u64>().ok())
        .map_or(1, |n| n + 1);
    found.result_id = Some(id.to_string());
    *sent = Some(found.clone());
    found
}

/// `semanticTokens/full/delta`: the change from the tokens last sent, when `previous` is
/// their id (one edit: the tokens between the common start and the common end), else the
/// whole document's.
pub fn tokens_delta(document: &Document, previous: &str) -> SemanticTokensFullDeltaResult {
    let old = document
        .sent_tokens
        .borrow()
        .clone()
        .filter(|s| s.result_id.as_deref() == Some(previous));
    let new = tokens_sent(document);
    let Some(old) = old else {
        return SemanticTokensFullDeltaResult::Tokens(new);
    };
    let (old, data) = (&old.data, &new.data);
    let same = old.iter().zip(data).take_while(|(a, b)| a == b).count();
    let rest = old.len().min(data.len()) - same;
    let tail = old
        .iter()
        .rev()
        .zip(data.iter().rev())
        .take(rest)
        .take_while(|(a, b)| a == b)
        .count();
    let edits = if old.len() == data.len() && same == old.len() {
        Vec::new()
    } else {
        vec![SemanticTokensEdit {
            start: (same * 5) as u32,
            delete_count: ((old.len() - same - tail) * 5) as u32,
            data: Some(data[same..data.len() - tail].to_vec()),
        }]
    };
    SemanticTokensFullDeltaResult::TokensDelta(SemanticTokensDelta {
        result_id: new.result_id,
        edits,
    })
}

/// The tokens that are in the bytes `range` of the document (wholly or in part), encoded
/// as the whole document's are (the first relative to the document's start).
pub fn tokens_in(document: &Document, range: std::ops::Range<usize>) -> SemanticTokens {
    let text = &document.text;
    let (from, to) = window(text, range.start, range.end);
    let mut found = highlight(&text[from..to]);
    for token in &mut found {
        token.range = token.range.start + from..token.range.end + from;
    }
    encode(document, found, range)
}

/// The bytes to highlight for a range `start..end`: from the start of the last line that
/// starts a top-level statement at or before `start`, to the start of the first one at or
/// after `end` (or the text's ends). Such a line starts outside any comment, string and
/// brace, after a `;` or a `}` (or nothing), so no token before it changes how one after it
/// reads.
fn window(text: &str, start: usize, end: usize) -> (usize, usize) {
    let bytes = text.as_bytes();
    let mut from = 0;
    // The brace and parenthesis depths (never below 0, as the highlighter counts them),
    // the last byte of code, and whether a `fn` waits for its body's `{`.
    let (mut braces, mut parens, mut last, mut function) = (0usize, 0usize, b';', false);
    let ident = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'\n' => {
                let line = i + 1;
                if braces == 0 && parens == 0 && !function && matches!(last, b';' | b'}') {
                    if line <= start {
                        from = line;
                    } else if line >= end {
                        return (from, line);
                    }
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                i = text[i..].find('\n').map_or(bytes.len(), |n| i + n);
                continue;
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                i = text[i + 2..]
                    .find("*/")
                    .map_or(bytes.len(), |n| i + 2 + n + 2);
                continue;
            }
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                last = b'"';
            }
            b'{' => {
                braces += 1;
                function = false;
                last = b'{';
            }
            b'}' => {
                braces = braces.saturating_sub(1);
                last = b'}';
            }
            b'(' => {
                parens += 1;
                last = b'(';
            }
            b')' => {
                parens = parens.saturating_sub(1);
                last = b')';
            }
            b' ' | b'\t' | b'\r' => {}
            b'f' if bytes.get(i + 1) == Some(&b'n')
                && (i == 0 || !ident(bytes[i - 1]))
                && !bytes.get(i + 2).is_some_and(|&b| ident(b)) =>
            {
                function = true;
                last = b'n';
                i += 1;
            }
            other => last = other,
        }
        i += 1;
    }
    (from, bytes.len())
}

/// `found`'s tokens that overlap `range`, encoded.
fn encode(
    document: &Document,
    found: Vec<whitted_lang::editor::view::Highlight>,
    range: std::ops::Range<usize>,
) -> SemanticTokens {
    let text = &document.text;
    let mut data = Vec::new();
    let (mut line, mut column) = (0u32, 0u32);
    for token in found
        .into_iter()
        .filter(|t| t.range.end > range.start && t.range.start < range.end)
    {
        let token_type = type_index(token.class);
        let modifiers = if token.definition { DEFINITION } else { 0 };
        // One piece per line the token covers, without its line break.
        let mut start = token.range.start;
        while start < token.range.end {
            let end = text[start..token.range.end]
                .find('\n')
                .map_or(token.range.end, |n| start + n);
            let piece = text[start..end]
                .strip_suffix('\r')
                .unwrap_or(&text[start..end]);
            let length = piece.encode_utf16().count() as u32;
            if length > 0 && start < range.end && end > range.start {
                let at = document.lines.position(text, start);
                let delta_line = at.line - line;
                let delta_start = if delta_line == 0 {
                    at.character - column
                } else {
                    at.character
                };
                data.push(SemanticToken {
                    delta_line,
                    delta_start,
                    length,
                    token_type,
                    token_modifiers_bitset: modifiers,
                });
                (line, column) = (at.line, at.character);
            }
            start = end + 1;
        }
    }
    SemanticTokens {
        result_id: None,
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lsp_types::Url;

    fn encoded(text: &str) -> Vec<[u32; 5]> {
        let uri = Url::parse("file:///a.scene").expect("a URI");
        tokens(&Document::new(&uri, text.to_string(), 1))
            .data
            .iter()
            .map(|t| {
                [
                    t.delta_line,
                    t.delta_start,
                    t.length,
                    t.token_type,
                    t.token_modifiers_bitset,
                ]
            })
            .collect()
    }

    /// Relative lines and UTF-16 columns: `é` is one unit, `😀` two; the block comment is cut
    /// into one token per line.
    #[test]
    fn tokens_are_relative_and_counted_in_utf16() {
        let text = "let s = \"é😀\"; /* a\nbc */ sphere { radius 2 }";
        assert_eq!(
            encoded(text),
            [
                [0, 0, 3, 0, 0], // let
                [0, 4, 1, 3, 1], // s, defined
                [0, 2, 1, 9, 0], // =
                [0, 2, 5, 7, 0], // "é😀"
                [0, 7, 4, 8, 0], // /* a
                [1, 0, 5, 8, 0], // bc */
                [0, 6, 6, 1, 0], // sphere
                [0, 9, 6, 2, 0], // radius
                [0, 7, 1, 6, 0], // 2
            ]
        );
    }

    /// Tokens as (line, column, length, type, modifiers), absolute.
    fn absolute(tokens: &SemanticTokens) -> Vec<[u32; 5]> {
        let (mut line, mut column) = (0, 0);
        tokens
            .data
            .iter()
            .map(|t| {
                line += t.delta_line;
                column = if t.delta_line == 0 {
                    column + t.delta_start
                } else {
                    t.delta_start
                };
                [
                    line,
                    column,
                    t.length,
                    t.token_type,
                    t.token_modifiers_bitset,
                ]
            })
            .collect()
    }

    /// The tokens of a range are the whole document's that overlap it, at every range of
    /// whole lines of texts with functions, comments and strings over several lines, and of
    /// texts that do not parse (an unclosed brace, a stray one, a `fn` without its body).
    #[test]
    fn a_ranges_tokens_are_the_whole_documents() {
        let texts = [
            "fn f(k) {\n  sphere { radius k }\n}\nlet k = 2;\n/* a\n} b */\nsphere \"x\n;}\" { radius k }\nf(k)\n// c {\nmaterial m\n{ }\n",
            "let a = 1;\n}\nfn g(p)\nsphere { radius p }\n{ p }\nlet b = p;\n",
            "sphere { radius 1\nlet z = 1;\nfn h(q) {\n",
            "fn f(k) ) (\nlet k = 1;\n{ k }\n",
            "let a = 1;\nfn g(p) }\nsphere { radius p }\nlet b = p;\n",
        ];
        let uri = Url::parse("file:///a.scene").expect("a URI");
        for text in texts {
            let document = Document::new(&uri, text.to_string(), 1);
            let whole = absolute(&tokens(&document));
            let starts: Vec<usize> = std::iter::once(0)
                .chain(text.match_indices('\n').map(|(i, _)| i + 1))
                .collect();
            for (a, &from) in starts.iter().enumerate() {
                for &to in &starts[a..] {
                    let range = document.lines.range(text, from..to);
                    let expected: Vec<[u32; 5]> = whole
                        .iter()
                        .filter(|t| t[0] >= range.start.line && t[0] < range.end.line)
                        .copied()
                        .collect();
                    assert_eq!(
                        absolute(&tokens_in(&document, from..to)),
                        expected,
                        "lines {}..{} of {text:?}",
                        range.start.line,
                        range.end.line
                    );
                }
            }
        }
    }

    /// A delta from the tokens last sent, applied to them, gives the new text's tokens; an
    /// unknown previous id gets the whole document's.
    #[test]
    fn a_delta_applied_to_the_last_tokens_gives_the_new_ones() {
        let uri = Url::parse("file:///a.scene").expect("a URI");
        let text = "let a = 1;\nsphere { radius a }\nplane { }\n";
        let mut document = Document::new(&uri, text.to_string(), 1);
        let first = tokens_sent(&document);
        assert_eq!(first.result_id.as_deref(), Some("1"));
        // `a` becomes `a + 2` on line 1: the tokens from there to the end of the line.
        document.apply(lsp_types::TextDocumentContentChangeEvent {
            range: Some(lsp_types::Range::new(
                lsp_types::Position::new(1, 17),
                lsp_types::Position::new(1, 17),
            )),
            range_length: None,
            text: " + 2".to_string(),
        });
        let SemanticTokensFullDeltaResult::TokensDelta(delta) = tokens_delta(&document, "1") else {
            panic!("a delta");
        };
        assert_eq!(delta.result_id.as_deref(), Some("2"));
        assert_eq!(delta.edits.len(), 1);
        let edit = &delta.edits[0];
        // Kept: `let a = 1`, `sphere radius a` (7 tokens); inserted: `+ 2`.
        assert_eq!((edit.start, edit.delete_count), (35, 0));
        let mut data = first.data.clone();
        let at = edit.start as usize / 5;
        let deleted = edit.delete_count as usize / 5;
        data.splice(at..at + deleted, edit.data.clone().unwrap_or_default());
        assert_eq!(data, tokens(&document).data);
        assert!(matches!(
            tokens_delta(&document, "1"),
            SemanticTokensFullDeltaResult::Tokens(_)
        ));
    }
}
