//! Findings: likely causes of a pixel's colour, read off its recorded ray tree with the IR,
//! each with the scene line concerned and a suggested fix. One module per family:
//! `depth.rs` (the depth limit, the weight cut-off, total internal reflection), `lights.rs`
//! (lights behind the surface, blocked shadow rays, lights inside solids), `surfaces.rs`
//! (self-hits, coincident surfaces) and `media.rs` (absorption, the background through
//! glass).

mod depth;
mod lights;
mod media;
pub(crate) mod surfaces;

pub use surfaces::is_self_hit;

use whitted_ir::{Handle, Material, Object, Scene};
use whitted_tracer::ray_tree::{RayNode, RayTree};
use whitted_tracer::{PreparedScene, RenderOptions};

use crate::model::{Contribution, Finding};
use crate::probe::largest;

/// A path weight (largest channel) at or above which a ray matters to the pixel: a finding
/// about a lighter ray would explain less than a twentieth of the pixel.
pub const SIGNIFICANT: f32 = 0.05;

/// At most this many findings of one kind, the heaviest: a trapped ray bounces many times.
pub const MAX_PER_KIND: usize = 3;

/// What the findings are read from.
pub struct Context<'a> {
    pub prepared: &'a PreparedScene,
    pub scene: &'a Scene,
    pub options: &'a RenderOptions,
    pub tree: &'a RayTree,
    pub contributions: &'a [Contribution],
}

/// Every finding, heaviest first (kinds in a fixed order among equals).
pub fn find(context: &Context<'_>) -> Vec<Finding> {
    let mut findings = Vec::new();
    depth::find(context, &mut findings);
    lights::find(context, &mut findings);
    surfaces::find(context, &mut findings);
    media::find(context, &mut findings);
    findings.sort_by(|a, b| {
        b.weight
            .total_cmp(&a.weight)
            .then_with(|| a.kind.cmp(&b.kind))
            .then_with(|| a.location.cmp(&b.location))
    });
    let mut per_kind = std::collections::BTreeMap::new();
    findings.retain(|f| {
        let count = per_kind.entry(f.kind).or_insert(0usize);
        *count += 1;
        *count <= MAX_PER_KIND
    });
    for finding in &mut findings {
        finding.source_line = source_line(context.scene, &finding.location);
    }
    findings
}

/// The text of the line a `path:line:col` location points at, when it is in the sources.
pub(crate) fn source_line(scene: &Scene, location: &str) -> Option<String> {
    let mut parts = location.rsplitn(3, ':');
    let _column = parts.next()?;
    let line: u32 = parts.next()?.parse().ok()?;
    let path = parts.next()?;
    let (_, file) = scene.sources.files().find(|(_, f)| f.path == path)?;
    let text = file.line_text(line).trim();
    (!text.is_empty()).then(|| text.to_string())
}

/// Calls `f` on every ray of every sample with the rays above it (the camera ray first).
pub(crate) fn walk<'t>(tree: &'t RayTree, f: &mut dyn FnMut(&'t RayNode, &[&'t RayNode])) {
    fn go<'t>(
        node: &'t RayNode,
        above: &mut Vec<&'t RayNode>,
        f: &mut dyn FnMut(&'t RayNode, &[&'t RayNode]),
    ) {
        f(node, above);
        above.push(node);
        for child in &node.children {
            go(child, above, f);
        }
        above.pop();
    }
    for sample in &tree.samples {
        go(&sample.root, &mut Vec::new(), f);
    }
}

/// The largest channel of a ray's path weight.
pub(crate) fn weight_of(node: &RayNode) -> f32 {
    largest(node.weight)
}

/// The IR material of an object (its own; a CSG leaf's for a leaf).
pub(crate) fn material_of(scene: &Scene, handle: u32) -> Option<(&Material, Handle<Material>)> {
    let object = scene
        .objects
        .get(Handle::<Object>::from_index(handle as usize))?;
    let material = scene.materials.get(object.material)?;
    Some((material, object.material))
}

/// `file:line:col` of a material.
pub(crate) fn material_location(scene: &Scene, handle: Handle<Material>) -> String {
    scene.sources.location(scene.materials.span(handle))
}

/// A colour for messages: `rgb(0.1, 0.2, 0.3)` with three decimals.
pub(crate) fn rgb(c: [f32; 3]) -> String {
    format!("rgb({:.3}, {:.3}, {:.3})", c[0], c[1], c[2])
}

/// Keeps the heaviest finding among those with the same kind and location.
pub(crate) fn push_unique(findings: &mut Vec<Finding>, finding: Finding) {
    match findings
        .iter_mut()
        .find(|f| f.kind == finding.kind && f.location == finding.location)
    {
        Some(existing) if existing.weight >= finding.weight => {}
        Some(existing) => *existing = finding,
        None => findings.push(finding),
    }
}
