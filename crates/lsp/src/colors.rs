//! Document colours: each `<r, g, b>` or `rgb(r, g, b)` literal written for a property the
//! property table says takes a colour (`editor::view::colors`), as a swatch clamped to 0..1
//! (a light's colour above 1 is an intensity); and the picker's choice written back as
//! `rgb(r, g, b)` with short decimals.

use lsp_types::{Color, ColorInformation, ColorPresentation, Range, TextEdit};

use crate::documents::Document;

/// The colours of the document's last analysis (none until it parses).
pub fn colors(document: &Document) -> Vec<ColorInformation> {
    let Some(index) = document.analysis.as_ref().and_then(|a| a.index.as_ref()) else {
        return Vec::new();
    };
    whitted_lang::editor::view::colors(&document.text, index)
        .into_iter()
        .map(|literal| {
            let [red, green, blue] = literal.rgb.map(|c| c.clamp(0.0, 1.0) as f32);
            ColorInformation {
                range: document.lines.range(&document.text, literal.range),
                color: Color {
                    red,
                    green,
                    blue,
                    alpha: 1.0,
                },
            }
        })
        .collect()
}

/// The one way to write a colour back: `rgb(…)` over the literal's range.
pub fn presentations(color: Color, range: Range) -> Vec<ColorPresentation> {
    let label = format!(
        "rgb({}, {}, {})",
        short(color.red),
        short(color.green),
        short(color.blue)
    );
    vec![ColorPresentation {
        text_edit: Some(TextEdit {
            range,
            new_text: label.clone(),
        }),
        label,
        additional_text_edits: None,
    }]
}

/// At most three decimals, trailing zeros dropped: `0.5`, `0.333`, `1`. Not-a-number (a
/// broken client) is written as 0 rather than as text the compiler refuses.
fn short(value: f32) -> String {
    let value = if value.is_finite() { value } else { 0.0 };
    let text = format!("{:.3}", value);
    let text = text.trim_end_matches('0').trim_end_matches('.');
    match text {
        "-0" | "" => "0".to_string(),
        _ => text.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lsp_types::Position;

    #[test]
    fn presentations_write_rgb_with_short_decimals() {
        let range = Range::new(Position::new(1, 2), Position::new(1, 9));
        let color = Color {
            red: 0.5,
            green: 1.0 / 3.0,
            blue: 1.0,
            alpha: 1.0,
        };
        let [presentation] = presentations(color, range).try_into().expect("one");
        assert_eq!(presentation.label, "rgb(0.5, 0.333, 1)");
        let edit = presentation.text_edit.expect("an edit");
        assert_eq!(edit.range, range);
        assert_eq!(edit.new_text, "rgb(0.5, 0.333, 1)");
        assert_eq!(short(0.0), "0");
        assert_eq!(short(-0.0001), "0");
        assert_eq!(short(f32::NAN), "0");
        assert_eq!(short(0.1), "0.1");
    }
}
