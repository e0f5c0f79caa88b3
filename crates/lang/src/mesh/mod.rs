//! Mesh files: after evaluation, each mesh the scene named is read through the
//! [`SourceLoader`] (bytes in, the library never touches the disk) and parsed by its
//! extension, `.obj` (`obj.rs`) or `.ply` (`ply.rs`), each a reader of its own. Every
//! problem, note and warning is located in the mesh file where one place is to blame: the
//! file is added to the source map as far as the last line a message points at (a model of
//! a million triangles is not copied for a note on its third line), and each message has a
//! secondary label at the `file` property that named the mesh. A problem with no place (an
//! unreadable file, no triangles, a binary PLY's body) is an error at the `file` property.

mod obj;
mod ply;

use std::ops::Range;

use whitted_ir::{
    Diagnostic, Mesh, NotSolid, ObjectKind, Scene, Severity, Shape, SourceFile, Span,
};

use crate::{Limits, SourceLoader};

/// A mesh file's contents before the IR checks it.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct MeshData {
    pub positions: Vec<[f32; 3]>,
    /// Empty, or one per position.
    pub normals: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// How the file numbers the vertices, for messages.
    pub vertex_numbers: VertexNumbers,
    /// Per triangle, the byte where the file writes its face (empty for binary files).
    pub face_starts: Vec<usize>,
    /// Notes and warnings about the file.
    pub remarks: Vec<Remark>,
}

/// The number a file gives each of [`MeshData::positions`].
#[derive(Debug, Default, PartialEq)]
pub(crate) enum VertexNumbers {
    /// The position's index + 1 (OBJ's numbering, without renumbering).
    #[default]
    FromOne,
    /// The position's index (PLY's numbering).
    FromZero,
    /// One number per position.
    Table(Vec<u64>),
}

impl VertexNumbers {
    fn number(&self, index: u64) -> u64 {
        match self {
            VertexNumbers::FromOne => index + 1,
            VertexNumbers::FromZero => index,
            VertexNumbers::Table(numbers) => usize::try_from(index)
                .ok()
                .and_then(|i| numbers.get(i))
                .copied()
                .unwrap_or(index + 1),
        }
    }
}

/// Where in a mesh file a message points.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Place {
    /// Nowhere in particular: the message is about the whole file.
    Whole,
    /// A line (1-based), all of it.
    Line(usize),
    /// Bytes of the file.
    Bytes(Range<usize>),
}

/// A note or warning about a mesh file that does not stop it loading.
#[derive(Debug, PartialEq)]
pub(crate) struct Remark {
    pub severity: Severity,
    pub place: Range<usize>,
    pub message: String,
    pub hints: Vec<String>,
}

impl Remark {
    pub(crate) fn new(
        severity: Severity,
        place: Range<usize>,
        message: impl Into<String>,
    ) -> Remark {
        Remark {
            severity,
            place,
            message: message.into(),
            hints: Vec::new(),
        }
    }

    pub(crate) fn with_hint(mut self, hint: impl Into<String>) -> Remark {
        self.hints.push(hint.into());
        self
    }
}

/// What is wrong with a mesh file, and where.
#[derive(Debug, PartialEq)]
pub(crate) struct MeshError {
    pub place: Place,
    pub message: String,
    pub hints: Vec<String>,
    /// Set when the file has more triangles than its budget: how many it has at least.
    pub too_many: Option<usize>,
}

impl MeshError {
    pub(crate) fn new(place: Place, message: impl Into<String>) -> MeshError {
        MeshError {
            place,
            message: message.into(),
            hints: Vec::new(),
            too_many: None,
        }
    }

    pub(crate) fn at(line: usize, message: impl Into<String>) -> MeshError {
        MeshError::new(Place::Line(line), message)
    }

    pub(crate) fn whole(message: impl Into<String>) -> MeshError {
        MeshError::new(Place::Whole, message)
    }

    /// A file with at least `count` triangles, more than its budget.
    pub(crate) fn too_many(count: usize) -> MeshError {
        MeshError {
            too_many: Some(count),
            ..MeshError::whole("")
        }
    }

