//! The event loop: one channel of [`Event`]s from every source, one state, one draw per
//! batch of events. User input goes through the key map and [`update`]; background results
//! through the app's `apply_*` methods; the [`Effect`]s that come back are carried out here
//! (start a render, ask for a reload, write an export).

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::time::{Duration, Instant};

use ratatui::crossterm::event::{self as terminal_event, Event as TerminalEvent};
use ratatui::layout::Rect;

use crate::action::{action_for_key, action_for_mouse, Action};
use crate::app::{App, Effect, LoadedScene};
use crate::event::Event;
use crate::image::ColorDepth;
use crate::reload::Reloader;
use crate::render_job::RenderJob;
use crate::session::Session;
use crate::terminal::{self, TerminalGuard};
use crate::update::update;
use crate::watch::FileWatch;

/// Why the debugger stopped other than by the user quitting.
#[derive(Debug)]
pub enum DebugError {
    /// stdin or stdout is not a terminal.
    NotATerminal,
    /// The terminal could not be set up, drawn to or read.
    Terminal(io::Error),
    /// A signal stopped the debugger (the terminal was restored); its number.
    Signal(i32),
}

impl fmt::Display for DebugError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DebugError::NotATerminal => {
                write!(
                    f,
                    "whitted debug needs an interactive terminal (stdin and stdout)"
                )
            }
            DebugError::Terminal(error) => write!(f, "terminal error: {error}"),
            DebugError::Signal(signal) => write!(f, "stopped by signal {signal}"),
        }
    }
}

impl std::error::Error for DebugError {}

impl From<io::Error> for DebugError {
    fn from(error: io::Error) -> Self {
        DebugError::Terminal(error)
    }
}

/// How long the loop waits after a file change before reloading, so that an editor's
/// several writes of one save become one reload.
const RELOAD_DEBOUNCE: Duration = Duration::from_millis(150);

/// The most time spent taking queued events before drawing again, so that a stream of
/// render tiles never delays a frame.
const DRAIN_BUDGET: Duration = Duration::from_millis(12);

/// Runs the debugger until the user quits. The terminal is restored however this returns.
pub fn run(session: Session) -> Result<(), DebugError> {
    if !terminal::is_interactive() {
        return Err(DebugError::NotATerminal);
    }
    let loaded = LoadedScene::new(session.scene);
    let mut guard = terminal::init()?;
    let size = guard.terminal.size()?;
    let mut app = App::new(
        session.scene_name,
        loaded,
        Rect::new(0, 0, size.width, size.height),
        session.export_dir,
    );
    app.frame = session.frame;
    app.color_depth = ColorDepth::from_colorterm(std::env::var("COLORTERM").ok().as_deref());

    let (events, inbox) = mpsc::channel();
    terminal::forward_signals(events.clone())?;
    spawn_input_thread(events.clone())?;
    let reloader = Reloader::start(session.recompile, events.clone())?;
    let mut watch = match FileWatch::start(events.clone()) {
        Ok(mut watch) => {
            watch.set_files(&session.watch);
            Some(watch)
        }
        Err(error) => {
            app.set_message(
                format!("not watching files ({error}); press r to reload"),
                true,
            );
            None
        }
    };
    let mut runner = Runner {
        events,
        reloader,
        render: None,
        generation: 0,
    };
    runner.carry_out(&mut app, vec![Effect::StartRender]);
    if let Some((x, y)) = session.pixel {
        app.cursor = (x, y);
        app.trace_cursor();
        runner.carry_out(&mut app, vec![Effect::Trace]);
    }
    event_loop(&mut guard, &mut app, &mut runner, &inbox, &mut watch)
}

/// What carries out effects: the channel workers answer on, the reload worker, the render.
struct Runner {
    events: Sender<Event>,
    reloader: Reloader,
    render: Option<RenderJob>,
    generation: u64,
}

