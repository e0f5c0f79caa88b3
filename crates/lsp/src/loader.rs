//! The compiler's loaders for the server: open documents first (the editor's unsaved text
//! is what the user means), then the files the binary reads for us.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use lsp_types::Url;

use crate::documents::Document;
use crate::Files;

pub struct Overlay<'a> {
    pub documents: &'a HashMap<Url, Document>,
    pub files: &'a mut dyn Files,
}

impl Overlay<'_> {
    fn open(&mut self, path: &Path) -> Option<Vec<u8>> {
        let identity = self.files.identify(path);
        self.documents
            .values()
            .find(|doc| {
                doc.path.as_deref() == Some(path) || doc.identity.as_deref() == Some(&identity)
            })
            .map(|doc| doc.text.clone().into_bytes())
    }
}

impl whitted_lang::SourceLoader for Overlay<'_> {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        match self.open(path) {
            Some(bytes) => Ok(bytes),
            None => self.files.read(path),
        }
    }

    fn identify(&mut self, path: &Path) -> PathBuf {
        self.files.identify(path)
    }
}

impl whitted_mit6837::MeshLoader for Overlay<'_> {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        self.files.read(path)
    }
}
