//! `mesh` objects: files read through the loader once however many objects name them, paths
//! relative to the scene, `smooth`, and every mesh file error located at the `file` that
//! named it, with the file's line where one line is at fault.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use whitted_ir::{ObjectKind, Shape};
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
        if let ObjectKind::Shape {
            shape: Shape::Mesh { mesh, smooth: s },
        } = object.kind
        {
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
