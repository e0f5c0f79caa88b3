//! Navigation on what a string names: an object's name (`sphere "ball" { ... }`) and the
//! file of an `import` or a mesh's `file`. Definition, references and rename of an object's
//! name; references of a file, and the edits that follow a file's move
//! (`workspace/willRenameFiles`); the go to definition of a file is `navigation.rs`'s.
//!
//! Nothing in the language refers to an object by its name: the name is what explain's
//! queries (`hit("ball")`), `whitted trace` and the debugger call it by, and many objects
//! may share one (a loop's spheres). So the occurrences of a name are the objects written
//! with that same name in the scenes that hold it (every open document whose compile read
//! the file the cursor is in, and the files those compiles read); its definition is the
//! first of them in the document's compile; renaming it renames them all, and is refused
//! when the new name is already another object's (the two groups would merge). A name with
//! `{name}` holes or escapes is not plain text and takes no part.
//!
//! The occurrences of a file are the `import` and `file` strings, in every open document's
//! compile, that name the same file once resolved as the compiler resolves them (relative to
//! the file they are written in) and identified by [`Files::identify`] (through links).

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use lsp_server::{ErrorCode, ResponseError};
use lsp_types::{Location, PrepareRenameResponse, Range, TextEdit, Url, WorkspaceEdit};
use whitted_ir::Span;

use crate::analysis::{Analysis, Locator};
use crate::documents::{indexed, Document};
use crate::references::Place;
use crate::Files;

/// What the string under the cursor names.
enum Named {
    /// An object's name.
    Object(String),
    /// A file, as the loader identifies it; and the path the compiler would read.
    File { identity: PathBuf, path: PathBuf },
}

fn covers(span: &Span, offset: usize) -> bool {
    span.file.0 == 0 && (span.start as usize) <= offset && offset <= span.end as usize
}

/// The file a path string in `span`'s file names, as the compiler resolves it.
fn resolve(analysis: &Analysis, span: Span, written: &str) -> Option<PathBuf> {
    let file = analysis.sources.get(span.file)?;
    Some(whitted_lang::editor::import_target(
        Path::new(&file.path),
        written,
    ))
}

fn named(document: &Document, offset: usize, files: &mut dyn Files) -> Option<Named> {
    let analysis = document.analysis.as_ref()?;
    let index = analysis.index.as_ref()?;
    if let Some((_, name)) = index.object_names.iter().find(|(s, _)| covers(s, offset)) {
        return Some(Named::Object(name.clone()));
    }
    let (span, written) = index.paths.iter().find(|(s, _)| covers(s, offset))?;
    let path = resolve(analysis, *span, written)?;
    Some(Named::File {
        identity: files.identify(&path),
        path,
    })
}

/// Whether the compile of `document` (at `uri`) read the file `file`.
fn reads(uri: &Url, analysis: &Analysis, file: &Url) -> bool {
    uri == file
        || analysis
            .sources
            .files()
            .skip(1)
            .filter_map(|(_, source)| Url::from_file_path(&source.path).ok())
            .any(|source| source == *file)
}

/// Places found across compiles, each once, in file and text order.
#[derive(Default)]
struct Found {
    places: BTreeSet<Place>,
    locations: HashMap<Place, Location>,
}

impl Found {
    fn add(&mut self, locator: &mut Locator<'_>, span: Span) {
        let Some(uri) = locator.uri(span.file) else {
            return;
        };
        let place = Place {
            uri,
            start: span.start as usize,
            end: span.end as usize,
        };
        if self.locations.contains_key(&place) {
            return;
        }
        if let Some(location) = locator.location(span) {
            self.locations.insert(place.clone(), location);
            self.places.insert(place);
        }
    }

    fn into_list(mut self) -> Vec<(Place, Location)> {
        self.places
            .into_iter()
            .filter_map(|p| {
                let location = self.locations.remove(&p)?;
                Some((p, location))
            })
            .collect()
    }
}

/// Every object written with the name `name` in the scenes that read the file `uri`: the
/// name's literal, with its quotes.
fn objects_named(documents: &HashMap<Url, Document>, uri: &Url, name: &str) -> Found {
    let mut found = Found::default();
    for (other, document, analysis, index) in indexed(documents) {
        if !reads(other, analysis, uri) {
            continue;
        }
        let mut locator = Locator::new(other, &analysis.sources, &document.lines);
        for (span, _) in index.object_names.iter().filter(|(_, n)| n == name) {
            found.add(&mut locator, *span);
        }
    }
    found
}

