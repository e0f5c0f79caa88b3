//! The 3D ray view in the image pane (`v`): a small render of the scene from the orbit
//! camera in half-blocks, dimmed, and the picked pixel's rays over it in braille, coloured by
//! kind, the selected ray thick and bold, with a legend on the bottom border.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Widget;
use whitted_tracer::display::linear_to_srgb8_rgb;

use crate::app::App;
use crate::image_view::ColorDepth;
use crate::ray_view::{segments, SegmentKind, ViewProjection};
use crate::ray_view_state::{Backdrop, RayViewState};

use super::braille::BrailleCanvas;
use super::pane_block;

const CAMERA: [u8; 3] = [255, 255, 255];
const REFLECTED: [u8; 3] = [0, 230, 255];
const TRANSMITTED: [u8; 3] = [255, 170, 0];
const SHADOW_LIT: [u8; 3] = [40, 255, 40];
const SHADOW_BLOCKED: [u8; 3] = [255, 40, 40];
const SELECTED: [u8; 3] = [255, 0, 255];

/// How bright the backdrop is drawn, so that the rays stand out against it.
const BACKDROP_BRIGHTNESS: f32 = 0.25;

/// Rays that hit nothing (and shadow rays to directional lights) are drawn this many times
/// the distance from the scene's camera to the point it looks at.
const MISS_LENGTH: f64 = 1.5;

fn kind_color(kind: SegmentKind) -> [u8; 3] {
    match kind {
        SegmentKind::Camera => CAMERA,
        SegmentKind::Reflected => REFLECTED,
        SegmentKind::Transmitted => TRANSMITTED,
        SegmentKind::ShadowLit => SHADOW_LIT,
        SegmentKind::ShadowBlocked => SHADOW_BLOCKED,
    }
}

/// Drawn in this order, so that the rays a picture is made of lie over the shadow rays.
fn draw_rank(kind: SegmentKind) -> u8 {
    match kind {
        SegmentKind::ShadowLit => 0,
        SegmentKind::ShadowBlocked => 1,
        SegmentKind::Camera => 2,
        SegmentKind::Reflected => 3,
        SegmentKind::Transmitted => 4,
    }
}

pub fn draw(app: &App, view: &RayViewState, pane: Rect, buf: &mut Buffer) {
    let focused = app.focus == crate::action::Focus::Image;
    let block = pane_block(title(app, pane.width), focused).title_bottom(legend(app, pane.width));
    let block = if view.is_rendering() {
        block.title_bottom(Line::from(" rendering the view ").right_aligned())
    } else {
        block
    };
    let area = block.inner(pane);
    block.render(pane, buf);
    if area.is_empty() {
        return;
    }
    let depth = app.color_depth;
    let backdrop = view.backdrop.as_ref();
    draw_backdrop(backdrop, depth, area, buf);

    let Some(picked) = &app.picked else {
        return;
    };
    let tree = &picked.tree;
    let camera = &app.loaded.scene.camera;
    let miss_length = ((camera.look_at - camera.eye).length() * MISS_LENGTH).max(1.0);
    let mut rays = segments(tree.tree(), miss_length);
    rays.sort_by_key(|s| (s.node == tree.selected(), draw_rank(s.kind)));
    let mut canvas = BrailleCanvas::new(area.width, area.height);
    let (width, height) = canvas.dots();
    let projection = ViewProjection::new(view.orbit.camera(), width, height);
    for ray in &rays {
        let Some((from, to)) = projection.project_segment(ray.from, ray.to) else {
            continue;
        };
        if ray.node == tree.selected() {
            // Thick: the line and its neighbours one dot right and one down.
            let color = depth.color(SELECTED);
            for (ox, oy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)] {
                canvas.line(
                    (from.0 + ox, from.1 + oy),
                    (to.0 + ox, to.1 + oy),
                    color,
                    true,
                );
            }
        } else {
            canvas.line(from, to, depth.color(kind_color(ray.kind)), false);
        }
    }
    canvas.draw(area, buf, |column, row| {
        cell_background(backdrop, depth, column, row)
    });
}

