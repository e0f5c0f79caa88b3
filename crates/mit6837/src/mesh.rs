//! `TriangleMesh { obj_file name.obj }`: the `.obj` file read through the caller's
//! [`crate::MeshLoader`] (its `v` and `f` lines; everything else is skipped), added to the
//! source map so that each triangle points at its `f` line, and lowered to the IR.
//!
//! The IR has no meshes yet, so [`lower_to_triangles`] makes a group of `triangle` shapes:
//! thin surfaces, which do not refract as one solid. It is the one place that decides how a
//! mesh becomes IR, so that it can switch to the IR's meshes when they exist.

use whitted_ir::{
    limits, DMat4, DVec3, Diagnostic, FileId, Handle, Material, Object, ObjectKind, Shape,
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
        // A mesh used twice is read, parsed and shown in the source map once.
        let known = self.meshes.iter().position(|(p, _)| *p == path);
        let index = match known {
            Some(index) => index,
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
                let mesh = parse_obj(&text, file, self.scene.objects.len())?;
                self.meshes.push((path, mesh));
                self.meshes.len() - 1
            }
        };
        let mesh = std::mem::replace(
            &mut self.meshes[index].1,
            ObjMesh {
                positions: Vec::new(),
                faces: Vec::new(),
            },
        );
        let lowered = lower_to_triangles(self, &mesh, span, world_from_object, material);
        self.meshes[index].1 = mesh;
        let (handle, degenerate) = lowered?;
        // Said once per file, not once per use.
        if let (Some((count, first)), None) = (degenerate, known) {
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
        Ok(handle)
    }
}

/// Parses the `v x y z` and `f a b c ...` lines of an `.obj` text (1-based indices, negative
/// ones counting back from the last vertex, `a/t/n` forms taking `a`; polygons are split into
/// a fan of triangles). `objects` is how many objects the scene already has, for the limit.
pub(crate) fn parse_obj(text: &str, file: FileId, objects: usize) -> Read<ObjMesh> {
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
                    if objects + mesh.faces.len() >= limits::MAX_OBJECTS {
                        return Err(Box::new(Diagnostic::error(
                            format!("this face is past {}", limits::describe("objects")),
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

/// The mesh as IR: a group of `triangle` shapes, each with its `f` line's span, under the
/// `TriangleMesh`'s transform and material. Degenerate faces (corners in a line, which
/// validation refuses) are left out; returns how many, and where the first is.
pub(crate) fn lower_to_triangles(
    converter: &mut Converter<'_, '_>,
    mesh: &ObjMesh,
    span: Span,
    world_from_object: DMat4,
    material: Handle<Material>,
) -> Read<(Handle<Object>, Degenerate)> {
    let mut children = Vec::with_capacity(mesh.faces.len());
    let mut degenerate: Degenerate = None;
    for &([i, j, k], face_span) in &mesh.faces {
        let (a, b, c) = (mesh.positions[i], mesh.positions[j], mesh.positions[k]);
        // The validator's own threshold for a degenerate triangle.
        if (b - a).cross(c - a).length() <= 1e-14 {
            let entry = degenerate.get_or_insert((0, face_span));
            entry.0 += 1;
            continue;
        }
        children.push(converter.append(
            Object {
                name: None,
                kind: ObjectKind::Shape {
                    shape: Shape::Triangle { a, b, c },
                },
                world_from_object,
                material,
            },
            face_span,
        )?);
    }
    let group = converter.append(
        Object {
            name: None,
            kind: ObjectKind::Group { children },
            world_from_object,
            material,
        },
        span,
    )?;
    Ok((group, degenerate))
}
