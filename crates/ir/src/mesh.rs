//! Triangle meshes: the geometry of a mesh file, held once in [`crate::Scene::meshes`] and
//! instanced by any number of objects (`Shape::Mesh`), each with its own transform.
//!
//! A mesh is a **solid** when it is closed and consistently oriented: after welding vertices
//! at exactly the same position, every edge is shared by exactly two triangles that cross it
//! in opposite directions. A solid's triangles are stored wound so that their normals
//! (`(b - a) × (c - a)`) point out of it (a file wound the other way is turned over), so that
//! the tracer decides entering and leaving from the face it hits, as for a sphere.

use glam::DVec3;
use serde::Serialize;

/// The geometry of one mesh file, in the file's own coordinates.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// The file as the scene named it, joined onto the scene's folder (for messages).
    pub file: String,
    pub positions: Vec<[f32; 3]>,
    /// Per-vertex normals from the file: empty, or one per position.
    pub normals: Vec<[f32; 3]>,
    /// Corner indices into `positions` (and `normals`).
    pub triangles: Vec<[u32; 3]>,
    /// Closed and consistently oriented, with outward-facing triangles (see the module).
    pub solid: bool,
}

/// What `whitted ir --json` shows of a mesh: its counts, not its vertices.
#[derive(Serialize)]
pub(crate) struct MeshSummary<'a> {
    file: &'a str,
    vertices: usize,
    triangles: usize,
    normals: bool,
    solid: bool,
}

impl Mesh {
    /// A mesh from a file's data. Works out whether it is a solid and, if it is one wound
    /// inwards, turns its triangles over. Indices are not checked here (validation does);
    /// out-of-range ones only make the mesh not a solid.
    pub fn new(
        file: String,
        positions: Vec<[f32; 3]>,
        normals: Vec<[f32; 3]>,
        mut triangles: Vec<[u32; 3]>,
    ) -> Mesh {
        let solid = match orientation(&positions, &triangles) {
            Some(Orientation::Outward) => true,
            Some(Orientation::Inward) => {
                for t in &mut triangles {
                    t.swap(1, 2);
                }
                true
            }
            None => false,
        };
        Mesh {
            file,
            positions,
            normals,
            triangles,
            solid,
        }
    }

    pub(crate) fn summary(&self) -> MeshSummary<'_> {
        MeshSummary {
            file: &self.file,
            vertices: self.positions.len(),
            triangles: self.triangles.len(),
            normals: !self.normals.is_empty(),
            solid: self.solid,
        }
    }

    /// The box around its positions (`None` when it has none, or one is not finite).
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let mut lo = DVec3::INFINITY;
        let mut hi = DVec3::NEG_INFINITY;
        for p in &self.positions {
            let p = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
    }
}

/// Which way a closed, consistently wound mesh faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Orientation {
    Outward,
    Inward,
}

/// `Some` when the mesh is closed and consistently oriented (and encloses a volume), with
/// the way its triangles face; `None` otherwise.
fn orientation(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Option<Orientation> {
    if triangles.is_empty() || triangles.len() > u32::MAX as usize / 3 {
        return None;
    }
    let welded = weld(positions);
    // Each directed edge as (low, high, direction), sorted: a closed, consistently wound
    // mesh has every undirected edge exactly twice, once each way. Sorting rather than
    // hashing keeps a million triangles at 24 MB and well under a second.
    let mut edges: Vec<(u32, u32, bool)> = Vec::with_capacity(triangles.len() * 3);
    for t in triangles {
        let mut ids = [0u32; 3];
        for (id, &index) in ids.iter_mut().zip(t) {
            *id = *welded.get(index as usize)?;
        }
        if ids[0] == ids[1] || ids[1] == ids[2] || ids[0] == ids[2] {
            // A triangle with two corners at one point has an edge that is no edge.
            return None;
        }
        for k in 0..3 {
            let (a, b) = (ids[k], ids[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), a < b));
        }
    }
    edges.sort_unstable();
    for pair in edges.chunks(2) {
        let [first, second] = pair else { return None };
        if (first.0, first.1) != (second.0, second.1) || first.2 == second.2 {
            return None;
        }
    }
    // The signed volume (divergence theorem), in f64: positive when faces point out.
    let point = |i: u32| {
        let p = positions[i as usize];
        DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]))
    };
    let volume: f64 = triangles
        .iter()
        .map(|t| point(t[0]).dot(point(t[1]).cross(point(t[2]))))
        .sum();
    if volume > 0.0 {
        Some(Orientation::Outward)
    } else if volume < 0.0 {
        Some(Orientation::Inward)
    } else {
        None
    }
}

/// One id per distinct position (bit for bit, with -0.0 and 0.0 the same), so that files
/// that repeat a vertex for each of its normals still count as closed.
fn weld(positions: &[[f32; 3]]) -> Vec<u32> {
    let key = |p: &[f32; 3]| p.map(|x| if x == 0.0 { 0 } else { x.to_bits() });
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.sort_unstable_by_key(|&i| key(&positions[i as usize]));
    let mut ids = vec![0u32; positions.len()];
    let mut next = 0u32;
    for (k, &i) in order.iter().enumerate() {
        if k > 0 && key(&positions[order[k - 1] as usize]) != key(&positions[i as usize]) {
            next += 1;
        }
        ids[i as usize] = next;
    }
    ids
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetrahedron() -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        // Wound so that (b - a) × (c - a) points away from the inside.
        let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        (positions, triangles)
    }

    #[test]
    fn a_closed_outward_tetrahedron_is_a_solid_as_it_is() {
        let (p, t) = tetrahedron();
        let mesh = Mesh::new("t.obj".into(), p, vec![], t.clone());
        assert!(mesh.solid);
        assert_eq!(mesh.triangles, t);
    }

    #[test]
    fn an_inward_tetrahedron_is_turned_over() {
        let (p, mut t) = tetrahedron();
        for tri in &mut t {
            tri.swap(1, 2);
        }
        let mesh = Mesh::new("t.obj".into(), p.clone(), vec![], t);
        assert!(mesh.solid);
        assert_eq!(mesh, Mesh::new("t.obj".into(), p, vec![], tetrahedron().1));
    }

    #[test]
    fn open_or_inconsistent_meshes_are_not_solids() {
        let (p, t) = tetrahedron();
        let open = Mesh::new("t.obj".into(), p.clone(), vec![], t[..3].to_vec());
        assert!(!open.solid);
        let mut flipped_one = t.clone();
        flipped_one[0].swap(1, 2);
        assert!(!Mesh::new("t.obj".into(), p.clone(), vec![], flipped_one).solid);
        let mut doubled = t.clone();
        doubled.extend_from_slice(&t);
        assert!(!Mesh::new("t.obj".into(), p, vec![], doubled).solid);
    }

    #[test]
    fn repeated_vertices_are_welded_by_position() {
        let (p, t) = tetrahedron();
        // Every corner its own vertex, as files with per-face normals write them.
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for tri in &t {
            let base = positions.len() as u32;
            positions.extend(tri.iter().map(|&i| p[i as usize]));
            triangles.push([base, base + 1, base + 2]);
        }
        assert!(Mesh::new("t.obj".into(), positions, vec![], triangles).solid);
    }
}
