//! Mesh files: after evaluation, each mesh the scene named is read through the
//! [`SourceLoader`] (bytes in, the library never touches the disk) and parsed by its
//! extension, `.obj` (`obj.rs`, with tobj) or `.ply` (`ply.rs`, a reader of its own). Every problem is an error
//! at the `file` property that first named the mesh, naming the file and, where a line of
//! the file is at fault, that line.

mod obj;
mod ply;

use whitted_ir::{Diagnostic, Mesh, Scene};

use crate::{Limits, SourceLoader};

/// A mesh file's contents before the IR checks it.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct MeshData {
    pub positions: Vec<[f32; 3]>,
    /// Empty, or one per position.
    pub normals: Vec<[f32; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

/// What is wrong with a mesh file, and on which line (1-based) when one line is to blame.
#[derive(Debug, PartialEq)]
pub(crate) struct MeshError {
    pub line: Option<usize>,
    pub message: String,
    /// Set when the file has more triangles than its budget: how many it has at least.
    pub too_many: Option<usize>,
}

impl MeshError {
    pub(crate) fn at(line: usize, message: impl Into<String>) -> MeshError {
        MeshError {
            line: Some(line),
            message: message.into(),
            too_many: None,
        }
    }

    pub(crate) fn whole(message: impl Into<String>) -> MeshError {
        MeshError {
            line: None,
            message: message.into(),
            too_many: None,
        }
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
                scene.meshes[handle] =
                    Mesh::new(file, data.positions, data.normals, data.triangles);
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
                let place = match error.line {
                    Some(line) => format!("`{file}`, line {line}"),
                    None => format!("`{file}`"),
                };
                diagnostics.push(
                    Diagnostic::error(format!("bad mesh {place}: {}", error.message), span)
                        .with_label("the mesh file"),
                );
            }
        }
    }
}

impl MeshError {
    /// A file with at least `count` triangles, more than its budget.
    pub(crate) fn too_many(count: usize) -> MeshError {
        MeshError {
            line: None,
            message: String::new(),
            too_many: Some(count),
        }
    }
}
