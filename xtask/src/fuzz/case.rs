//! One fuzz case through the whole pipeline, in-process: compile (whitted-lang, with small
//! limits), validate, prepare, render at 8x6 and trace one pixel, checking what must hold
//! for any input: diagnostics are located, a scene exists exactly when there is no error, no
//! pixel or tree colour is NaN or infinite, and the traced tree is the rendered pixel.

use std::path::Path;

use whitted_ir::Severity;
use whitted_lang::{compile_source, CompileOptions, Limits, SourceLoader};
use whitted_tracer::ray_tree::{format_text, trace_pixel, RayNode, SampleChoice, TextOptions};
use whitted_tracer::{render, PreparedScene, RenderObserver, RenderOptions, TileResult};

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

/// Imports resolve to a few fixed files (one of them imports itself).
struct Files;

impl SourceLoader for Files {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
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
#[derive(Clone, Copy, Debug, Default)]
pub struct Passed {
    pub compiled: bool,
    pub rendered: bool,
    pub objects: usize,
}

/// A failed check, with what to show.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// A short class for counting and deduplicating ("panic at crates/tracer/src/bvh.rs:88").
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
pub fn run(text: &str, cancel: &Cancel<'_>) -> Result<Passed, Failure> {
    let options = CompileOptions {
        limits: limits(),
        ..CompileOptions::default()
    };
    let compilation = compile_source("fuzz.scene", text, &mut Files, &options);
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
        return Ok(Passed::default());
    };

    let prepared = PreparedScene::new(&scene);
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
    Ok(Passed {
        compiled: true,
        rendered: true,
        objects: prepared.object_count(),
    })
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
