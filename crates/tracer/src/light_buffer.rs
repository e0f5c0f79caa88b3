//! Haines and Greenberg's light buffer (1986): for each point or spot light, which bounded
//! items lie in each direction from it, so that a shadow ray tests only the items in its
//! direction that are nearer the light than its origin, instead of walking the BVH; for a
//! directional light, which items lie in each column along its rays (a grid across them),
//! so that a shadow ray tests only those of its column that reach further towards the
//! light than its origin.
//!
//! The directions from a point light are the six faces of a cube around it; a face is the
//! directions whose largest component is along its axis, at `u = d[u_axis] / |d[axis]|`
//! and `v = d[v_axis] / |d[axis]|`, both in [-1, 1]. Each face keeps a grid over the window
//! its items cover, with cells of the median item's size, and each cell the items whose
//! directions reach it, nearest the light first. A shadow ray is answered from the cell of
//! its direction reversed.
//!
//! The answer is the walk's (`query.rs`'s `occluded_towards`): a ray that meets no
//! candidate (with the walk's own item test) is clear, because the candidates hold every
//! item it can meet: each item's directions are widened by more than the rounding of a
//! shadow ray's direction ([`angular_slack`]), and its distance from the light lowered by
//! more than the rounding of a point on the ray. A ray that meets a candidate well inside
//! the candidate's box is blocked, as the walk (whose boxes hold that box) finds it; at the
//! box's edge, within rounding, and whenever a recorder wants the blocker's name, the walk
//! answers.

use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use whitted_bvh::Ray;

/// Most cells of a face's grid for each item on the face: items scattered all round a
/// light would otherwise ask for a face's area in cells of their own small size.
const MAX_CELLS_PER_ITEM: f64 = 4.0;
/// Most cells along one side of a face's grid.
const MAX_SIDE: u32 = 1024;
/// The relative rounding a shadow ray's direction and a point on it may carry, many times
/// f32's: 2^-24 for each of the handful of operations that made them.
const RELATIVE_ROUNDING: f64 = 1e-5;
/// Directions widened by at least this much in `u` and `v` (about 0.006 degrees): far more
/// than rounding, which costs a few candidates at cell edges and nothing else.
const MIN_SLACK: f64 = 1e-4;
/// How far shadow rays may start, as a multiple of the largest coordinate of the light
/// and the items, and still be answered.
const REACH_FACTOR: f32 = 4.0;
/// A face's window reaches this far past [-1, 1], so that a direction on the edge between
/// two faces, rounded onto either, finds its cell.
const FACE_MARGIN: f64 = 0.01;

/// One light's buffer.
#[derive(Clone, Debug)]
pub(crate) struct LightBuffer {
    /// [`REACH_FACTOR`] times the largest coordinate (in magnitude) of the light and the
    /// bounded items: the rounding bounds hold for shadow rays starting within it. Others
    /// walk the BVH.
    reach: f32,
    projection: Projection,
    /// The cube's six faces for a point light; only the first for a directional one.
    faces: [FaceGrid; 6],
    /// Each cell's candidates start at `cell_starts[cell]` in `candidates`.
    cell_starts: Vec<u32>,
    candidates: Vec<Candidate>,
}

/// How directions become cells.
#[derive(Clone, Copy, Debug)]
enum Projection {
    /// From a point light: the cube's faces around it.
    Central,
    /// Along a directional light's rays: one grid across them, at `u = p · across[0]` and
    /// `v = p · across[1]`; `toward` is the unit vector towards the light, the very `f32`
    /// vector its shadow rays take, and the two across it are orthogonal to it.
    Parallel { across: [DVec3; 2], toward: DVec3 },
}

/// A face's grid over the window of `u` and `v` its items cover.
#[derive(Clone, Copy, Debug, Default)]
struct FaceGrid {
    u0: f32,
    v0: f32,
    /// Cells per unit of `u` and `v`.
    u_scale: f32,
    v_scale: f32,
    columns: u32,
    rows: u32,
    /// The face's first cell in `cell_starts`.
    first_cell: u32,
}

/// An item in a cell: its index among the bounded items and a lower bound of its distance
/// from the light.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Candidate {
    pub(crate) near: f32,
    pub(crate) item: u32,
}

