//! Source files, byte spans into them, and the line/column lookup that diagnostics need.

use std::sync::Arc;

use serde::Serialize;

/// Which source file a span points into: an index into the [`SourceMap`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct FileId(pub u32);

/// A byte range `start..end` in one source file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct Span {
    pub file: FileId,
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(file: FileId, start: usize, end: usize) -> Self {
        let clamp = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        Span {
            file,
            start: clamp(start),
            end: clamp(end.max(start)),
        }
    }

    /// A span for nodes that no source text made (defaults, synthesised materials).
    pub const fn detached() -> Self {
        Span {
            file: FileId(u32::MAX),
            start: 0,
            end: 0,
        }
    }

    pub fn is_detached(&self) -> bool {
        self.file.0 == u32::MAX
    }

    pub fn range(&self) -> std::ops::Range<usize> {
        self.start as usize..self.end as usize
    }

    /// The smallest span covering both (same file assumed; `self`'s file wins).
    pub fn to(self, other: Span) -> Span {
        Span {
            file: self.file,
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }
}

/// A 1-based line and a 1-based column counted in characters, as editors show them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct LineCol {
    pub line: u32,
    pub column: u32,
}

/// One loaded source file.
#[derive(Clone, Debug)]
pub struct SourceFile {
    /// The path as the user or the importing file named it (shown in diagnostics).
    pub path: String,
    /// An `Arc<String>` rather than an `Arc<str>`: a file's text moves in without being
    /// copied (a generated scene can be hundreds of megabytes).
    pub text: Arc<String>,
    line_starts: Arc<[u32]>,
}

impl SourceFile {
    pub fn new(path: impl Into<String>, text: impl Into<String>) -> Self {
        let text = Arc::new(text.into());
        // memchr finds the newlines many bytes at a time: a generated scene is millions of lines.
        let line_starts: Vec<u32> = std::iter::once(0)
            .chain(
                memchr::memchr_iter(b'\n', text.as_bytes())
                    .map(|i| u32::try_from(i + 1).unwrap_or(u32::MAX)),
            )
            .collect();
        SourceFile {
            path: path.into(),
            text,
            line_starts: line_starts.into(),
        }
    }

    /// Line and column of a byte offset (clamped to the text).
    pub fn line_col(&self, offset: u32) -> LineCol {
        let offset = offset.min(self.text.len() as u32);
        let line_index = match self.line_starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let line_start = self.line_starts[line_index] as usize;
        let mut end = offset as usize;
        while !self.text.is_char_boundary(end) {
            end -= 1;
        }
        let column = self.text[line_start..end].chars().count() + 1;
        LineCol {
            line: line_index as u32 + 1,
            column: column as u32,
        }
    }

    /// The text of a 1-based line, without its line ending.
    pub fn line_text(&self, line: u32) -> &str {
        let index = line.saturating_sub(1) as usize;
        let Some(&start) = self.line_starts.get(index) else {
            return "";
        };
        let end = self
            .line_starts
            .get(index + 1)
            .map_or(self.text.len(), |&e| e as usize);
        self.text[start as usize..end].trim_end_matches(['\n', '\r'])
    }

    pub fn line_count(&self) -> u32 {
        self.line_starts.len() as u32
    }
}

/// Every source file a scene was compiled from, in load order. Travels with the IR so that
/// the CLI and the debugger can show the line that made any object.
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    files: Vec<SourceFile>,
}

impl SourceMap {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn add(&mut self, file: SourceFile) -> FileId {
        self.files.push(file);
        FileId(self.files.len() as u32 - 1)
    }

    pub fn get(&self, id: FileId) -> Option<&SourceFile> {
        self.files.get(id.0 as usize)
    }

    pub fn files(&self) -> impl ExactSizeIterator<Item = (FileId, &SourceFile)> + '_ {
        self.files
            .iter()
            .enumerate()
            .map(|(i, f)| (FileId(i as u32), f))
    }

    /// `path:line:column` of a span's start, or `<built-in>` for a detached span.
    pub fn location(&self, span: Span) -> String {
        match self.get(span.file) {
            Some(file) => {
                let lc = file.line_col(span.start);
                format!("{}:{}:{}", file.path, lc.line, lc.column)
            }
            None => "<built-in>".to_string(),
        }
    }

    pub fn line_col(&self, span: Span) -> Option<LineCol> {
        self.get(span.file).map(|file| file.line_col(span.start))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_are_one_based_and_count_characters() {
        let file = SourceFile::new("a.scene", "ab\nçd e\n\nlast");
        assert_eq!(file.line_col(0), LineCol { line: 1, column: 1 });
        assert_eq!(file.line_col(3), LineCol { line: 2, column: 1 });
        // 'ç' is two bytes, so byte 6 (the space) is the third character of its line.
        assert_eq!(file.line_col(6), LineCol { line: 2, column: 3 });
        assert_eq!(file.line_col(9), LineCol { line: 3, column: 1 });
        assert_eq!(file.line_col(10), LineCol { line: 4, column: 1 });
        assert_eq!(file.line_text(2), "çd e");
        assert_eq!(file.line_text(9), "");
    }

    #[test]
    fn location_names_path_line_and_column() {
        let mut map = SourceMap::new();
        let id = map.add(SourceFile::new("dir/x.scene", "one\ntwo"));
        assert_eq!(map.location(Span::new(id, 5, 6)), "dir/x.scene:2:2");
        assert_eq!(map.location(Span::detached()), "<built-in>");
    }
}
