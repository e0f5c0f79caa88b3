//! One document through its front end: the scene language's compiler (with the editor's
//! index) or, for a 6.837 `.txt` scene, whitted-mit6837's converter; and the compiler's
//! diagnostics as the protocol's, per file.

use std::collections::HashMap;
use std::path::Path;

use lsp_types::{
    Diagnostic as LspDiagnostic, DiagnosticRelatedInformation, DiagnosticSeverity, Location, Range,
    Url,
};
use whitted_ir::{Diagnostic, FileId, Severity, SourceMap, Span};
use whitted_lang::editor::Index;

use crate::documents::Document;
use crate::loader::Overlay;
use crate::position::LineIndex;

/// What compiling a document's text found.
pub struct Analysis {
    /// Every file the compilation read; spans point into these (file 0 is the document).
    pub sources: SourceMap,
    /// The editor's index, when every file parsed.
    pub index: Option<Index>,
    /// The diagnostics for each file, the document's first (even when it has none).
    pub diagnostics: Vec<(Url, Vec<LspDiagnostic>)>,
    /// Each loop that made objects, with how many (`inlays.rs`), when the scene compiled.
    pub loops: Vec<(Span, usize)>,
    /// The quick fixes the diagnostics offer (`actions.rs`).
    pub fixes: Vec<crate::actions::Fix>,
    /// The compiled scene's materials with where each was defined, for hover's pictures.
    pub materials: Option<whitted_ir::Arena<whitted_ir::Material>>,
}

/// Whether the document is a 6.837 scene: named `.txt`, or starting with one of the
/// format's words (as the binary decides).
fn is_course_scene(document: &Document) -> bool {
    let txt = document
        .path
        .as_deref()
        .and_then(Path::extension)
        .is_some_and(|e| e.eq_ignore_ascii_case("txt"));
    txt || whitted_mit6837::is_mit6837(document.text.as_bytes())
}

pub fn analyze(uri: &Url, document: &Document, mut overlay: Overlay<'_>) -> Analysis {
    let name = document.name(uri);
    let mut loops = Vec::new();
    let mut materials = None;
    let (sources, index, diagnostics) = if is_course_scene(document) {
        let conversion = whitted_mit6837::convert(
            Path::new(&name),
            document.text.clone().into_bytes(),
            &mut overlay,
            &whitted_mit6837::CourseOptions::default(),
        );
        (conversion.sources, None, conversion.diagnostics)
    } else {
        let options = whitted_lang::CompileOptions {
            index: true,
            ..Default::default()
        };
        let compilation =
            whitted_lang::compile_source(&name, &document.text, &mut overlay, &options);
        if let Some(scene) = &compilation.scene {
            loops = crate::inlays::loop_counts(scene);
            materials = Some(scene.materials.clone());
        }
        (
            compilation.sources,
            compilation.index,
            compilation.diagnostics,
        )
    };
    let fixes = crate::actions::fixes(
        &mut Locator::new(uri, &sources, &document.lines),
        &sources,
        &diagnostics,
    );
    let mut diagnostics = convert_all(Locator::new(uri, &sources, &document.lines), &diagnostics);
    summarize_imports(uri, document, &name, &mut diagnostics);
    Analysis {
        sources,
        index,
        diagnostics,
        loops,
        fixes,
        materials,
    }
}

/// Turns spans into locations, caching each file's line index.
pub struct Locator<'a> {
    pub root: &'a Url,
    pub sources: &'a SourceMap,
    lines: HashMap<FileId, LineIndex>,
}

impl<'a> Locator<'a> {
    /// `root_lines` is the document's line index, already made (file 0 is the document's
    /// text), so that a big document is not indexed again for each answer.
    pub fn new(root: &'a Url, sources: &'a SourceMap, root_lines: &LineIndex) -> Self {
        Locator {
            root,
            sources,
            lines: HashMap::from([(FileId(0), root_lines.clone())]),
        }
    }

    /// The URI of a file of the compilation: the document for file 0, a `file:` URI for an
    /// import; none for the command line's pseudo-files.
    pub fn uri(&self, file: FileId) -> Option<Url> {
        if file.0 == 0 {
            return Some(self.root.clone());
        }
        let source = self.sources.get(file)?;
        Url::from_file_path(&source.path).ok()
    }