/// What the buffer says about a shadow ray.
pub(crate) enum Lookup<'b> {
    /// The items the ray can meet, nearest the light first; those whose `near` exceeds the
    /// second value are too far from the light to be met.
    Candidates(&'b [Candidate], f32),
    /// The ray starts beyond the buffer's reach: ask the BVH.
    Unanswered,
}

/// An item's directions on one face, and its distance from the light.
#[derive(Clone, Copy, Debug)]
struct Footprint {
    face: usize,
    item: u32,
    u: (f64, f64),
    v: (f64, f64),
    near: f32,
}

impl LightBuffer {
    /// The buffer of a light at `position` over the bounded items' boxes (indexed as the
    /// items), or `None` when it would hold more than `max_candidates` entries.
    pub(crate) fn new(position: Vec3A, boxes: &[Aabb], max_candidates: usize) -> Option<Self> {
        let light = position.as_dvec3();
        let reach = reach(boxes, Some(position))?;
        let mut footprints = Vec::new();
        for (item, aabb) in boxes.iter().enumerate() {
            let lo = aabb.min.as_dvec3() - light;
            let hi = aabb.max.as_dvec3() - light;
            let distance = distance_to_box(lo.to_array(), hi.to_array());
            // Lowered by more than a point on a shadow ray can be off: the ray's origin and
            // direction are rounded at the scale of `reach`.
            let near = (distance * (1.0 - RELATIVE_ROUNDING) - RELATIVE_ROUNDING * f64::from(reach))
                .max(0.0) as f32;
            for face in 0..6 {
                let extent = face_extent(face, lo.to_array(), hi.to_array(), distance, reach);
                if let Some((u, v)) = extent {
                    footprints.push(Footprint {
                        face,
                        item: item as u32,
                        u,
                        v,
                        near,
                    });
                }
            }
        }
        Self::from_footprints(reach, Projection::Central, &footprints, max_candidates)
    }

