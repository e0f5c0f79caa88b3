//! Rename: every occurrence of a definition's name (`references.rs`) replaced, in every file
//! the server knows. Before answering, the renamed texts are compiled again: a new name that
//! would clash with another definition in the same block, or make a use mean another
//! definition (or another use mean this one), is refused with a message saying so, as is a
//! name that is not one and a rename while a file that may use it does not parse.

use std::collections::HashMap;

use lsp_server::{ErrorCode, ResponseError};
use lsp_types::{PrepareRenameResponse, TextEdit, Url, WorkspaceEdit};

use crate::documents::Document;
use crate::loader::Overlay;
use crate::references::{occurrences, target, Place};
use crate::Files;

/// `textDocument/prepareRename`: the name under the cursor, when it names a definition.
pub fn prepare(
    documents: &HashMap<Url, Document>,
    uri: &Url,
    offset: usize,
) -> Option<PrepareRenameResponse> {
    let document = documents.get(uri)?;
    let definition = target(uri, document, offset)?;
    let found = occurrences(documents, &definition)?;
    let (_, location) = found
        .places
        .iter()
        .find(|(place, _)| place.uri == *uri && place.start <= offset && offset <= place.end)?;
    Some(PrepareRenameResponse::RangeWithPlaceholder {
        range: location.range,
        placeholder: found.name,
    })
}

/// `textDocument/rename`: the edits, or an error saying why the name cannot change.
pub fn rename(
    documents: &HashMap<Url, Document>,
    files: &mut dyn Files,
    uri: &Url,
    offset: usize,
    new_name: &str,
) -> Result<Option<WorkspaceEdit>, ResponseError> {
    let Some(document) = documents.get(uri) else {
        return Ok(None);
    };
    // A 6.837 scene has no names to rename.
    if is_course(document) {
        return Ok(None);
    }
    if document
        .analysis
        .as_ref()
        .is_some_and(|a| a.index.is_none())
    {
        return Err(refuse(format!(
            "{} does not parse: fix its syntax error before renaming",
            file_name(uri)
        )));
    }
    let Some(definition) = target(uri, document, offset) else {
        return Err(refuse(
            "there is no name of a definition here to rename".to_string(),
        ));
    };
    whitted_lang::editor::check_name(new_name).map_err(refuse)?;
    let Some(found) = occurrences(documents, &definition) else {
        return Ok(None);
    };
    // An open file whose compile read the definition's file but did not parse may use the
    // name where nobody can see it.
    for (other, doc) in documents {
        let Some(analysis) = doc.analysis.as_ref() else {
            continue;
        };
        let reads = *other == definition.uri
            || analysis
                .sources
                .files()
                .filter_map(|(_, file)| Url::from_file_path(&file.path).ok())
                .any(|file| file == definition.uri);
        if reads && analysis.index.is_none() && !is_course(doc) {
            return Err(refuse(format!(
                "{} does not parse: fix its syntax error before renaming",
                file_name(other)
            )));
        }
    }
    if found.name == new_name {
        return Ok(Some(WorkspaceEdit::default()));
    }
    let mut changes: HashMap<Url, Vec<TextEdit>> = HashMap::new();
    for (_, location) in &found.places {
        changes
            .entry(location.uri.clone())
            .or_default()
            .push(TextEdit {
                range: location.range,
                new_text: new_name.to_string(),
            });
    }
    check_meaning(documents, files, &found, new_name)?;
    Ok(Some(WorkspaceEdit {
        changes: Some(changes),
        ..WorkspaceEdit::default()
    }))
}

fn is_course(document: &Document) -> bool {
    whitted_mit6837::is_mit6837(document.text.as_bytes())
        || document
            .path
            .as_deref()
            .and_then(std::path::Path::extension)
            .is_some_and(|e| e.eq_ignore_ascii_case("txt"))
}

fn refuse(message: String) -> ResponseError {
    ResponseError {
        code: ErrorCode::RequestFailed as i32,
        message,
        data: None,
    }
}

fn file_name(uri: &Url) -> String {
    uri.to_file_path()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| uri.to_string())
}

