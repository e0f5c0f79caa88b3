//! `whitted trace`: compile a scene, record one pixel's ray tree, print it as text or JSON.

use std::io::IsTerminal;

use whitted_tracer::ray_tree::{format_text, trace_pixel, SampleChoice, TextOptions};
use whitted_tracer::PreparedScene;

use crate::cli::TraceArgs;
use crate::scene_input::{load_scene, write_json_stdout, write_stdout};
use crate::setting_flags::apply_render_flags;
use crate::Failure;

pub fn trace(args: &TraceArgs) -> Result<(), Failure> {
    let loaded = load_scene(&args.scene, false)?;
    let (loaded, options) = apply_render_flags(loaded, &args.overrides)?;
    let [x, y] = args.pixel;
    let which = match args.sample {
        Some(sample) => SampleChoice::One(sample),
        None => SampleChoice::All,
    };
    // Check the request before the BVH build, which is the slow part on big scenes.
    crate::request::check_pixel(&options, args.pixel, args.sample)?;
    let prepared = PreparedScene::for_ray_trees(&loaded.scene);
    let tree = trace_pixel(&prepared, &loaded.scene, &options, x, y, which)
        .map_err(|error| crate::request::trace_failure(&error))?;
    if args.json {
        write_json_stdout(&tree.document())
    } else {
        let swatches = std::io::stdout().is_terminal() && std::env::var_os("NO_COLOR").is_none();
        write_stdout(&format_text(&tree, TextOptions { swatches }))
    }
}
