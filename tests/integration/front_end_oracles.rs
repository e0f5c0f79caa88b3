//! Oracles for the second front end and for meshes that are not the code under test: a
//! 6.837 scene against a hand translation of it into whitted's language (two front ends,
//! one image), and a mesh against the same triangles written as `triangle` objects (the
//! mesh's own BVH and intersection against the plain triangle's).

use std::path::Path;
use std::process::Command;

use whitted_lang::{compile_source, CompileOptions, SourceLoader};
use whitted_tracer::{render, NoObserver, PreparedScene, RenderOptions};

/// Serves one in-memory file (the mesh) to the compiler.
struct OneFile {
    name: &'static str,
    bytes: Vec<u8>,
}

impl SourceLoader for OneFile {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        if path.file_name().and_then(|n| n.to_str()) == Some(self.name) {
            Ok(self.bytes.clone())
        } else {
            Err(std::io::Error::other(format!("no file {}", path.display())))
        }
    }
}

fn render_text(text: &str, loader: &mut OneFile, size: u32) -> Vec<[f32; 3]> {
    let compilation = compile_source("oracle.scene", text, loader, &CompileOptions::default());
    let Some(scene) = compilation.scene else {
        panic!("does not compile: {:?}", compilation.diagnostics);
    };
    let prepared = PreparedScene::new(&scene);
    let options = RenderOptions {
        width: size,
        height: size,
        samples_per_pixel: 1,
        max_depth: 3,
        min_weight: 0.0,
    };
    render(&prepared, &options, &NoObserver)
        .unwrap_or_else(|| panic!("cancelled"))
        .0
        .pixels
}

/// A deterministic stream of numbers in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Pixels that differ by more than `tolerance` on some channel.
fn differing(a: &[[f32; 3]], b: &[[f32; 3]], tolerance: f32) -> usize {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > tolerance))
        .count()
}

const LIGHTS: &str = "camera perspective { eye <0, 1, -7> look_at <0, 0, 0> fov 50 }
    light point { position <3, 5, -4> color 0.8 }
    light directional { direction <-1, -2, 1> color 0.3 }
    material m { diffuse rgb(0.7, 0.5, 0.3) specular 0.4 shininess 20 reflective 0.2 }
    plane { normal <0, 1, 0> offset -2.5 material { diffuse 0.6 } }\n";

/// Random triangles, thin and fat, crossing each other, as vertices and as a mesh file.
fn random_triangles(seed: u64, count: usize) -> Vec<[[f64; 3]; 3]> {
    let mut random = Lcg(seed);
    (0..count)
        .map(|_| {
            let centre = [
                random.next() * 5.0 - 2.5,
                random.next() * 4.0 - 2.0,
                random.next() * 4.0 - 2.0,
            ];
            let corner = |r: &mut Lcg| {
                [
                    centre[0] + r.next() * 2.0 - 1.0,
                    centre[1] + r.next() * 2.0 - 1.0,
                    centre[2] + r.next() * 2.0 - 1.0,
                ]
            };
            [
                corner(&mut random),
                corner(&mut random),
                corner(&mut random),
            ]
        })
        .collect()
}

fn obj_text(triangles: &[[[f64; 3]; 3]]) -> String {
    let mut text = String::new();
    for triangle in triangles {
        for v in triangle {
            text.push_str(&format!("v {} {} {}\n", v[0], v[1], v[2]));
        }
    }
    for i in 0..triangles.len() {
        text.push_str(&format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3));
    }
    text
}

fn vector(v: [f64; 3]) -> String {
    format!("<{}, {}, {}>", v[0], v[1], v[2])
}

#[test]
fn an_open_mesh_renders_as_the_same_triangles_written_one_by_one() {
    for seed in [1, 2, 3] {
        let triangles = random_triangles(seed, 40);
        let mut loader = OneFile {
            name: "random.obj",
            bytes: obj_text(&triangles).into_bytes(),
        };
        let mesh = format!("{LIGHTS}mesh {{ file \"random.obj\" smooth false material m }}\n");
        let mut one_by_one = LIGHTS.to_string();
        for [a, b, c] in &triangles {
            one_by_one.push_str(&format!(
                "triangle {{ vertices {}, {}, {} material m }}\n",
                vector(*a),
                vector(*b),
                vector(*c)
            ));
        }
        let from_mesh = render_text(&mesh, &mut loader, 64);
        let from_triangles = render_text(&one_by_one, &mut loader, 64);
        let off = differing(&from_mesh, &from_triangles, 1e-3);
        // Two intersection routines may disagree on a ray through an edge; no more.
        assert!(
            off <= 8,
            "seed {seed}: {off} of {} pixels differ between the mesh and its triangles",
            from_mesh.len()
        );
    }
}

#[test]
fn a_transformed_mesh_instance_renders_as_its_transformed_triangles() {
    let triangles = random_triangles(7, 30);
    let mut loader = OneFile {
        name: "random.obj",
        bytes: obj_text(&triangles).into_bytes(),
    };
    // scale 0.8, then 90 degrees about y (x -> -z, z -> x), then translate <0.5, 0.25, 1>.
    let transform = |v: [f64; 3]| {
        let s = [v[0] * 0.8, v[1] * 0.8, v[2] * 0.8];
        [s[2] + 0.5, s[1] + 0.25, -s[0] + 1.0]
    };
    let mesh = format!(
        "{LIGHTS}mesh {{ file \"random.obj\" smooth false material m scale 0.8 rotate <0, 90, 0> translate <0.5, 0.25, 1> }}\n"
    );
    let mut moved = LIGHTS.to_string();
    for [a, b, c] in &triangles {
        moved.push_str(&format!(
            "triangle {{ vertices {}, {}, {} material m }}\n",
            vector(transform(*a)),
            vector(transform(*b)),
            vector(transform(*c))
        ));
    }
    let from_mesh = render_text(&mesh, &mut loader, 64);
    let from_triangles = render_text(&moved, &mut loader, 64);
    let off = differing(&from_mesh, &from_triangles, 2e-3);
    assert!(
        off <= 8,
        "{off} pixels differ between the instance and its moved triangles"
    );
}

/// The 6.837 scene and its hand translation, rendered by the binary, pixel by pixel.
#[test]
fn a_course_scene_renders_as_its_hand_translation() {
    let dir = tempfile::tempdir().unwrap();
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/integration/oracles");
    let exe = env!("CARGO_BIN_EXE_whitted");
    let course = dir.path().join("course.png");
    let translated = dir.path().join("translated.png");
    let settings = [
        "--set",
        "width=72",
        "--set",
        "height=72",
        "--set",
        "shadows=opaque",
        "--set",
        "max_depth=3",
        "--set",
        "min_weight=0",
    ];
    for (scene, out) in [
        ("course-pair.txt", &course),
        ("course-pair.scene", &translated),
    ] {
        let status = Command::new(exe)
            .arg("render")
            .arg(here.join(scene))
            .args(settings)
            .arg("--quiet")
            .arg("-o")
            .arg(out)
            .status()
            .unwrap();
        assert!(status.success(), "whitted render {scene} failed");
    }
    let a = image::open(&course).unwrap().to_rgb8();
    let b = image::open(&translated).unwrap().to_rgb8();
    assert_eq!(a.dimensions(), b.dimensions());
    let off = a
        .pixels()
        .zip(b.pixels())
        .filter(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > 1))
        .count();
    assert_eq!(
        off, 0,
        "{off} pixels differ between the 6.837 scene and its translation"
    );
}
