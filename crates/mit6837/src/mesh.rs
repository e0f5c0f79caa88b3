//! `TriangleMesh { obj_file name.obj }`: the `.obj` file read through the caller's
//! [`crate::MeshLoader`] (its `v` and `f` lines; everything else is skipped), added to the
//! source map so that each triangle points at its `f` line, and lowered to the IR.
//!
//! Each file becomes one mesh of the IR (`Scene::meshes`), read and parsed once however
//! often the scene uses it; every `TriangleMesh` is an object instancing it, so a closed,
//! consistently oriented mesh is a solid (a glass gem refracts as one) as in the language.

use whitted_ir::{
    limits, DMat4, DVec3, Diagnostic, FileId, Handle, Material, Mesh, Object, ObjectKind, Shape,
    SourceFile, Span,
};

use crate::convert::{decode, Converter};
use crate::reader::Read;
use crate::tokens::Token;

/// Faces left out for having their corners in a line: how many, and where the first is.
pub(crate) type Degenerate = Option<(usize, Span)>;

/// A mesh as the `.obj` file gives it.
pub(crate) struct ObjMesh {
    pub positions: Vec<DVec3>,
    /// Corner indices into `positions`, and the span of the face's `f` line.
    pub faces: Vec<([usize; 3], Span)>,
}

impl<'a> Converter<'a, '_> {
    /// Reads the mesh file `name` (relative to the scene's folder) and lowers it.
    pub(crate) fn mesh(
        &mut self,
        name: Token<'a>,
        span: Span,
        world_from_object: DMat4,
        material: Handle<Material>,
    ) -> Read<Handle<Object>> {
        let path = self.folder.join(name.text);
        let display = path.to_string_lossy().into_owned();
        // A mesh used twice is read, parsed and shown in the source map once, and held once.
        let known = self
            .meshes
            .iter()
            .find(|(p, _)| *p == path)
            .map(|&(_, h)| h);
        let mesh = match known {
            Some(mesh) => mesh,
            None => {
                let bytes = match self.loader.load(&path) {
                    Ok(bytes) => bytes,
                    Err(error) => {
                        return Err(Box::new(
                            Diagnostic::error(
                                format!("cannot read the mesh {}: {error}", path.display()),
                                self.reader.span(name),
                            )
                            .with_label("this file")
                            .with_hint("the path is relative to the scene file's folder"),
                        ))
                    }
                };
                let text = decode(&display, bytes, &mut self.scene.sources)?;
                let file = self
                    .scene
                    .sources
                    .add(SourceFile::new(display.clone(), text.as_str()));
                let parsed = parse_obj(&text, file)?;
                let (mesh, degenerate) = to_ir_mesh(&parsed, display.clone());
                if mesh.triangles.is_empty() {
                    return Err(Box::new(
                        Diagnostic::error(
                            format!("the mesh {display} has no triangles"),
                            self.reader.span(name),
                        )
                        .with_label("this file")
                        .with_hint("a mesh needs `f` lines naming three or more `v` lines"),
                    ));
                }
                if let Some((count, first)) = degenerate {
                    self.warnings.push(
                        Diagnostic::warning(
                            format!(
                                "{count} degenerate face{} of {display} (corners in a line) left out",
                                if count == 1 { "" } else { "s" }
                            ),
                            first,
                        )
                        .with_label("the first of them"),
                    );
                }
                let handle = self.scene.meshes.append(mesh, self.reader.span(name));
                self.meshes.push((path, handle));
                handle
            }
        };
        let handle = self.append(
            Object {
                name: None,
                kind: ObjectKind::Shape {
                    shape: Shape::Mesh {
                        mesh,
                        // The course's meshes are faceted: its files have no normals.
                        smooth: false,
                    }
                    .into(),
                },
                world_from_object: world_from_object.into(),
                material,
            },
            span,
        )?;
        Ok(handle)
    }
}

