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

use crate::source::Span;

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
    /// Why it is not a solid, with an example, for the message of a CSG that needs one.
    pub not_solid: Option<NotSolid>,
}

/// Why a mesh is not a solid.
#[derive(Clone, Debug, PartialEq)]
pub enum NotSolid {
    /// It has no triangles, or corners that name no vertex (validation reports those).
    Unchecked,
    /// Closed and consistently oriented, but it encloses no volume.
    Flat,
    /// An edge at fault, with the triangle that has it.
    Edge(BadEdge),
}

/// One edge that keeps a mesh from being a solid: the first such in triangle order, so that
/// the face a message shows is the earliest in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct BadEdge {
    pub defect: EdgeDefect,
    /// Its two vertices, in the triangle's direction, numbered as the file numbers them:
    /// `positions` indices + 1 from [`Mesh::new`], renumbered by a front end that knows
    /// better.
    pub vertices: [u64; 2],
    /// The triangle that has it (an index into `triangles`).
    pub triangle: u32,
    /// Another triangle that has it (none for an open edge or a degenerate face).
    pub other_triangle: Option<u32>,
    /// Where the file writes those triangles' faces, when the front end says.
    pub face: Option<Span>,
    pub other_face: Option<Span>,
}

/// What is wrong with a [`BadEdge`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeDefect {
    /// Used by one face only: the surface has a hole there.
    Open,
    /// Used twice in the same direction: one of the faces is turned over.
    Inconsistent,
    /// Used by more than two faces.
    Shared,
    /// Both ends at one point: a face with two corners at one position.
    Degenerate,
}

