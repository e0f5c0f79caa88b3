//! The `?` overlay: every key in one table (pane, keys, what they do), centred over the
//! screen. It fits the smallest terminal the layout accepts.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Widget};

use crate::action::KEY_HELP;

const SECTION_WIDTH: usize = 10;
const KEY_WIDTH: usize = 18;

pub fn draw(area: Rect, buf: &mut Buffer) {
    let lines = help_lines();
    let content_width = lines.iter().map(Line::width).max().unwrap_or(0) as u16;
    let width = (content_width + 4).min(area.width);
    let height = (lines.len() as u16 + 2).min(area.height);
    let popup = Rect::new(
        area.x + (area.width - width) / 2,
        area.y + (area.height - height) / 2,
        width,
        height,
    );
    Clear.render(popup, buf);
    let block = Block::bordered()
        .border_style(Style::new().fg(Color::Yellow))
        .title(" Keys · any key closes ");
    let inner = block.inner(popup);
    block.render(popup, buf);
    let padded = Rect::new(
        inner.x + 1,
        inner.y,
        inner.width.saturating_sub(1),
        inner.height,
    );
    Paragraph::new(lines).render(padded, buf);
}

/// One line per key; the pane's name only on the first line of its group.
pub fn help_lines() -> Vec<Line<'static>> {
    let mut lines = Vec::new();
    let mut section = "";
    for &(name, keys, what) in KEY_HELP {
        let shown = if name == section { "" } else { name };
        section = name;
        lines.push(Line::from(vec![
            Span::styled(
                format!("{shown:<SECTION_WIDTH$}"),
                Style::new().add_modifier(Modifier::BOLD),
            ),
            Span::styled(
                format!("{keys:<KEY_WIDTH$}"),
                Style::new().fg(Color::Yellow),
            ),
            Span::raw(what),
        ]));
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::{MIN_HEIGHT, MIN_WIDTH};

    #[test]
    fn the_help_fits_the_smallest_layout() {
        let lines = help_lines();
        let width = lines.iter().map(Line::width).max().unwrap() + 4;
        assert!(width <= usize::from(MIN_WIDTH), "{width}");
        assert!(
            lines.len() + 2 <= usize::from(MIN_HEIGHT),
            "{}",
            lines.len()
        );
    }
}
