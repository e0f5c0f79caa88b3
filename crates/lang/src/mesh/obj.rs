//! Wavefront `.obj` files, read with tobj from bytes.
//!
//! tobj reports what went wrong but not where, and trusts face indices in arithmetic that
//! can overflow; so a quick pass over the lines first (`check`) finds the first line at
//! fault (a vertex that is not three finite numbers, a face index that names no vertex
//! defined before it) and counts the triangles against the budget, and tobj then builds
//! the mesh from a file known to be sound. Polygons are split into fans of triangles;
//! points and lines are ignored; materials (`mtllib`, `usemtl`) are ignored, as the scene
//! gives the mesh its material.

use super::{MeshData, MeshError};

/// Parses an OBJ file of at most `budget` triangles.
pub(super) fn parse(bytes: &[u8], budget: usize) -> Result<MeshData, MeshError> {
    check(bytes, budget)?;
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::Cursor::new(bytes);
    let (models, _materials) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|error| MeshError::whole(format!("tobj could not read it: {error}")))?;
    let mut data = MeshData::default();
    // Vertex normals only when every part of the file has one per vertex: a mesh cannot
    // interpolate normals it has only for some of its corners.
    let all_normals = models
        .iter()
        .all(|m| !m.mesh.normals.is_empty() && m.mesh.normals.len() == m.mesh.positions.len());
    for model in &models {
        let mesh = &model.mesh;
        let base = data.positions.len();
        let Ok(base) = u32::try_from(base) else {
            return Err(MeshError::whole("it has more than 2³² vertices"));
        };
        data.positions
            .extend(mesh.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        if all_normals {
            data.normals
                .extend(mesh.normals.chunks_exact(3).map(|n| [n[0], n[1], n[2]]));
        }
        for t in mesh.indices.chunks_exact(3) {
            let corner = |i: u32| base.checked_add(i);
            match (corner(t[0]), corner(t[1]), corner(t[2])) {
                (Some(a), Some(b), Some(c)) => data.triangles.push([a, b, c]),
                _ => return Err(MeshError::whole("it has more than 2³² vertices")),
            }
        }
    }
    Ok(data)
}

