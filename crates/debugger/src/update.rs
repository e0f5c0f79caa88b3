//! `update`: how each user [`Action`] changes the [`App`]. Pure state changes plus the
//! [`Effect`]s the event loop must carry out (reload, render, write a file); no terminal and
//! no threads here, so every transition is unit-tested.

use std::path::Path;

use ratatui::crossterm::event::KeyEvent;
use whitted_ir::Handle;

use crate::action::{Action, Focus};
use crate::app::{App, Effect, SourceScroll, SourceTarget, View};
use crate::follow::update as follow_update;
use crate::image::Viewport;
use crate::layout;
use crate::line_input::{InputOutcome, LineInput};
use crate::search;
use crate::what_if::state::WhatIf;

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
    // Another definition in the source pane starts unscrolled.
    let shown = crate::ui::source_pane::target_span(app);
    if app.source_scroll.span != shown {
        app.source_scroll = SourceScroll {
            span: shown,
            ..SourceScroll::default()
        };
    }
    // Focus and zoom change the tree pane's height: keep the selected ray in sight.
    let rows = app.tree_rows();
    if let Some(picked) = &mut app.picked {
        picked.tree.keep_selection_in_view(rows);
    }
    effects
}

fn apply(app: &mut App, action: Action) -> Vec<Effect> {
    // `+ - f` and the pans act on the image from any pane, but not while another pane is
    // zoomed over it: the change could not be seen.
    let image_hidden = app.zoomed && app.focus != Focus::Image;
    let moves_the_image = matches!(
        action,
        Action::ZoomIn | Action::ZoomOut | Action::Fit | Action::Pan { .. }
    );
    if image_hidden && moves_the_image {
        app.set_message(
            "the image is hidden by the zoomed pane: z shows the layout",
            false,
        );
        return Vec::new();
    }
    if app.ray_view.is_some() && crate::ray_view::update::action(app, action) {
        return Vec::new();
    }
    match action {
        Action::Quit => app.should_quit = true,
        Action::Cancel => cancel(app),
        Action::ToggleHelp => {
            app.help_open = !app.help_open;
            app.help_scroll = 0;
        }
        Action::HelpScroll(lines) => {
            // No further than the last key: the help has a line per key and a border.
            let rows = crate::action::KEY_HELP.len() + 2;
            let hidden = rows.saturating_sub(usize::from(app.area.height));
            let scrolled = i64::from(app.help_scroll) + i64::from(lines);
            app.help_scroll = scrolled.clamp(0, hidden as i64) as u16;
        }
        Action::MoveCursor { dx, dy } => move_cursor(app, dx, dy),
        Action::MoveCursorByCells { dx, dy } => {
            // One cell is `scale` image pixels across and one half-block row down.
            let step = app.viewport().scale.round().max(1.0) as i32;
            move_cursor(app, dx.saturating_mul(step), dy.saturating_mul(step));
        }
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
        // The explanation does not scroll sideways: the hidden inspector must not either.
        Action::InspectorScrollSideways(_) if app.explain_open => {}
        Action::InspectorScrollSideways(columns) => {
            app.inspector_columns =
                (i32::from(app.inspector_columns) + columns).clamp(0, 500) as u16;
        }
        Action::ToggleZoom => app.zoomed = !app.zoomed,
        Action::StartSearch => search::update::start(app),
        // The search prompt, the query prompt and the what-if popup each take every key.
        Action::PromptKey(key) => {
            if app.search_prompt.is_some() {
                search::update::prompt_key(app, key);
            } else {
                return input_key(app, key);
            }
        }
        Action::WhatIf => open_what_if(app),
        Action::QueryPrompt => {
            // Empty, not the last query: ↑ brings that back when it is wanted.
            app.query.prompt = Some(LineInput::with_history(&app.query.history));
        }
        Action::NextMatch => step_match(app, false),
        Action::PreviousMatch => step_match(app, true),
        Action::SearchStep { forward } => search::update::step(app, forward),
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
        Action::ToggleHitPoint => {
            app.show_hit_point = !app.show_hit_point;
            let state = if app.show_hit_point { "on" } else { "off" };
            app.set_message(format!("hit-point mark {state}"), false);
        }
        // After a failed reload the errors are in the source pane's place: the keys must
        // not scroll the hidden source.
        Action::SourceScroll { .. } | Action::SourceScrollHome if app.errors.is_some() => {}
        Action::SourceScroll { lines, columns } => scroll_source(app, lines, columns),
        Action::SourceScrollHome => {
            app.source_scroll = SourceScroll {
                span: app.source_scroll.span,
                ..SourceScroll::default()
            }
        }
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
        Action::StepFrame { forward } => return step_frame(app, forward),
        Action::Export => return export(app),
        Action::ToggleShowAll => follow_update::toggle_show_all(app),
        Action::FollowHeaviest => follow_update::follow_heaviest(app),
        Action::ToggleExplain => crate::explain::update::toggle_explain(app),
        Action::Step { forward } => follow_update::step(app, forward),
        Action::RunToEvent { forward } => follow_update::run_to_event(app, forward),
        Action::ExplainGo => crate::explain::update::go(app),
        Action::ToggleRayView => {
            app.toggle_ray_view();
            app.focus = Focus::Image;
        }
        Action::ResetRayView => {
            app.set_message("0 resets the 3D view's camera (v shows it)", false)
        }
        // Drags only orbit the 3D view.
        Action::Drag { .. } => {}
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
            // Kept even when wrong, so that ↑ in the next prompt brings it back to be fixed.
            if app.query.history.last() != Some(&text) {
                app.query.history.push(text.clone());
            }
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

/// How many lines either side of the definition the source pane's sideways scroll measures
/// for the longest line.
const SOURCE_SCROLL_REACH: u32 = 500;

/// Scrolls the source pane, within its file: no further up than its first line, down than
/// its last, or right than the longest line near the definition.
fn scroll_source(app: &mut App, lines: i32, columns: i32) {
    let shown = crate::ui::source_pane::target_span(app);
    let Some(file) = shown.and_then(|span| app.loaded.scene.sources.get(span.file)) else {
        app.set_message("no source to scroll: pick a ray that hit something", false);
        return;
    };
    // Bounds relative to the definition's line, so that a key pressed past an end is not
    // stored (the next press the other way moves at once). The longest line is looked for
    // near the definition only: a scene written by a program can have a million lines, and
    // this runs on every key.
    let line_count = file.line_count();
    let at = shown.map_or(1, |span| file.line_col(span.start).line);
    let near = at.saturating_sub(SOURCE_SCROLL_REACH).max(1)
        ..=at.saturating_add(SOURCE_SCROLL_REACH).min(line_count);
    let longest = near
        .map(|n| file.line_text(n).chars().count())
        .max()
        .unwrap_or(0);
    let scroll = &mut app.source_scroll;
    scroll.span = shown;
    let above = -i64::from(at);
    let below = i64::from(line_count) - i64::from(at);
    scroll.lines = (i64::from(scroll.lines) + i64::from(lines)).clamp(above, below) as i32;
    let columns = i64::from(scroll.columns) + i64::from(columns);
    scroll.columns = columns.clamp(0, longest.min(usize::from(u16::MAX)) as i64) as u16;
}

/// Esc leaves whatever the user is in, one thing at a time, and never quits (`q` does, as
/// in gitui and lazygit): a trace under way, a query under way, the query's matches, the
/// zoomed pane, the 3D view, the search.
fn cancel(app: &mut App) {
    if app.cancel_trace() {
        app.set_message("cancelled the trace", false);
    } else if app.query.cancel() {
        app.set_message("cancelled the query", false);
    } else if app.query.overlay.take().is_some() {
        app.set_message("cleared the query's matches", false);
    } else if app.zoomed {
        app.zoomed = false;
    } else if app.ray_view.take().is_some() {
        app.set_message("3D view closed (v opens it)", false);
    } else if app.search.take().is_some() {
        app.set_message("search ended", false);
    } else {
        app.set_message("Esc closes and leaves modes; q quits", false);
    }
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
            // The first row is the column header.
            let Some(row) = (row - tree_area.y).checked_sub(1) else {
                return;
            };
            let index = picked.tree.scroll() + usize::from(row);
            if let Some(&id) = picked.tree.visible().get(index) {
                if id != picked.tree.selected() {
                    picked.tree.select(id);
                    app.inspector_scroll = 0;
                    app.source_focus = None;
                }
            }
        }
    } else if panes.inspector.contains(position) {
        app.focus = Focus::Inspector;
    } else if panes.source.contains(position) {
        app.focus = Focus::Source;
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
    } else if panes.source.contains(position) {
        scroll_source(app, lines * 3, 0);
    }
}

