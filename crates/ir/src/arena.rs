//! Typed arenas: items appended bottom-up, addressed by `Handle<T>`, each with its source span.
//!
//! Children are appended before their parents, so a handle always points backwards; arena
//! order is therefore a valid bottom-up order and cycles cannot be written down.

use std::fmt;
use std::hash::{Hash, Hasher};
use std::marker::PhantomData;

use crate::source::Span;

/// An index into an [`Arena<T>`]. Cheap to copy; typed so that a material handle cannot be
/// used where an object handle is expected.
pub struct Handle<T> {
    index: u32,
    marker: PhantomData<fn() -> T>,
}

impl<T> Handle<T> {
    /// Makes a handle from a raw index. The validator checks that every stored handle is in
    /// range, so a hand-made handle cannot reach the tracer unchecked.
    pub fn from_index(index: usize) -> Self {
        let index = u32::try_from(index).unwrap_or(u32::MAX);
        Handle {
            index,
            marker: PhantomData,
        }
    }

    /// The position of the item in its arena.
    pub fn index(self) -> usize {
        self.index as usize
    }
}

impl<T> Clone for Handle<T> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T> Copy for Handle<T> {}
impl<T> PartialEq for Handle<T> {
    fn eq(&self, other: &Self) -> bool {
        self.index == other.index
    }
}
impl<T> Eq for Handle<T> {}
impl<T> PartialOrd for Handle<T> {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl<T> Ord for Handle<T> {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.index.cmp(&other.index)
    }
}
impl<T> Hash for Handle<T> {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.index.hash(state)
    }
}
impl<T> fmt::Debug for Handle<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.index)
    }
}
impl<T> fmt::Display for Handle<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "#{}", self.index)
    }
}
impl<T> serde::Serialize for Handle<T> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_u32(self.index)
    }
}

/// A growable list of `T` with a span per item, kept in a side table so that
/// [`Arena::append`] makes the span impossible to forget.
#[derive(Clone, Debug)]
pub struct Arena<T> {
    items: Vec<T>,
    spans: Vec<Span>,
}

impl<T> Default for Arena<T> {
    fn default() -> Self {
        Arena {
            items: Vec::new(),
            spans: Vec::new(),
        }
    }
}

impl<T> Arena<T> {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn with_capacity(capacity: usize) -> Self {
        Arena {
            items: Vec::with_capacity(capacity),
            spans: Vec::with_capacity(capacity),
        }
    }

    /// Appends an item with the span of the source that made it and returns its handle.
    pub fn append(&mut self, value: T, span: Span) -> Handle<T> {
        let handle = Handle::from_index(self.items.len());
        self.items.push(value);
        self.spans.push(span);
        handle
    }

    pub fn get(&self, handle: Handle<T>) -> Option<&T> {
        self.items.get(handle.index())
    }

    pub fn get_mut(&mut self, handle: Handle<T>) -> Option<&mut T> {
        self.items.get_mut(handle.index())
    }

    /// The span of the source that made the item. Panics on a foreign handle, like indexing.
    pub fn span(&self, handle: Handle<T>) -> Span {
        self.spans[handle.index()]
    }

    pub fn contains(&self, handle: Handle<T>) -> bool {
        handle.index() < self.items.len()
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Items in arena (bottom-up) order with their handles.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (Handle<T>, &T)> + '_ {
        self.items
            .iter()
            .enumerate()
            .map(|(i, item)| (Handle::from_index(i), item))
    }

    /// Items with their handles and spans.
    pub fn iter_with_spans(&self) -> impl ExactSizeIterator<Item = (Handle<T>, &T, Span)> + '_ {
        self.items
            .iter()
            .zip(&self.spans)
            .enumerate()
            .map(|(i, (item, span))| (Handle::from_index(i), item, *span))
    }

    pub fn as_slice(&self) -> &[T] {
        &self.items
    }

    /// Drops the items from `len` on, with their spans, and gives their memory back: for a
    /// consumer that reads the arena from its end and needs no handle at or past `len`
    /// again (such a handle is then foreign).
    pub fn truncate(&mut self, len: usize) {
        self.items.truncate(len);
        self.items.shrink_to_fit();
        self.spans.truncate(len);
        self.spans.shrink_to_fit();
    }
}

impl<T> std::ops::Index<Handle<T>> for Arena<T> {
    type Output = T;
    fn index(&self, handle: Handle<T>) -> &T {
        &self.items[handle.index()]
    }
}

impl<T> std::ops::IndexMut<Handle<T>> for Arena<T> {
    fn index_mut(&mut self, handle: Handle<T>) -> &mut T {
        &mut self.items[handle.index()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::FileId;

    #[test]
    fn truncate_keeps_the_first_items_and_their_spans() {
        let mut arena = Arena::new();
        let spans: Vec<Span> = (0..5).map(|i| Span::new(FileId(0), i, i + 1)).collect();
        let handles: Vec<_> = spans.iter().map(|&s| arena.append(s.start, s)).collect();
        arena.truncate(2);
        assert_eq!(arena.len(), 2);
        assert_eq!((arena[handles[1]], arena.span(handles[1])), (1, spans[1]));
        assert!(!arena.contains(handles[2]));
        arena.truncate(7);
        assert_eq!(arena.len(), 2);
    }

    #[test]
    fn append_returns_sequential_handles_and_keeps_spans() {
        let mut arena = Arena::new();
        let span_a = Span::new(FileId(0), 0, 3);
        let span_b = Span::new(FileId(0), 4, 9);
        let a = arena.append("a", span_a);
        let b = arena.append("b", span_b);
        assert_eq!((a.index(), b.index()), (0, 1));
        assert_eq!(arena[b], "b");
        assert_eq!(arena.span(a), span_a);
        assert_eq!(arena.span(b), span_b);
        assert!(arena.contains(b));
        assert!(!arena.contains(Handle::from_index(2)));
    }
}