fn dimmed(linear: [f32; 3]) -> [u8; 3] {
    linear_to_srgb8_rgb(linear.map(|c| c * BACKDROP_BRIGHTNESS))
}

/// The backdrop in half-blocks, one pixel per half-cell (it is rendered at the pane's size;
/// for a moment after a resize it may be smaller or larger, and is drawn as far as it goes).
fn draw_backdrop(backdrop: Option<&Backdrop>, depth: ColorDepth, area: Rect, buf: &mut Buffer) {
    for row in 0..area.height {
        for column in 0..area.width {
            let pixel = |half: u32| {
                backdrop
                    .and_then(|b| b.linear(u32::from(column), u32::from(row) * 2 + half))
                    .map(|linear| depth.color(dimmed(linear)))
            };
            let Some(cell) = buf.cell_mut((area.x + column, area.y + row)) else {
                continue;
            };
            match (pixel(0), pixel(1)) {
                (Some(top), Some(bottom)) => cell.set_char('▀').set_fg(top).set_bg(bottom),
                _ => cell.set_char(' ').set_fg(Color::Reset).set_bg(Color::Reset),
            };
        }
    }
}

/// A braille cell's background: the mean of the two backdrop pixels it covers.
fn cell_background(backdrop: Option<&Backdrop>, depth: ColorDepth, column: u16, row: u16) -> Color {
    let Some(backdrop) = backdrop else {
        return Color::Reset;
    };
    let (x, y) = (u32::from(column), u32::from(row) * 2);
    match (backdrop.linear(x, y), backdrop.linear(x, y + 1)) {
        (Some(top), Some(bottom)) => {
            depth.color(dimmed([0, 1, 2].map(|i| (top[i] + bottom[i]) / 2.0)))
        }
        _ => Color::Reset,
    }
}

fn title(app: &App, width: u16) -> Line<'static> {
    let pixel = app
        .picked
        .as_ref()
        .map(|p| {
            let [x, y] = p.tree.tree().pixel;
            format!(" of ({x}, {y})")
        })
        .unwrap_or_default();
    let name = format!(" 3D rays{pixel}");
    // The longest list of keys that fits beside the name inside the corners.
    let room = usize::from(width.saturating_sub(2)).saturating_sub(name.chars().count());
    let keys = [
        " · ←↑↓→ drag: orbit · +/-: zoom · 0: reset · v: image ",
        " · ←↑↓→ orbit · +- zoom · 0 reset · v image ",
        " ←↑↓→ orbit +- zoom 0 reset v image ",
        " ←↑↓→ +- 0 v ",
    ]
    .into_iter()
    .find(|keys| keys.chars().count() <= room)
    .unwrap_or("");
    Line::from(vec![
        Span::raw(name),
        Span::styled(keys, Style::new().fg(Color::Gray)),
    ])
}

/// The colours of the rays, on the bottom border (shorter names in a narrow pane).
fn legend(app: &App, width: u16) -> Line<'static> {
    if app.picked.is_none() {
        return Line::from(" no ray tree yet: Enter traces the cursor pixel ");
    }
    let names: [&str; 6] = if width >= 66 {
        [
            "camera",
            "reflected",
            "transmitted",
            "shadow",
            "blocked",
            "selected",
        ]
    } else if width >= 45 {
        ["cam", "refl", "trans", "shadow", "blocked", "sel"]
    } else {
        ["cam", "refl", "trans", "lit", "blocked", "sel"]
    };
    let colors = [
        CAMERA,
        REFLECTED,
        TRANSMITTED,
        SHADOW_LIT,
        SHADOW_BLOCKED,
        SELECTED,
    ];
    let mut spans = vec![Span::raw(" ")];
    for (name, color) in names.iter().zip(colors) {
        let [r, g, b] = color;
        let style = Style::new().fg(app.color_depth.color([r, g, b]));
        spans.push(Span::styled("━", style.add_modifier(Modifier::BOLD)));
        spans.push(Span::raw(format!("{name} ")));
    }
    Line::from(spans)
}
