//! The debugger's state: the scene and its render, the image view and cursor, the picked
//! pixel's ray tree, overlays, focus, and what the status line says. Changed only through
//! [`crate::update::update`] (user actions) and the `apply_*` methods here (background
//! results); drawing reads it and never changes it.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use ratatui::layout::Rect;
use whitted_ir::{Diagnostic, SourceMap, ValidScene};
use whitted_tracer::ray_tree::{trace_pixel, SampleChoice};
use whitted_tracer::{PixelStats, PreparedScene, RenderOptions, RenderStats, TileResult};

use crate::action::Focus;
use crate::framebuffer::Framebuffer;
use crate::heat_map::{HeatMap, HeatMapKind};
use crate::image_view::{ColorDepth, Viewport};
use crate::layout::{self, Panes};
use crate::tree_view::TreeView;

/// A scene ready to render and trace: the IR (names, spans, sources) and its prepared form.
#[derive(Clone)]
pub struct LoadedScene {
    pub scene: Arc<ValidScene>,
    pub prepared: Arc<PreparedScene>,
}

impl LoadedScene {
    pub fn new(scene: ValidScene) -> LoadedScene {
        let prepared = PreparedScene::new(&scene);
        LoadedScene {
            scene: Arc::new(scene),
            prepared: Arc::new(prepared),
        }
    }
}

/// A scene that failed to compile on reload: its diagnostics and the files they point into.
#[derive(Clone, Debug)]
pub struct SceneErrors {
    pub diagnostics: Vec<Diagnostic>,
    pub sources: SourceMap,
}

impl SceneErrors {
    pub fn error_count(&self) -> usize {
        self.diagnostics.iter().filter(|d| d.is_error()).count()
    }
}

/// Where the background render is.
#[derive(Clone, Debug, PartialEq)]
pub enum RenderState {
    /// Tiles are streaming in; `pixels` counts those received.
    Rendering {
        generation: u64,
        pixels: u64,
    },
    Done {
        stats: RenderStats,
    },
    /// A reload cancelled it, or the renderer stopped.
    Stopped,
}

/// The picked pixel's tree and how long it took to appear.
#[derive(Clone, Debug)]
pub struct Picked {
    pub tree: TreeView,
    /// Recording the tree (`trace_pixel`).
    pub trace_time: Duration,
    /// From the key or click that picked it to the frame showing it on the terminal,
    /// measured by the event loop (`None` until that frame is drawn, and in tests).
    pub on_screen_after: Option<Duration>,
}

/// Which definition the source pane shows for the selected ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SourceTarget {
    Object,
    Material,
}

/// How the image pane maps pixels to cells: fitted to the pane, or a zoomed/panned view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    Fit,
    Manual(Viewport),
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Message {
    pub text: String,
    pub is_error: bool,
}

/// What the event loop must do after a state change: work the state cannot do itself.
#[derive(Clone, Debug, PartialEq)]
pub enum Effect {
    /// Compile the scene again (on the reload worker).
    Reload,
    /// Render the current scene (cancelling any render under way).
    StartRender,
    /// Write `contents` to `path`, then report through [`App::apply_export`].
    Export { path: PathBuf, contents: String },
}

pub struct App {
    pub scene_name: String,
    pub loaded: LoadedScene,
    pub options: RenderOptions,
    pub image: Framebuffer,
    pub render: RenderState,
    /// Per-pixel statistics of the last finished render of this scene.
    pub pixel_stats: Option<Arc<Vec<PixelStats>>>,
    /// The heat map shown over the image, if any.
    pub overlay: Option<HeatMapKind>,
    pub heat_map: Option<HeatMap>,
    pub show_hit_point: bool,
    pub view: View,
    pub cursor: (u32, u32),
    pub focus: Focus,
    pub picked: Option<Picked>,
    pub source_target: SourceTarget,
    pub inspector_scroll: u16,
    pub help_open: bool,
    /// Set after a failed reload, cleared by a good one.
    pub errors: Option<SceneErrors>,
    pub reloading: bool,
    pub message: Option<Message>,
    /// The terminal's area, for layout.
    pub area: Rect,
    pub color_depth: ColorDepth,
    pub export_dir: PathBuf,
    pub should_quit: bool,
    /// How many pixels have been traced: the event loop sees a new pick by its change.
    pub traces: u64,
}

