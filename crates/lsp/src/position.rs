//! Byte offsets (the compiler's spans) to and from LSP positions: a line and a column
//! counted in UTF-16 code units, the protocol's default encoding, so a line holding `é` or
//! `😀` before the place still lands on the right character.

use lsp_types::{Position, Range};

/// Where each line of a text starts, for conversions in both directions.
#[derive(Clone, Debug, Default)]
pub struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    pub fn new(text: &str) -> Self {
        let mut starts = vec![0];
        starts.extend(
            text.bytes()
                .enumerate()
                .filter(|&(_, b)| b == b'\n')
                .map(|(i, _)| i + 1),
        );
        LineIndex { starts }
    }

    /// The position of byte `offset` (clamped to the text, and to the start of the
    /// character it falls inside).
    /// The line (from 0) of a byte offset: [`Self::position`]'s line without counting the
    /// column.
    pub fn line(&self, offset: usize) -> u32 {
        saturate(self.starts.partition_point(|&start| start <= offset).max(1) - 1)
    }

    pub fn position(&self, text: &str, offset: usize) -> Position {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&start| start <= offset).max(1) - 1;
        // An index made for another text would put `start` anywhere: count nothing then
        // rather than slice outside a character.
        let start = self.starts.get(line).copied().unwrap_or(0).min(offset);
        let column = text
            .get(start..offset)
            .map_or(0, |s| s.encode_utf16().count());
        Position::new(saturate(line), saturate(column))
    }

    pub fn range(&self, text: &str, span: std::ops::Range<usize>) -> Range {
        Range::new(
            self.position(text, span.start),
            self.position(text, span.end),
        )
    }

    /// The byte offset of `position`. A line past the end is the end of the text; a column
    /// past the end of its line is the line's end (before its line break), as the protocol
    /// says; a column inside a surrogate pair is the character's start.
    pub fn offset(&self, text: &str, position: Position) -> usize {
        let Some(&start) = self.starts.get(position.line as usize) else {
            return text.len();
        };
        let end = self
            .starts
            .get(position.line as usize + 1)
            .map_or(text.len(), |next| next - 1);
        let Some(line) = text.get(start..end.max(start)) else {
            return text.len();
        };
        let line = line.strip_suffix('\r').unwrap_or(line);
        let mut units = 0usize;
        for (at, c) in line.char_indices() {
            units += c.len_utf16();
            if units > position.character as usize {
                return start + at;
            }
        }
        start + line.len()
    }
}

fn saturate(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `é` is two bytes and one UTF-16 unit; `😀` is four bytes and two units: `x` is byte 11
    /// of its line, character 6 and unit 7.
    const TEXT: &str = "a\n// é😀 x\nradius 1\r\nlast";

    #[test]
    fn columns_count_utf16_units() {
        let index = LineIndex::new(TEXT);
        let x = TEXT.find('x').unwrap();
        assert_eq!(index.position(TEXT, x), Position::new(1, 7));
        assert_eq!(index.offset(TEXT, Position::new(1, 7)), x);
        let smiley = TEXT.find('😀').unwrap();
        assert_eq!(index.position(TEXT, smiley), Position::new(1, 4));
        // Inside the surrogate pair: the character's start.
        assert_eq!(index.offset(TEXT, Position::new(1, 5)), smiley);
        // A byte inside a character counts as the character.
        assert_eq!(index.position(TEXT, smiley + 2), Position::new(1, 4));
    }

    #[test]
    fn every_offset_round_trips() {
        let index = LineIndex::new(TEXT);
        for (offset, c) in TEXT.char_indices() {
            if c == '\n' || c == '\r' {
                continue;
            }
            let position = index.position(TEXT, offset);
            assert_eq!(index.offset(TEXT, position), offset, "{c:?} at {offset}");
        }
    }

    #[test]
    fn past_the_end_clamps() {
        let index = LineIndex::new(TEXT);
        let radius_line_end = TEXT.find("\r\n").unwrap();
        assert_eq!(index.offset(TEXT, Position::new(2, 99)), radius_line_end);
        assert_eq!(index.offset(TEXT, Position::new(9, 0)), TEXT.len());
        assert_eq!(index.position(TEXT, 999), Position::new(3, 4));
        assert_eq!(index.position("", 0), Position::new(0, 0));
    }
}