/// The first object named `name` in the document's own compile.
fn first_named(uri: &Url, document: &Document, name: &str) -> Option<Location> {
    let analysis = document.analysis.as_ref()?;
    let index = analysis.index.as_ref()?;
    let (span, _) = index.object_names.iter().find(|(_, n)| n == name)?;
    Locator::new(uri, &analysis.sources, &document.lines).location(*span)
}

/// Go to definition on an object's name: the first object of that name (itself, when the
/// name is its own).
pub fn definition(uri: &Url, document: &Document, offset: usize) -> Option<Location> {
    let index = document.analysis.as_ref()?.index.as_ref()?;
    let (_, name) = index.object_names.iter().find(|(s, _)| covers(s, offset))?;
    first_named(uri, document, name)
}

/// `textDocument/references` on an object's name or a file's string; `None` when the cursor
/// is on neither (the caller then asks the resolver's names).
pub fn references(
    documents: &HashMap<Url, Document>,
    files: &mut dyn Files,
    uri: &Url,
    offset: usize,
    include_declaration: bool,
) -> Option<Vec<Location>> {
    let document = documents.get(uri)?;
    match named(document, offset, files)? {
        Named::Object(name) => {
            let first = first_named(uri, document, &name);
            let list = objects_named(documents, uri, &name).into_list();
            Some(
                list.into_iter()
                    .map(|(_, location)| location)
                    .filter(|location| include_declaration || Some(location) != first.as_ref())
                    .collect(),
            )
        }
        Named::File { identity, path } => {
            let mut found = Found::default();
            for (other, document, analysis, index) in indexed(documents) {
                let mut locator = Locator::new(other, &analysis.sources, &document.lines);
                for (span, written) in &index.paths {
                    let same = resolve(analysis, *span, written)
                        .is_some_and(|p| p == path || files.identify(&p) == identity);
                    if same {
                        found.add(&mut locator, *span);
                    }
                }
            }
            let mut list: Vec<Location> = Vec::new();
            if include_declaration {
                // The file itself, where go to definition takes the cursor.
                list.extend(
                    Url::from_file_path(&path)
                        .ok()
                        .map(|file| Location::new(file, Range::default())),
                );
            }
            list.extend(found.into_list().into_iter().map(|(_, location)| location));
            Some(list)
        }
    }
}

/// The range inside a name's quotes.
fn inside(mut location: Location) -> Location {
    location.range.start.character += 1;
    location.range.end.character = location.range.end.character.saturating_sub(1);
    location
}

/// `textDocument/prepareRename` on an object's name: the text between its quotes.
/// `None` for anything else (a file's string is not renamed here).
pub fn prepare(
    documents: &HashMap<Url, Document>,
    files: &mut dyn Files,
    uri: &Url,
    offset: usize,
) -> Option<Option<PrepareRenameResponse>> {
    let document = documents.get(uri)?;
    match named(document, offset, files)? {
        Named::Object(name) => {
            let analysis = document.analysis.as_ref()?;
            let index = analysis.index.as_ref()?;
            let (span, _) = index.object_names.iter().find(|(s, _)| covers(s, offset))?;
            let location = Locator::new(uri, &analysis.sources, &document.lines).location(*span)?;
            Some(Some(PrepareRenameResponse::RangeWithPlaceholder {
                range: inside(location).range,
                placeholder: name,
            }))
        }
        Named::File { .. } => Some(None),
    }
}

/// `textDocument/rename` on an object's name: every object of that name renamed, or a
/// refusal. `None` when the cursor is not on an object's name.
pub fn rename(
    documents: &HashMap<Url, Document>,
    files: &mut dyn Files,
    uri: &Url,
    offset: usize,
    new_name: &str,
) -> Option<Result<Option<WorkspaceEdit>, ResponseError>> {
    let document = documents.get(uri)?;
    let name = match named(document, offset, files)? {
        Named::Object(name) => name,
        Named::File { .. } => {
            return Some(Err(refuse(
                "a file is renamed by renaming the file; its `import` and `file` strings are its references".to_string(),
            )))
        }
    };
    Some(rename_object(documents, uri, &name, new_name))
}

