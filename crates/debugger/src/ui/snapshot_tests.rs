//! Screen snapshots of whole frames (ratatui's TestBackend, insta): the layout at the usual
//! sizes, a picked pixel with its tree, every pane focused and zoomed at 80x24 and 120x40,
//! the search prompt, the help, a failed reload, a terminal too small.
//! Timings that vary from run to run are pinned before drawing.

use std::time::Duration;

use insta::assert_snapshot;
use ratatui::backend::TestBackend;
use ratatui::crossterm::event::{KeyCode, KeyEvent};
use ratatui::layout::Rect;
use ratatui::Terminal;
use whitted_ir::{Diagnostic, SourceFile, SourceMap, Span};
use whitted_tracer::{render_with_pixel_stats, NoObserver, RayKind, TileResult};

use crate::action::{Action, Focus};
use crate::app::{App, LoadedScene, SceneErrors};
use crate::heat_map::HeatMapKind;
use crate::test_scene::{whitted_scene, GLASS_PIXEL};
use crate::update::update;

/// The app after a finished render of scenes/whitted.scene in a `width × height` terminal.
fn rendered_app(width: u16, height: u16) -> App {
    let mut app = App::new(
        "scenes/whitted.scene".into(),
        LoadedScene::new(whitted_scene()),
        Rect::new(0, 0, width, height),
        "/tmp".into(),
    );
    let (image, mut stats, pixel_stats) =
        render_with_pixel_stats(&app.loaded.prepared, &app.options, &NoObserver)
            .expect("not cancelled");
    stats.render_seconds = 0.25;
    app.render_started(1);
    app.apply_tile(
        1,
        &TileResult {
            x: 0,
            y: 0,
            width: image.width,
            height: image.height,
            pixels: image.pixels,
        },
    );
    app.apply_render_done(1, Some((stats, pixel_stats)));
    app
}

fn pick_glass_pixel(app: &mut App) {
    app.cursor = GLASS_PIXEL;
    update(app, Action::TraceCursor);
    crate::test_scene::finish_trace(app);
    if let Some(picked) = &mut app.picked {
        picked.trace_time = Duration::from_micros(60);
    }
}

fn draw(app: &App) -> Terminal<TestBackend> {
    let mut terminal =
        Terminal::new(TestBackend::new(app.area.width, app.area.height)).expect("a test terminal");
    terminal
        .draw(|frame| frame.render_widget(app, frame.area()))
        .expect("drawing to a test terminal");
    terminal
}

