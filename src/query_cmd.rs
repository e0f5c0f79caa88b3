//! `whitted query`: the pixels whose rays match a predicate (`whitted_explain::query`),
//! printed as a list with the ray that shows each, and written as a mask image.

use std::io::Write;
use std::time::Instant;

use serde::Serialize;
use whitted_explain::query::{describe_witness, run, Query};
use whitted_ir::{Handle, Object};
use whitted_tracer::PreparedScene;

use crate::cli::{ImageFormat, QueryArgs};
use crate::image_output::{write_image, Pixels};
use crate::scene_input::{load_scene, write_json_stdout, write_stdout};
use crate::setting_flags::apply_render_flags;
use crate::Failure;

/// The version of `whitted query --json`'s document (docs/query.md).
const QUERY_JSON_VERSION: u32 = 1;

#[derive(Serialize)]
struct QueryDocument {
    version: u32,
    query: String,
    image_size: [u32; 2],
    /// How many pixels match (all of them, whatever `--limit`).
    count: usize,
    /// The first `--limit` matching pixels, in row order.
    pixels: Vec<PixelDocument>,
}

#[derive(Serialize)]
struct PixelDocument {
    pixel: [u32; 2],
    /// The ray that first showed a predicate outside any `not` (null when the pixel
    /// matches through `depth` or `not` alone).
    witness: Option<WitnessDocument>,
    /// The depth of its deepest camera, reflected or transmitted ray.
    deepest: u32,
}

#[derive(Serialize)]
struct WitnessDocument {
    predicate: String,
    sample: u32,
    ray: &'static str,
    depth: u32,
    object: Option<String>,
    location: Option<String>,
    text: String,
}

pub fn query(args: &QueryArgs) -> Result<(), Failure> {
    let loaded = load_scene(&args.scene, true)?;
    let (loaded, options) = apply_render_flags(loaded, &args.overrides)?;
    if let Some(mask) = &args.mask {
        crate::render_cmd::check_output_folder(mask)?;
        if crate::render_cmd::same_file(mask, &args.scene.scene) {
            return Err(Failure::Usage(format!(
                "--mask {} would overwrite the scene",
                mask.display()
            )));
        }
    }
    let query = Query::compile(&args.expr, &loaded.scene)
        .map_err(|error| Failure::Usage(format!("in the query: {}", error.render(&args.expr))))?;
    let pool = crate::render_cmd::thread_pool(args.threads)?;
    let started = Instant::now();
    let prepared = PreparedScene::for_ray_trees(&loaded.scene);
    let result = pool.install(|| run(&prepared, &options, &query));
    let seconds = started.elapsed().as_secs_f64();
    if let Some(path) = &args.mask {
        let bytes: Vec<u8> = result
            .mask
            .iter()
            .flat_map(|&m| if m { [255u8; 3] } else { [0u8; 3] })
            .collect();
        let format = ImageFormat::from_path(path).unwrap_or(ImageFormat::Png);
        write_image(
            path,
            format,
            result.width,
            result.height,
            Pixels::Srgb8(bytes),
        )
        .map_err(Failure::Message)?;
    }
    let scene = &loaded.scene;
    let shown = &result.matches[..result.matches.len().min(args.limit)];
    if args.json {
        let pixels = shown
            .iter()
            .map(|m| PixelDocument {
                pixel: m.pixel,
                deepest: m.deepest,
                witness: m.witness.map(|w| {
                    let handle = w.object.map(|h| Handle::<Object>::from_index(h as usize));
                    WitnessDocument {
                        predicate: describe_witness(&query, scene, &w)
                            .split(':')
                            .next()
                            .unwrap_or("")
                            .to_string(),
                        sample: w.sample,
                        ray: w.kind.name(),
                        depth: w.depth,
                        object: handle.map(|h| scene.object_label(h)),
                        location: handle.map(|h| scene.sources.location(scene.objects.span(h))),
                        text: describe_witness(&query, scene, &w),
                    }
                }),
            })
            .collect();
        return write_json_stdout(&QueryDocument {
            version: QUERY_JSON_VERSION,
            query: args.expr.clone(),
            image_size: [result.width, result.height],
            count: result.matches.len(),
            pixels,
        });
    }
    let total = u64::from(result.width) * u64::from(result.height);
    let mut out = format!(
        "{} of {total} pixels ({}x{}) match {}\n",
        result.matches.len(),
        result.width,
        result.height,
        args.expr
    );
    for m in shown {
        let [x, y] = m.pixel;
        let why = match &m.witness {
            Some(w) => describe_witness(&query, scene, w),
            // Only `depth` and predicates under `not` decided it: no one ray shows it.
            None => format!("deepest ray at depth {}", m.deepest),
        };
        out.push_str(&format!("  ({x}, {y})  {why}\n"));
    }
    if result.matches.len() > shown.len() {
        out.push_str(&format!(
            "  ... and {} more (--limit N lists more; --mask OUT.png shows them all)\n",
            result.matches.len() - shown.len()
        ));
    }
    write_stdout(&out)?;
    // Timing goes to stderr so that the listing stays the same from run to run.
    let _ = writeln!(
        std::io::stderr(),
        "queried in {seconds:.2} s on {} threads",
        pool.current_num_threads()
    );
    Ok(())
}
