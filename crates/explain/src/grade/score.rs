//! How well one candidate image explains a student's: of the pixels where the student
//! differs from the reference, how many the candidate matches (explained), and of those
//! where the student matches the reference, how many the candidate gets wrong (broken).

/// The student against the reference, once per image.
pub(super) struct Baseline {
    tolerance: u8,
    /// Per pixel: does the student differ from the reference?
    differs: Vec<bool>,
    pub differing: u64,
    /// Sum of absolute 8-bit differences, all channels.
    pub energy: u64,
}

/// One candidate's score.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Score {
    /// Differing pixels the candidate matches.
    pub explained: u64,
    /// Pixels the student got right that the candidate gets wrong.
    pub broken: u64,
    /// Sum of absolute 8-bit differences between the student and the candidate.
    pub residual_energy: u64,
    /// The same between the student and the reference, for [`Score::energy_share`].
    pub reference_energy: u64,
}

impl Score {
    /// Explained less broken: what ranks candidates.
    pub fn net(&self) -> i64 {
        self.explained as i64 - self.broken as i64
    }

    /// The share of the differing pixels the candidate explains, net of those it breaks.
    pub fn share(&self, differing: u64) -> f64 {
        if differing == 0 {
            return 0.0;
        }
        self.net().max(0) as f64 / differing as f64
    }

    /// The share of the difference's energy (summed 8-bit steps) the candidate removes.
    pub fn energy_share(&self) -> f64 {
        if self.reference_energy == 0 {
            return 0.0;
        }
        1.0 - self.residual_energy as f64 / self.reference_energy as f64
    }
}

fn pixel_difference(a: &[u8], b: &[u8]) -> (u8, u64) {
    let mut largest = 0;
    let mut sum = 0;
    for (x, y) in a.iter().zip(b) {
        let d = x.abs_diff(*y);
        largest = largest.max(d);
        sum += u64::from(d);
    }
    (largest, sum)
}

impl Baseline {
    pub fn new(student: &[u8], reference: &[u8], tolerance: u8) -> Baseline {
        let mut differs = Vec::with_capacity(student.len() / 3);
        let mut energy = 0;
        for (s, r) in student.chunks_exact(3).zip(reference.chunks_exact(3)) {
            let (largest, sum) = pixel_difference(s, r);
            differs.push(largest > tolerance);
            energy += sum;
        }
        let differing = differs.iter().filter(|d| **d).count() as u64;
        Baseline {
            tolerance,
            differs,
            differing,
            energy,
        }
    }

    pub fn score(&self, student: &[u8], candidate: &[u8]) -> Score {
        let mut score = Score {
            explained: 0,
            broken: 0,
            residual_energy: 0,
            reference_energy: self.energy,
        };
        for ((s, c), differs) in student
            .chunks_exact(3)
            .zip(candidate.chunks_exact(3))
            .zip(&self.differs)
        {
            let (largest, sum) = pixel_difference(s, c);
            score.residual_energy += sum;
            let matches = largest <= self.tolerance;
            match (differs, matches) {
                (true, true) => score.explained += 1,
                (false, false) => score.broken += 1,
                _ => {}
            }
        }
        score
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn explained_and_broken_pixels_are_counted_by_hand() {
        // Four pixels: the student differs from the reference at 0 and 1.
        let reference = [10, 10, 10, 20, 20, 20, 30, 30, 30, 40, 40, 40];
        let student = [90, 10, 10, 20, 90, 20, 30, 30, 30, 40, 40, 40];
        // The candidate matches pixel 0 (within 2), misses 1, breaks 3.
        let candidate = [89, 10, 10, 20, 20, 20, 30, 30, 30, 40, 40, 90];
        let baseline = Baseline::new(&student, &reference, 2);
        assert_eq!(baseline.differing, 2);
        assert_eq!(baseline.energy, 80 + 70);
        let score = baseline.score(&student, &candidate);
        assert_eq!((score.explained, score.broken), (1, 1));
        assert_eq!(score.net(), 0);
        assert_eq!(score.residual_energy, 1 + 70 + 50);
        assert!((score.energy_share() - (1.0 - 121.0 / 150.0)).abs() < 1e-12);
    }
}
