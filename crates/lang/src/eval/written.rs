//! Fills the scene's table of where settings and properties were written
//! ([`whitted_ir::Written`]): each `settings`, camera, light and material block once (a loop
//! runs a block many times; its text is one), and each property in it once.

use std::collections::{HashMap, HashSet};

use whitted_ir::{BlockId, BlockKind, Span, WrittenBlock, WrittenProperty};

use super::Evaluator;
use crate::ast::Property;
use crate::schema::Prop;

/// The evaluator's side of the table: which block is open, and what was recorded already.
#[derive(Default)]
pub(super) struct WrittenRecorder {
    open: Option<BlockId>,
    blocks: HashMap<(BlockKind, Span), BlockId>,
    recorded: HashSet<Span>,
}

impl Evaluator<'_> {
    /// Opens the block of `kind` made by `header` (its braces `body`); returns the block that
    /// was open, for [`Evaluator::leave_written_block`].
    pub(super) fn enter_written_block(
        &mut self,
        kind: BlockKind,
        header: Span,
        body: Span,
    ) -> Option<BlockId> {
        let written = &mut self.scene.written;
        let id = *self
            .written
            .blocks
            .entry((kind, header))
            .or_insert_with(|| written.add_block(WrittenBlock { kind, header, body }));
        self.written.open.replace(id)
    }

    pub(super) fn leave_written_block(&mut self, previous: Option<BlockId>) {
        self.written.open = previous;
    }

    /// Records where `property` (of the open block) was written.
    pub(super) fn record_written(&mut self, property: &Property, prop: Prop) {
        let Some(block) = self.written.open else {
            return;
        };
        let name_span = property.name.span;
        if !self.written.recorded.insert(name_span) {
            return;
        }
        let value_span = match (property.values.first(), property.values.last()) {
            (Some(first), Some(last)) if first.span.file == last.span.file => Span::new(
                first.span.file,
                first.span.start as usize,
                last.span.end as usize,
            ),
            _ => Span::new(
                name_span.file,
                name_span.end as usize,
                name_span.end as usize,
            ),
        };
        self.scene.written.add_property(WrittenProperty {
            block,
            name: prop.name(),
            name_span,
            value_span,
        });
    }

    /// Records a `--set NAME=VALUE` (its pseudo-file holds `NAME=VALUE`, the value at
    /// `value_span`) as a settings block of its own, after the scene's.
    pub(super) fn record_override(&mut self, prop: Prop, value_span: Span) {
        let file = value_span.file;
        let name_end = (value_span.start as usize).saturating_sub(1);
        let header = Span::new(file, 0, value_span.end as usize);
        let block = self.scene.written.add_block(WrittenBlock {
            kind: BlockKind::Settings,
            header,
            body: Span::detached(),
        });
        self.scene.written.add_property(WrittenProperty {
            block,
            name: prop.name(),
            name_span: Span::new(file, 0, name_end),
            value_span,
        });
    }
}
