//! whitted-lsp: the language server behind `whitted lsp`: diagnostics from the compiler
//! (the scene language, and 6.837 `.txt` scenes), hover and completion from the property
//! table, go to definition, references, rename and the outline from the resolver (and for
//! objects' names and files' strings, `strings.rs`), hover on
//! names from what evaluation found, quick fixes from the diagnostics' suggestions, and the
//! view features (semantic tokens, folding, colours, inlay hints: `view.rs`).
//!
//! The crate speaks the protocol over an lsp-server `Connection` the binary makes on stdio
//! (`run.rs`); what each message does is [`Server`] (`server.rs`), which tests drive
//! in-process. It reads no files itself: imports and meshes come from the editor's open
//! documents first, then through [`Files`], which the binary implements.

mod actions;
mod analysis;
mod colors;
mod completion;
mod documents;
mod folding;
mod hover;
mod inlays;
mod loader;
mod names;
mod navigation;
pub mod position;
mod references;
mod rename;
mod run;
mod server;
mod server_nav;
mod strings;
mod tokens;
mod view;

pub use run::{serve, serve_with};
pub use server::{capabilities, Server};

/// A material's picture for hover, made by whoever runs the server (the binary renders a
/// ball of it with the tracer; this crate never renders): a URI a Markdown image can show,
/// such as a PNG `data:` URI, or `None`.
pub trait Thumbnails {
    fn material(
        &self,
        materials: &whitted_ir::Arena<whitted_ir::Material>,
        material: whitted_ir::Handle<whitted_ir::Material>,
    ) -> Option<String>;
}

/// The files the server may read: imports and mesh files that are not open in the editor.
pub trait Files {
    fn read(&mut self, path: &std::path::Path) -> std::io::Result<Vec<u8>>;

    /// What makes two paths the same file (see `whitted_lang::SourceLoader::identify`).
    fn identify(&mut self, path: &std::path::Path) -> std::path::PathBuf {
        path.to_path_buf()
    }
}

#[cfg(test)]
mod nav_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod view_tests;