    pub(crate) fn with_hint(mut self, hint: impl Into<String>) -> MeshError {
        self.hints.push(hint.into());
        self
    }
}

/// Reads and parses every mesh of `scene` (registered by the evaluator with only its
/// file's path), reporting problems into `diagnostics`.
pub(crate) fn load_meshes(
    scene: &mut Scene,
    loader: &mut dyn SourceLoader,
    limits: &Limits,
    diagnostics: &mut Vec<Diagnostic>,
) {
    let mut total = 0usize;
    let handles: Vec<_> = scene.meshes.iter().map(|(handle, _)| handle).collect();
    // The meshes a CSG operation takes as children: if one is not a solid, the validator
    // says why, at the face of an edge at fault.
    let mut in_csg = vec![false; handles.len()];
    for (_, object) in scene.objects.iter() {
        if let ObjectKind::Csg { children, .. } = &object.kind {
            for &child in children {
                if let Some(Shape::Mesh { mesh, .. }) =
                    scene.objects.get(child).and_then(|o| o.kind.shape())
                {
                    if let Some(slot) = in_csg.get_mut(mesh.index()) {
                        *slot = true;
                    }
                }
            }
        }
    }
    for handle in handles {
        let span = scene.meshes.span(handle);
        let file = scene.meshes[handle].file.clone();
        let path = std::path::Path::new(&file);
        let bytes = match loader.load(path) {
            Ok(bytes) => bytes,
            Err(error) => {
                diagnostics.push(
                    Diagnostic::error(format!("cannot read the mesh `{file}`: {error}"), span)
                        .with_label("this file")
                        .with_hint("mesh paths are relative to the folder of the scene file that names them"),
                );
                continue;
            }
        };
        let extension = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let scene_left = limits.max_scene_triangles.saturating_sub(total);
        let budget = limits.max_mesh_triangles.min(scene_left);
        let parsed = match extension.as_str() {
            "obj" => obj::parse(&bytes, budget),
            "ply" => ply::parse(&bytes, budget),
            _ => {
                diagnostics.push(
                    Diagnostic::error(format!("`{file}` is not a mesh file whitted reads"), span)
                        .with_label("this file")
                        .with_hint("meshes are Wavefront `.obj` or Stanford `.ply` files"),
                );
                continue;
            }
        };
        let data = parsed.and_then(|data| {
            if data.triangles.is_empty() {
                Err(MeshError::whole("it has no triangles"))
            } else {
                Ok(data)
            }
        });
        match data {
            Ok(data) => {
                total += data.triangles.len();
                let MeshData {
                    positions,
                    normals,
                    triangles,
                    vertex_numbers,
                    face_starts,
                    remarks,
                } = data;
                let mut mesh = Mesh::new(file.clone(), positions, normals, triangles);
                let mut places: Vec<Range<usize>> =
                    remarks.iter().map(|r| r.place.clone()).collect();
                // A mesh that a CSG needs solid says why it is not, at its face.
                let mut face_starts_at_fault = [None, None];
                if let Some(NotSolid::Edge(edge)) = &mut mesh.not_solid {
                    edge.vertices = edge.vertices.map(|v| vertex_numbers.number(v - 1));
                    if in_csg[handle.index()] {
                        let start = |t: u32| face_starts.get(t as usize).copied();
                        face_starts_at_fault =
                            [start(edge.triangle), edge.other_triangle.and_then(start)];
                        places.extend(face_starts_at_fault.iter().flatten().map(|&s| s..s));
                    }
                }
                let located = Located::new(scene, &file, &bytes, &places);
                if let Some(NotSolid::Edge(edge)) = &mut mesh.not_solid {
                    let [face, other] =
                        face_starts_at_fault.map(|s| s.map(|s| located.line_span(&bytes, s)));
                    edge.face = face;
                    // Two triangles of one polygon are one face, shown once.
                    edge.other_face = other.filter(|&o| Some(o) != face);
                }
                for remark in remarks {
                    let mut diagnostic = Diagnostic::new(
                        remark.severity,
                        remark.message,
                        Some(located.span(remark.place)),
                    )
                    .with_secondary(span, "the mesh file named here");
                    for hint in remark.hints {
                        diagnostic = diagnostic.with_hint(hint);
                    }
                    diagnostics.push(diagnostic);
                }
                scene.meshes[handle] = mesh;
            }
            Err(MeshError {
                too_many: Some(count),
                ..
            }) => {
                let message = if limits.max_mesh_triangles <= scene_left {
                    format!(
                        "the mesh `{file}` has {count} triangles or more, over the mesh triangles limit of {}",
                        limits.max_mesh_triangles
                    )
                } else {
                    format!(
                        "the mesh `{file}` brings the scene's meshes to {} triangles or more, over the scene triangles limit of {}",
                        total.saturating_add(count),
                        limits.max_scene_triangles
                    )
                };
                diagnostics.push(
                    Diagnostic::error(message, span)
                        .with_label("the mesh file")
                        .with_hint("see \"Limits\" in docs/language.md; instances of one file share its triangles"),
                );
            }
            Err(error) => {
                let range = match &error.place {
                    Place::Whole => None,
                    Place::Line(line) => line_range(&bytes, *line),
                    Place::Bytes(range) => Some(range.clone()),
                };
                let mut diagnostic = match range {
                    Some(range) => {
                        let located =
                            Located::new(scene, &file, &bytes, std::slice::from_ref(&range));
                        Diagnostic::error(error.message, located.span(range))
                            .with_secondary(span, "the mesh file named here")
                    }
                    None => {
                        Diagnostic::error(format!("bad mesh `{file}`: {}", error.message), span)
                            .with_label("the mesh file")
                    }
                };
                for hint in error.hints {
                    diagnostic = diagnostic.with_hint(hint);
                }
                diagnostics.push(diagnostic);
            }
        }
    }
}

