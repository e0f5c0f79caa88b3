//! The query language's reader: text to an expression tree, with every error located by a
//! byte range in the text so that the binary can point at it with a caret.

use std::fmt;
use std::ops::Range;

/// A predicate over one pixel's rays.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Atom(Atom),
    Not(Box<Expr>),
    And(Box<Expr>, Box<Expr>),
    Or(Box<Expr>, Box<Expr>),
}

/// One test of a pixel's rays; `names` are resolved against the scene later.
#[derive(Clone, Debug, PartialEq)]
pub enum Atom {
    MaxDepth,
    WeightCutoff,
    Tir,
    ShadowBlocked,
    /// The object name and where it is written in the query.
    ShadowBlockedBy(String, Range<usize>),
    ShadowBlockedByTransparent,
    SelfHit,
    Nan,
    Hit(String, Range<usize>),
    Depth(Compare, u32),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    Less,
    LessEqual,
    Equal,
    NotEqual,
    GreaterEqual,
    Greater,
}

impl Compare {
    pub fn holds(self, left: u32, right: u32) -> bool {
        match self {
            Compare::Less => left < right,
            Compare::LessEqual => left <= right,
            Compare::Equal => left == right,
            Compare::NotEqual => left != right,
            Compare::GreaterEqual => left >= right,
            Compare::Greater => left > right,
        }
    }
}

/// A query that cannot be read or resolved, located in its text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct QueryError {
    pub message: String,
    /// Byte range in the query text (empty at the end of the text for "expected more").
    pub span: Range<usize>,
}

impl QueryError {
    pub(crate) fn new(message: impl Into<String>, span: Range<usize>) -> QueryError {
        QueryError {
            message: message.into(),
            span,
        }
    }

    /// The message, the query and a caret line under the place it concerns.
    pub fn render(&self, query: &str) -> String {
        let start = query[..self.span.start.min(query.len())].chars().count();
        let width = query
            .get(self.span.clone())
            .map_or(1, |s| s.chars().count().max(1));
        format!(
            "{}\n  {}\n  {}{}",
            self.message,
            query.replace(['\n', '\t'], " "),
            " ".repeat(start),
            "^".repeat(width)
        )
    }
}

impl fmt::Display for QueryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// The predicates without arguments, with what they test (for `unknown` messages).
pub const PREDICATES: &[&str] = &[
    "max_depth",
    "weight_cutoff",
    "tir",
    "shadow_blocked",
    "shadow_blocked_by(\"NAME\")",
    "shadow_blocked_by_transparent",
    "self_hit",
    "nan",
    "hit(\"NAME\")",
    "depth >= N",
];

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Word(String),
    Text(String),
    Number(u32),
    Compare(Compare),
    Open,
    Close,
    End,
}

fn lex(text: &str) -> Result<Vec<(Token, Range<usize>)>, QueryError> {
    let mut tokens = Vec::new();
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        if c.is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let token = match c {
            b'(' => {
                i += 1;
                Token::Open
            }
            b')' => {
                i += 1;
                Token::Close
            }
            b'"' => {
                let Some(len) = text[i + 1..].find('"') else {
                    return Err(QueryError::new(
                        "this name has no closing `\"`",
                        start..text.len(),
                    ));
                };
                i += len + 2;
                Token::Text(text[start + 1..i - 1].to_string())
            }
            b'<' | b'>' | b'=' | b'!' => {
                let two = text.get(i..i + 2).unwrap_or("");
                let (compare, len) = match (c, two) {
                    (_, "<=") => (Compare::LessEqual, 2),
                    (_, ">=") => (Compare::GreaterEqual, 2),
                    (_, "==") => (Compare::Equal, 2),
                    (_, "!=") => (Compare::NotEqual, 2),
                    (b'<', _) => (Compare::Less, 1),
                    (b'>', _) => (Compare::Greater, 1),
                    (b'=', _) => (Compare::Equal, 1),
                    _ => {
                        return Err(QueryError::new(
                            "`!` is not an operator here: write `not`",
                            start..start + 1,
                        ))
                    }
                };
                i += len;
                Token::Compare(compare)
            }
            b'0'..=b'9' => {
                while i < bytes.len() && bytes[i].is_ascii_digit() {
                    i += 1;
                }
                let number = text[start..i]
                    .parse::<u32>()
                    .map_err(|_| QueryError::new("this number is too large", start..i))?;
                Token::Number(number)
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                Token::Word(text[start..i].to_string())
            }
            b'&' | b'|' => {
                let word = if c == b'&' { "and" } else { "or" };
                let len = if bytes.get(i + 1) == Some(&c) { 2 } else { 1 };
                return Err(QueryError::new(
                    format!("write `{word}` to combine predicates"),
                    start..start + len,
                ));
            }
            _ => {
                let len = text[start..].chars().next().map_or(1, char::len_utf8);
                return Err(QueryError::new(
                    format!("unexpected `{}` in the query", &text[start..start + len]),
                    start..start + len,
                ));
            }
        };
        tokens.push((token, start..i));
    }
    tokens.push((Token::End, text.len()..text.len()));
    Ok(tokens)
}

