//! The ray-tree pane: one row per ray — kind, depth, what it hit (or why it ended) and its
//! contribution to the pixel, with a swatch — indented under the ray that spawned it, under
//! a header naming each column.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget, Wrap};
use whitted_tracer::ray_tree::{RayNode, ShadowOutcome};
use whitted_tracer::{RayKind, Termination};

use crate::action::Focus;
use crate::app::App;
use crate::image_view::ColorDepth;
use crate::stepping;
use crate::tree_view::{NodeId, TreeView};

use super::format::{self, swatch};
use super::pane_block;

pub fn draw(app: &App, pane: Rect, buf: &mut Buffer) {
    let focused = app.focus == Focus::Tree;
    let Some(picked) = &app.picked else {
        let block = pane_block(Line::from(" Ray tree "), focused);
        let text = vec![
            Line::from("No pixel picked yet."),
            Line::from("Move the cursor (arrows, hjkl) and press Enter, or click the image."),
        ];
        Paragraph::new(text)
            .style(Style::new().fg(Color::Gray))
            .wrap(Wrap { trim: true })
            .block(block)
            .render(pane, buf);
        return;
    };
    let tree = &picked.tree;
    let mut block = pane_block(Line::from(title(tree, pane.width)), focused);
    if tree.is_stepping() {
        block = block.title_bottom(step_line(tree, app.color_depth));
    }
    let area = block.inner(pane);
    block.render(pane, buf);

    if area.is_empty() {
        return;
    }
    header_line(usize::from(area.width)).render(Rect { height: 1, ..area }, buf);
    let visible = tree.visible();
    let rows = visible
        .iter()
        .skip(tree.scroll())
        .take(usize::from(area.height - 1));
    let matches = app.search.as_ref().map_or(&[][..], |s| &s.matches[..]);
    let numbers = shows_numbers(usize::from(area.width));
    for (row, &id) in rows.enumerate() {
        let line = row_line(app, tree, id, usize::from(area.width), numbers);
        let selected = id == tree.selected();
        let style = match (selected, focused) {
            (true, true) => Style::new().add_modifier(Modifier::REVERSED),
            (true, false) => Style::new().bg(Color::DarkGray),
            // Search matches are underlined, so the next one can be seen.
            _ if matches.contains(&id) => Style::new().add_modifier(Modifier::UNDERLINED),
            _ => Style::new(),
        };
        let row_area = Rect::new(area.x, area.y + 1 + row as u16, area.width, 1);
        buf.set_style(row_area, style);
        line.render(row_area, buf);
    }
}

/// The width of the numbers after a row's swatch: ` 0.19 0.29 0.69`.
const NUMBERS_WIDTH: usize = 15;

/// The width of a camera ray's head (marker, kind, depth): `▼ camera      d0 `.
const HEAD_WIDTH: usize = 2 + 11 + 4;

/// Whether a pane `width` columns wide shows the numbers after the swatches: when a camera
/// ray's row keeps 8 columns for what it met. The choice is the same for every row, so that
/// the numbers stay under their header (deeper rows cut what they met first).
fn shows_numbers(width: usize) -> bool {
    width >= HEAD_WIDTH + 8 + 3 + NUMBERS_WIDTH
}

/// The column header: the ray's kind and depth, what it met, and its share of the pixel
/// (over the swatch and, when they show, r g b over the numbers). In a narrow pane "what it
/// met" is cut, never the share's header.
fn header_line(width: usize) -> Line<'static> {
    // Over a camera ray's head (marker, kind, depth "d0"): the kind and "d" for depth.
    let head = format!("  {:<11} {:<3}", "ray", "d");
    let right = if shows_numbers(width) {
        "share r    g    b"
    } else {
        "share"
    };
    let left_width = width.saturating_sub(right.len() + 1);
    let left = format::truncate(&format!("{head}what it met"), left_width);
    let text = format::truncate(&format!("{left:<left_width$} {right}"), width);
    Line::from(Span::styled(
        text,
        Style::new()
            .fg(Color::Gray)
            .add_modifier(Modifier::BOLD | Modifier::UNDERLINED),
    ))
}

