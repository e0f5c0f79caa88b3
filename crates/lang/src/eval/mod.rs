//! The evaluator: runs the resolved tree (`let`, `for`, `if`, calls, imports) and builds the
//! IR as it goes.
//!
//! Objects are appended to the IR arena as soon as their body has run, children before their
//! parents. A parent's transforms and material are only known once its own body has run, so
//! on completion it walks its subtree once: it premultiplies its transform into each
//! descendant's `world_from_object` and hands its material to descendants that have none.
//!
//! Errors: a failing statement is reported and skipped, and evaluation goes on so that one
//! run reports every error it can. Limits (objects, loop iterations, call depth) stop the run.

mod arrays;
mod builders;
mod convert;
mod expr;
mod keyframes;
mod loops;
mod materials;
mod objects;
mod properties;
mod provenance;
mod shown;
mod strings;
mod written;

use std::borrow::Borrow;
use std::collections::HashSet;

use whitted_ir::{Diagnostic, Handle, Material, Object, Scene, Severity, Span};

use crate::ast::*;
use crate::intern::Interner;
use crate::resolve::{Define, Resolution};
use crate::value::Value;
use crate::Limits;

use builders::Target;
use materials::{MaterialDef, PatternDef};

/// Why evaluation of a statement stopped early.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Abort {
    /// An error was reported; the enclosing statement is skipped and evaluation goes on.
    Reported,
    /// A limit was reached (or too many errors): evaluation stops.
    Fatal,
}

pub(crate) type Eval<T> = Result<T, Abort>;

/// What running a block ended with.
enum Flow {
    Normal,
    Return(Value),
}

/// Where object statements put the objects they make.
enum Sink {
    Collect(Vec<Handle<Object>>),
    /// Inside a function called for its value: objects cannot be made here.
    Forbidden {
        call: Span,
    },
}

/// A marker material handle for "not set; take the parent's". Never left in the output:
/// the last pass replaces it with the default material.
const INHERIT: u32 = u32::MAX;

fn inherit() -> Handle<Material> {
    Handle::from_index(INHERIT as usize)
}

/// Unique errors beyond this many stop evaluation (the rest would be noise).
const MAX_ERRORS: usize = 100;

/// How deep blocks, expressions and calls may nest while running, at most. Parsing bounds
/// each file's tree; this bounds what recursion through calls adds on top, so the stack
/// always suffices (the driver lowers it for a smaller stack).
pub(crate) const MAX_EVALUATION_DEPTH: usize = 20_000;

pub(crate) struct Evaluator<'a> {
    program: &'a Program,
    interner: &'a Interner,
    limits: &'a Limits,
    resolution: &'a Resolution,
    defines: &'a [Define],
    /// `--set NAME=VALUE`: applied after the scene has run, so they win.
    overrides: &'a [crate::compile::SettingOverride],
    /// The values of `frame`, `clock` and `fps`.
    clock: crate::FrameClock,
    /// Set when the scene reads `frame`, `clock` or `fps` (the compiler then checks that
    /// the clock it assumed is the scene's own).
    clock_read: &'a std::cell::Cell<bool>,

    globals: Vec<Value>,
    /// Call frames, each `frame_size` values; `base` is where the current frame starts.
    stack: Vec<Value>,
    base: usize,

    pub(crate) scene: Scene,
    pub(crate) diagnostics: Vec<Diagnostic>,
    /// Where errors were already reported, so that a loop repeats none of them (the values
    /// in the message may differ from one iteration to the next; the place does not).
    reported: HashSet<Span>,
    /// Material definitions already warned about (a definition in a loop warns once).
    warned_materials: HashSet<Span>,
    unique_errors: usize,
    /// Every error reported or repeated: an object whose body adds to this is not built.
    error_events: usize,

    materials: Vec<MaterialDef>,
    patterns: Vec<PatternDef>,
    /// Arrays and strings.
    store: arrays::Store,
    default_material: Option<Handle<Material>>,
    /// Meshes by their normalised path, so that a file named many times is one mesh.
    mesh_files: std::collections::HashMap<std::path::PathBuf, Handle<whitted_ir::Mesh>>,

    sinks: Vec<Sink>,
    targets: Vec<Target>,
    /// Spare vectors for container children, so nested objects do not allocate each time.
    spare_children: Vec<Vec<Handle<Object>>>,
    scratch: Vec<Handle<Object>>,

    call_depth: usize,
    depth: usize,
    max_depth: usize,
    /// Evaluation steps so far: loop iterations (counted when a loop starts) and calls.
    steps: u64,
    files_run: Vec<bool>,
    camera_span: Option<Span>,
    settings_set: Vec<(crate::schema::Prop, Span)>,
    /// The active imports, calls and loop iterations, for each object's instantiation stack.
    trail: provenance::Trail,
    /// Where settings and properties were written, for the scene's side table.
    written: written::WrittenRecorder,
    /// What an editor's hover shows of each definition (`shown.rs`), when asked for.
    pub(crate) shown: Option<std::collections::HashMap<Span, crate::editor::Shown>>,
}

