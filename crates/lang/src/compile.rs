//! The driver: loads the root file and its imports, then runs parse, resolve, evaluate and
//! validate, stopping after the first phase that reports an error.
//!
//! Everything runs on a thread with a large stack, so that deep (but within-limit) nesting
//! never meets the small stack of a test thread or a user's worker thread. The loader stays
//! on the caller's thread: the compile thread asks for files over a channel.

use std::collections::{HashMap, HashSet};
use std::path::{Component, Path, PathBuf};
use std::sync::mpsc;

use whitted_ir::{Diagnostic, FileId, Severity, SourceFile, SourceMap, Span};

use crate::ast::{FileAst, FileIndex, ItemKind, Program};
use crate::intern::Interner;
use crate::parser::{self, ParseContext};
use crate::properties::{self, Family, Kind, Prop};
use crate::resolve::{Define, Resolver};
use crate::suggest::{closest, list_and, list_or};
use crate::{Compilation, CompileOptions, FrameClock, Limits, SourceLoader, WorkCounts};
use std::cell::Cell;

/// Stacks to try for the compile thread, largest first. Only the pages actually touched are
/// committed; the deepest legal nesting uses a fraction of the first. The smaller one is for
/// systems that refuse to reserve that much address space (strict overcommit).
const COMPILE_STACK_BYTES: [usize; 2] = [512 * 1024 * 1024, 64 * 1024 * 1024];

/// Stack one level of evaluation may use, generously: a debug build measures about 5 KiB.
/// The evaluator's depth bound is the stack divided by this.
const STACK_BYTES_PER_EVALUATION_LEVEL: usize = 16 * 1024;

/// Expressions and blocks may nest this many times deeper than brackets (an operator adds a
/// level without a bracket).
const EXPRESSION_DEPTH_PER_NESTING: usize = 16;

/// Compiles the file at `path` (read through `loader`, as are its imports).
pub fn compile_file(
    path: &Path,
    loader: &mut dyn SourceLoader,
    options: &CompileOptions,
) -> Compilation {
    let path = normalize(path);
    on_big_stack(loader, move |loader, max_depth| {
        let display = path.to_string_lossy().into_owned();
        match loader.load(&path) {
            Ok(bytes) => {
                let mut bytes = Some(bytes);
                with_frame_clock(options, |clock, clock_read| {
                    // The second compilation, when there is one, reads the files again.
                    let bytes = match bytes.take() {
                        Some(bytes) => bytes,
                        None => loader.load(&path).unwrap_or_default(),
                    };
                    compile_root(
                        &path,
                        display.clone(),
                        bytes,
                        loader,
                        options,
                        max_depth,
                        (clock, clock_read),
                    )
                })
            }
            Err(error) => Compilation {
                sources: SourceMap::new(),
                scene: None,
                index: None,
                work: WorkCounts::default(),
                diagnostics: vec![Diagnostic::new(
                    Severity::Error,
                    format!("cannot read `{display}`: {error}"),
                    None,
                )],
            },
        }
    })
}

/// For tests and the docs checker: compiles text named `name`; imports go to `loader`.
pub fn compile_source(
    name: &str,
    text: &str,
    loader: &mut dyn SourceLoader,
    options: &CompileOptions,
) -> Compilation {
    compile_bytes(name, text.as_bytes(), loader, options)
}

/// Like [`compile_source`], for contents that may not be UTF-8.
pub fn compile_bytes(
    name: &str,
    bytes: &[u8],
    loader: &mut dyn SourceLoader,
    options: &CompileOptions,
) -> Compilation {
    let path = normalize(Path::new(name));
    let bytes = bytes.to_vec();
    on_big_stack(loader, move |loader, max_depth| {
        with_frame_clock(options, |clock, clock_read| {
            compile_root(
                &path,
                name.to_string(),
                bytes.clone(),
                loader,
                options,
                max_depth,
                (clock, clock_read),
            )
        })
    })
}

