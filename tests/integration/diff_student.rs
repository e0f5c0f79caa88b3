//! `whitted diff SCENE --against-image STUDENT` as a teacher uses it (issue 28, part 3):
//! whitted's own images in every format it writes (the course's 8-bit linear TGA and PNG,
//! `render`'s sRGB PNG, TGA and PPM, and EXR) match the reference in 0 pixels, an image in
//! the other space draws a warning, a student's image made without shadow rays is read from
//! the student's side, naming the missing shadow ray and what blocks the light, and images
//! made with recursion stopped early, no specular term or lit back faces are read as such.

use std::path::Path;

use crate::support::{ok, run};
use serde_json::Value;

fn path(dir: &Path, name: &str) -> String {
    dir.join(name).to_str().unwrap().to_string()
}

const COURSE_SCENE: &str = "scenes/mit6837/lights-perspective.txt";

/// The course's switches `-shadows -bounces 4 -weight 0.01` as `--set`s.
const COURSE_SETS: [&str; 6] = [
    "--set",
    "shadows=opaque",
    "--set",
    "max_depth=4",
    "--set",
    "min_weight=0.01",
];

#[test]
fn the_courses_own_images_match_the_reference_in_every_pixel() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["ref.tga", "ref.png", "ref.ppm"] {
        let image = path(dir.path(), name);
        ok(&[
            "mit6837",
            "-input",
            COURSE_SCENE,
            "-size",
            "200",
            "200",
            "-output",
            &image,
            "-shadows",
            "-bounces",
            "4",
            "-weight",
            "0.01",
        ]);
        let mut args = vec![
            "diff",
            COURSE_SCENE,
            "--against-image",
            &image,
            "--width",
            "200",
            "--height",
            "200",
            "--tolerance",
            "0",
        ];
        args.extend(COURSE_SETS);
        let text = ok(&args);
        assert!(
            text.contains(
                "the images match: no pixel of 200x200 differs by more than 0 (8-bit linear steps)"
            ),
            "{name}: {text}"
        );
        // The switches are shown as the course's command line, for the teacher to check.
        assert!(
            text.contains("-size 200 200 -shadows -bounces 4 -weight 0.01` makes it"),
            "{text}"
        );
        args.push("--json");
        let report: Value = serde_json::from_str(&ok(&args)).unwrap();
        assert_eq!(report["version"], 2);
        assert_eq!(report["space"], "linear");
        assert_eq!(report["differing_pixels"], 0);
        // As sRGB the course's image differs almost everywhere.
        assert!(report["other_space_differing_pixels"].as_u64().unwrap() > 20_000);
    }
    // Compared in the wrong space (forced), the warning says which space fits.
    let image = path(dir.path(), "ref.tga");
    let mut args = vec![
        "diff",
        COURSE_SCENE,
        "--against-image",
        &image,
        "--width",
        "200",
        "--height",
        "200",
        "--srgb",
    ];
    args.extend(COURSE_SETS);
    let output = run(&args);
    assert_eq!(output.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("looks like linear 8-bit values") && stderr.contains("add --linear"),
        "{stderr}"
    );
}

#[test]
fn renders_in_png_tga_ppm_and_exr_match_the_reference_in_every_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let scene = "tests/diff/glass-a.scene";
    for name in ["x.png", "x.tga", "x.ppm", "x.exr"] {
        let image = path(dir.path(), name);
        ok(&["render", scene, "-o", &image, "--quiet"]);
        let text = ok(&["diff", scene, "--against-image", &image, "--tolerance", "0"]);
        assert!(
            text.contains("the images match") && text.contains("8-bit srgb steps"),
            "{name}: {text}"
        );
        let output = run(&["diff", scene, "--against-image", &image, "--tolerance", "0"]);
        assert!(output.stderr.is_empty(), "{name}: no warning expected");
    }
    // Something that is not an image is an error naming the file, exit 1.
    let output = run(&["diff", scene, "--against-image", scene]);
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("cannot read the student's image tests/diff/glass-a.scene"),
        "{stderr}"
    );
}

/// A student who cast no shadow rays: the largest region is read as the missing shadow,
/// naming the object in the way, and says what the tracer must do, not what to change in
/// the scene.
#[test]
fn a_student_without_shadow_rays_is_told_the_shadow_ray_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    // In whitted's language: the student's image rendered with shadows switched off.
    let scene = "scenes/shadows.scene";
    let student = path(dir.path(), "student.png");
    let size = ["--width", "160", "--height", "120"];
    let mut args = vec![
        "render",
        scene,
        "-o",
        &student,
        "--quiet",
        "--set",
        "shadows=none",
    ];
    args.extend(size);
    ok(&args);
    let mut args = vec!["diff", scene, "--against-image", &student, "--regions", "3"];
    args.extend(size);
    let text = ok(&args);
    assert_shadow_reading(&text);
    args.push("--json");
    let report: Value = serde_json::from_str(&ok(&args)).unwrap();
    let region = &report["regions"][0];
    assert_eq!(
        region["reading"]["behaviour"]["kind"], "shadows",
        "{region:#}"
    );
    assert_eq!(region["reading"]["behaviour"]["mode"], "none");
    assert_eq!(region["reading"]["direction"], "brighter");
    assert_eq!(region["reading"]["remaining_difference"], 0);
    let schema: Value =
        serde_json::from_str(&std::fs::read_to_string("docs/diff-image.schema.json").unwrap())
            .unwrap();
    let errors = crate::json_schema::validate(&schema, &report);
    assert!(errors.is_empty(), "{errors:#?}");

    // A 6.837 scene: the student's course-format image made without -shadows.
    let student = path(dir.path(), "student.tga");
    ok(&[
        "mit6837",
        "-input",
        COURSE_SCENE,
        "-size",
        "200",
        "200",
        "-output",
        &student,
        "-bounces",
        "4",
        "-weight",
        "0.01",
    ]);
    let mut args = vec![
        "diff",
        COURSE_SCENE,
        "--against-image",
        &student,
        "--width",
        "200",
        "--height",
        "200",
    ];
    args.extend(COURSE_SETS);
    let text = ok(&args);
    assert_shadow_reading(&text);
    assert!(text.contains("lights-perspective.txt:"), "{text}");
}

