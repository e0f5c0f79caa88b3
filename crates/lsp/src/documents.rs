//! The open documents: each one's text as the editor has it (which imports read instead of
//! the disk), its line index, and what the last analysis of that text found.

use std::collections::HashMap;
use std::path::PathBuf;

use lsp_types::{TextDocumentContentChangeEvent, Url};

use crate::analysis::Analysis;
use crate::position::LineIndex;

/// The open documents whose last analysis kept an editor index (every file parsed), each
/// with its analysis and index: what references, renames and file strings search.
pub fn indexed(
    documents: &HashMap<Url, Document>,
) -> impl Iterator<Item = (&Url, &Document, &Analysis, &whitted_lang::editor::Index)> {
    documents.iter().filter_map(|(uri, document)| {
        let analysis = document.analysis.as_ref()?;
        let index = analysis.index.as_ref()?;
        Some((uri, document, analysis, index))
    })
}

pub struct Document {
    pub text: String,
    pub version: i32,
    pub lines: LineIndex,
    /// The file the document is, when its URI names one (imports are relative to it).
    pub path: Option<PathBuf>,
    /// What the loader says the path is (through links), so that an import reaching the
    /// same file by another path reads this text.
    pub identity: Option<PathBuf>,
    /// The analysis of `text`; `None` until the text has been analysed since its last
    /// change.
    pub analysis: Option<Analysis>,
    /// The last whole-document semantic tokens sent, with their result id, for
    /// `semanticTokens/full/delta` (`tokens.rs`).
    pub sent_tokens: std::cell::RefCell<Option<lsp_types::SemanticTokens>>,
}

impl Document {
    pub fn new(uri: &Url, text: String, version: i32) -> Self {
        Document {
            lines: LineIndex::new(&text),
            text,
            version,
            path: uri.to_file_path().ok(),
            identity: None,
            analysis: None,
            sent_tokens: std::cell::RefCell::new(None),
        }
    }

    /// Applies an edit: a whole new text, or a range replaced (positions clamped to the
    /// text, so a stale or wrong range edits the nearest place rather than failing).
    pub fn apply(&mut self, change: TextDocumentContentChangeEvent) {
        match change.range {
            None => self.text = change.text,
            Some(range) => {
                let start = self.lines.offset(&self.text, range.start);
                let end = self.lines.offset(&self.text, range.end).max(start);
                self.text.replace_range(start..end, &change.text);
            }
        }
        self.lines = LineIndex::new(&self.text);
        self.analysis = None;
    }

    /// The URI's name for messages and the compiler's file name.
    pub fn name(&self, uri: &Url) -> String {
        match &self.path {
            Some(path) => path.to_string_lossy().into_owned(),
            None => uri.to_string(),
        }
    }
}
