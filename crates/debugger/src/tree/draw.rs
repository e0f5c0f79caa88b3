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
use crate::image::ColorDepth;
use crate::stepping;
use crate::tree::state::{NodeId, TreeView};

use crate::ui::format::{self, swatch};
use crate::ui::pane_block;

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
    let width = usize::from(area.width);
    let visible = tree.visible();
    let shown: Vec<NodeId> = visible
        .iter()
        .copied()
        .skip(tree.scroll())
        .take(usize::from(area.height - 1))
        .collect();
    let columns = Columns::fit(tree, &shown, width);
    header_line(&columns, width).render(Rect { height: 1, ..area }, buf);
    let matches = app.search.as_ref().map_or(&[][..], |s| &s.matches[..]);
    for (row, &id) in shown.iter().enumerate() {
        let line = row_line(app, tree, id, width, &columns);
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

/// The kind column: as wide as the longest kind, `transmitted`.
const KIND_WIDTH: usize = 11;

/// The share column: its header, over a swatch as wide.
const SHARE: &str = "share";
const SHARE_WIDTH: usize = SHARE.len();

/// What a row keeps for what it met at the least (a character and `…`) before a column on
/// its right goes.
const MIN_MET: usize = 2;

const CHANNELS: [&str; 3] = ["r", "g", "b"];

/// The columns of the rows on screen, fitted to the pane. A number is never cut: a column
/// that does not fit on every row goes, b first, then g, r and last the swatch; and rows
/// deeper than the pane can indent are drawn at the deepest indentation that still leaves
/// their depth and swatch whole (the depth column says how deep they are).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Columns {
    /// The widest depth (`d12`) on screen: depths are padded to it.
    depth_width: usize,
    /// The deepest indentation, in levels.
    max_level: usize,
    share: bool,
    /// How many of r, g and b show.
    channels: usize,
    /// The widest number on screen (`0.19`, `12.50`): numbers are right-aligned in it.
    number_width: usize,
}

impl Columns {
    fn fit(tree: &TreeView, shown: &[NodeId], width: usize) -> Columns {
        let depth_width = shown
            .iter()
            .filter_map(|&id| tree.node(id))
            .map(|node| format!("d{}", node.depth).len())
            .max()
            .unwrap_or(2);
        let number_width = shown
            .iter()
            .flat_map(|&id| tree.contribution(id))
            .map(|value| channel(value).chars().count())
            .max()
            .unwrap_or(4);
        let shallowest = head_width(0, depth_width);
        let share = shallowest + MIN_MET + 1 + SHARE_WIDTH <= width;
        let tail = if share { 1 + SHARE_WIDTH } else { 0 };
        let max_level = width.saturating_sub(shallowest + MIN_MET + tail) / 2;
        let deepest = shown
            .iter()
            .map(|&id| tree.level(id).min(max_level))
            .max()
            .unwrap_or(0);
        let room = width.saturating_sub(head_width(deepest, depth_width) + MIN_MET + tail);
        let channels = if share {
            (room / (1 + number_width)).min(CHANNELS.len())
        } else {
            0
        };
        Columns {
            depth_width,
            max_level,
            share,
            channels,
            number_width,
        }
    }

    /// The width of everything right of what the ray met.
    fn tail(&self) -> usize {
        if self.share {
            1 + SHARE_WIDTH + self.channels * (1 + self.number_width)
        } else {
            0
        }
    }

    /// The share column and the numbers: ` share    r    g    b` over ` █████ 0.19 0.29 0.69`.
    fn tail_spans(&self, contribution: [f32; 3], depth: ColorDepth) -> Vec<Span<'static>> {
        if !self.share {
            return Vec::new();
        }
        // The swatch fills the column under its header, so that no cell is wasted.
        let mut spans = vec![
            Span::raw(" "),
            Span::styled(
                "█".repeat(SHARE_WIDTH),
                Style::new().fg(format::terminal_color(contribution, depth)),
            ),
        ];
        for value in contribution.into_iter().take(self.channels) {
            let width = self.number_width;
            spans.push(Span::raw(format!(" {:>width$}", channel(value))));
        }
        spans
    }
}

/// A colour channel in the tree: two decimals.
fn channel(value: f32) -> String {
    format!("{value:.2}")
}

/// The width of a row's head at an indentation `level`: indentation, marker, kind, depth.
fn head_width(level: usize, depth_width: usize) -> usize {
    2 * level + 2 + KIND_WIDTH + 1 + depth_width + 1
}

/// The column header, each name over its column: over the head of a camera ray (marker,
/// kind, depth) the kind and `d` for depth, then what it met, and right of it the share over
/// the swatches and r g b over their numbers, as many as the rows show. In a narrow pane
/// "what it met" is cut, never the share's header.
fn header_line(columns: &Columns, width: usize) -> Line<'static> {
    let depth_width = columns.depth_width;
    let head = format!("  {:<KIND_WIDTH$} {:<depth_width$} ", "ray", "d");
    let mut right = String::new();
    if columns.share {
        right.push_str(&format!(" {SHARE}"));
        for name in CHANNELS.iter().take(columns.channels) {
            let number_width = columns.number_width;
            right.push_str(&format!(" {name:>number_width$}"));
        }
    }
    let left_width = width.saturating_sub(right.chars().count());
    let left = format::truncate(&format!("{head}what it met"), left_width);
    let text = format::truncate(&format!("{left:<left_width$}{right}"), width);
    Line::from(Span::styled(
        text,
        Style::new()
            .fg(Color::Gray)
            .add_modifier(Modifier::BOLD | Modifier::UNDERLINED),
    ))
}

/// One ray's row, fitted to `width` columns: what it met is cut, never a number.
fn row_line(
    app: &App,
    tree: &TreeView,
    id: NodeId,
    width: usize,
    columns: &Columns,
) -> Line<'static> {
    let Some(node) = tree.node(id) else {
        return Line::default();
    };
    let level = tree.level(id).min(columns.max_level);
    let indent = "  ".repeat(level);
    let marker = match (tree.has_children(id), tree.is_open(id)) {
        (false, _) => "  ",
        (true, true) => "▼ ",
        (true, false) => "▶ ",
    };
    let depth_width = columns.depth_width;
    let head = format!(
        "{indent}{marker}{:<KIND_WIDTH$} {:<depth_width$} ",
        node.kind.name(),
        format!("d{}", node.depth)
    );
    let label_width = width.saturating_sub(head_width(level, depth_width) + columns.tail());
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
    let mut spans = vec![Span::styled(head, kind_style), Span::raw(label)];
    spans.extend(columns.tail_spans(tree.contribution(id), app.color_depth));
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
