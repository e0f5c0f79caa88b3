//! The 6.837 format's tokens: words separated by whitespace, read lazily with their byte
//! ranges so that every diagnostic and every IR node can point at the text.
//!
//! The course's own reader took whitespace-separated words (`fscanf("%s")`), so `Sphere{`
//! was one word there. Braces are split off here even without space around them: a file
//! the course read is read the same way, and a file it misread gets a clear message rather
//! than "unknown keyword `Sphere{`".

/// One word of the file and where it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Token<'a> {
    pub text: &'a str,
    pub start: usize,
    pub end: usize,
}

/// A cursor over the words of a text, with one word of look-ahead.
pub struct Tokens<'a> {
    text: &'a str,
    position: usize,
    peeked: Option<Option<Token<'a>>>,
    /// Where the last token taken ends (a field's value ends there).
    last_end: usize,
}

impl<'a> Tokens<'a> {
    pub fn new(text: &'a str) -> Self {
        Tokens {
            text,
            position: 0,
            peeked: None,
            last_end: 0,
        }
    }

    /// The next word without taking it.
    pub fn peek(&mut self) -> Option<Token<'a>> {
        if self.peeked.is_none() {
            let token = self.scan();
            self.peeked = Some(token);
        }
        self.peeked.flatten()
    }

    pub fn next_token(&mut self) -> Option<Token<'a>> {
        let token = match self.peeked.take() {
            Some(token) => token,
            None => self.scan(),
        };
        if let Some(token) = &token {
            self.last_end = token.end;
        }
        token
    }

    /// Where the last token taken ends.
    pub fn last_end(&self) -> usize {
        self.last_end
    }

    /// Where the text ends (for "the file ends before ..." messages).
    pub fn end(&self) -> usize {
        self.text.len()
    }

    fn scan(&mut self) -> Option<Token<'a>> {
        let bytes = self.text.as_bytes();
        let mut i = self.position;
        while i < bytes.len() && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        if i == bytes.len() {
            self.position = i;
            return None;
        }
        let start = i;
        if matches!(bytes[i], b'{' | b'}') {
            i += 1;
        } else {
            // Words end at whitespace or a brace; both are ASCII, so `i` stays on a
            // character boundary of the UTF-8 text.
            while i < bytes.len()
                && !bytes[i].is_ascii_whitespace()
                && !matches!(bytes[i], b'{' | b'}')
            {
                i += 1;
            }
        }
        self.position = i;
        Some(Token {
            text: &self.text[start..i],
            start,
            end: i,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(text: &str) -> Vec<(&str, usize, usize)> {
        let mut tokens = Tokens::new(text);
        let mut out = Vec::new();
        while let Some(t) = tokens.next_token() {
            out.push((t.text, t.start, t.end));
        }
        out
    }

    #[test]
    fn words_and_braces_with_their_places() {
        assert_eq!(
            words("Sphere {\n  center 0 0 -1e2\n}"),
            vec![
                ("Sphere", 0, 6),
                ("{", 7, 8),
                ("center", 11, 17),
                ("0", 18, 19),
                ("0", 20, 21),
                ("-1e2", 22, 26),
                ("}", 27, 28),
            ]
        );
        assert_eq!(
            words("Group{1}"),
            vec![("Group", 0, 5), ("{", 5, 6), ("1", 6, 7), ("}", 7, 8)]
        );
        assert!(words(" \t\r\n").is_empty());
    }

    #[test]
    fn peeking_does_not_take() {
        let mut tokens = Tokens::new("a b");
        assert_eq!(tokens.peek().map(|t| t.text), Some("a"));
        assert_eq!(tokens.peek().map(|t| t.text), Some("a"));
        assert_eq!(tokens.next_token().map(|t| t.text), Some("a"));
        assert_eq!(tokens.next_token().map(|t| t.text), Some("b"));
        assert_eq!(tokens.peek(), None);
        assert_eq!(tokens.next_token(), None);
    }
}
