//! `update`: how each user [`Action`] changes the [`App`]. Pure state changes plus the
//! [`Effect`]s the event loop must carry out (reload, render, write a file); no terminal and
//! no threads here, so every transition is unit-tested.

use std::path::Path;

use ratatui::crossterm::event::KeyEvent;
use whitted_ir::Handle;

use crate::action::{Action, Focus};
use crate::app::{App, Effect, SourceTarget, View};
use crate::image_view::Viewport;
use crate::layout;
use crate::line_input::{InputOutcome, LineInput};
use crate::what_if_state::WhatIf;

/// Applies one action; returns what the event loop must do about it.
pub fn update(app: &mut App, action: Action) -> Vec<Effect> {
    // A message answers the previous action; the next one replaces or clears it. Scene
    // errors stay in their own pane until a reload succeeds.
    app.message = None;
    let requests = app.trace_requests;
    let mut effects = apply(app, action);
    if app.trace_requests != requests {
        effects.push(Effect::Trace);
    }
    effects
}

fn apply(app: &mut App, action: Action) -> Vec<Effect> {
    match action {
        Action::Quit => app.should_quit = true,
        // Esc stops a runaway trace first, then a query, then clears the query's overlay;
        // with none of those it quits.
        Action::Cancel => {
            if app.cancel_trace() {
                app.set_message("cancelled the trace", false);
            } else if app.query.cancel() {
                app.set_message("cancelled the query", false);
            } else if app.query.overlay.take().is_some() {
                app.set_message("cleared the query's matches", false);
            } else {
                app.should_quit = true;
            }
        }
        Action::ToggleHelp => app.help_open = !app.help_open,
        Action::MoveCursor { dx, dy } => move_cursor(app, dx, dy),
        Action::TraceCursor => app.trace_cursor(),
        Action::Click { column, row } => click(app, column, row),
        Action::Wheel { column, row, lines } => wheel(app, column, row, lines),
        Action::ZoomIn => zoom(app, 2.0, cursor_focus(app)),
        Action::ZoomOut => zoom(app, 0.5, cursor_focus(app)),
        Action::Pan { columns, rows } => pan(app, columns, rows),
        Action::Fit => app.view = View::Fit,
        Action::FocusNext => app.focus = app.focus.next(),
        Action::FocusPrevious => app.focus = app.focus.previous(),
        Action::TreeUp => tree(app, |t| t.select_previous()),
        Action::TreeDown => tree(app, |t| t.select_next()),
        Action::TreeLeft => tree(app, |t| t.left()),
        Action::TreeRight => tree(app, |t| t.right()),
        Action::TreeFirst => tree(app, |t| t.select_first()),
        Action::TreeLast => tree(app, |t| t.select_last()),
        Action::TreePage(rows) => tree(app, |t| t.page(rows as isize)),
        Action::TreeToggle => tree(app, |t| t.toggle()),
        Action::InspectorScroll(lines) => scroll_inspector(app, lines),
        Action::ToggleOverlay(kind) => {
            app.overlay = if app.overlay == Some(kind) {
                None
            } else {
                Some(kind)
            };
            app.refresh_heat_map();
            if app.overlay.is_some() && app.heat_map.is_none() {
                app.set_message("the overlay appears when the render finishes", false);
            }
        }
        Action::ToggleHitPoint => app.show_hit_point = !app.show_hit_point,
        Action::ToggleSourceTarget => {
            app.source_target = match app.source_target {
                SourceTarget::Object => SourceTarget::Material,
                SourceTarget::Material => SourceTarget::Object,
            }
        }
        Action::Reload => {
            if !app.reloading {
                app.reloading = true;
                app.set_message(format!("reloading {}", app.scene_name), false);
                return vec![Effect::Reload];
            }
        }
        Action::Export => return export(app),
        Action::WhatIf => open_what_if(app),
        Action::QueryPrompt => {
            app.query.prompt = Some(LineInput::new(&app.query.last_text));
        }
        Action::InputKey(key) => return input_key(app, key),
        Action::NextMatch => step_match(app, false),
        Action::PreviousMatch => step_match(app, true),
    }
    Vec::new()
}