/// What the command line adds to a scene: `-D` constants and `--set` settings.
pub(crate) struct CommandLine<'a> {
    pub defines: &'a [Define],
    pub overrides: &'a [crate::compile::SettingOverride],
    pub clock: crate::FrameClock,
    pub clock_read: &'a std::cell::Cell<bool>,
}

impl<'a> Evaluator<'a> {
    pub(crate) fn new(
        program: &'a Program,
        interner: &'a Interner,
        limits: &'a Limits,
        resolution: &'a Resolution,
        command_line: CommandLine<'a>,
        sources: whitted_ir::SourceMap,
        max_depth: usize,
    ) -> Self {
        let CommandLine {
            defines,
            overrides,
            clock,
            clock_read,
        } = command_line;
        let scene = Scene {
            sources,
            ..Scene::default()
        };
        Evaluator {
            program,
            interner,
            limits,
            resolution,
            defines,
            overrides,
            clock,
            clock_read,
            globals: vec![Value::Poisoned; resolution.global_count as usize],
            stack: Vec::with_capacity(256),
            base: 0,
            scene,
            diagnostics: Vec::new(),
            reported: HashSet::new(),
            warned_materials: HashSet::new(),
            unique_errors: 0,
            error_events: 0,
            materials: Vec::new(),
            patterns: Vec::new(),
            store: arrays::Store::default(),
            default_material: None,
            mesh_files: std::collections::HashMap::new(),
            sinks: vec![Sink::Collect(Vec::new())],
            targets: Vec::new(),
            spare_children: Vec::new(),
            scratch: Vec::new(),
            call_depth: 0,
            depth: 0,
            max_depth,
            steps: 0,
            files_run: vec![false; program.files.len()],
            camera_span: None,
            settings_set: Vec::new(),
            trail: provenance::Trail::default(),
            written: written::WrittenRecorder::default(),
            shown: None,
        }
    }

    /// Runs the root file (and its imports), then gives every object without a material the
    /// default one. Returns the scene; errors are in `diagnostics`.
    ///
    /// `root_items` are the root file's items, taken out of the program: each is dropped once
    /// it has run.
    #[allow(clippy::type_complexity)]
    pub(crate) fn run(
        mut self,
        root_items: Vec<Item>,
    ) -> (
        Scene,
        Vec<Diagnostic>,
        bool,
        Option<std::collections::HashMap<Span, crate::editor::Shown>>,
    ) {
        // A scene written by a program is mostly top-level objects: room for them at once,
        // rather than arenas that grow by copying a million objects several times.
        let literal_objects = self
            .program
            .files
            .iter()
            .flat_map(|file| &file.items)
            .chain(&root_items)
            .filter(|item| matches!(item.kind, ItemKind::Object { .. }))
            .count()
            .min(self.limits.max_objects);
        if literal_objects > self.scene.objects.len() {
            self.scene.objects = whitted_ir::Arena::with_capacity(literal_objects);
        }
        let outcome = self
            .run_root(root_items)
            .and_then(|()| self.apply_overrides());
        let failed = outcome.is_err() || self.unique_errors > 0;
        if let Some(Sink::Collect(roots)) = self.sinks.pop() {
            self.scene.roots = roots;
        }
        if !failed {
            self.assign_default_materials();
        }
        if let Some(span) = self.camera_span {
            self.scene.camera_span = span;
        }
        let shown = self.take_shown();
        (self.scene, self.diagnostics, failed, shown)
    }

