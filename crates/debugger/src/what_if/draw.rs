//! The what-if popup (`w`): the values that can change with their current values, the one
//! being typed, then the old and new colour of the pixel side by side and the tree diff
//! (rays removed, added and changed, with what they give the pixel before and after).

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Widget};
use whitted_explain::diff::{Change, RayChange};

use crate::image::ColorDepth;
use crate::what_if::state::WhatIf;

use crate::ui::format::{number, rgb, swatch, wrap_words};

const KEY_STYLE: Style = Style::new().fg(Color::Yellow);

pub fn draw(what_if: &WhatIf, depth: ColorDepth, area: Rect, buf: &mut Buffer) {
    let width = area.width.saturating_sub(4).min(100);
    let height = area.height.saturating_sub(2);
    let popup = crate::ui::format::centered(area, width, height);
    Clear.render(popup, buf);
    let (x, y) = what_if.pixel;
    let block = Block::bordered()
        .border_style(Style::new().fg(Color::Yellow))
        .title(format!(" What if · pixel ({x}, {y}) "))
        .title_bottom(
            Line::from(vec![
                Span::styled(" ↑↓", KEY_STYLE),
                Span::raw(" choose "),
                Span::styled("Enter", KEY_STYLE),
                Span::raw(" change "),
                Span::styled("W", KEY_STYLE),
                Span::raw(" write to the file "),
                Span::styled("Esc", KEY_STYLE),
                Span::raw(" close "),
            ])
            .right_aligned(),
        );
    let inner = block.inner(popup);
    block.render(popup, buf);
    let inner = crate::ui::format::left_padded(inner);
    let lines = lines(what_if, depth, inner.width, usize::from(inner.height));
    Paragraph::new(lines).render(inner, buf);
}

/// Everything the popup says in `width` columns, cut to `rows` (the diff gives way first).
pub fn lines(what_if: &WhatIf, depth: ColorDepth, width: u16, rows: usize) -> Vec<Line<'static>> {
    let scene = &what_if.base.scene;
    let mut lines = Vec::new();
    let owner_width = what_if
        .params
        .iter()
        .map(|p| p.owner(scene).chars().count())
        .max()
        .unwrap_or(0);
    for (index, param) in what_if.params.iter().enumerate() {
        let selected = index == what_if.selected;
        let marker = if selected { "▶ " } else { "  " };
        let mut spans = vec![
            Span::styled(marker, KEY_STYLE),
            Span::raw(format!(
                "{:<owner_width$}  {:<12} ",
                param.owner(scene),
                param.property()
            )),
        ];
        let current = param.current_text(scene);
        match (&what_if.editing, selected) {
            (Some(input), true) => {
                spans.push(Span::raw(format!("{current} → ")));
                let text = input.text();
                let at = text
                    .char_indices()
                    .nth(input.cursor())
                    .map_or(text.len(), |(i, _)| i);
                let (before, after) = text.split_at(at);
                let mut rest = after.chars();
                let under = rest.next().map_or(" ".to_string(), String::from);
                spans.push(Span::styled(
                    before.to_string(),
                    Style::new().add_modifier(Modifier::BOLD),
                ));
                spans.push(Span::styled(
                    under,
                    Style::new().add_modifier(Modifier::REVERSED),
                ));
                spans.push(Span::styled(
                    rest.as_str().to_string(),
                    Style::new().add_modifier(Modifier::BOLD),
                ));
            }
            _ => {
                let style = if selected {
                    Style::new().add_modifier(Modifier::BOLD)
                } else {
                    Style::new()
                };
                spans.push(Span::styled(current, style));
                if let Some(outcome) = what_if.outcome.as_ref().filter(|o| o.param == *param) {
                    spans.push(Span::styled(
                        format!(" → {}", outcome.text),
                        Style::new()
                            .fg(Color::LightCyan)
                            .add_modifier(Modifier::BOLD),
                    ));
                }
            }
        }
        lines.push(Line::from(spans));
    }
    if let (Some(_), Some(param)) = (&what_if.editing, what_if.selected_param()) {
        lines.push(Line::styled(
            format!("  {}: {}", param.property(), param.range()),
            Style::new().fg(Color::Gray),
        ));
    }
    lines.push(Line::raw(""));
    if let Some(note) = &what_if.note {
        let style = if note.is_error {
            Style::new()
                .fg(Color::LightRed)
                .add_modifier(Modifier::BOLD)
        } else {
            Style::new().fg(Color::LightGreen)
        };
        for part in wrap_words(&note.text, usize::from(width).max(8)) {
            lines.push(Line::styled(part, style));
        }
    }
    if what_if.running.is_some() {
        lines.push(Line::styled(
            "re-tracing the pixel in the changed scene…",
            Style::new().fg(Color::Yellow),
        ));
    }
    let Some(outcome) = &what_if.outcome else {
        if what_if.note.is_none() && what_if.running.is_none() {
            lines.push(Line::styled(
                "Choose a value and press Enter to change it; the pixel is traced again.",
                Style::new().fg(Color::Gray),
            ));
        }
        lines.truncate(rows);
        return lines;
    };
    let diff = &outcome.diff;
    let [old, new] = diff.color;
    lines.push(Line::from(vec![
        Span::styled(
            format!(
                "{} {} → {}  ",
                outcome.param.property(),
                outcome.param.current_text(scene),
                outcome.text
            ),
            Style::new().add_modifier(Modifier::BOLD),
        ),
        Span::raw("old "),
        swatch(old, depth),
        Span::raw(format!(" {}   new ", rgb(old))),
        swatch(new, depth),
        Span::raw(format!(" {}", rgb(new))),
    ]));
    let cause = match diff.divergences.first() {
        Some(first) => format!(
            "first difference: {}: {} → {}",
            first.what, first.values[0], first.values[1]
        ),
        None => "the two ray trees are the same, ray by ray".to_string(),
    };
    let summary = format!("{} rays → {} rays; {cause}", diff.rays[0], diff.rays[1]);
    lines.extend(
        wrap_words(&summary, usize::from(width).max(8))
            .into_iter()
            .map(Line::raw),
    );
    let room = rows.saturating_sub(lines.len());
    let shown = if outcome.rays.len() <= room {
        outcome.rays.len()
    } else {
        room.saturating_sub(1)
    };
    for change in &outcome.rays[..shown] {
        lines.push(ray_line(change, depth, width >= WIDE));
    }
    if shown < outcome.rays.len() {
        lines.push(Line::styled(
            format!("… and {} more changed rays", outcome.rays.len() - shown),
            Style::new().fg(Color::Gray),
        ));
    }
    lines.truncate(rows);
    lines
}

