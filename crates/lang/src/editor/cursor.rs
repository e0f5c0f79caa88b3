//! Where a cursor is, read from the text around it without parsing: an editor asks while
//! the text is half typed (`sphere { rad` does not parse), so this reads tokens the way the
//! grammar writes them (comments, strings, words, brackets) and decides which block the
//! cursor is in from the words before each `{`, as the resolver decides from the statement.

use super::{block_named, BlockKind, PropertyDoc};
use crate::schema::Context;

/// What may be typed at the cursor.
#[derive(Clone, Debug, PartialEq)]
pub enum Place {
    /// A property's name in a block of `block`; `written` are the properties the block
    /// already has (before or after the cursor), which it takes once each.
    PropertyName {
        block: BlockKind,
        written: Vec<&'static str>,
    },
    /// The value of `property`, just after its name.
    Value {
        block: BlockKind,
        property: PropertyDoc,
    },
    /// The start of a statement in a file, a function or a loop: `statements` lists what
    /// may start one there.
    Statement {
        statements: Vec<(&'static str, &'static str)>,
    },
    /// A material's name after `:` (`material tinted : glass`); `child` is the material
    /// being defined, which cannot be its own parent.
    ParentMaterial { child: Option<String> },
    /// Anywhere else: statements, inside an expression, a comment or a string.
    Other,
}

/// The cursor's place and the word being typed there (from `word_start` to the cursor).
#[derive(Clone, Debug, PartialEq)]
pub struct Cursor {
    pub place: Place,
    pub word_start: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    Word,
    Number,
    Text,
    Punct(u8),
    /// A character outside ASCII (the grammar has none outside strings and comments).
    Other,
}

#[derive(Clone, Copy, Debug)]
struct Token {
    class: Class,
    start: usize,
    end: usize,
}

/// The tokens of `text`, and the byte ranges of its comments and strings' insides.
fn tokens(text: &str) -> (Vec<Token>, Vec<(usize, usize)>) {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut quiet = Vec::new();
    let mut at = 0;
    while at < bytes.len() {
        let start = at;
        let byte = bytes[at];
        let class = match byte {
            b' ' | b'\t' | b'\r' | b'\n' => {
                at += 1;
                continue;
            }
            b'/' if bytes.get(at + 1) == Some(&b'/') => {
                at = memchr_newline(bytes, at);
                quiet.push((start, at));
                continue;
            }
            b'/' if bytes.get(at + 1) == Some(&b'*') => {
                at = find(bytes, at + 2, b"*/").map_or(bytes.len(), |end| end + 2);
                quiet.push((start + 1, at.saturating_sub(1).max(start + 1)));
                continue;
            }
            b'"' => {
                at += 1;
                while at < bytes.len() && bytes[at] != b'"' && bytes[at] != b'\n' {
                    at += if bytes[at] == b'\\' { 2 } else { 1 };
                }
                let end = at.min(bytes.len());
                quiet.push((start + 1, end));
                if at < bytes.len() && bytes[at] == b'"' {
                    at += 1;
                }
                at = at.min(bytes.len());
                Class::Text
            }
            b'a'..=b'z' | b'A'..=b'Z' | b'_' => {
                at = word_end(bytes, at);
                Class::Word
            }
            b'0'..=b'9' | b'#' => {
                at = word_end(bytes, at + 1);
                // `1.5` and `1e-3`, but not the range `0..10`.
                while at < bytes.len() {
                    match bytes[at] {
                        b'.' if bytes.get(at + 1).is_some_and(u8::is_ascii_digit) => {
                            at = word_end(bytes, at + 1)
                        }
                        b'+' | b'-' if matches!(bytes[at - 1], b'e' | b'E') => {
                            at = word_end(bytes, at + 1)
                        }
                        _ => break,
                    }
                }
                Class::Number
            }
            b'.' if bytes.get(at + 1).is_some_and(u8::is_ascii_digit) => {
                at = word_end(bytes, at + 1);
                Class::Number
            }
            _ if byte.is_ascii() => {
                at += 1;
                Class::Punct(byte)
            }
            _ => {
                at += text[at..].chars().next().map_or(1, char::len_utf8);
                Class::Other
            }
        };
        out.push(Token {
            class,
            start,
            end: at,
        });
    }
    (out, quiet)
}

fn word_end(bytes: &[u8], mut at: usize) -> usize {
    while at < bytes.len() && (bytes[at].is_ascii_alphanumeric() || bytes[at] == b'_') {
        at += 1;
    }
    at
}

