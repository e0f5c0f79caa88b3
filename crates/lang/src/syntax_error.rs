//! Turns pest's "expected one of these rules" into a sentence a user can act on: what could
//! come next, in words ("a value such as `1`, `<0, 1, 0>` or a name", "`;`"), what was found
//! instead, and where the enclosing block opened.
//!
//! pest reports two things: the rules it tried at the position where its last rule failed
//! (`positives`), and, with error detail on, the literal tokens it would have accepted at the
//! furthest position it reached. The furthest position is usually the better place to point,
//! and its tokens name punctuation that rule names cannot (`,` inside a vector).

use pest::error::{ErrorVariant, InputLocation};
use whitted_ir::{Diagnostic, FileId, Span};

use crate::lexical::Brackets;
use crate::parser::Rule;

/// What may come next, collected from rules and tokens, then worded in a fixed order.
#[derive(Default, Debug)]
struct Expected {
    statement: bool,
    value: bool,
    name: bool,
    string: bool,
    operator: bool,
    /// The failure is inside `<x, y, z>` (where `>` closes the vector).
    in_vector: bool,
    /// Right after a `.`, where a field name must follow.
    after_dot: bool,
    /// Right after a property's name, where its value must follow.
    value_for: Option<&'static str>,
    /// Exact tokens such as `;`, `,`, `}` (kept in grammar-independent order).
    punctuation: Vec<&'static str>,
}

const PUNCTUATION: [&str; 14] = [
    ";", ",", ">", ")", "}", "{", "=", ":", "..", "..=", "(", "in", "about", "else",
];

impl Expected {
    fn punct(&mut self, token: &str) {
        if let Some(&known) = PUNCTUATION.iter().find(|p| **p == token) {
            if !self.punctuation.contains(&known) {
                self.punctuation.push(known);
            }
        }
    }

    fn add_rule(&mut self, rule: Rule) {
        use Rule::*;
        match rule {
            file => self.statement = true,
            expr | arith | postfix | neg | not | paren | vector | number | hex_color | call
            | material_literal | kw_true | kw_false | define_value => self.value = true,
            ident => self.name = true,
            string => self.string = true,
            block => self.punct("{"),
            params => self.punct("("),
            range_op => {
                self.punct("..");
                self.punct("..=");
            }
            material_body => {
                self.punct(":");
                self.punct("{");
            }
            kw_in => self.punct("in"),
            kw_about => {}
            kw_import | kw_const | kw_let | kw_fn | kw_for | kw_while | kw_if | kw_return
            | kw_settings | kw_camera | kw_light | kw_material | kw_open => self.statement = true,
            or | and | eq | ne | le | ge | lt | gt | add | sub | mul | div | rem | field => {
                self.operator = true
            }
            _ => {}
        }
    }

    /// `tokens` are pest's expected tokens as text: literals as themselves, character
    /// ranges as `a..z`.
    fn add_tokens(&mut self, tokens: &[String]) {
        let has = |text: &str| tokens.iter().any(|t| t == text);
        if has("#") {
            self.value = true;
        }
        if has("let") {
            self.statement = true;
        } else if !self.value && has("a..z") {
            self.name = true;
        }
        // Where a value may start, a string is one of the values.
        if has("\"") && !self.value {
            self.string = true;
        }
        if has("*") {
            self.operator = true;
        }
        for token in tokens {
            let skip = match token.as_str() {
                // These also start values; only name them where no value may start.
                "(" | "<" => self.value || self.operator,
                // After a value, `>` is a comparison unless a vector is being closed.
                ">" => !self.in_vector,
                // After a property's value: a pattern's block or `about` are rare and
                // would only crowd the message.
                "{" | "about" => self.statement,
                _ => false,
            };
            if !skip {
                self.punct(token);
            }
        }
    }

    fn words(&self) -> Vec<String> {
        if let (Some(property), true) = (self.value_for, self.value) {
            return vec![format!("a value for `{property}`")];
        }
        let mut words = Vec::new();
        if self.statement {
            words.push("a property, object or statement".to_string());
        }
        if self.value {
            words.push("a value such as `1`, `<0, 1, 0>` or a name".to_string());
        }
        if self.after_dot && self.name && !self.statement && !self.value {
            words.push("a field name (`x`, `y`, `z`, `r`, `g` or `b`)".to_string());
        } else if self.name && !self.statement && !self.value {
            words.push("a name".to_string());
        }
        if self.string {
            words.push("a name in quotes".to_string());
        }
        for p in PUNCTUATION {
            if self.punctuation.contains(&p) {
                words.push(format!("`{p}`"));
            }
        }
        if words.is_empty() && self.operator {
            words.push("an operator".to_string());
        }
        words
    }
}

