//! Reading the format's pieces from the token stream: keywords, braces, numbers, vectors and
//! counts, each failure a located [`Diagnostic`] that says what was expected in words.

use whitted_ir::{DVec3, Diagnostic, FileId, Span};

use crate::tokens::{Token, Tokens};

/// A failure that ends the reading of the file: the format has no way to resynchronise
/// after a wrong word, as the course's reader had none.
pub type Read<T> = Result<T, Box<Diagnostic>>;

/// The tokens of one file, with the file's id for spans.
pub struct Reader<'a> {
    pub tokens: Tokens<'a>,
    pub file: FileId,
}

impl<'a> Reader<'a> {
    pub fn new(text: &'a str, file: FileId) -> Self {
        Reader {
            tokens: Tokens::new(text),
            file,
        }
    }

    pub fn span(&self, token: Token<'_>) -> Span {
        Span::new(self.file, token.start, token.end)
    }

    /// An error at `token`.
    pub fn error_at<T>(&self, token: Token<'_>, message: impl Into<String>) -> Read<T> {
        Err(Box::new(Diagnostic::error(message, self.span(token))))
    }

    /// The next word; at the end of the file, an error saying what was expected.
    pub fn next(&mut self, expected: &str) -> Read<Token<'a>> {
        match self.tokens.next_token() {
            Some(token) => Ok(token),
            None => {
                let end = self.tokens.end();
                Err(Box::new(
                    Diagnostic::error(
                        format!("the file ends where {expected} was expected"),
                        Span::new(self.file, end, end),
                    )
                    .with_label(format!("expected {expected}")),
                ))
            }
        }
    }

    /// Takes the word `word` or fails, saying what came instead.
    pub fn expect(&mut self, word: &str) -> Read<Token<'a>> {
        let token = self.next(&format!("`{word}`"))?;
        if token.text == word {
            Ok(token)
        } else {
            Err(Box::new(
                Diagnostic::error(
                    format!("expected `{word}`, found `{}`", token.text),
                    self.span(token),
                )
                .with_label(format!("expected `{word}`")),
            ))
        }
    }

    /// A finite number (`what` names it for the message: "the sphere's radius").
    pub fn number(&mut self, what: &str) -> Read<f64> {
        let token = self.next(&format!("a number ({what})"))?;
        match token.text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            Ok(_) => self.error_at(
                token,
                format!("{what} must be a finite number, not `{}`", token.text),
            ),
            Err(_) => Err(Box::new(
                Diagnostic::error(
                    format!("expected a number ({what}), found `{}`", token.text),
                    self.span(token),
                )
                .with_label("not a number"),
            )),
        }
    }

    /// A whole number from 0 to `max` (a count or an index).
    pub fn count(&mut self, what: &str, max: usize, limit: &str) -> Read<usize> {
        let token = self.next(&format!("a whole number ({what})"))?;
        match token.text.parse::<u64>() {
            Ok(n) if n <= max as u64 => Ok(n as usize),
            Ok(n) => Err(Box::new(
                Diagnostic::error(
                    format!(
                        "{what} is {n}, past {}",
                        whitted_ir::limits::describe(limit)
                    ),
                    self.span(token),
                )
                .with_label("too many"),
            )),
            Err(_) => self.error_at(
                token,
                format!("expected a whole number ({what}), found `{}`", token.text),
            ),
        }
    }

    /// Three numbers.
    pub fn vector(&mut self, what: &str) -> Read<DVec3> {
        Ok(DVec3::new(
            self.number(what)?,
            self.number(what)?,
            self.number(what)?,
        ))
    }
}
