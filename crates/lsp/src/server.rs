//! The server's state and what each message does to it, apart from any transport: the
//! stdio loop (`run.rs`) and the tests drive the same [`Server`].
//!
//! Edits only mark a document as changed; analysis (a full compile) runs when the server
//! has read every message already waiting, or before a request that needs it, so a burst
//! of keystrokes is compiled once, at its last version.

use std::collections::HashMap;

use lsp_server::{ErrorCode, Notification, ResponseError};
use lsp_types::notification::{
    DidChangeTextDocument, DidCloseTextDocument, DidOpenTextDocument, Notification as _,
    PublishDiagnostics,
};
use lsp_types::request::{
    Completion, DocumentSymbolRequest, Formatting, GotoDefinition, HoverRequest, Request as _,
};
use lsp_types::{
    CompletionOptions, CompletionResponse, DocumentSymbolResponse, GotoDefinitionResponse,
    HoverProviderCapability, OneOf, PublishDiagnosticsParams, ServerCapabilities,
    TextDocumentPositionParams, TextDocumentSyncCapability, TextDocumentSyncKind, Url,
};
use serde::de::DeserializeOwned;
use serde_json::Value;

use crate::documents::Document;
use crate::loader::Overlay;
use crate::Files;

/// What the server can do; every capability here is implemented below.
pub fn capabilities() -> ServerCapabilities {
    ServerCapabilities {
        text_document_sync: Some(TextDocumentSyncCapability::Kind(
            TextDocumentSyncKind::INCREMENTAL,
        )),
        hover_provider: Some(HoverProviderCapability::Simple(true)),
        completion_provider: Some(CompletionOptions::default()),
        definition_provider: Some(OneOf::Left(true)),
        document_symbol_provider: Some(OneOf::Left(true)),
        document_formatting_provider: Some(OneOf::Left(true)),
        // The view features (`view.rs`).
        semantic_tokens_provider: Some(crate::tokens::options().into()),
        folding_range_provider: Some(lsp_types::FoldingRangeProviderCapability::Simple(true)),
        color_provider: Some(lsp_types::ColorProviderCapability::Simple(true)),
        inlay_hint_provider: Some(OneOf::Left(true)),
        references_provider: Some(OneOf::Left(true)),
        rename_provider: Some(OneOf::Right(lsp_types::RenameOptions {
            prepare_provider: Some(true),
            work_done_progress_options: Default::default(),
        })),
        // Moving a file or folder rewrites the `import` and `file` strings naming it.
        workspace: Some(lsp_types::WorkspaceServerCapabilities {
            workspace_folders: None,
            file_operations: Some(lsp_types::WorkspaceFileOperationsServerCapabilities {
                will_rename: Some(lsp_types::FileOperationRegistrationOptions {
                    filters: vec![lsp_types::FileOperationFilter {
                        scheme: Some("file".to_string()),
                        pattern: lsp_types::FileOperationPattern {
                            glob: "**/*".to_string(),
                            matches: None,
                            options: None,
                        },
                    }],
                }),
                ..Default::default()
            }),
        }),
        code_action_provider: Some(lsp_types::CodeActionProviderCapability::Options(
            lsp_types::CodeActionOptions {
                code_action_kinds: Some(vec![lsp_types::CodeActionKind::QUICKFIX]),
                ..Default::default()
            },
        )),
        ..ServerCapabilities::default()
    }
}

pub struct Server {
    files: Box<dyn Files>,
    documents: HashMap<Url, Document>,
    /// For each analysed document, the other files it published diagnostics to (its
    /// imports), so that they are cleared when they have none any more.
    published: HashMap<Url, Vec<Url>>,
    /// Pictures of materials for hover, when the runner gives a renderer.
    thumbnails: Option<Box<dyn crate::Thumbnails>>,
}

impl Server {
    pub fn new(files: Box<dyn Files>) -> Self {
        Server {
            files,
            documents: HashMap::new(),
            published: HashMap::new(),
            thumbnails: None,
        }
    }

    /// Material hovers show a picture made by `thumbnails`.
    pub fn set_thumbnails(&mut self, thumbnails: Box<dyn crate::Thumbnails>) {
        self.thumbnails = Some(thumbnails);
    }

