//! The torus, a quartic: where a ray crosses the ring of major radius 1 around the y axis
//! with tube radius `r`, solved in f64 so that grazing rays and thin rings stay exact.
//!
//! `f(p) = (|p|² + 1 − r²)² − 4(x² + z²)` is negative inside the tube. Along a ray the
//! quartic's coefficients are formed around the ray's point closest to the centre (so that a
//! camera far away does not cancel them), and its roots are isolated between the roots of its
//! derivatives (a cubic, then a quadratic): between two neighbours the quartic is monotone, so
//! each sign change holds exactly one root, found by bisection. No closed-form quartic
//! formula, whose cancellations lose grazing hits.

/// The ray parameters where `o + t·d` enters and leaves the solid torus, in order: up to two
/// spans (a ray through the hole crosses the tube twice).
pub fn spans(o: [f64; 3], d: [f64; 3], r: f64) -> ([(f64, f64); 2], usize) {
    let mut out = [(0.0, 0.0); 2];
    let dd = dot(d, d);
    // A zero (or NaN) direction meets nothing.
    if dd.is_nan() || dd <= 0.0 {
        return (out, 0);
    }
    // Around the point closest to the centre.
    let t_c = -dot(o, d) / dd;
    let c = [o[0] + t_c * d[0], o[1] + t_c * d[1], o[2] + t_c * d[2]];
    let outer = 1.0 + r;
    let cc = dot(c, c);
    if cc >= outer * outer {
        return (out, 0);
    }
    // Every root lies within the bounding sphere: |c + s·d| <= 1 + r.
    let half = ((outer * outer - cc) / dd).sqrt();
    let k = cc + 1.0 - r * r;
    let a_xz = d[0] * d[0] + d[2] * d[2];
    let b_xz = c[0] * d[0] + c[2] * d[2];
    let c_xz = c[0] * c[0] + c[2] * c[2];
    // (dd·s² + k)² − 4(a_xz·s² + 2·b_xz·s + c_xz), with c·d = 0.
    let quartic = [
        k * k - 4.0 * c_xz,
        -8.0 * b_xz,
        2.0 * dd * k - 4.0 * a_xz,
        0.0,
        dd * dd,
    ];
    let mut roots = [0.0; 4];
    let count = real_roots(&quartic, -half, half, &mut roots);
    // Inside where the quartic is negative: pair the roots whose middle is inside.
    let mut n = 0;
    let mut i = 0;
    while i + 1 < count && n < 2 {
        let (s0, s1) = (roots[i], roots[i + 1]);
        if eval(&quartic, 0.5 * (s0 + s1)) < 0.0 {
            out[n] = (s0 + t_c, s1 + t_c);
            n += 1;
            i += 2;
        } else {
            i += 1;
        }
    }
    (out, n)
}

