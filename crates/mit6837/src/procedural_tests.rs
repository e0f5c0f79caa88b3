//! The course's procedural materials against their formulas: what each becomes in the IR,
//! the colour at traced points as the formula evaluated here in f64 gives it, and located
//! errors for broken blocks.

use std::path::Path;

use whitted_ir::{DMat4, DVec3, PatternKind, Scene};
use whitted_tracer::ray_tree::{trace_pixel, SampleChoice};
use whitted_tracer::testing::reference_octave_sum;

use crate::{convert, Conversion, CourseOptions, MeshLoader};

struct NoFiles;

impl MeshLoader for NoFiles {
    fn load(&mut self, _: &Path) -> std::io::Result<Vec<u8>> {
        Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "no files here",
        ))
    }
}

fn read(text: &str, options: &CourseOptions) -> Conversion {
    convert(
        Path::new("course/scene.txt"),
        text.as_bytes().to_vec(),
        &mut NoFiles,
        options,
    )
}

/// Each diagnostic as `file:line:col: message`.
fn messages(conversion: &Conversion) -> String {
    conversion
        .diagnostics
        .iter()
        .map(|d| {
            let at = d
                .span
                .map_or("-".to_string(), |s| conversion.sources.location(s));
            format!("{at}: {}\n", d.message)
        })
        .collect()
}

/// A camera looking straight down on a plane at height 0.3, over x and z in [-3, 3]; no
/// lights, so each point shows its material's diffuse colour (the course's flat colour,
/// ambient white). The plane is written as a plane at 0.15 scaled by 2, so that a pattern
/// read in object space would differ from the course's world-space one. Material 0 is red,
/// material 1 blue, material 2 green; `extra` follows as material 3, which the plane uses.
fn flat_scene(extra: &str) -> String {
    format!(
        "OrthographicCamera {{ center 0 5 0 direction 0 -1 0 up 0 0 -1 size 6 }}\n\
         Materials {{ numMaterials 4\n\
           Material {{ diffuseColor 1 0 0 }}\n\
           Material {{ diffuseColor 0 0 1 }}\n\
           Material {{ diffuseColor 0 1 0 }}\n\
           {extra}\n\
         }}\n\
         Group {{ numObjects 1 MaterialIndex 3\n\
           Transform {{ UniformScale 2 Plane {{ normal 0 1 0 offset 0.15 }} }}\n\
         }}\n"
    )
}

fn scene_of(text: &str) -> Scene {
    let conversion = read(text, &CourseOptions::default());
    match conversion.scene {
        Some(scene) => scene.into_inner(),
        None => panic!("{}", messages(&conversion)),
    }
}

#[test]
fn the_four_materials_become_patterns_over_earlier_materials() {
    let cases = [
        (
            "Checkerboard { Transform { Scale 2 1 2 Translate 1 0 0 } materialIndex 1 materialIndex 0 }",
            PatternKind::CourseCheckerboard,
            DMat4::from_scale(DVec3::new(2.0, 1.0, 2.0))
                * DMat4::from_translation(DVec3::X),
            (1, 0),
        ),
        (
            "Noise { materialIndex 0 materialIndex 2 octaves 5 }",
            PatternKind::CourseNoise { octaves: 5 },
            DMat4::IDENTITY,
            (0, 2),
        ),
        (
            "Marble { Transform { YRotate 90 } materialIndex 2 materialIndex 1 octaves 3 frequency 2.5 amplitude 4 }",
            PatternKind::CourseMarble {
                octaves: 3,
                frequency: 2.5,
                amplitude: 4.0,
            },
            DMat4::from_rotation_y(90f64.to_radians()),
            (2, 1),
        ),
        (
            "Wood { Transform { UniformScale 0.5 } materialIndex 0 materialIndex 1 octaves 16 frequency 10 amplitude -1 }",
            PatternKind::CourseWood {
                octaves: 16,
                frequency: 10.0,
                amplitude: -1.0,
            },
            DMat4::from_scale(DVec3::splat(0.5)),
            (0, 1),
        ),
    ];
    for (block, kind, matrix, (a, b)) in cases {
        let scene = scene_of(&flat_scene(block));
        let handles: Vec<_> = scene.materials.iter().map(|(h, _)| h).collect();
        let host = &scene.materials[handles[3]];
        let Some(pattern) = &host.pattern else {
            panic!("no pattern from {block}");
        };
        assert_eq!(pattern.kind, kind, "{block}");
        assert_eq!((pattern.a, pattern.b), (handles[a], handles[b]), "{block}");
        assert_eq!(pattern.scale, 1.0);
        assert!(
            pattern.pattern_from_object.abs_diff_eq(matrix, 1e-12),
            "{block}: {:?}",
            pattern.pattern_from_object
        );
        // Its span is the whole block, for messages and the debugger.
        let span = scene.materials.span(handles[3]);
        let first_word = block.split(' ').next().unwrap_or_default();
        assert!(
            scene.sources.location(span).ends_with(":6:1"),
            "{first_word}: {}",
            scene.sources.location(span)
        );
    }
}