fn memchr_newline(bytes: &[u8], at: usize) -> usize {
    bytes[at..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |n| at + n)
}

fn find(bytes: &[u8], from: usize, needle: &[u8]) -> Option<usize> {
    bytes
        .get(from..)?
        .windows(needle.len())
        .position(|w| w == needle)
        .map(|n| from + n)
}

/// A block opened by `{`: its kind (None when it takes neither properties nor statements
/// the editor knows, such as the body of an unknown kind of object).
#[derive(Clone, Copy, Debug)]
struct Frame {
    kind: Option<BlockKind>,
    /// The token index of its `{` (none for the file).
    open: Option<usize>,
}

struct Reader<'a> {
    text: &'a str,
    tokens: Vec<Token>,
}

impl Reader<'_> {
    fn word(&self, index: usize) -> Option<&str> {
        let token = self.tokens.get(index)?;
        (token.class == Class::Word).then(|| &self.text[token.start..token.end])
    }

    fn punct(&self, index: usize) -> Option<u8> {
        match self.tokens.get(index)?.class {
            Class::Punct(byte) => Some(byte),
            _ => None,
        }
    }

    /// What the `{` at token `open` opens, from the statement before it (which starts after
    /// the previous `{`, `}` or `;` at or after `floor`).
    fn classify(&self, open: usize, floor: usize) -> Option<BlockKind> {
        // The statement's tokens, walking back over brackets of its own.
        let mut start = open;
        let mut depth = 0i32;
        while start > floor {
            match self.punct(start - 1) {
                Some(b'(' | b'[') => depth -= 1,
                Some(b')' | b']') => depth += 1,
                Some(b'{' | b'}' | b';') if depth <= 0 => break,
                _ => {}
            }
            start -= 1;
        }
        let statement = start..open;
        let keyword = |w: &str| statement.clone().any(|i| self.word(i) == Some(w));
        if ["fn", "for", "while", "if", "else"]
            .into_iter()
            .any(keyword)
        {
            return Some(BlockKind(Context::Statements {
                top_level: false,
                in_function: keyword("fn"),
            }));
        }
        let last = open.checked_sub(1)?;
        if self.punct(last) == Some(b')') {
            // `ring(3) { ... }` or a pattern: `diffuse checker(a, b, 1) { ... }`.
            let mut depth = 0;
            let mut at = last;
            loop {
                match self.punct(at) {
                    Some(b')') => depth += 1,
                    Some(b'(') => depth -= 1,
                    _ => {}
                }
                if depth == 0 || at == start {
                    break;
                }
                at -= 1;
            }
            let before_callee = at.checked_sub(2).filter(|&i| i >= start);
            let context = match before_callee.and_then(|i| self.word(i)) {
                Some(_) => Context::PatternTransform,
                None => Context::Modifiers,
            };
            return Some(BlockKind(context));
        }
        // `material`, `material glass`, `material a : b`, `material : b`: a material.
        if statement.clone().any(|i| self.word(i) == Some("material")) {
            return Some(BlockKind(Context::Material));
        }
        let words: Vec<&str> = statement.filter_map(|i| self.word(i)).collect();
        block_named(&words)
    }
}

