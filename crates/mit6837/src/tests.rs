//! The 6.837 reader against hand-worked expectations: what each construct becomes in the IR,
//! the course's camera convention in a rendered image, located errors for broken files
//! (every prefix of a good file), and the course's switches as settings.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use whitted_ir::{
    DMat4, DVec3, Diagnostic, Highlight, LightKind, Projection, Scene, ShadowMode, Shape,
};

use crate::{convert, is_mit6837, Conversion, CourseOptions, MeshLoader};

/// Mesh files from memory.
#[derive(Default)]
struct Files(HashMap<PathBuf, String>);

impl MeshLoader for Files {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        self.0
            .get(path)
            .map(|text| text.clone().into_bytes())
            .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"))
    }
}

fn read_with(text: &str, files: &mut Files, options: &CourseOptions) -> Conversion {
    convert(
        Path::new("course/scene.txt"),
        text.as_bytes().to_vec(),
        files,
        options,
    )
}

fn scene_of(text: &str) -> Scene {
    let conversion = read_with(text, &mut Files::default(), &CourseOptions::default());
    match conversion.scene {
        Some(scene) => scene.into_inner(),
        None => panic!("{}", messages(&conversion)),
    }
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

/// The single error of a broken scene, located.
fn error_of(text: &str) -> String {
    let conversion = read_with(text, &mut Files::default(), &CourseOptions::default());
    assert!(conversion.scene.is_none(), "accepted: {text}");
    messages(&conversion)
}

const SCENE: &str = "\
OrthographicCamera {
    center 0 0 10
    direction 0 0 -1
    up 0 1 0
    size 5
}
Background { color 0.1 0.2 0.3 ambientLight 0.2 0.2 0.2 }
Lights {
    numLights 2
    DirectionalLight { direction -1 -1 -1 color 0.8 0.8 0.8 }
    PointLight { position 0 5 5 color 1 1 1 attenuation 1 0.5 0.25 }
}
Materials {
    numMaterials 2
    PhongMaterial { diffuseColor 1 0 0 specularColor 0.5 0.5 0.5 exponent 20 }
    Material { diffuseColor 0 1 0 reflectiveColor 0.5 0.5 0.5
               transparentColor 0.2 0.2 0.2 indexOfRefraction 1.5 }
}
Group {
    numObjects 3
    MaterialIndex 0
    Sphere { center 0 0 0 radius 1 }
    Transform {
        Translate 1 0 0
        UniformScale 2
        Group {
            numObjects 2
            MaterialIndex 1
            Plane { normal 0 2 0 offset -1 }
            Triangle { vertex0 0 0 0 vertex1 1 0 0 vertex2 0 1 0 }
        }
    }
    Sphere { center 3 0 0 radius 0.5 }
}
";

#[test]
fn only_files_that_start_with_a_course_keyword_are_course_scenes() {
    assert!(is_mit6837(SCENE.as_bytes()));
    assert!(is_mit6837(b"\n  PerspectiveCamera{"));
    assert!(is_mit6837(b"Group {"));
    assert!(!is_mit6837(b"camera perspective { }"));
    assert!(!is_mit6837(b"// OrthographicCamera"));
    assert!(!is_mit6837(b"OrthographicCameras {"));
    assert!(!is_mit6837(b""));
}

