//! `mesh` objects: files read through the loader once however many objects name them, paths
//! relative to the scene, `smooth`, files as exporters write them, and every mesh file error,
//! warning and note located in the file (with the `file` that named it), "not a solid" with
//! its reason, edge and faces.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use whitted_ir::{Severity, Shape};
use whitted_lang::{compile_source, CompileOptions, Limits, SourceLoader};

use crate::support::{check_errors_with, output, MapLoader};

/// A closed, outward tetrahedron.
const TETRAHEDRON: &str =
    "# a tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

/// Counts how often each file is read.
struct Counting {
    inner: MapLoader,
    reads: HashMap<PathBuf, usize>,
}

impl SourceLoader for Counting {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        *self.reads.entry(path.to_path_buf()).or_default() += 1;
        self.inner.load(path)
    }
}

/// Planted bug, seen failing: the evaluator registered a new mesh at every `file` (no
/// lookup by path), and the scene held 1,000 meshes.
#[test]
fn a_thousand_instances_read_the_file_once_and_share_one_mesh() {
    let mut loader = Counting {
        inner: MapLoader::with(&[("scenes/models/tet.obj", TETRAHEDRON)]),
        reads: HashMap::new(),
    };
    let text = "for i in 0..1000 {\n  mesh \"t{i}\" { file \"models/tet.obj\" translate <i, 0, 0> }\n}\nmesh { file \"models/../models/tet.obj\" smooth false }\n";
    let compilation = compile_source(
        "scenes/many.scene",
        text,
        &mut loader,
        &CompileOptions::default(),
    );
    let Some(scene) = compilation.scene else {
        panic!("did not compile:\n{}", output(&compilation));
    };
    let scene = scene.into_inner();
    assert_eq!(
        loader.reads.get(Path::new("scenes/models/tet.obj")),
        Some(&1)
    );
    assert_eq!(scene.meshes.len(), 1);
    let (handle, mesh) = scene.meshes.iter().next().expect("one mesh");
    assert_eq!(mesh.file, "scenes/models/tet.obj");
    assert_eq!((mesh.positions.len(), mesh.triangles.len()), (4, 4));
    assert!(mesh.solid);
    let mut instances = 0;
    let mut smooth = Vec::new();
    for (_, object) in scene.objects.iter() {
        if let Some(Shape::Mesh { mesh, smooth: s }) = object.kind.shape() {
            assert_eq!(mesh, handle);
            instances += 1;
            smooth.push(s);
        }
    }
    assert_eq!(instances, 1001);
    assert_eq!(
        smooth.iter().filter(|s| !**s).count(),
        1,
        "only the last is faceted"
    );
    // `whitted ir` shows the mesh once, by its counts.
    let dump = whitted_ir::print(&scene);
    assert!(
        dump.contains(
            "mesh #0 \"scenes/models/tet.obj\" 4 vertices, 4 triangles, no normals, solid"
        ),
        "{}",
        dump.lines().take(8).collect::<Vec<_>>().join("\n")
    );
    let json = whitted_ir::to_json(&scene);
    assert_eq!(json["meshes"][0]["triangles"], 4);
    assert_eq!(json["meshes"][0]["solid"], true);
}

