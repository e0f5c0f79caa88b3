//! One fuzz case through the whole pipeline, in-process: compile (whitted-lang, with small
//! limits, its mesh files served from the case), validate, prepare, lint (`whitted check`),
//! render at 8x6, trace one pixel and explain it, checking what must hold for any input:
//! diagnostics and lints are located, a scene exists exactly when there is no error, no
//! pixel or tree colour is NaN or infinite, the traced tree and the explanation are the
//! rendered pixel, and the explanation's paths sum to it.

use std::path::Path;

use whitted_ir::Severity;
use whitted_lang::{compile_source, CompileOptions, Limits, SourceLoader};
use whitted_tracer::ray_tree::{format_text, trace_pixel, RayNode, SampleChoice, TextOptions};
use whitted_tracer::{render, PreparedScene, RenderObserver, RenderOptions, TileResult};

use super::Case;

/// The image every case renders: tiny, so that a case costs the scene, not the pixels.
pub const WIDTH: u32 = 8;
pub const HEIGHT: u32 = 6;
/// Samples per pixel at most (a scene may ask for fewer).
const MAX_SAMPLES: u32 = 4;
/// The depth at most: with `min_weight 0` a glass scene's tree doubles at every level, and
/// the tracer bounds depth (256), not work. Cancelling long renders is a separate matter.
const MAX_DEPTH: u32 = 10;

/// Small budgets, so that a mutation into a huge loop or a doubling recursion ends within
/// milliseconds with the language's own limit error.
pub fn limits() -> Limits {
    Limits {
        max_objects: 20_000,
        max_evaluation_steps: 200_000,
        max_call_depth: 64,
        max_nesting: 256,
        max_import_depth: 8,
        max_imports: 16,
        max_source_bytes: 1 << 20,
        max_lights: 64,
        max_materials: 20_000,
        max_mesh_triangles: 10_000,
        max_scene_triangles: 100_000,
    }
}

/// Imports resolve to the case's own files (its meshes) and a few fixed files (one of them
/// imports itself).
struct Files<'a>(&'a [(String, Vec<u8>)]);

impl SourceLoader for Files<'_> {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if let Some((_, bytes)) = self.0.iter().find(|(file, _)| file == name) {
            return Ok(bytes.clone());
        }
        match name {
            "materials.scene" => Ok(b"material chrome { reflective 0.8 specular 1 }\n".to_vec()),
            "loop.scene" => Ok(b"import \"loop.scene\"\nsphere { }\n".to_vec()),
            _ => Err(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "no such file",
            )),
        }
    }
}

/// What a passing case did, for the summary.
#[derive(Clone, Debug, Default)]
pub struct Passed {
    pub compiled: bool,
    pub rendered: bool,
    pub objects: usize,
    /// Meshes the scene holds (read from the case's `.obj` and `.ply` files).
    pub meshes: usize,
    /// Lints `whitted check` would print.
    pub lints: usize,
    /// Findings `whitted explain` gave for the traced pixel.
    pub findings: usize,
    /// Why it stopped before the tracer: its first error, numbers and names blanked.
    pub stopped_by: Option<String>,
}

/// A failed check, with what to show.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// A short class for counting and deduplicating ("panic at crates/bvh/src/walk.rs:88").
    pub class: String,
    pub detail: String,
}

impl Failure {
    fn new(class: impl Into<String>, detail: impl Into<String>) -> Failure {
        Failure {
            class: class.into(),
            detail: detail.into(),
        }
    }
}

/// Stops a render when the case runner gave up on it (a hang) so that it frees its core.
pub struct Cancel<'a>(pub &'a std::sync::atomic::AtomicBool);

