//! Find references: every place a definition's name is written (its definition and each use
//! the resolver linked to it), across the files the server knows: the open documents and
//! the files their compiles read, so a definition in an imported file is found from every
//! open file that uses it.

use std::collections::{BTreeSet, HashMap};

use lsp_types::{Location, Url};
use whitted_ir::Span;

use crate::analysis::Locator;
use crate::documents::{indexed, Document};

/// A place in a file: its URI and byte range (the same file read by two compiles has the
/// same bytes, so the same place has the same key in both).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Place {
    pub uri: Url,
    pub start: usize,
    pub end: usize,
}

/// Every occurrence of one definition's name.
pub struct Occurrences {
    /// The definition's name as written.
    pub name: String,
    pub definition: Place,
    /// The definition and every use, in file and text order, each once.
    pub places: Vec<(Place, Location)>,
}

/// The definition whose name (or a use of it) is at `offset` in the document `uri`.
pub fn target(uri: &Url, document: &Document, offset: usize) -> Option<Place> {
    let analysis = document.analysis.as_ref()?;
    let index = analysis.index.as_ref()?;
    let at = |span: &Span| {
        span.file.0 == 0 && (span.start as usize) <= offset && offset <= span.end as usize
    };
    let span = index
        .links
        .iter()
        .find(|(from, _)| at(from))
        .map(|(_, to)| *to)
        .or_else(|| index.definitions.iter().map(|d| d.span).find(at))?;
    let locator = Locator::new(uri, &analysis.sources, &document.lines);
    place(&locator, span)
}

fn place(locator: &Locator<'_>, span: Span) -> Option<Place> {
    Some(Place {
        uri: locator.uri(span.file)?,
        start: span.start as usize,
        end: span.end as usize,
    })
}

/// Every occurrence of `definition` in what the open documents' compiles read.
pub fn occurrences(documents: &HashMap<Url, Document>, definition: &Place) -> Option<Occurrences> {
    let mut found: BTreeSet<Place> = BTreeSet::new();
    let mut locations: HashMap<Place, Location> = HashMap::new();
    let mut name = None;
    for (uri, document, analysis, index) in indexed(documents) {
        let mut locator = Locator::new(uri, &analysis.sources, &document.lines);
        let mut add = |locator: &mut Locator<'_>, span: Span| {
            let Some(at) = place(locator, span) else {
                return;
            };
            if !locations.contains_key(&at) {
                if let Some(location) = locator.location(span) {
                    locations.insert(at.clone(), location);
                    found.insert(at);
                }
            }
        };
        for d in &index.definitions {
            if place(&locator, d.span).as_ref() == Some(definition) {
                if name.is_none() {
                    name = analysis
                        .sources
                        .get(d.span.file)
                        .and_then(|file| file.text.get(d.span.range()))
                        .map(str::to_string);
                }
                add(&mut locator, d.span);
            }
        }
        for (from, to) in &index.links {
            if place(&locator, *to).as_ref() == Some(definition) {
                add(&mut locator, *from);
            }
        }
    }
    let places = found
        .into_iter()
        .filter_map(|p| {
            let location = locations.remove(&p)?;
            Some((p, location))
        })
        .collect();
    Some(Occurrences {
        name: name?,
        definition: definition.clone(),
        places,
    })
}

/// `textDocument/references`: the uses of the name at `offset`, with its definition when
/// the client asks for it.
pub fn references(
    documents: &HashMap<Url, Document>,
    uri: &Url,
    offset: usize,
    include_declaration: bool,
) -> Option<Vec<Location>> {
    let document = documents.get(uri)?;
    let definition = target(uri, document, offset)?;
    let found = occurrences(documents, &definition)?;
    Some(
        found
            .places
            .into_iter()
            .filter(|(p, _)| include_declaration || *p != found.definition)
            .map(|(_, location)| location)
            .collect(),
    )
}