#[test]
fn mesh_errors_name_the_file_and_line() {
    let flipped = TETRAHEDRON.replace("f 1 3 2", "f 1 2 3");
    let odd = format!("{TETRAHEDRON}vx 1 2 3\nvx 4 5 6\n");
    let files = [
        ("tet.obj", TETRAHEDRON),
        ("short.obj", "v 0 0 0\nv 1 0 0\nv 0 1\nf 1 2 3\n"),
        (
            "index.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\n# the fourth vertex is missing\nf 1 2 4\n",
        ),
        ("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n"),
        ("empty.obj", "# nothing but a comment\nv 0 0 0\n"),
        ("notes.txt", "v 0 0 0\n"),
        ("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ("bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
        ("line.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
        ("line.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2   # an edge\n"),
        ("corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1/1 3/1/1\n"),
        ("flipped.obj", &flipped),
        ("odd.obj", &odd),
    ];
    check_errors_with(
        "mesh_errors",
        &[
            ("missing file", "mesh { file \"gone.obj\" }"),
            ("a vertex with two numbers", "mesh { file \"short.obj\" }"),
            (
                "a face index past the vertices",
                "mesh { file \"index.obj\" }",
            ),
            ("a vertex that is not finite", "mesh { file \"nan.obj\" }"),
            ("no triangles", "mesh { file \"empty.obj\" }"),
            ("not a mesh file", "mesh { file \"notes.txt\" }"),
            (
                "a PLY face index past the vertices",
                "mesh { file \"bad.ply\" }",
            ),
            ("no file", "mesh \"gem\" { smooth false }"),
            ("file is not a string", "mesh { file 3 }"),
            (
                "smooth is not a boolean",
                "mesh { file \"tet.obj\" smooth 1 }",
            ),
            (
                "an open mesh in CSG",
                "difference { sphere { } mesh { file \"open.obj\" } }",
            ),
            (
                "a flipped face in CSG",
                "intersection { sphere { } mesh { file \"flipped.obj\" } }",
            ),
            ("a face of two corners", "mesh { file \"line.obj\" }"),
            ("a PLY face of two vertices", "mesh { file \"line.ply\" }"),
            ("a malformed corner", "mesh { file \"corner.obj\" }"),
            (
                "an unknown statement",
                "material m { } mesh { file \"odd.obj\" material m }",
            ),
        ],
        &files,
        &CompileOptions::default(),
    );
}

/// Planted bug, seen failing: the triangle budget ignored the scene limit (only the mesh
/// limit), and the second file loaded.
#[test]
fn too_many_triangles_is_an_error_naming_the_limit() {
    let files = [("a.obj", TETRAHEDRON), ("b.obj", TETRAHEDRON)];
    let mut options = CompileOptions {
        limits: Limits {
            max_mesh_triangles: 3,
            ..Limits::default()
        },
        ..CompileOptions::default()
    };
    check_errors_with(
        "mesh_triangle_limits",
        &[("over the mesh limit", "mesh { file \"a.obj\" }")],
        &files,
        &options,
    );
    options.limits = Limits {
        max_scene_triangles: 6,
        ..Limits::default()
    };
    check_errors_with(
        "mesh_scene_triangle_limit",
        &[(
            "over the scene limit",
            "mesh { file \"a.obj\" } mesh { file \"b.obj\" } mesh { file \"a.obj\" }",
        )],
        &files,
        &options,
    );
}

/// Each diagnostic of compiling `scene` (as `test.scene`) with `files`: its severity, where it
/// points (`path:line:column`), its message, and where its secondary labels point.
fn located(files: &[(&str, &str)], scene: &str) -> Vec<(Severity, String, String, Vec<String>)> {
    let compilation = compile_source(
        "test.scene",
        scene,
        &mut MapLoader::with(files),
        &CompileOptions::default(),
    );
    compilation
        .diagnostics
        .iter()
        // The scenes here give their meshes no material, and are told so.
        .filter(|d| !d.message.contains("gets the default"))
        .map(|d| {
            let place = d.span.map_or_else(
                || "nowhere".to_string(),
                |span| compilation.sources.location(span),
            );
            let secondary = d
                .secondary
                .iter()
                .map(|l| compilation.sources.location(l.span))
                .collect();
            (d.severity, place, d.message.clone(), secondary)
        })
        .collect()
}

/// The default cube as Blender's OBJ exporter writes it without UVs: header comments,
/// `mtllib`, `o`, `usemtl`, `s off`, per-face normals, `v//vn` quads, CRLF line ends.
const BLENDER_CUBE: &str = "# Blender v2.93.1 OBJ File: ''\r\n# www.blender.org\r\nmtllib cube.mtl\r\no Cube\r\nv 1.000000 1.000000 -1.000000\r\nv 1.000000 -1.000000 -1.000000\r\nv 1.000000 1.000000 1.000000\r\nv 1.000000 -1.000000 1.000000\r\nv -1.000000 1.000000 -1.000000\r\nv -1.000000 -1.000000 -1.000000\r\nv -1.000000 1.000000 1.000000\r\nv -1.000000 -1.000000 1.000000\r\nvn 0.0000 1.0000 0.0000\r\nvn 0.0000 0.0000 1.0000\r\nvn -1.0000 0.0000 0.0000\r\nvn 0.0000 -1.0000 0.0000\r\nvn 1.0000 0.0000 0.0000\r\nvn 0.0000 0.0000 -1.0000\r\nusemtl Material\r\ns off\r\nf 1//1 5//1 7//1 3//1\r\nf 4//2 3//2 7//2 8//2\r\nf 8//3 7//3 5//3 6//3\r\nf 6//4 2//4 4//4 8//4\r\nf 2//5 1//5 3//5 4//5\r\nf 6//6 5//6 1//6 2//6\r\n";

/// Planted bug, seen failing before the fix: nothing noted the ignored materials (the
/// scene compiled with no diagnostic).
#[test]
fn a_blender_export_is_a_solid_with_one_note_that_its_materials_are_ignored() {
    let files = [("models/cube.obj", BLENDER_CUBE)];
    let text = "mesh \"cube\" { file \"models/cube.obj\" }\n";
    let diagnostics = located(&files, text);
    assert_eq!(diagnostics.len(), 1, "{diagnostics:#?}");
    let (severity, place, message, secondary) = &diagnostics[0];
    assert_eq!(*severity, Severity::Note);
    assert_eq!(place, "models/cube.obj:3:1");
    assert!(message.contains("materials"), "{message}");
    assert_eq!(secondary, &["test.scene:1:20".to_string()]);
    let compilation = compile_source(
        "test.scene",
        text,
        &mut MapLoader::with(&files),
        &CompileOptions::default(),
    );
    let scene = compilation.scene.as_ref().expect("compiles").scene();
    let (_, mesh) = scene.meshes.iter().next().expect("one mesh");
    assert_eq!(mesh.triangles.len(), 12);
    assert!(mesh.solid);
    assert_eq!(mesh.normals.len(), mesh.positions.len());
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!("mesh_blender_cube", output(&compilation));
    });
}

