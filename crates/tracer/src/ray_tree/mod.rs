//! Ray trees: every ray behind one pixel, with its numbers, recorded from the renderer's own
//! code path. [`trace_pixel`] records a pixel; [`format_text`] prints it for people and
//! [`RayTree::document`] is its versioned JSON form (`docs/ray-tree.md`).

mod json;
mod model;
mod pixel;
mod scene_refs;
mod text;
mod tree_recorder;

#[cfg(test)]
mod tests;

pub use json::RayTreeDocument;
pub use model::{
    BlendInfo, Blocker, CoincidentInfo, ConeInfo, HitInfo, InterfaceInfo, LightContribution,
    LightRef, LocalIllumination, MaterialRef, ObjectRef, RayNode, RayTree, SampleChoice,
    SampleTree, ShadingModel, ShadowInfo, ShadowOutcome, SkippedInfo, StackArg, StackStep,
    Visibility, RAY_TREE_JSON_VERSION,
};
pub use pixel::{check_request, trace_pixel, trace_pixel_request, TraceError, TraceRequest};
pub use text::{format_text, TextOptions};
pub use tree_recorder::TreeRecorder;
