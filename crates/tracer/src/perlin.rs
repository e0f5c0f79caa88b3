//! Ken Perlin's improved noise (2002) with his published permutation, and the MIT 6.837
//! course's procedural materials built on it: `Noise`, `Marble` and `Wood` blend weights.
//!
//! This is a second noise beside `noise.rs` on purpose: whitted's own patterns keep their
//! noise (their images must not change), and the course's materials use the noise the course
//! handed out, so that a 6.837 scene looks as it did in the course.

use whitted_ir::PatternKind;

/// Perlin's reference permutation of 0..=255 (from his improved-noise reference code).
pub(crate) const PERMUTATION: [u8; 256] = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69,
    142, 8, 99, 37, 240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219,
    203, 117, 35, 11, 32, 57, 177, 33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175,
    74, 165, 71, 134, 139, 48, 27, 166, 77, 146, 158, 231, 83, 111, 229, 122, 60, 211, 133, 230,
    220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25, 63, 161, 1, 216, 80, 73, 209, 76,
    132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100, 109, 198, 173,
    186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163,
    70, 221, 153, 101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232,
    178, 185, 112, 104, 218, 246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162,
    241, 81, 51, 145, 235, 249, 14, 239, 107, 49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204,
    176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205, 93, 222, 114, 67, 29, 24, 72, 243, 141,
    128, 195, 78, 66, 215, 61, 156, 180,
];

/// The permutation at `i` modulo 256 (the reference code repeats the table to 512 entries
/// to spare the wrap; indices here are below 512 as there).
#[inline]
fn perm(i: usize) -> usize {
    PERMUTATION[i & 255] as usize
}

/// The dot product of the gradient picked by the low four bits of `hash` with `(x, y, z)`:
/// the twelve cube-edge directions, four of them twice (Perlin's choice, so that the
/// sixteen codes need no division).
#[inline]
fn gradient(hash: usize, x: f32, y: f32, z: f32) -> f32 {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
}

#[inline]
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[inline]
fn lerp(t: f32, a: f32, b: f32) -> f32 {
    a + t * (b - a)
}

/// Perlin's improved noise at a point: 0 on the integer lattice, smooth, within about
/// [-1, 1]. Points past the f32 integers (and NaN) give 0, as the lattice does.
pub fn improved_noise(x: f32, y: f32, z: f32) -> f32 {
    if !(x.abs() < 8.0e6 && y.abs() < 8.0e6 && z.abs() < 8.0e6) {
        return 0.0;
    }
    let (fx, fy, fz) = (x.floor(), y.floor(), z.floor());
    // The unit cube's corner, wrapped to the table (`& 255` of a negative integer in two's
    // complement is its value modulo 256, as the reference code's `& 255` on an int).
    let cx = (fx as i32 & 255) as usize;
    let cy = (fy as i32 & 255) as usize;
    let cz = (fz as i32 & 255) as usize;
    let (x, y, z) = (x - fx, y - fy, z - fz);
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let a = perm(cx) + cy;
    let aa = perm(a) + cz;
    let ab = perm(a + 1) + cz;
    let b = perm(cx + 1) + cy;
    let ba = perm(b) + cz;
    let bb = perm(b + 1) + cz;
    lerp(
        w,
        lerp(
            v,
            lerp(
                u,
                gradient(perm(aa), x, y, z),
                gradient(perm(ba), x - 1.0, y, z),
            ),
            lerp(
                u,
                gradient(perm(ab), x, y - 1.0, z),
                gradient(perm(bb), x - 1.0, y - 1.0, z),
            ),
        ),
        lerp(
            v,
            lerp(
                u,
                gradient(perm(aa + 1), x, y, z - 1.0),
                gradient(perm(ba + 1), x - 1.0, y, z - 1.0),
            ),
            lerp(
                u,
                gradient(perm(ab + 1), x, y - 1.0, z - 1.0),
                gradient(perm(bb + 1), x - 1.0, y - 1.0, z - 1.0),
            ),
        ),
    )
}

/// The course's `N(p)`: `octaves` octaves of improved noise, octave `i` at `2^i` times the
/// frequency and `1 / 2^i` of the weight: `Σ_{i=0}^{octaves-1} noise(2^i·p) / 2^i`.
pub fn octave_sum(x: f32, y: f32, z: f32, octaves: u32) -> f32 {
    let mut sum = 0.0;
    let mut scale = 1.0f32;
    for _ in 0..octaves {
        sum += improved_noise(scale * x, scale * y, scale * z) / scale;
        scale *= 2.0;
    }
    sum
}