fn rename_object(
    documents: &HashMap<Url, Document>,
    uri: &Url,
    name: &str,
    new_name: &str,
) -> Result<Option<WorkspaceEdit>, ResponseError> {
    if new_name.is_empty() {
        return Err(refuse("an object's name cannot be empty".to_string()));
    }
    if let Some(c) = new_name
        .chars()
        .find(|c| matches!(c, '"' | '\\' | '{' | '}' | '\n' | '\r'))
    {
        return Err(refuse(format!(
            "an object's new name is plain text: `{}` would need an escape or make a `{{name}}` hole",
            c.escape_default()
        )));
    }
    for (other, document) in documents {
        let Some(analysis) = document.analysis.as_ref() else {
            continue;
        };
        if analysis.index.is_none()
            && reads(other, analysis, uri)
            && !whitted_mit6837::is_mit6837(document.text.as_bytes())
        {
            return Err(refuse(format!(
                "{} does not parse: fix its syntax error before renaming",
                other.path().rsplit('/').next().unwrap_or_default()
            )));
        }
    }
    if name == new_name {
        return Ok(Some(WorkspaceEdit::default()));
    }
    let taken = objects_named(documents, uri, new_name).into_list();
    if let Some((_, location)) = taken.first() {
        return Err(refuse(format!(
            "renaming \"{name}\" to \"{new_name}\" would merge its objects with the ones already named so ({} line {})",
            location.uri.path().rsplit('/').next().unwrap_or_default(),
            location.range.start.line + 1
        )));
    }
    let mut changes: HashMap<Url, Vec<TextEdit>> = HashMap::new();
    for (_, location) in objects_named(documents, uri, name).into_list() {
        let location = inside(location);
        changes.entry(location.uri).or_default().push(TextEdit {
            range: location.range,
            new_text: new_name.to_string(),
        });
    }
    Ok(Some(WorkspaceEdit {
        changes: Some(changes),
        ..WorkspaceEdit::default()
    }))
}

fn refuse(message: String) -> ResponseError {
    ResponseError {
        code: ErrorCode::RequestFailed as i32,
        message,
        data: None,
    }
}

/// `workspace/willRenameFiles`: before the editor renames or moves files or folders, the
/// edits that keep every `import` and mesh `file` string in the open documents' compiles
/// naming them, each written relative to its own file as before. A string in a file that
/// moves with what it names (both in a moved folder) is left alone; the relative strings
/// of a scene file that moves away from what it names are not rewritten.
pub fn will_rename(
    documents: &HashMap<Url, Document>,
    files: &mut dyn Files,
    renames: &[lsp_types::FileRename],
) -> Option<WorkspaceEdit> {
    let moves: Vec<(PathBuf, PathBuf, PathBuf)> = renames
        .iter()
        .filter_map(|rename| {
            let old = Url::parse(&rename.old_uri).ok()?.to_file_path().ok()?;
            let new = Url::parse(&rename.new_uri).ok()?.to_file_path().ok()?;
            Some((files.identify(&old), old, new))
        })
        .collect();
    let mut edits: HashMap<Place, Location> = HashMap::new();
    let mut texts: HashMap<Place, String> = HashMap::new();
    let mut places: BTreeSet<Place> = BTreeSet::new();
    for (uri, document, analysis, index) in indexed(documents) {
        let mut locator = Locator::new(uri, &analysis.sources, &document.lines);
        for (span, written) in &index.paths {
            let (Some(target), Some(source)) = (
                resolve(analysis, *span, written),
                analysis.sources.get(span.file),
            ) else {
                continue;
            };
            let from = Path::new(&source.path);
            for (identity, old, new) in &moves {
                let moved = if target == *old || files.identify(&target) == *identity {
                    new.clone()
                } else if let Ok(rest) = target.strip_prefix(old) {
                    new.join(rest)
                } else {
                    continue;
                };
                if from.starts_with(old) {
                    break;
                }
                let Some(location) = locator.location(*span) else {
                    break;
                };
                let place = Place {
                    uri: location.uri.clone(),
                    start: span.start as usize,
                    end: span.end as usize,
                };
                let folder = from.parent().unwrap_or(Path::new("/"));
                texts.insert(place.clone(), relative(folder, &moved));
                edits.insert(place.clone(), inside(location));
                places.insert(place);
                break;
            }
        }
    }
    if places.is_empty() {
        return None;
    }
    let mut changes: HashMap<Url, Vec<TextEdit>> = HashMap::new();
    for place in places {
        let (Some(location), Some(text)) = (edits.remove(&place), texts.remove(&place)) else {
            continue;
        };
        changes.entry(location.uri).or_default().push(TextEdit {
            range: location.range,
            new_text: text,
        });
    }
    Some(WorkspaceEdit {
        changes: Some(changes),
        ..WorkspaceEdit::default()
    })
}

/// `to` as written from the folder `from` (both absolute): `..` up to their common folder,
/// then down, with `/` between the parts.
fn relative(from: &Path, to: &Path) -> String {
    let from: Vec<_> = from.components().collect();
    let to: Vec<_> = to.components().collect();
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    let mut parts: Vec<String> = vec!["..".to_string(); from.len() - common];
    parts.extend(
        to[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    parts.join("/")
}
