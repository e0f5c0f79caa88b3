//! Formatted strings: `"ball {i}"` splits into text and `{name}` holes when parsed; the
//! evaluator fills the holes (crates/lang/src/eval/strings.rs). `{{` and `}}` write braces.

use whitted_ir::{Diagnostic, FileId, Span};

use crate::ast::{Ident, Name, Res, StrPart};
use crate::intern::Interner;

/// Splits the raw text of a string literal (between its quotes, escapes not yet applied)
/// into parts. `raw_start` is the byte offset of the raw text in its file. A string without
/// holes gives no parts: its value is the literal's text.
pub(crate) fn template(
    raw: &str,
    raw_start: usize,
    file: FileId,
    interner: &mut Interner,
) -> Result<Vec<StrPart>, Diagnostic> {
    if !raw.contains(['{', '}']) {
        return Ok(Vec::new());
    }
    let mut parts = Vec::new();
    let mut text = String::new();
    let mut chars = raw.char_indices().peekable();
    let at = |start: usize, end: usize| Span::new(file, raw_start + start, raw_start + end);
    while let Some((i, c)) = chars.next() {
        match c {
            '\\' => match chars.next() {
                Some((_, 'n')) => text.push('\n'),
                Some((_, 't')) => text.push('\t'),
                // `\"` and `\\`; other escapes were already reported by the parser.
                Some((_, other)) => text.push(other),
                None => {}
            },
            '{' if chars.peek().is_some_and(|&(_, next)| next == '{') => {
                chars.next();
                text.push('{');
            }
            '}' if chars.peek().is_some_and(|&(_, next)| next == '}') => {
                chars.next();
                text.push('}');
            }
            '}' => {
                return Err(
                    Diagnostic::error("a `}` in a string without its `{`", at(i, i + 1))
                        .with_label("this `}`")
                        .with_hint("write `}}` for a `}` in a string"),
                );
            }
            '{' => {
                let rest = &raw[i + 1..];
                let close = rest.find('}');
                let inner = close.map(|end| &rest[..end]);
                let name = inner.filter(|name| is_name(name));
                let Some(name) = name else {
                    let end = close.map_or(raw.len(), |end| i + 2 + end);
                    return Err(Diagnostic::error(
                        "a `{` in a string must hold a name, as in `\"ball {i}\"`",
                        at(i, end),
                    )
                    .with_label(if close.is_some() {
                        "not a name"
                    } else {
                        "no `}` closes this"
                    })
                    .with_hint(
                        "compute the value first with `let`, then write its name in braces; write `{{` for a `{`",
                    ));
                };
                if !text.is_empty() {
                    parts.push(StrPart::Text(std::mem::take(&mut text)));
                }
                let start = i + 1;
                parts.push(StrPart::Hole(Name {
                    ident: Ident {
                        sym: interner.intern(name),
                        span: at(start, start + name.len()),
                    },
                    res: Res::Unresolved,
                }));
                for _ in 0..name.chars().count() + 1 {
                    chars.next();
                }
            }
            other => text.push(other),
        }
    }
    if !text.is_empty() {
        parts.push(StrPart::Text(text));
    }
    Ok(parts)
}

/// Whether `text` is a name as the grammar writes one (a keyword is refused later, as an
/// unknown name).
fn is_name(text: &str) -> bool {
    let mut chars = text.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// How a number appears in a string: whole numbers without a fraction (`3`, not `3.0`).
pub(crate) fn format_number(x: f64) -> String {
    // `-0` would surprise in a name; it is the same number as `0`.
    let x = if x == 0.0 { 0.0 } else { x };
    format!("{x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parts(raw: &str) -> Result<Vec<String>, String> {
        let mut interner = Interner::default();
        template(raw, 10, FileId(0), &mut interner)
            .map(|parts| {
                parts
                    .iter()
                    .map(|p| match p {
                        StrPart::Text(t) => format!("text {t:?}"),
                        StrPart::Hole(n) => format!(
                            "hole {} at {}..{}",
                            interner.name(n.ident.sym),
                            n.ident.span.start,
                            n.ident.span.end
                        ),
                    })
                    .collect()
            })
            .map_err(|d| d.message)
    }

    #[test]
    fn holes_text_and_braces_split_with_their_places() {
        assert_eq!(parts("plain"), Ok(vec![]));
        assert_eq!(
            parts("ball {i}!"),
            Ok(vec![
                "text \"ball \"".to_string(),
                "hole i at 16..17".to_string(),
                "text \"!\"".to_string()
            ])
        );
        // An escape before a hole shifts the raw text, and the hole's place with it.
        assert_eq!(
            parts(r#"\"{name_2}{{}}"#),
            Ok(vec![
                "text \"\\\"\"".to_string(),
                "hole name_2 at 13..19".to_string(),
                "text \"{}\"".to_string()
            ])
        );
        for bad in ["{", "{}", "{1}", "{a b}", "}", "a{b", "{a.x}", "{é}"] {
            assert!(parts(bad).is_err(), "{bad:?} was accepted");
        }
    }

    #[test]
    fn numbers_are_written_as_people_write_them() {
        assert_eq!(format_number(3.0), "3");
        assert_eq!(format_number(-0.0), "0");
        assert_eq!(format_number(0.5), "0.5");
        assert_eq!(format_number(-2.25), "-2.25");
        assert_eq!(format_number(1e21), "1000000000000000000000");
    }
}
