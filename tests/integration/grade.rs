//! `whitted grade` (issue 28, part 4) as a teacher uses it: for every student bug model, an
//! image whitted makes with that bug, at two scenes each, is diagnosed as
//! that bug first; a planted pair is diagnosed as the pair; a correct image matches; and a
//! generated class of 30 students (random models, some correct) gets every student's
//! diagnosis right, writes its report, and resumes instead of grading again.

use std::path::{Path, PathBuf};

use crate::support::{ok, run};
use serde_json::Value;

/// The scene made to show every model, and its two command lines (the second without
/// shadows, so that a highlight from a light behind a surface survives).
const BUGS_SCENE: &str = "scenes/mit6837/student-bugs.txt";
const LINE_A: &str =
    "-input scenes/mit6837/student-bugs.txt -size 96 72 -shadows -bounces 4 -weight 0.05";
const LINE_B: &str =
    "-input scenes/mit6837/student-bugs.txt -size 96 72 -bounces 3 -weight 0.3 -shade_back";
const REFLECT: &str =
    "-input scenes/mit6837/reflect-refract.txt -size 80 80 -shadows -bounces 4 -weight 0.01";
const GEM: &str = "-input scenes/mit6837/glass-gem.txt -size 80 80 -transparent_shadows -bounces 3 -weight 0.05 -shade_back";
const BACK: &str = "-input scenes/mit6837/back-faces.txt -size 80 80";

/// Renders `line` with `sets` (the bug) into `out`, the course's 8-bit linear TGA.
fn student_image(line: &str, sets: &[&str], out: &Path) {
    let mut args: Vec<&str> = vec!["mit6837"];
    args.extend(line.split_whitespace());
    let out = out.to_str().unwrap();
    args.extend(["-output", out]);
    for set in sets {
        args.extend(["--set", set]);
    }
    ok(&args);
}

fn grade(line: &str, image: &Path) -> Value {
    let text = ok(&[
        "grade",
        "--command",
        line,
        image.to_str().unwrap(),
        "--json",
    ]);
    serde_json::from_str(&text).unwrap()
}

fn top(document: &Value) -> String {
    document["explanations"][0]["id"]
        .as_str()
        .unwrap_or("(none)")
        .to_string()
}

/// Each model, the settings that make it, and two command lines where it shows.
const MODELS: &[(&str, &[&str], [&str; 2])] = &[
    ("no-shadow-offset", &["epsilon=0"], [LINE_B, REFLECT]),
    ("no-shadows", &["shadows=none"], [LINE_A, REFLECT]),
    (
        "opaque-shadows",
        &["shadows=opaque"],
        [GEM, REFLECT_FILTERED],
    ),
    ("shadows-not-asked", &["shadows=opaque"], [LINE_B, HALL]),
    ("back-faces-lit", &["shade_back=on"], [LINE_A, BACK]),
    ("back-faces-not-shaded", &["shade_back=off"], [LINE_B, GEM]),
    ("back-face-ambient", &["back_ambient=on"], [LINE_A, BACK]),
    (
        "normals-not-flipped",
        &["flip_normals=off"],
        [LINE_A, REFLECT],
    ),
    (
        "ior-not-inverted",
        &["exit_ior=uninverted"],
        [LINE_A, REFLECT],
    ),
    (
        "no-total-internal-reflection",
        &["total_internal_reflection=off"],
        [LINE_A, GEM],
    ),
    ("one-bounce-fewer", &["max_depth=3"], [LINE_A, HALL]),
    ("one-bounce-more", &["max_depth=5"], [LINE_A, HALL]),
    ("no-weight-cutoff", &["min_weight=0"], [LINE_B, HALL_HEAVY]),
    ("no-ambient", &["ambient=0"], [LINE_A, BACK]),
    ("highlight-gate", &["highlight_gate=on"], [LINE_B, HALL]),
    ("highlight-model", &["highlight=phong"], [LINE_A, REFLECT]),
    ("pixel-corner", &["sample_position=corner"], [LINE_A, BACK]),
    ("no-attenuation", &["light_falloff=off"], [LINE_A, REFLECT]),
    ("fresnel", &["fresnel_rule=schlick"], [LINE_A, GEM]),
    ("energy-scaled", &["energy_clamp=on"], [LINE_A, HALL]),
];

