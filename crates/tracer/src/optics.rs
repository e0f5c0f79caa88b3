//! The optics of Whitted's model as small pure functions: reflection, Snell refraction,
//! Schlick's and the exact Fresnel terms, light attenuation, the spot-light cone and Beer-Lambert absorption (the surface offset is
//! `hit_error.rs`).
//!
//! They are kept free of scene types so that unit tests can check each formula numerically.

use glam::Vec3A;

/// Mirror reflection of the incident direction `d` about the unit normal `n`:
/// `R = d − 2(d·n)n`. Works whichever side of the surface `n` faces.
#[inline]
pub fn reflect(d: Vec3A, n: Vec3A) -> Vec3A {
    d - 2.0 * d.dot(n) * n
}

/// Refraction of the unit incident direction `d` at a surface whose unit normal `n` faces
/// the incoming ray (`d·n <= 0`), going from a medium of index `ior_from` into `ior_to`.
/// Returns `None` on total internal reflection. Snell's law: `n1·sin θi = n2·sin θt`.
#[inline]
pub fn refract(d: Vec3A, n: Vec3A, ior_from: f32, ior_to: f32) -> Option<Vec3A> {
    let eta = ior_from / ior_to;
    let cos_i = (-d.dot(n)).clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((eta * d + (eta * cos_i - cos_t) * n).normalize())
}

/// Schlick's approximation of the Fresnel reflectance for light crossing from `ior_from`
/// into `ior_to`, where `cos_i` is the cosine of the angle of incidence. Going into a less
/// dense medium it uses the transmitted angle, so it reaches 1 at the critical angle.
#[inline]
pub fn schlick(cos_i: f32, ior_from: f32, ior_to: f32) -> f32 {
    let r0 = ((ior_from - ior_to) / (ior_from + ior_to)).powi(2);
    let cos = if ior_from > ior_to {
        let eta = ior_from / ior_to;
        let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
        if sin2_t > 1.0 {
            return 1.0;
        }
        (1.0 - sin2_t).sqrt()
    } else {
        cos_i
    };
    let x = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    r0 + (1.0 - r0) * x
}

/// The exact Fresnel reflectance of a dielectric interface for unpolarised light crossing
/// from `ior_from` into `ior_to` at an angle whose cosine is `cos_i`: the average of the
/// s- and p-polarised reflectances, `Rs = ((n1·cos i − n2·cos t)/(n1·cos i + n2·cos t))²`
/// and `Rp = ((n2·cos i − n1·cos t)/(n2·cos i + n1·cos t))²`. 1 beyond the critical angle.
#[inline]
pub fn fresnel_exact(cos_i: f32, ior_from: f32, ior_to: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let eta = ior_from / ior_to;
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let (n1, n2) = (ior_from, ior_to);
    let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    (0.5 * (rs * rs + rp * rp)).min(1.0)
}

/// The critical angle (radians) beyond which light going from `ior_from` into a less dense
/// `ior_to` is totally reflected; `None` when there is none.
pub fn critical_angle(ior_from: f32, ior_to: f32) -> Option<f32> {
    (ior_from > ior_to).then(|| (ior_to / ior_from).asin())
}

/// Distance attenuation of point and spot lights: `min(1, 1 / (c + l·d + q·d²))`, or with
/// `clamp` false `1 / (c + l·d + q·d²)` itself, bounded by the largest attenuation limit
/// (a surface at a light with no constant term would otherwise get infinite light).
#[inline]
pub fn attenuation(constant: f32, linear: f32, quadratic: f32, distance: f32, clamp: bool) -> f32 {
    let denominator = constant + linear * distance + quadratic * distance * distance;
    let largest = if clamp {
        1.0
    } else {
        whitted_ir::limits::MAX_UNCLAMPED_ATTENUATION as f32
    };
    if denominator * largest <= 1.0 {
        largest
    } else {
        1.0 / denominator
    }
}

/// The spot-light factor for a point seen at `cos_angle` from the spot's axis: 1 inside the
/// inner cone, 0 outside the outer cone, and a smoothstep between them.
#[inline]
pub fn spot_factor(cos_angle: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    if cos_angle >= cos_inner {
        1.0
    } else if cos_angle <= cos_outer {
        0.0
    } else {
        let x = (cos_angle - cos_outer) / (cos_inner - cos_outer);
        x * x * (3.0 - 2.0 * x)
    }
}

/// The largest of the three channels: the path-weight test looks at the strongest one.
#[inline]
pub fn max_channel(c: Vec3A) -> f32 {
    c.max_element()
}

