//! The instantiation stack while the evaluator runs: which imports, calls and loop
//! iterations are active, turned into `whitted_ir::Provenance` frames only when an object is
//! made under them.
//!
//! Entering a loop iteration, a call or an imported file only writes a pending entry (no
//! allocation, no formatting); the first object made under it turns the pending entries into
//! IR frames, which every later object made in the same iteration shares. Objects at the top
//! level of the root file find the stack empty and cost one length check.

use std::collections::HashMap;

use whitted_ir::{ArgValue, FrameId, Handle, Object, Site, SiteId, SiteKind, Span};

use super::Evaluator;
use crate::ast::{FileIndex, FnId};
use crate::intern::Sym;
use crate::strings::format_number;
use crate::value::Value;

/// Arrays shown as an argument are cut after this many elements, so that a call with a huge
/// array does not copy it into every frame.
const MAX_SHOWN_ELEMENTS: usize = 8;

#[derive(Clone, Copy, Debug)]
enum PendingKind {
    Loop {
        var: Sym,
        value: f64,
    },
    /// The call's arguments are `stack[first..first + count]` of the evaluator: the first
    /// slots of the callee's frame, which hold them for the whole call (parameters cannot be
    /// assigned to).
    Call {
        function: FnId,
        first: usize,
        count: usize,
    },
    Import,
}

#[derive(Clone, Copy, Debug)]
struct Pending {
    kind: PendingKind,
    span: Span,
    /// The IR site, once one frame of this entry was made.
    site: Option<SiteId>,
    /// The IR frame of the current iteration or call, once an object needed it.
    frame: Option<FrameId>,
}

/// The evaluator's part of provenance (see the module documentation).
#[derive(Default)]
pub(super) struct Trail {
    pending: Vec<Pending>,
    /// Sites already in the IR, by kind and span, so that a loop run many times (an inner
    /// loop, a function called again) has one site.
    sites: HashMap<(u8, Span), SiteId>,
    /// The import line that first ran each file, by file index.
    imported_by: Vec<Option<Span>>,
}

impl Trail {
    /// Notes the import line that runs `file`; the first one is kept.
    pub(super) fn note_import(&mut self, file: FileIndex, span: Span) {
        if self.imported_by.len() <= file {
            self.imported_by.resize(file + 1, None);
        }
        if self.imported_by[file].is_none() {
            self.imported_by[file] = Some(span);
        }
    }

    /// The import line through which `file`'s code runs, if it is an imported file.
    pub(super) fn import_of(&self, file: FileIndex) -> Option<Span> {
        self.imported_by.get(file).copied().flatten()
    }

    fn push(&mut self, kind: PendingKind, span: Span) {
        self.pending.push(Pending {
            kind,
            span,
            site: None,
            frame: None,
        });
    }

    pub(super) fn enter_loop(&mut self, var: Sym, span: Span) {
        self.push(PendingKind::Loop { var, value: 0.0 }, span);
    }

    /// Starts the next iteration of the innermost loop: objects made from now on get a new
    /// frame.
    pub(super) fn next_iteration(&mut self, value: f64) {
        if let Some(Pending {
            kind: PendingKind::Loop { value: current, .. },
            frame,
            ..
        }) = self.pending.last_mut()
        {
            *current = value;
            *frame = None;
        }
    }

    pub(super) fn enter_import(&mut self, span: Span) {
        self.push(PendingKind::Import, span);
    }

    /// Enters a call whose `count` arguments are on the evaluator's stack from `first`.
    pub(super) fn enter_call(&mut self, function: FnId, span: Span, first: usize, count: usize) {
        self.push(
            PendingKind::Call {
                function,
                first,
                count,
            },
            span,
        );
    }

    /// Leaves the innermost loop, call or import.
    pub(super) fn leave(&mut self) {
        self.pending.pop();
    }
}

impl<'a> Evaluator<'a> {
    /// Records the instantiation stack of an object just appended.
    pub(super) fn record_provenance(&mut self, object: Handle<Object>) {
        if self.trail.pending.is_empty() {
            return;
        }
        let frame = self.current_frame();
        self.scene.provenance.set_object(object, frame);
    }