#[test]
fn every_construct_becomes_the_ir_the_course_means() {
    let scene = scene_of(SCENE);
    let camera = &scene.camera;
    assert_eq!(camera.eye, DVec3::new(0.0, 0.0, 10.0));
    assert_eq!(camera.look_at, DVec3::new(0.0, 0.0, 9.0));
    assert_eq!(
        camera.projection,
        Projection::Orthographic { view_height: 5.0 }
    );
    assert_eq!(scene.settings.background.b, 0.3);
    assert_eq!(scene.settings.ambient.r, 0.2);

    let lights: Vec<_> = scene.lights.iter().map(|(_, l)| l.kind.clone()).collect();
    assert!(
        matches!(lights[0], LightKind::Directional { direction } if direction == DVec3::splat(-1.0))
    );
    let LightKind::Point { attenuation, .. } = &lights[1] else {
        panic!("{lights:?}");
    };
    assert_eq!(
        (
            attenuation.constant,
            attenuation.linear,
            attenuation.quadratic
        ),
        (1.0, 0.5, 0.25)
    );

    let materials: Vec<_> = scene.materials.iter().map(|(_, m)| m.clone()).collect();
    assert_eq!(materials.len(), 2, "no default material is needed");
    // ka = 1: the ambient term is ambientLight·kd, as in the course.
    assert_eq!(materials[0].ambient.r, 1.0);
    assert_eq!(
        (materials[0].specular.g, materials[0].shininess),
        (0.5, 20.0)
    );
    assert_eq!(
        (materials[1].reflective.r, materials[1].transmissive.r),
        (0.5, 0.2)
    );
    assert_eq!(materials[1].ior, 1.5);

    // Children before parents: sphere, plane, triangle, inner group, sphere, outer group.
    let objects: Vec<_> = scene.objects.iter().map(|(_, o)| o.clone()).collect();
    assert_eq!(objects.len(), 6);
    assert_eq!(scene.roots.len(), 1);
    let transform = DMat4::from_translation(DVec3::X) * DMat4::from_scale(DVec3::splat(2.0));
    // The plane: normal normalised, offset kept; under Translate then UniformScale, with
    // the inner group's material.
    assert!(matches!(
        objects[1].kind.shape(),
        Some(Shape::Plane { normal, offset }) if normal == DVec3::Y && offset == -1.0
    ));
    assert_eq!(objects[1].world_from_object.matrix(), transform);
    assert_eq!(objects[1].material.index(), 1);
    assert_eq!(objects[3].world_from_object.matrix(), transform);
    // MaterialIndex holds past the inner group's end, as in the course's reader.
    assert_eq!(objects[4].material.index(), 1);
    assert_eq!(objects[0].material.index(), 0);
    // A world point: the object's (1, 0, 0) scaled by 2, then moved by 1 along x.
    assert_eq!(
        transform.transform_point3(DVec3::X),
        DVec3::new(3.0, 0.0, 0.0)
    );

    // Spans point at the file's lines.
    let location = scene
        .sources
        .location(scene.objects.span(whitted_ir::Handle::from_index(2)));
    assert_eq!(location, "course/scene.txt:30:13");
    assert_eq!(
        scene.sources.location(scene.camera_span),
        "course/scene.txt:1:1"
    );
}

#[test]
fn the_course_switches_become_settings() {
    let defaults = scene_of(SCENE).settings;
    assert_eq!(defaults.shadows, ShadowMode::None);
    assert!(!defaults.shade_back && !defaults.attenuation_clamp);
    assert_eq!(defaults.highlight, Highlight::Blinn);
    assert_eq!((defaults.max_depth, defaults.min_weight), (0, 0.0));

    let options = CourseOptions {
        width: 100,
        height: 80,
        shadows: true,
        shade_back: true,
        bounces: 4,
        weight: 0.01,
        ..CourseOptions::default()
    };
    let conversion = read_with(SCENE, &mut Files::default(), &options);
    let settings = conversion.scene.map(|s| s.settings.clone());
    let settings = settings.unwrap_or_else(|| panic!("not converted"));
    assert_eq!((settings.width, settings.height), (100, 80));
    assert_eq!(settings.shadows, ShadowMode::Opaque);
    assert!(settings.shade_back);
    assert_eq!((settings.max_depth, settings.min_weight), (4, 0.01));

    let transparent = CourseOptions {
        transparent_shadows: true,
        ..CourseOptions::default()
    };
    let conversion = read_with(SCENE, &mut Files::default(), &transparent);
    assert_eq!(
        conversion.scene.map(|s| s.settings.shadows),
        Some(ShadowMode::Filtered)
    );
}

#[test]
fn a_scene_without_background_gets_the_course_grey() {
    let scene = scene_of(
        "PerspectiveCamera { center 0 0 5 direction 0 0 -1 up 0 1 0 angle 30 }\n\
         Group { numObjects 0 }\n",
    );
    assert_eq!(scene.settings.background.g, 0.5);
    // No lights either: flat colour (see below).
    assert_eq!(scene.settings.ambient.g, 1.0);
    assert_eq!(
        scene.camera.projection,
        Projection::Perspective {
            vertical_fov_degrees: 30.0
        }
    );
}