    pub fn location(&mut self, span: Span) -> Option<Location> {
        let uri = self.uri(span.file)?;
        let source = self.sources.get(span.file)?;
        let lines = self
            .lines
            .entry(span.file)
            .or_insert_with(|| LineIndex::new(&source.text));
        Some(Location::new(uri, lines.range(&source.text, span.range())))
    }
}

fn convert_all(
    mut locator: Locator<'_>,
    diagnostics: &[Diagnostic],
) -> Vec<(Url, Vec<LspDiagnostic>)> {
    let root = locator.root;
    let mut by_file: Vec<(Url, Vec<LspDiagnostic>)> = vec![(root.clone(), Vec::new())];
    for diagnostic in diagnostics {
        // A diagnostic without a place (or in a file that is not one) is shown at the
        // document's start, where it cannot be missed.
        let location = diagnostic
            .span
            .and_then(|span| locator.location(span))
            .unwrap_or_else(|| Location::new(root.clone(), Range::default()));
        let related: Vec<DiagnosticRelatedInformation> = diagnostic
            .secondary
            .iter()
            .filter_map(|label| {
                Some(DiagnosticRelatedInformation {
                    location: locator.location(label.span)?,
                    message: label.message.clone(),
                })
            })
            .collect();
        let converted = LspDiagnostic {
            range: location.range,
            severity: Some(match diagnostic.severity {
                Severity::Error => DiagnosticSeverity::ERROR,
                Severity::Warning => DiagnosticSeverity::WARNING,
                Severity::Note => DiagnosticSeverity::INFORMATION,
            }),
            source: Some("whitted".to_string()),
            message: message(diagnostic),
            related_information: (!related.is_empty()).then_some(related),
            ..LspDiagnostic::default()
        };
        match by_file.iter_mut().find(|(uri, _)| *uri == location.uri) {
            Some((_, list)) => list.push(converted),
            None => by_file.push((location.uri, vec![converted])),
        }
    }
    by_file
}

/// The message as the terminal shows it, minus the drawing: the message, the label under
/// the underline, and each hint as a `help:` line.
pub(crate) fn message(diagnostic: &Diagnostic) -> String {
    let mut text = diagnostic.message.clone();
    if let Some(label) = &diagnostic.label {
        text.push_str(&format!(" ({label})"));
    }
    for hint in &diagnostic.hints {
        text.push_str(&format!("\nhelp: {hint}"));
    }
    text
}

/// An error in a file the document imports is reported in that file; the document gets one
/// error on its `import` line too, saying so and pointing there, so that a user looking at
/// the document sees why it does not compile.
fn summarize_imports(
    root: &Url,
    document: &Document,
    name: &str,
    by_file: &mut [(Url, Vec<LspDiagnostic>)],
) {
    let errors_elsewhere = by_file.iter().any(|(file, diagnostics)| {
        file != root
            && diagnostics
                .iter()
                .any(|d| d.severity == Some(DiagnosticSeverity::ERROR))
    });
    if !errors_elsewhere {
        // Reading the document's imports lexes all of it (a tenth of a big scene's
        // keystroke-to-diagnostics): only when there is an error to point to.
        return;
    }
    let imports = whitted_lang::editor::cursor::imports(&document.text);
    let mut summaries = Vec::new();
    for (file, diagnostics) in by_file.iter().filter(|(file, _)| file != root) {
        let errors: Vec<&LspDiagnostic> = diagnostics
            .iter()
            .filter(|d| d.severity == Some(DiagnosticSeverity::ERROR))
            .collect();
        let Some(first) = errors.first() else {
            continue;
        };
        let statement = imports.iter().find(|(written, _)| {
            let target = whitted_lang::editor::import_target(Path::new(name), written);
            Url::from_file_path(target).is_ok_and(|target| target == *file)
        });
        let Some((written, span)) = statement else {
            continue;
        };
        let count = match errors.len() {
            1 => "an error".to_string(),
            n => format!("{n} errors"),
        };
        let headline = first.message.lines().next().unwrap_or_default();
        summaries.push(LspDiagnostic {
            range: document.lines.range(&document.text, span.clone()),
            severity: Some(DiagnosticSeverity::ERROR),
            source: Some("whitted".to_string()),
            message: format!("`{written}` has {count}: {headline}"),
            related_information: Some(vec![DiagnosticRelatedInformation {
                location: Location::new(file.clone(), first.range),
                message: first.message.clone(),
            }]),
            ..LspDiagnostic::default()
        });
    }
    if let Some((_, own)) = by_file.iter_mut().find(|(file, _)| file == root) {
        own.extend(summaries);
    }
}