/// Runs `compile` with the values of `frame`, `clock` and `fps` the scene's own settings
/// give. Those settings are known only once the scene has run, so the first compilation
/// assumes a still (the frame asked for, or 0, in a range of that one frame, at the default
/// rate). A scene that never reads the clock is done; one that reads it and whose settings
/// say otherwise is compiled again with its own clock. A scene whose frame range or rate
/// depends on the clock (so that the two never agree) is an error.
fn with_frame_clock(
    options: &CompileOptions,
    mut compile: impl FnMut(FrameClock, &Cell<bool>) -> Compilation,
) -> Compilation {
    let frame = options.frame.unwrap_or(0);
    let assumed = FrameClock {
        frame,
        first: frame,
        last: frame,
        fps: whitted_ir::DEFAULT_FPS,
    };
    let clock_read = Cell::new(false);
    let first = compile(assumed, &clock_read);
    let actual = match &first.scene {
        Some(scene) if clock_read.get() => FrameClock::of(&scene.settings, options.frame),
        _ => return first,
    };
    if actual == assumed {
        return first;
    }
    let clock_read = Cell::new(false);
    let mut second = compile(actual, &clock_read);
    if let Some(scene) = &second.scene {
        let again = FrameClock::of(&scene.settings, options.frame);
        if again != actual {
            second.scene = None;
            second.diagnostics.push(Diagnostic::new(
                Severity::Error,
                "the settings `frames`, `first_frame` and `fps` must not depend on `frame`, `clock` or `fps`".to_string(),
                None,
            ));
        }
    }
    second
}

/// What the compile thread asks the caller's thread for.
enum Request {
    Load(PathBuf),
    Identify(PathBuf),
}

enum Reply {
    Loaded(std::io::Result<Vec<u8>>),
    Identified(PathBuf),
}

/// A loader that forwards requests to the caller's thread.
struct ChannelLoader {
    requests: mpsc::Sender<Request>,
    replies: mpsc::Receiver<Reply>,
}

impl SourceLoader for ChannelLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        let gone = || std::io::Error::other("the loader is no longer available");
        self.requests
            .send(Request::Load(path.to_path_buf()))
            .map_err(|_| gone())?;
        match self.replies.recv() {
            Ok(Reply::Loaded(result)) => result,
            _ => Err(gone()),
        }
    }

    fn identify(&mut self, path: &Path) -> PathBuf {
        let sent = self.requests.send(Request::Identify(path.to_path_buf()));
        match (sent, self.replies.recv()) {
            (Ok(()), Ok(Reply::Identified(identity))) => identity,
            _ => path.to_path_buf(),
        }
    }
}

