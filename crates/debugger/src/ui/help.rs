//! The `?` overlay: every key in one table (pane, keys, what they do), centred over the
//! screen; ↑↓ scroll it when the terminal is shorter than the table.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Widget};

use crate::action::KEY_HELP;

const SECTION_WIDTH: usize = 10;
const KEY_WIDTH: usize = 18;

pub fn draw(area: Rect, scroll: u16, buf: &mut Buffer) {
    let lines = help_lines();
    let content_width = lines.iter().map(Line::width).max().unwrap_or(0) as u16;
    let width = (content_width + 4).min(area.width);
    let height = (lines.len() as u16 + 2).min(area.height);
    let popup = super::format::centered(area, width, height);
    Clear.render(popup, buf);
    let inner_rows = height.saturating_sub(2);
    let hidden = (lines.len() as u16).saturating_sub(inner_rows);
    let scroll = scroll.min(hidden);
    let title = if hidden > 0 {
        " Keys · ↑↓ scroll · other keys close "
    } else {
        " Keys · any key closes "
    };
    let block = Block::bordered()
        .border_style(Style::new().fg(Color::Yellow))
        .title(title);
    let inner = block.inner(popup);
    block.render(popup, buf);
    let padded = super::format::left_padded(inner);
    Paragraph::new(lines)
        .scroll((scroll, 0))
        .render(padded, buf);
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
    fn the_help_fits_the_smallest_layout_in_width_and_scrolls_in_height() {
        let lines = help_lines();
        let width = lines.iter().map(Line::width).max().unwrap() + 4;
        assert!(width <= usize::from(MIN_WIDTH), "{width}");
        let area = Rect::new(0, 0, MIN_WIDTH, MIN_HEIGHT);
        let text = |scroll| {
            let mut buf = Buffer::empty(area);
            draw(area, scroll, &mut buf);
            (0..area.height)
                .map(|y| {
                    (0..area.width)
                        .map(|x| buf[(x, y)].symbol().to_string())
                        .collect::<String>()
                })
                .collect::<Vec<_>>()
                .join("\n")
        };
        let last = KEY_HELP.last().unwrap().2;
        if lines.len() + 2 > usize::from(MIN_HEIGHT) {
            assert!(!text(0).contains(last));
            assert!(text(100).contains(last), "scrolled to the end");
        } else {
            assert!(text(0).contains(last));
        }
        assert!(text(0).contains(KEY_HELP[0].2));
    }
}