/// The most nested parentheses and `not`s a query may have (the reader recurses on them).
pub const MAX_NESTING: usize = 64;

struct Parser {
    tokens: Vec<(Token, Range<usize>)>,
    at: usize,
    nesting: usize,
}

/// Reads a query: `or` binds loosest, then `and`, then `not`; parentheses group.
pub fn parse(text: &str) -> Result<Expr, QueryError> {
    let mut parser = Parser {
        tokens: lex(text)?,
        at: 0,
        nesting: 0,
    };
    if parser.peek() == &Token::End {
        return Err(QueryError::new(
            format!(
                "the query is empty: write a predicate such as {}",
                PREDICATES.join(", ")
            ),
            0..0,
        ));
    }
    let expr = parser.or()?;
    match parser.peek() {
        Token::End => Ok(expr),
        Token::Close => Err(parser.error_here("this `)` has no `(` before it")),
        _ => Err(parser.error_here("expected `and`, `or` or the end of the query here")),
    }
}

impl Parser {
    fn peek(&self) -> &Token {
        &self.tokens[self.at].0
    }

    fn span(&self) -> Range<usize> {
        self.tokens[self.at].1.clone()
    }

    fn error_here(&self, message: &str) -> QueryError {
        QueryError::new(message, self.span())
    }

    fn is_word(&self, word: &str) -> bool {
        matches!(self.peek(), Token::Word(w) if w == word)
    }

    fn or(&mut self) -> Result<Expr, QueryError> {
        let mut left = self.and()?;
        while self.is_word("or") {
            self.at += 1;
            let right = self.and()?;
            left = Expr::Or(Box::new(left), Box::new(right));
        }
        Ok(left)
    }

    fn and(&mut self) -> Result<Expr, QueryError> {
        let mut left = self.unary()?;
        while self.is_word("and") {
            self.at += 1;
            let right = self.unary()?;
            left = Expr::And(Box::new(left), Box::new(right));
        }
        Ok(left)
    }

    fn deeper(&mut self) -> Result<(), QueryError> {
        self.nesting += 1;
        if self.nesting > MAX_NESTING {
            return Err(self.error_here(&format!(
                "the query nests more than {MAX_NESTING} levels of `not` and parentheses"
            )));
        }
        Ok(())
    }

    fn unary(&mut self) -> Result<Expr, QueryError> {
        if self.is_word("not") {
            self.deeper()?;
            self.at += 1;
            let inner = self.unary()?;
            self.nesting -= 1;
            return Ok(Expr::Not(Box::new(inner)));
        }
        if self.peek() == &Token::Open {
            self.deeper()?;
            let open = self.span();
            self.at += 1;
            let inner = self.or()?;
            if self.peek() != &Token::Close {
                let mut error = self.error_here("expected `)` to close the `(` before");
                if self.peek() == &Token::End {
                    error = QueryError::new("this `(` is never closed", open);
                }
                return Err(error);
            }
            self.at += 1;
            self.nesting -= 1;
            return Ok(inner);
        }
        self.atom().map(Expr::Atom)
    }

    fn atom(&mut self) -> Result<Atom, QueryError> {
        let span = self.span();
        let word = match self.peek() {
            Token::Word(word) => word.clone(),
            Token::End => {
                return Err(self.error_here("the query ends where a predicate was expected"))
            }
            _ => {
                return Err(self.error_here(&format!(
                    "expected a predicate here ({})",
                    PREDICATES.join(", ")
                )))
            }
        };
        self.at += 1;
        let atom = match word.as_str() {
            "max_depth" => Atom::MaxDepth,
            "weight_cutoff" => Atom::WeightCutoff,
            "tir" => Atom::Tir,
            "shadow_blocked" => Atom::ShadowBlocked,
            "shadow_blocked_by_transparent" => Atom::ShadowBlockedByTransparent,
            "self_hit" => Atom::SelfHit,
            "nan" => Atom::Nan,
            "shadow_blocked_by" => {
                let (name, at) = self.name_argument(&word)?;
                Atom::ShadowBlockedBy(name, at)
            }
            "hit" => {
                let (name, at) = self.name_argument(&word)?;
                Atom::Hit(name, at)
            }
            "depth" => {
                let Token::Compare(compare) = *self.peek() else {
                    return Err(
                        self.error_here("expected a comparison after `depth`, as in `depth >= 4`")
                    );
                };
                self.at += 1;
                let Token::Number(n) = *self.peek() else {
                    return Err(self.error_here("expected a whole number here, as in `depth >= 4`"));
                };
                self.at += 1;
                Atom::Depth(compare, n)
            }
            "and" | "or" => {
                return Err(QueryError::new(
                    format!("`{word}` needs a predicate before it"),
                    span,
                ))
            }
            _ => {
                let hint = suggest(&word)
                    .map(|s| format!(": did you mean `{s}`?"))
                    .unwrap_or_else(|| format!(" (the predicates: {})", PREDICATES.join(", ")));
                return Err(QueryError::new(
                    format!("unknown predicate `{word}`{hint}"),
                    span,
                ));
            }
        };
        Ok(atom)
    }