/// From this many columns a changed ray shows both colours' numbers, not only the new one's.
const WIDE: u16 = 96;

/// One changed ray: added (+), removed (−) or changed (~), indented by depth, what it hits,
/// its path weight (once when it did not change) and its colour before and after.
fn ray_line(change: &RayChange, depth: ColorDepth, wide: bool) -> Line<'static> {
    let (mark, color) = match change.change {
        Change::Removed => ("−", Color::LightRed),
        Change::Added => ("+", Color::LightGreen),
        Change::Changed => ("~", Color::LightYellow),
    };
    let kind = change.route.last().map_or("ray", |k| k.name());
    let (indent, kind_width, hits_width) = if wide {
        ("  ".repeat(change.depth.min(8) as usize), 24, 14)
    } else {
        (" ".repeat(change.depth.min(6) as usize), 18, 12)
    };
    let hits: String = change.hits.chars().take(hits_width).collect();
    let mut spans = vec![
        Span::styled(
            format!("{mark} "),
            Style::new().fg(color).add_modifier(Modifier::BOLD),
        ),
        Span::raw(format!(
            "{:<kind_width$} {hits:<hits_width$} ",
            format!("{indent}{kind}")
        )),
    ];
    let side = |i: usize| change.weight[i].zip(change.color[i]);
    match (side(0), side(1)) {
        (Some((wa, ca)), Some((wb, cb))) => {
            let weight = if wa == wb {
                format!("w {}  ", compact(wa))
            } else {
                format!("w {} → {}  ", compact(wa), compact(wb))
            };
            spans.push(Span::raw(weight));
            spans.push(swatch(ca, depth));
            spans.push(Span::raw(if wide {
                format!(" {} → ", compact(ca))
            } else {
                "→".to_string()
            }));
            spans.push(swatch(cb, depth));
            spans.push(Span::raw(format!(" {}", compact(cb))));
        }
        (Some((w, c)), None) | (None, Some((w, c))) => {
            spans.push(Span::raw(format!("w {}  ", compact(w))));
            spans.push(swatch(c, depth));
            spans.push(Span::raw(format!(" {}", compact(c))));
            if change.rays_below > 0 {
                spans.push(Span::styled(
                    format!("  and {} rays below", change.rays_below),
                    Style::new().fg(Color::Gray),
                ));
            }
        }
        (None, None) => {}
    }
    Line::from(spans)
}

/// A grey as one number, any other colour as three.
fn compact(c: [f32; 3]) -> String {
    if c[0] == c[1] && c[1] == c[2] {
        number(c[0])
    } else {
        rgb(c)
    }
}