/// Runs a tree navigation ([`crate::tree::update::with_tree`]).
fn tree(app: &mut App, navigate: impl FnOnce(&mut crate::tree::state::TreeView)) {
    crate::tree::update::with_tree(app, navigate);
}

fn scroll_inspector(app: &mut App, lines: i32) {
    if app.explain_open {
        return crate::explain::update::move_explain_selection(app, lines);
    }
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

/// `<` `>`: the previous or next frame of an animated scene, compiled by the reload worker
/// (requests merge, so holding the key compiles only the last frame asked for).
fn step_frame(app: &mut App, forward: bool) -> Vec<Effect> {
    let settings = &app.loaded.scene.settings;
    if !settings.is_animated() {
        app.set_message(
            "the scene is not animated (`settings { frames N }`): no other frame",
            false,
        );
        return Vec::new();
    }
    let range = settings.frame_range();
    let (first, last) = (*range.start(), *range.end());
    let current = app.frame.unwrap_or(first);
    let next = if forward {
        current.saturating_add(1).clamp(first, last)
    } else {
        current.saturating_sub(1).clamp(first, last)
    };
    if next == current {
        let end = if forward { "last" } else { "first" };
        app.set_message(
            format!("frame {current} is the {end} frame ({first} to {last})"),
            false,
        );
        return Vec::new();
    }
    app.frame = Some(next);
    app.reloading = true;
    app.set_message(format!("frame {next} of {first} to {last}"), false);
    vec![Effect::Reload]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::LoadedScene;
    use crate::heat_map::HeatMapKind;
    use crate::test_scene::{whitted_scene, GLASS_PIXEL};
    use ratatui::crossterm::event::KeyCode;
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

    #[test]
    fn angle_brackets_step_the_frames_of_an_animated_scene_and_stop_at_its_ends() {
        // A still: nothing to step to, and no reload.
        let mut still = app();
        assert_eq!(
            update(&mut still, Action::StepFrame { forward: true }),
            vec![]
        );
        assert!(still
            .message
            .as_ref()
            .unwrap()
            .text
            .contains("not animated"));
        assert_eq!(still.frame, None);

        let mut scene = whitted_scene().into_inner();
        scene.settings.first_frame = 4;
        scene.settings.frames = 3;
        let valid = whitted_ir::validate(scene).unwrap_or_else(|_| panic!("invalid"));
        let mut app = App::new(
            "scenes/whitted.scene".into(),
            LoadedScene::new(valid),
            Rect::new(0, 0, 120, 40),
            "/tmp/out".into(),
        );
        // From the first frame (4) back: already there.
        assert_eq!(
            update(&mut app, Action::StepFrame { forward: false }),
            vec![]
        );
        assert_eq!(app.frame, None);
        for expected in [5, 6] {
            assert_eq!(
                update(&mut app, Action::StepFrame { forward: true }),
                vec![Effect::Reload]
            );
            assert_eq!(app.frame, Some(expected));
        }
        assert_eq!(app.message.as_ref().unwrap().text, "frame 6 of 4 to 6");
        assert_eq!(
            update(&mut app, Action::StepFrame { forward: true }),
            vec![]
        );
        assert_eq!(app.frame, Some(6));
        assert_eq!(
            update(&mut app, Action::StepFrame { forward: false }),
            vec![Effect::Reload]
        );
        assert_eq!(app.frame, Some(5));
        assert_eq!(
            crate::action::action_for_key(
                ratatui::crossterm::event::KeyEvent::from(KeyCode::Char('>')),
                Focus::Image,
                false,
                false
            ),
            Some(Action::StepFrame { forward: true })
        );
    }

    fn picked_app() -> App {
        let mut app = app();
        app.cursor = GLASS_PIXEL;
        assert_eq!(update(&mut app, Action::TraceCursor), vec![Effect::Trace]);
        crate::test_scene::finish_trace(&mut app);
        app
    }

    #[test]
    fn the_source_pane_scrolls_within_its_file_and_a_new_definition_starts_unscrolled() {
        let mut app = picked_app();
        let glass = crate::ui::source_pane::target_span(&app).expect("the glass sphere's line");
        let up_down = |lines| Action::SourceScroll { lines, columns: 0 };
        update(&mut app, up_down(2));
        update(
            &mut app,
            Action::SourceScroll {
                lines: 0,
                columns: 8,
            },
        );
        assert_eq!(
            app.source_scroll,
            SourceScroll {
                span: Some(glass),
                lines: 2,
                columns: 8
            }
        );
        // No further left than the first column, nor right than the longest line.
        update(
            &mut app,
            Action::SourceScroll {
                lines: 0,
                columns: -100,
            },
        );
        assert_eq!(app.source_scroll.columns, 0);
        update(
            &mut app,
            Action::SourceScroll {
                lines: 0,
                columns: 10_000,
            },
        );
        let file = app.loaded.scene.sources.get(glass.file).unwrap();
        let longest = (1..=file.line_count())
            .map(|n| file.line_text(n).chars().count())
            .max()
            .unwrap();
        assert_eq!(usize::from(app.source_scroll.columns), longest);
        // Presses past the file's first line are not stored: the next press down moves.
        let at = file.line_col(glass.start).line as i32;
        update(&mut app, up_down(-1000));
        assert_eq!(app.source_scroll.lines, -at);
        update(&mut app, up_down(1));
        assert_eq!(app.source_scroll.lines, 1 - at);
        update(&mut app, Action::SourceScrollHome);
        assert_eq!((app.source_scroll.lines, app.source_scroll.columns), (0, 0));
        // Another ray's definition (the floor, hit by the reflected ray) starts unscrolled.
        update(&mut app, up_down(3));
        app.focus = Focus::Tree;
        for _ in 0..2 {
            update(&mut app, Action::TreeDown);
        }
        let shown = crate::ui::source_pane::target_span(&app);
        assert_ne!(shown, Some(glass));
        assert_eq!(
            app.source_scroll,
            SourceScroll {
                span: shown,
                lines: 0,
                columns: 0
            }
        );
    }

    #[test]
    fn tab_reaches_the_source_pane_and_z_zooms_it() {
        let mut app = picked_app();
        for _ in 0..3 {
            update(&mut app, Action::FocusNext);
        }
        assert_eq!(app.focus, Focus::Source);
        update(&mut app, Action::ToggleZoom);
        let panes = app.panes().expect("a layout");
        assert_eq!(panes.source.width, 120);
        assert!(panes.inspector.is_empty() && panes.image.is_empty());
        update(&mut app, Action::FocusNext);
        assert_eq!(app.focus, Focus::Image);
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
        // The first row is the header: a click there selects nothing.
        update(
            &mut app,
            Action::Click {
                column: tree.x + 3,
                row: tree.y,
            },
        );
        assert_eq!(app.picked.as_ref().unwrap().tree.selected(), 0);
        update(
            &mut app,
            Action::Click {
                column: tree.x + 3,
                row: tree.y + 3,
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
        assert_eq!(app.focus, Focus::Source);
        update(&mut app, Action::FocusNext);
        assert_eq!(app.focus, Focus::Image);
        update(&mut app, Action::FocusPrevious);
        assert_eq!(app.focus, Focus::Source);
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
        assert_eq!(app.message.as_ref().unwrap().text, "hit-point mark off");
        update(&mut app, Action::ToggleHitPoint);
        assert_eq!(app.message.as_ref().unwrap().text, "hit-point mark on");
    }

    /// At fit zoom an arrow moves the cursor one display cell: `scale` pixels (11 at
    /// 120x40, where a pixel step was 1/11 of a cell), and Shift one pixel.
    #[test]
    fn arrows_move_a_cell_at_fit_zoom_and_shift_moves_a_pixel() {
        let mut app = app();
        let scale = app.viewport().scale;
        assert!((10.5..11.5).contains(&scale), "{scale}");
        update(&mut app, Action::MoveCursorByCells { dx: 1, dy: 0 });
        assert_eq!(app.cursor, (331, 240));
        update(&mut app, Action::MoveCursorByCells { dx: 0, dy: -2 });
        assert_eq!(app.cursor, (331, 218));
        update(&mut app, Action::MoveCursor { dx: -1, dy: 1 });
        assert_eq!(app.cursor, (330, 219));
        // The drawn cursor moves one column per cell step.
        let area = app.image_area().unwrap();
        let before = app.viewport().cell_of(app.cursor.0, app.cursor.1, area);
        update(&mut app, Action::MoveCursorByCells { dx: 1, dy: 0 });
        let after = app.viewport().cell_of(app.cursor.0, app.cursor.1, area);
        assert_eq!(after.map(|c| c.0), before.map(|c| c.0 + 1));
        // Zoomed in past one pixel per cell, a cell step is one pixel.
        for _ in 0..5 {
            update(&mut app, Action::ZoomIn);
        }
        let cursor = app.cursor;
        update(&mut app, Action::MoveCursorByCells { dx: 1, dy: 0 });
        assert_eq!(app.cursor, (cursor.0 + 1, cursor.1));
    }

    #[test]
    fn z_zooms_the_focused_pane_tab_cycles_it_and_z_or_esc_restore() {
        let mut app = app();
        update(&mut app, Action::ToggleZoom);
        let body = Rect::new(0, 0, 120, 39);
        assert_eq!(app.panes().unwrap().image, body);
        assert_eq!(app.image_area(), Some(layout::inner(body)));
        update(&mut app, Action::FocusNext);
        let panes = app.panes().unwrap();
        assert_eq!((panes.tree, panes.image.is_empty()), (body, true));
        update(&mut app, Action::ToggleZoom);
        assert!(!app.zoomed);
        update(&mut app, Action::ToggleZoom);
        update(&mut app, Action::Cancel);
        assert!(!app.zoomed && !app.should_quit);
    }

    /// Keys act on the pane that shows: with the explanation (or the errors) in a pane's
    /// place, the keys of the pane it hides do nothing to it.
    #[test]
    fn keys_never_act_on_a_hidden_pane() {
        let mut app = picked_app();
        app.focus = Focus::Tree;
        update(&mut app, Action::ToggleExplain);
        assert_eq!(
            app.focus,
            Focus::Inspector,
            "x gives the explanation the keyboard"
        );
        update(&mut app, Action::ToggleZoom);
        assert_eq!(app.panes().unwrap().inspector, Rect::new(0, 0, 120, 39));
        update(&mut app, Action::InspectorScrollSideways(8));
        assert_eq!(app.inspector_columns, 0);
        update(&mut app, Action::ToggleExplain);
        update(&mut app, Action::InspectorScrollSideways(8));
        assert_eq!(app.inspector_columns, 8);

        // Another pane zoomed over the image: the image's keys leave it alone.
        app.focus = Focus::Tree;
        assert!(app.zoomed, "still zoomed from above");
        let view = app.view;
        for action in [
            Action::ZoomIn,
            Action::Fit,
            Action::Pan {
                columns: 4,
                rows: 0,
            },
        ] {
            update(&mut app, action);
            assert_eq!(app.view, view, "{action:?}");
        }
        assert!(app.message.as_ref().unwrap().text.contains("z shows"));
        update(&mut app, Action::ToggleZoom);
        update(&mut app, Action::ZoomIn);
        assert_ne!(app.view, view, "unzoomed, + zooms the image from the tree");

        app.errors = Some(crate::app::SceneErrors {
            diagnostics: Vec::new(),
            sources: whitted_ir::SourceMap::new(),
        });
        app.focus = Focus::Source;
        update(
            &mut app,
            Action::SourceScroll {
                lines: 3,
                columns: 8,
            },
        );
        assert_eq!((app.source_scroll.lines, app.source_scroll.columns), (0, 0));
    }

    fn search(app: &mut App, query: &str) {
        update(app, Action::StartSearch);
        assert!(app.search_prompt.is_some(), "the prompt opens");
        for c in query.chars() {
            update(app, Action::PromptKey(KeyEvent::from(KeyCode::Char(c))));
        }
        update(app, Action::PromptKey(KeyEvent::from(KeyCode::Enter)));
        assert!(app.search_prompt.is_none(), "Enter closes the prompt");
    }

    #[test]
    fn slash_finds_rays_by_kind_and_n_and_shift_n_step_through_the_matches() {
        let mut app = picked_app();
        // A collapsed parent is opened to show the match.
        app.picked.as_mut().unwrap().tree.left();
        assert_eq!(app.picked.as_ref().unwrap().tree.visible().len(), 1);
        search(&mut app, "transmitted");
        let tree = &app.picked.as_ref().unwrap().tree;
        let node = tree.selected_node().unwrap();
        assert_eq!((node.kind, node.depth), (RayKind::Transmitted, 1));
        assert!(tree.visible().contains(&tree.selected()));
        assert_eq!(app.focus, Focus::Tree);
        let count = app.search.as_ref().unwrap().matches.len();
        assert_eq!(
            app.message.as_ref().unwrap().text,
            format!("match 1 of {count} for `transmitted` (n / N: next / previous)")
        );
        update(&mut app, Action::SearchStep { forward: true });
        assert!(app.message.as_ref().unwrap().text.starts_with("match 2 of"));
        let second = app.picked.as_ref().unwrap().tree.selected();
        update(&mut app, Action::SearchStep { forward: false });
        update(&mut app, Action::SearchStep { forward: false });
        assert!(app
            .message
            .as_ref()
            .unwrap()
            .text
            .starts_with(&format!("match {count} of")));
        assert_ne!(app.picked.as_ref().unwrap().tree.selected(), second);
        // Esc ends the search; a query with no match says so and moves nothing.
        update(&mut app, Action::Cancel);
        assert!(app.search.is_none());
        let selected = app.picked.as_ref().unwrap().tree.selected();
        search(&mut app, "foo");
        assert_eq!(app.message.as_ref().unwrap().text, "no ray matches `foo`");
        assert_eq!(app.picked.as_ref().unwrap().tree.selected(), selected);
    }

    #[test]
    fn esc_in_the_prompt_closes_it_without_searching() {
        let mut app = picked_app();
        update(&mut app, Action::StartSearch);
        update(
            &mut app,
            Action::PromptKey(KeyEvent::from(KeyCode::Char('s'))),
        );
        update(&mut app, Action::PromptKey(KeyEvent::from(KeyCode::Esc)));
        assert!(app.search_prompt.is_none() && app.search.is_none());
        assert!(!app.should_quit);
        let mut untraced = self::app();
        update(&mut untraced, Action::StartSearch);
        assert!(untraced.search_prompt.is_none());
        assert!(untraced
            .message
            .as_ref()
            .unwrap()
            .text
            .contains("no ray tree"));
    }

    #[test]
    fn the_inspector_scrolls_sideways_but_not_left_of_its_start() {
        let mut app = app();
        update(&mut app, Action::InspectorScrollSideways(8));
        assert_eq!(app.inspector_columns, 8);
        update(&mut app, Action::InspectorScrollSideways(-20));
        assert_eq!(app.inspector_columns, 0);
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
    fn the_help_scrolls_no_further_than_its_last_line() {
        let mut app = app();
        app.area = Rect::new(0, 0, 80, 24);
        update(&mut app, Action::ToggleHelp);
        update(&mut app, Action::HelpScroll(100));
        let hidden = crate::action::KEY_HELP.len() + 2 - 24;
        assert_eq!(usize::from(app.help_scroll), hidden);
        update(&mut app, Action::HelpScroll(-1));
        assert_eq!(usize::from(app.help_scroll), hidden - 1);
        update(&mut app, Action::HelpScroll(-100));
        assert_eq!(app.help_scroll, 0);
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

    #[test]
    fn in_the_3d_view_arrows_orbit_zoom_pans_and_0_resets_to_the_scene_camera() {
        let mut app = picked_app();
        let scene_camera = app.loaded.scene.camera.clone();
        update(&mut app, Action::ToggleRayView);
        let view = app.ray_view.as_ref().expect("the 3D view is shown");
        assert_eq!(
            view.orbit.camera(),
            &scene_camera,
            "it starts at the scene's camera"
        );
        let hit = app
            .picked
            .as_ref()
            .unwrap()
            .tree
            .node(0)
            .unwrap()
            .hit
            .clone()
            .unwrap();
        let target = view.orbit.target();
        assert!(
            (target.x - f64::from(hit.point[0])).abs() < 1e-6,
            "it orbits the hit"
        );
        let cursor = app.cursor;
        update(&mut app, Action::MoveCursor { dx: 1, dy: 0 });
        update(&mut app, Action::ZoomIn);
        update(
            &mut app,
            Action::Pan {
                columns: 4,
                rows: 0,
            },
        );
        assert_eq!(app.cursor, cursor, "the cursor stays");
        let moved = app.ray_view.as_ref().unwrap().orbit.camera().clone();
        assert_ne!(moved, scene_camera);
        update(&mut app, Action::ResetRayView);
        assert_eq!(app.ray_view.as_ref().unwrap().orbit.camera(), &scene_camera);
        update(&mut app, Action::ToggleRayView);
        assert!(app.ray_view.is_none());
        update(&mut app, Action::MoveCursor { dx: 1, dy: 0 });
        assert_eq!(
            app.cursor,
            (cursor.0 + 1, cursor.1),
            "the image's keys are back"
        );
    }

    #[test]
    fn a_drag_that_starts_in_the_3d_view_orbits_it_and_a_click_there_picks_nothing() {
        let mut app = picked_app();
        update(&mut app, Action::ToggleRayView);
        let image = app.image_area().unwrap();
        let tree = layout::inner(app.panes().unwrap().tree);
        let start = app.ray_view.as_ref().unwrap().orbit.camera().clone();
        // A drag from outside the pane does nothing.
        update(
            &mut app,
            Action::Click {
                column: tree.x + 1,
                row: tree.y + 1,
            },
        );
        update(
            &mut app,
            Action::Drag {
                column: image.x + 9,
                row: image.y + 3,
            },
        );
        assert_eq!(app.ray_view.as_ref().unwrap().orbit.camera(), &start);
        let requests = app.trace_requests;
        update(
            &mut app,
            Action::Click {
                column: image.x + 5,
                row: image.y + 3,
            },
        );
        assert_eq!(app.trace_requests, requests, "no pixel is picked");
        update(
            &mut app,
            Action::Drag {
                column: image.x + 9,
                row: image.y + 3,
            },
        );
        let dragged = app.ray_view.as_ref().unwrap().orbit.camera().clone();
        assert_ne!(dragged, start);
        assert!(
            (dragged.eye.y - start.eye.y).abs() < 1e-9,
            "a sideways drag only yaws"
        );
        // The wheel zooms towards the target.
        let target = app.ray_view.as_ref().unwrap().orbit.target();
        let distance =
            |app: &App| (app.ray_view.as_ref().unwrap().orbit.camera().eye - target).length();
        let before = distance(&app);
        update(
            &mut app,
            Action::Wheel {
                column: image.x + 2,
                row: image.y + 2,
                lines: -1,
            },
        );
        assert!(distance(&app) < before);
    }
}