/// Compiles every open document again with the renamed texts and checks that the rename
/// means what it did: no new error (a clash: "already defined"), every renamed use still
/// linked to the renamed definition, and no other use linked to it.
fn check_meaning(
    documents: &HashMap<Url, Document>,
    files: &mut dyn Files,
    found: &crate::references::Occurrences,
    new_name: &str,
) -> Result<(), ResponseError> {
    let delta = new_name.len() as isize - found.name.len() as isize;
    // Where a place of the old texts is in the new ones: shifted by the renamed names
    // before it in its file.
    let moved = |place: &Place| -> Place {
        let before = found
            .places
            .iter()
            .filter(|(p, _)| p.uri == place.uri && p.end <= place.start)
            .count() as isize;
        let start = (place.start as isize + before * delta).max(0) as usize;
        let end = if found.places.iter().any(|(p, _)| p == place) {
            start + new_name.len()
        } else {
            (place.end as isize + before * delta).max(0) as usize
        };
        Place {
            uri: place.uri.clone(),
            start,
            end,
        }
    };
    // The renamed texts: open documents from their text, other files from the compile
    // that read them.
    let mut texts: HashMap<Url, String> = HashMap::new();
    for (uri, document) in documents {
        texts.insert(uri.clone(), document.text.clone());
    }
    for document in documents.values() {
        let Some(analysis) = document.analysis.as_ref() else {
            continue;
        };
        for (_, file) in analysis.sources.files().skip(1) {
            if let Ok(uri) = Url::from_file_path(&file.path) {
                texts.entry(uri).or_insert_with(|| file.text.to_string());
            }
        }
    }
    let edited: Vec<Url> = {
        let mut list: Vec<Url> = found.places.iter().map(|(p, _)| p.uri.clone()).collect();
        list.dedup();
        list
    };
    for uri in &edited {
        let Some(text) = texts.get_mut(uri) else {
            continue;
        };
        let mut spans: Vec<&Place> = found
            .places
            .iter()
            .map(|(p, _)| p)
            .filter(|p| p.uri == *uri)
            .collect();
        spans.sort();
        for place in spans.iter().rev() {
            if text.get(place.start..place.end).is_some() {
                text.replace_range(place.start..place.end, new_name);
            }
        }
    }
    let mut renamed: HashMap<Url, Document> = HashMap::new();
    for (uri, text) in &texts {
        let old = documents.get(uri);
        if old.is_none() && !edited.contains(uri) {
            continue;
        }
        let mut document = Document::new(uri, text.clone(), old.map_or(0, |d| d.version));
        document.identity = old.and_then(|d| d.identity.clone());
        renamed.insert(uri.clone(), document);
    }
    let new_definition = moved(&found.definition);
    let new_uses: Vec<Place> = found.places.iter().map(|(p, _)| moved(p)).collect();
    for (uri, old) in documents {
        let Some(old_analysis) = old.analysis.as_ref() else {
            continue;
        };
        if old_analysis.index.is_none() {
            continue;
        }
        let Some(document) = renamed.get(uri) else {
            continue;
        };
        let analysis = crate::analysis::analyze(
            uri,
            document,
            Overlay {
                documents: &renamed,
                files: &mut *files,
            },
        );
        let errors = |a: &crate::analysis::Analysis| -> Vec<String> {
            a.diagnostics
                .iter()
                .flat_map(|(_, list)| list)
                .filter(|d| d.severity == Some(lsp_types::DiagnosticSeverity::ERROR))
                .map(|d| d.message.clone())
                .collect()
        };
        // A clash is a new error ("already defined"); the old errors may change their
        // words (a "did you mean" naming the renamed name), not their number.
        let before = errors(old_analysis);
        let after = errors(&analysis);
        if after.len() > before.len() {
            let new_error = after
                .iter()
                .find(|message| !before.contains(message))
                .or(after.first())
                .cloned()
                .unwrap_or_default();
            let headline = new_error.lines().next().unwrap_or_default().to_string();
            return Err(refuse(format!(
                "renaming `{}` to `{new_name}` would clash with another definition: {headline}",
                found.name
            )));
        }
        let Some(index) = analysis.index.as_ref() else {
            continue;
        };
        let locator = crate::analysis::Locator::new(uri, &analysis.sources, &document.lines);
        let at = |span: whitted_ir::Span| Place {
            uri: locator.uri(span.file).unwrap_or_else(|| uri.clone()),
            start: span.start as usize,
            end: span.end as usize,
        };
        for (from, to) in &index.links {
            let (from, to) = (at(*from), at(*to));
            let renamed_use = new_uses.contains(&from);
            let means_it = to == new_definition;
            if renamed_use != means_it {
                let why = if renamed_use {
                    "a use of it would then mean another definition of that name"
                } else {
                    "another name's use would then mean it"
                };
                return Err(refuse(format!(
                    "renaming `{}` to `{new_name}` would change what the scene means: {why} ({} line {})",
                    found.name,
                    file_name(&from.uri),
                    line_of(&texts, &from),
                )));
            }
        }
    }
    Ok(())
}

fn line_of(texts: &HashMap<Url, String>, place: &Place) -> usize {
    texts
        .get(&place.uri)
        .and_then(|t| t.get(..place.start))
        .map_or(0, |t| t.matches('\n').count() + 1)
}