/// A mesh file in the source map, as far as the places its messages point at; or nothing,
/// when no message points into it.
struct Located {
    file: Option<whitted_ir::FileId>,
    /// How many bytes of the file the source map holds.
    length: usize,
}

impl Located {
    fn new(scene: &mut Scene, path: &str, bytes: &[u8], places: &[Range<usize>]) -> Located {
        let Some(last) = places.iter().map(|p| p.end.max(p.start)).max() else {
            return Located {
                file: None,
                length: 0,
            };
        };
        // Up to the end of the last line pointed at, its line end included (so that a CRLF
        // file's last line shown does not end in a lone `\r`).
        let last = last.min(bytes.len());
        let end = bytes[last..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| last + p + 1);
        let prefix = &bytes[..end];
        let text = match std::str::from_utf8(prefix) {
            Ok(text) => text,
            // Only a line that is not UTF-8 (its error points before the first bad byte)
            // or a binary PLY's header (all text) come here: cut at the first bad byte.
            Err(error) => std::str::from_utf8(&prefix[..error.valid_up_to()]).unwrap_or(""),
        };
        let file = scene.sources.add(SourceFile::new(path, text.to_string()));
        Located {
            file: Some(file),
            length: text.len(),
        }
    }

    /// The span of bytes of the file (cut to what the source map holds).
    fn span(&self, range: Range<usize>) -> Span {
        match self.file {
            Some(file) => Span::new(
                file,
                range.start.min(self.length),
                range.end.min(self.length),
            ),
            None => Span::detached(),
        }
    }

    /// The span of the line that starts at byte `start`, without its line end.
    fn line_span(&self, bytes: &[u8], start: usize) -> Span {
        let start = start.min(bytes.len());
        let end = bytes[start..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |p| start + p);
        let end = if end > start && bytes[end - 1] == b'\r' {
            end - 1
        } else {
            end
        };
        self.span(start..end)
    }
}

/// The bytes of line `line` (1-based), without its line end.
fn line_range(bytes: &[u8], line: usize) -> Option<Range<usize>> {
    let mut start = 0usize;
    for _ in 1..line {
        start += bytes.get(start..)?.iter().position(|&b| b == b'\n')? + 1;
    }
    let rest = bytes.get(start..)?;
    let mut end = start + rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
    if end > start && bytes[end - 1] == b'\r' {
        end -= 1;
    }
    Some(start..end)
}
