//! The MIT 6.837 front end through the real binary: `whitted mit6837` with the course's
//! command lines (images, depth and normals as the course wrote them, linear 8-bit), every
//! other command reading a `.txt` scene by its content, `--set` on it, and errors located in
//! the `.txt` file with the documented exit codes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn whitted(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("NO_COLOR", "1")
        .args(args)
        .output()
        .expect("the whitted binary runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn path_in(dir: &Path, name: &str) -> String {
    dir.join(name).to_string_lossy().into_owned()
}

/// The RGB bytes of an uncompressed 24-bit TGA (rows top first), after checking its header.
fn read_tga(path: &str) -> (u32, u32, Vec<u8>) {
    let bytes = std::fs::read(path).expect("the TGA exists");
    assert_eq!(bytes[2], 2, "uncompressed true colour");
    assert_eq!(bytes[16], 24, "24 bits per pixel");
    let width = u32::from(u16::from_le_bytes([bytes[12], bytes[13]]));
    let height = u32::from(u16::from_le_bytes([bytes[14], bytes[15]]));
    let row = width as usize * 3;
    // Bottom-up BGR in the file.
    let rgb = bytes[18..]
        .chunks_exact(row)
        .rev()
        .flat_map(|line| line.chunks_exact(3).flat_map(|p| [p[2], p[1], p[0]]))
        .collect();
    (width, height, rgb)
}

fn pixel(rgb: &[u8], width: u32, x: u32, y: u32) -> [u8; 3] {
    let i = ((y * width + x) * 3) as usize;
    [rgb[i], rgb[i + 1], rgb[i + 2]]
}

const SPHERES: &str = "scenes/mit6837/spheres-orthographic.txt";

#[test]
fn an_assignment_command_line_writes_the_course_s_images() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (out, depth, normals) = (
        path_in(dir.path(), "out.tga"),
        path_in(dir.path(), "depth.tga"),
        path_in(dir.path(), "normals.ppm"),
    );
    let output = whitted(&[
        "mit6837", "-input", SPHERES, "-size", "120", "120", "-output", &out, "-depth", "8.5",
        "10", &depth, "-normals", &normals,
    ]);
    assert!(output.status.success(), "{}", stderr(&output));

    let (width, height, rgb) = read_tga(&out);
    assert_eq!((width, height), (120, 120));
    // The background (0.1, 0.1, 0.2) as linear bytes: colour times 255, no sRGB curve.
    assert_eq!(pixel(&rgb, width, 0, 0), [26, 26, 51]);
    // The red ball (1, 0.2, 0.2) near its centre, lit by ambient 0.2 and the light at
    // N·L = 0.82: linear 0.2 + 0.8·0.82 = 0.856 red (218), 0.2·0.856 = 0.171 green and blue.
    assert_eq!(pixel(&rgb, width, 31, 74), [218, 44, 44]);

    // Depth: the ball's front is at t = 9 from the camera at z = 10, between 8.5 (white)
    // and 10 (black): (10 - 9) / 1.5 = 0.667 of white. Nothing hit: black.
    let (_, _, depth_rgb) = read_tga(&depth);
    assert_eq!(pixel(&depth_rgb, width, 31, 74), [170; 3]);
    assert_eq!(pixel(&depth_rgb, width, 0, 0), [0; 3]);

    // Normals: |n| of (0.0125, -0.0042, 0.9999) there, as a PPM.
    let ppm = std::fs::read(&normals).expect("the normals image");
    let header = b"P6\n120 120\n255\n";
    assert!(ppm.starts_with(header));
    let i = header.len() + ((74 * 120 + 31) * 3) as usize;
    assert_eq!(&ppm[i..i + 3], &[3, 1, 255]);
}

