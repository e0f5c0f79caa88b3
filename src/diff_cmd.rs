//! `whitted diff` and `whitted trace --against`: one pixel's ray trees under two scenes or
//! settings compared (`whitted_explain::diff`), or whitted's render compared with a
//! reference image, region by region, each explained (`whitted_explain::regions`).

use std::path::Path;

use serde::Serialize;
use whitted_explain::diff::{diff_pixel, format_text, Side};
use whitted_explain::regions::{differing_regions, Region};
use whitted_explain::{explain, format_summary, ExplanationDocument};
use whitted_tracer::{NoObserver, PreparedScene};

use crate::cli::{DiffArgs, RenderOverrides, SceneArgs, TraceArgs};
use crate::image_output::to_srgb8;
use crate::scene_input::{load_scene, write_json_stdout, write_stdout};
use crate::setting_flags::apply_render_flags;
use crate::Failure;

/// `whitted diff`.
pub fn diff(args: &DiffArgs) -> Result<(), Failure> {
    if let Some(reference) = &args.against_image {
        if args.other.is_some() || !args.against_set.is_empty() || args.pixel.is_some() {
            return Err(Failure::Usage(
                "--against-image compares the whole image: give no SCENE_B, --against-set or --pixel with it".into(),
            ));
        }
        return against_image(args, reference);
    }
    let Some(pixel) = args.pixel else {
        return Err(Failure::Usage(
            "which pixel? add --pixel X,Y (or compare whole images with --against-image REF.png)"
                .into(),
        ));
    };
    pixel_diff(
        &args.scene,
        args.other.as_deref(),
        &args.against_set,
        pixel,
        &args.overrides,
        args.json,
    )
}

/// `whitted trace SCENE --pixel X,Y --against B` (or `--against-set`).
pub fn trace_against(args: &TraceArgs) -> Result<(), Failure> {
    if args.sample.is_some() {
        return Err(Failure::Usage(
            "--against compares every sample of the pixel: leave out --sample".into(),
        ));
    }
    pixel_diff(
        &args.scene,
        args.against.as_deref(),
        &args.against_set,
        args.pixel,
        &args.overrides,
        args.json,
    )
}

fn pixel_diff(
    scene_a: &SceneArgs,
    other: Option<&Path>,
    against_set: &[(String, String)],
    [x, y]: [u32; 2],
    overrides: &RenderOverrides,
    json: bool,
) -> Result<(), Failure> {
    if other.is_none() && against_set.is_empty() {
        return Err(Failure::Usage(
            "compare with what? give a second scene or --against-set NAME=VALUE".into(),
        ));
    }
    let mut scene_b = scene_a.clone();
    if let Some(path) = other {
        scene_b.scene = path.to_path_buf();
    }
    // An --against-set replaces the same setting's --set, which would otherwise be given twice.
    scene_b
        .set
        .retain(|(name, _)| against_set.iter().all(|(other, _)| other != name));
    scene_b.set.extend(against_set.iter().cloned());
    let loaded_a = load_scene(scene_a, true)?;
    let loaded_b = load_scene(&scene_b, true)?;
    let (loaded_a, options_a) = apply_render_flags(loaded_a, overrides)?;
    let (loaded_b, options_b) = apply_render_flags(loaded_b, overrides)?;
    for options in [&options_a, &options_b] {
        crate::request::check_pixel(options, [x, y], None)?;
    }
    let prepared_a = PreparedScene::new(&loaded_a.scene);
    let prepared_b = PreparedScene::new(&loaded_b.scene);
    let side_a = Side {
        prepared: &prepared_a,
        scene: &loaded_a.scene,
        options: &options_a,
    };
    let side_b = Side {
        prepared: &prepared_b,
        scene: &loaded_b.scene,
        options: &options_b,
    };
    let diff = diff_pixel(side_a, side_b, x, y).map_err(|e| crate::request::trace_failure(&e))?;
    if json {
        return write_json_stdout(&diff);
    }
    let name_a = scene_a.scene.display().to_string();
    let mut name_b = other.map_or(name_a.clone(), |p| p.display().to_string());
    for (name, value) in against_set {
        name_b.push_str(&format!(" --set {name}={value}"));
    }
    write_stdout(&format_text(&diff, &name_a, &name_b))
}

/// The JSON document of `--against-image` (docs/diff.md).
#[derive(Serialize)]
struct ImageDiffDocument<'a> {
    version: u32,
    image_size: [u32; 2],
    tolerance: u8,
    differing_pixels: u64,
    regions: Vec<RegionDocument<'a>>,
}

