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
pub mod findings;
mod inside;
mod json;
mod locate;
mod model;
pub mod probe;
mod text;

pub use json::{ExplanationDocument, EXPLAIN_JSON_VERSION};
pub use model::{Contribution, Explanation, Finding, FindingKind, Step, Term};
pub use text::format_text;

use whitted_ir::Scene;
use whitted_tracer::ray_tree::{trace_pixel, SampleChoice, TraceError};
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
    let tree = trace_pixel(prepared, scene, options, x, y, SampleChoice::All)?;
    let contributions = contributions::decompose(&tree);
    let context = findings::Context {
        prepared,
        scene,
        options,
        tree: &tree,
        contributions: &contributions,
    };
    let findings = findings::find(&context);
    Ok(Explanation {
        pixel: tree.pixel,
        image_size: tree.image_size,
        color: tree.color,
        samples_per_pixel: tree.samples_per_pixel,
        max_depth: tree.max_depth,
        min_weight: tree.min_weight,
        unrecorded: tree.unrecorded,
        contributions,
        findings,
    })
}
