//! `whitted grade --class DIR --commands FILE`: every student's images (one folder per
//! student, named as the assignment's command lines write them) graded against the
//! references those command lines make. Writes a report folder: `index.html` with the
//! pictures, `scores.csv`, `scores.json`, and one record per student in `students/`, which
//! a rerun reuses when the student's images have not changed (so an interrupted class
//! resumes where it stopped). Each command line's renders are shared by every student.

use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use whitted_explain::grade::{Grader, Verdict};
use whitted_ir::ValidScene;

use crate::cli::{GradeArgs, SceneArgs};
use crate::grade_cmd::{entry, verdict_word, write_picture, ExplanationEntry};
use crate::mit6837_cmd::{self, Request};
use crate::scene_input::{load_scene_with, write_stdout};
use crate::student_image::{self, Space};
use crate::Failure;

/// The version of `scores.json` and of the student records.
const CLASS_JSON_VERSION: u32 = 1;
/// At most this many command lines and students: a typo in a path should not start a
/// week of renders.
const MAX_COMMANDS: usize = 200;
const MAX_STUDENTS: usize = 2000;

/// One command line of the assignment.
struct Assignment {
    /// The line as written, for the report.
    line: String,
    /// The image name students' folders hold.
    image: String,
    scene: ValidScene,
    space: Space,
}

/// One student's image, graded.
#[derive(Serialize, Deserialize, Clone)]
struct ImageResult {
    image: String,
    /// `matches`, `explained`, `unexplained`, `missing` or `unreadable`.
    verdict: String,
    differing_pixels: u64,
    /// The best explanation's id (`a+b` for a pair) when the verdict is `explained`.
    diagnosis: Option<String>,
    explanations: Vec<ExplanationEntry>,
    /// The picture, relative to the report folder.
    picture: Option<String>,
    /// Why the image could not be graded.
    problem: Option<String>,
}

/// One student's record (`students/NAME.json`).
#[derive(Serialize, Deserialize, Clone)]
struct StudentRecord {
    version: u32,
    student: String,
    /// Each image's name, size and modification time when graded: a rerun grades the
    /// student again only when these changed.
    fingerprint: Vec<(String, u64, u128)>,
    images: Vec<ImageResult>,
}

impl StudentRecord {
    /// The classic bugs the student's images show (each once).
    fn bugs(&self) -> Vec<String> {
        let mut bugs: Vec<String> = Vec::new();
        for image in &self.images {
            if let Some(diagnosis) = &image.diagnosis {
                for id in diagnosis.split('+') {
                    if !bugs.iter().any(|b| b == id) {
                        bugs.push(id.to_string());
                    }
                }
            }
        }
        bugs
    }

    fn all_match(&self) -> bool {
        self.images.iter().all(|i| i.verdict == "matches")
    }
}

#[derive(Serialize)]
struct ClassDocument<'a> {
    version: u32,
    commands: Vec<&'a str>,
    students: &'a [StudentRecord],
    /// Each bug and how many students show it.
    summary: Vec<(String, usize)>,
    correct_students: usize,
    figures: Figures,
}

#[derive(Serialize, Clone, Copy)]
struct Figures {
    students: usize,
    graded_now: usize,
    reused: usize,
    images: usize,
    renders: u32,
    wall_seconds: f64,
    cpu_seconds: f64,
}

/// One course command line, the program's name (any words before the first flag) dropped.
fn course_run(line: &str) -> Result<mit6837_cmd::CourseRun, String> {
    let words: Vec<OsString> = line
        .split_whitespace()
        .skip_while(|w| !w.starts_with('-'))
        .map(OsString::from)
        .collect();
    match mit6837_cmd::parse(&words)? {
        Request::Run(run) => Ok(*run),
        Request::Help => Err("-help is not a command line to grade".into()),
    }
}