impl Runner {
    fn carry_out(&mut self, app: &mut App, effects: Vec<Effect>) {
        for effect in effects {
            match effect {
                Effect::Reload => self.reloader.request(app.frame),
                Effect::StartRender => {
                    if let Some(old) = self.render.take() {
                        old.cancel();
                    }
                    self.generation += 1;
                    app.render_started(self.generation);
                    match RenderJob::start(
                        self.generation,
                        &app.loaded,
                        app.options.clone(),
                        self.events.clone(),
                    ) {
                        Ok(job) => self.render = Some(job),
                        Err(error) => {
                            app.apply_render_done(self.generation, None);
                            app.set_message(format!("cannot start rendering: {error}"), true);
                        }
                    }
                }
                Effect::Trace => {
                    if let Some(job) = app.trace_job() {
                        if let Err(error) = job.spawn(self.events.clone()) {
                            app.cancel_trace();
                            app.set_message(format!("cannot start tracing: {error}"), true);
                        }
                    }
                }
                Effect::WhatIfTrace => {
                    let job = app.what_if.as_mut().and_then(|w| w.take_job());
                    if let Some(job) = job {
                        if let Err(error) = job.spawn(self.events.clone()) {
                            if let Some(what_if) = &mut app.what_if {
                                what_if.cancel();
                            }
                            app.set_message(format!("cannot start the re-trace: {error}"), true);
                        }
                    }
                }
                Effect::StartQuery => {
                    if let Some(job) = app.query.take_job() {
                        if let Err(error) = job.spawn(self.events.clone()) {
                            app.query.cancel();
                            app.set_message(format!("cannot start the query: {error}"), true);
                        }
                    }
                }
                Effect::WriteScene {
                    path,
                    original,
                    contents,
                    line,
                } => {
                    let written = write_scene(&path, &original, &contents).map(|()| (path, line));
                    app.apply_write_scene(written);
                }
                Effect::Export { path, contents } => {
                    let written = write_atomically(&path, &contents).map(|()| path);
                    app.apply_export(written.map_err(|e| e.to_string()));
                }
            }
        }
    }
}

fn event_loop(
    guard: &mut TerminalGuard,
    app: &mut App,
    runner: &mut Runner,
    inbox: &Receiver<Event>,
    watch: &mut Option<FileWatch>,
) -> Result<(), DebugError> {
    let mut reload_at: Option<Instant> = None;
    // When the batch being drawn picked a pixel: when its first event arrived.
    let mut picked_at: Option<Instant> = None;
    loop {
        if let Some(job) = app.backdrop_job() {
            // Without a thread there is no backdrop; the rays are still drawn.
            let _ = job.spawn(runner.events.clone());
        }
        guard
            .terminal
            .draw(|frame| frame.render_widget(&*app, frame.area()))?;
        if let (Some(arrived), Some(picked)) = (picked_at.take(), app.picked.as_mut()) {
            // The figure covers the pick's own frame, so it shows in one more.
            picked.on_screen_after = Some(arrived.elapsed());
            guard
                .terminal
                .draw(|frame| frame.render_widget(&*app, frame.area()))?;
        }
        if app.should_quit {
            return Ok(());
        }
        let timeout = reload_at.map_or(Duration::from_secs(3600), |at| {
            at.saturating_duration_since(Instant::now())
        });
        let first = match inbox.recv_timeout(timeout) {
            Ok(event) => event,
            Err(RecvTimeoutError::Timeout) => Event::Tick,
            Err(RecvTimeoutError::Disconnected) => return Ok(()),
        };
        let started = Instant::now();
        let traces_before = app.traces;
        let mut next = Some(first);
        while let Some(event) = next.take() {
            match event {
                Event::InputFailed(message) => {
                    return Err(DebugError::Terminal(io::Error::other(message)));
                }
                // Returning drops the terminal guard, which restores the terminal.
                Event::Signal(signal) => return Err(DebugError::Signal(signal)),
                Event::FileChanged => reload_at = Some(Instant::now() + RELOAD_DEBOUNCE),
                Event::Tick => {}
                Event::Reloaded(reloaded) => {
                    if let Some(watch) = watch.as_mut() {
                        if !reloaded.watch.is_empty() {
                            watch.set_files(&reloaded.watch);
                        }
                    }
                    let effects = app.apply_reload(reloaded.result);
                    runner.carry_out(app, effects);
                }
                other => {
                    let effects = handle(app, other);
                    runner.carry_out(app, effects);
                }
            }
            if app.should_quit {
                break;
            }
            if started.elapsed() < DRAIN_BUDGET {
                next = inbox.try_recv().ok();
            }
        }
        if app.traces != traces_before {
            // Timed from the key or click that asked for the tree, not from its arrival.
            picked_at = Some(app.traced_request_at.take().unwrap_or(started));
        }
        if let Some(at) = reload_at {
            if Instant::now() >= at {
                if app.reloading {
                    // A reload is running; this change needs one more after it.
                    reload_at = Some(Instant::now() + RELOAD_DEBOUNCE);
                } else {
                    reload_at = None;
                    let effects = update(app, Action::Reload);
                    runner.carry_out(app, effects);
                }
            }
        }
    }
}

