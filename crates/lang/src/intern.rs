//! Interned names: every identifier becomes a small `Sym`, so the resolver compares integers
//! and the evaluator never touches strings.

use std::collections::HashMap;

/// An interned identifier. Only meaningful with the [`Interner`] that made it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Sym(u32);

#[derive(Default, Debug)]
pub struct Interner {
    /// Hashed with foldhash, not SipHash: a scene written by a program interns a name for
    /// every word of a million statements, and no one chooses these keys to collide.
    ids: HashMap<Box<str>, Sym, foldhash::fast::FixedState>,
    names: Vec<Box<str>>,
}

impl Interner {
    pub fn intern(&mut self, name: &str) -> Sym {
        if let Some(&sym) = self.ids.get(name) {
            return sym;
        }
        let sym = Sym(u32::try_from(self.names.len()).unwrap_or(u32::MAX));
        self.names.push(name.into());
        self.ids.insert(name.into(), sym);
        sym
    }

    /// How many names are interned: a mark for [`Self::forget_after`].
    pub fn mark(&self) -> usize {
        self.names.len()
    }

    /// Forgets every name interned after `mark` (a parse that was abandoned), so the
    /// symbols of a second attempt are numbered as if the first had never run.
    #[inline]
    pub fn forget_after(&mut self, mark: usize) {
        // Backtracking usually interned nothing: keep that case to one comparison.
        if mark >= self.names.len() {
            return;
        }
        for name in self.names.drain(mark.min(self.names.len())..) {
            self.ids.remove(&name);
        }
    }

    /// Every interned name, in the order of their symbols (for tests comparing two parses).
    #[cfg(test)]
    pub(crate) fn names(&self) -> &[Box<str>] {
        &self.names
    }

    pub fn name(&self, sym: Sym) -> &str {
        self.names.get(sym.0 as usize).map_or("?", |name| name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_name_gives_the_same_symbol() {
        let mut interner = Interner::default();
        let a = interner.intern("radius");
        let b = interner.intern("center");
        assert_eq!(interner.intern("radius"), a);
        assert_ne!(a, b);
        assert_eq!(interner.name(b), "center");
    }
}
