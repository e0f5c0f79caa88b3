//! A quick pass over the raw text before pest sees it: unterminated strings and comments,
//! unbalanced or mismatched brackets, and nesting deeper than the limit.
//!
//! pest stops at its first error and only knows what it expected at one position; this pass
//! knows where every bracket opened, so "missing `}`" can point at the `{` that needs it, and
//! a file with 100,000 `(` is refused before any recursive parser runs.

use whitted_ir::{Diagnostic, FileId, Span};

/// A matched pair of brackets: byte offsets of the opener and the closer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BracketPair {
    pub open: u32,
    pub close: u32,
    pub kind: u8,
}

/// Every matched bracket pair in a file, in order of their openers.
#[derive(Debug, Default)]
pub struct Brackets {
    pairs: Vec<BracketPair>,
}

impl Brackets {
    /// The innermost `{ ... }` pair that contains `offset` (strictly after its `{`).
    pub fn innermost_brace_around(&self, offset: u32) -> Option<BracketPair> {
        self.pairs
            .iter()
            .filter(|p| p.kind == b'{' && p.open < offset && offset <= p.close)
            .max_by_key(|p| p.open)
            .copied()
    }
}

fn closer_of(open: u8) -> u8 {
    match open {
        b'(' => b')',
        b'[' => b']',
        _ => b'}',
    }
}

