//! The debugger's state: the scene and its render, the image view and cursor, the picked
//! pixel's ray tree, overlays, focus, and what the status line says. Changed only through
//! [`crate::update::update`] (user actions) and the `apply_*` methods here (background
//! results); drawing reads it and never changes it.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use ratatui::layout::Rect;
use whitted_ir::{Diagnostic, SourceMap, ValidScene};
use whitted_tracer::{PixelStats, PreparedScene, RenderOptions, RenderStats, TileResult};

use crate::action::Focus;
use crate::framebuffer::Framebuffer;
use crate::heat_map::{HeatMap, HeatMapKind};
use crate::image::{ColorDepth, Viewport};
use crate::layout::{self, Arrangement, Panes};
use crate::line_input::LineInput;
use crate::query_job::QueryState;
use crate::ray_view::state::{BackdropJob, BackdropRendered, RayViewState};
use crate::search::state::Search;
use crate::trace_job::{Explained, TraceFailure, TraceJob, Traced};
use crate::tree::state::TreeView;
use crate::what_if::state::WhatIf;

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
    /// The trace request that recorded the tree: its explanation arrives with this number.
    pub generation: u64,
    /// Why the pixel has its colour, from this tree (`x` shows it).
    pub explanation: ExplanationState,
}

/// The picked tree's explanation: worked out on the trace worker after the tree arrives.
#[derive(Clone, Debug, PartialEq)]
pub enum ExplanationState {
    Working,
    Ready(whitted_explain::Explanation),
    /// The explain library panicked (a bug): its message.
    Failed(String),
}

impl ExplanationState {
    pub fn ready(&self) -> Option<&whitted_explain::Explanation> {
        match self {
            ExplanationState::Ready(explanation) => Some(explanation),
            _ => None,
        }
    }
}

/// Which definition the source pane shows for the selected ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SourceTarget {
    Object,
    Material,
}

/// The source pane's scroll: lines and columns away from where the definition `span` is
/// shown. It belongs to that definition: another one shown starts unscrolled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SourceScroll {
    pub span: Option<whitted_ir::Span>,
    pub lines: i32,
    pub columns: u16,
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
    /// Start the trace [`App::trace_job`] describes (on a worker thread).
    Trace,
    /// Start the what-if popup's re-trace (on a worker thread).
    WhatIfTrace,
    /// Write a what-if change back to a scene file: `contents` replaces the file, provided
    /// it still holds `original` (the text the scene was compiled from); then report
    /// through [`App::apply_write_scene`].
    WriteScene {
        path: PathBuf,
        original: Arc<String>,
        contents: String,
        line: u32,
    },
    /// Start the query [`App::query`] holds (on a worker thread).
    StartQuery,
}

