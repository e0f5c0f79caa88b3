//! `whitted diff SCENE --against-image STUDENT.tga`: a student's image against whitted's
//! render of the scene (the reference), compared in the 8-bit space the student's image was
//! written in, region by region, each read from the student's side
//! (`whitted_explain::student`).

use std::path::Path;

use serde::Serialize;
use whitted_explain::regions::{differing_regions, Region, IMAGE_DIFF_JSON_VERSION};
use whitted_explain::student::{read_student_pixel, Behaviours, Reference, StudentReading};
use whitted_explain::{explain_tree, format_summary, ExplanationDocument};
use whitted_ir::{Settings, ShadowMode};
use whitted_tracer::ray_tree::{trace_pixel, SampleChoice};
use whitted_tracer::{NoObserver, PreparedScene};

use crate::cli::DiffArgs;
use crate::scene_input::{load_scene, write_json_stdout, write_stdout};
use crate::setting_flags::apply_render_flags;
use crate::student_image::{self, Space};
use crate::Failure;

/// The JSON document of `--against-image` (docs/diff.md).
#[derive(Serialize)]
struct ImageDiffDocument<'a> {
    version: u32,
    image_size: [u32; 2],
    tolerance: u8,
    /// `linear` or `srgb`: the 8-bit space of the comparison.
    space: &'static str,
    differing_pixels: u64,
    /// The same count in the other space (`null` for an EXR, which has none of its own).
    other_space_differing_pixels: Option<u64>,
    regions: Vec<RegionDocument<'a>>,
}

#[derive(Serialize)]
struct RegionDocument<'a> {
    #[serde(flatten)]
    region: &'a Region,
    /// The sample pixel's 8-bit value in the student's image and in the reference.
    student: [u8; 3],
    reference: [u8; 3],
    /// The pixel read from the student's side.
    reading: &'a StudentReading,
    /// `whitted explain`'s document of the reference pixel.
    explanation: ExplanationDocument<'a>,
}