/// The outward normal (not normalised) at a point on the torus: the gradient of `f`.
pub fn normal(p: [f64; 3], r: f64) -> [f64; 3] {
    let k = dot(p, p) + 1.0 - r * r;
    [p[0] * k - 2.0 * p[0], p[1] * k, p[2] * k - 2.0 * p[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `p(x)` for coefficients lowest degree first (Horner).
fn eval(p: &[f64], x: f64) -> f64 {
    p.iter().rev().fold(0.0, |acc, c| acc * x + c)
}

/// The real roots of `p` (degree at most 4, lowest coefficient first) in `[lo, hi]`,
/// ascending, written to `out`; returns how many. A root where `p` only touches zero without
/// changing sign (a ray tangent to the surface) may be missed: it enters nothing.
fn real_roots(p: &[f64], lo: f64, hi: f64, out: &mut [f64; 4]) -> usize {
    let mut degree = p.len() - 1;
    while degree > 0 && p[degree] == 0.0 {
        degree -= 1;
    }
    if degree == 0 {
        return 0;
    }
    if degree == 1 {
        let x = -p[0] / p[1];
        if x >= lo && x <= hi {
            out[0] = x;
            return 1;
        }
        return 0;
    }
    // The derivative's roots split [lo, hi] into pieces where p is monotone.
    let mut derivative = [0.0; 4];
    for i in 1..=degree {
        derivative[i - 1] = p[i] * i as f64;
    }
    let mut critical = [0.0; 4];
    let n_critical = real_roots(&derivative[..degree], lo, hi, &mut critical);
    let mut count = 0;
    let mut a = lo;
    let mut pa = eval(&p[..=degree], a);
    let ends = critical[..n_critical].iter().copied().chain([hi]);
    for b in ends {
        let pb = eval(&p[..=degree], b);
        if pa == 0.0 {
            if count == 0 || out[count - 1] != a {
                out[count] = a;
                count += 1;
            }
        } else if pa.signum() != pb.signum() && pb != 0.0 {
            out[count] = bisect(&p[..=degree], a, b, pa);
            count += 1;
        }
        if count == 4 {
            break;
        }
        a = b;
        pa = pb;
    }
    if count < 4 && pa == 0.0 && (count == 0 || out[count - 1] != a) {
        out[count] = a;
        count += 1;
    }
    count
}

/// The root of `p` between `a` and `b`, where `p(a)` (= `pa`) and `p(b)` differ in sign and
/// `p` is monotone: bisection to the last representable midpoint.
fn bisect(p: &[f64], mut a: f64, mut b: f64, pa: f64) -> f64 {
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let pm = eval(p, m);
        if pm == 0.0 {
            return m;
        }
        if pm.signum() == pa.signum() {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The oracle: march along the ray in fine steps and find where `f` changes sign, in the
    /// torus's own implicit form, not the quartic's coefficients.
    fn sampled_crossings(o: [f64; 3], d: [f64; 3], r: f64, t_max: f64) -> Vec<f64> {
        let f = |t: f64| {
            let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
            let k = dot(p, p) + 1.0 - r * r;
            k * k - 4.0 * (p[0] * p[0] + p[2] * p[2])
        };
        let steps = 200_000;
        let mut crossings = Vec::new();
        let mut previous = f(-t_max);
        for i in 1..=steps {
            let t = -t_max + 2.0 * t_max * i as f64 / steps as f64;
            let value = f(t);
            if (previous < 0.0) != (value < 0.0) {
                crossings.push(t);
            }
            previous = value;
        }
        crossings
    }

    fn solved(o: [f64; 3], d: [f64; 3], r: f64) -> Vec<f64> {
        let (found, n) = spans(o, d, r);
        found[..n].iter().flat_map(|&(a, b)| [a, b]).collect()
    }

    /// A small deterministic generator (xorshift) of rays.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
    }

    #[test]
    fn the_roots_are_where_the_sampled_implicit_function_changes_sign() {
        let mut rng = Rng(0x7031_5eed);
        let mut checked = 0;
        for case in 0..400 {
            let r = [0.05, 0.3, 0.5, 0.99, 1.5][case % 5];
            // Origins around the torus, directions of every kind (some axis-aligned, some
            // through the hole, some with zero components of either sign).
            let o = [
                rng.range(-3.0, 3.0),
                rng.range(-2.0, 2.0),
                rng.range(-3.0, 3.0),
            ];
            let mut d = [
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            ];
            match case % 7 {
                0 => d = [1.0, 0.0, 0.0],
                1 => d = [0.0, -1.0, -0.0],
                2 => d = [-o[0], -o[1], -o[2]], // through the centre, so through the hole
                3 => d[1] = 0.0,
                _ => {}
            }
            let t_max = 10.0 / dot(d, d).sqrt();
            let expected = sampled_crossings(o, d, r, t_max);
            let roots = solved(o, d, r);
            let step = 2.0 * t_max / 200_000.0;
            // A tangent touch may show as two very close crossings in the samples and none
            // in the solver, or the other way round; compare away from those.
            if expected.windows(2).any(|w| w[1] - w[0] < 4.0 * step) {
                continue;
            }
            assert_eq!(
                roots.len(),
                expected.len(),
                "case {case}: o {o:?} d {d:?} r {r}: roots {roots:?}, samples {expected:?}"
            );
            for (root, sample) in roots.iter().zip(&expected) {
                assert!(
                    (root - sample).abs() <= step,
                    "case {case}: root {root} vs sampled crossing {sample}"
                );
            }
            checked += 1;
        }
        assert!(checked > 350, "only {checked} cases were comparable");
    }

    #[test]
    fn a_far_camera_and_grazing_rays_keep_their_hits() {
        // From 1e4 away, along x through the tube's centre line at z = 0: enters at x = 1.3...
        let (found, n) = spans([-1e4, 0.0, 0.0], [1.0, 0.0, 0.0], 0.3);
        assert_eq!(n, 2);
        let expected = [1e4 - 1.3, 1e4 - 0.7, 1e4 + 0.7, 1e4 + 1.3];
        let got = [found[0].0, found[0].1, found[1].0, found[1].1];
        for (g, e) in got.iter().zip(expected) {
            assert!((g - e).abs() < 1e-9, "{got:?} vs {expected:?}");
        }
        // Just inside the top of the tube (y = 0.3 - 1e-6) along x: two short chords.
        let (_, n) = spans([-5.0, 0.3 - 1e-6, 0.0], [1.0, 0.0, 0.0], 0.3);
        assert_eq!(n, 2);
        // Just above it: nothing.
        let (_, n) = spans([-5.0, 0.3 + 1e-6, 0.0], [1.0, 0.0, 0.0], 0.3);
        assert_eq!(n, 0);
        // Straight down the axis, through the hole: nothing.
        let (_, n) = spans([0.0, 5.0, 0.0], [0.0, -1.0, 0.0], 0.3);
        assert_eq!(n, 0);
        // A degenerate direction: nothing, no panic.
        let (_, n) = spans([0.0, 5.0, 0.0], [0.0, 0.0, 0.0], 0.3);
        assert_eq!(n, 0);
    }

    #[test]
    fn the_normal_is_the_direction_from_the_tube_centre() {
        let mut rng = Rng(42);
        for _ in 0..200 {
            let r = rng.range(0.1, 0.9);
            let angle = rng.range(0.0, std::f64::consts::TAU);
            let around = rng.range(0.0, std::f64::consts::TAU);
            // A point on the surface, and the centre of the tube there.
            let centre = [angle.cos(), 0.0, angle.sin()];
            let outward = [
                around.cos() * angle.cos(),
                around.sin(),
                around.cos() * angle.sin(),
            ];
            let p = [
                centre[0] + r * outward[0],
                centre[1] + r * outward[1],
                centre[2] + r * outward[2],
            ];
            let n = normal(p, r);
            let length = dot(n, n).sqrt();
            let cosine = dot(n, outward) / length;
            assert!(cosine > 1.0 - 1e-9, "normal {n:?} vs {outward:?}");
        }
    }
}