/// One ray's row, fitted to `width` columns: the label is cut first, the numbers only
/// when the pane is very narrow.
fn row_line(
    app: &App,
    tree: &TreeView,
    id: NodeId,
    width: usize,
    show_numbers: bool,
) -> Line<'static> {
    let Some(node) = tree.node(id) else {
        return Line::default();
    };
    let indent = "  ".repeat(tree.level(id));
    let marker = match (tree.has_children(id), tree.is_open(id)) {
        (false, _) => "  ",
        (true, true) => "▼ ",
        (true, false) => "▶ ",
    };
    let head = format!("{indent}{marker}{:<11} d{} ", node.kind.name(), node.depth);
    let contribution = tree.contribution(id);
    let [r, g, b] = contribution;
    let numbers = format!(" {r:.2} {g:.2} {b:.2}");
    let head_width = head.chars().count();
    let tail = 3 + if show_numbers { numbers.len() } else { 0 };
    let label_width = width.saturating_sub(head_width + tail);
    let mut description = describe(node);
    if node.kind == RayKind::Camera && tree.tree().samples.len() > 1 {
        if let Some(sample) = tree.sample(id) {
            description = format!("sample {}: {description}", sample.index);
        }
    }
    let label = format!(
        "{:<label_width$}",
        format::truncate(&description, label_width)
    );
    let kind_style = Style::new().fg(match node.kind {
        RayKind::Camera => Color::LightBlue,
        RayKind::Reflected => Color::LightCyan,
        RayKind::Transmitted => Color::LightGreen,
        RayKind::Shadow => Color::Gray,
    });
    let mut spans = vec![
        Span::styled(head, kind_style),
        Span::raw(label),
        Span::raw(" "),
        swatch(contribution, app.color_depth),
    ];
    if show_numbers {
        spans.push(Span::raw(numbers));
    }
    Line::from(spans)
}

/// What the ray met: the object it hit, a miss, or for a shadow ray its light and blocker;
/// plus why recursion stopped when it stopped early.
fn describe(node: &RayNode) -> String {
    if let Some(shadow) = &node.shadow {
        let light = &shadow.light.label;
        return match shadow.result {
            ShadowOutcome::Unblocked => format!("→ {light}: lit"),
            ShadowOutcome::Filtered => format!("→ {light}: filtered"),
            ShadowOutcome::Blocked => match &shadow.blocker {
                Some(blocker) => format!("→ {light}: blocked ({})", blocker.object.label),
                None => format!("→ {light}: blocked"),
            },
        };
    }
    let mut text = match &node.hit {
        Some(hit) if hit.leaf.handle != hit.object.handle => {
            format!("{} ({})", hit.object.label, hit.leaf.label)
        }
        Some(hit) => hit.object.label.clone(),
        None => "miss: background".to_string(),
    };
    if node.hit.as_ref().is_some_and(|h| !h.front_face) {
        text.push_str(" (inside)");
    }
    // A matte surface ends recursion as "absorbed" all the time: not worth a mention here.
    let ended = match node.termination {
        Termination::MaxDepth => Some("max depth"),
        Termination::WeightCutoff => Some("weight cut-off"),
        Termination::TotalInternalReflection => Some("total internal reflection"),
        Termination::RayBudget => Some("ray budget"),
        Termination::Absorbed | Termination::NotEnded | Termination::Miss => None,
    };
    if let Some(ended) = ended {
        text.push_str(&format!(" · {ended}"));
    }
    text
}

/// The pane's title: the pixel, and how many rays the collapse hides (`a` shows them),
/// shortened to fit the pane.
fn title(tree: &TreeView, width: u16) -> String {
    let [x, y] = tree.tree().pixel;
    let all = tree.len();
    let hidden = tree.hidden_count();
    let light = tree.light_count();
    let (long, short) = if hidden > 0 {
        let shown = all - hidden;
        (
            format!(" Ray tree of ({x}, {y}) · {shown} of {all} rays, a shows all "),
            format!(" Ray tree · {shown} of {all} rays, a: all "),
        )
    } else if light > 0 {
        (
            format!(" Ray tree of ({x}, {y}) · {all} rays, a hides {light} light "),
            format!(" Ray tree · {all} rays, a: collapse "),
        )
    } else {
        (
            format!(" Ray tree of ({x}, {y}) · {all} rays "),
            format!(" Ray tree · {all} rays "),
        )
    };
    if long.chars().count() + 2 <= usize::from(width) {
        long
    } else {
        short
    }
}

/// While stepping: which ray of how many in the tracer's order, and the pixel's colour
/// counting the rays so far (it ends at the pixel's colour on the last ray).
fn step_line(tree: &TreeView, depth: ColorDepth) -> Line<'static> {
    let id = tree.selected();
    let running = stepping::running_color(tree, id);
    Line::from(vec![
        Span::raw(format!(" step {}/{} ", id + 1, tree.len())),
        swatch(running, depth),
        Span::raw(format!(" {} ", format::rgb(running))),
    ])
}