    /// Applies the command line's `--set NAME=VALUE`s to the settings the scene made.
    fn apply_overrides(&mut self) -> Eval<()> {
        let overrides = self.overrides;
        for setting in overrides {
            let (value, word) = match &setting.value {
                crate::compile::OverrideValue::Word(word) => (Value::Poisoned, Some(*word)),
                crate::compile::OverrideValue::Expr(expr) => (self.eval(expr)?, None),
            };
            self.apply_setting(setting.prop, value, setting.value_span, word)?;
            self.record_override(setting.prop, setting.value_span);
        }
        Ok(())
    }

    fn name(&self, sym: crate::intern::Sym) -> &'a str {
        self.interner.name(sym)
    }

    /// Reports an error (once per span and message) and returns `Abort::Reported`.
    fn fail<T>(&mut self, diagnostic: Diagnostic) -> Eval<T> {
        self.error_events += 1;
        let key = diagnostic.span.unwrap_or_else(Span::detached);
        if !self.reported.insert(key) {
            return Err(Abort::Reported);
        }
        self.unique_errors += 1;
        self.diagnostics.push(diagnostic);
        if self.unique_errors >= MAX_ERRORS {
            self.diagnostics.push(Diagnostic::new(
                Severity::Error,
                format!("too many errors ({MAX_ERRORS}); stopping here"),
                None,
            ));
            return Err(Abort::Fatal);
        }
        Err(Abort::Reported)
    }

    /// Reports an error that stops evaluation (a limit).
    fn fatal<T>(&mut self, diagnostic: Diagnostic) -> Eval<T> {
        self.unique_errors += 1;
        self.error_events += 1;
        self.diagnostics.push(diagnostic);
        Err(Abort::Fatal)
    }

    fn enter(&mut self, span: Span) -> Eval<()> {
        self.depth += 1;
        if self.depth > self.max_depth {
            self.depth -= 1;
            let limit = self.max_depth;
            return self.fatal(
                Diagnostic::error(
                    format!(
                        "the scene nests too deeply while running: more than {limit} levels of calls, blocks and expressions"
                    ),
                    span,
                )
                .with_hint("a function that calls itself many times goes this deep; lower the recursion"),
            );
        }
        Ok(())
    }

    fn leave(&mut self) {
        self.depth -= 1;
    }

    // ---- files, blocks and statements ------------------------------------------------------

    fn run_file(&mut self, index: FileIndex) -> Eval<()> {
        let program = self.program;
        match program.files.get(index) {
            Some(file) => self.run_file_items(index, &file.items),
            None => Ok(()),
        }
    }

    /// Runs the root file like [`Self::run_file`], dropping each item once it has run.
    fn run_root(&mut self, items: Vec<Item>) -> Eval<()> {
        self.run_file_items(0, items)
    }

    /// Runs file `index`'s items, once, in a frame of the file's size. The items are the
    /// program's (borrowed) or, for the root file, owned, so that each is dropped as soon as
    /// it has run.
    fn run_file_items<I: Borrow<Item>>(
        &mut self,
        index: FileIndex,
        items: impl IntoIterator<Item = I>,
    ) -> Eval<()> {
        let Some(file) = self.program.files.get(index) else {
            return Ok(());
        };
        if self.files_run[index] {
            return Ok(());
        }
        self.files_run[index] = true;
        let saved_base = self.base;
        self.base = self.stack.len();
        self.stack
            .resize(self.base + file.frame_size as usize, Value::Poisoned);
        let result = self.items(items);
        self.stack.truncate(self.base);
        self.base = saved_base;
        result.map(|_| ())
    }

    fn items<I: Borrow<Item>>(&mut self, items: impl IntoIterator<Item = I>) -> Eval<Flow> {
        for item in items {
            match self.item(item.borrow()) {
                Ok(Flow::Normal) | Err(Abort::Reported) => {}
                Ok(flow @ Flow::Return(_)) => return Ok(flow),
                Err(Abort::Fatal) => return Err(Abort::Fatal),
            }
        }
        Ok(Flow::Normal)
    }

    fn set_slot(&mut self, slot: Slot, value: Value) {
        match slot {
            Slot::Local(i) => {
                if let Some(cell) = self.stack.get_mut(self.base + i as usize) {
                    *cell = value;
                }
            }
            Slot::Global(g) => {
                if let Some(cell) = self.globals.get_mut(g as usize) {
                    *cell = value;
                }
            }
            Slot::None => {}
        }
    }

    fn item(&mut self, item: &Item) -> Eval<Flow> {
        self.enter(item.span)?;
        let result = self.item_inner(item);
        self.leave();
        result
    }

    fn item_inner(&mut self, item: &Item) -> Eval<Flow> {
        match &item.kind {
            ItemKind::Import { file, .. } => {
                if let Some(index) = *file {
                    if !self.files_run.get(index).copied().unwrap_or(true) {
                        // The imported file's objects are made "through" this line.
                        self.trail.note_import(index, item.span);
                        self.trail.enter_import(item.span);
                        let result = self.run_file(index);
                        self.trail.leave();
                        result?;
                    }
                }
            }
            ItemKind::Const(binding) => {
                let value = self.constant(binding);
                if let Ok(shown) = &value {
                    self.show_value(binding.name.span, *shown);
                }
                self.set_slot(binding.slot, *value.as_ref().unwrap_or(&Value::Poisoned));
                value?;
            }
            ItemKind::Let(binding) => {
                let value = self.eval(&binding.value);
                if let Ok(shown) = &value {
                    self.show_value(binding.name.span, *shown);
                }
                self.set_slot(binding.slot, *value.as_ref().unwrap_or(&Value::Poisoned));
                value?;
            }
            ItemKind::Fn(_) => {}
            ItemKind::For {
                var,
                slot,
                start,
                end,
                inclusive,
                step,
                body,
            } => {
                self.trail.enter_loop(var.sym, item.span);
                let result = match step {
                    Some(step) => {
                        self.stepped_loop(*var, *slot, start, end, *inclusive, step, body)
                    }
                    None => self.for_loop(*var, *slot, start, end, *inclusive, body),
                };
                self.trail.leave();
                return result;
            }
            ItemKind::While { condition, body } => return self.while_loop(condition, body),
            ItemKind::Assign { target, value } => self.assign(target, value)?,
            ItemKind::If {
                condition,
                then,
                otherwise,
            } => {
                let go = self.boolean(condition, "an `if` condition")?;
                if go {
                    return self.items(&then.items);
                }
                match otherwise.as_deref() {
                    Some(Else::If(item)) => return self.item(item),
                    Some(Else::Block(block)) => return self.items(&block.items),
                    None => {}
                }
            }
            ItemKind::Return(value) => {
                let value = self.eval(value)?;
                return Ok(Flow::Return(value));
            }
            ItemKind::Settings(body) => self.settings(item.span, body)?,
            ItemKind::Camera { tag, body, kind } => {
                if let Some(tag) = tag {
                    let header = Span::new(
                        kind.span.file,
                        item.span.start as usize,
                        kind.span.end as usize,
                    );
                    self.camera(*tag, header, body)?;
                }
            }
            ItemKind::Light {
                tag,
                body,
                name,
                kind,
            } => {
                if let Some(tag) = tag {
                    let end = name.as_ref().map_or(kind.span.end, |n| n.span.end);
                    let header = Span::new(kind.span.file, item.span.start as usize, end as usize);
                    self.light(*tag, header, name.as_deref(), body)?;
                }
            }
            ItemKind::Material { name, slot, body } => {
                let text = self.name(name.sym).to_string();
                let value = self.material(body, Some(text)).map(Value::Material);
                if let Ok(shown) = &value {
                    self.show_value(name.span, *shown);
                }
                self.set_slot(*slot, *value.as_ref().unwrap_or(&Value::Poisoned));
                value?;
            }
            ItemKind::Object {
                kind,
                tag,
                name,
                body,
            } => {
                if let Some(tag) = tag {
                    self.object(*tag, *kind, name.as_deref(), body)?;
                }
            }
            ItemKind::Call { call, modifiers } => self.call_statement(call, modifiers.as_ref())?,
            ItemKind::Property(property) => self.property(property)?,
        }
        Ok(Flow::Normal)
    }

    /// A `const`, with its `-D` override if there is one.
    fn constant(&mut self, binding: &Binding) -> Eval<Value> {
        let value = self.eval(&binding.value)?;
        let Slot::Global(slot) = binding.slot else {
            return Ok(value);
        };
        let Some(&index) = self.resolution.overrides.get(&slot) else {
            return Ok(value);
        };
        let defines = self.defines;
        let Some(define) = defines.get(index) else {
            return Ok(value);
        };
        if matches!(define.value.kind, ExprKind::Material(_)) {
            // Refused by the resolver.
            return Err(Abort::Reported);
        }
        let overridden = self.eval(&define.value)?;
        if !overridden.same_type(&value) {
            let name = self.name(binding.name.sym);
            return self.fail(
                Diagnostic::error(
                    format!(
                        "`-D {name}` gives {}, but `{name}` is {}",
                        overridden.type_name(),
                        value.type_name()
                    ),
                    define.value.span,
                )
                .with_label(format!("{} here", overridden.type_name()))
                .with_secondary(binding.name.span, "the constant is defined here"),
            );
        }
        Ok(overridden)
    }

    fn for_loop(
        &mut self,
        var: crate::ast::Ident,
        slot: Slot,
        start: &Expr,
        end: &Expr,
        inclusive: bool,
        body: &Block,
    ) -> Eval<Flow> {
        let first = self.whole_number(start, "a loop's start")?;
        let last = self.whole_number(end, "a loop's end")?;
        let stop = if inclusive { last + 1 } else { last };
        self.show_range(var.span, first.into(), i128::from(stop) - 1, 1);
        let count = (stop - first).max(0) as u64;
        let limit = self.limits.max_evaluation_steps;
        if self.steps.saturating_add(count) > limit {
            // Refused before the first iteration, so that a loop of a billion costs nothing.
            let range = start.span.to(end.span);
            let mut diagnostic = Diagnostic::error(
                format!(
                    "this loop would run {count} times, past the evaluation steps limit ({limit} loop iterations and calls in total)"
                ),
                range,
            )
            .with_label(format!("{count} iterations"));
            if self.steps > 0 {
                diagnostic = diagnostic.with_hint(format!(
                    "{} steps (iterations and calls) have already run",
                    self.steps
                ));
            }
            return self.fatal(diagnostic.with_hint(
                "the limit keeps a mistake from running for days; see \"Limits\" in docs/language.md",
            ));
        }
        self.steps += count;
        for i in first..stop {
            self.set_slot(slot, Value::Number(i as f64));
            self.trail.next_iteration(i as f64);
            match self.items(&body.items)? {
                Flow::Normal => {}
                flow @ Flow::Return(_) => return Ok(flow),
            }
        }
        Ok(Flow::Normal)
    }

    // ---- calls -----------------------------------------------------------------------------

    /// A call used as a statement: its objects go where the statement is, after the
    /// modifier block's transforms and material are applied to them.
    fn call_statement(&mut self, call: &Call, modifiers: Option<&Block>) -> Eval<()> {
        let CallTarget::User(id) = call.target else {
            // A built-in as a statement has nothing to make; evaluate it for its errors.
            self.call_value(call)?;
            return Ok(());
        };
        let Some(modifiers) = modifiers else {
            self.call_user(id, call)?;
            return Ok(());
        };
        let children = self.spare_children.pop().unwrap_or_default();
        self.sinks.push(Sink::Collect(children));
        let result = self.call_user(id, call);
        let made = match self.sinks.pop() {
            Some(Sink::Collect(made)) => made,
            _ => Vec::new(),
        };
        result?;
        let placement = self.modifiers(modifiers)?;
        let material = match placement.material {
            Some(id) => Some(self.lower_material(id)?),
            None => None,
        };
        self.place_subtree(&made, placement.transform, material);
        for &handle in &made {
            self.emit(handle);
        }
        let mut made = made;
        made.clear();
        self.spare_children.push(made);
        Ok(())
    }

    /// A call in an expression: its value. Objects made inside are an error.
    fn call_value(&mut self, call: &Call) -> Eval<Value> {
        match call.target {
            CallTarget::Builtin(function) => self.call_builtin(function, call),
            CallTarget::User(id) => {
                self.sinks.push(Sink::Forbidden { call: call.span });
                let result = self.call_user(id, call);
                self.sinks.pop();
                match result? {
                    Some(value) => Ok(value),
                    None => {
                        let name = self.name(call.callee.sym);
                        self.fail(
                            Diagnostic::error(
                                format!("`{name}` returns no value"),
                                call.span,
                            )
                            .with_label("used as a value here")
                            .with_hint(format!(
                                "end `{name}` with `return ...;`, or call it as a statement to make its objects"
                            )),
                        )
                    }
                }
            }
            CallTarget::Unresolved | CallTarget::Error => Err(Abort::Reported),
        }
    }

    /// Runs a user function: arguments become the first slots of a fresh frame.
    fn call_user(&mut self, id: FnId, call: &Call) -> Eval<Option<Value>> {
        let program = self.program;
        let Some(function) = program.functions.get(id) else {
            return Err(Abort::Reported);
        };
        if self.call_depth >= self.limits.max_call_depth {
            let name = self.name(call.callee.sym);
            return self.fatal(
                Diagnostic::error(
                    format!(
                        "the call depth limit ({}) was reached when calling `{name}`",
                        self.limits.max_call_depth
                    ),
                    call.span,
                )
                .with_label("one call too many")
                .with_secondary(function.name.span, "the function")
                .with_hint(format!(
                    "does `{name}` call itself without a condition that ends the recursion?"
                )),
            );
        }
        if self.steps >= self.limits.max_evaluation_steps {
            let name = self.name(call.callee.sym);
            let limit = self.limits.max_evaluation_steps;
            return self.fatal(
                Diagnostic::error(
                    format!(
                        "the evaluation steps limit ({limit} loop iterations and calls in total) was reached when calling `{name}`"
                    ),
                    call.span,
                )
                .with_label("one step too many")
                .with_secondary(function.name.span, "the function")
                .with_hint(format!(
                    "does `{name}` call itself more than once per call? The calls then double at every level"
                )),
            );
        }
        self.steps += 1;
        let base = self.stack.len();
        for arg in &call.args {
            match self.eval(arg) {
                Ok(value) => self.stack.push(value),
                Err(abort) => {
                    self.stack.truncate(base);
                    return Err(abort);
                }
            }
        }
        self.stack.resize(
            base + (function.frame_size as usize).max(call.args.len()),
            Value::Poisoned,
        );
        let saved_base = std::mem::replace(&mut self.base, base);
        self.call_depth += 1;
        self.trail.enter_call(id, call.span, base, call.args.len());
        // A function written in another file runs that file's code: its stack shows the
        // import line that brought the file in.
        let function_file = function.name.span.file.0 as usize;
        let import = (function_file != call.span.file.0 as usize)
            .then(|| self.trail.import_of(function_file))
            .flatten();
        if let Some(span) = import {
            self.trail.enter_import(span);
        }
        let result = self.items(&function.body.items);
        if import.is_some() {
            self.trail.leave();
        }
        self.trail.leave();
        self.call_depth -= 1;
        self.base = saved_base;
        self.stack.truncate(base);
        match result? {
            Flow::Return(value) => Ok(Some(value)),
            Flow::Normal => Ok(None),
        }
    }

    // ---- objects into sinks ----------------------------------------------------------------

    /// Checks that objects may be made here, before any work is done for one.
    fn check_sink(&mut self, span: Span) -> Eval<()> {
        if let Some(Sink::Forbidden { call }) = self.sinks.last() {
            let call = *call;
            return self.fail(
                Diagnostic::error(
                    "this object is made inside a function that was called for its value",
                    span,
                )
                .with_label("an object")
                .with_secondary(call, "called here, in an expression")
                .with_hint("call the function as a statement (on its own line) to make objects"),
            );
        }
        if self.scene.objects.len() >= self.limits.max_objects {
            return self.fatal(
                Diagnostic::error(
                    format!("the objects limit ({}) was reached", self.limits.max_objects),
                    span,
                )
                .with_label("one object too many")
                .with_hint(
                    "the limit keeps a runaway loop from filling the memory; see \"Limits\" in docs/language.md",
                ),
            );
        }
        Ok(())
    }

    fn emit(&mut self, handle: Handle<Object>) {
        if let Some(Sink::Collect(list)) = self.sinks.last_mut() {
            list.push(handle);
        }
    }

    /// Applies a parent's transform and material to a finished subtree: the transform is
    /// premultiplied into every descendant, the material given to those without one.
    fn place_subtree(
        &mut self,
        roots: &[Handle<Object>],
        transform: whitted_ir::DMat4,
        material: Option<Handle<Material>>,
    ) {
        let identity = transform == whitted_ir::DMat4::IDENTITY;
        if identity && material.is_none() {
            return;
        }
        let mut work = std::mem::take(&mut self.scratch);
        work.clear();
        work.extend_from_slice(roots);
        while let Some(handle) = work.pop() {
            let Some(object) = self.scene.objects.get_mut(handle) else {
                continue;
            };
            if !identity {
                object.world_from_object = (transform * *object.world_from_object).into();
            }
            if let Some(material) = material {
                if object.material.index() == INHERIT as usize {
                    object.material = material;
                }
            }
            if let whitted_ir::ObjectKind::Csg { children, .. }
            | whitted_ir::ObjectKind::Group { children } = &object.kind
            {
                work.extend_from_slice(children);
            }
        }
        self.scratch = work;
    }

    /// The last pass: every object still without a material gets the default one, and each
    /// source statement that made such a shape gets one note.
    fn assign_default_materials(&mut self) {
        let mut noted: HashSet<Span> = HashSet::new();
        let mut notes = Vec::new();
        let count = self.scene.objects.len();
        for index in 0..count {
            let handle = Handle::<Object>::from_index(index);
            if self.scene.objects[handle].material.index() != INHERIT as usize {
                continue;
            }
            let default = match self.default_material {
                Some(h) => h,
                None => {
                    let material = Material {
                        name: Some("default".to_string()),
                        ..Material::default()
                    };
                    let h = self.scene.materials.append(material, Span::detached());
                    self.default_material = Some(h);
                    h
                }
            };
            let span = self.scene.objects.span(handle);
            let object = &mut self.scene.objects[handle];
            object.material = default;
            if let whitted_ir::ObjectKind::Shape { shape } = &object.kind {
                if noted.insert(span) {
                    notes.push(
                        Diagnostic::note(
                            format!(
                                "this {} has no material, so it gets the default",
                                shape.kind_name()
                            ),
                            span,
                        )
                        .with_label("no material here or on any enclosing object")
                        .with_hint(
                            "the default is a matte light grey; add `material ...` to choose",
                        ),
                    );
                }
            }
        }
        self.diagnostics.extend(notes);
    }
}
