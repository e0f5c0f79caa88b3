//! What an editor draws over the text: each token's class for highlighting (read by the
//! formatter's tokenizer, so it works on text that does not parse), the brace pairs that
//! fold, and the colour literals written for colour-valued properties.
//!
//! Classes come from the words themselves and the few tokens around them (`fn name`,
//! `let name`, `material name {`, a word before `(`), as the grammar writes them, so a
//! half-typed file is highlighted as far as it can be lexed.

use std::ops::Range;

use crate::format::tokens::{self, Kind as TokenKind, Role, Roles, Token};
use crate::properties::Prop;
use crate::schema::{CameraTag, LightTag, ObjectTag};

use super::{BlockKind, Index};

/// A token's class, as an editor colours it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    Keyword,
    /// An object, light or camera kind: `sphere`, `point`, `perspective`.
    Type,
    Property,
    Variable,
    Function,
    Parameter,
    Number,
    String,
    Comment,
    Operator,
}

/// One highlighted token: its bytes in the text, its class, and whether it is where a name
/// is defined (`fn ring`, `let n`, `material glass {`, a parameter).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Highlight {
    pub range: Range<usize>,
    pub class: Class,
    pub definition: bool,
}

/// The grammar's keywords (`grammar/scene.pest`, `keyword`).
const KEYWORDS: &[&str] = &[
    "import", "const", "let", "fn", "for", "in", "step", "while", "if", "else", "return",
    "settings", "camera", "light", "material", "true", "false",
];

/// Operators of two or three characters, which the tokenizer (without a syntax tree to
/// tell it) splits.
const LONG_OPERATORS: &[&str] = &["==", "!=", "<=", ">=", "&&", "||"];

fn text_of<'t>(text: &'t str, token: &Token) -> &'t str {
    text.get(token.start as usize..token.end as usize)
        .unwrap_or_default()
}

/// The tokens of `text`, comments included, whether or not it parses.
fn lex(text: &str) -> Vec<Token> {
    tokens::tokenize(text, &Roles::default())
}

/// Every token of `text` an editor colours, in order. Brackets and separators get none.
pub fn highlight(text: &str) -> Vec<Highlight> {
    let tokens = lex(text);
    let code: Vec<&Token> = tokens.iter().filter(|t| !t.is_comment()).collect();
    let word = |k: usize| code.get(k).map(|t| text_of(text, t));
    let mut out = Vec::with_capacity(tokens.len());
    let mut comments = tokens.iter().filter(|t| t.is_comment()).peekable();
    // Parameters of the function being read: its body's brace depth and their names.
    let mut depth = 0usize;
    let mut function: Option<(usize, Vec<&str>)> = None;
    // Inside a function's parameter list: the depth of its parentheses.
    let mut params: Option<usize> = None;
    let mut after_fn_name = false;
    let mut k = 0;
    while k < code.len() {
        let token = code[k];
        while let Some(comment) = comments.next_if(|c| c.start < token.start) {
            out.push(plain(comment, Class::Comment));
        }
        let s = text_of(text, token);
        let previous = k.checked_sub(1).and_then(word);
        let next = word(k + 1);
        match token.kind {
            TokenKind::Number | TokenKind::Hex => out.push(plain(token, Class::Number)),
            TokenKind::Str => out.push(plain(token, Class::String)),
            TokenKind::LineComment | TokenKind::BlockComment => {}
            TokenKind::Punct => {
                match s {
                    "{" => depth += 1,
                    "}" => {
                        depth = depth.saturating_sub(1);
                        if function.as_ref().is_some_and(|(d, _)| depth < *d) {
                            function = None;
                        }
                    }
                    "(" if after_fn_name => {
                        params = Some(0);
                        after_fn_name = false;
                    }
                    "(" => params = params.map(|p| p + 1),
                    ")" => {
                        params = match params {
                            Some(0) | None => None,
                            Some(p) => Some(p - 1),
                        }
                    }
                    _ => {}
                }
                if s == "{" && after_fn_name {
                    after_fn_name = false;
                }
                if s == "{" {
                    if let Some((d, _)) = function.as_mut().filter(|(d, _)| *d == 0) {
                        *d = depth;
                    }
                }
                let glued = code.get(k + 1).filter(|n| {
                    n.start == token.end
                        && n.kind == TokenKind::Punct
                        && LONG_OPERATORS.contains(&&text[token.start as usize..n.end as usize])
                });
                if let Some(n) = glued {
                    out.push(Highlight {
                        range: token.start as usize..n.end as usize,
                        class: Class::Operator,
                        definition: false,
                    });
                    k += 2;
                    continue;
                }
                let bracket = matches!(s, "{" | "}" | "(" | ")" | "[" | "]" | "," | ";" | ":")
                    || matches!(token.role, Role::VectorOpen | Role::VectorClose);
                if !bracket {
                    out.push(plain(token, Class::Operator));
                }
            }
            TokenKind::Word => {
                let (class, definition) = if KEYWORDS.contains(&s) {
                    (Class::Keyword, false)
                } else if previous == Some("fn") {
                    after_fn_name = true;
                    function = Some((0, Vec::new()));
                    (Class::Function, true)
                } else if params == Some(0) && matches!(previous, Some("(" | ",")) {
                    if let Some((_, names)) = function.as_mut() {
                        names.push(s);
                    }
                    (Class::Parameter, true)
                } else if matches!(previous, Some("let" | "const" | "for"))
                    || previous == Some("material") && next == Some("{")
                {
                    (Class::Variable, true)
                } else if previous == Some("light") && LightTag::ALL.iter().any(|t| t.name() == s)
                    || previous == Some("camera") && CameraTag::ALL.iter().any(|t| t.name() == s)
                    || ObjectTag::from_name(s).is_some() && previous != Some("material")
                {
                    (Class::Type, false)
                } else if next == Some("(") {
                    (Class::Function, false)
                } else if function
                    .as_ref()
                    .is_some_and(|(d, names)| *d > 0 && names.contains(&s))
                {
                    (Class::Parameter, false)
                } else if previous != Some("material") && is_property(s) {
                    (Class::Property, false)
                } else if is_word_value(s) {
                    (Class::Keyword, false)
                } else {
                    (Class::Variable, false)
                };
                out.push(Highlight {
                    range: token.start as usize..token.end as usize,
                    class,
                    definition,
                });
            }
        }
        k += 1;
    }
    out.extend(comments.map(|c| plain(c, Class::Comment)));
    out
}