/// The scene and course options of a command line, its `-input` relative to `base`.
pub fn course_line(
    line: &str,
    base: &Path,
) -> Result<(SceneArgs, whitted_mit6837::CourseOptions), String> {
    let run = course_run(line)?;
    let scene_args = SceneArgs {
        scene: base.join(&run.input),
        define: Vec::new(),
        set: run.sets.clone(),
        frame: None,
    };
    Ok((scene_args, run.options))
}

/// Reads the command lines: blank lines and `#` comments skipped, the program's name (any
/// words before the first flag) dropped.
fn read_commands(path: &Path) -> Result<Vec<Assignment>, Failure> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Failure::Message(format!("cannot read {}: {e}", path.display())))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let at =
            |message: String| Failure::Usage(format!("{}:{}: {message}", path.display(), n + 1));
        if out.len() == MAX_COMMANDS {
            return Err(at(format!("more than {MAX_COMMANDS} command lines")));
        }
        let run = course_run(line).map_err(at)?;
        let Some(output) = run.output.as_ref().and_then(|o| o.file_name()) else {
            return Err(at("no -output: the line names no image to grade".into()));
        };
        let image = output.to_string_lossy().into_owned();
        if out.iter().any(|a: &Assignment| a.image == image) {
            return Err(at(format!("{image} is written by two command lines")));
        }
        let scene_args = SceneArgs {
            scene: base.join(&run.input),
            define: Vec::new(),
            set: run.sets.clone(),
            frame: None,
        };
        let loaded = load_scene_with(&scene_args, true, &run.options)?;
        out.push(Assignment {
            line: line.to_string(),
            image,
            scene: loaded.scene,
            space: Space::Linear,
        });
    }
    if out.is_empty() {
        return Err(Failure::Usage(format!(
            "{} has no command lines",
            path.display()
        )));
    }
    Ok(out)
}

/// The student's file for `image`: the name itself, or the same stem as PNG, TGA or PPM.
fn find_image(dir: &Path, image: &str) -> Option<PathBuf> {
    let exact = dir.join(image);
    if exact.is_file() {
        return Some(exact);
    }
    let stem = Path::new(image).file_stem()?;
    ["png", "tga", "ppm"]
        .iter()
        .map(|ext| dir.join(stem).with_extension(ext))
        .find(|p| p.is_file())
}

fn fingerprint(dir: &Path, assignments: &[Assignment]) -> Vec<(String, u64, u128)> {
    assignments
        .iter()
        .map(|a| {
            let meta = find_image(dir, &a.image).and_then(|p| std::fs::metadata(p).ok());
            let size = meta.as_ref().map_or(0, |m| m.len());
            let modified = meta
                .and_then(|m| m.modified().ok())
                .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                .map_or(0, |d| d.as_nanos());
            (a.image.clone(), size, modified)
        })
        .collect()
}

fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Writes `bytes` to `path` whole or not at all.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Failure> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let cannot = |e: &dyn std::fmt::Display| {
        Failure::Message(format!("cannot write {}: {e}", path.display()))
    };
    let mut file = tempfile::NamedTempFile::new_in(dir).map_err(|e| cannot(&e))?;
    std::io::Write::write_all(&mut file, bytes).map_err(|e| cannot(&e))?;
    file.persist(path).map_err(|e| cannot(&e.error))?;
    Ok(())
}