/// The second material's weight at a world point, by the course's formulas in f64.
fn weight(kind: PatternKind, world: DVec3, texture_from_world: DMat4) -> f64 {
    let p = texture_from_world.transform_point3(world);
    let n = |octaves| reference_octave_sum(p.to_array(), octaves);
    match kind {
        PatternKind::CourseCheckerboard => {
            let sum = p.x.floor() + p.y.floor() + p.z.floor();
            if sum.rem_euclid(2.0) == 0.0 {
                0.0
            } else {
                1.0
            }
        }
        PatternKind::CourseNoise { octaves } => n(octaves).clamp(0.0, 1.0),
        PatternKind::CourseMarble {
            octaves,
            frequency,
            amplitude,
        } => (1.0 + (frequency * p.x + amplitude * n(octaves)).sin()) / 2.0,
        PatternKind::CourseWood {
            octaves,
            frequency,
            amplitude,
        } => {
            let radius = (p.x * p.x + p.z * p.z).sqrt();
            (1.0 + (frequency * radius + amplitude * n(octaves)).sin()) / 2.0
        }
        _ => unreachable!("not a course pattern"),
    }
}

/// Traces every pixel of a 16×16 image of the plane and checks its colour against the
/// formula at the recorded hit point.
fn check_colours(block: &str, expected: impl Fn(DVec3) -> Option<[f64; 3]>) {
    let options = CourseOptions {
        width: 16,
        height: 16,
        ..CourseOptions::default()
    };
    let conversion = read(&flat_scene(block), &options);
    let Some(scene) = conversion.scene else {
        panic!("{}", messages(&conversion));
    };
    let prepared = whitted_tracer::PreparedScene::new(&scene);
    let render_options = whitted_tracer::RenderOptions::from_settings(&scene.settings);
    let mut checked = 0;
    let mut wrong = String::new();
    for y in 0..16 {
        for x in 0..16 {
            let tree = trace_pixel(&prepared, &scene, &render_options, x, y, SampleChoice::All)
                .unwrap_or_else(|e| panic!("{e}"));
            let Some(hit) = tree.samples[0].root.hit.as_ref() else {
                panic!("pixel {x},{y} missed the plane");
            };
            let point = DVec3::from_array(hit.point.map(f64::from));
            let Some(want) = expected(point) else {
                continue;
            };
            checked += 1;
            let got = tree.color.map(f64::from);
            if (0..3).any(|i| (got[i] - want[i]).abs() > 2e-4) {
                wrong += &format!("pixel {x},{y} at {point}: {got:?}, formula {want:?}\n");
            }
        }
    }
    assert!(wrong.is_empty(), "{block}\n{wrong}");
    assert!(checked > 200, "{block}: only {checked} pixels checked");
}

const RED: [f64; 3] = [1.0, 0.0, 0.0];
const BLUE: [f64; 3] = [0.0, 0.0, 1.0];

fn mix(a: [f64; 3], b: [f64; 3], w: f64) -> [f64; 3] {
    [0, 1, 2].map(|i| (1.0 - w) * a[i] + w * b[i])
}

