//! Scopes and slots: which names are visible where, each definition's slot (a local of the
//! current call frame or a global), lookups, suggestions from what is visible, and uses.

use std::cell::Cell;
use std::collections::HashMap;

// Symbols are small numbers made by the interner, not text an attacker chooses the hashes
// of: the fast hash the interner uses is safe here and cheaper than SipHash on 100,000 names.
use foldhash::fast::FixedState;

use super::*;

pub(super) struct Scope {
    /// Every definition in the order it was made (for suggestions and exports).
    pub(super) names: Vec<(Sym, DefId)>,
    /// For each name: its first definition (what "already defined here" points at) and its
    /// latest (what a use finds). A script's file scope can hold 100,000 names, so finding one
    /// must not scan them all.
    pub(super) index: HashMap<Sym, (DefId, DefId), FixedState>,
    /// Names in scopes below this one (except the file scope) are not visible: a function
    /// body sees its own locals and the file's top level, nothing in between.
    pub(super) barrier: bool,
}

impl Scope {
    pub(super) fn new(barrier: bool) -> Scope {
        Scope {
            names: Vec::new(),
            index: HashMap::default(),
            barrier,
        }
    }

    /// A file's scope, with room for the names its top level defines.
    pub(super) fn with_capacity(names: usize) -> Scope {
        Scope {
            names: Vec::with_capacity(names),
            index: HashMap::with_capacity_and_hasher(names, FixedState::default()),
            barrier: false,
        }
    }

    pub(super) fn add(&mut self, sym: Sym, def: DefId) {
        self.names.push((sym, def));
        self.index
            .entry(sym)
            .and_modify(|(_, latest)| *latest = def)
            .or_insert((def, def));
    }

    pub(super) fn first(&self, sym: Sym, probes: &Cell<u64>) -> Option<DefId> {
        probes.set(probes.get() + 1);
        self.index.get(&sym).map(|&(first, _)| first)
    }

    pub(super) fn latest(&self, sym: Sym, probes: &Cell<u64>) -> Option<DefId> {
        probes.set(probes.get() + 1);
        self.index.get(&sym).map(|&(_, latest)| latest)
    }
}

/// Per-call-frame slot allocation: slots are reused once their scope ends.
#[derive(Clone, Copy, Default)]
pub(super) struct Frame {
    pub(super) next: u32,
    pub(super) size: u32,
}

impl<'a> Resolver<'a> {
    pub(super) fn push_scope(&mut self, barrier: bool) -> Frame {
        self.scopes.push(Scope::new(barrier));
        self.frame
    }

    pub(super) fn pop_scope(&mut self, saved: Frame) {
        self.scopes.pop();
        // Slots of the scope's locals are free again; the frame keeps its largest size.
        self.frame.next = saved.next;
    }

    pub(super) fn at_file_scope(&self) -> bool {
        self.scopes.len() == 1
    }

    pub(super) fn new_local(&mut self) -> Slot {
        let slot = self.frame.next;
        self.frame.next += 1;
        self.frame.size = self.frame.size.max(self.frame.next);
        Slot::Local(slot)
    }

    pub(super) fn new_global(&mut self) -> Slot {
        let slot = Slot::Global(self.resolution.global_count);
        self.resolution.global_count += 1;
        slot
    }

    /// Defines `ident` in the innermost scope. Returns the slot it lives in.
    pub(super) fn define(&mut self, ident: Ident, kind: DefKind, function: Option<FnId>) -> Slot {
        let slot = match kind {
            DefKind::Function => Slot::None,
            DefKind::Const | DefKind::Let | DefKind::Material if self.at_file_scope() => {
                self.new_global()
            }
            _ => self.new_local(),
        };
        let existing = self
            .scopes
            .last()
            .and_then(|s| s.first(ident.sym, &self.name_probes));
        if let Some(existing) = existing {
            let name = self.name(ident.sym);
            let first = &self.definitions[existing];
            let what = first.kind.describe();
            let first_span = first.span;
            self.error(
                Diagnostic::error(format!("`{name}` is already defined here"), ident.span)
                    .with_label("defined a second time")
                    .with_secondary(first_span, format!("first defined here, as {what}"))
                    .with_hint("names cannot be redefined in the same block; choose another name"),
            );
        }
        let def = self.definitions.len();
        self.definitions.push(Definition {
            name: ident.sym,
            span: ident.span,
            kind,
            file: self.file,
            slot,
            function,
            uses: 0,
        });
        if let Some(scope) = self.scopes.last_mut() {
            scope.add(ident.sym, def);
        }
        slot
    }

    /// Finds a visible definition: innermost scope first, skipping past a barrier to the
    /// file scope.
    pub(super) fn lookup(&self, sym: Sym) -> Option<DefId> {
        for (depth, scope) in self.scopes.iter().enumerate().rev() {
            if let Some(def) = scope.latest(sym, &self.name_probes) {
                return Some(def);
            }
            if scope.barrier && depth > 0 {
                return self
                    .scopes
                    .first()
                    .and_then(|s| s.latest(sym, &self.name_probes));
            }
        }
        None
    }

    /// Every name visible here, for suggestions.
    pub(super) fn visible_names(&self) -> Vec<(&'a str, DefKind)> {
        let mut names = Vec::new();
        for (depth, scope) in self.scopes.iter().enumerate().rev() {
            for &(sym, def) in &scope.names {
                names.push((self.name(sym), self.definitions[def].kind));
            }
            if scope.barrier && depth > 0 {
                if let Some(file_scope) = self.scopes.first() {
                    for &(sym, def) in &file_scope.names {
                        names.push((self.name(sym), self.definitions[def].kind));
                    }
                }
                break;
            }
        }
        names
    }

    pub(super) fn note_use(&mut self, def: DefId) {
        let definition = &mut self.definitions[def];
        if definition.function.is_some() && definition.function == self.current_function {
            return;
        }
        definition.uses += 1;
    }

    /// An unknown name: says whether it is defined later, or suggests the closest one.
    pub(super) fn unknown(&mut self, ident: Ident, what: &str, candidates: Vec<&str>) {
        let name = self.name(ident.sym);
        if let Some(&later) = self.later.get(&ident.sym) {
            if later.start > ident.span.start || self.current_function.is_some() {
                self.error(
                    Diagnostic::error(format!("`{name}` is used before it is defined"), ident.span)
                        .with_label("used here")
                        .with_secondary(later, "defined here, later in the file")
                        .with_hint(
                            "definitions take effect in file order; move it above its first use",
                        ),
                );
                return;
            }
        }
        let mut diagnostic = Diagnostic::error(format!("unknown {what} `{name}`"), ident.span)
            .with_label(match what {
                "name" => "nothing with this name is defined here".to_string(),
                _ => format!("no {what} with this name is defined here"),
            });
        if let Some(best) = closest(name, candidates.iter().copied()) {
            diagnostic = diagnostic.with_hint(format!("did you mean `{best}`?"));
        }
        if let Some(advice) = crate::hints::unknown_name(name) {
            diagnostic = diagnostic.with_hint(advice);
        }
        self.error(diagnostic);
    }
}
