//! How numbers, vectors and colours read on screen: fixed decimals so columns line up, and
//! colour swatches (`██` in the colour itself) beside the numbers.

use ratatui::style::{Color, Style};
use ratatui::text::Span;

use crate::image::ColorDepth;
use whitted_tracer::display::linear_to_srgb8_rgb;

/// A number with three decimals; very large or small magnitudes in scientific notation so
/// that they never push a line off the pane.
pub fn number(value: f32) -> String {
    let magnitude = value.abs();
    if value == 0.0 {
        "0.000".to_string()
    } else if !(1e-3..1e5).contains(&magnitude) {
        format!("{value:.2e}")
    } else {
        format!("{value:.3}")
    }
}

/// `(x, y, z)` with three decimals each.
pub fn vector(v: [f32; 3]) -> String {
    format!("({}, {}, {})", number(v[0]), number(v[1]), number(v[2]))
}

/// `r g b` with three decimals each.
pub fn rgb(c: [f32; 3]) -> String {
    format!("{} {} {}", number(c[0]), number(c[1]), number(c[2]))
}

/// The terminal colour of a linear RGB value (clamped to what a display shows).
pub fn terminal_color(c: [f32; 3], depth: ColorDepth) -> Color {
    depth.color(linear_to_srgb8_rgb(c))
}

/// Two full blocks in the colour: the swatch shown before colour numbers.
pub fn swatch(c: [f32; 3], depth: ColorDepth) -> Span<'static> {
    Span::styled("██", Style::new().fg(terminal_color(c, depth)))
}

/// Component-wise product.
pub fn mul(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

pub fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn scale(a: [f32; 3], s: f32) -> [f32; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Shortens `text` to `width` characters, ending with `…` when cut.
pub fn truncate(text: &str, width: usize) -> String {
    if text.chars().count() <= width {
        return text.to_string();
    }
    if width == 0 {
        return String::new();
    }
    let mut out: String = text.chars().take(width - 1).collect();
    out.push('…');
    out
}

/// A popup of `width` x `height` (at most the area's) centred in `area`.
pub fn centered(area: ratatui::layout::Rect, width: u16, height: u16) -> ratatui::layout::Rect {
    let (width, height) = (width.min(area.width), height.min(area.height));
    ratatui::layout::Rect::new(
        area.x + (area.width - width) / 2,
        area.y + (area.height - height) / 2,
        width,
        height,
    )
}

/// `inner` less its first column: a popup's text starts one space in from its border.
pub fn left_padded(inner: ratatui::layout::Rect) -> ratatui::layout::Rect {
    ratatui::layout::Rect::new(
        inner.x + 1,
        inner.y,
        inner.width.saturating_sub(1),
        inner.height,
    )
}

/// `text` in lines of at most `width` characters, broken between words; a word longer than a
/// line is cut, and an empty text is one empty line (so a message always has a row).
pub fn wrap_words(text: &str, width: usize) -> Vec<String> {
    let width = width.max(1);
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let needed = line.chars().count() + usize::from(!line.is_empty()) + word.chars().count();
        if needed > width && !line.is_empty() {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
        while line.chars().count() > width {
            lines.push(line.chars().take(width).collect());
            line = line.chars().skip(width).collect();
        }
    }
    if !line.is_empty() || lines.is_empty() {
        lines.push(line);
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_three_decimals_and_a_bounded_width() {
        assert_eq!(number(0.0), "0.000");
        assert_eq!(number(-1.23456), "-1.235");
        assert_eq!(number(1e-5), "1.00e-5");
        assert_eq!(number(123456.0), "1.23e5");
        assert_eq!(vector([1.0, -2.0, 0.5]), "(1.000, -2.000, 0.500)");
        assert_eq!(rgb([0.25, 0.5, 1.0]), "0.250 0.500 1.000");
    }

    #[test]
    fn truncation_marks_the_cut() {
        assert_eq!(truncate("glass sphere", 20), "glass sphere");
        assert_eq!(truncate("glass sphere", 6), "glass…");
        assert_eq!(truncate("glass", 0), "");
    }

    #[test]
    fn wrapping_breaks_between_words_and_cuts_long_words() {
        assert_eq!(
            wrap_words("a light behind the surface", 10),
            ["a light", "behind the", "surface"]
        );
        assert_eq!(
            wrap_words("add `ior 1.3` inside material mirror", 16),
            ["add `ior 1.3`", "inside material", "mirror"]
        );
        assert_eq!(wrap_words("abcdefghij", 4), ["abcd", "efgh", "ij"]);
        assert_eq!(wrap_words("short", 16), ["short"]);
        assert_eq!(wrap_words("", 5), [""]);
    }
}