/// Input and render events: the part of event handling that needs no worker handles.
fn handle(app: &mut App, event: Event) -> Vec<Effect> {
    match event {
        Event::Key(key) => match action_for_key(key, app.focus, app.help_open, app.takes_keys()) {
            Some(action) => update(app, action),
            None => Vec::new(),
        },
        // An open popup or prompt has the input: the mouse waits until it closes.
        Event::Mouse(_) if app.takes_keys() => Vec::new(),
        Event::Mouse(mouse) => match action_for_mouse(mouse) {
            Some(action) => update(app, action),
            None => Vec::new(),
        },
        Event::Resize(width, height) => {
            app.area = Rect::new(0, 0, width, height);
            let rows = app.tree_rows();
            if let Some(picked) = &mut app.picked {
                picked.tree.keep_selection_in_view(rows);
            }
            Vec::new()
        }
        Event::RenderTile { generation, tile } => {
            app.apply_tile(generation, &tile);
            Vec::new()
        }
        Event::Traced(traced) => {
            app.apply_trace(traced);
            Vec::new()
        }
        Event::Explained(explained) => {
            app.apply_explained(explained);
            Vec::new()
        }
        Event::Backdrop(rendered) => {
            app.apply_backdrop(rendered);
            Vec::new()
        }
        Event::RenderDone { generation, result } => {
            app.apply_render_done(generation, result);
            Vec::new()
        }
        Event::RenderFailed {
            generation,
            message,
        } => {
            app.apply_render_done(generation, None);
            app.set_message(
                format!("the renderer crashed (a bug in whitted): {message}"),
                true,
            );
            Vec::new()
        }
        Event::WhatIfTraced(traced) => {
            if let Some(what_if) = &mut app.what_if {
                what_if.apply(traced);
            }
            Vec::new()
        }
        Event::Query(news) => {
            if let Some((message, is_error)) = app.query.apply(news) {
                app.set_message(message, is_error);
            }
            Vec::new()
        }
        Event::InputFailed(_)
        | Event::FileChanged
        | Event::Tick
        | Event::Reloaded(_)
        | Event::Signal(_) => Vec::new(),
    }
}

/// Reads the terminal on its own thread and forwards keys, mouse events and resizes.
fn spawn_input_thread(events: Sender<Event>) -> io::Result<()> {
    std::thread::Builder::new()
        .name("input".into())
        .spawn(move || loop {
            let event = match terminal_event::read() {
                Ok(TerminalEvent::Key(key)) => Event::Key(key),
                Ok(TerminalEvent::Mouse(mouse)) => Event::Mouse(mouse),
                Ok(TerminalEvent::Resize(width, height)) => Event::Resize(width, height),
                Ok(_) => continue,
                Err(error) => Event::InputFailed(error.to_string()),
            };
            let failed = matches!(event, Event::InputFailed(_));
            if events.send(event).is_err() || failed {
                return;
            }
        })?;
    Ok(())
}

/// Writes a what-if change into a scene file, provided the file still holds the text the
/// scene was compiled from (an edit made since is never overwritten).
fn write_scene(path: &Path, original: &str, contents: &str) -> Result<(), String> {
    let on_disk =
        std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if on_disk != original.as_bytes() {
        return Err(format!(
            "{} changed on disk since it was loaded; reload (r) and try again",
            path.display()
        ));
    }
    write_atomically(path, contents).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Writes a file whole or not at all: a temporary file beside it, then a rename.
fn write_atomically(path: &Path, contents: &str) -> io::Result<()> {
    let mut temporary = PathBuf::from(path);
    temporary.as_mut_os_string().push(".partial");
    std::fs::write(&temporary, contents)?;
    std::fs::rename(&temporary, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&temporary);
    })
}
