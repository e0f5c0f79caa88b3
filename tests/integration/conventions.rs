//! The conventions docs/language.md states under "Handedness, rotations and the checker",
//! each checked with a render: which side of the image +x is on, which way `rotate` turns,
//! and which checker colour goes where (edges included).

use std::path::Path;

use whitted_lang::{compile_source, CompileOptions, SourceLoader};
use whitted_tracer::{render, NoObserver, PreparedScene, RenderOptions};

struct NoImports;

impl SourceLoader for NoImports {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        Err(std::io::Error::other(format!(
            "no imports here: {}",
            path.display()
        )))
    }
}

/// Renders `text` at `width`×`height`; pixels row by row, top row first.
fn render_text(text: &str, width: u32, height: u32) -> Vec<[f32; 3]> {
    let compilation = compile_source(
        "conventions.scene",
        text,
        &mut NoImports,
        &CompileOptions::default(),
    );
    let Some(scene) = compilation.scene else {
        panic!("does not compile: {:?}", compilation.diagnostics);
    };
    let prepared = PreparedScene::new(&scene);
    let options = RenderOptions {
        width,
        height,
        samples_per_pixel: 1,
        max_depth: 2,
        min_weight: 0.001,
    };
    render(&prepared, &options, &NoObserver)
        .unwrap_or_else(|| panic!("cancelled"))
        .0
        .pixels
}

/// The mean column (0 = left edge) of the pixels for which `is` holds.
fn mean_column(pixels: &[[f32; 3]], width: u32, is: impl Fn([f32; 3]) -> bool) -> f64 {
    let columns: Vec<f64> = pixels
        .iter()
        .enumerate()
        .filter(|(_, p)| is(**p))
        .map(|(i, _)| (i as u32 % width) as f64)
        .collect();
    assert!(!columns.is_empty(), "no such pixel");
    columns.iter().sum::<f64>() / columns.len() as f64
}

fn reddish(p: [f32; 3]) -> bool {
    p[0] > 0.3 && p[2] < 0.1
}

fn bluish(p: [f32; 3]) -> bool {
    p[2] > 0.3 && p[0] < 0.1
}

#[test]
fn with_the_camera_looking_along_plus_z_plus_x_is_on_the_left() {
    let pixels = render_text(
        "camera perspective { eye <0, 0, -6> look_at <0, 0, 0> }
         light directional { direction <0, 0, 1> }
         sphere { center <2, 0, 0> radius 0.8 material { ambient 0 diffuse red } }
         sphere { center <-2, 0, 0> radius 0.8 material { ambient 0 diffuse blue } }",
        64,
        32,
    );
    let red = mean_column(&pixels, 64, reddish);
    let blue = mean_column(&pixels, 64, bluish);
    assert!(
        red < 32.0 && blue > 32.0,
        "red (+x) at column {red}, blue (-x) at {blue}"
    );
}

#[test]
fn rotate_y_30_turns_plus_x_towards_minus_z() {
    // Seen from above (camera on +y looking down, image up = +z, so +x is on the left), a
    // red bar along +x turned by `rotate <0, 30, 0>` ends at (2.6, 0, -1.5): left and down
    // in the image, a counter-clockwise turn as seen from above. Turned by -30 it ends left
    // and up.
    let bar_end = |angle: &str| {
        let pixels = render_text(
            &format!(
                "camera orthographic {{ eye <0, 10, 0> look_at <0, 0, 0> up <0, 0, 1> height 8 }}
                 light directional {{ direction <0, -1, 0> }}
                 box {{ min <0, -0.1, -0.1> max <3, 0.1, 0.1> rotate <0, {angle}, 0>
                       material {{ ambient 0 diffuse red }} }}"
            ),
            64,
            64,
        );
        // 8 pixels per unit, the origin at the image centre (32, 32).
        let (mut below, mut above, mut right) = (0, 0, 0);
        for (i, p) in pixels.iter().enumerate() {
            let (x, y) = (i % 64, i / 64);
            if reddish(*p) {
                if x > 34 {
                    right += 1;
                } else if x < 28 && y > 34 {
                    below += 1;
                } else if x < 28 && y < 30 {
                    above += 1;
                }
            }
        }
        (below, above, right)
    };
    let (below, above, right) = bar_end("30");
    assert!(
        below > 20 && above == 0 && right == 0,
        "rotate 30: {below} below, {above} above, {right} right"
    );
    let (below, above, right) = bar_end("-30");
    assert!(
        above > 20 && below == 0 && right == 0,
        "rotate -30: {below} below, {above} above, {right} right"
    );
}