/// Parses the `v x y z` and `f a b c ...` lines of an `.obj` text (1-based indices, negative
/// ones counting back from the last vertex, `a/t/n` forms taking `a`; polygons are split into
/// a fan of triangles), up to the mesh triangle limit.
pub(crate) fn parse_obj(text: &str, file: FileId) -> Read<ObjMesh> {
    let mut mesh = ObjMesh {
        positions: Vec::new(),
        faces: Vec::new(),
    };
    let mut line_start = 0;
    for line in text.split_inclusive('\n') {
        let start = line_start;
        line_start += line.len();
        let content = line.trim_end_matches(['\n', '\r']);
        let span_of = |word: &str| {
            // `word` is a slice of `content`: its offset locates it in the file.
            let offset = word.as_ptr() as usize - content.as_ptr() as usize;
            Span::new(file, start + offset, start + offset + word.len())
        };
        let line_span = Span::new(file, start, start + content.len());
        let mut words = content.split_ascii_whitespace();
        match words.next() {
            Some("v") => {
                let mut p = [0.0; 3];
                for (axis, value) in p.iter_mut().enumerate() {
                    let Some(word) = words.next() else {
                        return Err(Box::new(
                            Diagnostic::error("a vertex needs three coordinates", line_span)
                                .with_label(format!("coordinate {} is missing", axis + 1)),
                        ));
                    };
                    *value = match word.parse::<f64>() {
                        Ok(x) if x.is_finite() => x,
                        _ => {
                            return Err(Box::new(
                                Diagnostic::error(
                                    format!("expected a coordinate, found `{word}`"),
                                    span_of(word),
                                )
                                .with_label("not a finite number"),
                            ))
                        }
                    };
                }
                mesh.positions.push(DVec3::from_array(p));
            }
            Some("f") => {
                let mut corners = Vec::new();
                for word in words {
                    let index_text = word.split('/').next().unwrap_or(word);
                    let count = mesh.positions.len() as i64;
                    let index = match index_text.parse::<i64>() {
                        Ok(i) if i >= 1 && i <= count => (i - 1) as usize,
                        Ok(i) if i < 0 && -i <= count => (count + i) as usize,
                        _ => {
                            return Err(Box::new(
                                Diagnostic::error(
                                    format!(
                                        "`{word}` is not a vertex: the file has {count} vertices \
                                         before this line"
                                    ),
                                    span_of(word),
                                )
                                .with_label("no such vertex")
                                .with_hint(
                                    "vertices are numbered from 1, in the order of `v` lines",
                                ),
                            ))
                        }
                    };
                    corners.push(index);
                }
                if corners.len() < 3 {
                    return Err(Box::new(
                        Diagnostic::error("a face needs at least three corners", line_span)
                            .with_label("too few corners"),
                    ));
                }
                for i in 1..corners.len() - 1 {
                    if mesh.faces.len() >= limits::MAX_MESH_TRIANGLES {
                        return Err(Box::new(Diagnostic::error(
                            format!("this face is past {}", limits::describe("mesh triangles")),
                            line_span,
                        )));
                    }
                    mesh.faces
                        .push(([corners[0], corners[i], corners[i + 1]], line_span));
                }
            }
            // Normals, texture coordinates, groups, materials and comments: not needed.
            _ => {}
        }
    }
    Ok(mesh)
}

/// The mesh as the IR holds it: positions and triangles (degenerate faces, which have no
/// normal, left out; returns how many, and where the first is). `file` names it in messages
/// and in `whitted ir`.
pub(crate) fn to_ir_mesh(mesh: &ObjMesh, file: String) -> (Mesh, Degenerate) {
    let mut degenerate: Degenerate = None;
    let mut triangles = Vec::with_capacity(mesh.faces.len());
    for &([i, j, k], face_span) in &mesh.faces {
        let (a, b, c) = (mesh.positions[i], mesh.positions[j], mesh.positions[k]);
        // The validator's own threshold for a degenerate triangle.
        if (b - a).cross(c - a).length() <= 1e-14 {
            let entry = degenerate.get_or_insert((0, face_span));
            entry.0 += 1;
            continue;
        }
        // Indices are below the vertex count, which the source size limit keeps far below
        // u32::MAX (a `v` line is at least 7 bytes).
        triangles.push([i as u32, j as u32, k as u32]);
    }
    let positions = mesh
        .positions
        .iter()
        .map(|p| p.as_vec3().to_array())
        .collect();
    (
        Mesh::new(file, positions, Vec::new(), triangles),
        degenerate,
    )
}
