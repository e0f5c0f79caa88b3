//! The requests of references, rename and quick fixes (`references`, `prepareRename`,
//! `rename`, `codeAction` and `willRenameFiles`), read and answered apart from `server.rs` so that its
//! dispatch grows by one arm. Strings (objects' names, files) are asked first
//! (`strings.rs`), then the resolver's names (`references.rs`, `rename.rs`).

use std::collections::HashMap;

use lsp_server::{ErrorCode, ResponseError};
use lsp_types::request::{
    CodeActionRequest, PrepareRenameRequest, References, Rename, Request as _, WillRenameFiles,
};
use lsp_types::{TextDocumentPositionParams, Url};
use serde::de::DeserializeOwned;
use serde_json::Value;

use crate::documents::Document;
use crate::Files;

pub fn handles(method: &str) -> bool {
    [
        References::METHOD,
        PrepareRenameRequest::METHOD,
        Rename::METHOD,
        CodeActionRequest::METHOD,
        WillRenameFiles::METHOD,
    ]
    .contains(&method)
}

pub fn request(
    method: &str,
    params: Value,
    documents: &HashMap<Url, Document>,
    files: &mut dyn Files,
) -> Result<Value, ResponseError> {
    match method {
        References::METHOD => {
            let p: lsp_types::ReferenceParams = parse(params)?;
            let (uri, offset) = at(documents, &p.text_document_position);
            let found = offset.and_then(|offset| {
                // An object's name or a file's string; else a name the resolver linked.
                if let Some(found) = crate::strings::references(
                    documents,
                    files,
                    &uri,
                    offset,
                    p.context.include_declaration,
                ) {
                    return Some(found);
                }
                crate::references::references(
                    documents,
                    &uri,
                    offset,
                    p.context.include_declaration,
                )
            });
            to_value(found)
        }
        PrepareRenameRequest::METHOD => {
            let p: TextDocumentPositionParams = parse(params)?;
            let (uri, offset) = at(documents, &p);
            to_value(offset.and_then(|offset| {
                crate::strings::prepare(documents, files, &uri, offset)
                    .unwrap_or_else(|| crate::rename::prepare(documents, &uri, offset))
            }))
        }
        Rename::METHOD => {
            let p: lsp_types::RenameParams = parse(params)?;
            let (uri, offset) = at(documents, &p.text_document_position);
            match offset {
                Some(offset) => {
                    match crate::strings::rename(documents, files, &uri, offset, &p.new_name) {
                        Some(answer) => to_value(answer?),
                        None => to_value(crate::rename::rename(
                            documents,
                            files,
                            &uri,
                            offset,
                            &p.new_name,
                        )?),
                    }
                }
                None => to_value(None::<()>),
            }
        }
        CodeActionRequest::METHOD => {
            let p: lsp_types::CodeActionParams = parse(params)?;
            let uri = p.text_document.uri;
            to_value(
                documents
                    .get(&uri)
                    .map(|d| crate::actions::code_actions(&uri, d, p.range)),
            )
        }
        WillRenameFiles::METHOD => {
            let p: lsp_types::RenameFilesParams = parse(params)?;
            to_value(crate::strings::will_rename(documents, files, &p.files))
        }
        _ => Err(ResponseError {
            code: ErrorCode::MethodNotFound as i32,
            message: format!("whitted lsp does not handle `{method}`"),
            data: None,
        }),
    }
}

/// The document's URI and the byte offset of the position, when the document is open.
fn at(documents: &HashMap<Url, Document>, p: &TextDocumentPositionParams) -> (Url, Option<usize>) {
    let offset = documents
        .get(&p.text_document.uri)
        .map(|d| d.lines.offset(&d.text, p.position));
    (p.text_document.uri.clone(), offset)
}

fn parse<P: DeserializeOwned>(params: Value) -> Result<P, ResponseError> {
    serde_json::from_value(params).map_err(|_| ResponseError {
        code: ErrorCode::InvalidParams as i32,
        message: "the parameters do not read as this request's".to_string(),
        data: None,
    })
}

fn to_value<T: serde::Serialize>(value: T) -> Result<Value, ResponseError> {
    serde_json::to_value(value).map_err(|e| ResponseError {
        code: ErrorCode::InternalError as i32,
        message: e.to_string(),
        data: None,
    })
}
