//! A bench figure beside the base's (issue 31): the change, and a mark when it is larger than
//! the noise the runs themselves showed, so that a regression stands out in the table.

/// Which way a figure improves.
#[derive(Clone, Copy)]
pub(super) enum Better {
    /// Rays per CPU-second.
    Higher,
    /// Seconds and mebibytes.
    Lower,
}

/// Changes smaller than this are never marked, however steady the runs were: a percent is
/// below what anyone acts on.
const FLOOR: f64 = 0.01;

/// The change from `base` to `new` as a signed percentage with a mark: `!` when it is worse
/// by more than `noise` (the two binaries' relative spreads added: each one's best run is
/// uncertain by about its own spread; at least 1%),
/// `*` when it is better by more, a space otherwise. Always 8 characters, e.g. ` +4.8%* `.
pub(super) fn change(new: f64, base: f64, noise: f64, better: Better) -> String {
    if base.is_nan() || base <= 0.0 || !new.is_finite() {
        return format!("{:>8}", "-");
    }
    let fraction = (new - base) / base;
    let beyond = fraction.abs() > noise.max(FLOOR);
    let improved = match better {
        Better::Higher => fraction > 0.0,
        Better::Lower => fraction < 0.0,
    };
    let mark = match (beyond, improved) {
        (false, _) => ' ',
        (true, true) => '*',
        (true, false) => '!',
    };
    format!("{:>+6.1}%{mark}", fraction * 100.0)
}

/// The noise of a figure for [`change`]: the runs' relative `spreads`, or `floor` (in the
/// figure's own unit) relative to `base`, whichever is larger: below the floor a
/// difference is the measurement's own (a clock's jitter, a process's stray MiB).
pub(super) fn noise(spreads: f64, floor: f64, base: f64) -> f64 {
    spreads.max(floor / base.max(1e-9))
}

/// Whether [`change`] marked a regression.
pub(super) fn is_regression(change: &str) -> bool {
    change.trim_end().ends_with('!')
}

/// The relative spread of some runs' figure: (most − least) / least.
pub(super) fn spread(values: impl IntoIterator<Item = f64>) -> f64 {
    let (least, most) = values
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, m), v| {
            (l.min(v), m.max(v))
        });
    if least.is_finite() && least > 0.0 {
        (most - least) / least
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_faster_render_beyond_the_noise_is_marked_better() {
        assert_eq!(change(9.12, 8.70, 0.02, Better::Higher), "  +4.8%*");
    }

    #[test]
    fn a_slower_render_beyond_the_noise_is_marked_a_regression() {
        let slower = change(8.0, 9.0, 0.05, Better::Higher);
        assert_eq!(slower, " -11.1%!");
        assert!(is_regression(&slower));
    }

    #[test]
    fn a_change_within_the_noise_or_the_floor_is_not_marked() {
        assert_eq!(change(9.3, 9.0, 0.05, Better::Higher), "  +3.3% ");
        assert_eq!(change(100.5, 100.0, 0.0, Better::Lower), "  +0.5% ");
        assert!(!is_regression(&change(9.3, 9.0, 0.05, Better::Lower)));
    }

    #[test]
    fn more_time_or_memory_is_worse() {
        assert!(is_regression(&change(1.2, 1.0, 0.05, Better::Lower)));
        assert_eq!(change(0.8, 1.0, 0.05, Better::Lower), " -20.0%*");
    }

    /// A 0.000 s build that clock jitter made half again as long is not marked (the
    /// Menger sponge's was, "+53%!"); the same ratio on a build of seconds is.
    #[test]
    fn a_change_below_the_floor_of_its_unit_is_not_marked() {
        let tiny = change(0.00046, 0.0003, noise(0.02, 0.005, 0.0003), Better::Lower);
        assert!(!is_regression(&tiny), "{tiny}");
        let real = change(0.46, 0.3, noise(0.02, 0.005, 0.3), Better::Lower);
        assert!(is_regression(&real), "{real}");
        // Memory: 3 MiB more of 45 is the process's noise, 12 MiB more is not.
        assert!(!is_regression(&change(
            48.0,
            45.0,
            noise(0.0, 4.0, 45.0),
            Better::Lower
        )));
        assert!(is_regression(&change(
            57.0,
            45.0,
            noise(0.0, 4.0, 45.0),
            Better::Lower
        )));
    }

    #[test]
    fn no_base_figure_is_a_dash() {
        assert_eq!(change(1.0, 0.0, 0.0, Better::Lower), "       -");
        assert_eq!(change(1.0, f64::NAN, 0.0, Better::Lower), "       -");
    }

    #[test]
    fn the_spread_is_relative_to_the_least() {
        assert!((spread([2.0, 2.5, 2.2]) - 0.25).abs() < 1e-12);
        assert_eq!(spread([]), 0.0);
    }
}