/// "a, b or c"; "a, b or c, or d" when a phrase has its own "or".
fn join_or(words: &[String]) -> String {
    match words {
        [] => "something else".to_string(),
        [one] => one.clone(),
        [rest @ .., last] => {
            let nested = rest.iter().any(|w| w.contains(" or "));
            let or = if nested { ", or" } else { " or" };
            format!("{}{or} {last}", rest.join(", "))
        }
    }
}

/// The token that starts at `pos`, for "found ...", and its byte length.
fn found_token(text: &str, pos: usize) -> (String, usize) {
    let rest = text.get(pos..).unwrap_or("");
    let Some(first) = rest.chars().next() else {
        return ("the end of the file".to_string(), 0);
    };
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    let len = if first.is_ascii_digit() {
        // A number: digits, then `.digits` (but not the `..` of a range).
        let digits = |s: &str| s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len());
        let whole = digits(rest);
        let after = &rest[whole..];
        match after.strip_prefix('.') {
            Some(fraction) if fraction.starts_with(|c: char| c.is_ascii_digit()) => {
                whole + 1 + digits(fraction)
            }
            _ => whole,
        }
    } else if first.is_alphanumeric() || first == '_' {
        rest.find(|c: char| !is_word(c)).unwrap_or(rest.len())
    } else {
        let two = rest.get(..2).unwrap_or("");
        if ["==", "!=", "<=", ">=", "&&", "||", "..", "//", "/*"].contains(&two) {
            2
        } else {
            first.len_utf8()
        }
    };
    let token = &rest[..len];
    let shown = if first.is_control() {
        format!("the character {}", first.escape_default())
    } else if first.is_alphabetic() || first == '_' {
        format!("`{token}`")
    } else if first.is_ascii_digit() {
        format!("the number `{token}`")
    } else {
        format!("`{token}`")
    };
    (shown, len)
}

fn previous_word(text: &str, pos: usize) -> &str {
    let before = text.get(..pos).unwrap_or("").trim_end();
    let start = before
        .char_indices()
        .rev()
        .find(|(_, c)| !(c.is_alphanumeric() || *c == '_'))
        .map_or(0, |(i, c)| i + c.len_utf8());
    &before[start..]
}

/// Converts a pest error into one diagnostic. `brackets` (from the lexical pass) lets the
/// message point at the block a missing `}` belongs to.
pub fn translate(
    error: &pest::error::Error<Rule>,
    text: &str,
    file: FileId,
    brackets: Option<&Brackets>,
) -> Diagnostic {
    let pest_pos = match error.location {
        InputLocation::Pos(p) => p,
        InputLocation::Span((s, _)) => s,
    };
    let positives: &[Rule] = match &error.variant {
        ErrorVariant::ParsingError { positives, .. } => positives,
        ErrorVariant::CustomError { .. } => &[],
    };
    if let ErrorVariant::CustomError { message } = &error.variant {
        // pest's own limits ("stack limit reached"): the input is nested past what it can
        // parse. The lexical pass catches brackets, so this is a long run of `<` or `-`.
        return Diagnostic::error(
            "this part of the scene is nested too deeply to parse",
            Span::new(file, pest_pos, pest_pos + 1),
        )
        .with_hint(format!("the parser said: {message}"));
    }

    let mut expected = Expected::default();
    let mut pos = pest_pos;
    let mut used_tokens = false;
    if let Some(attempts) = error.parse_attempts() {
        let tokens: Vec<String> = attempts
            .expected_tokens()
            .into_iter()
            .map(|t| t.to_string())
            .filter(|t| {
                !matches!(
                    t.as_str(),
                    " " | "\t" | "\r" | "\n" | "\u{feff}" | "//" | "/*"
                )
            })
            .collect();
        // Tokens that only continue a word are a keyword check looking past a name
        // (`let in = 1`); the rule-level position explains that better.
        let inside_word = tokens
            .iter()
            .all(|t| t == "_" || matches!(t.as_str(), "a..z" | "A..Z" | "0..9"));
        if attempts.max_position >= pest_pos && !tokens.is_empty() && !inside_word {
            pos = attempts.max_position;
            // Rule names at this position are too coarse (`file`, `block`) to add words;
            // they only tell whether the failure is inside a vector.
            expected.in_vector = attempts
                .call_stacks()
                .iter()
                .any(|s| s.deepest.get_rule() == Some(&Rule::arith));
            expected.add_tokens(&tokens);
            used_tokens = true;
        }
    }
    if !used_tokens {
        for rule in positives {
            expected.add_rule(*rule);
        }
    }

    expected.after_dot = pos > 0 && text.as_bytes().get(pos - 1) == Some(&b'.');
    let previous = previous_word(text, pos);
    expected.value_for = crate::schema::Prop::ALL
        .iter()
        .map(|p| p.name())
        .find(|name| *name == previous);
    let (found, found_len) = found_token(text, pos);
    if let Some(diagnostic) = common_mistake(text, pos, found_len, file) {
        return diagnostic;
    }
    let words = expected.words();
    let message = format!("expected {}, found {found}", join_or(&words));
    let span = Span::new(file, pos, pos + found_len);
    let mut diagnostic = Diagnostic::error(message, span).with_label(match words.as_slice() {
        [one] => format!("expected {one} here"),
        _ => "unexpected here".to_string(),
    });
    if expected.punctuation.contains(&"}") {
        if let Some(pair) = brackets.and_then(|b| b.innermost_brace_around(pos as u32)) {
            diagnostic = diagnostic.with_secondary(
                Span::new(file, pair.open as usize, pair.open as usize + 1),
                "in the block that starts here",
            );
        }
    }
    if let (Some((_, comma)), true) = (
        crate::hints::comma_before_property(text.get(..pos).unwrap_or("")),
        expected.punctuation.contains(&",") && !expected.in_vector && expected.statement,
    ) {
        diagnostic =
            diagnostic.with_secondary(Span::new(file, comma, comma + 1), "remove this comma");
    }
    // The word the advice is about, unless the error already points at it.
    if let Some((start, end)) =
        crate::hints::first_foreign_word(text, pos).filter(|&(start, _)| start != pos)
    {
        diagnostic =
            diagnostic.with_secondary(Span::new(file, start, end), "see the help about this");
    }
    for hint in hints(&expected, text, pos, &found) {
        diagnostic = diagnostic.with_hint(hint);
    }
    diagnostic
}

