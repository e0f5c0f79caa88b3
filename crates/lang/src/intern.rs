//! Interned names: every identifier becomes a small `Sym`, so the resolver compares integers
//! and the evaluator never touches strings.

use std::collections::HashMap;

/// An interned identifier. Only meaningful with the [`Interner`] that made it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Sym(u32);

#[derive(Default, Debug)]
pub struct Interner {
    ids: HashMap<Box<str>, Sym>,
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
