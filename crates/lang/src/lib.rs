//! whitted-lang: the scene language. Source text in, validated IR out, with diagnostics a
//! user can act on.
//!
//! The phases, each in its own module: a lexical pass over brackets, strings and comments
//! (`lexical`); the pest grammar (`grammar/scene.pest`) and the tree it builds (`parser`,
//! `ast`); name resolution and static checks (`resolve`); evaluation straight into the IR
//! (`eval`); and the IR validator. [`compile_file`] runs them all; [`render_diagnostics`]
//! turns the result into rustc-style text. The library never touches the disk (imports go
//! through a [`SourceLoader`]) and never prints.

mod ast;
#[cfg(test)]
mod ast_dump;
mod builtins;
mod compile;
mod eval;
mod intern;
mod lexical;
mod parser;
mod render;
mod resolve;
mod schema;
mod suggest;
mod syntax_error;
mod value;

pub use whitted_ir::{Diagnostic, SourceMap};

pub use compile::{compile_file, compile_source};
pub use render::render_diagnostics;

/// Supplies file text for the root file and for imports; the library never touches the disk.
pub trait SourceLoader {
    /// `path` is already resolved (relative imports joined onto the importing file's directory).
    fn load(&mut self, path: &std::path::Path) -> std::io::Result<String>;
}

/// Bounds that keep bad input from hanging or exhausting the machine. Each is reported by
/// name when reached.
#[derive(Clone, Debug)]
pub struct Limits {
    /// Objects in the scene (shapes, CSG nodes and groups). A million spheres take about
    /// 300 MB; the default allows a few million.
    pub max_objects: usize,
    /// Loop iterations in total, over every loop of a compilation.
    pub max_loop_iterations: u64,
    /// Nested calls of user functions.
    pub max_call_depth: usize,
    /// Nested brackets `(` and `{`. Expressions and blocks together may nest 16 times this.
    pub max_nesting: usize,
    /// Nested imports.
    pub max_import_depth: usize,
    /// Source text in total, over every file, in bytes.
    pub max_source_bytes: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_objects: 5_000_000,
            max_loop_iterations: 100_000_000,
            max_call_depth: 256,
            max_nesting: 256,
            max_import_depth: 64,
            max_source_bytes: 64 * 1024 * 1024,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct CompileOptions {
    /// `-D NAME=VALUE` from the command line, in order: (NAME, VALUE source text).
    pub defines: Vec<(String, String)>,
    pub limits: Limits,
}

#[derive(Debug)]
pub struct Compilation {
    /// Every file read (root first, then imports), plus a pseudo-file for each -D value so that
    /// its diagnostics can point into it.
    pub sources: SourceMap,
    /// Some only when there are no errors (validation by whitted_ir::validate passed too).
    pub scene: Option<whitted_ir::ValidScene>,
    /// Errors, warnings and notes, in source order within each phase.
    pub diagnostics: Vec<Diagnostic>,
}

impl Compilation {
    /// Whether any diagnostic is an error (then `scene` is `None`).
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}
