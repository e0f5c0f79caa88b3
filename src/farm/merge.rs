//! `whitted farm merge DIR -o OUT`: check every part against the scene as it is now and
//! against each other, assemble the linear pixels, and encode them exactly as `whitted
//! render` does, so the merged file is byte-identical to a single render's. `--verify`
//! renders a deterministic sample of pixels again and compares them bit for bit.

use std::path::Path;

use whitted_tracer::{PixelRect, PreparedScene, RenderOptions};

use crate::cli::{FarmMergeArgs, ImageFormat};
use crate::farm::part::{self, PartState};
use crate::farm::plan::read_plan;
use crate::farm::task;
use crate::image_output::{write_image, Pixels};
use crate::Failure;

pub fn merge(args: &FarmMergeArgs) -> Result<(), Failure> {
    let plan = read_plan(&args.dir)?;
    let format = ImageFormat::from_path(&args.output).unwrap_or(ImageFormat::Png);
    crate::render_cmd::check_output_folder(&args.output)?;
    let (scene, options, now) = crate::farm::compile_plan_scene(&plan)?;
    let parts = Path::new(&plan.parts);
    let (width, height) = (options.width, options.height);
    let mut image = vec![[0.0f32; 3]; width as usize * height as usize];
    let mut placed: Vec<(u32, PixelRect)> = Vec::with_capacity(plan.tasks as usize);
    let mut covered = 0u64;
    for index in 0..plan.tasks {
        let name = format!("task {index}/{}", plan.tasks);
        let (manifest, pixels) = match part::read_part(parts, index, plan.tasks, true) {
            PartState::Missing => {
                return Err(Failure::Message(format!(
                    "{name}: its part is missing from {}: run the task (`whitted farm status {}` lists what is left)",
                    parts.display(),
                    args.dir.display()
                )))
            }
            PartState::Corrupt(why) => {
                return Err(Failure::Message(format!("{name}: the part is corrupt: {why}")))
            }
            PartState::Intact(manifest, pixels) => (manifest, pixels.unwrap_or_default()),
        };
        if let Some(why) = task::staleness(&manifest, &now) {
            return Err(Failure::Message(format!(
                "{name}: refused: the part was {why}; render the task again"
            )));
        }
        if (manifest.image_width, manifest.image_height) != (width, height) {
            return Err(Failure::Message(format!(
                "{name}: refused: the part belongs to a {}x{} image, the scene makes {width}x{height}",
                manifest.image_width, manifest.image_height
            )));
        }
        let region = PixelRect::from(manifest.region);
        if region.clipped(width, height) != region {
            return Err(Failure::Message(format!(
                "{name}: refused: its pixels {region:?} reach past the {width}x{height} image"
            )));
        }
        if let Some((other, _)) = placed.iter().find(|(_, r)| overlap(r, &region)) {
            return Err(Failure::Message(format!(
                "{name}: refused: its pixels overlap those of task {other}/{} (the tasks did not agree on the plan)",
                plan.tasks
            )));
        }
        let row = region.width as usize;
        for (y, source) in pixels.chunks(row.max(1)).enumerate() {
            let start = (region.y as usize + y) * width as usize + region.x as usize;
            image[start..start + row].copy_from_slice(source);
        }
        covered += region.pixel_count();
        placed.push((index, region));
    }
    let total = u64::from(width) * u64::from(height);
    if covered != total {
        return Err(Failure::Message(format!(
            "the {} parts cover {covered} of the image's {total} pixels (the tasks did not agree on the plan)",
            plan.tasks
        )));
    }
    if args.verify {
        verify(scene, &options, &image, args.samples)?;
    }
    write_image(&args.output, format, width, height, Pixels::Linear(&image))
        .map_err(Failure::Message)?;
    Ok(())
}

fn overlap(a: &PixelRect, b: &PixelRect) -> bool {
    let a_right = u64::from(a.x) + u64::from(a.width);
    let b_right = u64::from(b.x) + u64::from(b.width);
    let a_bottom = u64::from(a.y) + u64::from(a.height);
    let b_bottom = u64::from(b.y) + u64::from(b.height);
    !a.is_empty()
        && !b.is_empty()
        && u64::from(a.x) < b_right
        && u64::from(b.x) < a_right
        && u64::from(a.y) < b_bottom
        && u64::from(b.y) < a_bottom
}

/// Pixel `i` of the sample `--verify` checks: a hash of `i` (SplitMix64), the same on every
/// run, spread over the whole image.
pub fn sample_pixel(i: u64, width: u32, height: u32) -> (u32, u32) {
    let mut z = i.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    let pixels = u64::from(width) * u64::from(height);
    let at = z % pixels.max(1);
    (
        (at % u64::from(width.max(1))) as u32,
        (at / u64::from(width.max(1))) as u32,
    )
}

/// Renders `samples` pixels of the image again, each as a 1x1 region, and compares them
/// with the merged pixels bit for bit; the first mismatch is the error.
fn verify(
    scene: whitted_ir::ValidScene,
    options: &RenderOptions,
    image: &[[f32; 3]],
    samples: u32,
) -> Result<(), Failure> {
    let pool = crate::render_cmd::thread_pool(None)?;
    let prepared = pool.install(|| PreparedScene::new_releasing_ir(scene));
    let (width, height) = (options.width, options.height);
    for i in 0..u64::from(samples) {
        let (x, y) = sample_pixel(i, width, height);
        let region = PixelRect {
            x,
            y,
            width: 1,
            height: 1,
        };
        let again = pool
            .install(|| {
                whitted_tracer::render_region(
                    &prepared,
                    options,
                    region,
                    &whitted_tracer::NoObserver,
                )
            })
            .and_then(|(part, _)| part.pixel(0, 0))
            .ok_or_else(|| Failure::Message("the verification render was cancelled".into()))?;
        let merged = image[y as usize * width as usize + x as usize];
        if again.map(f32::to_bits) != merged.map(f32::to_bits) {
            return Err(Failure::Message(format!(
                "--verify: pixel ({x}, {y}) is {merged:?} in the parts but renders as {again:?}: \
                 the parts do not match this whitted's render of the scene"
            )));
        }
    }
    eprintln!("verified {samples} pixels: each is bit for bit the render's");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_pixels_stay_in_the_image_and_spread() {
        let pixels: Vec<_> = (0..64).map(|i| sample_pixel(i, 7, 5)).collect();
        assert!(pixels.iter().all(|&(x, y)| x < 7 && y < 5));
        let distinct: std::collections::BTreeSet<_> = pixels.iter().collect();
        assert!(distinct.len() > 20, "{distinct:?}");
        assert_eq!(sample_pixel(0, 1, 1), (0, 0));
    }

    #[test]
    fn rectangles_overlap_only_when_they_share_a_pixel() {
        let rect = |x, y, width, height| PixelRect {
            x,
            y,
            width,
            height,
        };
        assert!(overlap(&rect(0, 0, 4, 4), &rect(3, 3, 4, 4)));
        assert!(!overlap(&rect(0, 0, 4, 4), &rect(4, 0, 4, 4)));
        assert!(!overlap(&rect(0, 0, 4, 4), &rect(0, 4, 4, 4)));
        assert!(!overlap(&rect(0, 0, 0, 4), &rect(0, 0, 4, 4)));
    }
}
