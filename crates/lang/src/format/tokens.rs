//! The formatter's view of a file: its tokens, comments included, each with the whitespace
//! before it and the role the syntax tree gave it (a `<` that compares or opens a vector).
//!
//! The formatter only ever changes the whitespace between these tokens, so reading them
//! exactly as pest does is what makes its output mean the same as its input. Where pest's
//! reading depends on context (`<1, 2, 3>==x` is `>` then `==`, not `>=` then `=`), the
//! operator spans of the syntax tree decide.

use std::collections::{HashMap, HashSet};

/// What a token is, as far as spacing cares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A name or a keyword.
    Word,
    Number,
    Hex,
    Str,
    /// Punctuation and operators: `{`, `,`, `..=`, `&&`, ...
    Punct,
    LineComment,
    BlockComment,
}

/// What the syntax tree says a punctuation token does, where spacing depends on it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    Plain,
    /// An infix operator: `a - b`, `a < b`.
    Binary,
    /// A prefix operator: `-b`, `!b`.
    Unary,
    /// The `<` and `>` around a vector.
    VectorOpen,
    VectorClose,
    /// The `(` of a call's arguments (no space may come before it: `f (x)` is not a call).
    CallOpen,
    /// The `(` of a function's parameters.
    ParamsOpen,
    /// The `[` of indexing, `a[i]` (an array value is `[` with `Plain`).
    IndexOpen,
    /// The `.` of `a.x`.
    FieldDot,
    /// `..` or `..=`.
    Range,
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Token {
    pub kind: Kind,
    pub role: Role,
    pub start: u32,
    pub end: u32,
    /// Line breaks in the whitespace before the token.
    pub newlines_before: u32,
    /// When the token is on the same line as the one before it: how many spaces were
    /// between them, if the gap was only spaces (trailing comments keep their alignment).
    pub spaces_before: Option<u32>,
}

impl Token {
    pub fn is_comment(&self) -> bool {
        matches!(self.kind, Kind::LineComment | Kind::BlockComment)
    }
}

/// Where the syntax tree puts operators and brackets whose reading depends on context.
#[derive(Debug, Default)]
pub(crate) struct Roles {
    /// Start offset and length of every infix operator.
    pub binary: HashMap<u32, u32>,
    /// Offsets of the `(` of calls' arguments.
    pub calls: HashSet<u32>,
    /// Offsets after which the first `(` opens a function's parameters.
    pub params_after: Vec<u32>,
    /// Offsets after which the first `[` opens an index.
    pub index_after: Vec<u32>,
}

fn is_ident_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_'
}

fn is_ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Splits `text` (which parsed) into tokens. Whitespace is what the grammar calls
/// whitespace, the byte-order mark included.
pub(crate) fn tokenize(text: &str, roles: &Roles) -> Vec<Token> {
    let bytes = text.as_bytes();
    let at = |i: usize| text.get(i..).and_then(|s| s.chars().next());
    let mut tokens = Vec::new();
    let mut i = 0;
    let mut newlines = 0u32;
    let mut gap_start = 0usize;
    while i < bytes.len() {
        let Some(c) = at(i) else { break };
        if matches!(c, ' ' | '\t' | '\r' | '\n' | '\u{feff}') {
            if c == '\n' {
                newlines += 1;
            }
            i += c.len_utf8();
            continue;
        }
        let start = i;
        let next = bytes.get(i + 1).copied();
        let kind;
        if c == '/' && next == Some(b'/') {
            kind = Kind::LineComment;
            i = text[i..].find('\n').map_or(bytes.len(), |n| i + n);
        } else if c == '/' && next == Some(b'*') {
            kind = Kind::BlockComment;
            i = text[i + 2..]
                .find("*/")
                .map_or(bytes.len(), |n| i + 2 + n + 2);
        } else if c == '"' {
            kind = Kind::Str;
            i += 1;
            while let Some(d) = at(i) {
                i += d.len_utf8();
                if d == '"' {
                    break;
                }
                if d == '\\' {
                    if let Some(escaped) = at(i) {
                        i += escaped.len_utf8();
                    }
                }
            }
        } else if c.is_ascii_digit() || (c == '.' && next.is_some_and(|b| b.is_ascii_digit())) {
            kind = Kind::Number;
            i = number_end(bytes, i);
        } else if c == '#' {
            kind = Kind::Hex;
            i += 1;
            while bytes.get(i).is_some_and(u8::is_ascii_hexdigit) {
                i += 1;
            }
        } else if is_ident_start(c) {
            kind = Kind::Word;
            while at(i).is_some_and(is_ident_char) {
                i += 1;
            }
        } else {
            kind = Kind::Punct;
            i += if let Some(&len) = roles.binary.get(&(i as u32)) {
                len as usize
            } else if text[i..].starts_with("..=") {
                3
            } else if text[i..].starts_with("..") {
                2
            } else {
                c.len_utf8()
            };
        }
        let gap = &text[gap_start..start];
        let spaces_before =
            (newlines == 0 && gap.bytes().all(|b| b == b' ')).then_some(gap.len() as u32);
        tokens.push(Token {
            kind,
            role: Role::Plain,
            start: start as u32,
            end: i as u32,
            newlines_before: newlines,
            spaces_before,
        });
        newlines = 0;
        gap_start = i;
    }
    assign_roles(text, &mut tokens, roles);
    tokens
}

/// The end of the number starting at `i`, as the grammar's `number` rule reads it.
fn number_end(bytes: &[u8], mut i: usize) -> usize {
    let digits = |i: &mut usize| {
        let from = *i;
        while bytes.get(*i).is_some_and(u8::is_ascii_digit) {
            *i += 1;
        }
        *i > from
    };
    if digits(&mut i) {
        if bytes.get(i) == Some(&b'.') && bytes.get(i + 1).is_some_and(u8::is_ascii_digit) {
            i += 1;
            digits(&mut i);
        }
    } else {
        i += 1;
        digits(&mut i);
    }
    if matches!(bytes.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        if matches!(bytes.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        if digits(&mut j) {
            i = j;
        }
    }
    i
}

fn assign_roles(text: &str, tokens: &mut [Token], roles: &Roles) {
    // The first code token at or after `offset`.
    let first_after = |tokens: &[Token], offset: u32| {
        let from = tokens.partition_point(|t| t.start < offset);
        (from..tokens.len()).find(|&k| !tokens[k].is_comment())
    };
    for &offset in &roles.params_after {
        if let Some(k) = first_after(tokens, offset) {
            if &text[tokens[k].start as usize..tokens[k].end as usize] == "(" {
                tokens[k].role = Role::ParamsOpen;
            }
        }
    }
    for &offset in &roles.index_after {
        if let Some(k) = first_after(tokens, offset) {
            if &text[tokens[k].start as usize..tokens[k].end as usize] == "[" {
                tokens[k].role = Role::IndexOpen;
            }
        }
    }
    for token in tokens.iter_mut() {
        if token.kind != Kind::Punct || token.role != Role::Plain {
            continue;
        }
        let s = &text[token.start as usize..token.end as usize];
        token.role = if roles.binary.contains_key(&token.start) {
            Role::Binary
        } else {
            match s {
                "<" => Role::VectorOpen,
                ">" => Role::VectorClose,
                "-" | "!" => Role::Unary,
                "(" if roles.calls.contains(&token.start) => Role::CallOpen,
                "." => Role::FieldDot,
                ".." | "..=" => Role::Range,
                _ => Role::Plain,
            }
        };
    }
}