/// Runs `work` on a thread with a large stack, passing it the evaluation depth that stack
/// allows.
fn on_big_stack<F>(loader: &mut dyn SourceLoader, work: F) -> Compilation
where
    F: FnOnce(&mut dyn SourceLoader, usize) -> Compilation + Send,
{
    let (request_tx, request_rx) = mpsc::channel::<Request>();
    let (reply_tx, reply_rx) = mpsc::channel();
    // The closure moves into whichever spawn succeeds; a failed spawn hands nothing back,
    // so the work is parked in an Option that the successful thread takes.
    let parcel = std::sync::Mutex::new(Some((work, request_tx, reply_rx)));
    std::thread::scope(|scope| {
        let mut spawned = Err(std::io::Error::other("no stack size to try"));
        for stack in COMPILE_STACK_BYTES {
            let parcel = &parcel;
            spawned = std::thread::Builder::new()
                .name("whitted-lang compile".into())
                .stack_size(stack)
                .spawn_scoped(scope, move || {
                    let taken = parcel.lock().ok().and_then(|mut p| p.take());
                    let (work, requests, replies) = taken?;
                    let mut channel = ChannelLoader { requests, replies };
                    let max_depth = (stack / STACK_BYTES_PER_EVALUATION_LEVEL)
                        .min(crate::eval::MAX_EVALUATION_DEPTH);
                    Some(work(&mut channel, max_depth))
                });
            if spawned.is_ok() {
                break;
            }
        }
        let handle = match spawned {
            Ok(handle) => handle,
            Err(error) => {
                // No thread (a resource limit): say so rather than risk the caller's stack.
                return Compilation {
                    sources: SourceMap::new(),
                    scene: None,
                    index: None,
                    work: WorkCounts::default(),
                    diagnostics: vec![Diagnostic::new(
                        Severity::Error,
                        format!("cannot start the compiler thread: {error}"),
                        None,
                    )],
                };
            }
        };
        // Serve file requests until the compile thread drops its sender.
        for request in request_rx {
            let reply = match request {
                Request::Load(path) => Reply::Loaded(loader.load(&path)),
                Request::Identify(path) => Reply::Identified(loader.identify(&path)),
            };
            if reply_tx.send(reply).is_err() {
                break;
            }
        }
        match handle.join() {
            Ok(Some(compilation)) => compilation,
            Ok(None) => Compilation {
                sources: SourceMap::new(),
                scene: None,
                index: None,
                work: WorkCounts::default(),
                diagnostics: vec![Diagnostic::new(
                    Severity::Error,
                    "the compiler thread started without its work",
                    None,
                )],
            },
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
}

/// `a/./b/../c` → `a/c`, without touching the disk (the loader decides what paths mean).
pub(crate) fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                let last_is_normal =
                    matches!(out.components().next_back(), Some(Component::Normal(_)));
                if last_is_normal {
                    out.pop();
                } else {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

/// Everything one compilation accumulates while loading files.
struct Loading<'a> {
    loader: &'a mut dyn SourceLoader,
    limits: &'a Limits,
    sources: SourceMap,
    program: Program,
    interner: Interner,
    diagnostics: Vec<Diagnostic>,
    /// Files by identity (the loader's canonical path), so a file imported twice, or through
    /// two paths, is loaded once.
    loaded: HashMap<PathBuf, FileIndex>,
    /// The chain of files being loaded, for cycle detection: (identity, path as written).
    stack: Vec<(PathBuf, PathBuf)>,
    total_bytes: usize,
    /// Parse steps over every file (see [`WorkCounts`]).
    parse_steps: u64,
    /// Set once the imports limit is reported, so later imports fail quietly.
    imports_exhausted: bool,
    /// Bracket nesting and syntax-tree depth allowed, within what the stack can take.
    max_nesting: usize,
    max_tree_depth: usize,
}

/// Bytes as text. Text that is not UTF-8 is kept with replacement characters (so that an
/// error can show its line) along with the offset and value of the first bad byte.
fn decode(bytes: Vec<u8>) -> (String, Option<(usize, u8)>) {
    match String::from_utf8(bytes) {
        Ok(text) => (text, None),
        Err(error) => {
            let at = error.utf8_error().valid_up_to();
            let bytes = error.into_bytes();
            let bad = bytes.get(at).copied().unwrap_or(0);
            (
                String::from_utf8_lossy(&bytes).into_owned(),
                Some((at, bad)),
            )
        }
    }
}

impl Loading<'_> {
    fn add_file(
        &mut self,
        path: PathBuf,
        identity: PathBuf,
        display: String,
        bytes: Vec<u8>,
    ) -> FileIndex {
        self.total_bytes += bytes.len();
        let (text, bad_byte) = decode(bytes);
        let file = self.sources.add(SourceFile::new(display.clone(), text));
        let index = file.0 as usize;
        self.program.files.push(FileAst {
            items: Vec::new(),
            frame_size: 0,
        });
        self.loaded.insert(identity.clone(), index);
        if let Some((at, byte)) = bad_byte {
            // Up to the bad byte the text is unchanged, so the offset is the same in it; the
            // replacement character there is three bytes long.
            self.diagnostics.push(
                Diagnostic::error(
                    format!("`{display}` is not UTF-8 text: byte 0x{byte:02x} here is not part of a character"),
                    Span::new(file, at, at + '\u{fffd}'.len_utf8()),
                )
                .with_label(format!("byte {at} of the file"))
                .with_hint("save the file as UTF-8 (scene files are text)"),
            );
            return index;
        }
        let text = match self.sources.get(file) {
            Some(source) => source.text.clone(),
            None => return index,
        };
        let mut cx = ParseContext::new(
            file,
            &mut self.interner,
            &mut self.program.functions,
            self.max_tree_depth,
        );
        let parsed = parser::parse_file(&text, &mut cx, self.max_nesting);
        self.parse_steps += cx.steps;
        let build_errors = std::mem::take(&mut cx.errors);
        self.diagnostics.extend(build_errors);
        let mut items = match parsed {
            Ok(items) => items,
            Err(diagnostic) => {
                self.diagnostics.push(diagnostic);
                return index;
            }
        };
        self.stack.push((identity, path.clone()));
        for item in &mut items {
            if let ItemKind::Import { path: import, file } = &mut item.kind {
                *file = self.import(&path, &import.value, import.span);
            }
        }
        self.stack.pop();
        self.program.files[index].items = items;
        index
    }

    fn import(&mut self, importer: &Path, name: &str, span: Span) -> Option<FileIndex> {
        let target = crate::editor::import_target(importer, name);
        let identity = self.loader.identify(&target);
        if let Some(position) = self.stack.iter().position(|(id, _)| *id == identity) {
            let chain: Vec<String> = self.stack[position..]
                .iter()
                .map(|(_, path)| path)
                .chain(std::iter::once(&target))
                .map(|p| format!("`{}`", p.display()))
                .collect();
            let mut diagnostic = Diagnostic::error(
                format!("import cycle: `{name}` imports this file again"),
                span,
            )
            .with_label("closes the cycle")
            .with_hint(format!("the chain is {}", chain.join(" → ")));
            if identity != target {
                diagnostic = diagnostic.with_hint(format!(
                    "`{}` is `{}` (through a symbolic link)",
                    target.display(),
                    identity.display()
                ));
            }
            self.diagnostics.push(
                diagnostic
                    .with_hint("move what both files need into a third file that imports neither"),
            );
            return None;
        }
        if let Some(&index) = self.loaded.get(&identity) {
            return Some(index);
        }
        if self.imports_exhausted {
            return None;
        }
        if self.loaded.len() >= self.limits.max_imports {
            self.imports_exhausted = true;
            self.diagnostics.push(
                Diagnostic::error(
                    format!(
                        "the imports limit ({} files in one compilation) was reached by this import",
                        self.limits.max_imports
                    ),
                    span,
                )
                .with_label("one file too many")
                .with_hint("see \"Limits\" in docs/language.md"),
            );
            return None;
        }
        // The stack holds the importing chain; its length is this import's depth.
        if self.stack.len() > self.limits.max_import_depth {
            self.diagnostics.push(
                Diagnostic::error(
                    format!(
                        "imports are nested too deeply: the import depth limit is {}",
                        self.limits.max_import_depth
                    ),
                    span,
                )
                .with_label("one import too deep"),
            );
            return None;
        }
        let bytes = match self.loader.load(&target) {
            Ok(bytes) => bytes,
            Err(error) => {
                self.diagnostics.push(
                    Diagnostic::error(format!("cannot import `{name}`: {error}"), span)
                        .with_label(format!("looked for `{}`", target.display()))
                        .with_hint("import paths are relative to the importing file's folder"),
                );
                return None;
            }
        };
        if self.total_bytes.saturating_add(bytes.len()) > self.limits.max_source_bytes {
            self.diagnostics.push(
                Diagnostic::error(
                    format!(
                        "the source size limit ({} bytes in total) was reached by this import",
                        self.limits.max_source_bytes
                    ),
                    span,
                )
                .with_label(format!("`{name}` has {} bytes", bytes.len())),
            );
            return None;
        }
        let display = target.to_string_lossy().into_owned();
        Some(self.add_file(target, identity, display, bytes))
    }
}

impl Loading<'_> {
    /// Parses the expression after `NAME=` (at `offset`) in the pseudo-file `file` of a `-D`
    /// or `--set`, keeping any problem found while building it.
    fn parse_value(
        &mut self,
        file: FileId,
        text: &str,
        offset: usize,
    ) -> Result<crate::ast::Expr, Diagnostic> {
        let mut cx = ParseContext::new(
            file,
            &mut self.interner,
            &mut self.program.functions,
            self.max_tree_depth,
        );
        let result = parser::parse_define_value(text, offset, &mut cx, self.max_nesting);
        let build_errors = std::mem::take(&mut cx.errors);
        self.diagnostics.extend(build_errors);
        result
    }
}

fn has_error(diagnostics: &[Diagnostic]) -> bool {
    diagnostics.iter().any(Diagnostic::is_error)
}

fn compile_root(
    path: &Path,
    display: String,
    bytes: Vec<u8>,
    loader: &mut dyn SourceLoader,
    options: &CompileOptions,
    max_evaluation_depth: usize,
    clock: (FrameClock, &Cell<bool>),
) -> Compilation {
    let limits = &options.limits;
    let mut loading = Loading {
        loader,
        limits,
        sources: SourceMap::new(),
        program: Program::default(),
        interner: Interner::default(),
        diagnostics: Vec::new(),
        loaded: HashMap::new(),
        stack: Vec::new(),
        total_bytes: 0,
        parse_steps: 0,
        imports_exhausted: false,
        // Limits raised far past their defaults stay within what this thread's stack can
        // take: every recursive pass is bounded by the tree depth.
        max_tree_depth: limits
            .max_nesting
            .saturating_mul(EXPRESSION_DEPTH_PER_NESTING)
            .min(max_evaluation_depth),
        max_nesting: limits.max_nesting.min(max_evaluation_depth / 2),
    };
    if bytes.len() > limits.max_source_bytes {
        let size = bytes.len();
        loading.sources.add(SourceFile::new(display.clone(), ""));
        return finish(
            loading.sources,
            None,
            vec![Diagnostic::new(
                Severity::Error,
                format!(
                    "`{display}` has {size} bytes, more than the source size limit ({} bytes)",
                    limits.max_source_bytes
                ),
                None,
            )],
            WorkCounts::default(),
        );
    }
    let identity = loading.loader.identify(path);
    loading.add_file(path.to_path_buf(), identity, display, bytes);
    let defines = parse_defines(&mut loading, &options.defines);
    let overrides = parse_setting_overrides(&mut loading, &options.settings);

    let Loading {
        loader,
        sources,
        mut program,
        interner,
        mut diagnostics,
        parse_steps,
        ..
    } = loading;
    let mut work = WorkCounts {
        parse_steps,
        name_probes: 0,
    };
    let (Some(mut defines), Some(mut overrides)) = (defines, overrides) else {
        return finish(sources, None, diagnostics, work);
    };
    if has_error(&diagnostics) {
        return finish(sources, None, diagnostics, work);
    }

    let (resolution, resolve_diagnostics) = {
        let mut values: Vec<_> = defines.iter_mut().map(|d| &mut d.value).collect();
        let mut resolver = Resolver::new(&interner, program.files.len(), &[]);
        for value in values.iter_mut() {
            resolver.resolve_define_value(value, &mut program);
        }
        for setting in &mut overrides {
            if let OverrideValue::Expr(value) = &mut setting.value {
                resolver.resolve_define_value(value, &mut program);
            }
        }
        let define_errors = std::mem::take(&mut resolver.diagnostics);
        diagnostics.extend(define_errors);
        let mut resolver = Resolver::new(&interner, program.files.len(), &defines);
        resolver.record_links = options.index;
        resolver.resolve_program(&mut program)
    };
    diagnostics.extend(resolve_diagnostics);
    work.name_probes = resolution.name_probes;
    // An editor's questions are about the text as written, so the index is read off the
    // resolved tree before evaluation consumes it.
    let mut index = options
        .index
        .then(|| crate::editor::index::build(&program, &interner, &resolution));
    let mut shown = index.as_ref().map(|_| HashMap::new());
    let mut compilation = evaluate_and_validate(
        EvaluationInput {
            program,
            interner,
            resolution,
            defines,
            overrides,
            sources,
            diagnostics,
            work,
            clock,
        },
        loader,
        limits,
        max_evaluation_depth,
        &mut shown,
    );
    if let (Some(index), Some(shown)) = (index.as_mut(), shown) {
        index.shown.extend(shown);
    }
    compilation.index = index;
    compilation
}

/// What resolution leaves for evaluation.
struct EvaluationInput<'c> {
    program: Program,
    interner: Interner,
    resolution: crate::resolve::Resolution,
    defines: Vec<Define>,
    overrides: Vec<SettingOverride>,
    sources: SourceMap,
    diagnostics: Vec<Diagnostic>,
    work: WorkCounts,
    clock: (FrameClock, &'c Cell<bool>),
}

/// Evaluation, mesh files and validation: the phases after resolution.
fn evaluate_and_validate(
    input: EvaluationInput<'_>,
    loader: &mut dyn SourceLoader,
    limits: &Limits,
    max_evaluation_depth: usize,
    shown: &mut Option<HashMap<Span, crate::editor::Shown>>,
) -> Compilation {
    let EvaluationInput {
        mut program,
        interner,
        resolution,
        defines,
        overrides,
        sources,
        mut diagnostics,
        work,
        clock: (clock, clock_read),
    } = input;
    // Evaluation runs even after resolution errors (unresolved names evaluate quietly to
    // nothing), so that one run reports every error it can find.

    // The root file's items are handed to the evaluator to own, so each is dropped as soon
    // as it has run: a scene written by a program is mostly its root file, and its syntax
    // tree is then given back while the scene grows rather than held beside all of it.
    let root_items = program
        .files
        .first_mut()
        .map(|root| std::mem::take(&mut root.items))
        .unwrap_or_default();
    let mut evaluator = crate::eval::Evaluator::new(
        &program,
        &interner,
        limits,
        &resolution,
        crate::eval::CommandLine {
            defines: &defines,
            overrides: &overrides,
            clock,
            clock_read,
        },
        sources.clone(),
        max_evaluation_depth,
    );
    evaluator.shown = shown.take();
    let (mut scene, eval_diagnostics, failed, recorded) = evaluator.run(root_items);
    *shown = recorded;
    diagnostics.extend(eval_diagnostics);
    if failed || has_error(&diagnostics) {
        return finish(sources, None, diagnostics, work);
    }
    crate::mesh::load_meshes(&mut scene, loader, limits, &mut diagnostics);
    // The scene's map is `sources` and the mesh files its diagnostics point into.
    let sources = scene.sources.clone();
    if has_error(&diagnostics) {
        return finish(sources, None, diagnostics, work);
    }
    match whitted_ir::validate(scene) {
        Ok(valid) => finish(sources, Some(valid), diagnostics, work),
        Err(invalid) => {
            diagnostics.extend(invalid.diagnostics);
            finish(sources, None, diagnostics, work)
        }
    }
}

/// Parses each `-D NAME=VALUE` in a pseudo-file of its own. `None` if any is malformed.
fn parse_defines(loading: &mut Loading<'_>, defines: &[(String, String)]) -> Option<Vec<Define>> {
    let mut parsed = Vec::new();
    let mut ok = true;
    // Each name with the span and value of its first `-D`.
    let mut seen: HashMap<&str, (Span, &str)> = HashMap::new();
    for (name, value) in defines {
        let text = format!("{name}={value}");
        let file: FileId = loading
            .sources
            .add(SourceFile::new(format!("<-D {name}>"), text.clone()));
        let name_span = Span::new(file, 0, name.len());
        let valid_name = name
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !valid_name {
            loading.diagnostics.push(
                Diagnostic::error(
                    format!("`-D {name}=...` needs a constant's name before `=`"),
                    name_span,
                )
                .with_label("not a name")
                .with_hint(
                    "names are letters, digits and `_`, starting with a letter or `_`: `-D N=100`",
                ),
            );
            ok = false;
            continue;
        }
        if let Some(&(first, first_value)) = seen.get(name.as_str()) {
            loading.diagnostics.push(
                Diagnostic::error(
                    format!("`-D {name}` is given twice: `-D {name}={first_value}` and `-D {name}={value}`"),
                    name_span,
                )
                .with_label("given again here")
                .with_secondary(first, "first given here")
                .with_hint(format!("keep one `-D {name}=...`")),
            );
            ok = false;
            continue;
        }
        seen.insert(name, (name_span, value));
        let result = loading.parse_value(file, &text, name.len() + 1);
        let sym = loading.interner.intern(name);
        match result {
            Ok(value) => parsed.push(Define {
                name: sym,
                name_span,
                value,
            }),
            Err(diagnostic) => {
                loading.diagnostics.push(diagnostic);
                ok = false;
            }
        }
    }
    ok.then_some(parsed)
}

/// A `--set NAME=VALUE`: a setting that replaces the scene's, after the scene has run.
pub(crate) struct SettingOverride {
    pub prop: Prop,
    pub value: OverrideValue,
    /// The VALUE part in the override's pseudo-file.
    pub value_span: Span,
}

pub(crate) enum OverrideValue {
    /// For settings that take a word (`--set shadows=filtered`).
    Word(&'static str),
    /// An expression with only the built-ins in scope (`--set background=rgb(0, 0, 0.2)`).
    Expr(crate::ast::Expr),
}

/// Reads each `--set NAME=VALUE` in a pseudo-file of its own, against the settings rows of
/// the property table. `None` if any is malformed (each problem is reported).
fn parse_setting_overrides(
    loading: &mut Loading<'_>,
    settings: &[(String, String)],
) -> Option<Vec<SettingOverride>> {
    let mut parsed = Vec::new();
    let mut ok = true;
    let mut seen: HashMap<&str, Span> = HashMap::new();
    let setting_names: Vec<&str> = Prop::ALL
        .iter()
        .filter(|p| properties::row(**p, Family::Settings).is_some())
        .map(|p| p.name())
        .collect();
    for (name, value) in settings {
        let text = format!("{name}={value}");
        let file: FileId = loading
            .sources
            .add(SourceFile::new(format!("<--set {text}>"), text.clone()));
        let name_span = Span::new(file, 0, name.len());
        let value_span = Span::new(file, name.len() + 1, text.len());
        let row = Prop::ALL
            .iter()
            .find(|p| p.name() == name)
            .and_then(|p| properties::row(*p, Family::Settings));
        let Some(row) = row else {
            let mut diagnostic =
                Diagnostic::error(format!("there is no setting `{name}`"), name_span)
                    .with_label("not a setting");
            diagnostic = match closest(name, setting_names.iter().copied()) {
                Some(best) => diagnostic.with_hint(format!("did you mean `{best}`?")),
                None => {
                    diagnostic.with_hint(format!("the settings are {}", list_and(&setting_names)))
                }
            };
            loading.diagnostics.push(diagnostic);
            ok = false;
            continue;
        };
        if let Some(&first) = seen.get(name.as_str()) {
            loading.diagnostics.push(
                Diagnostic::error(format!("`--set {name}` is given twice"), name_span)
                    .with_label("given again here")
                    .with_secondary(first, "first given here"),
            );
            ok = false;
            continue;
        }
        seen.insert(name, name_span);
        let value = match row.kind {
            Kind::Word(words) => match words.iter().find(|w| **w == value.trim()) {
                Some(word) => OverrideValue::Word(word),
                None => {
                    loading.diagnostics.push(
                        Diagnostic::error(
                            format!("`{name}` is {}, not `{value}`", list_or(words)),
                            value_span,
                        )
                        .with_label("not one of its words"),
                    );
                    ok = false;
                    continue;
                }
            },
            _ => match loading.parse_value(file, &text, name.len() + 1) {
                Ok(expr) => OverrideValue::Expr(expr),
                Err(diagnostic) => {
                    loading.diagnostics.push(diagnostic);
                    ok = false;
                    continue;
                }
            },
        };
        parsed.push(SettingOverride {
            prop: row.prop,
            value,
            value_span,
        });
    }
    ok.then_some(parsed)
}

/// Drops repeated diagnostics (a validation error on a million spheres from one line is one
/// error) and packs the result.
fn finish(
    sources: SourceMap,
    scene: Option<whitted_ir::ValidScene>,
    diagnostics: Vec<Diagnostic>,
    work: WorkCounts,
) -> Compilation {
    let mut seen = HashSet::new();
    // With errors, warnings and notes are mostly their echoes (a material whose definition
    // failed is "never used"); they come back once the errors are fixed.
    let errors = has_error(&diagnostics);
    let diagnostics: Vec<Diagnostic> = diagnostics
        .into_iter()
        .filter(|d| !errors || d.is_error())
        .filter(|d| seen.insert((d.severity as u8, d.span, d.message.clone())))
        .collect();
    let scene = if errors { None } else { scene };
    Compilation {
        sources,
        scene,
        index: None,
        diagnostics,
        work,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_normalize_lexically() {
        assert_eq!(
            normalize(Path::new("a/./b/../c.scene")),
            PathBuf::from("a/c.scene")
        );
        assert_eq!(
            normalize(Path::new("../x.scene")),
            PathBuf::from("../x.scene")
        );
        assert_eq!(normalize(Path::new("a/../../x")), PathBuf::from("../x"));
    }
}