/// Everything a hand-written or exported file may hold besides vertices and faces.
/// Planted bugs, seen failing before the fix: the trailing comment was "`#` is not a vertex
/// index", and a `\` continuation was not joined.
#[test]
fn comments_continuations_groups_points_lines_and_relative_indices_are_read() {
    let file = "# a tetrahedron, written by hand\n\n\
        mtllib a.mtl b.mtl\nmtllib c.mtl\n\
        o tetra\ng side one\ns 1\nusemtl glass\n\
        v 0 0 0   # the origin\n\
        v 1 0 0\n\
        v 0 1 0\t\n\
        v 0 \\\n  0 1\n\
        vt 0 0\nvt 1 0 0\nvn 0 0 -1\n\
        f 1 3 2 # the bottom\n\
        f 1/1 2/2 4/1\n\
        l 1 2 3\np 4\n\
        g side two\n\
        f -4 -1 -2\n\
        f 2 \\\n 3 4\n\
        \n";
    let files = [("tet.obj", file)];
    let text = "mesh { file \"tet.obj\" }\n";
    let diagnostics = located(&files, text);
    let errors: Vec<_> = diagnostics
        .iter()
        .filter(|d| d.0 == Severity::Error)
        .collect();
    assert!(errors.is_empty(), "{errors:#?}");
    let compilation = compile_source(
        "test.scene",
        text,
        &mut MapLoader::with(&files),
        &CompileOptions::default(),
    );
    let scene = compilation.scene.as_ref().expect("compiles").scene();
    let (_, mesh) = scene.meshes.iter().next().expect("one mesh");
    assert_eq!(mesh.triangles.len(), 4);
    assert!(mesh.solid, "the four faces close the tetrahedron");
    // Materials and lines are noted once each, where they first appear.
    let notes: Vec<_> = diagnostics
        .iter()
        .map(|(severity, place, _, _)| (*severity, place.as_str()))
        .collect();
    assert_eq!(
        notes,
        [
            (Severity::Note, "tet.obj:3:1"),
            (Severity::Note, "tet.obj:19:1")
        ],
        "{diagnostics:#?}"
    );
}

/// Planted bug, seen failing before the fix: unknown statements passed without a word.
#[test]
fn unknown_statements_are_a_warning_once_per_keyword_with_the_count() {
    let file = format!("vx 1 2 3\n{TETRAHEDRON}vx 4 5 6\nfoo bar\nvx 7 8 9\n");
    let files = [("odd.obj", file.as_str())];
    let diagnostics = located(&files, "mesh { file \"odd.obj\" }\n");
    let summary: Vec<_> = diagnostics
        .iter()
        .map(|(severity, place, message, _)| (*severity, place.as_str(), message.as_str()))
        .collect();
    assert_eq!(
        summary,
        [
            (
                Severity::Warning,
                "odd.obj:1:1",
                "`vx` is not an OBJ statement whitted knows; 3 lines use it (the first here), and they are ignored"
            ),
            (
                Severity::Warning,
                "odd.obj:12:1",
                "`foo` is not an OBJ statement whitted knows; this line is ignored"
            ),
        ],
        "{diagnostics:#?}"
    );
}