/// The weight of the second material at the texture-space point for the course's blending
/// patterns, in [0, 1] (the first material's is one minus it); `None` for a pattern that
/// chooses rather than blends.
///
/// - `Noise`: `clamp(N(p), 0, 1)`;
/// - `Marble`: `(1 + sin(frequency·x + amplitude·N(p))) / 2`;
/// - `Wood`: `(1 + sin(frequency·sqrt(x² + z²) + amplitude·N(p))) / 2`, rings around y.
pub fn course_weight(kind: PatternKind, x: f32, y: f32, z: f32) -> Option<f32> {
    let weight = match kind {
        PatternKind::CourseNoise { octaves } => octave_sum(x, y, z, octaves),
        PatternKind::CourseMarble {
            octaves,
            frequency,
            amplitude,
        } => {
            let n = octave_sum(x, y, z, octaves);
            0.5 + 0.5 * (frequency as f32 * x + amplitude as f32 * n).sin()
        }
        PatternKind::CourseWood {
            octaves,
            frequency,
            amplitude,
        } => {
            let n = octave_sum(x, y, z, octaves);
            let radius = (x * x + z * z).sqrt();
            0.5 + 0.5 * (frequency as f32 * radius + amplitude as f32 * n).sin()
        }
        _ => return None,
    };
    // A point past f32's range can make `sin` NaN: it counts as 0, as noise does there.
    Some(if weight.is_nan() {
        0.0
    } else {
        weight.clamp(0.0, 1.0)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::testing::reference_improved_noise as reference;

    #[test]
    fn the_permutation_is_perlins_and_holds_every_byte_once() {
        let mut seen = [false; 256];
        for &p in &PERMUTATION {
            assert!(!seen[p as usize], "{p} twice");
            seen[p as usize] = true;
        }
        assert_eq!(PERMUTATION[..6], [151, 160, 137, 91, 90, 15]);
        assert_eq!(PERMUTATION[250..], [195, 78, 66, 215, 61, 156, 180][1..]);
    }

    #[test]
    fn noise_is_zero_on_the_lattice() {
        for (x, y, z) in [(0, 0, 0), (1, 2, 3), (-7, 4, -250), (255, 256, -257)] {
            assert_eq!(improved_noise(x as f32, y as f32, z as f32), 0.0);
        }
    }

    /// Two values worked by hand from the definition. At a point with one coordinate 0.5
    /// and the others whole, the fade of 0.5 is 0.5 and of 0 is 0, so only the two corners
    /// along that axis count, half each.
    ///
    /// (0, 0.5, 0): corner (0,0,0) hashes to p[p[p[0] + 0] + 0] = p[p[151]] = p[17] = 36,
    /// code 36 & 15 = 4, gradient (1, 0, 1), dot (0, 0.5, 0) = 0; corner (0,1,0) hashes to
    /// p[p[p[0] + 1] + 0] = p[p[152]] = p[182] = 108, code 12, gradient (1, 1, 0), dot
    /// (0, -0.5, 0) = -0.5. So noise = 0.5·0 + 0.5·(-0.5) = -0.25.
    ///
    /// (0.5, 0, 0): corner (0,0,0), code 4, dot (0.5, 0, 0) with (1, 0, 1) = 0.5; corner
    /// (1,0,0) hashes to p[p[p[1]]] = p[p[160]] = p[119] = 86, code 6, gradient (1, 0, -1),
    /// dot (-0.5, 0, 0) = -0.5. So noise = 0.25 - 0.25 = 0.
    #[test]
    fn noise_at_points_worked_by_hand() {
        // The table entries the comment reads.
        let table: Vec<(usize, u8)> = [0, 151, 17, 152, 182, 1, 160, 119]
            .iter()
            .map(|&i| (i, PERMUTATION[i]))
            .collect();
        assert_eq!(
            table,
            [
                (0, 151),
                (151, 17),
                (17, 36),
                (152, 182),
                (182, 108),
                (1, 160),
                (160, 119),
                (119, 86)
            ]
        );
        assert_eq!(improved_noise(0.0, 0.5, 0.0), -0.25);
        assert_eq!(improved_noise(0.5, 0.0, 0.0), 0.0);
        // A whole-number shift by 256 lands on the same table entries.
        assert_eq!(improved_noise(256.0, 0.5, -256.0), -0.25);
    }

    #[test]
    fn noise_matches_an_independent_f64_transcription() {
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            ((state >> 40) as f64 / (1u64 << 24) as f64) * 600.0 - 300.0
        };
        for _ in 0..5_000 {
            let p = [next(), next(), next()];
            let ours = improved_noise(p[0] as f32, p[1] as f32, p[2] as f32);
            // f32 input rounding: |∇noise| is at most about 3, and the point moves by at most
            // 300·2^-24 per coordinate.
            let want = reference([p[0] as f32 as f64, p[1] as f32 as f64, p[2] as f32 as f64]);
            assert!(
                (f64::from(ours) - want).abs() < 2e-5,
                "noise at {p:?}: {ours}, reference {want}"
            );
        }
    }

    #[test]
    fn the_course_weights_follow_their_formulas() {
        let (x, y, z) = (0.3f32, 1.7f32, -2.2f32);
        let n = |octaves: u32| {
            (0..octaves)
                .map(|i| {
                    let s = f64::from(2u32.pow(i));
                    reference([s * x as f64, s * y as f64, s * z as f64]) / s
                })
                .sum::<f64>()
        };
        let close = |got: Option<f32>, want: f64| {
            let got = f64::from(got.expect("a blend"));
            assert!((got - want).abs() < 1e-5, "{got} against {want}");
        };
        close(
            course_weight(PatternKind::CourseNoise { octaves: 3 }, x, y, z),
            n(3).clamp(0.0, 1.0),
        );
        let (frequency, amplitude) = (2.0, 3.0);
        close(
            course_weight(
                PatternKind::CourseMarble {
                    octaves: 4,
                    frequency,
                    amplitude,
                },
                x,
                y,
                z,
            ),
            (1.0 + (frequency * x as f64 + amplitude * n(4)).sin()) / 2.0,
        );
        let radius = ((x * x + z * z) as f64).sqrt();
        close(
            course_weight(
                PatternKind::CourseWood {
                    octaves: 2,
                    frequency,
                    amplitude,
                },
                x,
                y,
                z,
            ),
            (1.0 + (frequency * radius + amplitude * n(2)).sin()) / 2.0,
        );
        assert_eq!(
            course_weight(PatternKind::CourseCheckerboard, x, y, z),
            None
        );
    }
}