    /// The buffer of a directional light whose shadow rays travel along `toward` over the
    /// bounded items' boxes, or `None` when it would hold more than `max_candidates`
    /// entries. A candidate's `near` is minus how far along `toward` its box reaches, so
    /// that the items furthest towards the light come first and those behind a ray's
    /// origin are left out.
    pub(crate) fn new_parallel(
        toward: Vec3A,
        boxes: &[Aabb],
        max_candidates: usize,
    ) -> Option<Self> {
        let reach = reach(boxes, None)?;
        let w = toward.as_dvec3();
        let unit = (w.length() - 1.0).abs() < 1e-3;
        if !unit {
            return None;
        }
        let first = w.any_orthonormal_vector();
        let across = [first, w.cross(first).normalize()];
        // Both across vectors exactly orthogonal to `w` would keep a ray's `u` and `v` the
        // same all along it; rounding leaves them off by about 1e-16, which over the reach
        // is far below the slack.
        let slack = RELATIVE_ROUNDING * f64::from(reach);
        let mut footprints = Vec::with_capacity(boxes.len());
        for (item, aabb) in boxes.iter().enumerate() {
            let (lo, hi) = (aabb.min.as_dvec3(), aabb.max.as_dvec3());
            let span = |axis: DVec3| {
                corners(lo, hi)
                    .map(|p| p.dot(axis))
                    .fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)))
            };
            let (u, v, along) = (span(across[0]), span(across[1]), span(w));
            footprints.push(Footprint {
                face: 0,
                item: item as u32,
                u: (u.0 - slack, u.1 + slack),
                v: (v.0 - slack, v.1 + slack),
                near: (-(along.1 + 2.0 * slack)) as f32,
            });
        }
        let projection = Projection::Parallel { across, toward: w };
        Self::from_footprints(reach, projection, &footprints, max_candidates)
    }

    /// The buffer of these footprints: their faces' grids, and each cell's candidates.
    fn from_footprints(
        reach: f32,
        projection: Projection,
        footprints: &[Footprint],
        max_candidates: usize,
    ) -> Option<Self> {
        let mut faces = [FaceGrid::default(); 6];
        let mut first_cell = 0u32;
        for (face, grid) in faces.iter_mut().enumerate() {
            *grid = FaceGrid::over(footprints.iter().filter(|f| f.face == face), first_cell);
            first_cell += grid.columns * grid.rows;
        }
        // Counted first, so that a buffer over budget is never allocated: its cells (three
        // arrays of 4 bytes while it is made) and its candidates (8 bytes) together.
        let cells = first_cell as usize + 1;
        if cells > max_candidates {
            return None;
        }
        // Each cell's count, then (summed in place) where its candidates start.
        let mut cell_starts = vec![0u32; cells];
        let mut total = 0usize;
        for footprint in footprints {
            let grid = &faces[footprint.face];
            let (columns, rows) = grid.cells_of(footprint);
            total += columns.len() * rows.len();
            if cells + total > max_candidates {
                return None;
            }
            for row in rows {
                for column in columns.clone() {
                    cell_starts[grid.cell(column, row)] += 1;
                }
            }
        }
        let mut start = 0u32;
        for entry in &mut cell_starts {
            let count = *entry;
            *entry = start;
            start += count;
        }
        let mut fill = cell_starts.clone();
        let mut candidates = vec![Candidate { near: 0.0, item: 0 }; total];
        for footprint in footprints {
            let grid = &faces[footprint.face];
            let (columns, rows) = grid.cells_of(footprint);
            for row in rows {
                for column in columns.clone() {
                    let cell = grid.cell(column, row);
                    candidates[fill[cell] as usize] = Candidate {
                        near: footprint.near,
                        item: footprint.item,
                    };
                    fill[cell] += 1;
                }
            }
        }
        for cell in cell_starts.windows(2) {
            // Footprints were made in item order, so equal distances keep it: the same
            // buffer on every run.
            candidates[cell[0] as usize..cell[1] as usize]
                .sort_by(|a, b| a.near.total_cmp(&b.near));
        }
        Some(LightBuffer {
            reach,
            projection,
            faces,
            cell_starts,
            candidates,
        })
    }

    /// Candidates in all the buffer's cells (for the statistics).
    pub(crate) fn len(&self) -> usize {
        self.candidates.len()
    }

    /// The bytes of its cells and candidates.
    pub(crate) fn bytes(&self) -> usize {
        std::mem::size_of_val(self.candidates.as_slice())
            + std::mem::size_of_val(self.cell_starts.as_slice())
    }

    /// What the buffer counts against the scene's budget: its candidates and its cells.
    pub(crate) fn budget_used(&self) -> usize {
        self.candidates.len() + self.cell_starts.len()
    }

    /// The candidates of a shadow ray towards this light that stops at `tmax` (infinite
    /// for a directional light).
    #[inline]
    pub(crate) fn lookup(&self, ray: &Ray, tmax: f32) -> Lookup<'_> {
        // NaN origins too.
        let within_reach = ray.origin.abs().max_element() <= self.reach;
        if !within_reach {
            return Lookup::Unanswered;
        }
        let (across, toward) = match self.projection {
            Projection::Central => return self.lookup_central(ray, tmax),
            Projection::Parallel { across, toward } => (across, toward),
        };
        let origin = ray.origin.as_dvec3();
        let grid = &self.faces[0];
        let column = (origin.dot(across[0]) as f32 - grid.u0) * grid.u_scale;
        let row = (origin.dot(across[1]) as f32 - grid.v0) * grid.v_scale;
        // Outside the window: no item lies that way.
        if !(column >= 0.0 && row >= 0.0 && column < grid.columns as f32 && row < grid.rows as f32)
        {
            return Lookup::Candidates(&[], 0.0);
        }
        let cell = grid.cell(column as u32, row as u32);
        let (start, end) = (self.cell_starts[cell], self.cell_starts[cell + 1]);
        // Items whose boxes end (with slack) before the origin, along the ray, are behind it.
        let limit = -origin.dot(toward) as f32;
        Lookup::Candidates(&self.candidates[start as usize..end as usize], limit)
    }

    /// [`LightBuffer::lookup`] for a point light.
    #[inline(always)]
    fn lookup_central(&self, ray: &Ray, tmax: f32) -> Lookup<'_> {
        // The direction from the light back along the ray.
        let d = -ray.direction;
        let a = d.abs();
        let (axis, major) = if a.x >= a.y && a.x >= a.z {
            (0, d.x)
        } else if a.y >= a.z {
            (1, d.y)
        } else {
            (2, d.z)
        };
        let has_direction = major != 0.0;
        if !has_direction {
            return Lookup::Unanswered;
        }
        let face = 2 * axis + usize::from(major < 0.0);
        let grid = &self.faces[face];
        let m = major.abs();
        let u = d[(axis + 1) % 3] / m;
        let v = d[(axis + 2) % 3] / m;
        let column = (u - grid.u0) * grid.u_scale;
        let row = (v - grid.v0) * grid.v_scale;
        // Outside the window (or a face without items): no item lies that way.
        if !(column >= 0.0 && row >= 0.0 && column < grid.columns as f32 && row < grid.rows as f32)
        {
            return Lookup::Candidates(&[], 0.0);
        }
        // Truncation is the floor here (both are at least 0), without a call to `floorf`.
        let cell = grid.cell(column as u32, row as u32);
        let (start, end) = (self.cell_starts[cell], self.cell_starts[cell + 1]);
        // A point the ray meets before `tmax` is at most `tmax` from the light, give or take
        // rounding, which the candidates' `near` already allows for.
        let limit = tmax * (1.0 + RELATIVE_ROUNDING as f32);
        Lookup::Candidates(&self.candidates[start as usize..end as usize], limit)
    }
}