/// `w`: the what-if popup on the picked pixel, with the material of the selected ray (or,
/// when it hit nothing, of the camera ray).
fn open_what_if(app: &mut App) {
    let Some(picked) = &app.picked else {
        app.set_message("what-if needs a ray tree: pick a pixel first (Enter)", true);
        return;
    };
    let tree = &picked.tree;
    let material = tree
        .selected_node()
        .and_then(|n| n.hit.as_ref())
        .or_else(|| tree.node(0).and_then(|n| n.hit.as_ref()))
        .map(|hit| Handle::from_index(hit.material.handle as usize));
    app.what_if = Some(WhatIf::open(
        app.loaded.clone(),
        tree.tree().clone(),
        material,
        app.node_budget,
    ));
}

/// A key for the open popup (first) or the query prompt.
fn input_key(app: &mut App, key: KeyEvent) -> Vec<Effect> {
    if let Some(what_if) = &mut app.what_if {
        let (close, effects) = what_if.handle_key(key);
        if close {
            app.what_if = None;
        }
        return effects;
    }
    let Some(prompt) = &mut app.query.prompt else {
        return Vec::new();
    };
    match prompt.handle(key) {
        InputOutcome::Edited | InputOutcome::Ignored => Vec::new(),
        InputOutcome::Cancelled => {
            app.query.prompt = None;
            Vec::new()
        }
        InputOutcome::Submitted => {
            let text = prompt.text().trim().to_string();
            app.query.prompt = None;
            if text.is_empty() {
                app.query.overlay = None;
                return Vec::new();
            }
            // Kept even when wrong, so that `:` brings it back to be fixed.
            app.query.last_text = text.clone();
            let scene = std::sync::Arc::clone(&app.loaded.scene);
            match app.query.start(&text, &app.loaded, &app.options, &scene) {
                Ok(()) => {
                    app.set_message(format!("querying {text}, Esc cancels"), false);
                    vec![Effect::StartQuery]
                }
                Err(message) => {
                    app.set_message(message, true);
                    Vec::new()
                }
            }
        }
    }
}

/// `n` / `N`: the cursor to the next or previous matching pixel (row order), traced.
fn step_match(app: &mut App, backward: bool) {
    let Some(overlay) = &app.query.overlay else {
        app.set_message("no query to step through: press : to run one", false);
        return;
    };
    let Some(pixel) = overlay.step(app.cursor, backward) else {
        app.set_message(format!("no pixel matches {}", overlay.text), false);
        return;
    };
    let index = overlay
        .matches
        .iter()
        .position(|&m| m == pixel)
        .unwrap_or(0);
    let count = overlay.matches.len();
    app.cursor = pixel;
    keep_cursor_in_view(app);
    app.trace_cursor();
    app.set_message(format!("match {} of {count}", index + 1), false);
}

/// The image point zooming keeps in place: the centre of the cursor pixel.
fn cursor_focus(app: &App) -> (f32, f32) {
    (app.cursor.0 as f32 + 0.5, app.cursor.1 as f32 + 0.5)
}

fn move_cursor(app: &mut App, dx: i32, dy: i32) {
    let (width, height) = app.image_size();
    let clamp = |value: u32, delta: i32, size: u32| -> u32 {
        let moved = i64::from(value) + i64::from(delta);
        moved.clamp(0, i64::from(size.saturating_sub(1))) as u32
    };
    app.cursor = (
        clamp(app.cursor.0, dx, width),
        clamp(app.cursor.1, dy, height),
    );
    keep_cursor_in_view(app);
}

/// In a zoomed view, re-centres on the cursor when it leaves the pane.
fn keep_cursor_in_view(app: &mut App) {
    let (View::Manual(viewport), Some(area)) = (app.view, app.image_area()) else {
        return;
    };
    if viewport.cell_of(app.cursor.0, app.cursor.1, area).is_none() {
        app.view = View::Manual(centred_on(viewport, area, cursor_focus(app)));
    }
}

fn centred_on(viewport: Viewport, area: ratatui::layout::Rect, (x, y): (f32, f32)) -> Viewport {
    Viewport {
        scale: viewport.scale,
        origin_x: x - f32::from(area.width) * viewport.scale / 2.0,
        origin_y: y - f32::from(area.height) * 2.0 * viewport.scale / 2.0,
    }
}

/// Zooms by `factor` about an image point; zooming out past the fitted size returns to fit.
fn zoom(app: &mut App, factor: f32, (x, y): (f32, f32)) {
    let Some(area) = app.image_area() else {
        return;
    };
    let (width, height) = app.image_size();
    let fit = Viewport::fit(width, height, area);
    let mut viewport = app.viewport();
    viewport.zoom_about(factor, x, y);
    app.view = if viewport.scale >= fit.scale {
        View::Fit
    } else {
        View::Manual(viewport)
    };
}