/// Planted bugs, seen failing before the fix: `f 1 2` was dropped silently, a file of only
/// short faces got an error with no line, `1/1/1/1` was "texture index out of range", and a
/// trailing comment was an error.
#[test]
fn short_faces_and_malformed_corners_are_errors_at_the_corner() {
    let three = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let cases = [
        (
            format!("{TETRAHEDRON}f 1 2\n"),
            "tet.obj:10:1",
            "a face needs three corners or more, and this one has 2",
        ),
        (
            format!("{three}f 3\nf 2\n"),
            "tet.obj:4:1",
            "a face needs three corners or more, and this one has 1",
        ),
        (
            format!("{three}f\n"),
            "tet.obj:4:1",
            "a face needs three corners or more, and this one has none",
        ),
        (
            format!("{three}vt 0 0\nvn 0 0 1\nf 1/1/1/1 2/1/1 3/1/1\n"),
            "tet.obj:6:3",
            "`1/1/1/1` is not a face corner",
        ),
        (
            format!("{three}vn 0 0 1\nf 1 2// 3\n"),
            "tet.obj:5:5",
            "`2//` is not a face corner",
        ),
        (
            format!("{three}f 1 a/b 3\n"),
            "tet.obj:4:5",
            "`a/b` is not a face corner",
        ),
        (
            format!("{three}f 1 /2 3\n"),
            "tet.obj:4:5",
            "`/2` is not a face corner",
        ),
        (
            format!("{three}f 1 2 4\n"),
            "tet.obj:4:7",
            "vertex index 4 is out of range",
        ),
        (
            format!("{three}vn 0 0 1\nf 1//1 2//2 3//1\n"),
            "tet.obj:5:8",
            "normal index 2 is out of range",
        ),
    ];
    for (file, place, words) in cases {
        let files = [("tet.obj", file.as_str())];
        let diagnostics = located(&files, "mesh { file \"tet.obj\" }\n");
        let errors: Vec<_> = diagnostics
            .iter()
            .filter(|d| d.0 == Severity::Error)
            .collect();
        assert_eq!(errors.len(), 1, "{file:?}: {diagnostics:#?}");
        let (_, at, message, secondary) = errors[0];
        assert_eq!(at, place, "{file:?}: {message}");
        assert!(message.contains(words), "{file:?}: {message}");
        assert_eq!(secondary, &["test.scene:1:13".to_string()], "{file:?}");
    }
}

/// A CSG child that is not a solid says why, with an example edge and its face's line.
/// Planted bug, seen failing before the fix: the message was only "this is not a solid".
#[test]
fn not_a_solid_says_open_or_inconsistent_with_an_edge_and_its_face() {
    let open = "v 0 0 0\nv 1 0 0\nv 0 1 0\n# one triangle\nf 1 2 3\n";
    // The tetrahedron with its first face turned over.
    let flipped = TETRAHEDRON.replace("f 1 3 2", "f 1 2 3");
    let cases = [
        (
            "open.obj",
            open.to_string(),
            "is open: the edge between vertices 1 and 2 belongs to one face only",
            vec!["open.obj:5:1"],
        ),
        (
            "flipped.obj",
            flipped,
            "is inconsistently oriented: two faces run from vertex 1 to vertex 2",
            vec!["flipped.obj:6:1", "flipped.obj:7:1"],
        ),
    ];
    for (name, file, words, faces) in cases {
        let files = [(name, file.as_str())];
        let text = format!("difference {{ sphere {{ }} mesh {{ file \"{name}\" }} }}\n");
        let diagnostics = located(&files, &text);
        assert_eq!(diagnostics.len(), 1, "{diagnostics:#?}");
        let (severity, _, message, secondary) = &diagnostics[0];
        assert_eq!(*severity, Severity::Error);
        assert!(message.contains(words), "{message}");
        // The CSG operation, then each face with the edge.
        assert_eq!(secondary[1..], faces, "{secondary:?}");
    }
}

/// PLY headers with CRLF line ends and comments read as before; a face of fewer than three
/// vertices is a located error. Planted bug, seen failing before the fix: `2 0 1` was
/// dropped silently.
#[test]
fn ply_files_with_crlf_and_comments_read_and_short_faces_are_located_errors() {
    let header = "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nelement vertex 4\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\nelement face 4\r\nproperty list uchar int vertex_indices\r\nend_header\r\n";
    let body = "0 0 0\r\n1 0 0\r\n0 1 0\r\n0 0 1\r\n3 0 2 1\r\n3 0 1 3\r\n3 0 3 2\r\n3 1 2 3\r\n";
    let good = format!("{header}{body}");
    let files = [("tet.ply", good.as_str())];
    let text = "mesh { file \"tet.ply\" }\n";
    assert_eq!(located(&files, text), []);
    let compilation = compile_source(
        "test.scene",
        text,
        &mut MapLoader::with(&files),
        &CompileOptions::default(),
    );
    let scene = compilation.scene.as_ref().expect("compiles").scene();
    assert!(scene.meshes.iter().next().expect("a mesh").1.solid);

    let short = good.replace("3 1 2 3\r\n", "2 1 2\r\n");
    let files = [("tet.ply", short.as_str())];
    let diagnostics = located(&files, "mesh { file \"tet.ply\" }\n");
    assert_eq!(diagnostics.len(), 1, "{diagnostics:#?}");
    let (severity, place, message, _) = &diagnostics[0];
    assert_eq!(*severity, Severity::Error);
    assert_eq!(place, "tet.ply:18:1");
    assert!(message.contains("three vertices or more"), "{message}");
}