impl FaceGrid {
    /// A grid over the window the footprints cover, whose cells are as wide and high as the
    /// median footprint (finer cells, half as wide, listed 2.3 times the candidates and
    /// rendered no faster), with at most [`MAX_CELLS_PER_ITEM`] cells for each footprint.
    fn over<'f>(footprints: impl Iterator<Item = &'f Footprint>, first_cell: u32) -> FaceGrid {
        let (mut widths, mut heights) = (Vec::new(), Vec::new());
        let (mut u_lo, mut u_hi, mut v_lo, mut v_hi) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for f in footprints {
            widths.push(f.u.1 - f.u.0);
            heights.push(f.v.1 - f.v.0);
            u_lo = u_lo.min(f.u.0);
            u_hi = u_hi.max(f.u.1);
            v_lo = v_lo.min(f.v.0);
            v_hi = v_hi.max(f.v.1);
        }
        let count = widths.len();
        if count == 0 {
            return FaceGrid {
                first_cell,
                ..FaceGrid::default()
            };
        }
        // Never narrower than slack, so that the scales stay finite.
        let width = (u_hi - u_lo).max(MIN_SLACK);
        let height = (v_hi - v_lo).max(MIN_SLACK);
        let cell_width = median(&mut widths).max(MIN_SLACK);
        let cell_height = median(&mut heights).max(MIN_SLACK);
        let mut columns = (width / cell_width).ceil().min(f64::from(MAX_SIDE));
        let mut rows = (height / cell_height).ceil().min(f64::from(MAX_SIDE));
        let most = MAX_CELLS_PER_ITEM * count as f64;
        if columns * rows > most {
            let shrink = (most / (columns * rows)).sqrt();
            columns = (columns * shrink).ceil();
            rows = (rows * shrink).ceil();
        }
        let (columns, rows) = (columns.max(1.0), rows.max(1.0));
        FaceGrid {
            u0: u_lo as f32,
            v0: v_lo as f32,
            u_scale: (columns / width) as f32,
            v_scale: (rows / height) as f32,
            columns: columns as u32,
            rows: rows as u32,
            first_cell,
        }
    }

    fn cell(&self, column: u32, row: u32) -> usize {
        (self.first_cell + row * self.columns + column) as usize
    }

    /// The columns and rows a footprint covers. Computed with the lookup's own f32
    /// arithmetic on the widened extent, so that a direction inside the extent finds a
    /// cell inside the range.
    fn cells_of(&self, f: &Footprint) -> (std::ops::Range<u32>, std::ops::Range<u32>) {
        let index = |x: f64, origin: f32, scale: f32, len: u32| {
            // As `lookup` finds its cell (below 0 is column 0 either way).
            let i = (x as f32 - origin) * scale;
            (i.max(0.0) as u32).min(len - 1)
        };
        let columns = index(f.u.0, self.u0, self.u_scale, self.columns)
            ..index(f.u.1, self.u0, self.u_scale, self.columns) + 1;
        let rows = index(f.v.0, self.v0, self.v_scale, self.rows)
            ..index(f.v.1, self.v0, self.v_scale, self.rows) + 1;
        (columns, rows)
    }
}

