//! What the binary hands the debugger: the compiled scene, a way to compile it again, the
//! files to watch, and where exported trees go. The debugger never parses or reads scene
//! files itself; recompiling is the binary's business.

use std::path::PathBuf;

use whitted_ir::{Diagnostic, SourceMap, ValidScene};

/// The result of one compilation, as the binary's compiler reports it.
pub struct Compiled {
    /// The scene, when it compiled without errors.
    pub scene: Option<ValidScene>,
    /// Errors and warnings, in the compiler's order.
    pub diagnostics: Vec<Diagnostic>,
    /// Every file read, so that diagnostics can show their lines.
    pub sources: SourceMap,
    /// The files the scene was made from (the root and its imports): a change to any of
    /// them triggers a reload.
    pub watch: Vec<PathBuf>,
}

/// Compiles the scene again from disk, at an animation frame (`None`: the frame the
/// command line asked for, or the scene's first). Runs on a worker thread, never the UI
/// thread.
pub type Recompile = Box<dyn FnMut(Option<u32>) -> Compiled + Send>;

/// Everything `whitted debug` needs to start.
pub struct Session {
    /// The scene path as the user typed it (titles, status line, export file names).
    pub scene_name: String,
    pub scene: ValidScene,
    /// The files to watch for the first scene.
    pub watch: Vec<PathBuf>,
    pub recompile: Recompile,
    /// The animation frame `scene` was compiled at (`--frame N`; `None`: the scene's first).
    pub frame: Option<u32>,
    /// A pixel to trace at start (`--pixel X,Y`).
    pub pixel: Option<(u32, u32)>,
    /// Where `e` writes the ray tree's JSON.
    pub export_dir: PathBuf,
}
