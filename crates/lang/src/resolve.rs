//! Name resolution and static checks, after parsing and before evaluation.
//!
//! Walks every file once, annotating the tree in place: each name gets its slot (a local in
//! the current call frame, or a global), each call its target, each property and object kind
//! its meaning in the block it sits in. Everything that can be known without running the
//! scene is reported here, all at once: unknown names (with the closest known one), items in
//! the wrong place, wrong argument counts, unused materials and functions, `-D` names that
//! match no constant.

use std::cell::Cell;
use std::collections::HashMap;

use whitted_ir::{Diagnostic, Span};

use crate::ast::*;
use crate::builtins::{Constant, Function};

mod constructs;
use crate::intern::{Interner, Sym};
use crate::schema::{Arity, CameraTag, Context, LightTag, ObjectTag, Prop};
use crate::suggest::{closest, list_and, list_or};

/// What kind of definition a name has, for messages and for unused warnings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DefKind {
    Const,
    Let,
    Material,
    Function,
    Parameter,
    LoopVariable,
}

impl DefKind {
    fn describe(self) -> &'static str {
        match self {
            DefKind::Const => "a constant",
            DefKind::Let => "a `let` binding",
            DefKind::Material => "a material",
            DefKind::Function => "a function",
            DefKind::Parameter => "a parameter",
            DefKind::LoopVariable => "a loop variable",
        }
    }
}

/// One definition, wherever it lives. Bindings in scopes refer to these by index.
#[derive(Clone, Debug)]
struct Definition {
    name: Sym,
    span: Span,
    kind: DefKind,
    file: FileIndex,
    /// Where it lives at run time (functions have no slot).
    slot: Slot,
    function: Option<FnId>,
    uses: u32,
}

type DefId = usize;

/// A `-D NAME=VALUE` from the command line, parsed.
#[derive(Debug)]
pub struct Define {
    pub name: Sym,
    /// The NAME part in the define's pseudo-file.
    pub name_span: Span,
    pub value: Expr,
}

/// What the evaluator needs besides the annotated tree.
#[derive(Debug, Default)]
pub struct Resolution {
    /// How many global slots the program uses.
    pub global_count: u32,
    /// For each overridden `const` (by global slot): which define replaces its value.
    pub overrides: HashMap<u32, usize>,
    /// Definitions examined while defining and looking up names: a deterministic measure of
    /// the resolver's work, which must grow linearly with the number of names.
    pub name_probes: u64,
}

struct Scope {
    /// Every definition in the order it was made (for suggestions and exports).
    names: Vec<(Sym, DefId)>,
    /// For each name: its first definition (what "already defined here" points at) and its
    /// latest (what a use finds). A script's file scope can hold 100,000 names, so finding one
    /// must not scan them all.
    index: HashMap<Sym, (DefId, DefId)>,
    /// Names in scopes below this one (except the file scope) are not visible: a function
    /// body sees its own locals and the file's top level, nothing in between.
    barrier: bool,
}

impl Scope {
    fn new(barrier: bool) -> Scope {
        Scope {
            names: Vec::new(),
            index: HashMap::new(),
            barrier,
        }
    }

    fn add(&mut self, sym: Sym, def: DefId) {
        self.names.push((sym, def));
        self.index
            .entry(sym)
            .and_modify(|(_, latest)| *latest = def)
            .or_insert((def, def));
    }

    fn first(&self, sym: Sym, probes: &Cell<u64>) -> Option<DefId> {
        probes.set(probes.get() + 1);
        self.index.get(&sym).map(|&(first, _)| first)
    }

    fn latest(&self, sym: Sym, probes: &Cell<u64>) -> Option<DefId> {
        probes.set(probes.get() + 1);
        self.index.get(&sym).map(|&(_, latest)| latest)
    }
}

/// Per-call-frame slot allocation: slots are reused once their scope ends.
#[derive(Clone, Copy, Default)]
struct Frame {
    next: u32,
    size: u32,
}

pub struct Resolver<'a> {
    interner: &'a Interner,
    pub diagnostics: Vec<Diagnostic>,
    definitions: Vec<Definition>,
    /// Each file's top-level names once resolved, for `import`.
    exports: Vec<Option<Vec<(Sym, DefId)>>>,
    scopes: Vec<Scope>,
    frame: Frame,
    file: FileIndex,
    /// Top-level names of the file being resolved, for "used before it is defined".
    later: HashMap<Sym, Span>,
    /// The function whose body is being resolved (its own recursive calls are not "uses").
    current_function: Option<FnId>,
    defines: &'a [Define],
    define_used: Vec<bool>,
    resolution: Resolution,
    /// Which files are being resolved (an import of one of these is a cycle the loader
    /// already reported).
    in_progress: Vec<bool>,
    /// See [`Resolution::name_probes`]; a cell because lookups only read.
    name_probes: Cell<u64>,
}

