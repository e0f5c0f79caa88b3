//! Drawing: the whole screen as a function of the [`App`] (`impl Widget for &App`). Each pane
//! has its own module; none of them changes state.

mod errors_pane;
pub mod format;
mod help;
mod image_pane;
mod inspector;
#[cfg(test)]
mod snapshot_tests;
mod source_pane;
mod status;
mod tree_pane;
mod what_if_popup;

use ratatui::buffer::Buffer;
use ratatui::layout::{Alignment, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Widget, Wrap};

use crate::app::App;
use crate::layout::{self, MIN_HEIGHT, MIN_WIDTH};

impl Widget for &App {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let Some(panes) = layout::panes(area, self.image_size(), self.errors.is_some()) else {
            too_small(area, buf);
            return;
        };
        image_pane::draw(self, panes.image, buf);
        tree_pane::draw(self, panes.tree, buf);
        inspector::draw(self, panes.inspector, buf);
        match &self.errors {
            Some(errors) => errors_pane::draw(errors, panes.source, buf),
            None => source_pane::draw(self, panes.source, buf),
        }
        status::draw(self, panes.status, buf);
        if let Some(what_if) = &self.what_if {
            what_if_popup::draw(what_if, self.color_depth, area, buf);
        }
        if self.help_open {
            help::draw(area, buf);
        }
    }
}

/// A pane's frame: its title, highlighted when the pane has the keyboard.
fn pane_block(title: Line<'static>, focused: bool) -> Block<'static> {
    let border = if focused {
        Style::new().fg(Color::Yellow).add_modifier(Modifier::BOLD)
    } else {
        Style::new().fg(Color::DarkGray)
    };
    Block::bordered()
        .border_style(border)
        .title(title)
        .title_style(Style::new().fg(Color::Reset).add_modifier(Modifier::BOLD))
}

/// Said instead of drawing a layout that cannot fit.
fn too_small(area: Rect, buf: &mut Buffer) {
    let lines = vec![
        Line::from(Span::styled(
            "Terminal too small",
            Style::new().add_modifier(Modifier::BOLD),
        )),
        Line::from(format!(
            "{}×{} here; whitted debug needs at least {MIN_WIDTH}×{MIN_HEIGHT}.",
            area.width, area.height
        )),
        Line::from("Enlarge the window, or press q to quit."),
    ];
    let height = (lines.len() as u16).min(area.height);
    let top = area.y + area.height.saturating_sub(height) / 2;
    Paragraph::new(lines)
        .alignment(Alignment::Center)
        .wrap(Wrap { trim: true })
        .render(
            Rect::new(area.x, top, area.width, area.height - (top - area.y)),
            buf,
        );
}
