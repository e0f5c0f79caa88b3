//! Quick fixes from the compiler's diagnostics: a "did you mean `x`?" replaces the
//! underlined text with `x`; a "remove this" deletes it; a "write `}}` for a `}`" writes
//! the one for the other. Each fix is found when the document is analysed and answered as a
//! `quickfix` code action linked to its diagnostic.

use std::collections::HashMap;

use lsp_types::{
    CodeAction, CodeActionKind, CodeActionOrCommand, Diagnostic as LspDiagnostic, Range, TextEdit,
    Url, WorkspaceEdit,
};
use whitted_ir::{Diagnostic, SourceMap};

use crate::analysis::Locator;
use crate::documents::Document;

/// One quick fix: the diagnostic it answers (by place and message) and its edit.
#[derive(Clone, Debug)]
pub struct Fix {
    pub title: String,
    pub uri: Url,
    /// The diagnostic's range and message, as published.
    pub range: Range,
    pub message: String,
    pub edit: TextEdit,
}

/// The fixes the compiler's diagnostics offer (see the module documentation).
pub fn fixes(
    locator: &mut Locator<'_>,
    sources: &SourceMap,
    diagnostics: &[Diagnostic],
) -> Vec<Fix> {
    let mut out = Vec::new();
    for diagnostic in diagnostics {
        let Some(span) = diagnostic.span else {
            continue;
        };
        let Some(written) = sources
            .get(span.file)
            .and_then(|file| file.text.get(span.range()))
        else {
            continue;
        };
        let Some(location) = locator.location(span) else {
            continue;
        };
        let mut edits: Vec<(String, String)> = Vec::new();
        for hint in &diagnostic.hints {
            if let Some(best) = quoted_after(hint, "did you mean `") {
                // `.x` for a field whose underline is the name after the dot.
                let best = match best.strip_prefix('.') {
                    Some(bare) if !written.starts_with('.') => bare,
                    _ => best,
                };
                if best != written {
                    edits.push((
                        format!("Replace `{written}` with `{best}`"),
                        best.to_string(),
                    ));
                }
            } else if let Some(instead) = quoted_after(hint, "write `") {
                let rest = &hint["write `".len() + instead.len() + 1..];
                if quoted_after(rest, " for a `") == Some(written) {
                    edits.push((
                        format!("Write `{instead}` for `{written}`"),
                        instead.to_string(),
                    ));
                }
            }
        }
        if diagnostic.label.as_deref() == Some("remove this") {
            edits.push((format!("Remove `{written}`"), String::new()));
        }
        let message = crate::analysis::message(diagnostic);
        for (title, new_text) in edits {
            out.push(Fix {
                title,
                uri: location.uri.clone(),
                range: location.range,
                message: message.clone(),
                edit: TextEdit {
                    range: location.range,
                    new_text,
                },
            });
        }
    }
    out
}

/// The text between `prefix` (at the start of `text`) and the next backquote.
fn quoted_after<'a>(text: &'a str, prefix: &str) -> Option<&'a str> {
    let rest = text.strip_prefix(prefix)?;
    let end = rest.find('`')?;
    Some(&rest[..end])
}

/// `textDocument/codeAction`: the quick fixes of the document's diagnostics that touch
/// `range`, each with the diagnostic it fixes.
pub fn code_actions(uri: &Url, document: &Document, range: Range) -> Vec<CodeActionOrCommand> {
    let Some(analysis) = document.analysis.as_ref() else {
        return Vec::new();
    };
    let published: Vec<&LspDiagnostic> = analysis
        .diagnostics
        .iter()
        .filter(|(file, _)| file == uri)
        .flat_map(|(_, list)| list)
        .collect();
    let touches = |r: &Range| r.start <= range.end && range.start <= r.end;
    analysis
        .fixes
        .iter()
        .filter(|fix| fix.uri == *uri && touches(&fix.range))
        .map(|fix| {
            let diagnostic = published
                .iter()
                .find(|d| d.range == fix.range && d.message == fix.message)
                .map(|d| (*d).clone());
            CodeActionOrCommand::CodeAction(CodeAction {
                title: fix.title.clone(),
                kind: Some(CodeActionKind::QUICKFIX),
                diagnostics: diagnostic.map(|d| vec![d]),
                edit: Some(WorkspaceEdit {
                    changes: Some(HashMap::from([(uri.clone(), vec![fix.edit.clone()])])),
                    ..WorkspaceEdit::default()
                }),
                is_preferred: Some(true),
                ..CodeAction::default()
            })
        })
        .collect()
}
