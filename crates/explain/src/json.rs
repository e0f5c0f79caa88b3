//! The JSON form of an explanation (`whitted explain --json`), versioned and documented in
//! docs/explain.md.

use serde::Serialize;

use crate::model::Explanation;

/// The version of the JSON document; bumped on any incompatible change.
pub const EXPLAIN_JSON_VERSION: u32 = 1;

/// `{"version", "pixel", "color", ..., "contributions", "findings"}`: the explanation's own
/// fields, in their order, after the version.
#[derive(Serialize)]
pub struct ExplanationDocument<'a> {
    pub version: u32,
    #[serde(flatten)]
    pub explanation: &'a Explanation,
}

impl Explanation {
    /// The versioned JSON document of this explanation.
    pub fn document(&self) -> ExplanationDocument<'_> {
        ExplanationDocument {
            version: EXPLAIN_JSON_VERSION,
            explanation: self,
        }
    }
}
