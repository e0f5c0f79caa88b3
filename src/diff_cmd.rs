//! `whitted diff` and `whitted trace --against`: one pixel's ray trees under two scenes or
//! settings compared (`whitted_explain::diff`); `--against-image` is `against_image.rs`.

use std::path::Path;

use whitted_explain::diff::{diff_pixel, format_text, Side};
use whitted_tracer::PreparedScene;

use crate::cli::{DiffArgs, RenderOverrides, SceneArgs, TraceArgs};
use crate::scene_input::{load_scene, write_json_stdout, write_stdout};
use crate::setting_flags::apply_render_flags;
use crate::Failure;

/// `whitted diff`.
pub fn diff(args: &DiffArgs) -> Result<(), Failure> {
    if let Some(student) = &args.against_image {
        if args.other.is_some() || !args.against_set.is_empty() || args.pixel.is_some() {
            return Err(Failure::Usage(
                "--against-image compares the whole image: give no SCENE_B, --against-set or --pixel with it".into(),
            ));
        }
        return crate::against_image::against_image(args, student);
    }
    if args.linear || args.srgb {
        return Err(Failure::Usage(
            "--linear and --srgb say how a student's image is compared: use them with --against-image".into(),
        ));
    }
    let Some(pixel) = args.pixel else {
        return Err(Failure::Usage(
            "which pixel? add --pixel X,Y (or compare whole images with --against-image STUDENT.png)"
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
    let prepared_a = PreparedScene::for_ray_trees(&loaded_a.scene);
    let prepared_b = PreparedScene::for_ray_trees(&loaded_b.scene);
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
