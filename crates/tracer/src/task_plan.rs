//! Splitting one image into tasks of about the same cost: a cheap, deterministic estimate
//! of each row's cost (a few probe rays per row), cut into contiguous bands of rows.
//!
//! The plan is a pure function of the scene, the options and the task count: every task of
//! a farm computes it on its own and all must agree, so the probes are fixed pixels traced
//! alone (no packets, no threads deciding anything) and the cut uses integer arithmetic.

use std::ops::Range;

use rayon::prelude::*;

use crate::recorder::NoRecord;
use crate::render::{trace_sample, PixelRect, RenderOptions};
use crate::scene::PreparedScene;
use crate::trace::{RayCounters, Tracer};

fn rays(c: &RayCounters) -> u64 {
    c.camera + c.shadow + c.reflected + c.transmitted
}

/// About this many probe pixels in all, whatever the image's size (each traced once).
const PROBE_BUDGET: u64 = 65_536;

/// The probes per row for a `width` x `height` image: at least 4 (at most the width), at
/// most 32, fewer for tall images so that the estimate stays cheap.
pub fn probes_per_row(width: u32, height: u32) -> u32 {
    let per_row = (PROBE_BUDGET / u64::from(height.max(1))).clamp(4, 32) as u32;
    per_row.min(width.max(1))
}

/// The estimated cost of each row of the image, in rays: the rays traced by sample 0 of
/// [`probes_per_row`] pixels spread evenly along the row. Only the ratios matter; a row's
/// cost is at least 1.
pub fn row_costs(scene: &PreparedScene, options: &RenderOptions) -> Vec<u64> {
    let (width, height) = (options.width, options.height);
    let probes = probes_per_row(width, height);
    (0..height)
        .into_par_iter()
        .map_init(
            || Tracer::new(scene, options.depth_limit(), options.min_weight),
            |tracer, y| {
                let before = rays(&tracer.counters);
                for j in 0..probes {
                    // The centre of the j-th of `probes` equal stretches of the row.
                    let x = ((2 * u64::from(j) + 1) * u64::from(width) / (2 * u64::from(probes)))
                        as u32;
                    trace_sample(tracer, scene, options, x, y, 0, &mut NoRecord);
                }
                (rays(&tracer.counters) - before).max(1)
            },
        )
        .collect()
}

/// Why rows cannot be split as asked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SplitError {
    /// No tasks were asked for.
    NoTasks,
    /// More tasks than rows: each task needs at least one row.
    MoreTasksThanRows { tasks: u32, rows: u32 },
}

impl std::fmt::Display for SplitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SplitError::NoTasks => write!(f, "the number of tasks must be at least 1"),
            SplitError::MoreTasksThanRows { tasks, rows } => write!(
                f,
                "{tasks} tasks for an image of {rows} rows: each task needs at least one row"
            ),
        }
    }
}

impl std::error::Error for SplitError {}

/// Cuts rows `0..costs.len()` into `tasks` contiguous, non-empty bands of about the same
/// total cost: band `i` ends at the first row where the cost so far reaches `(i + 1) / tasks`
/// of the whole, moved as little as needed to leave every band a row.
pub fn split_rows(costs: &[u64], tasks: u32) -> Result<Vec<Range<u32>>, SplitError> {
    let rows = u32::try_from(costs.len()).unwrap_or(u32::MAX);
    if tasks == 0 {
        return Err(SplitError::NoTasks);
    }
    if tasks > rows {
        return Err(SplitError::MoreTasksThanRows { tasks, rows });
    }
    let total: u128 = costs.iter().map(|&c| u128::from(c)).sum();
    let mut bands = Vec::with_capacity(tasks as usize);
    let mut start = 0u32;
    let mut prefix: u128 = 0;
    let mut row = 0u32;
    for i in 1..tasks {
        // The first row end `e` with prefix(e) * tasks >= total * i.
        let target = total * u128::from(i);
        while row < rows && prefix * u128::from(tasks) < target {
            prefix += u128::from(costs[row as usize]);
            row += 1;
        }
        let end = row.clamp(start + 1, rows - (tasks - i));
        // Keep `prefix` the cost of rows `0..row` for the next band.
        while row < end {
            prefix += u128::from(costs[row as usize]);
            row += 1;
        }
        while row > end {
            row -= 1;
            prefix -= u128::from(costs[row as usize]);
        }
        bands.push(start..end);
        start = end;
    }
    bands.push(start..rows);
    Ok(bands)
}

/// The plan of a render split into `tasks` parts: part `i` is the band of rows
/// `split_rows(row_costs(..), tasks)[i]`, the whole width.
pub fn plan_regions(
    scene: &PreparedScene,
    options: &RenderOptions,
    tasks: u32,
) -> Result<Vec<PixelRect>, SplitError> {
    if tasks == 0 {
        return Err(SplitError::NoTasks);
    }
    if tasks > options.height {
        return Err(SplitError::MoreTasksThanRows {
            tasks,
            rows: options.height,
        });
    }
    let costs = row_costs(scene, options);
    let bands = split_rows(&costs, tasks)?;
    Ok(bands
        .into_iter()
        .map(|rows| PixelRect::rows(options.width, rows))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_cover(bands: &[Range<u32>], rows: u32, tasks: u32) {
        assert_eq!(bands.len(), tasks as usize);
        assert_eq!(bands[0].start, 0);
        assert_eq!(bands.last().map(|b| b.end), Some(rows));
        for pair in bands.windows(2) {
            assert_eq!(pair[0].end, pair[1].start);
        }
        assert!(bands.iter().all(|b| b.end > b.start), "{bands:?}");
    }

    #[test]
    fn even_costs_split_into_even_bands() {
        let bands = split_rows(&[1; 12], 4).unwrap();
        assert_eq!(bands, vec![0..3, 3..6, 6..9, 9..12]);
        assert_eq!(split_rows(&[5; 7], 1).unwrap(), vec![0..7]);
    }

    #[test]
    fn an_expensive_row_gets_a_band_of_its_own() {
        let mut costs = vec![1u64; 10];
        costs[2] = 1000;
        let bands = split_rows(&costs, 3).unwrap();
        check_cover(&bands, 10, 3);
        assert_eq!(bands[0], 0..3, "{bands:?}");
    }

    #[test]
    fn every_band_keeps_a_row_whatever_the_costs() {
        for tasks in 1..=9 {
            let mut costs = vec![1u64; 9];
            costs[8] = 1_000_000;
            check_cover(&split_rows(&costs, tasks).unwrap(), 9, tasks);
            costs[8] = 1;
            costs[0] = 1_000_000;
            check_cover(&split_rows(&costs, tasks).unwrap(), 9, tasks);
        }
    }

    #[test]
    fn impossible_splits_are_errors() {
        assert_eq!(split_rows(&[1; 3], 0), Err(SplitError::NoTasks));
        assert_eq!(
            split_rows(&[1; 3], 4),
            Err(SplitError::MoreTasksThanRows { tasks: 4, rows: 3 })
        );
    }

    #[test]
    fn probes_stay_within_the_budget_and_the_width() {
        assert_eq!(probes_per_row(640, 480), 32);
        assert_eq!(probes_per_row(4096, 4096), 16);
        assert_eq!(probes_per_row(2, 100_000), 2);
        assert_eq!(probes_per_row(8192, 8192), 8);
    }
}