#[test]
fn the_checker_cell_at_the_origin_takes_the_first_colour_and_edges_belong_to_the_upper_cell() {
    // Looking straight down at a checkered floor (y = 0): image up is +z and +x is on the
    // left. One pixel per unit square, sampled at pixel centres: pixel (col, row) sees
    // x = 4 - (col + 0.5), z = 4 - (row + 0.5).
    let floor = |offset: &str| {
        render_text(
            &format!(
                "settings {{ ambient 1 }}
                 camera orthographic {{ eye <0, 10, 0> look_at <0, 0, 0> up <0, 0, 1> height 8 }}
                 plane {{ normal <0, 1, 0> offset {offset}
                         material {{ ambient 1 diffuse checker(red, blue, 1) }} }}"
            ),
            8,
            8,
        )
    };
    let colour_at = |pixels: &[[f32; 3]], x: f64, z: f64| {
        let col = (4.0 - x - 0.5).round() as usize;
        let row = (4.0 - z - 0.5).round() as usize;
        let p = pixels[row * 8 + col];
        if reddish(p) {
            "red"
        } else if bluish(p) {
            "blue"
        } else {
            "neither"
        }
    };
    let at_zero = floor("0");
    // Stripes: slabs along x, the first colour where floor(x) is even.
    let stripes = render_text(
        "settings { ambient 1 }
         camera orthographic { eye <0, 10, 0> look_at <0, 0, 0> up <0, 0, 1> height 8 }
         plane { normal <0, 1, 0> offset 0 material { ambient 1 diffuse stripes(red, blue, 1) } }",
        8,
        8,
    );
    assert_eq!(colour_at(&stripes, 0.5, 0.5), "red");
    assert_eq!(colour_at(&stripes, 0.5, -1.5), "red");
    assert_eq!(colour_at(&stripes, 1.5, 0.5), "blue");
    assert_eq!(colour_at(&stripes, -0.5, 2.5), "blue");
    // The square 0 <= x < 1, 0 <= z < 1 takes the first colour; its neighbours the second.
    assert_eq!(colour_at(&at_zero, 0.5, 0.5), "red");
    assert_eq!(colour_at(&at_zero, -0.5, 0.5), "blue");
    assert_eq!(colour_at(&at_zero, 0.5, -0.5), "blue");
    assert_eq!(colour_at(&at_zero, -0.5, -0.5), "red");
    assert_eq!(colour_at(&at_zero, 1.5, 1.5), "red");
    assert_eq!(colour_at(&at_zero, 1.5, 2.5), "blue");
    // The pattern is three-dimensional: a floor at y = -0.5 lies in the cells below y = 0,
    // so every square swaps colour.
    let lower = floor("-0.5");
    assert_eq!(colour_at(&lower, 0.5, 0.5), "blue");
    assert_eq!(colour_at(&lower, -0.5, 0.5), "red");
    // A floor exactly on a cell boundary (y = 1) takes the cells above it, all over: swapped.
    let on_edge = floor("1");
    assert!((0..64).all(|i| {
        let (x, z) = (i % 8, i / 8);
        let expected = if (x + z) % 2 == 0 { "blue" } else { "red" };
        colour_at(&on_edge, x as f64 - 3.5, z as f64 - 3.5) == expected
    }));

    // Edges: a point exactly on a cell boundary belongs to the cell above it (floor). An
    // orthographic view 2 units wide, 2x1 pixels, centred on x = 1.5: the two pixel centres
    // fall exactly on x = 2 (left, as +x is on the left) and x = 1 (right), at z = 0.5.
    let pixels = render_text(
        "settings { ambient 1 }
         camera orthographic { eye <1.5, 10, 0.5> look_at <1.5, 0, 0.5> up <0, 0, 1> height 1 }
         plane { normal <0, 1, 0> offset 0 material { ambient 1 diffuse checker(red, blue, 1) } }",
        2,
        1,
    );
    // x = 2 is in cell 2 (even: red); x = 1 in cell 1 (odd: blue). Were edges given to the
    // cell below, the colours would be the other way round.
    assert!(reddish(pixels[0]) && bluish(pixels[1]), "{pixels:?}");
}
