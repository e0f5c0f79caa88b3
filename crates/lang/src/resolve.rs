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

mod assignments_and_strings;
mod expressions;
mod properties;
mod scopes;
mod unused;

use crate::intern::{Interner, Sym};
use crate::schema::{Arity, CameraTag, Context, LightTag, ObjectTag, Prop};
use crate::suggest::{closest, list_and, list_or};
use scopes::{Frame, Scope};

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
    /// Each name that resolved to a definition in the scene, with where that definition
    /// is: (use, definition). Kept only when [`Resolver::record_links`] is set (an editor
    /// asks for it; a render does not pay for a million of them).
    pub links: Vec<(Span, Span)>,
    /// Every definition's name and kind, used or not; kept with [`Resolution::links`].
    pub definitions: Vec<(Span, DefKind)>,
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
    later: HashMap<Sym, Span, foldhash::fast::FixedState>,
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
    /// Each property name's row in each kind of block, once looked up: a script's million
    /// statements ask the table about the same few names over and over.
    property_rows: HashMap<(Sym, Context), Option<Prop>, foldhash::fast::FixedState>,
    /// Whether to keep [`Resolution::links`].
    pub record_links: bool,
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
            later: HashMap::default(),
            current_function: None,
            defines,
            define_used: vec![false; defines.len()],
            resolution: Resolution::default(),
            in_progress: vec![false; file_count],
            name_probes: Cell::new(0),
            property_rows: HashMap::default(),
            record_links: false,
        }
    }

    fn name(&self, sym: Sym) -> &'a str {
        self.interner.name(sym)
    }

    /// Remembers that the name at `use_span` means the definition `def` (for editors).
    fn link(&mut self, use_span: Span, def: DefId) {
        if self.record_links {
            let to = self.definitions[def].span;
            self.resolution.links.push((use_span, to));
        }
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
        if self.record_links {
            self.resolution.definitions = self
                .definitions
                .iter()
                .filter(|d| !d.span.is_detached())
                .map(|d| (d.span, d.kind))
                .collect();
        }
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

        let mut items = std::mem::take(&mut program.files[index].items);
        // A script's file can define 100,000 names: sized once, not rehashed as it grows.
        self.later.reserve(items.len());
        let mut top_level_names = 0;
        for item in &items {
            if let Some((sym, span)) = top_level_name(&item.kind, &program.functions) {
                self.later.entry(sym).or_insert(span);
                top_level_names += 1;
            }
        }
        self.scopes.push(Scope::with_capacity(top_level_names));
        self.definitions.reserve(top_level_names);
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
                // A foreign block (`pigment { ... }`) gets its advice as an unknown kind;
                // saying that an object cannot go here as well would mislead.
                if !allowed && crate::hints::foreign(self.name(kind.sym)).is_none() {
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
                if cx.property_named(callee).is_some() && self.lookup(call.callee.sym).is_none() {
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
        // A foreign word's advice says what to write instead; the list of kinds would only
        // bury it.
        diagnostic = match (
            crate::hints::foreign(name),
            closest(name, names.iter().copied()),
        ) {
            (Some(advice), _) => diagnostic.with_hint(advice),
            (None, Some(best)) => diagnostic.with_hint(format!("did you mean `{best}`?")),
            (None, None) => diagnostic.with_hint(format!("the kinds are {}", list_or(names))),
        };
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