#[test]
fn a_scene_without_lights_is_flat_colour() {
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n";
    assert_eq!(scene_of(text).settings.ambient, whitted_ir::Color::WHITE);
    // Unless it gives its own ambient light.
    let own = format!("{text}Background {{ ambientLight 0.3 0.3 0.3 }}");
    assert_eq!(scene_of(&own).settings.ambient.r, 0.3);
    // With lights, the course's default: none.
    let lit = format!(
        "{text}Lights {{ numLights 1 DirectionalLight {{ direction 0 0 -1 color 1 1 1 }} }}"
    );
    assert_eq!(scene_of(&lit).settings.ambient.r, 0.0);
}

#[test]
fn transforms_compose_as_the_course_multiplied_them() {
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
        Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n\
        Group { numObjects 1 MaterialIndex 0\n\
          Transform { Translate 0 1 0\n\
          Transform { ZRotate 90 Translate 1 0 0 Scale { 1 2 3 }\n\
            Rotate { axis 0 0 2 angle 90 } Rotate { 1 0 0 30 }\n\
            Matrix { 1 0 0 5  0 1 0 6  0 0 1 7  0 0 0 1 }\n\
            Sphere { center 0 0 0 radius 1 } } } }\n";
    let scene = scene_of(text);
    let Some((_, sphere)) = scene.objects.iter().next() else {
        panic!("no objects");
    };
    let m = sphere.world_from_object.matrix();
    // Each transform multiplies on the right, `Matrix` on the left (as the course's reader
    // did); the matrix is read row by row (it moves by (5, 6, 7)); braces around an
    // argument and the unnamed `Rotate { x y z degrees }` are read too. The outer block's
    // transform applies last.
    let rotate = DMat4::from_rotation_z(90f64.to_radians());
    let expected = DMat4::from_translation(DVec3::Y)
        * DMat4::from_translation(DVec3::new(5.0, 6.0, 7.0))
        * rotate
        * DMat4::from_translation(DVec3::X)
        * DMat4::from_scale(DVec3::new(1.0, 2.0, 3.0))
        * rotate
        * DMat4::from_rotation_x(30f64.to_radians());
    assert!(m.abs_diff_eq(expected, 1e-12), "{m}\n{expected}");
}

#[test]
fn a_mesh_becomes_one_ir_mesh_instanced_by_its_triangle_mesh() {
    let mut files = Files::default();
    files.0.insert(
        PathBuf::from("course/models/quad.obj"),
        "# a unit square and a degenerate face\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
         vn 0 0 1\nf 1 2 3 4\nf -4 -2 -1/1/1\nf 1 2 2\n"
            .to_string(),
    );
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
        Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n\
        Group { numObjects 1 MaterialIndex 0\n\
          Transform { Translate 0 0 1 TriangleMesh { obj_file models/quad.obj } } }\n";
    let conversion = read_with(text, &mut files, &CourseOptions::default());
    let warnings = messages(&conversion);
    let Some(scene) = conversion.scene else {
        panic!("{warnings}");
    };
    assert_eq!(
        warnings,
        "course/models/quad.obj:9:1: 1 degenerate face of course/models/quad.obj (corners in a line) left out\n"
    );
    let instances: Vec<_> = scene
        .objects
        .iter_with_spans()
        .filter_map(|(_, o, span)| match o.kind.shape() {
            Some(Shape::Mesh { mesh, smooth }) => Some((
                mesh,
                smooth,
                o.world_from_object.matrix(),
                scene.sources.location(span),
            )),
            _ => None,
        })
        .collect();
    assert_eq!(instances.len(), 1, "{instances:?}");
    let (mesh, smooth, world_from_object, location) = instances[0].clone();
    assert!(!smooth, "the course's meshes are faceted");
    assert_eq!(world_from_object, DMat4::from_translation(DVec3::Z));
    assert_eq!(location, "course/scene.txt:4:29");
    // The quad as a fan of two, then `f -4 -2 -1` (counted back from the fourth vertex:
    // vertices 1, 3 and 4) as the fan's second triangle again; the degenerate face left out.
    let mesh = &scene.meshes[mesh];
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
    assert_eq!(mesh.positions[2], [1.0, 1.0, 0.0]);
    assert!(mesh.normals.is_empty());
    // An open square (and a face repeated) is not a solid.
    assert!(!mesh.solid);
}