fn pan(app: &mut App, columns: i32, rows: i32) {
    let mut viewport = app.viewport();
    viewport.pan(columns as f32, rows as f32 * 2.0);
    app.view = View::Manual(viewport);
}

fn click(app: &mut App, column: u16, row: u16) {
    if app.help_open {
        app.help_open = false;
        return;
    }
    let Some(panes) = app.panes() else {
        return;
    };
    let position = ratatui::layout::Position::new(column, row);
    let image = layout::inner(panes.image);
    let tree_area = layout::inner(panes.tree);
    if image.contains(position) {
        app.focus = Focus::Image;
        let (width, height) = app.image_size();
        let half_row = u32::from(row - image.y) * 2;
        if let Some(pixel) = app
            .viewport()
            .pixel_at(column - image.x, half_row, width, height)
        {
            app.cursor = pixel;
            app.trace_cursor();
        }
    } else if tree_area.contains(position) {
        app.focus = Focus::Tree;
        if let Some(picked) = &mut app.picked {
            let index = picked.tree.scroll() + usize::from(row - tree_area.y);
            if let Some(&id) = picked.tree.visible().get(index) {
                if id != picked.tree.selected() {
                    picked.tree.select(id);
                    app.inspector_scroll = 0;
                }
            }
        }
    } else if panes.inspector.contains(position) {
        app.focus = Focus::Inspector;
    }
}

fn wheel(app: &mut App, column: u16, row: u16, lines: i32) {
    let Some(panes) = app.panes() else {
        return;
    };
    let position = ratatui::layout::Position::new(column, row);
    let image = layout::inner(panes.image);
    if image.contains(position) {
        let (width, height) = app.image_size();
        let half_row = u32::from(row - image.y) * 2;
        let viewport = app.viewport();
        let point = viewport
            .pixel_at(column - image.x, half_row, width, height)
            .map_or(cursor_focus(app), |(x, y)| (x as f32 + 0.5, y as f32 + 0.5));
        zoom(app, if lines < 0 { 2.0 } else { 0.5 }, point);
    } else if panes.tree.contains(position) {
        tree(app, |t| t.page(lines as isize));
    } else if panes.inspector.contains(position) {
        scroll_inspector(app, lines * 3);
    }
}

/// Runs a tree navigation, keeps the selection in view, and resets the inspector's scroll
/// when another ray is selected.
fn tree(app: &mut App, navigate: impl FnOnce(&mut crate::tree_view::TreeView)) {
    let rows = app.tree_rows();
    let Some(picked) = &mut app.picked else {
        app.set_message("no ray tree yet: move the cursor and press Enter", false);
        return;
    };
    let before = picked.tree.selected();
    navigate(&mut picked.tree);
    picked.tree.keep_selection_in_view(rows);
    if picked.tree.selected() != before {
        app.inspector_scroll = 0;
    }
}

fn scroll_inspector(app: &mut App, lines: i32) {
    app.inspector_scroll = if lines == i32::MIN {
        0
    } else {
        let scrolled = i32::from(app.inspector_scroll) + lines;
        scrolled.clamp(0, i32::from(u16::MAX)) as u16
    };
}