fn grade_student(
    name: &str,
    dir: &Path,
    assignments: &[Assignment],
    graders: &mut [Grader<'_>],
    report: &Path,
    tolerance: u8,
) -> Result<Vec<ImageResult>, Failure> {
    let mut images = Vec::new();
    for (assignment, grader) in assignments.iter().zip(graders.iter_mut()) {
        let mut result = ImageResult {
            image: assignment.image.clone(),
            verdict: "missing".into(),
            differing_pixels: 0,
            diagnosis: None,
            explanations: Vec::new(),
            picture: None,
            problem: None,
        };
        let Some(path) = find_image(dir, &assignment.image) else {
            result.problem = Some(format!("no {} in {}", assignment.image, dir.display()));
            images.push(result);
            continue;
        };
        let settings = &assignment.scene.scene().settings;
        let student = match student_image::read(&path) {
            Ok(s) if (s.width, s.height) == (settings.width, settings.height) => s,
            Ok(s) => {
                result.verdict = "unreadable".into();
                result.problem = Some(format!(
                    "{} is {}x{}, the command line renders {}x{}",
                    path.display(),
                    s.width,
                    s.height,
                    settings.width,
                    settings.height
                ));
                images.push(result);
                continue;
            }
            Err(failure) => {
                result.verdict = "unreadable".into();
                result.problem = failure.message().map(str::to_string);
                images.push(result);
                continue;
            }
        };
        let theirs = student.bytes_in(assignment.space);
        let grade = grader.grade(&theirs, tolerance).map_err(Failure::Message)?;
        result.verdict = verdict_word(&grade.verdict()).into();
        result.differing_pixels = grade.differing;
        result.diagnosis = grade.best().map(|c| c.id());
        result.explanations = grade
            .ranked
            .iter()
            .take(3)
            .map(|c| entry(c, grade.differing))
            .collect();
        if grade.verdict() != Verdict::Matches {
            let stem = Path::new(&assignment.image)
                .file_stem()
                .map_or("image".into(), |s| s.to_string_lossy().into_owned());
            let picture = format!("pictures/{}--{}.png", file_safe(name), file_safe(&stem));
            write_picture(&report.join(&picture), &grade, &theirs)?;
            result.picture = Some(picture);
        }
        images.push(result);
    }
    Ok(images)
}

pub fn grade_class(args: &GradeArgs, class: &Path) -> Result<(), Failure> {
    let started = Instant::now();
    let cpu_before = crate::cpu_time::process_cpu_seconds();
    let Some(commands) = &args.commands else {
        return Err(Failure::Usage("--class needs --commands FILE".into()));
    };
    let mut assignments = read_commands(commands)?;
    for assignment in &mut assignments {
        if args.srgb {
            assignment.space = Space::Srgb;
        }
    }
    let report = args
        .report
        .clone()
        .unwrap_or_else(|| class.join("grade-report"));
    for dir in [
        report.clone(),
        report.join("students"),
        report.join("pictures"),
    ] {
        std::fs::create_dir_all(&dir)
            .map_err(|e| Failure::Message(format!("cannot create {}: {e}", dir.display())))?;
    }
    let entries = std::fs::read_dir(class)
        .map_err(|e| Failure::Message(format!("cannot read {}: {e}", class.display())))?;
    let report_canonical = report.canonicalize().ok();
    let mut students: Vec<(String, PathBuf)> = entries
        .filter_map(Result::ok)
        .filter(|e| e.path().is_dir())
        .filter(|e| e.path().canonicalize().ok() != report_canonical)
        .map(|e| (e.file_name().to_string_lossy().into_owned(), e.path()))
        .collect();
    students.sort();
    if students.is_empty() {
        return Err(Failure::Usage(format!(
            "{} has no student folders (one folder of images per student)",
            class.display()
        )));
    }
    if students.len() > MAX_STUDENTS {
        return Err(Failure::Usage(format!(
            "{} has {} folders, more than the {MAX_STUDENTS} students one run grades",
            class.display(),
            students.len()
        )));
    }
    let mut graders: Vec<Grader<'_>> = assignments
        .iter()
        .map(|a| Grader::new(&a.scene, a.space))
        .collect();
    let mut records = Vec::new();
    let (mut graded_now, mut reused) = (0, 0);
    for (n, (name, dir)) in students.iter().enumerate() {
        let record_path = report
            .join("students")
            .join(format!("{}.json", file_safe(name)));
        let print = fingerprint(dir, &assignments);
        let previous: Option<StudentRecord> = std::fs::read_to_string(&record_path)
            .ok()
            .and_then(|text| serde_json::from_str(&text).ok())
            .filter(|r: &StudentRecord| {
                r.version == CLASS_JSON_VERSION && r.fingerprint == print && r.student == *name
            });
        let record = match previous {
            Some(record) => {
                reused += 1;
                record
            }
            None => {
                let images = grade_student(
                    name,
                    dir,
                    &assignments,
                    &mut graders,
                    &report,
                    args.tolerance,
                )?;
                let record = StudentRecord {
                    version: CLASS_JSON_VERSION,
                    student: name.clone(),
                    fingerprint: print,
                    images,
                };
                let json = serde_json::to_vec_pretty(&record)
                    .map_err(|e| Failure::Message(e.to_string()))?;
                write_atomic(&record_path, &json)?;
                graded_now += 1;
                record
            }
        };
        eprintln!(
            "[{}/{}] {name}: {}",
            n + 1,
            students.len(),
            student_line(&record)
        );
        records.push(record);
    }
    let figures = Figures {
        students: records.len(),
        graded_now,
        reused,
        images: records.len() * assignments.len(),
        renders: graders.iter().map(|g| g.render_count).sum(),
        wall_seconds: started.elapsed().as_secs_f64(),
        cpu_seconds: crate::cpu_time::process_cpu_seconds() - cpu_before,
    };
    let summary = summary(&records);
    let correct = records.iter().filter(|r| r.all_match()).count();
    let document = ClassDocument {
        version: CLASS_JSON_VERSION,
        commands: assignments.iter().map(|a| a.line.as_str()).collect(),
        students: &records,
        summary: summary.clone(),
        correct_students: correct,
        figures,
    };
    let json = serde_json::to_vec_pretty(&document).map_err(|e| Failure::Message(e.to_string()))?;
    write_atomic(&report.join("scores.json"), &json)?;
    write_atomic(&report.join("scores.csv"), csv(&records).as_bytes())?;
    write_atomic(
        &report.join("index.html"),
        html(&assignments, &records, &summary, correct, figures).as_bytes(),
    )?;
    let mut out = format!(
        "{} students, {} images: {correct} students match the reference everywhere\n",
        records.len(),
        figures.images
    );
    for (bug, count) in &summary {
        let words = whitted_explain::grade::models::bug(bug).map_or("", |b| b.words);
        let _ = writeln!(
            out,
            "  {count:>4} student{} {bug}: {words}",
            if *count == 1 { " " } else { "s" }
        );
    }
    let _ = writeln!(
        out,
        "graded {graded_now}, reused {reused} earlier records; {} renders, {:.1} s wall, {:.1} s CPU\nreport: {}",
        figures.renders,
        figures.wall_seconds,
        figures.cpu_seconds,
        report.join("index.html").display()
    );
    write_stdout(&out)
}

fn student_line(record: &StudentRecord) -> String {
    if record.all_match() {
        return "matches the reference".into();
    }
    let bugs = record.bugs();
    let unexplained = record
        .images
        .iter()
        .filter(|i| i.verdict != "matches" && i.diagnosis.is_none())
        .count();
    let mut parts = Vec::new();
    if !bugs.is_empty() {
        parts.push(bugs.join(", "));
    }
    if unexplained > 0 {
        parts.push(format!("{unexplained} image(s) unexplained or missing"));
    }
    parts.join("; ")
}

/// Each bug with how many students show it, most first.
fn summary(records: &[StudentRecord]) -> Vec<(String, usize)> {
    let mut counts: Vec<(String, usize)> = Vec::new();
    for record in records {
        for bug in record.bugs() {
            match counts.iter_mut().find(|(b, _)| *b == bug) {
                Some((_, n)) => *n += 1,
                None => counts.push((bug, 1)),
            }
        }
    }
    counts.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    counts
}

fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

fn csv(records: &[StudentRecord]) -> String {
    let mut out = String::from("student,image,verdict,diagnosis,share,differing_pixels,problem\n");
    for record in records {
        for image in &record.images {
            let share = image.explanations.first().map_or(0.0, |e| e.share);
            let _ = writeln!(
                out,
                "{},{},{},{},{:.3},{},{}",
                csv_field(&record.student),
                csv_field(&image.image),
                image.verdict,
                csv_field(image.diagnosis.as_deref().unwrap_or("")),
                share,
                image.differing_pixels,
                csv_field(image.problem.as_deref().unwrap_or(""))
            );
        }
    }
    out
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn html(
    assignments: &[Assignment],
    records: &[StudentRecord],
    summary: &[(String, usize)],
    correct: usize,
    figures: Figures,
) -> String {
    let mut out = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>whitted grade: class report</title>\n<style>\nbody{font-family:sans-serif;margin:1.5em;color:#222}\ntable{border-collapse:collapse}\ntd,th{border:1px solid #ccc;padding:4px 8px;vertical-align:top}\nth{background:#eee}\n.matches{color:#176f2c}.explained{color:#8a4b00}.unexplained,.missing,.unreadable{color:#a01010}\nimg{image-rendering:pixelated;max-width:420px;display:block;margin-top:4px}\ncode{background:#f4f4f4}\n</style></head><body>\n<h1>Class report</h1>\n",
    );
    let _ = writeln!(
        out,
        "<p>{} students, {} images; {correct} students match the reference in every image. {} renders, {:.1} s wall, {:.1} s CPU.</p>",
        figures.students, figures.images, figures.renders, figures.wall_seconds, figures.cpu_seconds
    );
    out.push_str("<h2>Command lines</h2>\n<ul>\n");
    for a in assignments {
        let _ = writeln!(out, "<li><code>{}</code></li>", escape(&a.line));
    }
    out.push_str("</ul>\n<h2>Which bugs, how many students</h2>\n<table><tr><th>students</th><th>bug</th><th>handout</th></tr>\n");
    for (bug, count) in summary {
        let model = whitted_explain::grade::models::bug(bug);
        let _ = writeln!(
            out,
            "<tr><td>{count}</td><td><b>{}</b>: {}</td><td>{}</td></tr>",
            escape(bug),
            escape(model.map_or("", |b| b.words)),
            escape(model.map_or("", |b| b.handout))
        );
    }
    out.push_str("</table>\n<h2>Students</h2>\n<p>Each picture: student | reference | best model | residual (x4).</p>\n<table><tr><th>student</th>");
    for a in assignments {
        let _ = write!(out, "<th>{}</th>", escape(&a.image));
    }
    out.push_str("</tr>\n");
    for record in records {
        let _ = write!(out, "<tr><td><b>{}</b></td>", escape(&record.student));
        for image in &record.images {
            let _ = write!(
                out,
                "<td><span class=\"{}\">{}</span>",
                escape(&image.verdict),
                escape(&image.verdict)
            );
            if let Some(best) = image
                .explanations
                .first()
                .filter(|_| image.diagnosis.is_some())
            {
                let _ = write!(
                    out,
                    ": <b>{}</b> ({:.0}% of {} differing pixels)<br>{}",
                    escape(&best.id),
                    100.0 * best.share,
                    image.differing_pixels,
                    escape(&best.words.join("; and "))
                );
            } else if image.verdict == "unexplained" {
                let _ = write!(out, " ({} differing pixels)", image.differing_pixels);
            }
            if let Some(problem) = &image.problem {
                let _ = write!(out, "<br>{}", escape(problem));
            }
            if let Some(picture) = &image.picture {
                let _ = write!(
                    out,
                    "<img src=\"{}\" alt=\"student, reference, best model, residual\">",
                    escape(picture)
                );
            }
            out.push_str("</td>");
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</table>\n</body></html>\n");
    out
}