impl NotSolid {
    /// What is wrong, in words that follow "this mesh" ("is open: ...").
    pub fn describe(&self) -> String {
        match self {
            NotSolid::Unchecked => "is not a solid".to_string(),
            NotSolid::Flat => "is closed but encloses no volume".to_string(),
            NotSolid::Edge(edge) => {
                let [a, b] = edge.vertices;
                match edge.defect {
                    EdgeDefect::Open => format!(
                        "is open: the edge between vertices {a} and {b} belongs to one face only"
                    ),
                    EdgeDefect::Inconsistent => format!(
                        "is inconsistently oriented: two faces run from vertex {a} to vertex {b}, where one should run back"
                    ),
                    EdgeDefect::Shared => format!(
                        "is not a closed surface: the edge between vertices {a} and {b} belongs to more than two faces"
                    ),
                    EdgeDefect::Degenerate => format!(
                        "has a face with two corners at one point (vertices {a} and {b})"
                    ),
                }
            }
        }
    }
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
        let orientation = orientation(&positions, &triangles);
        if orientation == Ok(Orientation::Inward) {
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        Mesh {
            file,
            positions,
            normals,
            triangles,
            solid: orientation.is_ok(),
            not_solid: orientation.err(),
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

/// The way a closed, consistently oriented mesh (that encloses a volume) faces, or why it
/// is not one.
fn orientation(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<Orientation, NotSolid> {
    if triangles.is_empty() || triangles.len() > u32::MAX as usize / 3 {
        return Err(NotSolid::Unchecked);
    }
    let welded = weld(positions);
    let mut ids = Vec::with_capacity(triangles.len());
    for t in triangles {
        let mut id = [0u32; 3];
        for (id, &index) in id.iter_mut().zip(t) {
            *id = *welded.get(index as usize).ok_or(NotSolid::Unchecked)?;
        }
        ids.push(id);
    }
    // Each directed edge as (low, high, direction), sorted: a closed, consistently wound
    // mesh has every undirected edge exactly twice, once each way. Sorting rather than
    // hashing keeps a million triangles at about 50 MB (with `ids`) and well under a second.
    let mut edges: Vec<(u32, u32, bool)> = Vec::with_capacity(triangles.len() * 3);
    // A triangle with two corners at one point has an edge that is no edge.
    let mut degenerate = None;
    for (k, id) in ids.iter().enumerate() {
        if id[0] == id[1] || id[1] == id[2] || id[0] == id[2] {
            degenerate.get_or_insert(k);
            continue;
        }
        for j in 0..3 {
            let (a, b) = (id[j], id[(j + 1) % 3]);
            edges.push((a.min(b), a.max(b), a < b));
        }
    }
    edges.sort_unstable();
    // The edges at fault, by kind (undirected, as (low, high)).
    let mut faults: [Vec<(u32, u32)>; 3] = Default::default();
    let mut at = 0;
    while at < edges.len() {
        let (lo, hi, _) = edges[at];
        let run = edges[at..]
            .iter()
            .take_while(|e| (e.0, e.1) == (lo, hi))
            .count();
        let defect = match run {
            1 => Some(0),
            2 if edges[at].2 == edges[at + 1].2 => Some(1),
            2 => None,
            _ => Some(2),
        };
        if let Some(kind) = defect {
            faults[kind].push((lo, hi));
        }
        at += run;
    }
    let kinds = [
        EdgeDefect::Open,
        EdgeDefect::Inconsistent,
        EdgeDefect::Shared,
    ];
    if let Some((kind, faulty)) = kinds.iter().zip(&faults).find(|(_, f)| !f.is_empty()) {
        // The earliest triangle with an edge of that kind (`faulty` is sorted).
        for (k, id) in ids.iter().enumerate() {
            if Some(k) == degenerate || id[0] == id[1] || id[1] == id[2] || id[0] == id[2] {
                continue;
            }
            for j in 0..3 {
                let (a, b) = (id[j], id[(j + 1) % 3]);
                if faulty.binary_search(&(a.min(b), a.max(b))).is_ok() {
                    let t = triangles[k];
                    // Any other triangle with the edge comes later: `k` is the first with
                    // any edge at fault.
                    let other = ids[k + 1..]
                        .iter()
                        .position(|o| {
                            (0..3).any(|i| {
                                let (c, d) = (o[i], o[(i + 1) % 3]);
                                (c.min(d), c.max(d)) == (a.min(b), a.max(b))
                            })
                        })
                        .map(|offset| (k + 1 + offset) as u32);
                    return Err(NotSolid::Edge(BadEdge {
                        defect: *kind,
                        vertices: [u64::from(t[j]) + 1, u64::from(t[(j + 1) % 3]) + 1],
                        triangle: k as u32,
                        other_triangle: other,
                        face: None,
                        other_face: None,
                    }));
                }
            }
        }
    }
    if let Some(k) = degenerate {
        let (t, id) = (triangles[k], ids[k]);
        let j = (0..3).find(|&j| id[j] == id[(j + 1) % 3]).unwrap_or(0);
        return Err(NotSolid::Edge(BadEdge {
            defect: EdgeDefect::Degenerate,
            vertices: [u64::from(t[j]) + 1, u64::from(t[(j + 1) % 3]) + 1],
            triangle: k as u32,
            other_triangle: None,
            face: None,
            other_face: None,
        }));
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
        Ok(Orientation::Outward)
    } else if volume < 0.0 {
        Ok(Orientation::Inward)
    } else {
        Err(NotSolid::Flat)
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

    /// What a CSG's message says of a mesh that is not a solid: the kind of fault, and the
    /// earliest triangle's edge of that kind.
    #[test]
    fn open_or_inconsistent_meshes_are_not_solids_and_say_why() {
        let (p, t) = tetrahedron();
        let defect = |triangles: Vec<[u32; 3]>| {
            let mesh = Mesh::new("t.obj".into(), p.clone(), vec![], triangles);
            assert!(!mesh.solid);
            match mesh.not_solid {
                Some(NotSolid::Edge(edge)) => (
                    edge.defect,
                    edge.vertices,
                    edge.triangle,
                    edge.other_triangle,
                ),
                other => panic!("{other:?}"),
            }
        };
        // The last three faces: the first face's edges are each used once, and the
        // earliest triangle with one is the first left, [0, 1, 3], at its edge 1 -> 2.
        assert_eq!(defect(t[1..].to_vec()), (EdgeDefect::Open, [1, 2], 0, None));
        let mut flipped_last = t.clone();
        flipped_last[3].swap(1, 2);
        assert_eq!(
            defect(flipped_last),
            (EdgeDefect::Inconsistent, [3, 2], 0, Some(3)),
            "the first triangle runs 2 -> 1, as the flipped [1, 3, 2] does"
        );
        let mut doubled = t.clone();
        doubled.extend_from_slice(&t);
        assert_eq!(defect(doubled), (EdgeDefect::Shared, [1, 3], 0, Some(2)));
        let mut pinched = t.clone();
        pinched[2] = [0, 3, 3];
        assert_eq!(
            defect(pinched).0,
            EdgeDefect::Open,
            "an open edge is told first"
        );
        let flat = Mesh::new(
            "t.obj".into(),
            p.clone(),
            vec![],
            vec![[0, 1, 2], [0, 2, 1]],
        );
        assert_eq!(flat.not_solid, Some(NotSolid::Flat));
        assert!(Mesh::new("t.obj".into(), p.clone(), vec![], t)
            .not_solid
            .is_none());
        let out_of_range = Mesh::new("t.obj".into(), p, vec![], vec![[0, 1, 9]]);
        assert_eq!(out_of_range.not_solid, Some(NotSolid::Unchecked));
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
