//! The explanation pane (`x`, in the inspector's place): why the picked pixel has its
//! colour, from the explain library: each main contribution with its share and swatch, then
//! each finding with its `file:line:col` and message. The selected entry is highlighted;
//! Enter goes to its ray or line (`update.rs`).

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget, Wrap};
use whitted_explain::contributions::describe_path;
use whitted_explain::{describe_term, Explanation};

use crate::action::Focus;
use crate::app::{App, ExplanationState};
use crate::explain::state::{entries, Entry};
use crate::image::ColorDepth;

use crate::ui::format::{self, swatch, wrap_words};
use crate::ui::pane_block;

pub fn draw(app: &App, pane: Rect, buf: &mut Buffer) {
    let focused = app.focus == Focus::Inspector;
    let state = app.picked.as_ref().map(|p| &p.explanation);
    let Some(ExplanationState::Ready(explanation)) = state else {
        let note = match state {
            None => "Pick a pixel (Enter) to see why it has its colour.".to_string(),
            Some(ExplanationState::Failed(message)) => {
                format!("The explanation failed (a bug in whitted): {message}")
            }
            Some(_) => "Working out why the pixel has its colour…".to_string(),
        };
        Paragraph::new(vec![
            Line::from(note),
            Line::from(""),
            Line::from("x: inspector"),
        ])
        .style(Style::new().fg(Color::Gray))
        .wrap(Wrap { trim: true })
        .block(pane_block(Line::from(" Explanation "), focused))
        .render(pane, buf);
        return;
    };
    let [x, y] = explanation.pixel;
    let long = format!(" Explanation of ({x}, {y}) · Enter: go to · x: inspector ");
    let title = if long.chars().count() + 2 <= usize::from(pane.width) {
        long
    } else {
        " Explanation · Enter: go to ".to_string()
    };
    let block = pane_block(Line::from(title), focused);
    let area = block.inner(pane);
    block.render(pane, buf);

    let selected = app.explain_selected;
    let rows = rows(
        explanation,
        selected,
        usize::from(area.width),
        app.color_depth,
    );
    let first = rows.iter().position(|r| r.entry == Some(selected));
    let last = rows.iter().rposition(|r| r.entry == Some(selected));
    let height = usize::from(area.height);
    // Scroll just enough that the selected entry shows whole (its first line if it is
    // taller than the pane); the headings above the first entries show when there is room.
    let scroll = match (first, last) {
        (Some(first), Some(last)) => (last + 1).saturating_sub(height).min(first),
        _ => 0,
    };
    let scroll = if first.is_some_and(|f| f <= 1) {
        0
    } else {
        scroll
    };
    for (row, line) in rows.into_iter().skip(scroll).take(height).enumerate() {
        let row_area = Rect::new(area.x, area.y + row as u16, area.width, 1);
        if line.entry == Some(selected) {
            let style = if focused {
                Style::new().add_modifier(Modifier::REVERSED)
            } else {
                Style::new().bg(Color::DarkGray)
            };
            buf.set_style(row_area, style);
        }
        line.line.render(row_area, buf);
    }
}

/// One screen row, and the entry it belongs to (`None` for headings).
struct Row {
    entry: Option<usize>,
    line: Line<'static>,
}

/// Every row, in `width` columns: a heading, one row per contribution, a heading, then
/// each finding as its kind and location over its message, wrapped.
fn rows(explanation: &Explanation, selected: usize, width: usize, depth: ColorDepth) -> Vec<Row> {
    // The selected entry's first row starts with a marker (the highlight aside), so that
    // it reads without colour too.
    let marker = |index: usize| if index == selected { "▸" } else { " " };
    let heading = Style::new().fg(Color::Cyan).add_modifier(Modifier::BOLD);
    let mut rows = vec![Row {
        entry: None,
        line: Line::from(vec![
            Span::styled("Contributions", heading),
            Span::raw(" "),
            swatch(explanation.color, depth),
            Span::raw(format!(" {}", format::rgb(explanation.color))),
        ]),
    }];
    if explanation.contributions.is_empty() {
        rows.push(Row {
            entry: None,
            line: Line::styled(
                " no recorded path brings light",
                Style::new().fg(Color::Gray),
            ),
        });
    }
    let mut findings_heading = false;
    for (index, entry) in entries(explanation).into_iter().enumerate() {
        match entry {
            Entry::Contribution(c) => {
                let share = c
                    .share
                    .map_or("      ".to_string(), |s| format!("{:5.1}%", s * 100.0));
                let path = describe_path(&c.path);
                let words = if path.is_empty() {
                    describe_term(c)
                } else {
                    format!("{}: {path}", describe_term(c))
                };
                let used = share.chars().count() + 5;
                rows.push(Row {
                    entry: Some(index),
                    line: Line::from(vec![
                        Span::raw(format!("{}{share} ", marker(index))),
                        swatch(c.color, depth),
                        Span::raw(" "),
                        Span::raw(format::truncate(&words, width.saturating_sub(used))),
                    ]),
                });
            }
            Entry::Finding(f) => {
                if !findings_heading {
                    findings_heading = true;
                    rows.push(Row {
                        entry: None,
                        line: Line::styled("Findings", heading),
                    });
                }
                let place = format!(" {}", f.location);
                rows.push(Row {
                    entry: Some(index),
                    line: Line::from(vec![
                        Span::raw(marker(index)),
                        Span::styled(f.kind.name(), Style::new().fg(Color::Yellow)),
                        Span::styled(
                            format::truncate(&place, width.saturating_sub(f.kind.name().len() + 1)),
                            Style::new().fg(Color::Gray),
                        ),
                    ]),
                });
                for text in wrap_words(&f.message, width.saturating_sub(3)) {
                    rows.push(Row {
                        entry: Some(index),
                        line: Line::from(format!("   {text}")),
                    });
                }
            }
        }
    }
    if !findings_heading {
        rows.push(Row {
            entry: None,
            line: Line::styled("No findings", heading),
        });
    }
    rows
}
