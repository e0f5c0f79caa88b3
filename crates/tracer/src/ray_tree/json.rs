//! The versioned JSON document of a ray tree (`docs/ray-tree.md`): a serde view of
//! [`RayTree`] with `version` and `root` at the top. The library does not depend on a JSON
//! crate; callers serialise the document with serde_json.

use serde::Serialize;

use super::model::{RayNode, RayTree, SampleTree, ShadingModel, RAY_TREE_JSON_VERSION};

/// What `whitted trace --json` prints: `version`, the pixel, its colour, `root` (the first
/// recorded sample's camera ray) and every recorded sample.
#[derive(Clone, Debug, Serialize)]
pub struct RayTreeDocument<'a> {
    pub version: u32,
    pub pixel: [u32; 2],
    pub image_size: [u32; 2],
    pub color: [f32; 3],
    pub samples_per_pixel: u32,
    pub max_depth: u32,
    pub min_weight: f32,
    pub model: ShadingModel,
    pub node_budget: usize,
    pub unrecorded: u64,
    /// The index of the sample `root` belongs to.
    pub root_sample: Option<u32>,
    pub root: Option<&'a RayNode>,
    pub samples: &'a [SampleTree],
}

impl RayTree {
    /// The JSON view of this tree.
    pub fn document(&self) -> RayTreeDocument<'_> {
        let first = self.samples.first();
        RayTreeDocument {
            version: RAY_TREE_JSON_VERSION,
            pixel: self.pixel,
            image_size: self.image_size,
            color: self.color,
            samples_per_pixel: self.samples_per_pixel,
            max_depth: self.max_depth,
            min_weight: self.min_weight,
            model: self.model,
            node_budget: self.node_budget,
            unrecorded: self.unrecorded,
            root_sample: first.map(|s| s.index),
            root: first.map(|s| &s.root),
            samples: &self.samples,
        }
    }
}