/// Beer-Lambert transmittance `exp(−absorption·distance)` per channel. A channel with no
/// absorption transmits fully even over an infinite distance.
#[inline]
pub fn beer_lambert(absorption: Vec3A, distance: f32) -> Vec3A {
    let channel = |a: f32| {
        if a == 0.0 {
            1.0
        } else {
            (-a * distance).exp()
        }
    };
    Vec3A::new(
        channel(absorption.x),
        channel(absorption.y),
        channel(absorption.z),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32, tolerance: f32) -> bool {
        (a - b).abs() <= tolerance
    }

    #[test]
    fn reflection_mirrors_about_the_normal() {
        let d = Vec3A::new(1.0, -1.0, 0.0).normalize();
        let r = reflect(d, Vec3A::Y);
        assert!(r.abs_diff_eq(Vec3A::new(1.0, 1.0, 0.0).normalize(), 1e-6));
        // The angle of reflection equals the angle of incidence.
        assert!(close(r.dot(Vec3A::Y), -d.dot(Vec3A::Y), 1e-6));
        // The normal's orientation does not matter.
        assert!(reflect(d, -Vec3A::Y).abs_diff_eq(r, 1e-6));
    }

    #[test]
    fn refraction_obeys_snells_law() {
        let n = Vec3A::Y;
        for degrees in [0.0f32, 10.0, 30.0, 45.0, 60.0, 80.0, 89.0] {
            let theta = degrees.to_radians();
            let d = Vec3A::new(theta.sin(), -theta.cos(), 0.0);
            let t = refract(d, n, 1.0, 1.5).expect("air to glass never reflects totally");
            assert!(close(t.length(), 1.0, 1e-6));
            let sin_t = t.x;
            assert!(
                close(1.0 * theta.sin(), 1.5 * sin_t, 1e-5),
                "Snell at {degrees}°"
            );
            // The transmitted ray continues into the surface, in the plane of incidence.
            assert!(t.y < 0.0 && t.z == 0.0);
        }
        // Normal incidence goes straight through.
        let straight = refract(-Vec3A::Y, n, 1.0, 1.5).unwrap_or(Vec3A::ZERO);
        assert!(straight.abs_diff_eq(-Vec3A::Y, 1e-6));
    }

    #[test]
    fn total_internal_reflection_starts_at_the_critical_angle() {
        let critical = critical_angle(1.5, 1.0).unwrap_or(0.0);
        assert!(close(critical.to_degrees(), 41.810_31, 1e-3));
        assert_eq!(critical_angle(1.0, 1.5), None);
        let n = Vec3A::Y;
        let at = |theta: f32| Vec3A::new(theta.sin(), -theta.cos(), 0.0);
        let just_below = refract(at(critical - 1e-3), n, 1.5, 1.0);
        let just_above = refract(at(critical + 1e-3), n, 1.5, 1.0);
        assert!(just_below.is_some());
        assert!(just_above.is_none());
        // Just below the critical angle the refracted ray leaves almost along the surface.
        assert!(just_below.unwrap_or(Vec3A::ZERO).x > 0.99);
    }

    #[test]
    fn schlick_at_normal_and_grazing_incidence() {
        let r0 = (0.5f32 / 2.5).powi(2);
        assert!(close(schlick(1.0, 1.0, 1.5), r0, 1e-7));
        assert!(close(r0, 0.04, 1e-7));
        assert!(close(schlick(0.0, 1.0, 1.5), 1.0, 1e-7));
        // The same normal-incidence value from the dense side, and 1 beyond the critical angle.
        assert!(close(schlick(1.0, 1.5, 1.0), r0, 1e-7));
        let past_critical = (45.0f32).to_radians().cos();
        assert_eq!(schlick(past_critical, 1.5, 1.0), 1.0);
        // It grows monotonically towards grazing incidence.
        let mut previous = 0.0;
        for i in (0..=10).rev() {
            let value = schlick(i as f32 / 10.0, 1.0, 1.5);
            assert!(value >= previous);
            previous = value;
        }
    }

    #[test]
    fn exact_fresnel_matches_values_worked_by_hand() {
        // Normal incidence: ((n1 − n2)/(n1 + n2))², from either side.
        assert!(close(fresnel_exact(1.0, 1.0, 1.5), 0.04, 1e-7));
        assert!(close(fresnel_exact(1.0, 1.5, 1.0), 0.04, 1e-7));
        let r0_diamond = ((2.4f32 - 1.0) / 3.4).powi(2);
        assert!(close(fresnel_exact(1.0, 1.0, 2.4), r0_diamond, 1e-6));
        // Brewster's angle, tan θB = n2/n1: Rp vanishes, so R = Rs / 2 with
        // Rs = ((1 − n²)/(1 + n²))² = (1.25/3.25)² for n = 1.5.
        let brewster = 1.5f32.atan();
        let rs = (1.25f32 / 3.25).powi(2);
        assert!(close(
            fresnel_exact(brewster.cos(), 1.0, 1.5),
            0.5 * rs,
            1e-6
        ));
        // From the dense side Brewster's angle is atan(1/1.5); the same Rs.
        let inner_brewster = (1.0f32 / 1.5).atan();
        assert!(close(
            fresnel_exact(inner_brewster.cos(), 1.5, 1.0),
            0.5 * rs,
            1e-6
        ));
        // Grazing incidence reflects everything; so does every angle past the critical one.
        assert!(close(fresnel_exact(0.0, 1.0, 1.5), 1.0, 1e-6));
        let critical = critical_angle(1.5, 1.0).unwrap_or(0.0);
        assert_eq!(fresnel_exact((critical + 1e-3).cos(), 1.5, 1.0), 1.0);
        assert_eq!(fresnel_exact(0.5, 2.4, 1.0), 1.0);
        // Just inside the critical angle it is close to 1 and below it.
        let near = fresnel_exact((critical - 1e-3).cos(), 1.5, 1.0);
        assert!(near > 0.5 && near < 1.0, "{near}");
        // Equal indices: no interface, nothing reflected.
        assert!(close(fresnel_exact(0.3, 1.33, 1.33), 0.0, 1e-10));
        // Schlick approximates it within a few hundredths over the air-to-glass range.
        for i in 0..=20 {
            let cos = i as f32 / 20.0;
            let exact = fresnel_exact(cos, 1.0, 1.5);
            assert!((0.0..=1.0).contains(&exact));
            assert!(close(schlick(cos, 1.0, 1.5), exact, 0.06), "cos {cos}");
        }
    }

    #[test]
    fn attenuation_follows_the_textbook_formula() {
        assert_eq!(attenuation(1.0, 0.0, 0.0, 100.0, true), 1.0);
        assert!(close(
            attenuation(1.0, 0.5, 0.25, 2.0, true),
            1.0 / 3.0,
            1e-7
        ));
        assert!(close(
            attenuation(0.0, 0.0, 1.0, 4.0, true),
            1.0 / 16.0,
            1e-7
        ));
        // Clamped to 1 close to the light.
        assert_eq!(attenuation(0.0, 0.0, 1.0, 0.5, true), 1.0);
    }

    #[test]
    fn unclamped_attenuation_exceeds_one_close_to_the_light() {
        // 1 / (0.25 + 0.5·0.5 + 1·0.25) = 1 / 0.75.
        assert!(close(
            attenuation(0.25, 0.5, 1.0, 0.5, false),
            4.0 / 3.0,
            1e-6
        ));
        // Far away the two agree.
        assert_eq!(
            attenuation(1.0, 0.5, 0.25, 2.0, false),
            attenuation(1.0, 0.5, 0.25, 2.0, true)
        );
        // At a light with no constant term: the largest attenuation, not infinity.
        let at_light = attenuation(0.0, 0.0, 1.0, 0.0, false);
        assert_eq!(
            at_light,
            whitted_ir::limits::MAX_UNCLAMPED_ATTENUATION as f32
        );
    }

    #[test]
    fn spot_fades_smoothly_between_the_cones() {
        let inner = 10.0f32.to_radians().cos();
        let outer = 20.0f32.to_radians().cos();
        assert_eq!(spot_factor(5.0f32.to_radians().cos(), inner, outer), 1.0);
        assert_eq!(spot_factor(25.0f32.to_radians().cos(), inner, outer), 0.0);
        let middle = spot_factor(15.0f32.to_radians().cos(), inner, outer);
        assert!(middle > 0.3 && middle < 0.7, "{middle}");
        let mut previous = 1.0;
        for degrees in 10..=20 {
            let value = spot_factor((degrees as f32).to_radians().cos(), inner, outer);
            assert!(value <= previous);
            previous = value;
        }
    }

    #[test]
    fn beer_lambert_decays_exponentially() {
        let t = beer_lambert(Vec3A::new(0.0, 1.0, 2.0), 0.5);
        assert_eq!(t.x, 1.0);
        assert!(close(t.y, (-0.5f32).exp(), 1e-7));
        assert!(close(t.z, (-1.0f32).exp(), 1e-7));
        let infinite = beer_lambert(Vec3A::new(0.0, 1.0, 0.0), f32::INFINITY);
        assert_eq!(infinite, Vec3A::new(1.0, 0.0, 1.0));
    }
}