impl App {
    pub fn new(scene_name: String, loaded: LoadedScene, area: Rect, export_dir: PathBuf) -> App {
        let options = RenderOptions::from_settings(&loaded.scene.settings);
        let image = Framebuffer::new(options.width, options.height);
        let cursor = (options.width / 2, options.height / 2);
        App {
            scene_name,
            loaded,
            options,
            image,
            render: RenderState::Stopped,
            pixel_stats: None,
            overlay: None,
            heat_map: None,
            show_hit_point: true,
            view: View::Fit,
            cursor,
            focus: Focus::Image,
            picked: None,
            source_target: SourceTarget::Object,
            inspector_scroll: 0,
            help_open: false,
            errors: None,
            reloading: false,
            message: None,
            area,
            color_depth: ColorDepth::TrueColor,
            export_dir,
            should_quit: false,
            traces: 0,
        }
    }

    pub fn image_size(&self) -> (u32, u32) {
        (self.options.width, self.options.height)
    }

    /// The panes for the current terminal size (`None` when it is too small).
    pub fn panes(&self) -> Option<Panes> {
        layout::panes(self.area, self.image_size(), self.errors.is_some())
    }

    /// The area the image is drawn in (inside the pane's border).
    pub fn image_area(&self) -> Option<Rect> {
        self.panes().map(|p| layout::inner(p.image))
    }

    /// The rows the tree pane shows.
    pub fn tree_rows(&self) -> usize {
        self.panes()
            .map_or(1, |p| usize::from(layout::inner(p.tree).height))
    }

    pub fn viewport(&self) -> Viewport {
        match self.view {
            View::Manual(viewport) => viewport,
            View::Fit => {
                let area = self.image_area().unwrap_or(Rect::new(0, 0, 1, 1));
                Viewport::fit(self.options.width, self.options.height, area)
            }
        }
    }

    pub fn set_message(&mut self, text: impl Into<String>, is_error: bool) {
        self.message = Some(Message {
            text: text.into(),
            is_error,
        });
    }

    /// Records the ray tree of the pixel under the cursor (every sample of it).
    pub fn trace_cursor(&mut self) {
        let (x, y) = self.cursor;
        let started = Instant::now();
        let traced = trace_pixel(
            &self.loaded.prepared,
            &self.loaded.scene,
            &self.options,
            x,
            y,
            SampleChoice::All,
        );
        let trace_time = started.elapsed();
        match traced {
            Ok(tree) => {
                let mut view = TreeView::new(tree);
                view.keep_selection_in_view(self.tree_rows());
                self.picked = Some(Picked {
                    tree: view,
                    trace_time,
                    on_screen_after: None,
                });
                self.inspector_scroll = 0;
                self.traces += 1;
            }
            Err(error) => self.set_message(error.to_string(), true),
        }
    }

    /// Called by the event loop when it starts a render with this generation number.
    pub fn render_started(&mut self, generation: u64) {
        self.render = RenderState::Rendering {
            generation,
            pixels: 0,
        };
    }

    fn is_current(&self, generation: u64) -> bool {
        matches!(self.render, RenderState::Rendering { generation: g, .. } if g == generation)
    }

    /// A finished tile of render `generation` (tiles of older renders are dropped).
    pub fn apply_tile(&mut self, generation: u64, tile: &TileResult) {
        if let RenderState::Rendering {
            generation: current,
            pixels,
        } = &mut self.render
        {
            if *current == generation {
                self.image.put_tile(tile);
                *pixels += u64::from(tile.width) * u64::from(tile.height);
            }
        }
    }

    /// The end of render `generation`: its statistics, or `None` when it was cancelled.
    pub fn apply_render_done(
        &mut self,
        generation: u64,
        result: Option<(RenderStats, Vec<PixelStats>)>,
    ) {
        if !self.is_current(generation) {
            return;
        }
        match result {
            Some((stats, pixel_stats)) => {
                self.render = RenderState::Done { stats };
                self.pixel_stats = Some(Arc::new(pixel_stats));
                self.refresh_heat_map();
            }
            None => self.render = RenderState::Stopped,
        }
    }

