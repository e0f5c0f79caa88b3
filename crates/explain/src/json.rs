//! The JSON form of an explanation (`whitted explain --json`), versioned and documented in
//! docs/explain.md.

use serde::Serialize;

use crate::model::{Contribution, Explanation, Finding};

/// The version of the JSON document; bumped on any incompatible change.
pub const EXPLAIN_JSON_VERSION: u32 = 1;

/// `{"version", "pixel", "color", ..., "contributions", "findings"}`.
#[derive(Serialize)]
pub struct ExplanationDocument<'a> {
    pub version: u32,
    pub pixel: [u32; 2],
    pub image_size: [u32; 2],
    pub color: [f32; 3],
    pub samples_per_pixel: u32,
    pub max_depth: u32,
    pub min_weight: f32,
    pub unrecorded: u64,
    pub contributions: &'a [Contribution],
    pub findings: &'a [Finding],
}

impl Explanation {
    /// The versioned JSON document of this explanation.
    pub fn document(&self) -> ExplanationDocument<'_> {
        ExplanationDocument {
            version: EXPLAIN_JSON_VERSION,
            pixel: self.pixel,
            image_size: self.image_size,
            color: self.color,
            samples_per_pixel: self.samples_per_pixel,
            max_depth: self.max_depth,
            min_weight: self.min_weight,
            unrecorded: self.unrecorded,
            contributions: &self.contributions,
            findings: &self.findings,
        }
    }
}