fn plain(token: &Token, class: Class) -> Highlight {
    Highlight {
        range: token.start as usize..token.end as usize,
        class,
        definition: false,
    }
}

fn is_property(word: &str) -> bool {
    Prop::ALL.iter().any(|p| p.name() == word)
}

/// A word some property takes as its value (`filtered`, `opaque`).
fn is_word_value(word: &str) -> bool {
    Prop::ALL
        .iter()
        .filter_map(|p| p.words())
        .any(|words| words.contains(&word))
}

/// Every `{ ... }` of `text` (outside strings and comments) with its `}`: byte offsets of
/// the two braces. A brace left open has none.
pub fn brace_pairs(text: &str) -> Vec<(usize, usize)> {
    outline_parts(text).braces
}

/// What folds in a text: its brace pairs ([`brace_pairs`]) and its comments, from one
/// reading of its tokens.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct OutlineParts {
    pub braces: Vec<(usize, usize)>,
    /// Each comment's bytes, `//` and `/* */` alike, in text order.
    pub comments: Vec<Range<usize>>,
}

/// [`OutlineParts`] of `text`, read by the tokenizer alone (no highlighting).
pub fn outline_parts(text: &str) -> OutlineParts {
    let mut open = Vec::new();
    let mut parts = OutlineParts::default();
    for token in lex(text) {
        if token.is_comment() {
            parts
                .comments
                .push(token.start as usize..token.end as usize);
            continue;
        }
        match (token.kind, text_of(text, &token)) {
            (TokenKind::Punct, "{") => open.push(token.start as usize),
            (TokenKind::Punct, "}") => {
                if let Some(start) = open.pop() {
                    parts.braces.push((start, token.start as usize));
                }
            }
            _ => {}
        }
    }
    parts.braces.sort_unstable();
    parts
}

/// A colour written as a literal for a colour-valued property: `<r, g, b>` or
/// `rgb(r, g, b)`, the values as written (a light's may be above 1).
#[derive(Clone, Debug, PartialEq)]
pub struct ColorLiteral {
    /// From `<` to `>`, or from `rgb` to `)`.
    pub range: Range<usize>,
    pub rgb: [f64; 3],
}

/// The colour literals of `text` (file 0 of the compilation `index` was made from): the
/// value of each colour-valued property written in a block, when it is a literal.
pub fn colors(text: &str, index: &Index) -> Vec<ColorLiteral> {
    let tokens: Vec<Token> = lex(text).into_iter().filter(|t| !t.is_comment()).collect();
    let mut out = Vec::new();
    for block in index.blocks.iter().filter(|b| b.span.file.0 == 0) {
        for (name, span) in &block.properties {
            if !block.kind.takes_color(name) {
                continue;
            }
            let from = tokens.partition_point(|t| (t.start as usize) < span.range().end);
            if let Some(found) = color_at(text, &tokens[from.min(tokens.len())..]) {
                out.push(found);
            }
        }
    }
    out.sort_by_key(|c| c.range.start);
    out
}