    /// Rebuilds the overlay's heat map from the latest statistics.
    pub fn refresh_heat_map(&mut self) {
        let (width, height) = self.image_size();
        self.heat_map = match (self.overlay, &self.pixel_stats) {
            (Some(kind), Some(stats)) => HeatMap::new(kind, width, height, stats),
            _ => None,
        };
    }

    /// The reload worker's result: a new scene (start rendering it, re-trace the picked
    /// pixel) or errors (show them, keep the last good image and tree).
    pub fn apply_reload(
        &mut self,
        result: Result<(LoadedScene, usize), SceneErrors>,
    ) -> Vec<Effect> {
        self.reloading = false;
        match result {
            Err(errors) => {
                let count = errors.error_count();
                self.set_message(
                    format!(
                        "{} has {count} error{}; showing the last good image",
                        self.scene_name,
                        if count == 1 { "" } else { "s" }
                    ),
                    true,
                );
                self.errors = Some(errors);
                Vec::new()
            }
            Ok((loaded, warnings)) => {
                self.errors = None;
                self.loaded = loaded;
                let old_size = self.image_size();
                self.options = RenderOptions::from_settings(&self.loaded.scene.settings);
                let size = self.image_size();
                if size != old_size {
                    self.image = Framebuffer::new(size.0, size.1);
                    self.view = View::Fit;
                    self.cursor = (
                        self.cursor.0.min(size.0.saturating_sub(1)),
                        self.cursor.1.min(size.1.saturating_sub(1)),
                    );
                }
                self.pixel_stats = None;
                self.heat_map = None;
                self.retrace_picked();
                let note = match warnings {
                    0 => String::new(),
                    1 => " (1 warning)".to_string(),
                    n => format!(" ({n} warnings)"),
                };
                self.set_message(format!("reloaded {}{note}", self.scene_name), false);
                vec![Effect::StartRender]
            }
        }
    }

    /// Traces the picked pixel again in the current scene, keeping the tree's selection and
    /// open nodes where the new tree has the same shape.
    fn retrace_picked(&mut self) {
        let Some(previous) = self.picked.take() else {
            return;
        };
        let [x, y] = previous.tree.tree().pixel;
        let started = Instant::now();
        let traced = trace_pixel(
            &self.loaded.prepared,
            &self.loaded.scene,
            &self.options,
            x,
            y,
            SampleChoice::All,
        );
        if let Ok(tree) = traced {
            let mut view = TreeView::new_like(tree, &previous.tree);
            view.keep_selection_in_view(self.tree_rows());
            self.picked = Some(Picked {
                tree: view,
                trace_time: started.elapsed(),
                on_screen_after: None,
            });
        }
    }

