//! Semantic tokens for a whole document: the compiler's classes (`editor::view::highlight`,
//! read by the formatter's tokenizer, so a file that does not parse is highlighted as far
//! as it lexes) in the protocol's relative encoding, columns in UTF-16 units, a token that
//! spans lines (a block comment, a string) cut at each line break.

use lsp_types::{
    SemanticToken, SemanticTokenModifier, SemanticTokenType, SemanticTokens,
    SemanticTokensFullOptions, SemanticTokensLegend, SemanticTokensOptions,
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

/// The capability: the legend, whole documents only.
pub fn options() -> SemanticTokensOptions {
    SemanticTokensOptions {
        legend: SemanticTokensLegend {
            token_types: TYPES.to_vec(),
            token_modifiers: vec![SemanticTokenModifier::DEFINITION],
        },
        full: Some(SemanticTokensFullOptions::Bool(true)),
        range: None,
        ..SemanticTokensOptions::default()
    }
}

/// Every token of the document, encoded.
pub fn tokens(document: &Document) -> SemanticTokens {
    let text = &document.text;
    let mut data = Vec::new();
    let (mut line, mut column) = (0u32, 0u32);
    for token in highlight(text) {
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
            if length > 0 {
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
}
