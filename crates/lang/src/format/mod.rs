//! `whitted fmt`: scene text laid out in the one canonical way, comments kept, meaning
//! unchanged.
//!
//! The file is parsed as the compiler parses it (a file with a syntax error is refused with
//! the compiler's own diagnostic, never half formatted), split into tokens with comments
//! (`tokens`), grouped into blocks and items by the syntax tree (`structure`), and printed
//! again by the layout rules (`layout`). Only whitespace between tokens changes. Before the
//! text is returned it is parsed again and must give the same tokens with the same roles,
//! so a formatter bug is an error, not a changed scene; the tests compare the IR of every
//! scene before and after.

mod layout;
mod structure;
pub(crate) mod tokens;

use whitted_ir::{limits, Diagnostic, FileId, SourceFile, SourceMap, Span};

use crate::ast::{FnDef, Item};
use crate::intern::Interner;
use crate::parser::{self, ParseContext};

/// Why a file was not formatted: the diagnostics, with the file they point into.
#[derive(Debug)]
pub struct FormatFailure {
    pub sources: SourceMap,
    pub diagnostics: Vec<Diagnostic>,
}

/// Stack for the formatting thread (the parser and the walks recurse as deep as the text
/// nests, within the compiler's limits); the smaller one for systems that refuse the first.
const STACK_BYTES: [usize; 2] = [256 * 1024 * 1024, 64 * 1024 * 1024];

/// Formats the text of a scene file named `name` (the name is only for diagnostics).
pub fn format_source(name: &str, text: &str) -> Result<String, FormatFailure> {
    let mut sources = SourceMap::new();
    let file = sources.add(SourceFile::new(name, text));
    let fail = |sources: SourceMap, diagnostics| {
        Err(FormatFailure {
            sources,
            diagnostics,
        })
    };
    if text.len() > limits::MAX_SOURCE_BYTES {
        let message = format!(
            "`{name}` has {} bytes, more than the source size limit ({} bytes)",
            text.len(),
            limits::MAX_SOURCE_BYTES
        );
        return fail(
            sources,
            vec![Diagnostic::error(message, Span::new(file, 0, 0))],
        );
    }
    match on_big_stack(|| format_parsed(text, file)) {
        Ok(Ok(formatted)) => Ok(formatted),
        Ok(Err(diagnostics)) => fail(sources, diagnostics),
        Err(message) => fail(
            sources,
            vec![Diagnostic::error(message, Span::new(file, 0, 0))],
        ),
    }
}

fn on_big_stack<T: Send>(work: impl FnOnce() -> T + Send) -> Result<T, String> {
    let parcel = std::sync::Mutex::new(Some(work));
    std::thread::scope(|scope| {
        let mut error = String::from("no stack size to try");
        for stack in STACK_BYTES {
            let parcel = &parcel;
            let spawned = std::thread::Builder::new()
                .name("whitted-lang fmt".into())
                .stack_size(stack)
                .spawn_scoped(scope, move || {
                    let work = parcel.lock().ok().and_then(|mut p| p.take());
                    work.map(|work| work())
                });
            match spawned {
                Ok(handle) => {
                    return match handle.join() {
                        Ok(Some(value)) => Ok(value),
                        Ok(None) => Err("the formatter thread started without its work".into()),
                        Err(panic) => std::panic::resume_unwind(panic),
                    }
                }
                Err(e) => error = e.to_string(),
            }
        }
        Err(format!("cannot start the formatter thread: {error}"))
    })
}

/// The parse of one file: its items and functions, or the compiler's diagnostics.
fn parse(text: &str, file: FileId) -> Result<(Vec<Item>, Vec<FnDef>), Vec<Diagnostic>> {
    let mut interner = Interner::default();
    let mut functions = Vec::new();
    // The compiler's own bounds for a thread of this stack (see compile.rs).
    let max_nesting = limits::MAX_NESTING;
    let max_tree_depth = limits::MAX_NESTING.saturating_mul(16);
    let mut cx = ParseContext::new(file, &mut interner, &mut functions, max_tree_depth);
    let parsed = parser::parse_file(text, &mut cx, max_nesting);
    let mut errors = std::mem::take(&mut cx.errors);
    match parsed {
        Ok(items) if errors.is_empty() => Ok((items, functions)),
        Ok(_) => Err(errors),
        Err(diagnostic) => {
            errors.push(diagnostic);
            Err(errors)
        }
    }
}

fn tokens_of(
    text: &str,
    file: FileId,
) -> Result<(Vec<tokens::Token>, structure::Structure), Vec<Diagnostic>> {
    let (items, functions) = parse(text, file)?;
    let structure = structure::collect(text, &items, &functions);
    let tokens = tokens::tokenize(text, &structure.roles);
    Ok((tokens, structure))
}

fn format_parsed(text: &str, file: FileId) -> Result<String, Vec<Diagnostic>> {
    let (tokens, structure) = tokens_of(text, file)?;
    let bug = |what: &str, at: u32| {
        vec![Diagnostic::error(
            format!("the formatter cannot lay out this file ({what}); it was left unchanged"),
            Span::new(file, at as usize, at as usize),
        )
        .with_hint("this is a bug in `whitted fmt`; please report it with the file")]
    };
    let formatted = layout::print(text, &tokens, &structure)
        .map_err(|mismatch| bug("its tokens and syntax tree disagree", mismatch.0))?;
    // The output must read as the same tokens doing the same things.
    let (again, _) =
        tokens_of(&formatted, file).map_err(|_| bug("the formatted text does not parse", 0))?;
    let key = |source: &str, t: &tokens::Token| {
        let s = &source[t.start as usize..t.end as usize];
        let s = if t.kind == tokens::Kind::LineComment {
            s.trim_end()
        } else {
            s
        };
        (s.to_string(), t.role)
    };
    let same = tokens.len() == again.len()
        && tokens
            .iter()
            .zip(&again)
            .all(|(a, b)| key(text, a) == key(&formatted, b));
    if !same {
        let at = tokens
            .iter()
            .zip(&again)
            .find(|(a, b)| key(text, a) != key(&formatted, b))
            .map_or(0, |(a, _)| a.start);
        return Err(bug("the formatted text reads differently", at));
    }
    Ok(formatted)
}