#[test]
fn the_switches_change_the_image_as_the_course_s_flags_do() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let render = |name: &str, flags: &[&str]| {
        let out = path_in(dir.path(), name);
        let mut args = vec![
            "mit6837",
            "-input",
            "scenes/mit6837/back-faces.txt",
            "-size",
            "60",
            "60",
            "-output",
            &out,
        ];
        args.extend_from_slice(flags);
        let output = whitted(&args);
        assert!(output.status.success(), "{}", stderr(&output));
        read_tga(&out).2
    };
    let unlit = render("a.tga", &[]);
    let lit = render("b.tga", &["-shade_back"]);
    // The right triangle faces away: black without -shade_back (the handout's back faces:
    // not even its ambient term 0.1·(0.9, 0.8, 0.2)), lit by the light from the camera with
    // it. The left one faces the camera: the same both ways.
    assert_eq!(pixel(&unlit, 60, 46, 30), [0, 0, 0]);
    assert!(pixel(&lit, 60, 46, 30)[0] > 200);
    assert_eq!(pixel(&unlit, 60, 13, 30), pixel(&lit, 60, 13, 30));
}

#[test]
fn other_commands_read_a_course_scene_by_its_content_and_point_at_its_lines() {
    let output = whitted(&["check", SPHERES]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(stdout(&output).contains("ok (5 objects, 1 light, 3 materials)"));

    let output = whitted(&["ir", SPHERES, "--set", "shadows=opaque"]);
    let text = stdout(&output);
    assert!(
        text.contains("shadows opaque, highlight blinn, back faces unlit, attenuation unclamped"),
        "{text}"
    );
    assert!(text.contains("sphere center <-1.2, -0.6, 0> radius 1 material #0  @ scenes/mit6837/spheres-orthographic.txt:31:5"), "{text}");

    // The trace names the .txt lines of the object and its material.
    let output = whitted(&["trace", SPHERES, "--pixel", "133,317"]);
    let text = stdout(&output);
    assert!(
        text.contains("object     sphere #0 (scenes/mit6837/spheres-orthographic.txt:31:5)"),
        "{text}"
    );
    assert!(
        text.contains("material   material #0 (scenes/mit6837/spheres-orthographic.txt:23:5)"),
        "{text}"
    );
    assert!(
        text.contains("model: no shadow rays (shadows none)"),
        "{text}"
    );

    // `render` writes the usual sRGB image of it.
    let dir = tempfile::tempdir().expect("a temporary directory");
    let out = path_in(dir.path(), "r.png");
    let output = whitted(&[
        "render", SPHERES, "-o", &out, "--width", "40", "--height", "40",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(Path::new(&out).is_file());
}

#[test]
fn errors_are_located_in_the_txt_file_and_exit_1() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let scene = dir.path().join("broken.txt");
    std::fs::write(
        &scene,
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
         Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n\
         Group {\n    numObjects 1\n    MaterialIndex 0\n    Sphere { center 0 0 0 radius 1 colour 2 }\n}\n",
    )
    .expect("writable");
    let scene = scene.to_string_lossy().into_owned();
    let out = path_in(dir.path(), "out.tga");
    std::fs::write(&out, b"the old image").expect("writable");
    for args in [
        vec!["check", scene.as_str()],
        vec![
            "mit6837", "-input", &scene, "-size", "10", "10", "-output", &out,
        ],
    ] {
        let output = whitted(&args);
        assert_eq!(output.status.code(), Some(1), "{args:?}");
        let message = stderr(&output);
        assert!(
            message.contains("`Sphere` has no field `colour`")
                && message.contains("broken.txt:6:36"),
            "{message}"
        );
    }
    // A failed run leaves the old output alone.
    assert_eq!(std::fs::read(&out).expect("still there"), b"the old image");

    // A missing mesh names the .obj file and the line that asked for it.
    let meshy = dir.path().join("meshy.txt");
    std::fs::write(
        &meshy,
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
         Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n\
         Group { numObjects 1 MaterialIndex 0\n  TriangleMesh { obj_file nowhere.obj } }\n",
    )
    .expect("writable");
    let output = whitted(&["check", &meshy.to_string_lossy()]);
    assert_eq!(output.status.code(), Some(1));
    let message = stderr(&output);
    assert!(
        message.contains("cannot read the mesh")
            && message.contains("nowhere.obj")
            && message.contains("meshy.txt:4:27"),
        "{message}"
    );
}

#[test]
fn bad_course_flags_are_usage_errors_that_name_the_flag() {
    let output = whitted(&[
        "mit6837", "-input", SPHERES, "-size", "10", "-output", "x.tga",
    ]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("-size: `-output` is not a height"),
        "{}",
        stderr(&output)
    );

    let output = whitted(&[
        "mit6837",
        "-input",
        SPHERES,
        "-size",
        "10",
        "10",
        "-output",
        "x.tga",
        "-visualize_grid",
    ]);
    assert_eq!(output.status.code(), Some(2));
    assert!(stderr(&output).contains("-visualize_grid is not available in whitted"));
    assert!(stderr(&output).contains("whitted accelerates with a BVH"));
    assert!(stderr(&output).contains("whitted trace SCENE.txt --pixel X,Y"));

    let output = whitted(&[
        "mit6837", "-input", SPHERES, "-size", "10", "10", "-output", SPHERES,
    ]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));

    let output = whitted(&[
        "mit6837",
        "-input",
        "scenes/whitted.scene",
        "-size",
        "10",
        "10",
        "-output",
        "x.tga",
    ]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        stderr(&output).contains("is not a 6.837 scene"),
        "{}",
        stderr(&output)
    );

    let output = whitted(&["mit6837", "-help"]);
    assert!(output.status.success());
    assert!(stdout(&output).starts_with("usage: whitted mit6837 -input SCENE.txt -size W H"));

    // -D has nothing to override in a 6.837 scene: the command line is wrong, not the scene.
    let output = whitted(&["check", SPHERES, "-D", "N=3"]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("a 6.837 scene has no constants")
            && stderr(&output).contains("(in `-D N`)"),
        "{}",
        stderr(&output)
    );
}

/// Every scene in scenes/mit6837/ is checked by the 6.837 reader (and has its golden entry;
/// `cargo xtask golden` refuses a scene without one).
#[test]
fn every_course_scene_checks() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/mit6837");
    let mut count = 0;
    for entry in std::fs::read_dir(dir).expect("scenes/mit6837") {
        let path = entry.expect("an entry").path();
        if path.extension().is_some_and(|e| e == "txt") {
            let output = whitted(&["check", &path.to_string_lossy()]);
            assert!(
                output.status.success(),
                "{}: {}",
                path.display(),
                stderr(&output)
            );
            count += 1;
        }
    }
    assert!(count >= 6, "{count} scenes");
}

