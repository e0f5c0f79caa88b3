//! The grading picture: student | reference | best model | residual, side by side with a
//! grey gap, 8-bit RGB. The residual is the student's difference from the best model,
//! four times brighter, so that what no model explains stands out.

/// The gap between panels, in pixels.
const GAP: u32 = 4;

/// The four panels of `width`×`height` 8-bit RGB images, left to right.
pub fn side_by_side(
    width: u32,
    height: u32,
    student: &[u8],
    reference: &[u8],
    best: &[u8],
) -> (u32, u32, Vec<u8>) {
    let residual: Vec<u8> = student
        .iter()
        .zip(best)
        .map(|(s, b)| s.abs_diff(*b).saturating_mul(4))
        .collect();
    let panels = [student, reference, best, &residual[..]];
    let total_width = width * 4 + GAP * 3;
    let mut out = vec![96u8; (total_width * height * 3) as usize];
    for (k, panel) in panels.iter().enumerate() {
        let x0 = k as u32 * (width + GAP);
        for y in 0..height {
            let from = (y * width * 3) as usize;
            let to = ((y * total_width + x0) * 3) as usize;
            let row = (width * 3) as usize;
            if let (Some(src), Some(dst)) = (panel.get(from..from + row), out.get_mut(to..to + row))
            {
                dst.copy_from_slice(src);
            }
        }
    }
    (total_width, height, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panels_sit_side_by_side_with_the_residual_last() {
        let student = [100, 0, 0];
        let reference = [0, 100, 0];
        let best = [90, 0, 0];
        let (w, h, out) = side_by_side(1, 1, &student, &reference, &best);
        assert_eq!((w, h), (1 + 3 * (1 + GAP), 1));
        assert_eq!(&out[0..3], &student);
        assert_eq!(&out[3..6], &[96, 96, 96]);
        let at = |k: u32| ((k * (1 + GAP)) * 3) as usize;
        assert_eq!(&out[at(1)..at(1) + 3], &reference);
        assert_eq!(&out[at(2)..at(2) + 3], &best);
        assert_eq!(&out[at(3)..at(3) + 3], &[40, 0, 0]);
    }
}