/// The first word of the line that opens the innermost block around `pos` (`sphere`,
/// `for`, `fn`), or "" at the top level.
fn enclosing_block_word(text: &str, pos: usize) -> &str {
    let mut depth = 0usize;
    for (i, c) in text.get(..pos).unwrap_or("").char_indices().rev() {
        match c {
            '}' => depth += 1,
            '{' if depth > 0 => depth -= 1,
            '{' => {
                let line_start = text[..i].rfind(['\n', ';', '}', '{']).map_or(0, |j| j + 1);
                return text[line_start..i]
                    .split(|c: char| !(c.is_alphanumeric() || c == '_'))
                    .find(|w| !w.is_empty())
                    .unwrap_or("");
            }
            _ => {}
        }
    }
    ""
}

/// Whether `word` names a property of some block.
fn is_property(word: &str) -> bool {
    crate::schema::Prop::ALL.iter().any(|p| p.name() == word)
}

/// The statement around `pos` so far: from the last `{`, `}`, `;` or new line before it.
fn statement_start(text: &str, pos: usize) -> usize {
    text.get(..pos)
        .unwrap_or("")
        .rfind(['{', '}', ';', '\n'])
        .map_or(0, |i| i + 1)
}

/// The syntax errors people make most, each said for what it is, at the place it is, with
/// the fix: `=` after a property's name (`radius = 1`), `;` after a property
/// (`radius 1;`), and a unit after a number (`640px`, `45deg`). `None` for anything else,
/// which the general message describes.
fn common_mistake(text: &str, pos: usize, found_len: usize, file: FileId) -> Option<Diagnostic> {
    let bytes = text.as_bytes();
    let found = text.get(pos..pos + found_len).unwrap_or("");
    // A unit glued to a number: letters right after a digit.
    if found.starts_with(|c: char| c.is_ascii_alphabetic())
        && pos > 0
        && bytes.get(pos - 1).is_some_and(u8::is_ascii_digit)
    {
        let number_start = text[..pos]
            .char_indices()
            .rev()
            .find(|&(_, c)| !(c.is_ascii_digit() || c == '.'))
            .map_or(0, |(i, c)| i + c.len_utf8());
        let number = &text[number_start..pos];
        let advice = match found {
            "px" | "pixels" => format!("sizes are in pixels already: write `{number}`"),
            "deg" | "degrees" | "d" => format!("angles are in degrees already: write `{number}`"),
            "rad" | "radians" => {
                "angles are in degrees: write the angle in degrees (45, not 0.785)".to_string()
            }
            _ => format!("write the number alone: `{number}`"),
        };
        return Some(
            Diagnostic::error(
                format!("`{found}` after the number `{number}`: numbers have no units"),
                Span::new(file, pos, pos + found_len),
            )
            .with_label("remove this")
            .with_hint(advice),
        );
    }
    // The statement before the error, which may have ended on an earlier line (pest
    // notices a missing `;` only at the next word).
    let end = text.get(..pos).unwrap_or("").trim_end().len();
    let start = statement_start(text, end);
    let statement = text.get(start..end).unwrap_or("");
    let first_word = statement
        .trim_start()
        .split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .next()
        .unwrap_or("");
    if !is_property(first_word) {
        return None;
    }
    let word_at = start + statement.find(first_word).unwrap_or(0);
    // `radius = 1`: pest read an assignment and wanted its `;`. Only in a block that
    // takes properties: in a loop's or a function's body it is an assignment.
    let after_word = &text[word_at + first_word.len()..end];
    let in_code_block = matches!(
        enclosing_block_word(text, word_at),
        "for" | "if" | "else" | "while" | "fn"
    );
    if let Some(equals) = after_word
        .trim_start()
        .strip_prefix('=')
        .filter(|_| !in_code_block)
    {
        if !equals.starts_with('=') {
            let at = word_at + first_word.len() + after_word.find('=').unwrap_or(0);
            let value = equals.trim();
            return Some(
                Diagnostic::error(
                    format!("`=` after the property `{first_word}`: a property takes its value without `=`"),
                    Span::new(file, at, at + 1),
                )
                .with_label("remove this")
                .with_hint(format!("write `{first_word} {value}`")),
            );
        }
    }
    // `radius 1;`: a property is not a statement that ends with `;`.
    if found == ";" {
        return Some(
            Diagnostic::error(
                format!("`;` after the property `{first_word}`: properties do not end with `;`"),
                Span::new(file, pos, pos + 1),
            )
            .with_label("remove this")
            .with_hint(
                "properties are separated by spaces or new lines; only `let`, `const` and \
                 `return` end with `;`",
            ),
        );
    }
    None
}