    /// A notification from the client. Unknown ones are ignored, as the protocol asks;
    /// ones whose parameters do not read are ignored too (a notification has no answer).
    pub fn notify(&mut self, method: &str, params: Value) -> Vec<Notification> {
        match method {
            DidOpenTextDocument::METHOD => {
                if let Some(p) = parse::<lsp_types::DidOpenTextDocumentParams>(params) {
                    let uri = p.text_document.uri;
                    let mut document =
                        Document::new(&uri, p.text_document.text, p.text_document.version);
                    document.identity = document.path.as_deref().map(|p| self.files.identify(p));
                    self.documents.insert(uri.clone(), document);
                    self.importers_changed(&uri);
                }
            }
            DidChangeTextDocument::METHOD => {
                if let Some(p) = parse::<lsp_types::DidChangeTextDocumentParams>(params) {
                    if let Some(document) = self.documents.get_mut(&p.text_document.uri) {
                        for change in p.content_changes {
                            document.apply(change);
                        }
                        document.version = p.text_document.version;
                        // A new version gets its diagnostics, even when nothing changed.
                        document.analysis = None;
                    }
                    self.importers_changed(&p.text_document.uri);
                }
            }
            DidCloseTextDocument::METHOD => {
                if let Some(p) = parse::<lsp_types::DidCloseTextDocumentParams>(params) {
                    let uri = p.text_document.uri;
                    self.documents.remove(&uri);
                    // Its diagnostics go with it.
                    let mut cleared = self.published.remove(&uri).unwrap_or_default();
                    cleared.push(uri);
                    return cleared
                        .into_iter()
                        .map(|uri| publish(uri, Vec::new(), None))
                        .collect();
                }
            }
            _ => {}
        }
        Vec::new()
    }

    /// Marks for analysis the open documents whose last compile read the document `uri`
    /// (they import it), so that their diagnostics follow its unsaved text.
    fn importers_changed(&mut self, uri: &Url) {
        let Some(path) = self.documents.get(uri).and_then(|d| d.path.clone()) else {
            return;
        };
        let path = path.to_string_lossy();
        for (other, document) in &mut self.documents {
            let imports = document.analysis.as_ref().is_some_and(|analysis| {
                analysis
                    .sources
                    .files()
                    .skip(1)
                    .any(|(_, file)| file.path == path)
            });
            if other != uri && imports {
                document.analysis = None;
            }
        }
    }

    /// Analyses every document changed since its last analysis and returns the
    /// diagnostics to publish.
    pub fn analyze_changed(&mut self) -> Vec<Notification> {
        let stale: Vec<Url> = self
            .documents
            .iter()
            .filter(|(_, d)| d.analysis.is_none())
            .map(|(uri, _)| uri.clone())
            .collect();
        let mut out = Vec::new();
        for uri in stale {
            out.extend(self.analyze(&uri));
        }
        out
    }

    fn analyze(&mut self, uri: &Url) -> Vec<Notification> {
        let Some(document) = self.documents.get(uri) else {
            return Vec::new();
        };
        let overlay = Overlay {
            documents: &self.documents,
            files: self.files.as_mut(),
        };
        let analysis = crate::analysis::analyze(uri, document, overlay);
        let version = document.version;
        let mut out = Vec::new();
        let mut others = Vec::new();
        for (file, diagnostics) in &analysis.diagnostics {
            let own = file == uri;
            if !own && self.documents.contains_key(file) {
                // An open file's diagnostics are its own compile's: an importer's view of
                // it (where its materials are used, say) would flicker with them.
                continue;
            }
            if !own {
                others.push(file.clone());
            }
            out.push(publish(
                file.clone(),
                diagnostics.clone(),
                own.then_some(version),
            ));
        }
        for gone in self.published.remove(uri).unwrap_or_default() {
            if !others.contains(&gone) && !self.documents.contains_key(&gone) {
                out.push(publish(gone, Vec::new(), None));
            }
        }
        self.published.insert(uri.clone(), others);
        if let Some(document) = self.documents.get_mut(uri) {
            document.analysis = Some(analysis);
        }
        out
    }