/// `--against-image`.
pub fn against_image(args: &DiffArgs, student_path: &Path) -> Result<(), Failure> {
    let loaded = load_scene(&args.scene, true)?;
    let (loaded, options) = apply_render_flags(loaded, &args.overrides)?;
    let student = student_image::read(student_path)?;
    let (width, height) = (student.width, student.height);
    if (width, height) != (options.width, options.height) {
        return Err(Failure::Usage(format!(
            "{} is {width}x{height} but the scene renders {}x{}: add --width {width} --height {height}",
            student_path.display(),
            options.width,
            options.height
        )));
    }
    let course = crate::front_end::is_course_scene(&args.scene.scene);
    let space = if args.linear {
        Space::Linear
    } else if args.srgb {
        Space::Srgb
    } else if course {
        Space::Linear
    } else {
        Space::Srgb
    };
    let prepared = PreparedScene::new(&loaded.scene);
    let Some((image, _)) = whitted_tracer::render(&prepared, &options, &NoObserver) else {
        return Err(Failure::Message("the render was cancelled".into()));
    };
    let reference = space.encode(&image.pixels);
    let theirs = student.bytes_in(space);
    let size_error = || Failure::Message("the two images do not have the same size".into());
    let regions = differing_regions(&theirs, &reference, width, height, args.tolerance)
        .ok_or_else(size_error)?;
    let differing: u64 = regions.iter().map(|r| u64::from(r.pixels)).sum();
    // An 8-bit image written in the other space differs almost everywhere: count it both
    // ways and say so when the other way matches far better.
    let other_space = match &student.pixels {
        student_image::StudentPixels::Bytes(_) => {
            let other = space.other().encode(&image.pixels);
            let regions = differing_regions(&theirs, &other, width, height, args.tolerance)
                .ok_or_else(size_error)?;
            Some(regions.iter().map(|r| u64::from(r.pixels)).sum::<u64>())
        }
        student_image::StudentPixels::Linear(_) => None,
    };
    let total = u64::from(width) * u64::from(height);
    if let Some(other) = other_space {
        if other * 4 <= differing && differing - other >= (total / 100).max(1) {
            eprintln!(
                "warning: {} looks like {} 8-bit values: {other} pixels differ compared as {}, {differing} as {} ({}); add --{} to compare as {}",
                student_path.display(),
                space.other().name(),
                space.other().name(),
                space.name(),
                if args.linear || args.srgb {
                    "as asked"
                } else if course {
                    "the default for a 6.837 scene"
                } else {
                    "the default for a scene in whitted's language"
                },
                space.other().name(),
                space.other().name(),
            );
        }
    }
    let shown = &regions[..regions.len().min(args.regions as usize)];
    let byte = |buffer: &[u8], [x, y]: [u32; 2]| {
        let i = ((y * width + x) * 3) as usize;
        [buffer[i], buffer[i + 1], buffer[i + 2]]
    };
    let behaviours = if shown.is_empty() {
        None
    } else {
        Some(Behaviours::new(&loaded.scene))
    };
    let side = Reference {
        prepared: &prepared,
        scene: &loaded.scene,
        options: &options,
    };
    let encode = |c: [f32; 3]| space.encode_one(c);
    let mut read = Vec::with_capacity(shown.len());
    for region in shown {
        let [x, y] = region.sample;
        let tree = trace_pixel(&prepared, &loaded.scene, &options, x, y, SampleChoice::All)
            .map_err(|e| crate::request::trace_failure(&e))?;
        let explanation = explain_tree(&prepared, &loaded.scene, &options, &tree);
        let reading = behaviours
            .as_ref()
            .map(|b| read_student_pixel(side, b, &tree, byte(&theirs, region.sample), &encode));
        read.push((explanation, reading));
    }
    if args.json {
        let document = ImageDiffDocument {
            version: IMAGE_DIFF_JSON_VERSION,
            image_size: [width, height],
            tolerance: args.tolerance,
            space: space.name(),
            differing_pixels: differing,
            other_space_differing_pixels: other_space,
            regions: shown
                .iter()
                .zip(&read)
                .filter_map(|(region, (explanation, reading))| {
                    Some(RegionDocument {
                        region,
                        student: byte(&theirs, region.sample),
                        reference: byte(&reference, region.sample),
                        reading: reading.as_ref()?,
                        explanation: explanation.document(),
                    })
                })
                .collect(),
        };
        return write_json_stdout(&document);
    }
    let mut out = format!(
        "student: {}\nreference: {}\n",
        student_path.display(),
        describe_reference(&args.scene.scene, &loaded.scene.settings, course)
    );
    if regions.is_empty() {
        out.push_str(&format!(
            "the images match: no pixel of {width}x{height} differs by more than {} (8-bit {} steps)\n",
            args.tolerance,
            space.name()
        ));
        return write_stdout(&out);
    }
    if course {
        out.push_str(COURSE_SWITCHES);
    }
    out.push_str(&format!(
        "{differing} of {total} pixels differ by more than {} (8-bit {} steps), in {} region{}\n",
        args.tolerance,
        space.name(),
        regions.len(),
        if regions.len() == 1 { "" } else { "s" }
    ));
    for (n, (region, (explanation, reading))) in shown.iter().zip(&read).enumerate() {
        let [sx, sy] = region.sample;
        let [r0, g0, b0] = byte(&theirs, region.sample);
        let [r1, g1, b1] = byte(&reference, region.sample);
        out.push_str(&format!(
            "\nregion {}: x {}..{}, y {}..{} ({} pixels)\n  pixel ({sx}, {sy}): student #{r0:02x}{g0:02x}{b0:02x}, reference #{r1:02x}{g1:02x}{b1:02x} (differs by {})\n",
            n + 1,
            region.min[0],
            region.max[0],
            region.min[1],
            region.max[1],
            region.pixels,
            region.largest_difference
        ));
        if let Some(reading) = reading {
            out.push_str(&format!("  {}\n", reading.message));
            out.push_str(&format!(
                "  the student's tracer must: {}\n",
                reading.tracer
            ));
            if let (Some([r, g, b]), Some(left)) =
                (reading.behaviour_color, reading.remaining_difference)
            {
                out.push_str(&format!(
                    "  (the reference traced that way gives #{r:02x}{g:02x}{b:02x}, {left} step{} from the student's)\n",
                    if left == 1 { "" } else { "s" }
                ));
            }
        }
        // The reference pixel's main light; its findings are about the scene, which the
        // student does not change.
        if let Some(line) = format_summary(explanation).lines().next() {
            out.push_str(&format!("  reference's {line}\n"));
        }
    }
    if regions.len() > shown.len() {
        let more = regions.len() - shown.len();
        out.push_str(&format!(
            "\n... and {more} smaller region{} (--regions N shows more)\n",
            if more == 1 { "" } else { "s" }
        ));
    }
    write_stdout(&out)
}

/// How the course's switches are given to `diff`, for a teacher whose reference differs
/// from the assignment's command line.
const COURSE_SWITCHES: &str = "(the course's switches, as --set: -shadows shadows=opaque, \
-transparent_shadows shadows=filtered, -shade_back shade_back=on, -bounces N max_depth=N, \
-weight W min_weight=W)\n";

/// What the reference is: for a 6.837 scene the course's command line that makes the same
/// image (the teacher checks it against the assignment's), else the main settings.
fn describe_reference(scene: &Path, settings: &Settings, course: bool) -> String {
    if !course {
        return format!(
            "whitted's render of {} at {}x{}, shadows {}, max_depth {}",
            scene.display(),
            settings.width,
            settings.height,
            shadow_word(settings.shadows),
            settings.max_depth
        );
    }
    let mut flags = vec![format!("-size {} {}", settings.width, settings.height)];
    match settings.shadows {
        ShadowMode::Opaque => flags.push("-shadows".into()),
        ShadowMode::Filtered => flags.push("-transparent_shadows".into()),
        ShadowMode::None => {}
    }
    if settings.shade_back {
        flags.push("-shade_back".into());
    }
    if settings.max_depth > 0 {
        flags.push(format!("-bounces {}", settings.max_depth));
    }
    if settings.min_weight > 0.0 {
        flags.push(format!("-weight {}", settings.min_weight));
    }
    format!(
        "whitted's render of {}, as `whitted mit6837 -input {} {}` makes it",
        scene.display(),
        scene.display(),
        flags.join(" ")
    )
}

fn shadow_word(mode: ShadowMode) -> &'static str {
    match mode {
        ShadowMode::Opaque => "opaque",
        ShadowMode::Filtered => "filtered",
        ShadowMode::None => "none",
    }
}