/// Advice for the mistakes people make most.
fn hints(expected: &Expected, text: &str, pos: usize, found: &str) -> Vec<String> {
    let mut hints = Vec::new();
    let next = text.get(pos..).unwrap_or("");
    let previous = previous_word(text, pos);
    if expected.punctuation.contains(&";") {
        hints.push("`let`, `const` and `return` end with `;`".to_string());
    }
    let starts_value = next.starts_with(|c: char| c.is_ascii_digit() || c == '<' || c == '-');
    let comma_before_property = crate::hints::comma_before_property(text.get(..pos).unwrap_or(""));
    if expected.punctuation.contains(&",") {
        if expected.in_vector {
            hints.push("vectors are written `<x, y, z>`, with commas".to_string());
        } else if let (Some((property, _)), true) = (comma_before_property, expected.statement) {
            hints.push(format!(
                "a comma separates the values of one property, not properties: remove the `,` before `{property}`"
            ));
        } else if expected.statement && starts_value && crate::hints::foreign(previous).is_some() {
            // `color rgb 0.9`: the advice for the foreign word below says what to write.
        } else if expected.statement && starts_value {
            hints.push(
                "a property takes one value; several values need commas between them".to_string(),
            );
        } else if !next.starts_with(')') {
            hints.push("separate values with commas".to_string());
        }
    }
    if expected.after_dot && found == "`.`" {
        hints.push("ranges such as `0..10` only go in `for` loops".to_string());
    }
    if next.starts_with('=') && !next.starts_with("==") && expected.operator {
        hints.push("to compare two values, write `==`".to_string());
    }
    let keyword = found.trim_matches('`');
    if expected.name
        && !expected.value
        && [
            "import", "const", "let", "fn", "for", "in", "if", "else", "return", "settings",
            "camera", "light", "material", "true", "false", "about", "open",
        ]
        .contains(&keyword)
    {
        hints.push(format!(
            "`{keyword}` is a keyword, so it cannot be used as a name"
        ));
    }
    if expected.name && previous == "camera" {
        hints.push(
            "a camera is `camera perspective { ... }` or `camera orthographic { ... }`".into(),
        );
    }
    if expected.name && previous == "light" {
        hints.push(
            "a light is `light point`, `light directional` or `light spot`, then `{ ... }`".into(),
        );
    }
    hints.extend(crate::hints::syntax(text, pos));
    hints
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn previous_word_copes_with_wide_characters() {
        assert_eq!(previous_word("sphere →radius ", 17), "radius");
        assert_eq!(previous_word("é", 2), "é");
        assert_eq!(previous_word("→", 3), "");
    }

    #[test]
    fn found_tokens_are_whole_words_numbers_or_operators() {
        assert_eq!(found_token("radius 1", 0), ("`radius`".to_string(), 6));
        assert_eq!(found_token("0..10", 0), ("the number `0`".to_string(), 1));
        assert_eq!(found_token("2.5e3", 0).1, 3);
        assert_eq!(found_token("== 1", 0), ("`==`".to_string(), 2));
        assert_eq!(found_token("", 0), ("the end of the file".to_string(), 0));
        assert_eq!(found_token("日本", 0).1, "日本".len());
    }
}
