//! `whitted lsp`: the language server on stdin and stdout; the protocol and every answer are
//! whitted-lsp's, the binary only opens stdio, reads the files the server asks for and
//! renders the material thumbnails its hovers show (`material_thumbnail.rs`).

use std::path::{Path, PathBuf};

use crate::failure::Failure;
use crate::scene_input::read_source;

/// Imports and mesh files not open in the editor, read as the other commands read them.
struct DiskFiles;

impl whitted_lsp::Files for DiskFiles {
    fn read(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        read_source(path)
    }

    fn identify(&mut self, path: &Path) -> PathBuf {
        std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
    }
}

pub fn lsp() -> Result<(), Failure> {
    let (connection, io_threads) = lsp_server::Connection::stdio();
    let thumbnails: Box<dyn whitted_lsp::Thumbnails> = Box::new(crate::material_thumbnail::Balls);
    let served = whitted_lsp::serve_with(&connection, Box::new(DiskFiles), Some(thumbnails));
    // The writer thread ends once every sender is gone; then the threads can be joined.
    drop(connection);
    let joined = io_threads.join();
    served.map_err(|e| Failure::Message(format!("language server: {e}")))?;
    joined.map_err(|e| Failure::Message(format!("language server: {e}")))
}