/// The colour literal the tokens start with, if they do.
fn color_at(text: &str, tokens: &[Token]) -> Option<ColorLiteral> {
    let s = |k: usize| tokens.get(k).map(|t| text_of(text, t));
    let (open, close) = match s(0)? {
        "<" => (1, ">"),
        "rgb" if s(1) == Some("(") => (2, ")"),
        _ => return None,
    };
    let mut k = open;
    let mut rgb = [0.0; 3];
    for (n, value) in rgb.iter_mut().enumerate() {
        let negative = s(k) == Some("-");
        if negative {
            k += 1;
        }
        let token = tokens.get(k).filter(|t| t.kind == TokenKind::Number)?;
        let number: f64 = text_of(text, token).parse().ok()?;
        *value = if negative { -number } else { number };
        k += 1;
        let separator = if n < 2 { "," } else { close };
        if s(k)? != separator {
            return None;
        }
        k += 1;
    }
    // The literal must be the whole value, not the start of an expression.
    let after = tokens.get(k);
    if after.is_some_and(|t| t.kind == TokenKind::Punct && !matches!(text_of(text, t), "}" | ";")) {
        return None;
    }
    Some(ColorLiteral {
        range: tokens[0].start as usize..tokens[k - 1].end as usize,
        rgb,
    })
}

impl BlockKind {
    /// Whether the property `name` of this block takes a colour (a light's colour may be
    /// brighter than 1).
    pub fn takes_color(self, name: &str) -> bool {
        use crate::properties::Kind;
        let Some(prop) = self.0.property_named(name) else {
            return false;
        };
        crate::properties::ROWS.iter().any(|row| {
            row.prop == prop
                && crate::properties::row_accepts(row, self.0)
                && matches!(
                    row.kind,
                    Kind::Color | Kind::LightColor | Kind::ColorOrPattern
                )
        })
    }

    /// Whether this is the `settings` block.
    pub fn is_settings(self) -> bool {
        self.0 == crate::schema::Context::Settings
    }

    /// Whether this is a material's block.
    pub fn is_material(self) -> bool {
        self.0 == crate::schema::Context::Material
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each highlighted token as `text:class` (`*` marks a definition).
    fn classes(text: &str) -> Vec<String> {
        highlight(text)
            .into_iter()
            .map(|h| {
                let star = if h.definition { "*" } else { "" };
                format!("{}:{:?}{star}", &text[h.range], h.class)
            })
            .collect()
    }

    #[test]
    fn a_small_scene_is_classified_token_by_token() {
        let text = "// ring\nfn ring(n, r) {\n  for i in 0..n { sphere { radius r * 0.5 } }\n}\nmaterial glass { ior 1.5 }\nlet k = sin(2);\nsettings { shadows filtered }\nlight point { color #fff }\nring(k) { material glass }\n";
        assert_eq!(
            classes(text),
            [
                "// ring:Comment",
                "fn:Keyword",
                "ring:Function*",
                "n:Parameter*",
                "r:Parameter*",
                "for:Keyword",
                "i:Variable*",
                "in:Keyword",
                "0:Number",
                "..:Operator",
                "n:Parameter",
                "sphere:Type",
                "radius:Property",
                "r:Parameter",
                "*:Operator",
                "0.5:Number",
                "material:Keyword",
                "glass:Variable*",
                "ior:Property",
                "1.5:Number",
                "let:Keyword",
                "k:Variable*",
                "=:Operator",
                "sin:Function",
                "2:Number",
                "settings:Keyword",
                "shadows:Property",
                "filtered:Keyword",
                "light:Keyword",
                "point:Type",
                "color:Property",
                "#fff:Number",
                "ring:Function",
                "k:Variable",
                "material:Keyword",
                "glass:Variable",
            ]
        );
    }

    #[test]
    fn text_that_does_not_parse_is_still_highlighted() {
        let text = "sphere { radius = \"open /* x";
        assert_eq!(
            classes(text),
            [
                "sphere:Type",
                "radius:Property",
                "=:Operator",
                "\"open /* x:String"
            ]
        );
        assert_eq!(
            classes("a <= b /* open"),
            ["a:Variable", "<=:Operator", "b:Variable", "/* open:Comment"]
        );
    }

    #[test]
    fn braces_pair_outside_strings_and_comments() {
        let text = "a { \"}\" // }\n b { } } {";
        assert_eq!(brace_pairs(text), [(2, 20), (16, 18)]);
    }
}
