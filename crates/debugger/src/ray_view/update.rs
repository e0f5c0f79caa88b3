//! What the keys and the mouse do to the 3D ray view: the image's moves steer its camera.
//! Called first from [`crate::update::update`] while the view shows.

use crate::action::{Action, Focus};
use crate::app::App;

/// How far one arrow press orbits the 3D view; Shift+arrow (a single pixel's move on the
/// image) turns it by a fine step.
const ORBIT_STEP_DEGREES: f64 = 5.0;
const FINE_ORBIT_STEP_DEGREES: f64 = 1.0;
/// How far a drag across one cell orbits it (a row is twice as tall as a column is wide).
const DRAG_DEGREES_PER_COLUMN: f64 = 3.0;
const ZOOM_STEP: f64 = 1.25;

/// In the 3D view, the image's moves steer its camera instead: arrows orbit, +/- and the
/// wheel zoom, pans pan, 0 resets, and a press and drag in the pane orbits. Whether the
/// action was taken here.
pub(crate) fn action(app: &mut App, action: Action) -> bool {
    let area = app.image_area();
    let Some(view) = app.ray_view.as_mut() else {
        return false;
    };
    let inside = |column: u16, row: u16| {
        area.is_some_and(|a| a.contains(ratatui::layout::Position::new(column, row)))
    };
    if let Action::Click { .. } = action {
        // Only a press inside the pane starts a drag.
        view.drag_from = None;
    }
    let orbit = &mut view.orbit;
    match action {
        Action::MoveCursorByCells { dx, dy } => orbit.orbit(
            f64::from(dx) * ORBIT_STEP_DEGREES.to_radians(),
            -f64::from(dy) * ORBIT_STEP_DEGREES.to_radians(),
        ),
        Action::MoveCursor { dx, dy } => orbit.orbit(
            f64::from(dx) * FINE_ORBIT_STEP_DEGREES.to_radians(),
            -f64::from(dy) * FINE_ORBIT_STEP_DEGREES.to_radians(),
        ),
        Action::ZoomIn => orbit.zoom(ZOOM_STEP),
        Action::ZoomOut => orbit.zoom(1.0 / ZOOM_STEP),
        Action::Wheel { column, row, lines } if inside(column, row) => {
            orbit.zoom(if lines < 0 {
                ZOOM_STEP
            } else {
                1.0 / ZOOM_STEP
            });
        }
        Action::Pan { columns, rows } => {
            // As a fraction of the view's height: a row is two of the backdrop's pixels,
            // a column one.
            let half_rows = f64::from(area.map_or(1, |a| a.height.max(1))) * 2.0;
            orbit.pan(
                f64::from(columns) / half_rows,
                -f64::from(rows) * 2.0 / half_rows,
            );
        }
        Action::ResetRayView => orbit.reset(),
        Action::Click { column, row } if inside(column, row) && !app.help_open => {
            view.drag_from = Some((column, row));
            app.focus = Focus::Image;
        }
        Action::Drag { column, row } => {
            // The scene follows the mouse: dragging right turns it right (the camera goes
            // left), dragging down tips its top towards the viewer (the camera rises).
            if let Some((from_column, from_row)) = view.drag_from {
                let dx = f64::from(column) - f64::from(from_column);
                let dy = f64::from(row) - f64::from(from_row);
                let step = DRAG_DEGREES_PER_COLUMN.to_radians();
                orbit.orbit(-dx * step, dy * 2.0 * step);
                view.drag_from = Some((column, row));
            }
        }
        _ => return false,
    }
    true
}
