//! The requests about how a document looks rather than what a name means: semantic tokens
//! (`tokens.rs`), folding ranges (`folding.rs`), colours and their presentations
//! (`colors.rs`) and inlay hints (`inlays.rs`), dispatched from [`Server`]'s request.
//!
//! [`Server`]: crate::Server

use std::collections::HashMap;

use lsp_server::ResponseError;
use lsp_types::request::{
    ColorPresentationRequest, DocumentColor, FoldingRangeRequest, InlayHintRequest, Request as _,
    SemanticTokensFullDeltaRequest, SemanticTokensFullRequest, SemanticTokensRangeRequest,
};
use lsp_types::{SemanticTokensRangeResult, SemanticTokensResult, Url};
use serde_json::Value;

use crate::documents::Document;
use crate::server::{invalid_params, parse, to_value};

/// The methods answered here.
pub const METHODS: [&str; 7] = [
    SemanticTokensFullRequest::METHOD,
    SemanticTokensFullDeltaRequest::METHOD,
    SemanticTokensRangeRequest::METHOD,
    FoldingRangeRequest::METHOD,
    DocumentColor::METHOD,
    ColorPresentationRequest::METHOD,
    InlayHintRequest::METHOD,
];

/// The answer to one of [`METHODS`]. A document that is not open gets an empty answer.
pub fn answer(
    documents: &HashMap<Url, Document>,
    method: &str,
    params: Value,
) -> Result<Value, ResponseError> {
    match method {
        SemanticTokensFullRequest::METHOD => {
            let p = parse::<lsp_types::SemanticTokensParams>(params).ok_or_else(invalid_params)?;
            to_value(
                documents
                    .get(&p.text_document.uri)
                    .map(|d| SemanticTokensResult::Tokens(crate::tokens::tokens_sent(d))),
            )
        }
        SemanticTokensFullDeltaRequest::METHOD => {
            let p =
                parse::<lsp_types::SemanticTokensDeltaParams>(params).ok_or_else(invalid_params)?;
            to_value(
                documents
                    .get(&p.text_document.uri)
                    .map(|d| crate::tokens::tokens_delta(d, &p.previous_result_id)),
            )
        }
        SemanticTokensRangeRequest::METHOD => {
            let p =
                parse::<lsp_types::SemanticTokensRangeParams>(params).ok_or_else(invalid_params)?;
            to_value(documents.get(&p.text_document.uri).map(|d| {
                let start = d.lines.offset(&d.text, p.range.start);
                let end = d.lines.offset(&d.text, p.range.end).max(start);
                SemanticTokensRangeResult::Tokens(crate::tokens::tokens_in(d, start..end))
            }))
        }
        FoldingRangeRequest::METHOD => {
            let p = parse::<lsp_types::FoldingRangeParams>(params).ok_or_else(invalid_params)?;
            to_value(
                documents
                    .get(&p.text_document.uri)
                    .map(crate::folding::folding_ranges),
            )
        }
        DocumentColor::METHOD => {
            let p = parse::<lsp_types::DocumentColorParams>(params).ok_or_else(invalid_params)?;
            to_value(
                documents
                    .get(&p.text_document.uri)
                    .map(crate::colors::colors)
                    .unwrap_or_default(),
            )
        }
        ColorPresentationRequest::METHOD => {
            let p =
                parse::<lsp_types::ColorPresentationParams>(params).ok_or_else(invalid_params)?;
            to_value(crate::colors::presentations(p.color, p.range))
        }
        _ => {
            let p = parse::<lsp_types::InlayHintParams>(params).ok_or_else(invalid_params)?;
            to_value(
                documents
                    .get(&p.text_document.uri)
                    .map(|d| crate::inlays::hints(d, p.range)),
            )
        }
    }
}
