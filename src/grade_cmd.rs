//! `whitted grade SCENE IMAGE`: which classic bug explains a student's image
//! (`whitted_explain::grade` renders and ranks the models; this reads the image, prints the
//! diagnosis and writes the picture). `--class` is `grade_class.rs`.

use std::path::Path;

use serde::Serialize;
use whitted_explain::grade::{side_by_side, Candidate, Grade, Grader, Verdict};

use crate::cli::{GradeArgs, SceneArgs};
use crate::image_output::{write_image, Pixels};
use crate::scene_input::{load_scene, load_scene_with, write_json_stdout, write_stdout};
use crate::setting_flags::apply_render_flags;
use crate::student_image::{self, Space};
use crate::Failure;

/// The version of `grade --json`'s document (docs/courses.md).
pub const GRADE_JSON_VERSION: u32 = 1;

#[derive(Serialize)]
pub struct GradeDocument {
    pub version: u32,
    pub image_size: [u32; 2],
    pub tolerance: u8,
    pub encoding: &'static str,
    pub differing_pixels: u64,
    /// `matches`, `explained` or `unexplained`.
    pub verdict: &'static str,
    pub explanations: Vec<ExplanationEntry>,
    /// Models a tracer could have without changing this scene's image.
    pub not_visible: Vec<&'static str>,
    pub renders: u32,
}

#[derive(Serialize, serde::Deserialize, Clone)]
pub struct ExplanationEntry {
    /// The model's id, or two joined by `+`.
    pub id: String,
    pub words: Vec<String>,
    pub handout: Vec<String>,
    pub fix: Vec<String>,
    /// Differing pixels the model makes match, and matching pixels it breaks.
    pub explained_pixels: u64,
    pub broken_pixels: u64,
    /// (explained - broken) / differing.
    pub share: f64,
    /// The share of the summed 8-bit difference the model removes.
    pub energy_share: f64,
    /// Models that render the same image here.
    pub same_as: Vec<String>,
}

pub fn verdict_word(verdict: &Verdict) -> &'static str {
    match verdict {
        Verdict::Matches => "matches",
        Verdict::Explained => "explained",
        Verdict::Unexplained => "unexplained",
    }
}

pub fn entry(candidate: &Candidate, differing: u64) -> ExplanationEntry {
    let list = |f: fn(&whitted_explain::grade::StudentBug) -> &'static str| {
        candidate.bugs.iter().map(|b| f(b).to_string()).collect()
    };
    ExplanationEntry {
        id: candidate.id(),
        words: list(|b| b.words),
        handout: list(|b| b.handout),
        fix: list(|b| b.fix),
        explained_pixels: candidate.score.explained,
        broken_pixels: candidate.score.broken,
        share: candidate.score.share(differing),
        energy_share: candidate.score.energy_share(),
        same_as: candidate.same_as.iter().map(|b| b.id.to_string()).collect(),
    }
}

