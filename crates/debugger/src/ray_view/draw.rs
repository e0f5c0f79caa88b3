//! The 3D ray view in the image pane (`v`): a small render of the scene from the orbit
//! camera in half-blocks, dimmed, and the picked pixel's rays over it in braille, coloured by
//! kind, the selected ray thick and bold, with a legend on the bottom border.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Widget;
use whitted_ir::LightKind;
use whitted_tracer::display::linear_to_srgb8_rgb;

use crate::app::{App, Picked};
use crate::image::ColorDepth;
use crate::ray_view::geometry::{segments, SegmentKind, ViewProjection};
use crate::ray_view::state::{Backdrop, RayViewState};

use crate::ui::braille::BrailleCanvas;
use crate::ui::pane_block;

const CAMERA: [u8; 3] = [255, 255, 255];
const REFLECTED: [u8; 3] = [0, 230, 255];
const TRANSMITTED: [u8; 3] = [255, 170, 0];
const SHADOW_LIT: [u8; 3] = [40, 255, 40];
const SHADOW_BLOCKED: [u8; 3] = [255, 40, 40];
const SELECTED: [u8; 3] = [255, 0, 255];
const LIGHT: [u8; 3] = [255, 255, 120];

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

    let (width, height) = (f64::from(area.width) * 2.0, f64::from(area.height) * 4.0);
    let projection = ViewProjection::new(view.orbit.camera(), width, height);
    if let Some(picked) = &app.picked {
        draw_rays(app, view, picked, &projection, area, buf);
    }
    // Over the rays, so that the shadow rays can be seen to end at them.
    draw_lights(app, &projection, area, buf);
}

/// The picked pixel's rays in braille over the backdrop, the selected one thick.
fn draw_rays(
    app: &App,
    view: &RayViewState,
    picked: &Picked,
    projection: &ViewProjection,
    area: Rect,
    buf: &mut Buffer,
) {
    let depth = app.color_depth;
    let backdrop = view.backdrop.as_ref();
    let tree = &picked.tree;
    let camera = &app.loaded.scene.camera;
    let miss_length = ((camera.look_at - camera.eye).length() * MISS_LENGTH).max(1.0);
    let mut rays = segments(tree.tree(), miss_length);
    rays.sort_by_key(|s| (s.node == tree.selected(), draw_rank(s.kind)));
    let mut canvas = BrailleCanvas::new(area.width, area.height);
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

/// Each point and spot light as a star where it is in view, so that the shadow rays
/// towards it can be seen to reach it.
fn draw_lights(app: &App, projection: &ViewProjection, area: Rect, buf: &mut Buffer) {
    let style = Style::new()
        .fg(app.color_depth.color(LIGHT))
        .add_modifier(Modifier::BOLD);
    for (_, light) in app.loaded.scene.lights.iter() {
        let position = match light.kind {
            LightKind::Point { position, .. } | LightKind::Spot { position, .. } => position,
            LightKind::Directional { .. } => continue,
        };
        let Some((x, y)) = projection.project(position) else {
            continue;
        };
        // Dots to cells: two dots across and four down per cell.
        let (column, row) = ((x / 2.0).floor(), (y / 4.0).floor());
        if column >= 0.0
            && row >= 0.0
            && column < f64::from(area.width)
            && row < f64::from(area.height)
        {
            if let Some(cell) = buf.cell_mut((area.x + column as u16, area.y + row as u16)) {
                cell.set_char('✶').set_style(style);
            }
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::LoadedScene;
    use crate::test_scene::whitted_scene;
    use whitted_ir::{Camera, DVec3, Projection};

    /// A camera looking straight at the sun sees its star in the middle of the pane; one
    /// looking away does not.
    #[test]
    fn a_point_light_in_view_is_drawn_as_a_star() {
        let app = App::new(
            "scenes/whitted.scene".into(),
            LoadedScene::new(whitted_scene()),
            Rect::new(0, 0, 120, 40),
            "/tmp".into(),
        );
        let sun = DVec3::new(-6.0, 10.0, -8.0);
        let area = Rect::new(0, 0, 21, 11);
        let star_cells = |look_at: DVec3| {
            let camera = Camera {
                eye: sun - DVec3::new(0.0, 0.0, 5.0),
                look_at,
                up: DVec3::Y,
                projection: Projection::Perspective {
                    vertical_fov_degrees: 45.0,
                },
            };
            let projection = ViewProjection::new(&camera, 42.0, 44.0);
            let mut buf = Buffer::empty(area);
            draw_lights(&app, &projection, area, &mut buf);
            buf.content()
                .iter()
                .enumerate()
                .filter(|(_, c)| c.symbol() == "✶")
                .map(|(i, _)| i)
                .collect::<Vec<_>>()
        };
        assert_eq!(star_cells(sun), vec![5 * 21 + 10]);
        assert!(star_cells(sun - DVec3::new(0.0, 0.0, 10.0)).is_empty());
    }
}