fn export(app: &mut App) -> Vec<Effect> {
    let Some(picked) = &app.picked else {
        app.set_message("nothing to export: pick a pixel first (Enter)", true);
        return Vec::new();
    };
    let tree = picked.tree.tree();
    let [x, y] = tree.pixel;
    let contents = match serde_json::to_string_pretty(&tree.document()) {
        Ok(json) => json + "\n",
        Err(error) => {
            app.set_message(format!("cannot export: {error}"), true);
            return Vec::new();
        }
    };
    let stem = Path::new(&app.scene_name)
        .file_stem()
        .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned());
    let path = app.export_dir.join(format!("{stem}-{x}-{y}.ray-tree.json"));
    vec![Effect::Export { path, contents }]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::LoadedScene;
    use crate::heat_map::HeatMapKind;
    use crate::test_scene::{whitted_scene, GLASS_PIXEL};
    use ratatui::layout::Rect;
    use whitted_tracer::RayKind;

    fn app() -> App {
        App::new(
            "scenes/whitted.scene".into(),
            LoadedScene::new(whitted_scene()),
            Rect::new(0, 0, 120, 40),
            "/tmp/out".into(),
        )
    }

    fn picked_app() -> App {
        let mut app = app();
        app.cursor = GLASS_PIXEL;
        assert_eq!(update(&mut app, Action::TraceCursor), vec![Effect::Trace]);
        crate::test_scene::finish_trace(&mut app);
        app
    }

    #[test]
    fn the_cursor_moves_and_stays_inside_the_image() {
        let mut app = app();
        assert_eq!(app.cursor, (320, 240));
        update(&mut app, Action::MoveCursor { dx: 10, dy: -1 });
        assert_eq!(app.cursor, (330, 239));
        update(
            &mut app,
            Action::MoveCursor {
                dx: -1000,
                dy: 1000,
            },
        );
        assert_eq!(app.cursor, (0, 479));
    }

    #[test]
    fn enter_traces_the_pixel_under_the_cursor() {
        let app = picked_app();
        let picked = app.picked.as_ref().expect("a tree");
        assert_eq!(picked.tree.tree().pixel, [400, 270]);
        let root = picked.tree.node(0).unwrap();
        assert_eq!(root.kind, RayKind::Camera);
        let hit = root.hit.as_ref().expect("the camera ray hits the glass");
        assert_eq!(hit.object.label, "glass sphere");
    }

    #[test]
    fn a_click_on_the_image_picks_and_traces_that_pixel() {
        let mut app = app();
        let image = app.image_area().unwrap();
        app.focus = Focus::Tree;
        update(
            &mut app,
            Action::Click {
                column: image.x + image.width / 2,
                row: image.y + image.height / 2,
            },
        );
        crate::test_scene::finish_trace(&mut app);
        assert_eq!(app.focus, Focus::Image);
        let picked = app.picked.as_ref().expect("a tree");
        assert_eq!(picked.tree.tree().pixel, [app.cursor.0, app.cursor.1]);
        assert!(app.cursor.0.abs_diff(320) < 12 && app.cursor.1.abs_diff(240) < 12);
    }

    #[test]
    fn a_click_on_a_tree_row_selects_that_ray() {
        let mut app = picked_app();
        let tree = layout::inner(app.panes().unwrap().tree);
        update(
            &mut app,
            Action::Click {
                column: tree.x + 3,
                row: tree.y + 2,
            },
        );
        assert_eq!(app.focus, Focus::Tree);
        let picked = app.picked.as_ref().unwrap();
        assert_eq!(picked.tree.selected(), picked.tree.visible()[2]);
    }

    #[test]
    fn tree_keys_walk_to_the_transmitted_ray() {
        let mut app = picked_app();
        app.focus = Focus::Tree;
        update(&mut app, Action::TreeRight);
        let tree = &app.picked.as_ref().unwrap().tree;
        assert_eq!(tree.selected(), 1);
        // Down through the camera ray's children until the transmitted one.
        for _ in 0..tree.len() {
            let node = app.picked.as_ref().unwrap().tree.selected_node().unwrap();
            if node.kind == RayKind::Transmitted {
                break;
            }
            update(&mut app, Action::TreeDown);
        }
        let tree = &app.picked.as_ref().unwrap().tree;
        let node = tree.selected_node().unwrap();
        assert_eq!(node.kind, RayKind::Transmitted);
        assert_eq!(node.depth, 1);
        update(&mut app, Action::TreeLeft);
        update(&mut app, Action::TreeLeft);
        let tree = &app.picked.as_ref().unwrap().tree;
        assert_eq!(tree.selected(), 0, "collapse, then go to the parent");
    }

    #[test]
    fn tree_keys_without_a_tree_say_how_to_get_one() {
        let mut app = app();
        update(&mut app, Action::TreeDown);
        assert!(app.message.as_ref().unwrap().text.contains("Enter"));
    }

    #[test]
    fn zooming_in_and_out_returns_to_fit() {
        let mut app = app();
        assert_eq!(app.view, View::Fit);
        update(&mut app, Action::ZoomIn);
        let View::Manual(zoomed) = app.view else {
            panic!("zooming in leaves fit");
        };
        assert!(zoomed.scale < app_fit_scale(&app));
        // The cursor stays visible.
        assert!(zoomed
            .cell_of(app.cursor.0, app.cursor.1, app.image_area().unwrap())
            .is_some());
        update(&mut app, Action::ZoomOut);
        assert_eq!(app.view, View::Fit);
        update(&mut app, Action::ZoomIn);
        update(&mut app, Action::Fit);
        assert_eq!(app.view, View::Fit);
    }

    fn app_fit_scale(app: &App) -> f32 {
        Viewport::fit(640, 480, app.image_area().unwrap()).scale
    }

    #[test]
    fn a_zoomed_view_follows_the_cursor() {
        let mut app = app();
        for _ in 0..4 {
            update(&mut app, Action::ZoomIn);
        }
        update(&mut app, Action::MoveCursor { dx: 300, dy: 0 });
        let viewport = app.viewport();
        assert!(viewport
            .cell_of(app.cursor.0, app.cursor.1, app.image_area().unwrap())
            .is_some());
    }

    #[test]
    fn panning_moves_the_view() {
        let mut app = app();
        let before = app.viewport();
        update(
            &mut app,
            Action::Pan {
                columns: 4,
                rows: 0,
            },
        );
        let after = app.viewport();
        assert_eq!(after.origin_x, before.origin_x + 4.0 * before.scale);
        assert_eq!(after.origin_y, before.origin_y);
    }

    #[test]
    fn tab_cycles_the_focus() {
        let mut app = app();
        update(&mut app, Action::FocusNext);
        assert_eq!(app.focus, Focus::Tree);
        update(&mut app, Action::FocusNext);
        assert_eq!(app.focus, Focus::Inspector);
        update(&mut app, Action::FocusNext);
        assert_eq!(app.focus, Focus::Image);
        update(&mut app, Action::FocusPrevious);
        assert_eq!(app.focus, Focus::Inspector);
    }

    #[test]
    fn overlays_toggle_and_replace_each_other() {
        let mut app = app();
        update(&mut app, Action::ToggleOverlay(HeatMapKind::RaysPerPixel));
        assert_eq!(app.overlay, Some(HeatMapKind::RaysPerPixel));
        assert!(
            app.heat_map.is_none(),
            "no statistics before the render ends"
        );
        update(&mut app, Action::ToggleOverlay(HeatMapKind::DeepestLevel));
        assert_eq!(app.overlay, Some(HeatMapKind::DeepestLevel));
        update(&mut app, Action::ToggleOverlay(HeatMapKind::DeepestLevel));
        assert_eq!(app.overlay, None);
        update(&mut app, Action::ToggleHitPoint);
        assert!(!app.show_hit_point);
    }

    #[test]
    fn reload_asks_once_until_the_result_arrives() {
        let mut app = app();
        assert_eq!(update(&mut app, Action::Reload), vec![Effect::Reload]);
        assert!(app.reloading);
        assert_eq!(update(&mut app, Action::Reload), vec![]);
    }

    #[test]
    fn export_writes_the_tree_json_next_to_nothing_but_the_export_dir() {
        let mut app = app();
        assert_eq!(update(&mut app, Action::Export), vec![]);
        assert!(app.message.as_ref().unwrap().is_error);
        let mut app = picked_app();
        let effects = update(&mut app, Action::Export);
        let [Effect::Export { path, contents }] = effects.as_slice() else {
            panic!("{effects:?}");
        };
        assert_eq!(path, Path::new("/tmp/out/whitted-400-270.ray-tree.json"));
        let json: serde_json::Value = serde_json::from_str(contents).unwrap();
        assert_eq!(json["pixel"], serde_json::json!([400, 270]));
        assert_eq!(json["root"]["kind"], "camera");
        app.apply_export(Ok(path.clone()));
        assert!(app
            .message
            .as_ref()
            .unwrap()
            .text
            .contains("/tmp/out/whitted-400-270.ray-tree.json"));
    }

    #[test]
    fn quit_and_help() {
        let mut app = app();
        update(&mut app, Action::ToggleHelp);
        assert!(app.help_open);
        update(&mut app, Action::Click { column: 0, row: 0 });
        assert!(!app.help_open, "a click closes the help");
        update(&mut app, Action::Quit);
        assert!(app.should_quit);
    }

    #[test]
    fn inspector_scroll_stays_non_negative_and_home_resets_it() {
        let mut app = app();
        update(&mut app, Action::InspectorScroll(-5));
        assert_eq!(app.inspector_scroll, 0);
        update(&mut app, Action::InspectorScroll(7));
        assert_eq!(app.inspector_scroll, 7);
        update(&mut app, Action::InspectorScroll(i32::MIN));
        assert_eq!(app.inspector_scroll, 0);
    }
}
