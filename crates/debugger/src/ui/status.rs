//! The status line: the scene, the latest message (or the render's progress), the cursor
//! pixel's colour and statistics, how long the tree took to record, and where help is.
//! When the line is too narrow, the least useful parts go first.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Widget;

use crate::app::{App, RenderState};
use crate::line_input::LineInput;

use super::format::{self, swatch};

/// A part of the status line; lower `rank` parts are dropped last.
struct Part {
    rank: u8,
    spans: Vec<Span<'static>>,
}

pub fn draw(app: &App, area: Rect, buf: &mut Buffer) {
    if draw_prompts(app, area, buf) {
        return;
    }
    let mut parts = Vec::new();
    parts.push(Part {
        rank: 4,
        spans: vec![Span::styled(
            app.scene_name.clone(),
            Style::new().add_modifier(Modifier::BOLD),
        )],
    });
    let news = match &app.message {
        Some(message) if message.is_error => Span::styled(
            message.text.clone(),
            Style::new()
                .fg(Color::LightRed)
                .add_modifier(Modifier::BOLD),
        ),
        Some(message) => Span::styled(message.text.clone(), Style::new().fg(Color::LightGreen)),
        None => Span::raw(render_state(app)),
    };
    parts.push(Part {
        rank: 0,
        spans: vec![news],
    });
    if app.message.is_some() && matches!(app.render, RenderState::Rendering { .. }) {
        parts.push(Part {
            rank: 2,
            spans: vec![Span::raw(render_state(app))],
        });
    }
    let (x, y) = app.cursor;
    let mut cursor = vec![Span::raw(format!("({x}, {y}) "))];
    match app.image.linear(x, y) {
        Some(color) => {
            cursor.push(swatch(color, app.color_depth));
            cursor.push(Span::raw(format!(" {}", format::rgb(color))));
        }
        None => cursor.push(Span::raw("not rendered yet")),
    }
    if let Some(map) = &app.heat_map {
        if let Some(value) = map.value(x, y) {
            cursor.push(Span::raw(format!(" · {} {value}", map.kind.title())));
        }
    }
    parts.push(Part {
        rank: 1,
        spans: cursor,
    });
    if let Some(run) = &app.query.running {
        let percent = (u64::from(run.rows_done) * 100)
            .checked_div(u64::from(run.rows))
            .unwrap_or(0);
        parts.push(Part {
            rank: 0,
            spans: vec![Span::styled(
                format!("query {percent}%, Esc cancels"),
                Style::new().fg(Color::Yellow),
            )],
        });
    } else if let Some(overlay) = &app.query.overlay {
        parts.push(Part {
            rank: 1,
            spans: vec![Span::styled(
                format!("{}: {} px", overlay.text, overlay.matches.len()),
                Style::new().fg(QUERY_COLOR),
            )],
        });
    }
    if let Some(tracing) = &app.tracing {
        let (x, y) = tracing.pixel;
        parts.push(Part {
            rank: 0,
            spans: vec![Span::styled(
                format!("tracing ({x}, {y}), Esc cancels"),
                Style::new().fg(Color::Yellow),
            )],
        });
    } else if let Some(picked) = &app.picked {
        parts.push(Part {
            rank: 3,
            spans: vec![Span::raw(match picked.on_screen_after {
                Some(shown) => format!(
                    "tree in {:.2} ms, on screen in {:.1} ms",
                    picked.trace_time.as_secs_f64() * 1000.0,
                    shown.as_secs_f64() * 1000.0
                ),
                None => format!("tree in {:.2} ms", picked.trace_time.as_secs_f64() * 1000.0),
            })],
        });
    }
    // Said even on the narrowest line: the other panes are hidden, and how to get them back.
    if app.zoomed {
        parts.push(Part {
            rank: 0,
            spans: vec![Span::styled(
                "zoomed: z back, Tab next",
                Style::new().fg(Color::Yellow),
            )],
        });
    }
    parts.push(Part {
        rank: 2,
        spans: vec![Span::styled("? help", Style::new().fg(Color::Yellow))],
    });
    fit(&mut parts, usize::from(area.width));
    let separator = Span::styled(" │ ", Style::new().fg(Color::DarkGray));
    let mut spans = vec![Span::raw(" ")];
    for (index, part) in parts.into_iter().enumerate() {
        if index > 0 {
            spans.push(separator.clone());
        }
        spans.extend(part.spans);
    }
    Line::from(spans).render(area, buf);
}

/// The colour the query's matches are marked in, here and over the image.
pub const QUERY_COLOR: Color = Color::Rgb(0, 230, 255);

/// The status line while a prompt is open: the search's (`/`) or the query's (`:`).
pub fn draw_prompts(app: &App, area: Rect, buf: &mut Buffer) -> bool {
    if let Some(prompt) = &app.search_prompt {
        let label = Span::styled(" search rays /", Style::new().fg(Color::Yellow));
        draw_prompt(label, prompt, "   Enter: find · Esc: cancel", area, buf);
    } else if let Some(prompt) = &app.query.prompt {
        let label = Span::styled(
            " query: ",
            Style::new().fg(QUERY_COLOR).add_modifier(Modifier::BOLD),
        );
        let hint = "   Enter runs it, Esc cancels; e.g. tir and not hit(\"floor\")";
        draw_prompt(label, prompt, hint, area, buf);
    } else {
        return false;
    }
    true
}

/// A prompt in place of the status line: its label, what is typed with the cursor as a
/// reversed cell, and a hint of what Enter and Esc do.
fn draw_prompt(label: Span<'static>, prompt: &LineInput, hint: &str, area: Rect, buf: &mut Buffer) {
    let text = prompt.text();
    let at = text
        .char_indices()
        .nth(prompt.cursor())
        .map_or(text.len(), |(i, _)| i);
    let (before, after) = text.split_at(at);
    let mut rest = after.chars();
    let under_cursor = rest.next().map_or(" ".to_string(), String::from);
    Line::from(vec![
        label,
        Span::raw(before.to_string()),
        Span::styled(under_cursor, Style::new().add_modifier(Modifier::REVERSED)),
        Span::raw(rest.as_str().to_string()),
        Span::styled(hint.to_string(), Style::new().fg(Color::DarkGray)),
    ])
    .render(area, buf);
}

/// Drops the highest-ranked parts until the line fits (the last part left is cut).
fn fit(parts: &mut Vec<Part>, width: usize) {
    let total = |parts: &[Part]| -> usize {
        1 + parts
            .iter()
            .map(|p| p.spans.iter().map(Span::width).sum::<usize>())
            .sum::<usize>()
            + 3 * parts.len().saturating_sub(1)
    };
    while parts.len() > 1 && total(parts) > width {
        let Some(worst) = parts
            .iter()
            .enumerate()
            .max_by_key(|(_, p)| p.rank)
            .map(|(i, _)| i)
        else {
            break;
        };
        parts.remove(worst);
    }
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