    /// A request from the client: its result, or an error for a method this server does
    /// not have or parameters that do not read. Diagnostics of documents analysed on the
    /// way are returned with it, to be sent first.
    pub fn request(
        &mut self,
        method: &str,
        params: Value,
    ) -> (Result<Value, ResponseError>, Vec<Notification>) {
        let published = self.analyze_changed();
        let result = match method {
            HoverRequest::METHOD => {
                let thumbnails = self.thumbnails.as_deref();
                self.at::<lsp_types::HoverParams>(params, |p| p.text_document_position_params)
                    .map(|found| {
                        found.and_then(|(document, _, offset)| {
                            let mut hover = crate::hover::hover(document, offset)?;
                            if let Some(picture) = thumbnails
                                .and_then(|t| crate::names::material_picture(document, offset, t))
                            {
                                if let lsp_types::HoverContents::Markup(markup) =
                                    &mut hover.contents
                                {
                                    markup.value.push_str(&format!(
                                        "\n\n![the material on a ball]({picture})"
                                    ));
                                }
                            }
                            Some(hover)
                        })
                    })
                    .and_then(to_value)
            }
            Completion::METHOD => self
                .at::<lsp_types::CompletionParams>(params, |p| p.text_document_position)
                .map(|found| {
                    found.map(|(document, _, offset)| {
                        CompletionResponse::Array(crate::completion::complete(document, offset))
                    })
                })
                .and_then(to_value),
            GotoDefinition::METHOD => self
                .at::<lsp_types::GotoDefinitionParams>(params, |p| p.text_document_position_params)
                .map(|found| {
                    found.and_then(|(document, uri, offset)| {
                        crate::navigation::definition(uri, document, offset)
                            .or_else(|| crate::strings::definition(uri, document, offset))
                            .map(GotoDefinitionResponse::Scalar)
                    })
                })
                .and_then(to_value),
            DocumentSymbolRequest::METHOD => {
                match parse::<lsp_types::DocumentSymbolParams>(params) {
                    Some(p) => to_value(
                        self.documents
                            .get(&p.text_document.uri)
                            .map(|d| DocumentSymbolResponse::Nested(crate::navigation::symbols(d))),
                    ),
                    None => Err(invalid_params()),
                }
            }
            m if crate::server_nav::handles(m) => {
                crate::server_nav::request(m, params, &self.documents, self.files.as_mut())
            }
            Formatting::METHOD => match parse::<lsp_types::DocumentFormattingParams>(params) {
                Some(p) => to_value(self.documents.get(&p.text_document.uri).and_then(format)),
                None => Err(invalid_params()),
            },
            method if crate::view::METHODS.contains(&method) => {
                crate::view::answer(&self.documents, method, params)
            }
            _ => Err(ResponseError {
                code: ErrorCode::MethodNotFound as i32,
                message: format!("whitted lsp does not handle `{method}`"),
                data: None,
            }),
        };
        (result, published)
    }

    /// The document and byte offset a positional request is about. A document that is not
    /// open is not an error: its answer is empty (`None` inside `Ok`).
    #[allow(clippy::type_complexity)]
    fn at<P: DeserializeOwned>(
        &self,
        params: Value,
        position: impl FnOnce(P) -> TextDocumentPositionParams,
    ) -> Result<Option<(&Document, &Url, usize)>, ResponseError> {
        let p = position(parse::<P>(params).ok_or_else(invalid_params)?);
        Ok(self
            .documents
            .get_key_value(&p.text_document.uri)
            .map(|(uri, document)| {
                let offset = document.lines.offset(&document.text, p.position);
                (document, uri, offset)
            }))
    }
}

/// `whitted fmt` on the document as the editor has it: one edit replacing the whole text
/// (none when it is formatted already). A document that does not parse, or a 6.837 scene
/// (the formatter knows only the scene language), gets no answer: its diagnostics say why.
fn format(document: &Document) -> Option<Vec<lsp_types::TextEdit>> {
    if whitted_mit6837::is_mit6837(document.text.as_bytes()) {
        return None;
    }
    let name = document
        .path
        .as_ref()
        .map_or("document.scene".to_string(), |p| p.display().to_string());
    let formatted = whitted_lang::format_source(&name, &document.text).ok()?;
    if formatted == document.text {
        return Some(Vec::new());
    }
    let whole = document.lines.range(&document.text, 0..document.text.len());
    Some(vec![lsp_types::TextEdit {
        range: whole,
        new_text: formatted,
    }])
}

pub(crate) fn to_value<T: serde::Serialize>(value: T) -> Result<Value, ResponseError> {
    serde_json::to_value(value).map_err(|e| ResponseError {
        code: ErrorCode::InternalError as i32,
        message: e.to_string(),
        data: None,
    })
}

pub(crate) fn parse<P: DeserializeOwned>(params: Value) -> Option<P> {
    serde_json::from_value(params).ok()
}

pub(crate) fn invalid_params() -> ResponseError {
    ResponseError {
        code: ErrorCode::InvalidParams as i32,
        message: "the parameters do not read as this request's".to_string(),
        data: None,
    }
}

fn publish(
    uri: Url,
    diagnostics: Vec<lsp_types::Diagnostic>,
    version: Option<i32>,
) -> Notification {
    Notification::new(
        PublishDiagnostics::METHOD.to_string(),
        PublishDiagnosticsParams {
            uri,
            diagnostics,
            version,
        },
    )
}
