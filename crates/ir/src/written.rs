//! Where each setting and each property of the camera, the lights and the materials was
//! written: the spans of its name and its value, and of the block that holds it. A side table
//! beside the scene like the arenas' spans, filled by both front ends, so that explain, the
//! linter and the debugger's write-back find a setting without reading the scene's text again.
//!
//! Objects' own properties are not recorded: a scene written by a program has millions of
//! them, and nothing after the IR needs their spans.

use crate::source::Span;

/// The kind of block a property was written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BlockKind {
    Settings,
    Camera,
    Light,
    Material,
}

/// A block that holds properties.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WrittenBlock {
    pub kind: BlockKind,
    /// The block's header: the span the IR keeps for what it made (`material glass`, a
    /// light's `light point "sun"`, `settings`, the camera's); for `--set` and other
    /// command-line flags, the whole pseudo-file.
    pub header: Span,
    /// From `{` to `}` included; detached when the block has no braces (the command line).
    pub body: Span,
}

/// Identifies a block in a [`Written`] table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BlockId(u32);

/// One property as written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WrittenProperty {
    pub block: BlockId,
    /// The property's name in the scene language (`max_depth`, `diffuse`, `color`).
    pub name: &'static str,
    pub name_span: Span,
    /// From the first value's start to the last value's end (for a flag, the empty span at
    /// the name's end).
    pub value_span: Span,
}

/// The table: blocks and their properties, in the order they ran, so that the last one of
/// a setting is the one that took effect (`--set` runs after the scene).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Written {
    blocks: Vec<WrittenBlock>,
    properties: Vec<WrittenProperty>,
}

impl Written {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn add_block(&mut self, block: WrittenBlock) -> BlockId {
        self.blocks.push(block);
        BlockId((self.blocks.len() - 1) as u32)
    }

    pub fn add_property(&mut self, property: WrittenProperty) {
        self.properties.push(property);
    }

    pub fn block(&self, id: BlockId) -> Option<&WrittenBlock> {
        self.blocks.get(id.0 as usize)
    }

    pub fn blocks(&self) -> impl Iterator<Item = (BlockId, &WrittenBlock)> {
        self.blocks
            .iter()
            .enumerate()
            .map(|(i, b)| (BlockId(i as u32), b))
    }

    pub fn properties(&self) -> &[WrittenProperty] {
        &self.properties
    }

    /// Where the setting `name` that took effect was written: the last one, in the scene's
    /// `settings` blocks or on the command line.
    pub fn setting(&self, name: &str) -> Option<&WrittenProperty> {
        self.properties.iter().rev().find(|p| {
            p.name == name
                && self
                    .block(p.block)
                    .is_some_and(|b| b.kind == BlockKind::Settings)
        })
    }

    /// Every place `name` was written in the block(s) of `kind` whose header is `header`
    /// (a material or light made by a loop has one block run many times, recorded once).
    pub fn properties_in(
        &self,
        kind: BlockKind,
        header: Span,
        name: &str,
    ) -> impl Iterator<Item = &WrittenProperty> + '_ {
        let name = name.to_string();
        self.properties.iter().filter(move |p| {
            p.name == name
                && self
                    .block(p.block)
                    .is_some_and(|b| b.kind == kind && b.header == header)
        })
    }

    /// The block of `kind` whose header is `header`.
    pub fn block_at(&self, kind: BlockKind, header: Span) -> Option<&WrittenBlock> {
        self.blocks
            .iter()
            .find(|b| b.kind == kind && b.header == header)
    }

    /// The scene's own `settings` blocks (written in braces, not on the command line).
    pub fn settings_blocks(&self) -> impl Iterator<Item = &WrittenBlock> {
        self.blocks
            .iter()
            .filter(|b| b.kind == BlockKind::Settings && !b.body.is_detached())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::FileId;

    fn span(start: usize, end: usize) -> Span {
        Span::new(FileId(0), start, end)
    }

    #[test]
    fn the_last_setting_written_is_the_one_found() {
        let mut written = Written::new();
        let settings = written.add_block(WrittenBlock {
            kind: BlockKind::Settings,
            header: span(0, 8),
            body: span(9, 40),
        });
        let material = written.add_block(WrittenBlock {
            kind: BlockKind::Material,
            header: span(41, 55),
            body: span(56, 80),
        });
        written.add_property(WrittenProperty {
            block: settings,
            name: "max_depth",
            name_span: span(11, 20),
            value_span: span(21, 22),
        });
        written.add_property(WrittenProperty {
            block: material,
            name: "ambient",
            name_span: span(58, 65),
            value_span: span(66, 69),
        });
        let command_line = written.add_block(WrittenBlock {
            kind: BlockKind::Settings,
            header: span(100, 111),
            body: Span::detached(),
        });
        written.add_property(WrittenProperty {
            block: command_line,
            name: "max_depth",
            name_span: span(100, 109),
            value_span: span(110, 111),
        });
        assert_eq!(
            written.setting("max_depth").map(|p| p.value_span),
            Some(span(110, 111))
        );
        assert_eq!(
            written.setting("ambient"),
            None,
            "a material's ambient is not a setting"
        );
        assert_eq!(written.settings_blocks().count(), 1);
        assert_eq!(
            written
                .properties_in(BlockKind::Material, span(41, 55), "ambient")
                .count(),
            1
        );
    }
}