/// The place at byte `offset` of `text` (an offset inside a character counts as its start).
pub fn place_at(text: &str, offset: usize) -> Cursor {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let (tokens, quiet) = tokens(text);
    let other = |word_start| Cursor {
        place: Place::Other,
        word_start,
    };
    if quiet
        .iter()
        .any(|&(s, e)| s <= offset && offset <= e && s < e)
        || quiet.iter().any(|&(s, e)| s == e && s == offset)
    {
        return other(offset);
    }
    let reader = Reader { text, tokens };
    let tokens = &reader.tokens;
    // The word being typed ends at the cursor.
    let typed = tokens
        .iter()
        .position(|t| t.class == Class::Word && t.start < offset && offset <= t.end);
    let before = typed.unwrap_or_else(|| tokens.partition_point(|t| t.end <= offset));
    let word_start = typed.map_or(offset, |i| tokens[i].start);
    if tokens
        .get(before)
        .is_some_and(|t| t.start < offset && typed.is_none())
    {
        // Inside a number or a token that is no word.
        return other(offset);
    }
    let file = Frame {
        kind: Some(BlockKind(Context::Statements {
            top_level: true,
            in_function: false,
        })),
        open: None,
    };
    let mut stack = vec![file];
    for index in 0..before {
        match reader.punct(index) {
            Some(b'{') => {
                let floor = stack.last().and_then(|f| f.open).map_or(0, |o| o + 1);
                let kind = reader.classify(index, floor);
                stack.push(Frame {
                    kind,
                    open: Some(index),
                });
            }
            Some(b'}') if stack.len() > 1 => {
                stack.pop();
            }
            _ => {}
        }
    }
    let frame = stack[stack.len() - 1];
    let Some(block) = frame.kind else {
        return other(word_start);
    };
    let previous = before.checked_sub(1).filter(|&i| Some(i) != frame.open);
    if let Some(previous) = previous {
        let word = |back: usize| previous.checked_sub(back).and_then(|i| reader.word(i));
        if reader.punct(previous) == Some(b':') {
            let child = match (word(2), word(1)) {
                (Some("material"), Some(child)) => Some(Some(child.to_string())),
                (_, Some("material")) => Some(None),
                _ => None,
            };
            if let Some(child) = child {
                return Cursor {
                    place: Place::ParentMaterial { child },
                    word_start,
                };
            }
        }
    }
    if let BlockKind(Context::Statements {
        top_level,
        in_function,
    }) = block
    {
        let at_start = previous.is_none_or(|i| matches!(reader.punct(i), Some(b'}' | b';')));
        if !at_start {
            return other(word_start);
        }
        return Cursor {
            place: Place::Statement {
                statements: super::statement_words(top_level, in_function),
            },
            word_start,
        };
    }
    match previous.map(|i| (tokens[i].class, reader.word(i))) {
        Some((Class::Word, Some(name))) => {
            if let Some(property) = block.property(name).filter(|p| !p.is_flag) {
                return Cursor {
                    place: Place::Value { block, property },
                    word_start,
                };
            }
        }
        Some((Class::Punct(byte), _)) if !matches!(byte, b'>' | b')' | b']' | b'}' | b';') => {
            return other(word_start);
        }
        Some((Class::Other, _)) => return other(word_start),
        _ => {}
    }
    let written = written_in(&reader, frame.open.map_or(0, |o| o + 1), typed, block);
    Cursor {
        place: Place::PropertyName { block, written },
        word_start,
    }
}

/// The properties written directly in the block whose tokens start at `first`, leaving out
/// the word being typed.
fn written_in(
    reader: &Reader<'_>,
    first: usize,
    typed: Option<usize>,
    block: BlockKind,
) -> Vec<&'static str> {
    let mut written = Vec::new();
    let mut depth = 0i32;
    for index in first..reader.tokens.len() {
        match reader.punct(index) {
            Some(b'{' | b'(' | b'[') => depth += 1,
            Some(b'}' | b')' | b']') => {
                depth -= 1;
                if depth < 0 {
                    break;
                }
            }
            _ => {}
        }
        if depth != 0 || Some(index) == typed {
            continue;
        }
        if let Some(property) = reader.word(index).and_then(|w| block.property(w)) {
            if !written.contains(&property.name) {
                written.push(property.name);
            }
        }
    }
    written
}

/// The names of the materials `text` defines (`material glass { ... }`, `material tinted :
/// glass { ... }`), in order, each once.
pub fn material_names(text: &str) -> Vec<String> {
    let reader = Reader {
        text,
        tokens: tokens(text).0,
    };
    let mut names = Vec::new();
    for index in 0..reader.tokens.len() {
        if reader.word(index) != Some("material") {
            continue;
        }
        let Some(name) = reader.word(index + 1) else {
            continue;
        };
        if matches!(reader.punct(index + 2), Some(b'{' | b':')) && !names.iter().any(|n| n == name)
        {
            names.push(name.to_string());
        }
    }
    names
}

/// The `import "path"` statements of `text`: each path as written, with the byte range of
/// the whole statement.
pub fn imports(text: &str) -> Vec<(String, std::ops::Range<usize>)> {
    let reader = Reader {
        text,
        tokens: tokens(text).0,
    };
    let mut found = Vec::new();
    for index in 0..reader.tokens.len() {
        let (Some("import"), Some(path)) = (reader.word(index), reader.tokens.get(index + 1))
        else {
            continue;
        };
        let closed = path.end >= path.start + 2 && text.as_bytes()[path.end - 1] == b'"';
        if path.class == Class::Text && closed {
            let written = &text[path.start + 1..path.end - 1];
            found.push((written.to_string(), reader.tokens[index].start..path.end));
        }
    }
    found
}