/// Checks strings, comments and brackets, and that no run of operators is longer than
/// `max_operators`. Returns the bracket pairs, or the first problem.
///
/// An operator adds a level to the syntax tree, so a flat sum `1 + 1 + ...` of more than the
/// expression depth limit is refused anyway; counting operators here refuses it before pest
/// builds a token for every term (a 64 MiB sum took 93 s and 7.7 GB to reach that refusal).
/// The count is per bracket level and restarts at `;`, `,`, `{` and `}`, which no single
/// operator chain crosses; a real scene never has thousands of operators between two of them.
pub fn scan(
    text: &str,
    file: FileId,
    max_nesting: usize,
    max_operators: usize,
) -> Result<Brackets, Diagnostic> {
    let bytes = text.as_bytes();
    let span = |start: usize, end: usize| Span::new(file, start, end);
    let mut open: Vec<(usize, u8)> = Vec::new();
    let mut brackets = Brackets::default();
    // `<` opens a vector or compares; which one is the grammar's business. Counting every `<`
    // not closed by a `>` within one statement bounds the nesting of vectors (pest parses them
    // recursively) without refusing any real scene: a statement with hundreds of unclosed
    // comparisons does not occur.
    let mut angle_depth = 0usize;
    // Operators since the last `;`, `,` or brace at each open bracket level (outermost first).
    let mut operators: Vec<usize> = vec![0];
    let mut i = 0;
    while i < bytes.len() {
        if matches!(
            bytes[i],
            b'+' | b'-' | b'*' | b'/' | b'%' | b'<' | b'>' | b'=' | b'!' | b'&' | b'|'
        ) && !(bytes[i] == b'/' && matches!(bytes.get(i + 1), Some(b'/' | b'*')))
        {
            if let Some(count) = operators.last_mut() {
                *count += 1;
                if *count > max_operators {
                    return Err(Diagnostic::error(
                        format!(
                            "this expression is too long: more than {max_operators} operators in a row (the expression depth limit)"
                        ),
                        span(i, i + 1),
                    )
                    .with_label("this operator goes past the limit")
                    .with_hint("split it into smaller parts with `let` or functions"));
                }
            }
        }
        match bytes[i] {
            b';' | b',' | b'{' | b'}' => {
                if let Some(count) = operators.last_mut() {
                    *count = 0;
                }
            }
            _ => {}
        }
        match bytes[i] {
            b'"' => {
                let start = i;
                i += 1;
                loop {
                    match bytes.get(i) {
                        None | Some(b'\n') => {
                            return Err(Diagnostic::error(
                                "this string is never closed",
                                span(start, start + 1),
                            )
                            .with_label("the string starts here")
                            .with_hint("strings end with `\"` on the same line"));
                        }
                        Some(b'\\') => i += 2,
                        Some(b'"') => break,
                        Some(_) => i += 1,
                    }
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                let start = i;
                match text[i + 2..].find("*/") {
                    Some(end) => i = i + 2 + end + 1,
                    None => {
                        return Err(Diagnostic::error(
                            "this comment is never closed",
                            span(start, start + 2),
                        )
                        .with_label("the comment starts here")
                        .with_hint("block comments end with `*/` (they do not nest)"));
                    }
                }
            }
            b'<' if bytes.get(i + 1) != Some(&b'=') => {
                angle_depth += 1;
                if angle_depth > max_nesting {
                    return Err(Diagnostic::error(
                        format!(
                            "vectors are nested too deeply: the nesting limit is {max_nesting} levels"
                        ),
                        span(i, i + 1),
                    )
                    .with_label("this `<` goes past the limit")
                    .with_hint("split the expression with `let`"));
                }
            }
            b'>' if bytes.get(i + 1) != Some(&b'=') => angle_depth = angle_depth.saturating_sub(1),
            b';' => angle_depth = 0,
            b @ (b'(' | b'[' | b'{') => {
                if b == b'{' {
                    angle_depth = 0;
                }
                if open.len() >= max_nesting {
                    return Err(Diagnostic::error(
                        format!(
                            "brackets are nested too deeply: the nesting limit is {max_nesting} levels"
                        ),
                        span(i, i + 1),
                    )
                    .with_label("this bracket goes past the limit")
                    .with_hint("split the scene into functions, or raise the nesting limit"));
                }
                open.push((i, b));
                operators.push(0);
            }
            b @ (b')' | b']' | b'}') => {
                if b == b'}' {
                    angle_depth = 0;
                }
                if operators.len() > 1 {
                    operators.pop();
                }
                match open.pop() {
                    Some((start, kind)) if closer_of(kind) == b => {
                        brackets.pairs.push(BracketPair {
                            open: start as u32,
                            close: i as u32,
                            kind,
                        })
                    }
                    Some((start, kind)) => {
                        return Err(Diagnostic::error(
                            format!(
                                "mismatched `{}`: expected `{}` first",
                                b as char,
                                closer_of(kind) as char
                            ),
                            span(i, i + 1),
                        )
                        .with_label(format!(
                            "expected `{}` before this",
                            closer_of(kind) as char
                        ))
                        .with_secondary(
                            span(start, start + 1),
                            format!("this `{}` is not closed", kind as char),
                        ));
                    }
                    None => {
                        return Err(Diagnostic::error(
                            format!("unexpected `{}`: there is nothing to close", b as char),
                            span(i, i + 1),
                        )
                        .with_label("no bracket is open here"));
                    }
                }
            }
            _ => {}
        }
        i += 1;
    }
    if let Some(&(start, kind)) = open.last() {
        let closer = closer_of(kind) as char;
        // Point at the last character of the file, not past it, so the line is shown.
        let last = text.trim_end().len();
        let start_of_last = text[..last]
            .char_indices()
            .next_back()
            .map_or(0, |(i, _)| i);
        let mut diagnostic = Diagnostic::error(
            format!("expected `{closer}` before the end of the file"),
            span(start_of_last, last),
        )
        .with_label(format!(
            "the file ends here, with a `{}` still open",
            kind as char
        ))
        .with_secondary(
            span(start, start + 1),
            format!("this `{}` is never closed", kind as char),
        );
        // Outer unclosed brackets are usually fine and only missing their partner because of
        // the innermost one, so they are named but not labelled.
        if open.len() > 1 {
            diagnostic = diagnostic.with_hint(format!(
                "{} brackets are open at the end of the file; the innermost is labelled",
                open.len()
            ));
        }
        return Err(diagnostic);
    }
    brackets.pairs.sort_by_key(|p| p.open);
    Ok(brackets)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan_ok(text: &str) -> Brackets {
        match scan(text, FileId(0), 8, 128) {
            Ok(brackets) => brackets,
            Err(d) => panic!("unexpected error: {}", d.message),
        }
    }

    fn scan_err(text: &str) -> Diagnostic {
        match scan(text, FileId(0), 8, 128) {
            Ok(_) => panic!("expected an error for {text:?}"),
            Err(d) => d,
        }
    }

    #[test]
    fn brackets_in_strings_and_comments_do_not_count() {
        let brackets = scan_ok("a { \"}\" // }\n /* { */ ( ) }");
        assert_eq!(brackets.pairs.len(), 2);
        let around = brackets.innermost_brace_around(10);
        assert_eq!(around.map(|p| p.open), Some(2));
    }

    #[test]
    fn an_unclosed_brace_points_at_its_opener() {
        let d = scan_err("sphere {\n radius 1\n");
        assert_eq!(d.message, "expected `}` before the end of the file");
        assert_eq!(d.secondary[0].span.start, 7);
    }

    #[test]
    fn mismatches_extra_closers_and_unterminated_tokens_are_errors() {
        assert!(scan_err("( }").message.starts_with("mismatched `}`"));
        assert!(scan_err("}").message.starts_with("unexpected `}`"));
        assert_eq!(scan_err("\"abc").message, "this string is never closed");
        assert_eq!(scan_err("/* abc").message, "this comment is never closed");
    }

    #[test]
    fn nesting_beyond_the_limit_is_refused() {
        assert!(scan_err(&"(".repeat(9))
            .message
            .contains("nesting limit is 8"));
        scan_ok(&format!("{}{}", "(".repeat(8), ")".repeat(8)));
        assert!(scan_err(&"<".repeat(9))
            .message
            .starts_with("vectors are nested"));
        // Comparisons in separate statements, and `<=`, do not add up.
        scan_ok(&"let a = b < c;".repeat(20));
        scan_ok(&"a <= ".repeat(20));
    }
}
