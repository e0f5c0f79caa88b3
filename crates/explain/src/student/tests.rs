//! The reading's arithmetic: which way a pixel differs and by how much.

use super::*;

#[test]
fn direction_counts_all_three_channels_and_ignores_rounding() {
    assert_eq!(direction([10, 10, 10], [40, 40, 40]), Direction::Brighter);
    assert_eq!(direction([40, 40, 40], [10, 10, 10]), Direction::Darker);
    assert_eq!(direction([10, 10, 10], [11, 11, 11]), Direction::Different);
    assert_eq!(direction([100, 0, 0], [0, 100, 0]), Direction::Different);
    assert_eq!(difference([100, 0, 7], [0, 100, 0]), 100);
}