    fn name_argument(&mut self, word: &str) -> Result<(String, Range<usize>), QueryError> {
        let example = format!("as in `{word}(\"glass\")`");
        if self.peek() != &Token::Open {
            return Err(self.error_here(&format!("`{word}` needs an object's name, {example}")));
        }
        self.at += 1;
        let Token::Text(name) = self.peek().clone() else {
            return Err(self.error_here(&format!("expected a quoted object name here, {example}")));
        };
        let at = self.span();
        self.at += 1;
        if self.peek() != &Token::Close {
            return Err(self.error_here("expected `)` after the name"));
        }
        self.at += 1;
        Ok((name, at))
    }
}

/// The predicate nearest to a misspelt word (at most two edits away).
fn suggest(word: &str) -> Option<&'static str> {
    let names = [
        "max_depth",
        "weight_cutoff",
        "tir",
        "shadow_blocked",
        "shadow_blocked_by",
        "shadow_blocked_by_transparent",
        "self_hit",
        "nan",
        "hit",
        "depth",
        "not",
        "and",
        "or",
    ];
    names
        .into_iter()
        .map(|name| (edit_distance(word, name), name))
        .filter(|(d, _)| *d <= 2)
        .min_by_key(|(d, _)| *d)
        .map(|(_, name)| name)
}

pub(crate) fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut previous = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let next = (row[j + 1] + 1)
                .min(row[j] + 1)
                .min(previous + usize::from(ca != *cb));
            previous = row[j + 1];
            row[j + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precedence_and_grouping() {
        let e = parse("tir or not nan and depth >= 3").unwrap();
        assert_eq!(
            e,
            Expr::Or(
                Box::new(Expr::Atom(Atom::Tir)),
                Box::new(Expr::And(
                    Box::new(Expr::Not(Box::new(Expr::Atom(Atom::Nan)))),
                    Box::new(Expr::Atom(Atom::Depth(Compare::GreaterEqual, 3)))
                ))
            )
        );
        let g = parse("(tir or nan) and hit(\"glass\")").unwrap();
        assert!(matches!(g, Expr::And(ref l, ref r)
            if matches!(**l, Expr::Or(..)) && matches!(**r, Expr::Atom(Atom::Hit(ref n, _)) if n == "glass")));
    }

    #[test]
    fn errors_point_at_the_place() {
        let query = "tir and shadow_blokced";
        let error = parse(query).unwrap_err();
        assert_eq!(error.span, 8..22);
        assert!(
            error.message.contains("did you mean `shadow_blocked`"),
            "{}",
            error.message
        );
        assert_eq!(
            error.render(query).lines().nth(2),
            Some("          ^^^^^^^^^^^^^^")
        );
        assert_eq!(parse("(tir").unwrap_err().span, 0..1);
        assert_eq!(parse("tir && nan").unwrap_err().span, 4..6);
        assert_eq!(parse("depth >= x").unwrap_err().span, 9..10);
        assert_eq!(parse("tir nan").unwrap_err().span, 4..7);
        assert_eq!(parse("hit(glass)").unwrap_err().span, 4..9);
        assert_eq!(parse("").unwrap_err().span, 0..0);
        assert!(parse(&"not ".repeat(100)).is_err());
        // Every cut of a query, and text that is not ASCII, is an error or a query, never a
        // panic, and the caret stays on the text.
        let full = "not (tir or shadow_blocked_by(\"ß glass\")) and depth >= 12 or é";
        for (cut, _) in full.char_indices() {
            if let Err(error) = parse(&full[..cut]) {
                assert!(error.span.end <= cut, "{cut}: {error:?}");
                let _ = error.render(&full[..cut]);
            }
        }
        let error = parse("tír").unwrap_err();
        assert!(
            error.render("tír").ends_with("\n   ^"),
            "{}",
            error.render("tír")
        );
        assert!(parse(&format!("{}tir{}", "(".repeat(100), ")".repeat(100))).is_err());
    }
}