/// `whitted grade SCENE IMAGE` (or `--class`).
pub fn grade(args: &GradeArgs) -> Result<(), Failure> {
    if let Some(class) = &args.class {
        return crate::grade_class::grade_class(args, class);
    }
    let (scene, image, loaded) = match &args.command {
        Some(line) => {
            let (Some(image), None) = (&args.scene, &args.image) else {
                return Err(Failure::Usage(
                    "with --command give only the student's IMAGE".into(),
                ));
            };
            let (scene_args, course) =
                crate::grade_class::course_line(line, Path::new(".")).map_err(Failure::Usage)?;
            let loaded = load_scene_with(&scene_args, true, &course)?;
            (scene_args.scene, image, loaded)
        }
        None => {
            let (Some(scene), Some(image)) = (&args.scene, &args.image) else {
                return Err(Failure::Usage(
                    "give SCENE and IMAGE, --command LINE and IMAGE, or --class DIR --commands FILE"
                        .into(),
                ));
            };
            let scene_args = SceneArgs {
                scene: scene.clone(),
                define: args.define.clone(),
                set: args.set.clone(),
                frame: None,
            };
            (scene.clone(), image, load_scene(&scene_args, true)?)
        }
    };
    let scene = &scene;
    let (loaded, options) = apply_render_flags(loaded, &args.overrides)?;
    let student = student_image::read(image)?;
    if (student.width, student.height) != (options.width, options.height) {
        return Err(Failure::Usage(format!(
            "{} is {}x{} but the scene renders {}x{}: add --width {} --height {}",
            image.display(),
            student.width,
            student.height,
            options.width,
            options.height,
            student.width,
            student.height
        )));
    }
    let course = crate::front_end::is_course_scene(scene);
    let space = if args.linear || (course && !args.srgb) {
        Space::Linear
    } else {
        Space::Srgb
    };
    let theirs = student.bytes_in(space);
    let mut grader = Grader::new(&loaded.scene, space);
    let grade = grader
        .grade(&theirs, args.tolerance)
        .map_err(Failure::Message)?;
    if let Some(path) = &args.picture {
        write_picture(path, &grade, &theirs)?;
    }
    let shown = &grade.ranked[..grade.ranked.len().min(args.top as usize)];
    if args.json {
        let document = GradeDocument {
            version: GRADE_JSON_VERSION,
            image_size: [grade.width, grade.height],
            tolerance: args.tolerance,
            encoding: space.name(),
            differing_pixels: grade.differing,
            verdict: verdict_word(&grade.verdict()),
            explanations: shown.iter().map(|c| entry(c, grade.differing)).collect(),
            not_visible: grade.invisible.iter().map(|b| b.id).collect(),
            renders: grader.render_count,
        };
        return write_json_stdout(&document);
    }
    let mut out = format!(
        "student: {}\nreference: whitted's render of {} ({}x{}, compared in 8-bit {} values)\n",
        image.display(),
        scene.display(),
        grade.width,
        grade.height,
        space.name()
    );
    out.push_str(&report_text(&grade, shown, args.tolerance));
    out.push_str(&format!(
        "({} renders: the reference and every model that can show in this scene, alone and in pairs)\n",
        grader.render_count
    ));
    if let Some(path) = &args.picture {
        out.push_str(&format!(
            "picture: {} (student | reference | best model | residual x4)\n",
            path.display()
        ));
    }
    write_stdout(&out)
}

/// The diagnosis in words: the verdict, then each explanation with its share.
pub fn report_text(grade: &Grade, shown: &[Candidate], tolerance: u8) -> String {
    let total = u64::from(grade.width) * u64::from(grade.height);
    let mut out = String::new();
    if grade.differing == 0 {
        out.push_str(&format!(
            "verdict: the image matches the reference (no pixel differs by more than {tolerance} steps)\n"
        ));
        return out;
    }
    out.push_str(&format!(
        "{} of {total} pixels differ by more than {tolerance} steps\n",
        grade.differing
    ));
    match grade.verdict() {
        Verdict::Explained => out.push_str("verdict: explained by a classic bug\n"),
        _ => out.push_str(
            "verdict: no classic bug (alone or with another) explains half of the differing pixels: look at the picture\n",
        ),
    }
    for (n, candidate) in shown.iter().enumerate() {
        let score = &candidate.score;
        let words: Vec<&str> = candidate.bugs.iter().map(|b| b.words).collect();
        out.push_str(&format!(
            "\n{}. {} [{}]\n   explains {} of the {} differing pixels ({:.0}% net of {} it breaks), {:.0}% of the difference's energy\n",
            n + 1,
            words.join("; and "),
            candidate.id(),
            score.explained,
            grade.differing,
            100.0 * score.share(grade.differing),
            score.broken,
            100.0 * score.energy_share()
        ));
        for bug in &candidate.bugs {
            out.push_str(&format!("   handout: {}\n", bug.handout));
            out.push_str(&format!("   the student's tracer must: {}\n", bug.fix));
        }
        if !candidate.same_as.is_empty() {
            let ids: Vec<&str> = candidate.same_as.iter().map(|b| b.id).collect();
            out.push_str(&format!(
                "   (renders the same image here: {})\n",
                ids.join(", ")
            ));
        }
    }
    if !grade.invisible.is_empty() {
        let ids: Vec<&str> = grade.invisible.iter().map(|b| b.id).collect();
        out.push_str(&format!(
            "\nnot visible in this scene (a tracer with them renders it right): {}\n",
            ids.join(", ")
        ));
    }
    out
}

/// The four panels as a PNG, written atomically.
pub fn write_picture(path: &Path, grade: &Grade, student: &[u8]) -> Result<(), Failure> {
    let (width, height, bytes) = side_by_side(
        grade.width,
        grade.height,
        student,
        &grade.reference_image,
        &grade.best_image,
    );
    write_image(
        path,
        crate::cli::ImageFormat::Png,
        width,
        height,
        Pixels::Srgb8(bytes),
    )
    .map_err(Failure::Message)
}
