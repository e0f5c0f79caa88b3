//! `whitted farm merge DIR -o OUT`: check every part against the scene as it is now and
//! against each other, assemble the linear pixels, and encode them exactly as `whitted
//! render` does, so the merged file is byte-identical to a single render's. `--verify`
//! renders a deterministic sample of pixels again and compares them bit for bit.

use std::path::Path;

use whitted_tracer::{PixelRect, PreparedScene, RenderOptions};

use crate::cli::{FarmMergeArgs, ImageFormat};
use crate::farm::part::{self, PartState};
use crate::farm::plan::{read_plan, Plan};
use crate::farm::task;
use crate::image_output::{write_image, Pixels};
use crate::setting_flags::apply_render_flags;
use crate::Failure;

pub fn merge(args: &FarmMergeArgs) -> Result<(), Failure> {
    let plan = read_plan(&args.dir)?;
    let (scene, options, now) = crate::farm::compile_plan_scene(&plan)?;
    let parts = Path::new(&plan.parts);
    let Some(range) = plan.frame_range() else {
        crate::render_cmd::check_output_folder(&args.output)?;
        let tasks: Vec<u32> = (0..plan.tasks).collect();
        let image = assemble((&args.dir, &plan), parts, &now, None, &tasks, &options)?;
        if args.verify {
            verify(scene, &options, &image, args.samples, None)?;
        }
        return write(&args.output, &options, &image);
    };
    let pattern = crate::animation::FramePattern::parse(&args.output.to_string_lossy())
        .map_err(Failure::Usage)?
        .ok_or_else(|| {
            Failure::Usage(format!(
                "-o {}: the plan is an animation of frames {}..={}, merged into one image per \
                 frame: put the frame number in the name, like frame-{{frame:04}}.png",
                args.output.display(),
                range.start(),
                range.end()
            ))
        })?;
    // Which tasks hold each frame, and every part checked before any image is written, so
    // a merge that cannot finish writes nothing.
    let mut holders: std::collections::BTreeMap<u32, Vec<u32>> = Default::default();
    for index in 0..plan.tasks {
        let task = task::TaskIndex {
            index,
            count: plan.tasks,
        };
        let share = task::share(Some(&range), task).map_err(Failure::Message)?;
        for frame in share.frames.into_iter().flatten() {
            holders.entry(frame).or_default().push(index);
        }
    }
    for (&frame, tasks) in &holders {
        for &index in tasks {
            let name = part_name(&plan, index, Some(frame));
            check_part(
                &args.dir,
                parts,
                &now,
                &name,
                (index, plan.tasks, Some(frame)),
                false,
            )?;
        }
    }
    let mut first = Some((scene, options));
    for (frame, tasks) in holders {
        let (scene, options) = match first.take() {
            Some(compiled) if frame == *range.start() => compiled,
            _ => {
                let loaded = task::load_frame(&plan.scene_args(), Some(frame), true)?;
                let (loaded, options) = apply_render_flags(loaded, &plan.overrides())?;
                (loaded.scene, options)
            }
        };
        let image = assemble(
            (&args.dir, &plan),
            parts,
            &now,
            Some(frame),
            &tasks,
            &options,
        )?;
        if args.verify {
            verify(scene, &options, &image, args.samples, Some(frame))?;
        }
        let path = pattern.path(frame);
        crate::render_cmd::check_output_folder(&path)?;
        write(&path, &options, &image)?;
    }
    Ok(())
}

/// Encodes the merged pixels exactly as `whitted render` does, in the format of `path`.
fn write(path: &Path, options: &RenderOptions, image: &[[f32; 3]]) -> Result<(), Failure> {
    let format = ImageFormat::from_path(path).unwrap_or(ImageFormat::Png);
    write_image(
        path,
        format,
        options.width,
        options.height,
        Pixels::Linear(image),
    )
    .map_err(Failure::Message)
}

/// How messages name a part: `task 2/4`, or `task 2/4, frame 7`.
fn part_name(plan: &Plan, index: u32, frame: Option<u32>) -> String {
    match frame {
        None => format!("task {index}/{}", plan.tasks),
        Some(frame) => format!("task {index}/{}, frame {frame}", plan.tasks),
    }
}

/// A part that is there, intact and fresh (its pixels when `keep_pixels`), or the error
/// naming it.
fn check_part(
    dir: &Path,
    parts: &Path,
    now: &task::Fingerprint,
    name: &str,
    (index, tasks, frame): (u32, u32, Option<u32>),
    keep_pixels: bool,
) -> Result<(Box<part::Manifest>, Vec<[f32; 3]>), Failure> {
    let (manifest, pixels) = match part::read_part(parts, index, tasks, frame, keep_pixels) {
        PartState::Missing => {
            return Err(Failure::Message(format!(
                "{name}: its part is missing from {}: run the task (`whitted farm status {}` lists what is left)",
                parts.display(),
                dir.display()
            )))
        }
        PartState::Corrupt(why) => {
            return Err(Failure::Message(format!("{name}: the part is corrupt: {why}")))
        }
        PartState::Intact(manifest, pixels) => (manifest, pixels.unwrap_or_default()),
    };
    if let Some(why) = task::staleness(&manifest, now) {
        return Err(Failure::Message(format!(
            "{name}: refused: the part was {why}; render the task again"
        )));
    }
    Ok((manifest, pixels))
}

/// One image (of `frame`, for an animation) from the parts of `tasks`: each checked, placed,
/// and the whole covered exactly once.
fn assemble(
    (dir, plan): (&Path, &Plan),
    parts: &Path,
    now: &task::Fingerprint,
    frame: Option<u32>,
    tasks: &[u32],
    options: &RenderOptions,
) -> Result<Vec<[f32; 3]>, Failure> {
    let (width, height) = (options.width, options.height);
    let mut image = vec![[0.0f32; 3]; width as usize * height as usize];
    let mut placed: Vec<(u32, PixelRect)> = Vec::with_capacity(tasks.len());
    let mut covered = 0u64;
    for &index in tasks {
        let name = part_name(plan, index, frame);
        let (manifest, pixels) =
            check_part(dir, parts, now, &name, (index, plan.tasks, frame), true)?;
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
        let of_frame = frame.map_or_else(String::new, |f| format!(" of frame {f}"));
        return Err(Failure::Message(format!(
            "the {} parts{of_frame} cover {covered} of the image's {total} pixels (the tasks did not agree on the plan)",
            tasks.len()
        )));
    }
    Ok(image)
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
    frame: Option<u32>,
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
            let of_frame = frame.map_or_else(String::new, |f| format!(" of frame {f}"));
            return Err(Failure::Message(format!(
                "--verify: pixel ({x}, {y}){of_frame} is {merged:?} in the parts but renders as \
                 {again:?}: the parts do not match this whitted's render of the scene"
            )));
        }
    }
    let of_frame = frame.map_or_else(String::new, |f| format!(" of frame {f}"));
    eprintln!("verified {samples} pixels{of_frame}: each is bit for bit the render's");
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