/// [`REACH_FACTOR`] times the largest coordinate (in magnitude) of the boxes and the light
/// (a directional one has none); `None` when that is not finite. Well beyond the items, so
/// that shadow rays from planes around them are answered too; the widening grows with it.
fn reach(boxes: &[Aabb], light: Option<Vec3A>) -> Option<f32> {
    let largest = boxes
        .iter()
        .flat_map(|b| [b.min, b.max])
        .chain(light)
        .map(|p| p.abs().max_element())
        .fold(0.0f32, f32::max);
    Some(REACH_FACTOR * largest).filter(|reach| reach.is_finite())
}

/// The eight corners of the box `[lo, hi]`.
fn corners(lo: DVec3, hi: DVec3) -> impl Iterator<Item = DVec3> {
    (0..8).map(move |corner: u32| {
        let pick = |bit: u32, a: f64, b: f64| if corner & bit == 0 { a } else { b };
        DVec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        )
    })
}

/// The median of `values` (reordered).
fn median(values: &mut [f64]) -> f64 {
    let middle = values.len() / 2;
    *values.select_nth_unstable_by(middle, f64::total_cmp).1
}

/// The Euclidean distance from the origin to the box `[lo, hi]`.
fn distance_to_box(lo: [f64; 3], hi: [f64; 3]) -> f64 {
    (0..3)
        .map(|i| lo[i].max(0.0).max(-hi[i]))
        .map(|gap| gap * gap)
        .sum::<f64>()
        .sqrt()
}

/// The widening of an item's directions, in `u` and `v`, for an item at least `near` from
/// the light. A point on a shadow ray is off by rounding at the scale of `reach`; seen from
/// the light at distance `near` or more, that turns its direction by up to that error over
/// `near`.
fn angular_slack(near: f64, reach: f32) -> f64 {
    // `u` is a tangent: within a face's margin it moves at most about twice as fast as the
    // angle.
    2.0 * (MIN_SLACK + 4.0 * RELATIVE_ROUNDING * f64::from(reach) / near)
}

/// The extent in `u` and `v` of the box `[lo, hi]` (relative to the light, and `near` from
/// it) on `face`, widened by [`angular_slack`] and kept within the face's margin; `None`
/// when no direction of the face reaches the box.
#[allow(clippy::type_complexity)]
fn face_extent(
    face: usize,
    lo: [f64; 3],
    hi: [f64; 3],
    near: f64,
    reach: f32,
) -> Option<((f64, f64), (f64, f64))> {
    let axis = face / 2;
    let (near_major, far_major) = if face.is_multiple_of(2) {
        (lo[axis], hi[axis])
    } else {
        (-hi[axis], -lo[axis])
    };
    let seen = far_major > 0.0;
    if !seen {
        return None;
    }
    let limit = 1.0 + FACE_MARGIN;
    // A box around the light (or touching it) is seen in every direction.
    let apart = near > 0.0;
    if !apart {
        return Some(((-limit, limit), (-limit, limit)));
    }
    let slack = angular_slack(near, reach);
    // The least and greatest of `c / m` over `c` in `[c_lo, c_hi]` and `m` in
    // `[near_major, far_major]`, `m > 0`: at the corners, or unbounded when the box
    // reaches the light's plane.
    let extent = |c_lo: f64, c_hi: f64| -> (f64, f64) {
        let least = if c_lo >= 0.0 {
            c_lo / far_major
        } else if near_major > 0.0 {
            c_lo / near_major
        } else {
            -limit
        };
        let greatest = if c_hi <= 0.0 {
            c_hi / far_major
        } else if near_major > 0.0 {
            c_hi / near_major
        } else {
            limit
        };
        ((least - slack).max(-limit), (greatest + slack).min(limit))
    };
    let u_axis = (axis + 1) % 3;
    let v_axis = (axis + 2) % 3;
    let u = extent(lo[u_axis], hi[u_axis]);
    let v = extent(lo[v_axis], hi[v_axis]);
    // A box seen only at directions of another face (past this one's margin).
    if u.0 > u.1 || v.0 > v.1 {
        return None;
    }
    Some((u, v))
}

#[cfg(test)]
mod tests;