impl RenderObserver for Cancel<'_> {
    fn tile_done(&self, _tile: &TileResult) {}
    fn should_stop(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// Runs one case. Panics are not caught here: the runner catches them.
pub fn run(case: &Case, cancel: &Cancel<'_>) -> Result<Passed, Failure> {
    let options = CompileOptions {
        limits: limits(),
        ..CompileOptions::default()
    };
    let compilation = compile_source("fuzz.scene", &case.text, &mut Files(&case.files), &options);
    let errors = compilation
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .count();
    if compilation.scene.is_some() != (errors == 0) {
        return Err(Failure::new(
            "a scene with errors, or no scene without",
            format!("{errors} errors, scene: {}", compilation.scene.is_some()),
        ));
    }
    for d in &compilation.diagnostics {
        let Some(span) = d.span else {
            // The one diagnostic that no source made: the summary after too many errors.
            if d.severity == Severity::Error && d.message.starts_with("too many errors") {
                continue;
            }
            return Err(Failure::new(
                format!("{:?} without a location", d.severity),
                d.message.clone(),
            ));
        };
        let len = compilation.sources.get(span.file).map(|f| f.text.len());
        if len.is_none_or(|len| span.start > span.end || span.end as usize > len) {
            return Err(Failure::new(
                "a span outside its file",
                format!("{span:?} in a file of {len:?} bytes: {}", d.message),
            ));
        }
    }
    let _ = whitted_lang::render_diagnostics(&compilation.sources, &compilation.diagnostics, false);
    let Some(scene) = compilation.scene else {
        let first = compilation.diagnostics.iter().find(|d| d.is_error());
        return Ok(Passed {
            stopped_by: first.map(|d| reason(&d.message)),
            ..Passed::default()
        });
    };

    let prepared = PreparedScene::new(&scene);
    // `whitted check`: every lint located inside the source.
    let lints = if whitted_explain::lint::lints_by_default(&scene) {
        whitted_explain::lint::lint(&prepared, &scene)
    } else {
        Vec::new()
    };
    for lint in &lints {
        let Some(span) = lint.diagnostic.span else {
            continue;
        };
        let len = compilation.sources.get(span.file).map(|f| f.text.len());
        if len.is_none_or(|len| span.start > span.end || span.end as usize > len) {
            return Err(Failure::new(
                "a lint outside its file",
                format!(
                    "{span:?} in a file of {len:?} bytes: {}",
                    lint.diagnostic.message
                ),
            ));
        }
    }
    let lint_diagnostics: Vec<_> = lints.iter().map(|l| l.diagnostic.clone()).collect();
    let _ = whitted_lang::render_diagnostics(&compilation.sources, &lint_diagnostics, false);
    let settings = &scene.settings;
    let render_options = RenderOptions {
        width: WIDTH,
        height: HEIGHT,
        samples_per_pixel: settings.samples_per_pixel.clamp(1, MAX_SAMPLES),
        max_depth: settings.max_depth.min(MAX_DEPTH),
        min_weight: settings.min_weight as f32,
    };
    let Some((image, _)) = render(&prepared, &render_options, cancel) else {
        return Err(Failure::new(
            "hang",
            "the render was cancelled after the time budget",
        ));
    };
    for (i, pixel) in image.pixels.iter().enumerate() {
        if pixel.iter().any(|c| !c.is_finite()) {
            return Err(Failure::new(
                "NaN or infinite pixel",
                format!(
                    "pixel ({}, {}) = {pixel:?}",
                    i as u32 % WIDTH,
                    i as u32 / WIDTH
                ),
            ));
        }
    }
    let (x, y) = (WIDTH / 2, HEIGHT / 2);
    let tree = trace_pixel(&prepared, &scene, &render_options, x, y, SampleChoice::All)
        .map_err(|e| Failure::new("trace refused a pixel in range", e.to_string()))?;
    let rendered = image.pixel(x, y).unwrap_or([f32::NAN; 3]);
    if tree.color.map(f32::to_bits) != rendered.map(f32::to_bits) {
        return Err(Failure::new(
            "tree colour is not the rendered pixel",
            format!("tree {:?}, pixel {rendered:?}", tree.color),
        ));
    }
    for sample in &tree.samples {
        if let Some(bad) = first_non_finite(&sample.root) {
            return Err(Failure::new("NaN or infinite colour in a ray tree", bad));
        }
    }
    let _ = format_text(&tree, TextOptions { swatches: false });
    if let Err(e) = serde_json::to_string(&tree.document()) {
        return Err(Failure::new("ray tree JSON", e.to_string()));
    }
    let findings = explain_pixel(&prepared, &scene, &render_options, (x, y), rendered)?;
    Ok(Passed {
        compiled: true,
        rendered: true,
        objects: prepared.object_count(),
        meshes: scene.meshes.len(),
        lints: lints.len(),
        findings,
        stopped_by: None,
    })
}

/// `whitted explain` of the traced pixel: its colour is the rendered pixel, its paths sum
/// to it (as `tests/integration/explain.rs` asserts on every shipped scene), and its text
/// and JSON can be written. Returns how many findings it has.
fn explain_pixel(
    prepared: &PreparedScene,
    scene: &whitted_ir::Scene,
    options: &RenderOptions,
    (x, y): (u32, u32),
    rendered: [f32; 3],
) -> Result<usize, Failure> {
    let explanation = whitted_explain::explain(prepared, scene, options, x, y)
        .map_err(|e| Failure::new("explain refused a pixel in range", e.to_string()))?;
    if explanation.color.map(f32::to_bits) != rendered.map(f32::to_bits) {
        return Err(Failure::new(
            "explained colour is not the rendered pixel",
            format!("explain {:?}, pixel {rendered:?}", explanation.color),
        ));
    }
    for (channel, &pixel) in rendered.iter().enumerate() {
        let parts = explanation
            .contributions
            .iter()
            .map(|c| f64::from(c.color[channel]));
        let sum: f64 = parts.clone().sum();
        let size: f64 = parts.map(f64::abs).sum::<f64>().max(1.0);
        let pixel = f64::from(pixel);
        let close = (sum - pixel).abs() <= 1e-4 * size;
        if !close {
            return Err(Failure::new(
                "explained paths do not sum to the pixel",
                format!("channel {channel}: paths sum to {sum}, pixel {pixel}"),
            ));
        }
    }
    let _ = whitted_explain::format_text(&explanation);
    if let Err(e) = serde_json::to_string(&explanation.document()) {
        return Err(Failure::new("explain JSON", e.to_string()));
    }
    Ok(explanation.findings.len())
}

/// A diagnostic's message as a class of reasons: numbers and quoted names blanked.
fn reason(message: &str) -> String {
    let mut out = String::new();
    let mut quoted = false;
    for ch in message.chars() {
        match ch {
            '`' => {
                quoted = !quoted;
                if quoted {
                    out.push_str("`_`");
                }
            }
            _ if quoted => {}
            '0'..='9' => {
                if !out.ends_with('#') {
                    out.push('#');
                }
            }
            _ => out.push(ch),
        }
    }
    out.chars().take(90).collect()
}

fn first_non_finite(node: &RayNode) -> Option<String> {
    if node.color.iter().any(|c| !c.is_finite()) {
        return Some(format!(
            "{} ray at depth {} returned {:?}",
            node.kind.name(),
            node.depth,
            node.color
        ));
    }
    node.children.iter().find_map(first_non_finite)
}
