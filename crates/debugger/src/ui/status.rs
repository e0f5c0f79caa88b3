//! The status line: the scene, the latest message (or the render's progress), the cursor
//! pixel's colour and statistics, how long the tree took to record, and where help is.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Widget;

use crate::app::{App, RenderState};

use super::format::{self, swatch};

pub fn draw(app: &App, area: Rect, buf: &mut Buffer) {
    let separator = || Span::styled(" │ ", Style::new().fg(Color::DarkGray));
    let mut spans = vec![Span::styled(
        format!(" {}", app.scene_name),
        Style::new().add_modifier(Modifier::BOLD),
    )];
    spans.push(separator());
    match &app.message {
        Some(message) if message.is_error => spans.push(Span::styled(
            message.text.clone(),
            Style::new().fg(Color::LightRed).add_modifier(Modifier::BOLD),
        )),
        Some(message) => spans.push(Span::styled(
            message.text.clone(),
            Style::new().fg(Color::LightGreen),
        )),
        None => spans.push(Span::raw(render_state(app))),
    }
    spans.push(separator());
    let (x, y) = app.cursor;
    spans.push(Span::raw(format!("({x}, {y}) ")));
    match app.image.linear(x, y) {
        Some(color) => {
            spans.push(swatch(color, app.color_depth));
            spans.push(Span::raw(format!(" {}", format::rgb(color))));
        }
        None => spans.push(Span::raw("not rendered yet")),
    }
    if let Some(map) = &app.heat_map {
        if let Some(value) = map.value(x, y) {
            spans.push(Span::raw(format!(" · {} {value}", map.kind.title())));
        }
    }
    if let Some(picked) = &app.picked {
        spans.push(separator());
        spans.push(Span::raw(format!(
            "tree recorded in {:.2} ms",
            picked.trace_time.as_secs_f64() * 1000.0
        )));
    }
    spans.push(separator());
    spans.push(Span::styled("? help", Style::new().fg(Color::Yellow)));
    Line::from(spans).render(area, buf);
}

fn render_state(app: &App) -> String {
    let (width, height) = app.image_size();
    if app.reloading {
        return "reloading".to_string();
    }
    match &app.render {
        RenderState::Rendering { pixels, .. } => {
            let total = u64::from(width) * u64::from(height);
            format!(
                "rendering {}%",
                (pixels * 100).checked_div(total).unwrap_or(0)
            )
        }
        RenderState::Done { stats } => format!(
            "rendered in {:.2} s, {:.2} M rays",
            stats.render_seconds,
            stats.total_rays() as f64 / 1e6
        ),
        RenderState::Stopped => "not rendering".to_string(),
    }
}