/// The course adds `reflectiveColor·trace + transparentColor·trace` as given: a thin mirror
/// that is also 95% transparent (ior 1), black itself, over a grey background of 0.2, is
/// `0.5·0.2 + 0.95·0.2 = 0.29` in linear light: 73.95 → 74 of 255 in the course's linear
/// 8-bit image. whitted's own language would scale 0.5 and 0.95 down to add up to 1 (0.2,
/// 51 of 255). `whitted mit6837` says so once, as a warning.
#[test]
fn reflective_and_transparent_are_added_as_given() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let scene = dir.path().join("bright.txt");
    std::fs::write(
        &scene,
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 2 }\n\
         Background { color 0.2 0.2 0.2 ambientLight 0 0 0 }\n\
         Materials { numMaterials 1\n\
           PhongMaterial { diffuseColor 0 0 0 reflectiveColor 0.5 0.5 0.5\n\
             transparentColor 0.95 0.95 0.95 indexOfRefraction 1 } }\n\
         Group { numObjects 1 MaterialIndex 0 Triangle { vertex0 -5 -5 0 vertex1 5 -5 0 vertex2 0 5 0 } }\n",
    )
    .expect("writable");
    let image = path_in(dir.path(), "bright.tga");
    let output = whitted(&[
        "mit6837",
        "-input",
        &scene.to_string_lossy(),
        "-size",
        "4",
        "4",
        "-bounces",
        "1",
        "-output",
        &image,
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let (width, _, rgb) = read_tga(&image);
    assert_eq!(pixel(&rgb, width, 2, 2), [74, 74, 74]);
    let said = stderr(&output);
    assert_eq!(said.matches("more than 1").count(), 1, "{said}");
    assert!(said.contains("as given"), "{said}");
    // One sentence, not one broken by the source's line continuation.
    assert!(
        said.contains("is more than 1: the course adds reflective·trace + transparent·trace as given, so it returns more light than arrives"),
        "{said}"
    );

    // The same material in whitted's language, where the default scales it down.
    let own = dir.path().join("bright.scene");
    std::fs::write(
        &own,
        "settings { width 4 height 4 max_depth 1 background 0.2 ambient 0 }\n\
         camera orthographic { eye <0, 0, 10> look_at <0, 0, 0> height 2 }\n\
         material m { diffuse 0 reflective 0.5 transmissive 0.95 ior 1 }\n\
         triangle { vertices <-5, -5, 0>, <5, -5, 0>, <0, 5, 0> material m }\n",
    )
    .expect("writable");
    let trace = |extra: &[&str]| {
        let mut args = vec![
            "trace",
            own.to_str().expect("UTF-8"),
            "--pixel",
            "2,2",
            "--json",
        ];
        args.extend_from_slice(extra);
        let output = whitted(&args);
        assert!(output.status.success(), "{}", stderr(&output));
        let tree: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
        tree["color"][0].as_f64().expect("a colour")
    };
    assert!((trace(&[]) - 0.2).abs() < 1e-6);
    assert!((trace(&["--set", "energy_clamp=off"]) - 0.29).abs() < 1e-6);
}

/// Assignment 7's command line: `-uniform_samples 4 -box_filter 0.5` is whitted's
/// `sampling grid` with 4 samples, the same image as `render --set` says it is; `-stats`
/// prints the ray counts (4 camera rays per pixel).
#[test]
fn assignment_7_sampling_flags_render_the_grid_sampler() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let course = path_in(dir.path(), "course.png");
    let output = whitted(&[
        "mit6837",
        "-input",
        "scenes/mit6837/spheres-orthographic.txt",
        "-size",
        "20",
        "20",
        "-uniform_samples",
        "4",
        "-box_filter",
        "0.5",
        "-stats",
        "-output",
        &course,
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let said = stdout(&output);
    assert!(
        said.contains("camera rays      1600 (4.00 per pixel)"),
        "{said}"
    );
    let single = path_in(dir.path(), "single.png");
    let output = whitted(&[
        "mit6837",
        "-input",
        "scenes/mit6837/spheres-orthographic.txt",
        "-size",
        "20",
        "20",
        "-output",
        &single,
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let read = |path: &str| image::open(path).expect("an image").to_rgb8().into_raw();
    assert_ne!(read(&course), read(&single), "4 samples smooth the edges");
    // The same setting through the scene's own `--set`, on `render`'s path, as the course's
    // linear encoding: `diff --against-image` at tolerance 0 finds no pixel.
    let output = whitted(&[
        "diff",
        "scenes/mit6837/spheres-orthographic.txt",
        "--against-image",
        &course,
        "--width",
        "20",
        "--height",
        "20",
        "--set",
        "samples=4",
        "--set",
        "sampling=grid",
        "--tolerance",
        "0",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        stdout(&output).contains("the images match"),
        "{}",
        stdout(&output)
    );
}

/// Assignment 7's filters: `-tent_filter 1` is the scene's `filter tent` with
/// `filter_radius 1` (the same image as `render --set` makes, to the bit), and differs from
/// the default box.
#[test]
fn assignment_7_filters_are_the_filter_setting() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let scene = "scenes/mit6837/spheres-orthographic.txt";
    let tent = path_in(dir.path(), "tent.png");
    let boxed = path_in(dir.path(), "box.png");
    for (flag, path) in [("-tent_filter", &tent), ("-box_filter", &boxed)] {
        let radius = if flag == "-tent_filter" { "1" } else { "0.5" };
        let output = whitted(&[
            "mit6837",
            "-input",
            scene,
            "-size",
            "24",
            "24",
            "-uniform_samples",
            "4",
            flag,
            radius,
            "-output",
            path,
        ]);
        assert!(output.status.success(), "{}", stderr(&output));
    }
    let read = |path: &str| image::open(path).expect("an image").to_rgb8().into_raw();
    assert_ne!(read(&tent), read(&boxed), "the tent blurs the edges");
    let output = whitted(&[
        "diff",
        scene,
        "--against-image",
        &tent,
        "--width",
        "24",
        "--height",
        "24",
        "--set",
        "samples=4",
        "--set",
        "sampling=grid",
        "--set",
        "filter=tent",
        "--set",
        "filter_radius=1",
        "--tolerance",
        "0",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    assert!(
        stdout(&output).contains("the images match"),
        "{}",
        stdout(&output)
    );
}

/// `-render_samples FILE ZOOM`: the image zoomed (9 x 20 = 180), a checkerboard of 0.2 grey
/// and black, each sample a dot of its own colour where its ray went (the uniform grid's
/// first sample of pixel (0, 0) at (5, 5), in the colour `whitted trace` gives that
/// sample). `-render_filter FILE ZOOM`: 181 x 181, the box's weight 1 white at the centre
/// pixel, dark blue beyond its reach, blue grid lines.
#[test]
fn assignment_7_pictures_show_the_samples_and_the_filter() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let scene = "scenes/mit6837/spheres-orthographic.txt";
    let samples = path_in(dir.path(), "samples.png");
    let filter = path_in(dir.path(), "filter.png");
    let output = whitted(&[
        "mit6837",
        "-input",
        scene,
        "-size",
        "9",
        "9",
        "-uniform_samples",
        "4",
        "-render_samples",
        &samples,
        "20",
        "-render_filter",
        &filter,
        "20",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let picture = image::open(&samples).expect("an image").to_rgb8();
    assert_eq!(picture.dimensions(), (180, 180));
    assert_eq!(
        picture.get_pixel(0, 0).0,
        [51, 51, 51],
        "pixel (0, 0): light"
    );
    assert_eq!(picture.get_pixel(20, 0).0, [0, 0, 0], "pixel (1, 0): dark");
    let output = whitted(&[
        "trace",
        scene,
        "--pixel",
        "0,0",
        "--sample",
        "0",
        "--json",
        "--width",
        "9",
        "--height",
        "9",
        "--set",
        "samples=4",
        "--set",
        "sampling=grid",
    ]);
    assert!(output.status.success(), "{}", stderr(&output));
    let tree: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
    let color = &tree["samples"][0]["color"];
    let expected: Vec<u8> = (0..3)
        .map(|c| (color[c].as_f64().expect("a number").clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    assert_eq!(picture.get_pixel(5, 5).0.to_vec(), expected, "{tree}");
    let picture = image::open(&filter).expect("an image").to_rgb8();
    assert_eq!(picture.dimensions(), (181, 181));
    assert_eq!(
        picture.get_pixel(90, 90).0,
        [255, 255, 255],
        "the centre pixel"
    );
    assert_eq!(
        picture.get_pixel(30, 30).0,
        [0, 0, 128],
        "beyond the box's reach"
    );
    assert_eq!(picture.get_pixel(40, 33).0, [0, 0, 255], "a grid line");
}

/// `-gui` opens the debugger, which needs a terminal: without one, a usage error that says
/// so, before any render.
#[test]
fn gui_without_a_terminal_is_a_clear_error() {
    let output = whitted(&[
        "mit6837",
        "-input",
        "scenes/mit6837/spheres-orthographic.txt",
        "-size",
        "9",
        "9",
        "-gui",
    ]);
    assert_eq!(output.status.code(), Some(2), "{}", stderr(&output));
    assert!(
        stderr(&output).contains("-gui opens whitted's terminal debugger, which needs a terminal"),
        "{}",
        stderr(&output)
    );
}