#[test]
fn start_screen_at_120x40() {
    let app = rendered_app(120, 40);
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn glass_pixel_walked_to_its_transmitted_ray_at_120x40() {
    let mut app = rendered_app(120, 40);
    pick_glass_pixel(&mut app);
    update(&mut app, Action::FocusNext);
    assert_eq!(app.focus, Focus::Tree);
    while app
        .picked
        .as_ref()
        .and_then(|p| p.tree.selected_node())
        .is_some_and(|n| n.kind != RayKind::Transmitted)
    {
        update(&mut app, Action::TreeDown);
    }
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn glass_pixel_at_80x24() {
    let mut app = rendered_app(80, 24);
    pick_glass_pixel(&mut app);
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn rays_per_pixel_overlay_and_material_source() {
    let mut app = rendered_app(120, 40);
    pick_glass_pixel(&mut app);
    update(&mut app, Action::ToggleOverlay(HeatMapKind::RaysPerPixel));
    update(&mut app, Action::ToggleSourceTarget);
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn help_at_80x24() {
    let mut app = rendered_app(80, 24);
    update(&mut app, Action::ToggleHelp);
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn failed_reload_keeps_the_image_and_shows_the_errors() {
    let mut app = rendered_app(120, 40);
    pick_glass_pixel(&mut app);
    let mut sources = SourceMap::new();
    let text = "sphere \"glass sphere\" { center <-0.75, 1.1, -1.2> radius -1 material glass }\n";
    let file = sources.add(SourceFile::new("scenes/whitted.scene", text));
    let start = text.find("-1 ").expect("the radius");
    let errors = SceneErrors {
        diagnostics: vec![Diagnostic::error(
            "a sphere's radius must be positive",
            Span::new(file, start, start + 2),
        )
        .with_label("this radius is -1")
        .with_hint("use a radius above 0")],
        sources,
    };
    let effects = app.apply_reload(Err(errors));
    assert!(effects.is_empty(), "nothing is re-rendered");
    assert!(
        app.image.linear(0, 0).is_some(),
        "the last good image stays"
    );
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn a_terminal_too_small_says_so() {
    let app = rendered_app(40, 10);
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn source_pane_shows_the_instantiation_stack_of_a_bead_made_by_a_call_in_a_loop() {
    use crate::test_provenance_scene::{provenance_scene, BEAD_PIXEL, MAIN_PATH};
    let mut app = App::new(
        MAIN_PATH.into(),
        LoadedScene::new(provenance_scene()),
        Rect::new(0, 0, 120, 40),
        "/tmp".into(),
    );
    app.cursor = BEAD_PIXEL;
    update(&mut app, Action::TraceCursor);
    crate::test_scene::finish_trace(&mut app);
    if let Some(picked) = &mut app.picked {
        picked.trace_time = Duration::from_micros(60);
    }
    let hit = app
        .picked
        .as_ref()
        .and_then(|p| p.tree.selected_node())
        .and_then(|node| node.hit.as_ref())
        .expect("the camera ray hits a bead");
    assert_eq!((hit.leaf.label.as_str(), hit.leaf.handle), ("bead 7", 19));
    let screen = draw(&app);
    let text: String = screen
        .backend()
        .buffer()
        .content()
        .iter()
        .map(|cell| cell.symbol())
        .collect();
    for step in [
        "i = 7  scenes/provenance/lib.scene:6:5",
        "ring(12, 2)  scenes/provenance/main.scene:12:5",
        "k = 1  scenes/provenance/main.scene:11:1",
        "import  scenes/provenance/main.scene:5:1",
    ] {
        assert!(text.contains(step), "the source pane shows `{step}`");
    }
    assert_snapshot!(screen.backend());
}

/// The glass pixel with its explanation in the inspector's place, the second entry selected.
fn explained_glass_pixel(width: u16, height: u16) -> App {
    let mut app = rendered_app(width, height);
    pick_glass_pixel(&mut app);
    update(&mut app, Action::ToggleExplain);
    assert_eq!(app.focus, Focus::Inspector, "x gives it the keyboard");
    update(&mut app, Action::InspectorScroll(1));
    app
}

#[test]
fn explanation_pane_at_120x40() {
    let app = explained_glass_pixel(120, 40);
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn explanation_pane_at_80x24() {
    let app = explained_glass_pixel(80, 24);
    assert_snapshot!(draw(&app).backend());
}

/// The glass pixel of scenes/whitted.scene with the most rays (16, of them 6 light: a
/// scan of the image every 10 pixels), stepped three rays on in trace order so that the
/// running colour shows under the tree.
fn collapsed_busy_pixel(width: u16, height: u16) -> App {
    let mut app = rendered_app(width, height);
    app.cursor = BUSY_PIXEL;
    update(&mut app, Action::TraceCursor);
    crate::test_scene::finish_trace(&mut app);
    if let Some(picked) = &mut app.picked {
        picked.trace_time = Duration::from_micros(60);
    }
    app.focus = Focus::Tree;
    for _ in 0..3 {
        update(&mut app, Action::Step { forward: true });
    }
    app
}

const BUSY_PIXEL: (u32, u32) = (370, 250);

#[test]
fn collapsed_tree_while_stepping_at_120x40() {
    let app = collapsed_busy_pixel(120, 40);
    let tree = &app.picked.as_ref().expect("a tree").tree;
    assert_eq!((tree.hidden_count(), tree.len()), (6, 16));
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn collapsed_tree_while_stepping_at_80x24() {
    let app = collapsed_busy_pixel(80, 24);
    assert_snapshot!(draw(&app).backend());
}

/// The glass pixel's rays in the 3D view, orbited 60° to the right and 15° up, with the
/// backdrop rendered here (synchronously), so the frame is the same on every run.
fn glass_pixel_in_3d(width: u16, height: u16) -> App {
    let mut app = rendered_app(width, height);
    pick_glass_pixel(&mut app);
    update(&mut app, Action::ToggleRayView);
    for _ in 0..12 {
        update(&mut app, Action::MoveCursor { dx: 1, dy: 0 });
    }
    for _ in 0..3 {
        update(&mut app, Action::MoveCursor { dx: 0, dy: -1 });
    }
    assert_eq!(
        app.cursor, GLASS_PIXEL,
        "arrows orbit the view, not the cursor"
    );
    let job = app.backdrop_job().expect("a backdrop to render");
    app.apply_backdrop(job.run());
    assert!(app.backdrop_job().is_none(), "the backdrop is current");
    app
}

/// The foreground colours of the braille cells in the image pane.
fn braille_colors(app: &App, terminal: &Terminal<TestBackend>) -> Vec<ratatui::style::Color> {
    let pane = app.panes().expect("a layout").image;
    let buffer = terminal.backend().buffer();
    let mut colors = Vec::new();
    for y in pane.top()..pane.bottom() {
        for x in pane.left()..pane.right() {
            let cell = &buffer[(x, y)];
            if cell
                .symbol()
                .chars()
                .next()
                .is_some_and(|c| ('\u{2801}'..='\u{28ff}').contains(&c))
            {
                colors.push(cell.fg);
            }
        }
    }
    colors
}

#[test]
fn glass_pixel_rays_in_3d_from_an_orbited_camera_at_120x40() {
    use ratatui::style::Color;
    let app = glass_pixel_in_3d(120, 40);
    let terminal = draw(&app);
    let colors = braille_colors(&app, &terminal);
    // The selected camera ray (magenta), reflected (cyan), transmitted (orange) and shadow
    // rays, lit (green) and blocked (red), each drawn somewhere.
    for (name, color) in [
        ("selected", Color::Rgb(255, 0, 255)),
        ("reflected", Color::Rgb(0, 230, 255)),
        ("transmitted", Color::Rgb(255, 170, 0)),
        ("lit shadow", Color::Rgb(40, 255, 40)),
        ("blocked shadow", Color::Rgb(255, 40, 40)),
    ] {
        assert!(colors.contains(&color), "no {name} ray drawn: {colors:?}");
    }
    assert_snapshot!(terminal.backend());
}

#[test]
fn glass_pixel_rays_in_3d_from_an_orbited_camera_at_80x24() {
    let app = glass_pixel_in_3d(80, 24);
    let terminal = draw(&app);
    assert!(braille_colors(&app, &terminal).len() > 10);
    assert_snapshot!(terminal.backend());
}

/// The glass pixel picked, its transmitted ray found with `/transmitted` (the tree focused,
/// the parent opened), in a `width × height` terminal.
fn transmitted_ray_found(width: u16, height: u16) -> App {
    let mut app = rendered_app(width, height);
    pick_glass_pixel(&mut app);
    update(&mut app, Action::StartSearch);
    for c in "transmitted".chars() {
        update(
            &mut app,
            Action::PromptKey(KeyEvent::from(KeyCode::Char(c))),
        );
    }
    update(&mut app, Action::PromptKey(KeyEvent::from(KeyCode::Enter)));
    assert_eq!(app.focus, Focus::Tree);
    app
}

/// Every pane focused, and zoomed, at the small and middle sizes: the focused pane
/// gets the room (at 80x24), its border is thick and its title reversed.
#[test]
fn every_pane_focused_and_zoomed_at_80x24_and_120x40() {
    for (width, height) in [(80, 24), (120, 40)] {
        let mut app = transmitted_ray_found(width, height);
        for focus in [Focus::Tree, Focus::Inspector, Focus::Source, Focus::Image] {
            app.focus = focus;
            let name = format!("{focus:?}_focused_at_{width}x{height}").to_lowercase();
            assert_snapshot!(name, draw(&app).backend());
        }
        update(&mut app, Action::ToggleZoom);
        for focus in [Focus::Image, Focus::Tree, Focus::Inspector, Focus::Source] {
            assert_eq!(app.focus, focus, "Tab cycles the zoomed pane");
            let name = format!("{focus:?}_zoomed_at_{width}x{height}").to_lowercase();
            assert_snapshot!(name, draw(&app).backend());
            update(&mut app, Action::FocusNext);
        }
    }
}

#[test]
fn the_inspector_scrolled_sideways_keeps_its_header_over_its_columns_at_80x24() {
    let mut app = transmitted_ray_found(80, 24);
    update(&mut app, Action::FocusNext);
    assert_eq!(app.focus, Focus::Inspector);
    update(&mut app, Action::InspectorScrollSideways(16));
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn the_search_prompt_on_the_status_line() {
    for (width, height) in [(80, 24), (120, 40)] {
        let mut app = rendered_app(width, height);
        pick_glass_pixel(&mut app);
        update(&mut app, Action::StartSearch);
        for c in "glass".chars() {
            update(
                &mut app,
                Action::PromptKey(KeyEvent::from(KeyCode::Char(c))),
            );
        }
        update(&mut app, Action::PromptKey(KeyEvent::from(KeyCode::Left)));
        let name = format!("search_prompt_at_{width}x{height}");
        assert_snapshot!(name, draw(&app).backend());
    }
}

#[test]
fn help_at_120x40_and_scrolled_at_80x24() {
    let mut app = rendered_app(120, 40);
    update(&mut app, Action::ToggleHelp);
    assert_snapshot!("help_at_120x40", draw(&app).backend());
    let mut app = rendered_app(80, 24);
    update(&mut app, Action::ToggleHelp);
    update(&mut app, Action::HelpScroll(10));
    assert_snapshot!("help_scrolled_at_80x24", draw(&app).backend());
}

/// The what-if popup on the glass pixel after changing the glass's ior to 1.
fn what_if_on_glass(width: u16, height: u16) -> App {
    use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    let mut app = rendered_app(width, height);
    pick_glass_pixel(&mut app);
    update(&mut app, Action::WhatIf);
    let key = |code| Action::PromptKey(KeyEvent::new(code, KeyModifiers::NONE));
    update(&mut app, key(KeyCode::Enter));
    for code in [KeyCode::Backspace, KeyCode::Char('0')] {
        update(&mut app, key(code));
    }
    let effects = update(&mut app, key(KeyCode::Enter));
    assert_eq!(effects, vec![crate::app::Effect::WhatIfTrace]);
    let what_if = app.what_if.as_mut().expect("the popup");
    let job = what_if.take_job().expect("a re-trace");
    what_if.apply(job.run());
    app
}

#[test]
fn what_if_glass_ior_at_80x24() {
    let app = what_if_on_glass(80, 24);
    assert_snapshot!(draw(&app).backend());
}

#[test]
fn what_if_glass_ior_at_120x40() {
    let app = what_if_on_glass(120, 40);
    assert_snapshot!(draw(&app).backend());
}