    /// The IR frame of the innermost pending entry, making the frames not made yet.
    fn current_frame(&mut self) -> Option<FrameId> {
        let pending = &self.trail.pending;
        // Entries below a made frame are made too (a frame is only dropped when its loop
        // moves on, and everything above it has been left by then).
        let mut start = pending.len();
        while start > 0 && pending[start - 1].frame.is_none() {
            start -= 1;
        }
        let mut parent = start.checked_sub(1).and_then(|i| pending[i].frame);
        for index in start..self.trail.pending.len() {
            let entry = self.trail.pending[index];
            let site = match entry.site {
                Some(site) => site,
                None => {
                    let site = self.site(entry.kind, entry.span);
                    self.trail.pending[index].site = Some(site);
                    site
                }
            };
            let provenance = &mut self.scene.provenance;
            let frame = match entry.kind {
                PendingKind::Loop { value, .. } => provenance.push_loop(parent, site, value),
                PendingKind::Import => provenance.push_import(parent, site),
                PendingKind::Call { first, count, .. } => {
                    let values = self.stack.get(first..first + count).unwrap_or(&[]);
                    let args: Vec<ArgValue> = values
                        .iter()
                        .map(|&value| self.arg_value(value, 0))
                        .collect();
                    self.scene.provenance.push_call(parent, site, args)
                }
            };
            self.trail.pending[index].frame = Some(frame);
            parent = Some(frame);
        }
        parent
    }

    /// The IR site of a pending entry, added on its first use.
    fn site(&mut self, kind: PendingKind, span: Span) -> SiteId {
        let key = match kind {
            PendingKind::Loop { .. } => 0,
            PendingKind::Call { .. } => 1,
            PendingKind::Import => 2,
        };
        if let Some(&site) = self.trail.sites.get(&(key, span)) {
            return site;
        }
        let site = match kind {
            PendingKind::Loop { var, .. } => Site {
                kind: SiteKind::Loop,
                span,
                name: self.name(var).to_string(),
                params: Vec::new(),
            },
            PendingKind::Call { function, .. } => {
                let program = self.program;
                let (name, params) = match program.functions.get(function) {
                    Some(f) => (
                        self.name(f.name.sym).to_string(),
                        f.params
                            .iter()
                            .map(|p| self.name(p.sym).to_string())
                            .collect(),
                    ),
                    None => (String::new(), Vec::new()),
                };
                Site {
                    kind: SiteKind::Call,
                    span,
                    name,
                    params,
                }
            }
            PendingKind::Import => Site {
                kind: SiteKind::Import,
                span,
                name: String::new(),
                params: Vec::new(),
            },
        };
        let site = self.scene.provenance.add_site(site);
        self.trail.sites.insert((key, span), site);
        site
    }

    /// An argument as the IR keeps it: numbers, booleans and vectors as values, the rest as
    /// the text the language would write for it.
    fn arg_value(&self, value: Value, depth: usize) -> ArgValue {
        match value {
            Value::Number(x) => ArgValue::Number(x),
            Value::Bool(b) => ArgValue::Bool(b),
            Value::Vector(v) => ArgValue::Vector(v),
            other => ArgValue::Text(self.value_text(other, depth)),
        }
    }

    pub(super) fn value_text(&self, value: Value, depth: usize) -> String {
        match value {
            Value::Str(id) => format!(
                "{:?}",
                self.store
                    .strings
                    .get(id as usize)
                    .map_or("", String::as_str)
            ),
            Value::Array(id) => {
                let items = self
                    .store
                    .arrays
                    .get(id as usize)
                    .map_or(&[][..], Vec::as_slice);
                if depth > 2 {
                    return format!("[{} elements]", items.len());
                }
                let mut shown: Vec<String> = items
                    .iter()
                    .take(MAX_SHOWN_ELEMENTS)
                    .map(|&item| self.arg_value(item, depth + 1).to_string())
                    .collect();
                if items.len() > MAX_SHOWN_ELEMENTS {
                    shown.push(format!("... {} more", items.len() - MAX_SHOWN_ELEMENTS));
                }
                format!("[{}]", shown.join(", "))
            }
            Value::Material(id) => match self.materials.get(id as usize) {
                Some(def) => match &def.material.name {
                    Some(name) => format!("material {name}"),
                    None => "a material".to_string(),
                },
                None => "a material".to_string(),
            },
            Value::Pattern(_) => "a pattern".to_string(),
            Value::Number(x) => format_number(x),
            Value::Bool(b) => b.to_string(),
            Value::Vector(v) => format!(
                "<{}, {}, {}>",
                format_number(v.x),
                format_number(v.y),
                format_number(v.z)
            ),
            // A poisoned argument means an error was reported; the scene is not built.
            Value::Poisoned => "an erroneous value".to_string(),
        }
    }
}