fn assert_shadow_reading(text: &str) {
    let first = text.split("\nregion 2").next().unwrap_or(text);
    assert!(first.contains("pixel ("), "{text}");
    assert!(first.contains("): student #"), "{text}");
    assert!(
        first.contains("student brighter: the reference is in the shadow of "),
        "{text}"
    );
    assert!(
        first.contains("the student cast no shadow ray there"),
        "{text}"
    );
    assert!(
        first.contains("the student's tracer must: for each light, cast a shadow ray"),
        "{text}"
    );
    assert!(!text.contains("fix:"), "{text}");
    assert!(!text.contains("whitted #"), "{text}");
}

/// The first region's reading of a course-format student image made by `course_flags`
/// (a student's tracer with that behaviour), against the reference made with `sets`.
fn course_reading(scene: &str, student_scene: &str, course_flags: &[&str], sets: &[&str]) -> Value {
    let dir = tempfile::tempdir().unwrap();
    let student = path(dir.path(), "student.tga");
    let mut args = vec![
        "mit6837",
        "-input",
        student_scene,
        "-size",
        "120",
        "120",
        "-output",
        &student,
    ];
    args.extend(course_flags);
    ok(&args);
    let mut args = vec![
        "diff",
        scene,
        "--against-image",
        &student,
        "--width",
        "120",
        "--height",
        "120",
        "--json",
    ];
    args.extend(sets);
    let report: Value = serde_json::from_str(&ok(&args)).unwrap();
    assert_eq!(report["space"], "linear");
    report["regions"][0]["reading"].clone()
}

/// The other main mistakes, each made by a real trace with that behaviour: recursion that
/// stops early, no specular term (the scene without its specular colours), back faces lit
/// without `-shade_back`; each read as that behaviour, exactly (0 steps left).
#[test]
fn depth_specular_and_back_face_mistakes_are_read_as_such() {
    let scene = "scenes/mit6837/reflect-refract.txt";
    let reading = course_reading(
        scene,
        scene,
        &["-shadows", "-bounces", "1"],
        &["--set", "shadows=opaque", "--set", "max_depth=4"],
    );
    assert_eq!(reading["behaviour"]["kind"], "depth", "{reading:#}");
    assert_eq!(reading["direction"], "darker");
    assert!(
        reading["behaviour"]["lowest"].as_u64().unwrap() <= 1,
        "{reading:#}"
    );
    assert!(
        reading["message"]
            .as_str()
            .unwrap()
            .contains("the student's tracer stopped recursing"),
        "{reading:#}"
    );
    assert!(reading["tracer"]
        .as_str()
        .unwrap()
        .contains("until depth 4"));
    assert_eq!(reading["remaining_difference"], 0);

    let scene = "scenes/mit6837/lights-perspective.txt";
    let dir = tempfile::tempdir().unwrap();
    let flat = dir.path().join("flat.txt");
    let text = std::fs::read_to_string(scene).unwrap();
    let without: String = text
        .lines()
        .filter(|l| !l.contains("specularColor") && !l.contains("exponent"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&flat, without).unwrap();
    let reading = course_reading(
        scene,
        flat.to_str().unwrap(),
        &["-shadows"],
        &["--set", "shadows=opaque"],
    );
    assert_eq!(reading["behaviour"]["kind"], "no_specular", "{reading:#}");
    assert!(
        reading["message"]
            .as_str()
            .unwrap()
            .contains("the reference has a specular highlight of light #0 on sphere"),
        "{reading:#}"
    );
    assert!(reading["location"].as_str().unwrap().starts_with(scene));

    let scene = "scenes/mit6837/back-faces.txt";
    let reading = course_reading(scene, scene, &["-shade_back"], &[]);
    assert_eq!(reading["behaviour"]["kind"], "shade_back", "{reading:#}");
    assert_eq!(reading["behaviour"]["on"], true);
    assert_eq!(reading["direction"], "brighter");
    assert!(
        reading["message"]
            .as_str()
            .unwrap()
            .contains("the student's tracer lit it"),
        "{reading:#}"
    );
}
