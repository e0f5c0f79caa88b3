//! whitted-lang: the scene language. Source text in, validated IR out, with diagnostics a
//! user can act on.
//!
//! The phases, each in its own module: a lexical pass over brackets, strings and comments
//! (`lexical`); the pest grammar (`grammar/scene.pest`) and the tree it builds (`parser`,
//! `ast`); name resolution and static checks (`resolve`); evaluation straight into the IR
//! (`eval`); and the IR validator. [`compile_file`] runs them all; [`render_diagnostics`]
//! (`diagnostic_text`) turns the result into rustc-style text; [`format_source`] (`format`)
//! lays a file out in the canonical way, `whitted fmt`. The library never touches the
//! disk (imports go through a [`SourceLoader`]) and never prints.

mod ast;
#[cfg(test)]
mod ast_dump;
mod builtins;
mod compile;
mod diagnostic_text;
pub mod editor;
mod eval;
mod format;
mod hints;
mod intern;
mod lexical;
mod mesh;
mod parser;
mod properties;
mod random;
mod resolve;
mod schema;
mod strings;
mod suggest;
mod syntax_error;
mod value;

pub use whitted_ir::{Diagnostic, SourceMap};

pub use compile::{compile_bytes, compile_file, compile_source};
pub use diagnostic_text::render_diagnostics;
pub use format::{format_source, FormatFailure};

/// Supplies file contents for the root file and for imports; the library never touches the
/// disk.
pub trait SourceLoader {
    /// The bytes of the file at `path`, which is already resolved (relative imports joined
    /// onto the importing file's directory). The library decodes them, so that text that is
    /// not UTF-8 gets an error pointing at the first bad byte.
    fn load(&mut self, path: &std::path::Path) -> std::io::Result<Vec<u8>>;

    /// What makes two paths the same file (a canonical path through symbolic links), so
    /// that a file reached by two paths is loaded once and a loop through a linked folder is
    /// an import cycle. The default is the path itself.
    fn identify(&mut self, path: &std::path::Path) -> std::path::PathBuf {
        path.to_path_buf()
    }
}

/// Bounds that keep bad input from hanging or exhausting the machine. Each is reported by
/// name when reached. The defaults are the constants of [`whitted_ir::limits`], the one home
/// of every limit; tests and fuzzers lower them to reach them quickly.
#[derive(Clone, Debug)]
pub struct Limits {
    /// Objects in the scene (shapes, CSG nodes and groups).
    pub max_objects: usize,
    /// Evaluation steps in total: every loop iteration and every function call counts one.
    pub max_evaluation_steps: u64,
    /// Nested calls of user functions.
    pub max_call_depth: usize,
    /// Nested brackets `(` and `{`. Expressions and blocks together may nest 16 times this.
    pub max_nesting: usize,
    /// Nested imports.
    pub max_import_depth: usize,
    /// Files read in one compilation (each distinct file counts once).
    pub max_imports: usize,
    /// Source text in total, over every file, in bytes.
    pub max_source_bytes: usize,
    /// Lights in the scene.
    pub max_lights: usize,
    /// Materials in the scene, named and inline together.
    pub max_materials: usize,
    /// Triangles in one mesh file.
    pub max_mesh_triangles: usize,
    /// Triangles over every distinct mesh of the scene.
    pub max_scene_triangles: usize,
}

impl Default for Limits {
    fn default() -> Self {
        use whitted_ir::limits;
        Limits {
            max_objects: limits::MAX_OBJECTS,
            max_evaluation_steps: limits::MAX_EVALUATION_STEPS,
            max_call_depth: limits::MAX_CALL_DEPTH,
            max_nesting: limits::MAX_NESTING,
            max_import_depth: limits::MAX_IMPORT_DEPTH,
            max_imports: limits::MAX_IMPORTS,
            max_source_bytes: limits::MAX_SOURCE_BYTES,
            max_lights: limits::MAX_LIGHTS,
            max_materials: limits::MAX_MATERIALS,
            max_mesh_triangles: limits::MAX_MESH_TRIANGLES,
            max_scene_triangles: limits::MAX_SCENE_TRIANGLES,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct CompileOptions {
    /// `-D NAME=VALUE` from the command line, in order: (NAME, VALUE source text).
    pub defines: Vec<(String, String)>,
    /// `--set NAME=VALUE` from the command line: settings that replace the scene's, by the
    /// rows of the property table (NAME, VALUE source text).
    pub settings: Vec<(String, String)>,
    pub limits: Limits,
    /// The animation frame to compile: the value of `frame` (and, with the scene's frame
    /// range, of `clock`). `None`: the scene's first frame.
    pub frame: Option<u32>,
    /// Keep an [`editor::Index`] of the text (properties by block, names to definitions,
    /// symbols) in [`Compilation::index`], for a language server.
    pub index: bool,
}

/// What the animation's built-in names are worth in one compilation: `frame`, `clock` and
/// `fps`. The frame range and rate are the scene's own settings (`first_frame`, `frames`,
/// `fps`); the compiler finds them by compiling (see `compile.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameClock {
    pub frame: u32,
    /// The first and last frames of the scene's range.
    pub first: u32,
    pub last: u32,
    pub fps: u32,
}

impl FrameClock {
    /// The clock of `frame` in the range of `settings`; `None` for the range's first frame.
    pub fn of(settings: &whitted_ir::Settings, frame: Option<u32>) -> FrameClock {
        let range = settings.frame_range();
        FrameClock {
            frame: frame.unwrap_or(*range.start()),
            first: *range.start(),
            last: *range.end(),
            fps: settings.fps,
        }
    }

    /// `(frame - first) / (last - first)`: 0 at the first frame, 1 at the last, 0 when the
    /// range has one frame. A frame outside the range gives a clock outside [0, 1].
    pub fn clock(&self) -> f64 {
        if self.last == self.first {
            return 0.0;
        }
        (f64::from(self.frame) - f64::from(self.first))
            / (f64::from(self.last) - f64::from(self.first))
    }
}

#[derive(Debug)]
pub struct Compilation {
    /// Every file read (root first, then imports), plus a pseudo-file for each -D value so that
    /// its diagnostics can point into it.
    pub sources: SourceMap,
    /// Some only when there are no errors (validation by whitted_ir::validate passed too).
    pub scene: Option<whitted_ir::ValidScene>,
    /// What an editor asks about the text, when [`CompileOptions::index`] asked for it and
    /// every file parsed (with names resolved as far as they could be).
    pub index: Option<editor::Index>,
    /// Errors, warnings and notes, in source order within each phase.
    pub diagnostics: Vec<Diagnostic>,
    /// How much work the compilation did, counted deterministically.
    pub work: WorkCounts,
}

/// Deterministic counts of a compilation's work, for tests that check it grows linearly
/// with the input (scenes written by programs are big; wall-clock time is too noisy to
/// test).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkCounts {
    /// Rules the fast reader entered, backtracked attempts included (none for a text it
    /// left to pest).
    pub parse_steps: u64,
    /// Definitions the resolver examined while defining and looking up names.
    pub name_probes: u64,
}

impl Compilation {
    /// Whether any diagnostic is an error (then `scene` is `None`).
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}