impl<'a> Resolver<'a> {
    pub fn new(interner: &'a Interner, file_count: usize, defines: &'a [Define]) -> Self {
        Resolver {
            interner,
            diagnostics: Vec::new(),
            definitions: Vec::new(),
            exports: vec![None; file_count],
            scopes: Vec::new(),
            frame: Frame::default(),
            file: 0,
            later: HashMap::new(),
            current_function: None,
            defines,
            define_used: vec![false; defines.len()],
            resolution: Resolution::default(),
            in_progress: vec![false; file_count],
            name_probes: Cell::new(0),
        }
    }

    fn name(&self, sym: Sym) -> &'a str {
        self.interner.name(sym)
    }

    fn error(&mut self, diagnostic: Diagnostic) {
        self.diagnostics.push(diagnostic);
    }

    /// Resolves the root file (index 0) and, through its imports, every other file.
    pub fn resolve_program(mut self, program: &mut Program) -> (Resolution, Vec<Diagnostic>) {
        if !program.files.is_empty() {
            self.resolve_file(program, 0);
        }
        self.report_unused();
        self.report_unused_defines();
        self.resolution.name_probes = self.name_probes.get();
        (self.resolution, self.diagnostics)
    }

    /// Resolves a `-D` value: only built-ins are visible there.
    pub fn resolve_define_value(&mut self, expr: &mut Expr, program: &mut Program) {
        if let ExprKind::Material(_) = expr.kind {
            self.error(
                Diagnostic::error("a `-D` value cannot be a material", expr.span)
                    .with_hint("`-D` sets numbers, vectors and booleans"),
            );
            return;
        }
        let saved = std::mem::take(&mut self.scopes);
        self.scopes.push(Scope::new(true));
        self.expr(expr, program);
        self.scopes = saved;
    }

    fn resolve_file(&mut self, program: &mut Program, index: FileIndex) {
        if self.exports.get(index).is_some_and(Option::is_some)
            || self.in_progress.get(index).copied().unwrap_or(true)
        {
            return;
        }
        self.in_progress[index] = true;
        let saved_scopes = std::mem::take(&mut self.scopes);
        let saved_frame = std::mem::take(&mut self.frame);
        let saved_file = std::mem::replace(&mut self.file, index);
        let saved_later = std::mem::take(&mut self.later);

        self.scopes.push(Scope::new(false));
        let mut items = std::mem::take(&mut program.files[index].items);
        for item in &items {
            if let Some((sym, span)) = top_level_name(&item.kind, &program.functions) {
                self.later.entry(sym).or_insert(span);
            }
        }
        let top = Context::Statements {
            top_level: true,
            in_function: false,
        };
        for item in &mut items {
            if let ItemKind::Import {
                file: Some(imported),
                path,
            } = &item.kind
            {
                let (imported, path_span) = (*imported, path.span);
                self.resolve_file(program, imported);
                self.import_names(imported, path_span);
                continue;
            }
            self.item(item, top, program);
            // A top-level name becomes visible once defined; drop it from `later`.
            if let Some((sym, _)) = top_level_name(&item.kind, &program.functions) {
                self.later.remove(&sym);
            }
        }
        program.files[index].items = items;
        program.files[index].frame_size = self.frame.size;
        let file_scope = self.scopes.pop().map(|s| s.names).unwrap_or_default();
        self.exports[index] = Some(file_scope);

        self.scopes = saved_scopes;
        self.frame = saved_frame;
        self.file = saved_file;
        self.later = saved_later;
        self.in_progress[index] = false;
    }

    /// Brings an imported file's top-level names into the current file's top level.
    fn import_names(&mut self, imported: FileIndex, span: Span) {
        let Some(Some(names)) = self.exports.get(imported).cloned() else {
            return;
        };
        for (sym, def) in names {
            match self
                .scopes
                .first()
                .and_then(|s| s.first(sym, &self.name_probes))
            {
                Some(existing) if existing == def => {}
                Some(existing) => {
                    let first = self.definitions[existing].span;
                    let name = self.name(sym);
                    self.error(
                        Diagnostic::error(
                            format!("this import defines `{name}` a second time"),
                            span,
                        )
                        .with_label(format!("brings in another `{name}`"))
                        .with_secondary(self.definitions[def].span, "the imported definition")
                        .with_secondary(first, "the first definition"),
                    );
                }
                None => {
                    if let Some(scope) = self.scopes.first_mut() {
                        scope.add(sym, def);
                    }
                }
            }
        }
    }

    // ---- scopes and slots ------------------------------------------------------------------

    fn push_scope(&mut self, barrier: bool) -> Frame {
        self.scopes.push(Scope::new(barrier));
        self.frame
    }

    fn pop_scope(&mut self, saved: Frame) {
        self.scopes.pop();
        // Slots of the scope's locals are free again; the frame keeps its largest size.
        self.frame.next = saved.next;
    }

    fn at_file_scope(&self) -> bool {
        self.scopes.len() == 1
    }

    fn new_local(&mut self) -> Slot {
        let slot = self.frame.next;
        self.frame.next += 1;
        self.frame.size = self.frame.size.max(self.frame.next);
        Slot::Local(slot)
    }

    fn new_global(&mut self) -> Slot {
        let slot = Slot::Global(self.resolution.global_count);
        self.resolution.global_count += 1;
        slot
    }

    /// Defines `ident` in the innermost scope. Returns the slot it lives in.
    fn define(&mut self, ident: Ident, kind: DefKind, function: Option<FnId>) -> Slot {
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
    fn lookup(&self, sym: Sym) -> Option<DefId> {
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
    fn visible_names(&self) -> Vec<(&'a str, DefKind)> {
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

    fn note_use(&mut self, def: DefId) {
        let definition = &mut self.definitions[def];
        if definition.function.is_some() && definition.function == self.current_function {
            return;
        }
        definition.uses += 1;
    }

    /// An unknown name: says whether it is defined later, or suggests the closest one.
    fn unknown(&mut self, ident: Ident, what: &str, candidates: Vec<&str>) {
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

    // ---- items -----------------------------------------------------------------------------

    fn block(&mut self, block: &mut Block, cx: Context, program: &mut Program) {
        let saved = self.push_scope(false);
        for item in &mut block.items {
            self.item(item, cx, program);
        }
        self.pop_scope(saved);
    }

    fn item(&mut self, item: &mut Item, cx: Context, program: &mut Program) {
        let top_level = matches!(
            cx,
            Context::Statements {
                top_level: true,
                ..
            }
        );
        let in_function = matches!(
            cx,
            Context::Statements {
                in_function: true,
                ..
            }
        );
        // The context for `for` and `if` blocks: the same kind of block, no longer top level.
        let inner_cx = match cx {
            Context::Statements { in_function, .. } => Context::Statements {
                top_level: false,
                in_function,
            },
            other => other,
        };
        let item_span = item.span;
        let header = header_span(&item.kind, item.span);
        match &mut item.kind {
            ItemKind::Import { path, .. } => {
                // A top-level import was handled by `resolve_file`; here it is misplaced, or its
                // file could not be loaded (reported by the loader).
                if !top_level {
                    self.error(
                        Diagnostic::error(
                            "`import` is only allowed at the top level of a file",
                            item_span,
                        )
                        .with_label("inside a block")
                        .with_hint("move the import to the top of the file"),
                    );
                }
                let _ = path;
            }
            ItemKind::Const(binding) => {
                if !top_level {
                    self.error(
                        Diagnostic::error("`const` is only allowed at the top level of a file", binding.name.span)
                            .with_label("inside a block")
                            .with_hint("use `let` for a name inside a block; `const` marks values that `-D` can override"),
                    );
                }
                self.expr(&mut binding.value, program);
                binding.slot = self.define(binding.name, DefKind::Const, None);
                if let (Slot::Global(g), true) = (binding.slot, top_level) {
                    if let Some(index) =
                        self.defines.iter().position(|d| d.name == binding.name.sym)
                    {
                        self.define_used[index] = true;
                        // The last `-D` for a name wins, like a C compiler's.
                        let last = self
                            .defines
                            .iter()
                            .rposition(|d| d.name == binding.name.sym)
                            .unwrap_or(index);
                        self.resolution.overrides.insert(g, last);
                        for (i, d) in self.defines.iter().enumerate() {
                            if d.name == binding.name.sym {
                                self.define_used[i] = true;
                            }
                        }
                    }
                }
            }
            ItemKind::Let(binding) => {
                self.expr(&mut binding.value, program);
                binding.slot = self.define(binding.name, DefKind::Let, None);
            }
            ItemKind::Fn(id) => {
                let id = *id;
                let Some(name) = program.functions.get(id).map(|f| f.name) else {
                    return;
                };
                if !top_level {
                    self.error(
                        Diagnostic::error(
                            "functions can only be defined at the top level of a file",
                            name.span,
                        )
                        .with_label("inside a block"),
                    );
                }
                self.define(name, DefKind::Function, Some(id));
                self.function_body(id, program);
            }
            ItemKind::For {
                var,
                slot,
                start,
                end,
                step,
                body,
                ..
            } => {
                self.expr(start, program);
                self.expr(end, program);
                if let Some(step) = step {
                    self.expr(step, program);
                }
                let saved = self.push_scope(false);
                *slot = self.define(*var, DefKind::LoopVariable, None);
                self.block(body, inner_cx, program);
                self.pop_scope(saved);
            }
            ItemKind::While { condition, body } => {
                self.expr(condition, program);
                self.block(body, inner_cx, program);
            }
            ItemKind::Assign { target, value } => self.assign(target, value, cx, program),
            ItemKind::If {
                condition,
                then,
                otherwise,
            } => {
                self.expr(condition, program);
                self.block(then, inner_cx, program);
                match otherwise.as_deref_mut() {
                    Some(Else::If(item)) => self.item(item, inner_cx, program),
                    Some(Else::Block(block)) => self.block(block, inner_cx, program),
                    None => {}
                }
            }
            ItemKind::Return(value) => {
                if !in_function {
                    self.error(
                        Diagnostic::error("`return` is only allowed in a function body", item_span)
                            .with_label(format!("inside {}", cx.describe())),
                    );
                }
                self.expr(value, program);
            }
            ItemKind::Settings(body) => {
                if !top_level {
                    self.misplaced(
                        "`settings`",
                        header,
                        cx,
                        "put `settings` at the top level of a file",
                    );
                }
                self.block(body, Context::Settings, program);
            }
            ItemKind::Camera { kind, tag, body } => {
                if !top_level {
                    self.misplaced(
                        "a camera",
                        header,
                        cx,
                        "put the camera at the top level of a file",
                    );
                }
                *tag = CameraTag::ALL
                    .into_iter()
                    .find(|t| t.name() == self.name(kind.sym));
                let body_cx = match *tag {
                    Some(t) => Context::Camera(t),
                    None => {
                        let names: Vec<&str> = CameraTag::ALL.iter().map(|t| t.name()).collect();
                        self.unknown_kind("camera", *kind, &names);
                        Context::Unknown
                    }
                };
                self.block(body, body_cx, program);
            }
            ItemKind::Light {
                kind,
                tag,
                body,
                name,
            } => {
                self.string_holes(name.as_deref_mut());
                if !cx.is_statements() {
                    self.misplaced(
                        "a light",
                        header,
                        cx,
                        "lights are not objects: put them at the top level or in a function",
                    );
                }
                *tag = LightTag::ALL
                    .into_iter()
                    .find(|t| t.name() == self.name(kind.sym));
                let body_cx = match *tag {
                    Some(t) => Context::Light(t),
                    None => {
                        let names: Vec<&str> = LightTag::ALL.iter().map(|t| t.name()).collect();
                        self.unknown_kind("light", *kind, &names);
                        Context::Unknown
                    }
                };
                self.block(body, body_cx, program);
            }
            ItemKind::Material { name, slot, body } => {
                if !cx.is_statements() {
                    let inline = format!(
                        "to derive a material inline, write `material : {} {{ ... }}`",
                        self.name(name.sym)
                    );
                    self.misplaced("a material definition", header, cx, &inline);
                    // Most likely an attempt to derive from `name`: count it as a use
                    // rather than defining it, so no "never used" follows.
                    if let Some(def) = self.lookup(name.sym) {
                        self.note_use(def);
                    }
                    self.material_body(body, program);
                    return;
                }
                self.material_body(body, program);
                *slot = self.define(*name, DefKind::Material, None);
            }
            ItemKind::Object {
                kind,
                tag,
                body,
                name,
            } => {
                self.string_holes(name.as_deref_mut());
                let allowed = match cx {
                    Context::Statements { .. } => true,
                    Context::Object(parent) => parent.is_container(),
                    _ => false,
                };
                if !allowed {
                    let hint = match cx {
                        Context::Object(_) => "only `union`, `intersection`, `difference` and `group` hold other objects",
                        _ => "objects go at the top level, in functions, or inside `union`, `intersection`, `difference` and `group`",
                    };
                    self.misplaced("an object", header, cx, hint);
                }
                *tag = self.object_tag(*kind);
                let body_cx = tag.map_or(Context::Unknown, Context::Object);
                self.block(body, body_cx, program);
            }
            ItemKind::Call { call, modifiers } => {
                let allowed = match cx {
                    Context::Statements { .. } => true,
                    Context::Object(parent) => parent.is_container(),
                    _ => false,
                };
                let callee = self.name(call.callee.sym);
                if cx.properties().iter().any(|p| p.name() == callee)
                    && self.lookup(call.callee.sym).is_none()
                {
                    // `scale(2)`: a property written like a call.
                    self.error(
                        Diagnostic::error(
                            format!("`{callee}` is a property, not a function"),
                            call.callee.span,
                        )
                        .with_label("written like a call")
                        .with_hint(format!(
                            "put a space between a property and its value: `{callee} (...)`"
                        )),
                    );
                    return;
                }
                if !allowed {
                    self.misplaced(
                        "a function call",
                        call.span,
                        cx,
                        "a call as a statement makes objects, so it goes where objects go",
                    );
                }
                self.call(call, program);
                if let Some(block) = modifiers {
                    self.block(block, Context::Modifiers, program);
                }
            }
            ItemKind::Property(property) if self.is_unbraced_object(property) => {
                self.unbraced_object(property)
            }
            ItemKind::Property(property) => self.property(property, cx, program),
        }
    }

    fn misplaced(&mut self, what: &str, span: Span, cx: Context, hint: &str) {
        let message = format!("{what} cannot go inside {}", cx.describe());
        self.error(
            Diagnostic::error(message, span)
                .with_label("not allowed here")
                .with_hint(hint.to_string()),
        );
    }

    fn unknown_kind(&mut self, what: &str, kind: Ident, names: &[&str]) {
        let name = self.name(kind.sym);
        let mut diagnostic = Diagnostic::error(format!("unknown {what} kind `{name}`"), kind.span)
            .with_label(format!("not a kind of {what}"));
        diagnostic = match closest(name, names.iter().copied()) {
            Some(best) => diagnostic.with_hint(format!("did you mean `{best}`?")),
            None => diagnostic.with_hint(format!("the kinds are {}", list_or(names))),
        };
        if let Some(advice) = crate::hints::foreign(name) {
            diagnostic = diagnostic.with_hint(advice);
        }
        self.error(diagnostic);
    }

    fn object_tag(&mut self, kind: Ident) -> Option<ObjectTag> {
        let name = self.name(kind.sym);
        if let Some(tag) = ObjectTag::from_name(name) {
            return Some(tag);
        }
        let names: Vec<&str> = ObjectTag::ALL.iter().map(|t| t.name()).collect();
        if let Some(def) = self.lookup(kind.sym) {
            if self.definitions[def].kind == DefKind::Function {
                self.note_use(def);
                self.error(
                    Diagnostic::error(
                        format!("`{name}` is a function, not a kind of object"),
                        kind.span,
                    )
                    .with_label("a function")
                    .with_hint(format!("call it with arguments in brackets: `{name}(...)`")),
                );
                return None;
            }
        }
        self.unknown_kind("object", kind, &names);
        None
    }

    fn function_body(&mut self, id: FnId, program: &mut Program) {
        let Some(function) = program.functions.get_mut(id) else {
            return;
        };
        let mut body = std::mem::replace(
            &mut function.body,
            Block {
                items: Vec::new(),
                span: Span::detached(),
            },
        );
        let params = function.params.clone();
        let saved_frame = std::mem::take(&mut self.frame);
        let saved_function = self.current_function.replace(id);
        let saved_later = std::mem::take(&mut self.later);
        // Names defined later in the file are still "later" inside the body.
        self.later = saved_later.clone();
        let saved = self.push_scope(true);
        for param in &params {
            self.define(*param, DefKind::Parameter, None);
        }
        let cx = Context::Statements {
            top_level: false,
            in_function: true,
        };
        for item in &mut body.items {
            self.item(item, cx, program);
        }
        self.pop_scope(saved);
        if let Some(function) = program.functions.get_mut(id) {
            function.body = body;
            function.frame_size = self.frame.size;
        }
        self.frame = saved_frame;
        self.current_function = saved_function;
        self.later = saved_later;
    }

    fn material_body(&mut self, body: &mut MaterialBody, program: &mut Program) {
        if let Some(parent) = &mut body.parent {
            self.name_ref(parent);
        }
        self.block(&mut body.block, Context::Material, program);
    }

    fn property(&mut self, property: &mut Property, cx: Context, program: &mut Program) {
        let name = self.name(property.name.sym);
        let allowed = cx.properties();
        let prop = allowed.iter().copied().find(|p| p.name() == name);
        match (prop, cx) {
            (_, Context::Unknown) => {}
            (Some(prop), _) => property.prop = Some(prop),
            (None, Context::Statements { .. }) => {
                self.error(
                    Diagnostic::error(format!("`{name}` cannot go here"), property.name.span)
                        .with_label("not inside an object, light, camera or material")
                        .with_hint(
                            "properties such as `radius` go inside the braces of an object, a light, a camera, a material or `settings`",
                        ),
                );
            }
            (None, _) => {
                let names: Vec<&str> = allowed.iter().map(|p| p.name()).collect();
                let mut diagnostic = Diagnostic::error(
                    format!("`{name}` is not a property of {}", cx.describe()),
                    property.name.span,
                )
                .with_label("unknown property");
                diagnostic = match closest(name, names.iter().copied()) {
                    Some(best) => diagnostic.with_hint(format!("did you mean `{best}`?")),
                    None => diagnostic.with_hint(format!(
                        "{} takes {}",
                        cx.describe(),
                        list_and(&names)
                    )),
                };
                if let Some(advice) = crate::hints::foreign(name) {
                    diagnostic = diagnostic.with_hint(advice);
                }
                self.error(diagnostic);
            }
        }

        if let Some(prop) = property.prop {
            self.check_arity(property, prop);
            if let Some(words) = prop.words() {
                for value in &mut property.values {
                    self.word(value, prop, words);
                }
            }
            if property.about.is_some() && prop != Prop::Rotate {
                self.error(
                    Diagnostic::error(
                        format!("`about` only goes with `rotate`, not `{name}`"),
                        property.name.span,
                    )
                    .with_label("not a rotation")
                    .with_hint("`rotate 30 about <0, 1, 0>` turns 30 degrees about an axis"),
                );
            }
            if let Some(block) = &property.block {
                if prop != Prop::Diffuse {
                    let span = block.span;
                    self.error(
                        Diagnostic::error(format!("`{name}` does not take a block"), span)
                            .with_label("unexpected block")
                            .with_hint("only a pattern takes a block of transforms: `diffuse checker(a, b, 1) { rotate <0, 45, 0> }`"),
                    );
                }
            }
        }
        if property.prop.and_then(Prop::words).is_none() {
            for value in &mut property.values {
                self.expr(value, program);
            }
        }
        if let Some(about) = &mut property.about {
            self.expr(about, program);
        }
        if let Some(block) = &mut property.block {
            self.block(block, Context::PatternTransform, program);
        }
    }

    fn check_arity(&mut self, property: &Property, prop: Prop) {
        let name = prop.name();
        let count = property.values.len();
        let span = property.values.first().map_or(property.name.span, |first| {
            property
                .values
                .last()
                .map_or(first.span, |last| first.span.to(last.span))
        });
        match prop.arity() {
            Arity::Flag | Arity::Numbers(_) => {}
            Arity::One if count != 1 => {
                let mut diagnostic =
                    Diagnostic::error(format!("`{name}` takes one value, not {count}"), span)
                        .with_label(format!("{count} values"));
                if count == 3 {
                    diagnostic =
                        diagnostic.with_hint("a vector is written in angle brackets: `<x, y, z>`");
                }
                self.error(diagnostic);
            }
            Arity::Exactly(n) if count != n => {
                self.error(
                    Diagnostic::error(
                        format!("`{name}` takes {n} values separated by commas, not {count}"),
                        span,
                    )
                    .with_label(format!("{count} values")),
                );
            }
            _ => {}
        }
    }

    /// A value that must be one of a few words (`shadows filtered`).
    fn word(&mut self, value: &mut Expr, prop: Prop, words: &[&str]) {
        if let ExprKind::Name(name) = &mut value.kind {
            let text = self.name(name.ident.sym);
            if let Some(index) = words.iter().position(|w| *w == text) {
                name.res = Res::Word(index as u8);
                return;
            }
            let mut diagnostic = Diagnostic::error(
                format!("`{}` is {}, not `{text}`", prop.name(), list_or(words)),
                value.span,
            )
            .with_label("unknown word");
            if let Some(best) = closest(text, words.iter().copied()) {
                diagnostic = diagnostic.with_hint(format!("did you mean `{best}`?"));
            }
            self.error(diagnostic);
            name.res = Res::Error;
            return;
        }
        self.error(
            Diagnostic::error(
                format!("`{}` is {}", prop.name(), list_or(words)),
                value.span,
            )
            .with_label("expected one of these words"),
        );
    }

    // ---- expressions -----------------------------------------------------------------------

    fn name_ref(&mut self, name: &mut Name) {
        let sym = name.ident.sym;
        if let Some(def) = self.lookup(sym) {
            let definition = &self.definitions[def];
            name.res = match definition.slot {
                Slot::Local(slot) => Res::Local(slot),
                Slot::Global(slot) => Res::Global(slot),
                Slot::None => {
                    let text = self.name(sym);
                    self.note_use(def);
                    self.error(
                        Diagnostic::error(
                            format!("`{text}` is a function, not a value"),
                            name.ident.span,
                        )
                        .with_label("a function")
                        .with_hint(format!("call it with arguments in brackets: `{text}(...)`")),
                    );
                    Res::Error
                }
            };
            if name.res != Res::Error {
                self.note_use(def);
            }
            return;
        }
        let text = self.name(sym);
        if let Some(constant) = Constant::from_name(text) {
            name.res = Res::Builtin(constant);
            return;
        }
        name.res = Res::Error;
        if Function::from_name(text).is_some() {
            self.error(
                Diagnostic::error(
                    format!("`{text}` is a built-in function, not a value"),
                    name.ident.span,
                )
                .with_label("a function")
                .with_hint(format!("call it with arguments in brackets: `{text}(...)`")),
            );
            return;
        }
        let mut candidates: Vec<&str> = self
            .visible_names()
            .into_iter()
            .filter(|(_, kind)| *kind != DefKind::Function)
            .map(|(n, _)| n)
            .collect();
        candidates.extend(Constant::ALL.iter().map(|c| c.name()));
        self.unknown(name.ident, "name", candidates);
    }

    fn call(&mut self, call: &mut Call, program: &mut Program) {
        for arg in &mut call.args {
            self.expr(arg, program);
        }
        let sym = call.callee.sym;
        let text = self.name(sym);
        let given = call.args.len();
        if let Some(def) = self.lookup(sym) {
            let definition = &self.definitions[def];
            match definition.function {
                Some(id) => {
                    self.note_use(def);
                    call.target = CallTarget::User(id);
                    let expected = program.functions.get(id).map_or(0, |f| f.params.len());
                    if expected != given {
                        let defined = program.functions.get(id).map(|f| f.name.span);
                        let mut diagnostic = Diagnostic::error(
                            format!(
                                "`{text}` takes {} but is given {}",
                                plural(expected, "argument"),
                                given
                            ),
                            call.span,
                        )
                        .with_label(format!("{} given", plural(given, "argument")));
                        if let Some(span) = defined {
                            diagnostic = diagnostic.with_secondary(span, "defined here");
                        }
                        self.error(diagnostic);
                    }
                }
                None => {
                    let what = definition.kind.describe();
                    self.error(
                        Diagnostic::error(
                            format!("`{text}` is {what}, not a function"),
                            call.callee.span,
                        )
                        .with_label("cannot be called")
                        .with_secondary(self.definitions[def].span, "defined here"),
                    );
                    call.target = CallTarget::Error;
                }
            }
            return;
        }
        if let Some(function) = Function::from_name(text) {
            call.target = CallTarget::Builtin(function);
            let (low, high) = function.arity();
            if given < low || given > high {
                let wanted = if low == high {
                    plural(low, "argument")
                } else {
                    format!("{low} or {high} arguments")
                };
                self.error(
                    Diagnostic::error(
                        format!("`{text}` takes {wanted} but is given {given}"),
                        call.span,
                    )
                    .with_label(format!("{} given", plural(given, "argument")))
                    .with_hint(format!("it is called as `{}`", function.signature())),
                );
            }
            return;
        }
        call.target = CallTarget::Error;
        let mut candidates: Vec<&str> = self
            .visible_names()
            .into_iter()
            .filter(|(_, kind)| *kind == DefKind::Function)
            .map(|(n, _)| n)
            .collect();
        candidates.extend(Function::ALL.iter().map(|f| f.name()));
        if Prop::ALL.iter().any(|p| p.name() == text) {
            self.error(
                Diagnostic::error(format!("unknown function `{text}`"), call.callee.span)
                    .with_label("no function with this name")
                    .with_hint(format!(
                        "`{text}` is a property; put a space before its value: `{text} (...)`"
                    )),
            );
            return;
        }
        self.unknown(call.callee, "function", candidates);
    }

    fn expr(&mut self, expr: &mut Expr, program: &mut Program) {
        match &mut expr.kind {
            ExprKind::Number(_) | ExprKind::Bool(_) | ExprKind::Color(_) => {}
            ExprKind::Vector(parts) => {
                for part in parts.iter_mut() {
                    self.expr(part, program);
                }
            }
            ExprKind::Name(name) => self.name_ref(name),
            ExprKind::Unary(_, inner) => self.expr(inner, program),
            ExprKind::Binary { lhs, rhs, .. } => {
                self.expr(lhs, program);
                self.expr(rhs, program);
            }
            ExprKind::Field {
                base,
                field,
                component,
            } => {
                self.expr(base, program);
                let text = self.name(field.sym);
                *component = match text {
                    "x" | "r" => Some(Component(0)),
                    "y" | "g" => Some(Component(1)),
                    "z" | "b" => Some(Component(2)),
                    _ => {
                        let mut diagnostic = Diagnostic::error(
                            format!("unknown field `.{text}`"),
                            field.span,
                        )
                        .with_label("not a component")
                        .with_hint(
                            "vectors have `.x`, `.y` and `.z`; colours also `.r`, `.g` and `.b`",
                        );
                        if let Some(best) = closest(text, ["x", "y", "z", "r", "g", "b"]) {
                            diagnostic = diagnostic.with_hint(format!("did you mean `.{best}`?"));
                        }
                        self.error(diagnostic);
                        None
                    }
                };
            }
            ExprKind::Call(call) => self.call(call, program),
            ExprKind::Material(body) => self.material_body(body, program),
            ExprKind::Array(items) => items.iter_mut().for_each(|i| self.expr(i, program)),
            ExprKind::Index { base, index } => {
                self.expr(base, program);
                self.expr(index, program);
            }
            ExprKind::Str(lit) => self.string_holes(Some(lit)),
        }
    }

    // ---- end-of-program reports ------------------------------------------------------------

    fn report_unused(&mut self) {
        let mut unused = Vec::new();
        for definition in &self.definitions {
            let name = self.name(definition.name);
            if definition.file != 0 || definition.uses > 0 || name.starts_with('_') {
                continue;
            }
            let what = match definition.kind {
                DefKind::Material => "material",
                DefKind::Function => "function",
                _ => continue,
            };
            unused.push(
                Diagnostic::warning(format!("{what} `{name}` is never used"), definition.span)
                    .with_label("defined here")
                    .with_hint(
                        "remove it, or start its name with `_` to keep it without this warning",
                    ),
            );
        }
        self.diagnostics.extend(unused);
    }

    fn report_unused_defines(&mut self) {
        let constants: Vec<&str> = self
            .definitions
            .iter()
            .filter(|d| d.kind == DefKind::Const && matches!(d.slot, Slot::Global(_)))
            .map(|d| self.name(d.name))
            .collect();
        for (index, define) in self.defines.iter().enumerate() {
            if self.define_used[index] {
                continue;
            }
            let name = self.name(define.name);
            let mut diagnostic = Diagnostic::error(
                format!("`-D {name}` sets a constant that the scene does not define"),
                define.name_span,
            )
            .with_label("no `const` with this name");
            let other = self
                .definitions
                .iter()
                .find(|d| d.name == define.name && d.kind != DefKind::Const);
            if let Some(other) = other {
                diagnostic = diagnostic
                    .with_secondary(
                        other.span,
                        format!("`{name}` is {} here", other.kind.describe()),
                    )
                    .with_hint(format!(
                        "only `const` values can be set with -D; write `const {name} = ...;`"
                    ));
            } else if let Some(best) = closest(name, constants.iter().copied()) {
                diagnostic = diagnostic.with_hint(format!("did you mean `{best}`?"));
            } else if constants.is_empty() {
                diagnostic = diagnostic
                    .with_hint("the scene defines no constants; `const N = 10;` defines one");
            } else {
                diagnostic = diagnostic.with_hint(format!(
                    "the scene's constants are {}",
                    list_and(&constants)
                ));
            }
            self.error(diagnostic);
        }
    }
}

/// The first line's worth of an item, for messages about the item as a whole: `light point
/// "key"`, `sphere "ball"`, `material glass`, not the whole block.
fn header_span(kind: &ItemKind, span: Span) -> Span {
    let until = |end: u32| Span::new(span.file, span.start as usize, end as usize);
    match kind {
        ItemKind::Light { kind, name, .. } => {
            until(name.as_ref().map_or(kind.span.end, |n| n.span.end))
        }
        ItemKind::Object { kind, name, .. } => {
            kind.span.to(name.as_ref().map_or(kind.span, |n| n.span))
        }
        ItemKind::Camera { kind, .. } => until(kind.span.end),
        ItemKind::Material { body, .. } => body.header,
        ItemKind::Settings(_) => until(span.start + "settings".len() as u32),
        _ => span,
    }
}

/// The name a top-level item defines, if any.
fn top_level_name(kind: &ItemKind, functions: &[FnDef]) -> Option<(Sym, Span)> {
    match kind {
        ItemKind::Const(b) | ItemKind::Let(b) => Some((b.name.sym, b.name.span)),
        ItemKind::Material { name, .. } => Some((name.sym, name.span)),
        ItemKind::Fn(id) => functions.get(*id).map(|f| (f.name.sym, f.name.span)),
        _ => None,
    }
}

fn plural(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}