#[derive(Serialize)]
struct RegionDocument<'a> {
    #[serde(flatten)]
    region: &'a Region,
    /// The sample pixel's 8-bit sRGB value in whitted's render and in the reference.
    whitted: [u8; 3],
    reference: [u8; 3],
    explanation: Option<ExplanationDocument<'a>>,
}

fn against_image(args: &DiffArgs, reference_path: &Path) -> Result<(), Failure> {
    let loaded = load_scene(&args.scene, true)?;
    let (loaded, options) = apply_render_flags(loaded, &args.overrides)?;
    let reference = image::open(reference_path)
        .map_err(|e| Failure::Message(format!("cannot read {}: {e}", reference_path.display())))?
        .to_rgb8();
    let (width, height) = reference.dimensions();
    if (width, height) != (options.width, options.height) {
        return Err(Failure::Usage(format!(
            "{} is {width}x{height} but the scene renders {}x{}: add --width {width} --height {height}",
            reference_path.display(),
            options.width,
            options.height
        )));
    }
    let prepared = PreparedScene::new(&loaded.scene);
    let Some((image, _)) = whitted_tracer::render(&prepared, &options, &NoObserver) else {
        return Err(Failure::Message("the render was cancelled".into()));
    };
    let ours = to_srgb8(&image.pixels);
    let theirs = reference.into_raw();
    let regions = differing_regions(&ours, &theirs, width, height, args.tolerance)
        .ok_or_else(|| Failure::Message("the two images do not have the same size".into()))?;
    let differing: u64 = regions.iter().map(|r| u64::from(r.pixels)).sum();
    let shown = &regions[..regions.len().min(args.regions as usize)];
    let byte = |buffer: &[u8], [x, y]: [u32; 2]| {
        let i = ((y * width + x) * 3) as usize;
        [buffer[i], buffer[i + 1], buffer[i + 2]]
    };
    let explanations: Vec<_> = shown
        .iter()
        .map(|r| explain(&prepared, &loaded.scene, &options, r.sample[0], r.sample[1]).ok())
        .collect();
    if args.json {
        let document = ImageDiffDocument {
            version: whitted_explain::diff::DIFF_JSON_VERSION,
            image_size: [width, height],
            tolerance: args.tolerance,
            differing_pixels: differing,
            regions: shown
                .iter()
                .zip(&explanations)
                .map(|(region, e)| RegionDocument {
                    region,
                    whitted: byte(&ours, region.sample),
                    reference: byte(&theirs, region.sample),
                    explanation: e.as_ref().map(|e| e.document()),
                })
                .collect(),
        };
        return write_json_stdout(&document);
    }
    let mut out = String::new();
    let total = u64::from(width) * u64::from(height);
    if regions.is_empty() {
        out.push_str(&format!(
            "the images match: no pixel of {width}x{height} differs by more than {} (8-bit steps)\n",
            args.tolerance
        ));
        return write_stdout(&out);
    }
    out.push_str(&format!(
        "{differing} of {total} pixels differ by more than {} (8-bit steps), in {} region{}\n",
        args.tolerance,
        regions.len(),
        if regions.len() == 1 { "" } else { "s" }
    ));
    for (n, (region, explanation)) in shown.iter().zip(&explanations).enumerate() {
        let [sx, sy] = region.sample;
        let [r0, g0, b0] = byte(&ours, region.sample);
        let [r1, g1, b1] = byte(&theirs, region.sample);
        out.push_str(&format!(
            "\nregion {}: x {}..{}, y {}..{} ({} pixels)\n  pixel ({sx}, {sy}): whitted #{r0:02x}{g0:02x}{b0:02x}, reference #{r1:02x}{g1:02x}{b1:02x} (differs by {})\n",
            n + 1,
            region.min[0],
            region.max[0],
            region.min[1],
            region.max[1],
            region.pixels,
            region.largest_difference
        ));
        if let Some(explanation) = explanation {
            for line in format_summary(explanation).lines() {
                out.push_str(&format!("  {line}\n"));
            }
        }
    }
    if regions.len() > shown.len() {
        out.push_str(&format!(
            "\n... and {} smaller region{} (--regions N shows more)\n",
            regions.len() - shown.len(),
            if regions.len() - shown.len() == 1 {
                ""
            } else {
                "s"
            }
        ));
    }
    write_stdout(&out)
}