#[test]
fn a_closed_mesh_is_a_solid() {
    let mut files = Files::default();
    files.0.insert(
        PathBuf::from("course/tetra.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n".to_string(),
    );
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
        Materials { numMaterials 1 Material { diffuseColor 1 1 1 transparentColor 0.9 0.9 0.9 indexOfRefraction 1.5 } }\n\
        Group { numObjects 1 MaterialIndex 0 TriangleMesh { obj_file tetra.obj } }\n";
    let conversion = read_with(text, &mut files, &CourseOptions::default());
    let Some(scene) = conversion.scene else {
        panic!("{}", messages(&conversion));
    };
    let meshes: Vec<_> = scene.meshes.iter().map(|(_, m)| m.solid).collect();
    assert_eq!(meshes, vec![true]);
}

#[test]
fn a_mesh_used_twice_is_one_source_file_and_one_warning() {
    let mut files = Files::default();
    files.0.insert(
        PathBuf::from("course/tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n".to_string(),
    );
    let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n\
        Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n\
        Group { numObjects 2 MaterialIndex 0\n\
          TriangleMesh { obj_file tri.obj }\n\
          Transform { Translate 0 0 1 TriangleMesh { obj_file tri.obj } } }\n";
    let conversion = read_with(text, &mut files, &CourseOptions::default());
    assert_eq!(
        messages(&conversion),
        "course/tri.obj:6:1: 1 degenerate face of course/tri.obj (corners in a line) left out\n"
    );
    assert_eq!(conversion.sources.files().len(), 2);
    let Some(scene) = conversion.scene else {
        panic!("not converted");
    };
    // One mesh, held once; two objects instancing it, and the root group.
    assert_eq!(scene.meshes.len(), 1);
    assert_eq!(scene.objects.len(), 3);
}

#[test]
fn broken_files_get_located_errors() {
    let camera = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }\n";
    let materials = "Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n";
    let cases = [
        (format!("{camera}Sphere {{ }}"), "scene.txt:2:1: expected a camera"),
        (
            format!("{camera}{materials}Group {{ numObjects 2 MaterialIndex 0 Sphere {{ center 0 0 0 radius 1 }} }}"),
            "scene.txt:3:71: `numObjects` is 2, but the group has 1 object",
        ),
        (
            format!("{camera}{materials}Group {{ numObjects 1 MaterialIndex 3 Sphere {{ center 0 0 0 radius 1 }} }}"),
            "scene.txt:3:36: there is no material 3: only material 0 is defined before this",
        ),
        (
            format!("{camera}{materials}Group {{ numObjects 1 Sphere {{ center 0 0 0 radius 1 }} }}"),
            "scene.txt:3:22: this `Sphere` has no material",
        ),
        (
            format!("{camera}{materials}Group {{ numObjects 1 MaterialIndex 0 Sphere {{ center 0 0 zero radius 1 }} }}"),
            "scene.txt:3:58: expected a number (the sphere's center), found `zero`",
        ),
        (
            format!("{camera}{materials}Group {{ numObjects 1 MaterialIndex 0 Sphere {{ center 0 0 0 radius 1 colour 1 }} }}"),
            "scene.txt:3:69: `Sphere` has no field `colour`",
        ),
        (
            format!("{camera}{materials}Group {{ numObjects 1 MaterialIndex 0 Sphere {{ center 0 0 0 radius -1 }} }}"),
            "scene.txt:3:38: a sphere's radius must be > 0",
        ),
        (
            format!("{camera}{materials}Group {{ numObjects 1 MaterialIndex 0 Sphere {{ center 0 0"),
            "the file ends where a number (the sphere's center) was expected",
        ),
        (
            format!("{camera}Lights {{ numLights 2 DirectionalLight {{ direction 0 0 0 color 1 1 1 }} }}"),
            "scene.txt:2:51: the light's direction must not be zero",
        ),
        (
            format!("{camera}{materials}Group {{ numObjects 1 MaterialIndex 0 TriangleMesh {{ obj_file missing.obj }} }}"),
            "scene.txt:3:62: cannot read the mesh course/missing.obj: no such file",
        ),
        (
            "Group { numObjects 0 }".to_string(),
            "scene.txt:1:1: the scene has no camera",
        ),
        (
            format!("{camera}{camera}"),
            "scene.txt:2:1: a second camera in one scene",
        ),
        (
            format!("{camera}{materials}Group {{ numObjects 1 MaterialIndex 0 Transform {{ Matrix {{ 1 0 0 0 0 1 0 0 0 0 1 0 1 0 0 1 }} Sphere {{ center 0 0 0 radius 1 }} }} }}"),
            "scene.txt:3:50: the matrix's last row must be `0 0 0 1`",
        ),
        (
            format!("{camera}{materials}Group {{ numObjects 1 MaterialIndex 0 Transform {{ Scale 1 0 1 Sphere {{ center 0 0 0 radius 1 }} }} }}"),
            "scene.txt:3:62: the object's transform is not invertible",
        ),
    ];
    let mut wrong = String::new();
    for (text, expected) in cases {
        let message = error_of(&text);
        if !message.contains(expected) {
            wrong += &format!("{text}\n  gave {message}  not {expected}\n");
        }
    }
    assert!(wrong.is_empty(), "{wrong}");
}

#[test]
fn every_prefix_of_a_good_file_is_an_error_or_a_scene_never_a_panic() {
    let mut files = Files::default();
    files.0.insert(
        PathBuf::from("course/tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_string(),
    );
    let text = SCENE.replace(
        "Sphere { center 3 0 0 radius 0.5 }",
        "TriangleMesh { obj_file tri.obj }",
    );
    for end in 0..=text.len() {
        let conversion = read_with(&text[..end], &mut files, &CourseOptions::default());
        if conversion.scene.is_none() {
            assert!(
                conversion
                    .diagnostics
                    .iter()
                    .any(|d| d.is_error() && d.span.is_some()),
                "no located error for the first {end} bytes"
            );
        }
    }
    // And bytes that are not text.
    let conversion = convert(
        Path::new("bad.txt"),
        b"Group { \xff }".to_vec(),
        &mut files,
        &CourseOptions::default(),
    );
    assert!(messages(&conversion).contains("bad.txt:1:9: `bad.txt` is not UTF-8 text"));
}

/// Renders `text` at 20×20 with the course's defaults.
fn render(text: &str) -> whitted_tracer::Image {
    let options = CourseOptions {
        width: 20,
        height: 20,
        ..CourseOptions::default()
    };
    let conversion = read_with(text, &mut Files::default(), &options);
    let Some(scene) = conversion.scene else {
        panic!("{}", messages(&conversion));
    };
    let prepared = whitted_tracer::PreparedScene::new(&scene);
    let render_options = whitted_tracer::RenderOptions::from_settings(&scene.settings);
    match whitted_tracer::render(&prepared, &render_options, &whitted_tracer::NoObserver) {
        Some((image, _)) => image,
        None => panic!("the render was cancelled"),
    }
}

/// The course's camera: `direction` is where it looks, `up` is up in the image and
/// `direction × up` is the image's right. A red ball at +x and a green one at +y, seen from
/// +z looking down -z, are on the right and at the top, with both kinds of camera.
#[test]
fn the_camera_basis_is_the_course_s() {
    let objects = "Materials { numMaterials 2\n\
          Material { diffuseColor 1 0 0 } Material { diffuseColor 0 1 0 } }\n\
        Background { color 0 0 0 ambientLight 1 1 1 }\n\
        Group { numObjects 2 MaterialIndex 0 Sphere { center 1.5 0 0 radius 0.5 }\n\
          MaterialIndex 1 Sphere { center 0 1.5 0 radius 0.5 } }\n";
    for camera in [
        "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 }\n",
        "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 25 }\n",
    ] {
        let image = render(&format!("{camera}{objects}"));
        let at = |x, y| image.pixel(x, y).unwrap_or_else(|| panic!("no pixel"));
        // Right of the centre row: red; top of the centre column: green.
        assert!(at(16, 10)[0] > 0.9 && at(3, 10)[0] == 0.0, "{camera}");
        assert!(at(10, 3)[1] > 0.9 && at(10, 16)[1] == 0.0, "{camera}");
        // The ambient term is ambientLight·kd (the ball's own colour, ka = 1).
        assert_eq!(at(16, 10), [1.0, 0.0, 0.0]);
    }
}

/// Thousands of mutated scenes (a word replaced by one that often breaks things: a brace, a
/// keyword out of place, a count far too big, a number at the edge of f64): each is a scene
/// or a located error, never a panic. The mutations are a fixed pseudo-random sequence.
#[test]
fn mutated_scenes_never_panic() {
    const WORDS: &[&str] = &[
        "{",
        "}",
        "Group",
        "Transform",
        "Sphere",
        "Matrix",
        "MaterialIndex",
        "numObjects",
        "0",
        "-1",
        "1e308",
        "-1e308",
        "1e-320",
        "nan",
        "inf",
        "4294967296",
        "99999999999999999999",
        "TriangleMesh",
        "obj_file",
        "Rotate",
        "angle",
        "0.5",
        "PointLight",
        "attenuation",
    ];
    const NUMBERS: &[&str] = &[
        "0", "-1", "1", "2", "0.001", "1e308", "-1e308", "1e-320", "1e9", "-1e9", "179", "181",
    ];
    let mut files = Files::default();
    files.0.insert(
        PathBuf::from("course/tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 3 2 -1\n".to_string(),
    );
    let base = SCENE.replace(
        "Sphere { center 3 0 0 radius 0.5 }",
        "Transform { Rotate { axis 0 1 0 angle 30 } TriangleMesh { obj_file tri.obj } }",
    );
    let words: Vec<&str> = base.split_whitespace().collect();
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = |n: usize| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state % n as u64) as usize
    };
    let mut converted = 0;
    for _ in 0..3000 {
        let mut mutated = words.clone();
        for _ in 0..1 + next(3) {
            let at = next(mutated.len());
            match next(4) {
                // A number for a number: the structure holds, the values go to the edges.
                3 if mutated[at].parse::<f64>().is_ok() => {
                    mutated[at] = NUMBERS[next(NUMBERS.len())]
                }
                0 | 3 => mutated[at] = WORDS[next(WORDS.len())],
                1 => {
                    mutated.remove(at);
                }
                _ => mutated.insert(at, WORDS[next(WORDS.len())]),
            }
        }
        let text = mutated.join(" ");
        let options = CourseOptions {
            width: 4,
            height: 4,
            shadows: true,
            bounces: 3,
            ..CourseOptions::default()
        };
        let conversion = read_with(&text, &mut files, &options);
        match conversion.scene {
            // What validation accepts, the tracer renders (finite colours, no panic).
            Some(scene) => {
                let prepared = whitted_tracer::PreparedScene::new(&scene);
                let render_options = whitted_tracer::RenderOptions::from_settings(&scene.settings);
                let rendered =
                    whitted_tracer::render(&prepared, &render_options, &whitted_tracer::NoObserver);
                let Some((image, _)) = rendered else {
                    panic!("cancelled");
                };
                assert!(
                    image.pixels.iter().flatten().all(|c| c.is_finite()),
                    "{text}"
                );
                converted += 1;
            }
            None => assert!(
                conversion.diagnostics.iter().any(Diagnostic::is_error),
                "no error for {text}"
            ),
        }
    }
    // Otherwise the renders above would check nothing.
    assert!(converted > 50, "only {converted} mutated scenes converted");
}

/// The 6.837 reader fills the scene's table of written settings and properties as the
/// language does, under the language's names, at the field's value.
#[test]
fn settings_and_properties_are_recorded_where_they_are_written() {
    use whitted_ir::{BlockKind, SceneFormat};
    let scene = scene_of(SCENE);
    assert_eq!(scene.format, SceneFormat::Mit6837);
    let text = |span: whitted_ir::Span| {
        let file = scene.sources.get(span.file).expect("the file");
        file.text[span.start as usize..span.end as usize].to_string()
    };
    let background = scene.written.setting("background").expect("background");
    assert_eq!(text(background.name_span), "color");
    assert_eq!(text(background.value_span), "0.1 0.2 0.3");
    let ambient = scene.written.setting("ambient").expect("ambient");
    assert_eq!(text(ambient.value_span), "0.2 0.2 0.2");
    assert!(
        scene.written.setting("max_depth").is_none(),
        "-bounces is not in the file"
    );
    let (phong, _) = scene.materials.iter().next().expect("a material");
    let exponent: Vec<_> = scene
        .written
        .properties_in(
            BlockKind::Material,
            scene.materials.span(phong),
            "shininess",
        )
        .map(|p| text(p.value_span))
        .collect();
    assert_eq!(exponent, ["20"]);
    let (point, _) = scene.lights.iter().nth(1).expect("two lights");
    let attenuation: Vec<_> = scene
        .written
        .properties_in(BlockKind::Light, scene.lights.span(point), "attenuation")
        .map(|p| text(p.value_span))
        .collect();
    assert_eq!(attenuation, ["1 0.5 0.25"]);
}