#[test]
fn each_material_shades_as_its_formula_says() {
    let transform = DMat4::from_scale(DVec3::new(0.7, 1.0, 1.3))
        * DMat4::from_translation(DVec3::new(0.25, 0.0, -0.5));
    let written = "Transform { Scale 0.7 1 1.3 Translate 0.25 0 -0.5 }";
    let kinds = [
        ("Checkerboard", "", PatternKind::CourseCheckerboard),
        (
            "Noise",
            "octaves 4",
            PatternKind::CourseNoise { octaves: 4 },
        ),
        (
            "Marble",
            "octaves 3 frequency 3 amplitude 2",
            PatternKind::CourseMarble {
                octaves: 3,
                frequency: 3.0,
                amplitude: 2.0,
            },
        ),
        (
            "Wood",
            "octaves 2 frequency 6 amplitude 1.5",
            PatternKind::CourseWood {
                octaves: 2,
                frequency: 6.0,
                amplitude: 1.5,
            },
        ),
    ];
    for (name, numbers, kind) in kinds {
        let block = format!("{name} {{ {written} materialIndex 0 materialIndex 1 {numbers} }}");
        check_colours(&block, |p| {
            let q = transform.transform_point3(p);
            // A checker cell is only decided away from its edges (the hit point's rounding).
            let near_edge = [q.x, q.y, q.z].iter().any(|c| (c - c.round()).abs() < 1e-4);
            if matches!(kind, PatternKind::CourseCheckerboard) && near_edge {
                return None;
            }
            Some(mix(RED, BLUE, weight(kind, p, transform)))
        });
    }
}

/// The course's materials nest: a `Checkerboard` may choose a `Noise`, and a `Noise` may
/// blend the choices of a `Checkerboard`.
#[test]
fn choices_and_blends_nest() {
    let checker_of_noise =
        "Noise { Transform { UniformScale 2 } materialIndex 1 materialIndex 2 octaves 3 }\n\
        Checkerboard { materialIndex 0 materialIndex 3 }";
    let text = flat_scene(checker_of_noise).replace("numMaterials 4", "numMaterials 5");
    let text = text.replace("MaterialIndex 3", "MaterialIndex 4");
    let conversion = read(&text, &CourseOptions::default());
    let Some(scene) = conversion.scene else {
        panic!("{}", messages(&conversion));
    };
    let prepared = whitted_tracer::PreparedScene::new(&scene);
    let options = whitted_tracer::RenderOptions {
        width: 16,
        height: 16,
        ..whitted_tracer::RenderOptions::from_settings(&scene.settings)
    };
    let noise = PatternKind::CourseNoise { octaves: 3 };
    let scale = DMat4::from_scale(DVec3::splat(2.0));
    let mut blended = 0;
    for (x, y) in (0..16).flat_map(|y| (0..16).map(move |x| (x, y))) {
        let tree = trace_pixel(&prepared, &scene, &options, x, y, SampleChoice::All)
            .unwrap_or_else(|e| panic!("{e}"));
        let hit = tree.samples[0].root.hit.as_ref().expect("a hit");
        let p = DVec3::from_array(hit.point.map(f64::from));
        if [p.x, p.z].iter().any(|c| (c - c.round()).abs() < 1e-4) {
            continue;
        }
        let even = (p.x.floor() + p.y.floor() + p.z.floor()).rem_euclid(2.0) == 0.0;
        let want = if even {
            RED
        } else {
            let w = weight(noise, p, scale);
            blended += usize::from(hit.blend.is_some());
            mix(BLUE, [0.0, 1.0, 0.0], w)
        };
        let got = tree.color.map(f64::from);
        assert!(
            (0..3).all(|i| (got[i] - want[i]).abs() < 2e-4),
            "pixel {x},{y} at {p}: {got:?}, want {want:?}"
        );
    }
    assert!(blended > 50, "{blended} blended pixels");

    // A blend of blends is refused by validation, at the outer material.
    let text = flat_scene(
        "Noise { materialIndex 0 materialIndex 1 octaves 2 }\n\
         Marble { materialIndex 3 materialIndex 2 octaves 2 frequency 1 amplitude 1 }",
    )
    .replace("numMaterials 4", "numMaterials 5");
    let conversion = read(&text, &CourseOptions::default());
    assert!(conversion.scene.is_none());
    assert!(
        messages(&conversion).contains(
            "scene.txt:7:1: a blending pattern's material #3 blends materials itself: a blend of blends is not supported"
        ),
        "{}",
        messages(&conversion)
    );
}

