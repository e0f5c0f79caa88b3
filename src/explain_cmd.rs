//! `whitted explain`: compile a scene, explain one pixel (its main light paths and the
//! findings, `whitted_explain`), print it as text or JSON.

use whitted_explain::{explain, format_text};
use whitted_tracer::PreparedScene;

use crate::cli::ExplainArgs;
use crate::scene_input::{load_scene, write_json_stdout, write_stdout};
use crate::setting_flags::apply_render_flags;
use crate::Failure;

pub fn explain_pixel(args: &ExplainArgs) -> Result<(), Failure> {
    let loaded = load_scene(&args.scene, false)?;
    let (loaded, options) = apply_render_flags(loaded, &args.overrides)?;
    let [x, y] = args.pixel;
    // A pixel the image cannot have is found before the BVH build (the size was checked
    // when the flags were applied).
    crate::request::check_pixel(&options, args.pixel, None)?;
    let prepared = PreparedScene::for_ray_trees(&loaded.scene);
    let explanation = explain(&prepared, &loaded.scene, &options, x, y)
        .map_err(|error| crate::request::trace_failure(&error))?;
    if args.json {
        write_json_stdout(&explanation.document())
    } else {
        write_stdout(&format_text(&explanation))
    }
}
