//! Drawing: the whole screen as a function of the [`App`] (`impl Widget for &App`). Each pane
//! has its own module (the ray tree's, the 3D ray view's and the explanation's are `draw.rs`
//! in their feature's folder: `tree/`, `ray_view/`, `explain/`); none of them changes state.

pub(crate) mod braille;
mod errors_pane;
pub mod format;
mod help;

mod inspector;
#[cfg(test)]
mod snapshot_tests;
pub(crate) mod source_pane;
pub(crate) mod status;

use ratatui::buffer::Buffer;
use ratatui::layout::{Alignment, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, BorderType, Paragraph, Widget, Wrap};

use crate::app::App;
use crate::layout::{self, MIN_HEIGHT, MIN_WIDTH};

impl Widget for &App {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let Some(panes) = layout::panes(area, self.image_size(), self.arrangement()) else {
            too_small(area, buf);
            return;
        };
        // Zoomed, the panes other than the focused one are empty: not drawn.
        if !panes.image.is_empty() {
            match &self.ray_view {
                Some(view) => crate::ray_view::draw::draw(self, view, panes.image, buf),
                None => crate::image::draw::draw(self, panes.image, buf),
            }
        }
        if !panes.tree.is_empty() {
            crate::tree::draw::draw(self, panes.tree, buf);
        }
        if !panes.inspector.is_empty() {
            if self.explain_open {
                crate::explain::draw::draw(self, panes.inspector, buf);
            } else {
                inspector::draw(self, panes.inspector, buf);
            }
        }
        if !panes.source.is_empty() {
            match &self.errors {
                Some(errors) => errors_pane::draw(errors, panes.source, buf),
                None => source_pane::draw(self, panes.source, buf),
            }
        }
        status::draw(self, panes.status, buf);
        if let Some(what_if) = &self.what_if {
            crate::what_if::draw::draw(what_if, self.color_depth, area, buf);
        }
        if self.help_open {
            help::draw(area, self.help_scroll, buf);
        }
    }
}

/// A pane's frame and title. The pane with the keyboard has a thick yellow border and its
/// title in black on yellow, so it stands out even in a 16-colour or monochrome terminal
/// (the border's shape differs, not only its colour).
pub(crate) fn pane_block(title: Line<'static>, focused: bool) -> Block<'static> {
    if focused {
        Block::bordered()
            .border_type(BorderType::Thick)
            .border_style(Style::new().fg(Color::Yellow).add_modifier(Modifier::BOLD))
            .title(title)
            .title_style(
                Style::new()
                    .fg(Color::Black)
                    .bg(Color::Yellow)
                    .add_modifier(Modifier::BOLD),
            )
    } else {
        Block::bordered()
            .border_style(Style::new().fg(Color::DarkGray))
            .title(title)
            .title_style(Style::new().fg(Color::Reset).add_modifier(Modifier::BOLD))
    }
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