    /// The result of writing an export.
    pub fn apply_export(&mut self, result: Result<PathBuf, String>) {
        match result {
            Ok(path) => {
                let pixel = self
                    .picked
                    .as_ref()
                    .map(|p| p.tree.tree().pixel)
                    .unwrap_or_default();
                self.set_message(
                    format!(
                        "wrote the ray tree of ({}, {}) to {}",
                        pixel[0],
                        pixel[1],
                        path.display()
                    ),
                    false,
                );
            }
            Err(error) => self.set_message(format!("cannot export: {error}"), true),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::{whitted_scene, GLASS_PIXEL};
    use whitted_ir::{Diagnostic, Severity};
    use whitted_tracer::RayKind;

    fn app() -> App {
        App::new(
            "scenes/whitted.scene".into(),
            LoadedScene::new(whitted_scene()),
            Rect::new(0, 0, 120, 40),
            "/tmp".into(),
        )
    }

    fn tile(x: u32, y: u32, value: f32) -> TileResult {
        TileResult {
            x,
            y,
            width: 2,
            height: 2,
            pixels: vec![[value; 3]; 4],
        }
    }

    #[test]
    fn tiles_of_the_current_render_fill_the_image_and_stale_ones_are_dropped() {
        let mut app = app();
        app.render_started(2);
        app.apply_tile(2, &tile(0, 0, 0.5));
        app.apply_tile(1, &tile(4, 4, 0.5));
        assert_eq!(app.image.linear(1, 1), Some([0.5; 3]));
        assert_eq!(app.image.linear(4, 4), None);
        assert_eq!(
            app.render,
            RenderState::Rendering {
                generation: 2,
                pixels: 4
            }
        );
        // The end of an older render changes nothing.
        app.apply_render_done(1, Some((RenderStats::default(), Vec::new())));
        assert!(matches!(app.render, RenderState::Rendering { .. }));
        app.apply_render_done(2, None);
        assert_eq!(app.render, RenderState::Stopped);
    }

    #[test]
    fn a_finished_render_brings_the_statistics_for_overlays() {
        let mut app = app();
        app.overlay = Some(HeatMapKind::DeepestLevel);
        app.render_started(1);
        let stats = vec![PixelStats::default(); 640 * 480];
        app.apply_render_done(1, Some((RenderStats::default(), stats)));
        assert!(matches!(app.render, RenderState::Done { .. }));
        assert!(app.heat_map.is_some());
    }

    #[test]
    fn a_good_reload_renders_again_and_retraces_the_picked_pixel() {
        let mut app = app();
        app.cursor = GLASS_PIXEL;
        app.trace_cursor();
        if let Some(picked) = &mut app.picked {
            let transmitted = (0..picked.tree.len())
                .find(|&id| {
                    picked
                        .tree
                        .node(id)
                        .is_some_and(|n| n.kind == RayKind::Transmitted)
                })
                .unwrap();
            picked.tree.select(transmitted);
        }
        let selected = app.picked.as_ref().map(|p| p.tree.selected());
        app.reloading = true;
        let effects = app.apply_reload(Ok((LoadedScene::new(whitted_scene()), 0)));
        assert_eq!(effects, vec![Effect::StartRender]);
        assert!(!app.reloading);
        assert!(app.errors.is_none());
        assert_eq!(app.picked.as_ref().map(|p| p.tree.selected()), selected);
        assert_eq!(
            app.message.as_ref().unwrap().text,
            "reloaded scenes/whitted.scene"
        );
    }

    #[test]
    fn a_failed_reload_keeps_the_scene_and_shows_errors_until_a_good_one() {
        let mut app = app();
        app.render_started(1);
        app.apply_tile(1, &tile(0, 0, 0.25));
        let errors = SceneErrors {
            diagnostics: vec![
                Diagnostic::new(Severity::Error, "one", None),
                Diagnostic::new(Severity::Warning, "two", None),
            ],
            sources: SourceMap::new(),
        };
        assert!(app.apply_reload(Err(errors)).is_empty());
        assert_eq!(app.errors.as_ref().map(SceneErrors::error_count), Some(1));
        assert_eq!(app.image.linear(0, 0), Some([0.25; 3]));
        let message = app.message.clone().unwrap();
        assert!(
            message.is_error && message.text.contains("1 error;"),
            "{message:?}"
        );
        app.apply_reload(Ok((LoadedScene::new(whitted_scene()), 2)));
        assert!(app.errors.is_none());
        assert_eq!(
            app.message.as_ref().unwrap().text,
            "reloaded scenes/whitted.scene (2 warnings)"
        );
    }

    #[test]
    fn a_reload_that_changes_the_image_size_refits_and_keeps_the_cursor_inside() {
        let mut app = app();
        app.cursor = (600, 400);
        app.view = View::Manual(app.viewport());
        let mut smaller = whitted_scene().into_inner();
        smaller.settings.width = 320;
        smaller.settings.height = 240;
        let smaller = whitted_ir::validate(smaller).unwrap();
        app.apply_reload(Ok((LoadedScene::new(smaller), 0)));
        assert_eq!(app.image_size(), (320, 240));
        assert_eq!(app.image.width(), 320);
        assert_eq!(app.cursor, (319, 239));
        assert_eq!(app.view, View::Fit);
    }

    #[test]
    fn tracing_outside_the_image_is_an_error_message_not_a_panic() {
        let mut app = app();
        app.cursor = (9999, 0);
        app.trace_cursor();
        assert!(app.picked.is_none());
        assert!(app.message.as_ref().unwrap().is_error);
    }
}
