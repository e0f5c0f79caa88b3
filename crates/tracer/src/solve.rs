//! Numerically stable roots of `a·t² + 2h·t + c = 0`, in f32 for the simple shapes and in
//! f64 for general quadrics.
//!
//! The textbook formula `(−b ± √(b² − 4ac)) / 2a` loses every digit of the smaller root when
//! `b² ≫ 4ac` (subtracting two nearly equal numbers). Computing `q = −(h + sign(h)·√disc)`
//! first and then `t₁ = q / a`, `t₂ = c / q` never subtracts like-signed values. The same
//! form degrades gracefully as `a → 0`: one root runs off to infinity and the other tends to
//! the linear root `−c / 2h`, which matters for quadrics hit along an asymptotic direction.

/// The real roots of `a·t² + 2h·t + c`, ascending; infinities stand for roots that ran off
/// to infinity when `a` is zero. `None` when there is no real root.
#[inline]
pub fn quadratic_f32(a: f32, h: f32, c: f32, discriminant: f32) -> Option<(f32, f32)> {
    if discriminant < 0.0 || discriminant.is_nan() {
        return None;
    }
    let root = discriminant.sqrt();
    let q = if h >= 0.0 { -(h + root) } else { -h + root };
    if q == 0.0 {
        // h and the discriminant are both zero: a double root at 0 (when a is non-zero).
        return if a != 0.0 { Some((0.0, 0.0)) } else { None };
    }
    let t1 = q / a;
    let t2 = c / q;
    if t1.is_nan() || t2.is_nan() {
        return None;
    }
    Some(if t1 <= t2 { (t1, t2) } else { (t2, t1) })
}

/// The f64 version of [`quadratic_f32`]; the discriminant is computed here as `h² − a·c`.
#[inline]
pub fn quadratic_f64(a: f64, h: f64, c: f64) -> Option<(f64, f64)> {
    let discriminant = h * h - a * c;
    if discriminant < 0.0 || discriminant.is_nan() {
        return None;
    }
    let root = discriminant.sqrt();
    let q = if h >= 0.0 { -(h + root) } else { -h + root };
    if q == 0.0 {
        return if a != 0.0 { Some((0.0, 0.0)) } else { None };
    }
    let t1 = q / a;
    let t2 = c / q;
    if t1.is_nan() || t2.is_nan() {
        return None;
    }
    Some(if t1 <= t2 { (t1, t2) } else { (t2, t1) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simple_roots() {
        // (t − 1)(t − 3) = t² − 4t + 3, so h = −2.
        assert_eq!(quadratic_f64(1.0, -2.0, 3.0), Some((1.0, 3.0)));
        assert_eq!(quadratic_f32(1.0, -2.0, 3.0, 4.0 - 3.0), Some((1.0, 3.0)));
        // No real roots.
        assert_eq!(quadratic_f64(1.0, 0.0, 1.0), None);
        // A double root.
        assert_eq!(quadratic_f64(1.0, -2.0, 4.0), Some((2.0, 2.0)));
    }

    #[test]
    fn small_root_keeps_its_precision() {
        // Roots 1e-9 and 1e9: t² − (1e9 + 1e-9)t + 1.
        let (small, large) = quadratic_f64(1.0, -0.5 * (1e9 + 1e-9), 1.0).unwrap_or((0.0, 0.0));
        assert!((small - 1e-9).abs() / 1e-9 < 1e-12, "{small}");
        assert!((large - 1e9).abs() / 1e9 < 1e-12);
        // The textbook formula gets the small root badly wrong here.
        let b: f64 = -(1e9 + 1e-9);
        let naive = (-b - (b * b - 4.0).sqrt()) / 2.0;
        assert!((naive - 1e-9).abs() / 1e-9 > 1e-3);
    }

    #[test]
    fn vanishing_leading_coefficient_gives_the_linear_root() {
        // 0·t² + 2·1·t − 4 = 0 → t = 2; the other root is infinite.
        let (t1, t2) = quadratic_f64(0.0, 1.0, -4.0).unwrap_or((0.0, 0.0));
        assert_eq!(t2, 2.0);
        assert!(t1.is_infinite());
        // Tiny but non-zero a: one root close to the linear one.
        let (r1, r2) = quadratic_f64(1e-20, 1.0, -4.0).unwrap_or((0.0, 0.0));
        let near = if r1.abs() < r2.abs() { r1 } else { r2 };
        assert!((near - 2.0).abs() < 1e-12);
        // Nothing at all when the polynomial is constant.
        assert_eq!(quadratic_f64(0.0, 0.0, 1.0), None);
    }
}