/// A trace under way on a worker thread.
#[derive(Clone, Debug)]
pub struct Tracing {
    pub generation: u64,
    pub pixel: (u32, u32),
    pub cancel: Arc<AtomicBool>,
    /// When it was asked for, so that the event loop can time it to the screen.
    pub requested_at: Instant,
    /// A re-trace after a reload keeps the old tree's selection and open nodes.
    pub retrace: bool,
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
    /// How far the user scrolled the source pane from where it shows the definition.
    pub source_scroll: SourceScroll,
    pub inspector_scroll: u16,
    /// How many columns the inspector is scrolled sideways.
    pub inspector_columns: u16,
    pub help_open: bool,
    pub help_scroll: u16,
    /// `z`: the focused pane fills the body.
    pub zoomed: bool,
    /// The `/` prompt while it is open (it takes the keys).
    pub search_prompt: Option<LineInput>,
    /// The last submitted search of the picked tree, for `n` / `N`.
    pub search: Option<Search>,
    /// Set after a failed reload, cleared by a good one.
    pub errors: Option<SceneErrors>,
    pub reloading: bool,
    /// The animation frame the scene is compiled at (`None`: the scene's first); `<` and
    /// `>` step it.
    pub frame: Option<u32>,
    pub message: Option<Message>,
    /// The terminal's area, for layout.
    pub area: Rect,
    pub color_depth: ColorDepth,
    pub export_dir: PathBuf,
    pub should_quit: bool,
    /// How many pixels have been traced: the event loop sees a new pick by its change.
    pub traces: u64,
    /// The trace under way, if any (Esc cancels it).
    pub tracing: Option<Tracing>,
    /// Trace requests so far: numbers them, and tells `update` that one was made.
    pub trace_requests: u64,
    /// When the latest finished trace was asked for (taken by the event loop).
    pub traced_request_at: Option<Instant>,
    /// The node budget of recorded trees: `limits::MAX_RAY_TREE_NODES`.
    pub node_budget: usize,
    /// `x`: the inspector's area shows the explanation, and which entry is selected.
    pub explain_open: bool,
    pub explain_selected: usize,
    /// A line the source pane shows instead of the selected ray's definition (a finding's,
    /// after Enter in the explanation) and what to call it; cleared when the ray changes.
    pub source_focus: Option<(whitted_ir::Span, String)>,
    /// The 3D ray view, when the image pane shows it instead of the image (`v`).
    pub ray_view: Option<RayViewState>,
    /// The what-if popup (`w`), when open.
    pub what_if: Option<WhatIf>,
    /// The query prompt, run and overlay (`:`).
    pub query: QueryState,
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
            source_scroll: SourceScroll::default(),
            inspector_scroll: 0,
            inspector_columns: 0,
            help_open: false,
            help_scroll: 0,
            zoomed: false,
            search_prompt: None,
            search: None,
            errors: None,
            reloading: false,
            frame: None,
            message: None,
            area,
            color_depth: ColorDepth::TrueColor,
            export_dir,
            should_quit: false,
            traces: 0,
            tracing: None,
            trace_requests: 0,
            traced_request_at: None,
            node_budget: whitted_ir::limits::MAX_RAY_TREE_NODES,
            explain_open: false,
            explain_selected: 0,
            source_focus: None,
            ray_view: None,
            what_if: None,
            query: QueryState::default(),
        }
    }

    /// Whether a popup or prompt is open and takes every key.
    pub fn takes_keys(&self) -> bool {
        self.what_if.is_some() || self.query.prompt.is_some() || self.search_prompt.is_some()
    }

    pub fn image_size(&self) -> (u32, u32) {
        (self.options.width, self.options.height)
    }

    /// What decides the layout besides the terminal size.
    pub fn arrangement(&self) -> Arrangement {
        Arrangement {
            errors: self.errors.is_some(),
            focus: self.focus,
            zoomed: self.zoomed,
        }
    }

    /// The panes for the current terminal size (`None` when it is too small).
    pub fn panes(&self) -> Option<Panes> {
        layout::panes(self.area, self.image_size(), self.arrangement())
    }

    /// The area the image is drawn in (inside the pane's border).
    pub fn image_area(&self) -> Option<Rect> {
        self.panes().map(|p| layout::inner(p.image))
    }

    /// The rays the tree pane shows: the rows inside its border but the column header.
    pub fn tree_rows(&self) -> usize {
        self.panes().map_or(1, |p| {
            usize::from(layout::inner(p.tree).height.saturating_sub(1)).max(1)
        })
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

    /// Asks for the ray tree of the pixel under the cursor (every sample of it): the event
    /// loop runs [`App::trace_job`] on a worker and hands the answer to
    /// [`App::apply_trace`]. A trace still under way is cancelled.
    pub fn trace_cursor(&mut self) {
        self.request_trace(self.cursor, false);
    }

    fn request_trace(&mut self, pixel: (u32, u32), retrace: bool) {
        self.cancel_trace();
        self.trace_requests += 1;
        self.tracing = Some(Tracing {
            generation: self.trace_requests,
            pixel,
            cancel: Arc::new(AtomicBool::new(false)),
            requested_at: Instant::now(),
            retrace,
        });
    }

    /// Cancels the trace under way; whether there was one.
    pub fn cancel_trace(&mut self) -> bool {
        match self.tracing.take() {
            Some(tracing) => {
                tracing.cancel.store(true, Ordering::Relaxed);
                true
            }
            None => false,
        }
    }

    /// The work of the trace under way, for a worker thread.
    pub fn trace_job(&self) -> Option<TraceJob> {
        let tracing = self.tracing.as_ref()?;
        Some(TraceJob {
            generation: tracing.generation,
            loaded: self.loaded.clone(),
            options: self.options.clone(),
            pixel: tracing.pixel,
            cancel: Arc::clone(&tracing.cancel),
            node_budget: self.node_budget,
        })
    }

    /// A trace's answer: the new tree, or a message. Answers to cancelled or superseded
    /// requests are dropped.
    pub fn apply_trace(&mut self, traced: Traced) {
        let Some(tracing) = self.tracing.take_if(|t| t.generation == traced.generation) else {
            return;
        };
        let (x, y) = traced.pixel;
        match traced.result {
            Ok((tree, trace_time)) => {
                let mut view = match self.picked.take() {
                    Some(previous) if tracing.retrace => TreeView::new_like(tree, &previous.tree),
                    _ => {
                        self.inspector_scroll = 0;
                        self.explain_selected = 0;
                        self.search = None;
                        TreeView::new(tree)
                    }
                };
                self.source_focus = None;
                view.keep_selection_in_view(self.tree_rows());
                // A re-traced tree may have other rays: the search's matches are found again.
                if let Some(search) = &mut self.search {
                    *search = Search::new(&search.query, &view);
                }
                if view.tree().unrecorded > 0 {
                    self.set_message(
                        format!(
                            "the tree of ({x}, {y}) was cut at {} nodes: {} more rays were traced but not recorded",
                            view.tree().node_budget,
                            view.tree().unrecorded
                        ),
                        false,
                    );
                }
                // A 3D view not yet moved turns to orbit the new pixel's hit.
                if self.ray_view.as_ref().is_some_and(|v| v.orbit.is_home()) {
                    self.ray_view = Some(RayViewState::new(
                        &self.loaded.scene.camera,
                        Some(view.tree()),
                    ));
                }
                self.picked = Some(Picked {
                    tree: view,
                    trace_time,
                    on_screen_after: None,
                    generation: traced.generation,
                    explanation: ExplanationState::Working,
                });
                self.traces += 1;
                self.traced_request_at = Some(tracing.requested_at);
            }
            Err(TraceFailure::Cancelled) => {
                self.set_message(format!("cancelled the trace of ({x}, {y})"), false);
            }
            Err(TraceFailure::Refused(message)) => {
                // A re-traced pixel that left the image (a smaller reload) has no tree now.
                if tracing.retrace {
                    self.picked = None;
                }
                self.set_message(message, true);
            }
            Err(TraceFailure::Crashed(message)) => self.set_message(
                format!("the tracer crashed on ({x}, {y}) (a bug in whitted): {message}"),
                true,
            ),
        }
    }

    /// The explanation of a traced tree: kept when that tree is still the one shown.
    pub fn apply_explained(&mut self, explained: Explained) {
        let Some(picked) = &mut self.picked else {
            return;
        };
        if picked.generation != explained.generation {
            return;
        }
        picked.explanation = match explained.result {
            Ok(explanation) => {
                // A re-traced pixel's explanation may have fewer entries than the last one.
                let entries = explanation.contributions.len() + explanation.findings.len();
                self.explain_selected = self.explain_selected.min(entries.saturating_sub(1));
                ExplanationState::Ready(explanation)
            }
            Err(message) => ExplanationState::Failed(message),
        };
    }

    /// Shows the 3D ray view in the image pane (from the scene's camera, orbiting the picked
    /// pixel's first hit), or the image again.
    pub fn toggle_ray_view(&mut self) {
        self.ray_view = match self.ray_view {
            Some(_) => None,
            None => Some(RayViewState::new(
                &self.loaded.scene.camera,
                self.picked.as_ref().map(|p| p.tree.tree()),
            )),
        };
    }

    /// The backdrop render the 3D view needs now (after a move, a resize or a reload), if any.
    pub fn backdrop_job(&mut self) -> Option<BackdropJob> {
        let area = self.image_area()?;
        let view = self.ray_view.as_mut()?;
        view.backdrop_job(&self.loaded, &self.options, area.width, area.height)
    }

    pub fn apply_backdrop(&mut self, rendered: BackdropRendered) {
        if let Some(view) = &mut self.ray_view {
            view.apply_backdrop(rendered);
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
                // A 3D view not yet moved follows the scene's (possibly new) camera.
                if self.ray_view.as_ref().is_some_and(|v| v.orbit.is_home()) {
                    self.ray_view = Some(RayViewState::new(
                        &self.loaded.scene.camera,
                        self.picked.as_ref().map(|p| p.tree.tree()),
                    ));
                }
                // The matches were of the old scene.
                self.query.cancel();
                self.query.overlay = None;
                let retrace = self.retrace_picked();
                let note = match warnings {
                    0 => String::new(),
                    1 => " (1 warning)".to_string(),
                    n => format!(" ({n} warnings)"),
                };
                // The popup's values and re-trace were of the old scene: showing them over
                // the new one would explain a scene that is gone.
                let closed = if self.what_if.take().is_some() {
                    "; what-if closed (w opens it on the new scene)"
                } else {
                    ""
                };
                // An animated scene says which frame is shown now (`<` `>` step them).
                let frame = match self.frame {
                    Some(frame) if self.loaded.scene.settings.is_animated() => {
                        let range = self.loaded.scene.settings.frame_range();
                        format!(" at frame {frame} of {} to {}", range.start(), range.end())
                    }
                    _ => String::new(),
                };
                self.set_message(
                    format!("reloaded {}{frame}{note}{closed}", self.scene_name),
                    false,
                );
                let mut effects = vec![Effect::StartRender];
                effects.extend(retrace);
                effects
            }
        }
    }

    /// Asks to trace the picked pixel again in the current scene; the new tree keeps the
    /// old one's selection and open nodes where it has the same shape.
    fn retrace_picked(&mut self) -> Option<Effect> {
        let [x, y] = self.picked.as_ref()?.tree.tree().pixel;
        self.request_trace((x, y), true);
        Some(Effect::Trace)
    }

    /// The result of writing a what-if change back to the scene file.
    pub fn apply_write_scene(&mut self, result: Result<(PathBuf, u32), String>) {
        match &mut self.what_if {
            Some(what_if) => what_if.apply_write(result),
            None => match result {
                Ok((path, line)) => {
                    self.set_message(format!("wrote {}:{line}", path.display()), false)
                }
                Err(error) => self.set_message(format!("not written: {error}"), true),
            },
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
                // The path first: on a narrow status line the end is what gets cut.
                self.set_message(
                    format!(
                        "wrote {} (the ray tree of ({}, {}))",
                        path.display(),
                        pixel[0],
                        pixel[1]
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
    use crate::test_scene::{finish_trace, whitted_scene, GLASS_PIXEL};
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
        finish_trace(&mut app);
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
        // A search made before the reload: its (here stale) matches are found again.
        app.search = Some(Search {
            query: "transmitted".into(),
            matches: vec![999],
            current: 0,
        });
        app.reloading = true;
        let effects = app.apply_reload(Ok((LoadedScene::new(whitted_scene()), 0)));
        assert_eq!(effects, vec![Effect::StartRender, Effect::Trace]);
        assert!(!app.reloading);
        assert!(app.errors.is_none());
        finish_trace(&mut app);
        assert_eq!(app.picked.as_ref().map(|p| p.tree.selected()), selected);
        let tree = &app.picked.as_ref().unwrap().tree;
        assert_eq!(
            app.search.as_ref().map(|s| s.matches.clone()),
            Some(crate::search::state::matching_rays(tree, "transmitted"))
        );
        assert_eq!(
            app.message.as_ref().unwrap().text,
            "reloaded scenes/whitted.scene"
        );
    }

    #[test]
    fn a_reload_closes_the_what_if_popup_of_the_old_scene() {
        let mut app = app();
        app.cursor = GLASS_PIXEL;
        app.trace_cursor();
        finish_trace(&mut app);
        crate::update::update(&mut app, crate::action::Action::WhatIf);
        assert!(app.what_if.is_some(), "the popup opens on a picked pixel");
        app.apply_reload(Ok((LoadedScene::new(whitted_scene()), 0)));
        assert!(app.what_if.is_none());
        let message = app.message.as_ref().map(|m| m.text.as_str());
        assert!(
            message.is_some_and(|m| m.contains("what-if closed")),
            "{message:?}"
        );
    }

    #[test]
    fn a_reload_of_an_animated_scene_says_which_frame_it_shows() {
        let animated = || {
            let mut scene = whitted_scene().into_inner();
            scene.settings.first_frame = 4;
            scene.settings.frames = 3;
            whitted_ir::validate(scene).unwrap_or_else(|_| panic!("invalid"))
        };
        let mut app = App::new(
            "scenes/whitted.scene".into(),
            LoadedScene::new(animated()),
            Rect::new(0, 0, 120, 40),
            "/tmp".into(),
        );
        app.frame = Some(5);
        app.reloading = true;
        app.apply_reload(Ok((LoadedScene::new(animated()), 0)));
        assert_eq!(
            app.message.as_ref().map(|m| m.text.as_str()),
            Some("reloaded scenes/whitted.scene at frame 5 of 4 to 6")
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
        finish_trace(&mut app);
        assert!(app.picked.is_none());
        assert!(app.message.as_ref().unwrap().is_error);
    }

    #[test]
    fn esc_cancels_a_runaway_trace_off_the_ui_thread_and_the_debugger_goes_on() {
        let mut app = App::new(
            "hall.scene".into(),
            LoadedScene::new(crate::test_scene::hall_of_mirrors()),
            Rect::new(0, 0, 120, 40),
            "/tmp".into(),
        );
        app.cursor = GLASS_PIXEL;
        let effects = crate::update::update(&mut app, crate::action::Action::TraceCursor);
        assert_eq!(effects, vec![Effect::Trace]);
        let job = app.trace_job().expect("a trace to run");
        let (sender, receiver) = std::sync::mpsc::channel();
        job.spawn(sender).expect("a trace thread");
        // The UI thread is free meanwhile: Esc cancels the trace instead of quitting.
        crate::update::update(&mut app, crate::action::Action::Cancel);
        assert!(!app.should_quit);
        assert!(app.tracing.is_none());
        let traced = match receiver.recv_timeout(Duration::from_secs(120)) {
            Ok(crate::event::Event::Traced(traced)) => traced,
            _ => panic!("the cancelled trace did not stop"),
        };
        assert_eq!(traced.result.as_ref().err(), Some(&TraceFailure::Cancelled));
        app.apply_trace(traced);
        assert!(app.picked.is_none(), "a cancelled trace leaves no tree");
        // With no trace under way, Esc still does not quit (q does).
        crate::update::update(&mut app, crate::action::Action::Cancel);
        assert!(!app.should_quit);
        assert!(app.message.as_ref().unwrap().text.contains("q quits"));
    }

    #[test]
    fn a_tree_over_its_budget_is_shown_cut_with_a_message() {
        let mut app = App::new(
            "hall.scene".into(),
            LoadedScene::new(whitted_scene()),
            Rect::new(0, 0, 120, 40),
            "/tmp".into(),
        );
        app.node_budget = 5;
        app.cursor = GLASS_PIXEL;
        app.trace_cursor();
        finish_trace(&mut app);
        let picked = app.picked.as_ref().expect("a tree");
        assert!(picked.tree.tree().unrecorded > 0);
        let message = app.message.as_ref().expect("a message");
        assert!(message.text.contains("was cut at 5 nodes"), "{message:?}");
    }

    #[test]
    fn an_answer_to_a_superseded_trace_is_dropped() {
        let mut app = app();
        app.cursor = GLASS_PIXEL;
        app.trace_cursor();
        let old = app.trace_job().expect("a job");
        app.cursor = (10, 10);
        app.trace_cursor();
        assert!(
            old.cancel.load(Ordering::Relaxed),
            "the old trace is cancelled"
        );
        app.apply_trace(old.run());
        assert!(app.picked.is_none());
        finish_trace(&mut app);
        assert_eq!(
            app.picked.as_ref().map(|p| p.tree.tree().pixel),
            Some([10, 10])
        );
    }

    /// The 3D view follows a reloaded scene's camera until it is moved, and a moved view
    /// stays where the user put it; either way its backdrop is rendered again.
    #[test]
    fn a_reload_moves_an_unmoved_3d_view_to_the_new_camera_and_rerenders_its_backdrop() {
        let mut app = app();
        app.toggle_ray_view();
        let job = app.backdrop_job().expect("a backdrop");
        app.apply_backdrop(job.run());
        assert!(app.backdrop_job().is_none());
        let mut moved_camera = whitted_scene().into_inner();
        moved_camera.camera.eye.y += 2.0;
        let new_camera = moved_camera.camera.clone();
        let reloaded = whitted_ir::validate(moved_camera).unwrap();
        app.apply_reload(Ok((LoadedScene::new(reloaded.clone()), 0)));
        let view = app.ray_view.as_ref().expect("still shown");
        assert_eq!(view.orbit.camera(), &new_camera);
        assert!(app.backdrop_job().is_some(), "the new scene is rendered");

        app.ray_view.as_mut().unwrap().orbit.orbit(0.3, 0.0);
        let orbited = app.ray_view.as_ref().unwrap().orbit.camera().clone();
        app.apply_reload(Ok((LoadedScene::new(reloaded), 0)));
        assert_eq!(app.ray_view.as_ref().unwrap().orbit.camera(), &orbited);
    }
}