const REFLECT_FILTERED: &str =
    "-input scenes/mit6837/reflect-refract.txt -size 80 80 -transparent_shadows -bounces 2";
/// Facing mirrors, a shiny ball lit from behind and glass whose kr + kt is over 1.
const HALL: &str =
    "-input scenes/mit6837/hall-of-mirrors.txt -size 80 60 -bounces 4 -weight 0.1 -shade_back";
const HALL_HEAVY: &str =
    "-input scenes/mit6837/hall-of-mirrors.txt -size 80 60 -bounces 6 -weight 0.3 -shade_back";

#[test]
fn every_student_bug_model_is_diagnosed_first_at_two_command_lines() {
    let dir = tempfile::tempdir().unwrap();
    let mut wrong = Vec::new();
    let mut scenes_per_model = Vec::new();
    for (model, sets, lines) in MODELS {
        for (k, line) in lines.iter().enumerate() {
            let image = dir.path().join(format!("{model}-{k}.tga"));
            student_image(line, sets, &image);
            let document = grade(line, &image);
            if document["verdict"] != "explained" || top(&document) != *model {
                wrong.push(format!(
                    "{model} at `{line}`: {} {}",
                    document["verdict"],
                    top(&document)
                ));
            }
        }
        let scene = |line: &str| line.split_whitespace().nth(1).map(str::to_string);
        scenes_per_model.push((model, scene(lines[0]) != scene(lines[1])));
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert!(
        scenes_per_model.iter().all(|(_, two)| *two),
        "{scenes_per_model:?}"
    );
}

#[test]
fn gamma_written_where_linear_is_expected_is_diagnosed() {
    // `whitted render` writes sRGB: the course expects colour times 255.
    let dir = tempfile::tempdir().unwrap();
    for (scene, sets, line) in [
        (
            BUGS_SCENE,
            &[
                "width=96",
                "height=72",
                "shadows=opaque",
                "max_depth=4",
                "min_weight=0.05",
            ][..],
            LINE_A,
        ),
        (
            "scenes/mit6837/back-faces.txt",
            &["width=80", "height=80"][..],
            BACK,
        ),
    ] {
        let image = dir.path().join("srgb.png");
        let mut args = vec!["render", scene, "--quiet", "-o", image.to_str().unwrap()];
        for set in sets {
            args.extend(["--set", set]);
        }
        ok(&args);
        let document = grade(line, &image);
        assert_eq!(top(&document), "gamma", "{scene}: {document}");
    }
}

#[test]
fn a_planted_pair_of_bugs_is_diagnosed_as_that_pair() {
    let dir = tempfile::tempdir().unwrap();
    for (sets, expected, line) in [
        (
            &["epsilon=0", "ambient=0"][..],
            ["no-ambient", "no-shadow-offset"],
            LINE_A,
        ),
        (
            &["light_falloff=off", "sample_position=corner"][..],
            ["no-attenuation", "pixel-corner"],
            LINE_A,
        ),
        // The second bug matches nothing alone here (the missing ambient changes every
        // pixel the corner sample does): found only by pairing the best with every model.
        (
            &["ambient=0", "sample_position=corner"][..],
            ["no-ambient", "pixel-corner"],
            HALL,
        ),
    ] {
        let image = dir.path().join("pair.tga");
        student_image(line, sets, &image);
        let document = grade(line, &image);
        let mut ids: Vec<String> = top(&document).split('+').map(str::to_string).collect();
        ids.sort();
        let mut expected = expected.map(str::to_string).to_vec();
        expected.sort();
        assert_eq!(ids, expected, "{document}");
        assert!(document["explanations"][0]["share"].as_f64().unwrap() > 0.9);
    }
}

#[test]
fn a_correct_image_matches_and_the_text_and_picture_say_so() {
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("right.tga");
    student_image(LINE_A, &[], &image);
    assert_eq!(grade(LINE_A, &image)["verdict"], "matches");

    // The text of a bug, with the picture of four panels.
    let buggy = dir.path().join("acne.tga");
    student_image(LINE_A, &["epsilon=0"], &buggy);
    let picture = dir.path().join("grade.png");
    let text = ok(&[
        "grade",
        "--command",
        LINE_A,
        buggy.to_str().unwrap(),
        "--picture",
        picture.to_str().unwrap(),
    ]);
    assert!(
        text.contains("verdict: explained by a classic bug"),
        "{text}"
    );
    assert!(text.contains("shadow acne"), "{text}");
    assert!(text.contains("handout: assignment 4"), "{text}");
    let panels = image::open(&picture).unwrap();
    assert_eq!((panels.width(), panels.height()), (96 * 4 + 4 * 3, 72));
}

#[test]
fn bad_grade_requests_get_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let small = dir.path().join("small.tga");
    student_image(
        "-input scenes/mit6837/back-faces.txt -size 10 10",
        &[],
        &small,
    );
    let output = run(&["grade", "--command", BACK, small.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("is 10x10 but the scene renders 80x80"),
        "{stderr}"
    );

    let output = run(&["grade", "--class", dir.path().to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let missing = dir.path().join("nothing.txt");
    let output = run(&[
        "grade",
        "--class",
        dir.path().to_str().unwrap(),
        "--commands",
        missing.to_str().unwrap(),
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&output.stderr).contains("cannot read"));
}

/// A deterministic stream of small numbers (no random crate in the tests).
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) % n as u64) as usize
    }
}

