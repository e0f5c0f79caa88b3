//! whitted-explain: why a pixel has its colour, in words.
//!
//! [`explain`] records the pixel's ray tree through the tracer's one code path
//! (`whitted_tracer::ray_tree::trace_pixel`) and analyses it with the IR: the colour split
//! into the light paths that make it ([`contributions`]), and findings that name a likely
//! cause with the scene line concerned and a fix ([`findings`]). Where a finding needs to
//! know what another setting would do (the `max_depth` that reaches the light), it traces
//! the pixel again through the same code path with a recorder of its own ([`probe`]); it
//! never traces by itself. The library prints nothing: [`format_text`] and
//! [`Explanation::document`] are for the binary to show.

pub mod contributions;
pub mod diff;
pub mod findings;
pub mod grade;
mod inside;
mod json;
pub mod lint;
mod locate;
mod model;
mod numbers;
pub mod probe;
pub mod query;
pub mod regions;
pub mod student;
mod text;

pub use json::{ExplanationDocument, EXPLAIN_JSON_VERSION};
pub use model::{Contribution, Explanation, Finding, FindingKind, Step, Term};
pub use text::{describe_term, format_summary, format_text};

use std::sync::atomic::AtomicBool;

use whitted_ir::Scene;
use whitted_tracer::ray_tree::{
    trace_pixel_request, RayTree, SampleChoice, TraceError, TraceRequest,
};
use whitted_tracer::{PreparedScene, RenderOptions};

/// Explains pixel `(x, y)`: records its ray tree (every sample) and analyses it.
/// `scene` must be the scene `prepared` was made from (names, locations and materials
/// come from it).
pub fn explain(
    prepared: &PreparedScene,
    scene: &Scene,
    options: &RenderOptions,
    x: u32,
    y: u32,
) -> Result<Explanation, TraceError> {
    let request = ExplainRequest {
        x,
        y,
        node_budget: whitted_ir::limits::MAX_RAY_TREE_NODES,
        cancel: None,
    };
    explain_request(prepared, scene, options, &request)
}

/// One pixel to explain, with the ray tree's node budget and an optional cancel flag.
#[derive(Clone, Copy, Debug)]
pub struct ExplainRequest<'c> {
    pub x: u32,
    pub y: u32,
    /// The most nodes the ray tree may hold; past it the light of the rays not kept is one
    /// `unrecorded` contribution.
    pub node_budget: usize,
    /// When set (from another thread) the trace stops soon and returns `Cancelled`.
    pub cancel: Option<&'c AtomicBool>,
}

/// [`explain`] with a node budget and a cancel flag (the debugger records trees off its UI
/// thread and cancels them). Every sample is recorded, so that the paths sum to the pixel.
pub fn explain_request(
    prepared: &PreparedScene,
    scene: &Scene,
    options: &RenderOptions,
    request: &ExplainRequest<'_>,
) -> Result<Explanation, TraceError> {
    let trace_request = TraceRequest {
        x: request.x,
        y: request.y,
        which: SampleChoice::All,
        node_budget: request.node_budget,
        cancel: request.cancel,
    };
    let tree = trace_pixel_request(prepared, scene, options, &trace_request)?;
    Ok(explain_tree(prepared, scene, options, &tree))
}

/// Explains a ray tree already recorded (the debugger's picked pixel), so that the
/// explanation is of exactly the rays shown beside it. `tree` must have been traced from
/// `prepared` with `options`, recording every sample (`SampleChoice::All`), for the
/// contributions to sum to the pixel.
pub fn explain_tree(
    prepared: &PreparedScene,
    scene: &Scene,
    options: &RenderOptions,
    tree: &RayTree,
) -> Explanation {
    let contributions = contributions::decompose(tree);
    let context = findings::Context {
        prepared,
        scene,
        options,
        tree,
        contributions: &contributions,
    };
    let findings = findings::find(&context);
    Explanation {
        pixel: tree.pixel,
        image_size: tree.image_size,
        color: tree.color,
        samples_per_pixel: tree.samples_per_pixel,
        max_depth: tree.max_depth,
        min_weight: tree.min_weight,
        unrecorded: tree.unrecorded,
        contributions,
        findings,
    }
}