/// The first line at fault, and whether the triangles fit the budget.
fn check(bytes: &[u8], budget: usize) -> Result<(), MeshError> {
    let (mut positions, mut normals, mut texcoords) = (0usize, 0usize, 0usize);
    let mut triangles = 0usize;
    for (number, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line_number = number + 1;
        let Ok(line) = std::str::from_utf8(raw) else {
            return Err(MeshError::at(line_number, "this line is not UTF-8 text"));
        };
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                numbers(words, 3, "a vertex", line_number)?;
                positions += 1;
            }
            Some("vn") => {
                numbers(words, 3, "a normal", line_number)?;
                normals += 1;
            }
            Some("vt") => {
                numbers(words, 1, "a texture coordinate", line_number)?;
                texcoords += 1;
            }
            Some("f") => {
                let mut corners = 0usize;
                for word in words {
                    let counts = [positions, texcoords, normals];
                    for (slot, part) in word.split('/').enumerate() {
                        if part.is_empty() && slot > 0 {
                            continue;
                        }
                        let Some(&defined) = counts.get(slot) else {
                            return Err(MeshError::at(
                                line_number,
                                format!("`{word}` is not a face corner (`v`, `v/vt`, `v//vn` or `v/vt/vn`)"),
                            ));
                        };
                        index(part, defined, slot, line_number)?;
                    }
                    corners += 1;
                }
                triangles = triangles.saturating_add(corners.saturating_sub(2));
                if triangles > budget {
                    return Err(MeshError::too_many(triangles));
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// At least `count` finite numbers.
fn numbers<'a>(
    words: impl Iterator<Item = &'a str>,
    count: usize,
    what: &str,
    line: usize,
) -> Result<(), MeshError> {
    let mut found = 0;
    for word in words.take(count) {
        match word.parse::<f32>() {
            Ok(x) if x.is_finite() => found += 1,
            Ok(_) => {
                return Err(MeshError::at(
                    line,
                    format!("{what} has a number that is not finite: `{word}`"),
                ))
            }
            Err(_) => {
                return Err(MeshError::at(
                    line,
                    format!("{what} needs {count} numbers, and `{word}` is not one"),
                ))
            }
        }
    }
    if found < count {
        return Err(MeshError::at(
            line,
            format!("{what} needs {count} numbers, and this line has {found}"),
        ));
    }
    Ok(())
}

/// One index of a face corner: 1 to `defined` counts from the start, -1 to -`defined` back
/// from the latest (OBJ's relative indices); 0 and anything else name nothing.
fn index(word: &str, defined: usize, slot: usize, line: usize) -> Result<(), MeshError> {
    let (what, plural) = [
        ("vertex", "vertices"),
        ("texture coordinate", "texture coordinates"),
        ("normal", "normals"),
    ][slot];
    let Ok(i) = word.parse::<i64>() else {
        return Err(MeshError::at(
            line,
            format!("`{word}` is not a {what} index"),
        ));
    };
    let defined_i = defined as i64;
    let ok = (1..=defined_i).contains(&i) || (-defined_i..=-1).contains(&i);
    if ok {
        Ok(())
    } else {
        Err(MeshError::at(
            line,
            match defined {
                1 => format!("{what} index {i} is out of range: 1 {what} is defined before this line"),
                _ => format!("{what} index {i} is out of range: {defined} {plural} are defined before this line"),
            },
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE_CORNERS: &str =
        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n";

    #[test]
    fn quads_become_two_triangles_each_and_negative_indices_count_back() {
        let text = format!("{CUBE_CORNERS}f 1 2 3 4\nf -4 -3 -2 -1\n");
        let data = parse(text.as_bytes(), 100).unwrap();
        assert_eq!(data.positions.len(), 8);
        assert_eq!(data.triangles.len(), 4);
        assert!(data.normals.is_empty());
    }

    #[test]
    fn vertex_normals_come_one_per_vertex() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0.6 0.8\nf 1//1 2//1 3//2\n";
        let data = parse(text.as_bytes(), 100).unwrap();
        assert_eq!(data.triangles.len(), 1);
        assert_eq!(data.normals.len(), data.positions.len());
        let t = data.triangles[0];
        assert_eq!(data.normals[t[2] as usize], [0.0, 0.6, 0.8]);
    }

    #[test]
    fn errors_name_the_line() {
        let cases = [
            ("v 0 0 0\nv 1 0\n", 2, "needs 3 numbers"),
            ("v 0 0 0\nv 1 0 nan\n", 2, "not finite"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n",
                5,
                "vertex index 4 is out of range",
            ),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", 4, "vertex index 0"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 2 3\n",
                4,
                "vertex index -4",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n",
                4,
                "normal index 1",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 two 3\n",
                4,
                "`two` is not a vertex index",
            ),
            ("v 0 0 0\n\u{ff}\n", 2, "not UTF-8"),
        ];
        for (text, line, words) in cases {
            let bytes: Vec<u8> = if text.contains('\u{ff}') {
                text.replace('\u{ff}', "")
                    .bytes()
                    .take(8)
                    .chain([0xff, b'\n'])
                    .collect()
            } else {
                text.as_bytes().to_vec()
            };
            let error = parse(&bytes, 100).unwrap_err();
            assert_eq!(error.line, Some(line), "{text:?}: {error:?}");
            assert!(error.message.contains(words), "{text:?}: {error:?}");
        }
    }

    #[test]
    fn the_triangle_budget_is_checked_before_building() {
        let text = format!("{CUBE_CORNERS}f 1 2 3 4\nf 5 6 7 8\n");
        assert!(parse(text.as_bytes(), 4).is_ok());
        let error = parse(text.as_bytes(), 3).unwrap_err();
        assert_eq!(error.too_many, Some(4));
    }
}