#[test]
fn broken_procedural_materials_get_located_errors() {
    let cases = [
        (
            "Checkerboard { materialIndex 0 materialIndex 3 }",
            "scene.txt:6:46: `Checkerboard` (material 3) refers to material 3: only materials 0 to 2 are defined before it",
        ),
        (
            "Noise { materialIndex 7 materialIndex 0 octaves 2 }",
            "scene.txt:6:23: `Noise` (material 3) refers to material 7: only materials 0 to 2 are defined before it",
        ),
        (
            "Checkerboard { materialIndex 0 }",
            "scene.txt:6:32: `Checkerboard` needs `materialIndex` here",
        ),
        (
            "Marble { materialIndex 0 materialIndex 1 octaves 2 amplitude 1 frequency 2 }",
            "scene.txt:6:52: expected `frequency` in `Marble`, found `amplitude`",
        ),
        (
            "Noise { materialIndex 0 materialIndex 1 color 1 1 1 }",
            "scene.txt:6:41: expected `octaves` in `Noise`, found `color`",
        ),
        (
            "Checkerboard { materialIndex 0 materialIndex 1 octaves 3 }",
            "scene.txt:6:48: `Checkerboard` has no more fields, found `octaves`",
        ),
        (
            "Wood { materialIndex 0 materialIndex 1 octaves 0 frequency 1 amplitude 1 }",
            "scene.txt:6:48: `octaves` must be at least 1",
        ),
        (
            "Wood { materialIndex 0 materialIndex 1 octaves 17 frequency 1 amplitude 1 }",
            "scene.txt:6:48: the number of octaves is 17, past the noise octaves limit (16)",
        ),
        (
            "Noise { materialIndex 0 materialIndex 1 octaves 1000000000000 }",
            "scene.txt:6:49: the number of octaves is 1000000000000, past the noise octaves limit (16)",
        ),
        (
            "Noise { materialIndex zero materialIndex 1 octaves 2 }",
            "scene.txt:6:23: expected a material index (a whole number), found `zero`",
        ),
        (
            "Noise { Transform { Sphere { center 0 0 0 radius 1 } } materialIndex 0 materialIndex 1 octaves 2 }",
            "scene.txt:6:21: expected a transform or `}` in a material's `Transform`, found `Sphere`",
        ),
        (
            "Marble { materialIndex 0 materialIndex 1 octaves 2 frequency x amplitude 1 }",
            "scene.txt:6:62: expected a number (the Marble's frequency), found `x`",
        ),
    ];
    let mut wrong = String::new();
    for (block, expected) in cases {
        let conversion = read(&flat_scene(block), &CourseOptions::default());
        let message = messages(&conversion);
        if conversion.scene.is_some() || !message.contains(expected) {
            wrong += &format!("{block}\n  gave {message}  not {expected}\n");
        }
    }
    // The first material cannot be procedural: nothing comes before it.
    let text = "OrthographicCamera { center 0 5 0 direction 0 -1 0 up 0 0 -1 size 6 }\n\
        Materials { numMaterials 1 Checkerboard { materialIndex 0 materialIndex 0 } }";
    let message = messages(&read(text, &CourseOptions::default()));
    if !message.contains("scene.txt:2:57: `Checkerboard` (material 0) refers to material 0: no material is defined before it") {
        wrong += &format!("first material procedural: gave {message}");
    }
    assert!(wrong.is_empty(), "{wrong}");
}

/// Every prefix of a scene with all four is a located error or a scene, never a panic.
#[test]
fn every_prefix_of_a_procedural_scene_is_an_error_or_a_scene() {
    let text = flat_scene(
        "Marble { Transform { XRotate 30 Scale 1 2 3 } materialIndex 0 materialIndex 1 octaves 2 frequency 1 amplitude 1 }",
    );
    for end in (0..text.len()).filter(|&i| text.is_char_boundary(i)) {
        let conversion = read(&text[..end], &CourseOptions::default());
        assert!(
            conversion.scene.is_some()
                || conversion
                    .diagnostics
                    .iter()
                    .any(|d| d.is_error() && d.span.is_some()),
            "prefix of {end} bytes: {}",
            messages(&conversion)
        );
    }
}
