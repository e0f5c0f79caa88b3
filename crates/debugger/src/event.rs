//! Everything the event loop reacts to, from every source: the terminal (keys, mouse,
//! resize), the render worker (tiles, the end), the reload worker, the file watcher, and the
//! loop's own timer. A closed enum, so that handling is one exhaustive match.

use std::path::PathBuf;

use ratatui::crossterm::event::{KeyEvent, MouseEvent};
use whitted_tracer::{PixelStats, RenderStats, TileResult};

use crate::app::{LoadedScene, SceneErrors};

pub enum Event {
    Key(KeyEvent),
    Mouse(MouseEvent),
    Resize(u16, u16),
    /// The terminal could not be read any more.
    InputFailed(String),
    RenderTile {
        generation: u64,
        tile: TileResult,
    },
    /// The render ended: its statistics, or `None` when it was cancelled.
    RenderDone {
        generation: u64,
        result: Option<(RenderStats, Vec<PixelStats>)>,
    },
    /// The renderer crashed (a bug): the panic's message.
    RenderFailed {
        generation: u64,
        message: String,
    },
    Reloaded(Reloaded),
    /// A pixel's ray tree, recorded off the UI thread (or why not).
    Traced(crate::trace_job::Traced),
    /// The explanation of a traced pixel's tree, worked out after it on the same worker.
    Explained(crate::trace_job::Explained),
    /// A backdrop of the 3D ray view, rendered off the UI thread (or cancelled).
    Backdrop(crate::ray_view::state::BackdropRendered),
    /// A what-if re-trace's answer (the popup's `w`).
    WhatIfTraced(crate::what_if::state::WhatIfTraced),
    /// A query's progress or answer (`:`).
    Query(crate::query_job::QueryNews),
    /// A watched scene file changed on disk.
    FileChanged,
    /// The loop's timer: nothing arrived before the next deadline.
    Tick,
    /// The process received this signal (SIGTERM, SIGHUP, SIGQUIT or SIGINT): give the
    /// terminal back and stop.
    Signal(i32),
}

/// The reload worker's answer: the new scene and its warning count, or its errors; and the
/// files it was made from, to watch from now on.
pub struct Reloaded {
    pub result: Result<(LoadedScene, usize), SceneErrors>,
    pub watch: Vec<PathBuf>,
}