#[test]
fn a_class_of_thirty_is_graded_right_and_a_rerun_reuses_the_records() {
    let dir = tempfile::tempdir().unwrap();
    let class = dir.path().join("class");
    std::fs::create_dir(&class).unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let commands = dir.path().join("commands.txt");
    let scene = root.join(BUGS_SCENE);
    let scene = scene.to_str().unwrap();
    let lines = [
        format!("raytracer -input {scene} -size 64 48 -output bugs_a.tga -shadows -bounces 4 -weight 0.05"),
        format!("raytracer -input {scene} -size 64 48 -output bugs_b.tga -bounces 2 -weight 0.01"),
    ];
    std::fs::write(
        &commands,
        format!("# assignment 4\n{}\n\n{}\n", lines[0], lines[1]),
    )
    .unwrap();
    // Models that show at both command lines, and "none" for a correct student.
    let models: &[(&str, &str)] = &[
        ("none", ""),
        ("no-ambient", "ambient=0"),
        ("no-attenuation", "light_falloff=off"),
        ("pixel-corner", "sample_position=corner"),
        ("highlight-model", "highlight=phong"),
        ("normals-not-flipped", "flip_normals=off"),
        ("ior-not-inverted", "exit_ior=uninverted"),
        ("fresnel", "fresnel_rule=schlick"),
        ("back-faces-lit", "shade_back=on"),
    ];
    let mut lcg = Lcg(28);
    let mut planted = Vec::new();
    for n in 0..30 {
        let name = format!("student{n:02}");
        let folder = class.join(&name);
        std::fs::create_dir(&folder).unwrap();
        let (model, set) = models[lcg.below(models.len())];
        for line in &lines {
            let words: Vec<&str> = line.split_whitespace().skip(1).collect();
            let mut args = vec!["mit6837"];
            let out = folder.join(if line.contains("bugs_a") {
                "bugs_a.tga"
            } else {
                "bugs_b.tga"
            });
            let out = out.to_str().unwrap().to_string();
            for (i, word) in words.iter().enumerate() {
                // The student's own output path instead of the line's.
                if i > 0 && words[i - 1] == "-output" {
                    args.push(&out);
                } else {
                    args.push(word);
                }
            }
            if !set.is_empty() {
                args.extend(["--set", set]);
            }
            ok(&args);
        }
        planted.push((name, model));
    }
    let report = dir.path().join("report");
    let grade_class = || {
        ok(&[
            "grade",
            "--class",
            class.to_str().unwrap(),
            "--commands",
            commands.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ])
    };
    let summary = grade_class();
    let scores: Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("scores.json")).unwrap())
            .unwrap();
    let students = scores["students"].as_array().unwrap();
    assert_eq!(students.len(), 30);
    for (record, (name, model)) in students.iter().zip(&planted) {
        assert_eq!(record["student"], *name);
        for image in record["images"].as_array().unwrap() {
            if *model == "none" {
                assert_eq!(image["verdict"], "matches", "{name}: {image}");
            } else {
                assert_eq!(image["diagnosis"], *model, "{name}: {image}");
            }
        }
    }
    let correct = planted.iter().filter(|(_, m)| *m == "none").count();
    assert!(correct > 0 && correct < 30, "{correct} correct students");
    assert_eq!(scores["correct_students"], correct);
    assert!(
        summary.contains(&format!("{correct} students match the reference")),
        "{summary}"
    );
    let html = std::fs::read_to_string(report.join("index.html")).unwrap();
    assert!(
        html.contains("student29") && html.contains("pictures/"),
        "{html}"
    );
    let csv = std::fs::read_to_string(report.join("scores.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 30 * 2);

    // A second run reuses every record; a changed image is graded again.
    let again = grade_class();
    assert!(again.contains("graded 0, reused 30"), "{again}");
    let first = &planted[0].0;
    let words: Vec<&str> = lines[0].split_whitespace().skip(1).collect();
    let out = class.join(first).join("bugs_a.tga");
    let out = out.to_str().unwrap().to_string();
    let mut args = vec!["mit6837"];
    for (i, word) in words.iter().enumerate() {
        args.push(if i > 0 && words[i - 1] == "-output" {
            &out
        } else {
            word
        });
    }
    args.extend(["--set", "ambient=0"]);
    ok(&args);
    let third = grade_class();
    assert!(third.contains("graded 1, reused 29"), "{third}");
}

#[test]
fn a_scene_in_whitted_s_language_is_graded_in_srgb() {
    // `whitted render` writes sRGB, the default comparison for the language's scenes.
    let dir = tempfile::tempdir().unwrap();
    let image = dir.path().join("student.png");
    let size = ["--width", "96", "--height", "72"];
    let mut args = vec![
        "render",
        "scenes/whitted.scene",
        "--quiet",
        "--set",
        "shadows=none",
    ];
    args.extend(size);
    args.extend(["-o", image.to_str().unwrap()]);
    ok(&args);
    let mut args = vec![
        "grade",
        "scenes/whitted.scene",
        image.to_str().unwrap(),
        "--json",
    ];
    args.extend(size);
    let document: Value = serde_json::from_str(&ok(&args)).unwrap();
    assert_eq!(document["encoding"], "srgb");
    assert_eq!(top(&document), "no-shadows", "{document}");
}

#[test]
fn images_written_upside_down_or_with_red_and_blue_swapped_are_diagnosed() {
    let dir = tempfile::tempdir().unwrap();
    for line in [LINE_A, REFLECT] {
        let right = dir.path().join("right.tga");
        student_image(line, &[], &right);
        let image = image::open(&right).unwrap().to_rgb8();
        let flipped = image::imageops::flip_vertical(&image);
        let mut swapped = image.clone();
        for pixel in swapped.pixels_mut() {
            pixel.0.swap(0, 2);
        }
        for (model, picture) in [("upside-down", flipped), ("red-blue-swapped", swapped)] {
            let path = dir.path().join(format!("{model}.png"));
            picture.save(&path).unwrap();
            let document = grade(line, &path);
            assert_eq!(top(&document), model, "{line}: {document}");
        }
    }
}
