//! The image pane: the render (or a heat map) in half-blocks, the cursor pixel and the
//! selected ray's hit point marked, and arrows on the border that point at the cursor.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Widget;

use crate::app::{App, RenderState, View};
use crate::hit_point::{hit_point_view, HitPointView};
use crate::image::{draw_image, PixelSource, Viewport};
use crate::layout::inner;

use crate::query_job::QueryOverlay;
use crate::ui::pane_block;
use crate::ui::status::QUERY_COLOR;

const CURSOR_COLOR: Color = Color::Rgb(255, 0, 255);
const HIT_POINT_COLOR: Color = Color::Rgb(0, 255, 128);

pub fn draw(app: &App, pane: Rect, buf: &mut Buffer) {
    let (width, height) = app.image_size();
    let viewport = app.viewport();
    let zoom = match app.view {
        View::Fit => "fit".to_string(),
        View::Manual(v) => {
            let fit = Viewport::fit(width, height, inner(pane));
            format!("zoom {:.1}×", fit.scale / v.scale)
        }
    };
    let mut title = vec![Span::raw(format!(" Image {width}×{height} · {zoom} "))];
    if let Some(overlay) = &app.query.overlay {
        title.push(Span::styled(
            format!("· query: {} px ", overlay.matches.len()),
            Style::new().fg(QUERY_COLOR),
        ));
    }
    if let Some(kind) = app.overlay {
        let legend = match &app.heat_map {
            Some(map) => format!("· {} {}–{} ", kind.title(), map.min, map.max),
            None => format!("· {} (after the render) ", kind.title()),
        };
        title.push(Span::styled(legend, Style::new().fg(Color::LightRed)));
    }
    let mut block = pane_block(Line::from(title), app.focus == crate::action::Focus::Image);
    if let RenderState::Rendering { pixels, .. } = app.render {
        let total = u64::from(width) * u64::from(height);
        let percent = (pixels * 100).checked_div(total).unwrap_or(0);
        block = block.title_bottom(Line::from(format!(" rendering {percent}% ")).right_aligned());
    }
    let area = block.inner(pane);
    block.render(pane, buf);

    let base: &dyn PixelSource = match &app.heat_map {
        Some(map) if app.overlay.is_some() => map,
        _ => &app.image,
    };
    let tinted = app
        .query
        .overlay
        .as_ref()
        .map(|overlay| QueryTint { base, overlay });
    let source: &dyn PixelSource = match &tinted {
        Some(tinted) => tinted,
        None => base,
    };
    // Mark the pixel each marked cell samples, so the mark shows at any zoom.
    let sampled = |(x, y): (u32, u32)| -> Option<(u32, u32)> {
        let (column, half_row) = viewport.cell_of(x, y, area)?;
        viewport.pixel_at(column, half_row, width, height)
    };
    // The first mark of a pixel wins: the cursor over a hit point at the same place.
    let mut marked = Vec::new();
    if let Some(pixel) = sampled(app.cursor) {
        marked.push((pixel, CURSOR_COLOR));
    }
    if app.show_hit_point {
        if let Some(HitPointView::Shown(x, y)) = hit_point_view(app) {
            if let Some(pixel) = sampled((x, y)) {
                marked.push((pixel, HIT_POINT_COLOR));
            }
        }
    }
    draw_image(source, &viewport, app.color_depth, &marked, area, buf);
    draw_rulers(app, &viewport, pane, area, buf);
}

/// The picture with a query's matches marked: matching pixels tinted towards the query's
/// colour, the others dimmed, so that the matches stand out whatever the picture.
struct QueryTint<'a> {
    base: &'a dyn PixelSource,
    overlay: &'a QueryOverlay,
}

impl PixelSource for QueryTint<'_> {
    fn size(&self) -> (u32, u32) {
        self.base.size()
    }

    fn srgb(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        let pixel = self.base.srgb(x, y)?;
        Some(if self.overlay.matches_pixel(x, y) {
            let tint = [0u16, 230, 255];
            std::array::from_fn(|i| ((u16::from(pixel[i]) + tint[i]) / 2) as u8)
        } else {
            pixel.map(|c| (u16::from(c) * 2 / 5) as u8)
        })
    }
}

/// Arrows on the bottom and left borders in line with the cursor, so it can be found at a
/// glance in a busy picture (the top border carries the title).
fn draw_rulers(app: &App, viewport: &Viewport, pane: Rect, area: Rect, buf: &mut Buffer) {
    let Some((column, half_row)) = viewport.cell_of(app.cursor.0, app.cursor.1, area) else {
        return;
    };
    let style = Style::new().fg(CURSOR_COLOR).add_modifier(Modifier::BOLD);
    let row = u16::try_from(half_row / 2).unwrap_or(u16::MAX);
    let bottom = pane.y + pane.height.saturating_sub(1);
    if let Some(cell) = buf.cell_mut((area.x + column, bottom)) {
        cell.set_symbol("▲").set_style(style);
    }
    if let Some(cell) = buf.cell_mut((pane.x, area.y.saturating_add(row))) {
        cell.set_symbol("▶").set_style(style);
    }
}
