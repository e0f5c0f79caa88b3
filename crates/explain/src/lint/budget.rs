//! The `ray_budget` lint: a scene whose worst sample casts more rays than the tracer's
//! budget per sample (`whitted_ir::limits::MAX_RAYS_PER_SAMPLE`), so that `render` will cut
//! its recursion short. That happens when glass that both reflects and transmits (each hit
//! spawns two rays) meets path weights that cannot fall (`min_weight 0`, or a coefficient
//! of 1) at a deep `max_depth`.
//!
//! The worst case is counted from the IR alone, without tracing: every ray is assumed to
//! meet the most branching material again, and a ray is traced while its path weight (the
//! product of the coefficients on its way, largest channel) is at least `min_weight`, to
//! `max_depth`. Fresnel materials are counted with their reflectance head on, ((n−1)/(n+1))²
//! (grazing rays reflect more, and those are rare). Each traced ray at a surface with a
//! diffuse or specular colour also casts a shadow ray per light.

use whitted_ir::limits::MAX_RAYS_PER_SAMPLE;
use whitted_ir::{Color, Diagnostic, Fresnel, Handle, Material, Scene};

use super::{Lint, LintKind};
use crate::locate::setting_span;

/// The most rays one sample of `scene` could cast, and the material that makes it so.
#[derive(Clone, Debug, PartialEq)]
pub struct WorstCase {
    /// Reflected, transmitted and shadow rays of the worst sample (an f64: 2^256 fits).
    pub rays: f64,
    pub material: Handle<Material>,
}

/// The worst case over the scene's materials that branch (reflect and transmit), or `None`
/// when none does (then a sample casts at most a ray per level and its shadow rays).
pub fn worst_case(scene: &Scene) -> Option<WorstCase> {
    let settings = &scene.settings;
    worst_case_at(scene, settings.min_weight, settings.max_depth)
}

/// [`worst_case`] with other limits than the scene's (`render`'s flags override them).
pub fn worst_case_at(scene: &Scene, min_weight: f64, max_depth: u32) -> Option<WorstCase> {
    let depth = max_depth.min(whitted_ir::limits::MAX_DEPTH);
    let mut worst: Option<WorstCase> = None;
    for (handle, material) in scene.materials.iter() {
        let Some(rays) = rays_of(scene, material, min_weight, depth) else {
            continue;
        };
        if worst.as_ref().is_none_or(|w| rays > w.rays) {
            worst = Some(WorstCase {
                rays,
                material: handle,
            });
        }
    }
    worst
}

/// The rays of the worst sample if every ray met `material`, at `depth`; `None` when the
/// material does not branch.
fn rays_of(scene: &Scene, material: &Material, min_weight: f64, depth: u32) -> Option<f64> {
    let (reflect, transmit) = branch_factors(material)?;
    let rays_per_hit = if material.diffuse.is_black() && material.specular.is_black() {
        1.0
    } else {
        1.0 + scene.lights.len() as f64
    };
    Some(traced_rays(reflect, transmit, min_weight, depth) * rays_per_hit)
}

/// The largest channel of the reflected and transmitted coefficients a material gives
/// its secondary rays, when it gives both (after the tracer's scaling to a sum of at most
/// 1 per channel); `None` when it does not branch.
fn branch_factors(material: &Material) -> Option<(f64, f64)> {
    if material.transmissive.is_black() {
        return None;
    }
    let r0 = ((material.ior - 1.0) / (material.ior + 1.0)).powi(2);
    let channels = |c: &Color| [c.r, c.g, c.b];
    let (mut reflect, mut transmit) = (0.0f64, 0.0f64);
    for (kr, kt) in channels(&material.reflective)
        .into_iter()
        .zip(channels(&material.transmissive))
    {
        let (kr, kt) = match material.fresnel {
            Fresnel::Off => (kr, kt),
            Fresnel::Schlick | Fresnel::Exact => (kr + kt * r0, kt * (1.0 - r0)),
        };
        let scale = 1.0 / (kr + kt).max(1.0);
        reflect = reflect.max(kr * scale);
        transmit = transmit.max(kt * scale);
    }
    (reflect > 0.0 && transmit > 0.0).then_some((reflect, transmit))
}

/// Whether a branch of `material` keeps its whole path weight on some channel (a
/// coefficient of 1), so that no `min_weight` ends the paths along it.
fn weight_cannot_fall(material: &Material) -> bool {
    branch_factors(material).is_some_and(|(reflect, transmit)| reflect.max(transmit) >= 1.0)
}

/// Secondary rays traced below one camera ray when every hit splits into a reflected ray
/// (coefficient `reflect`) and a transmitted one (`transmit`): the paths of 1 to `depth`
/// bounces whose weight stays at or above `min_weight`. A path of `j` reflections and `m`
/// transmissions is one of C(j + m, j) in its tree.
fn traced_rays(reflect: f64, transmit: f64, min_weight: f64, depth: u32) -> f64 {
    let depth = depth as usize;
    // C(n, j) for the current n, updated row by row (f64: the counts reach 2^256).
    let mut row = vec![0.0f64; depth + 1];
    row[0] = 1.0;
    let mut total = 0.0;
    for n in 1..=depth {
        for j in (1..=n).rev() {
            row[j] += row[j - 1];
        }
        for (j, paths) in row.iter().enumerate().take(n + 1) {
            let weight = reflect.powi(j as i32) * transmit.powi((n - j) as i32);
            if weight >= min_weight {
                total += paths;
            }
        }
    }
    total
}

/// Warns at `min_weight` (or at the material when `min_weight` is not written) when the
/// worst sample would pass the ray budget and nothing makes the weights fall: `min_weight 0`,
/// or a branch that keeps its whole weight. (With a minimum weight the worst case is far
/// above what happens: a Fresnel gem of ior 2, whose transmitted rays keep 89% at each
/// surface, counts 11,223 rays at `max_depth 63` where its busiest sample casts 236, since
/// real rays leave the gem. `render`'s report catches any scene that does reach it.)
pub(super) fn ray_budget(scene: &Scene, lints: &mut Vec<Lint>) {
    let Some(worst) = worst_case(scene) else {
        return;
    };
    let budget = f64::from(MAX_RAYS_PER_SAMPLE);
    let settings = &scene.settings;
    let material = &scene.materials[worst.material];
    if worst.rays <= budget || !(settings.min_weight <= 0.0 || weight_cannot_fall(material)) {
        return;
    }
    let name = match &scene.materials[worst.material].name {
        Some(name) => format!("material `{name}`"),
        None => format!("the material {}", worst.material),
    };
    let material_span = scene.materials.span(worst.material);
    let (span, at_setting) = match setting_span(scene, "min_weight") {
        Some(span) => (span, true),
        None => (material_span, false),
    };
    // The counts grow with the depth: the deepest under the budget.
    let depth_ok = (1..=settings.max_depth)
        .take_while(|&d| {
            rays_of(scene, material, settings.min_weight, d).is_some_and(|rays| rays <= budget)
        })
        .last()
        .unwrap_or(0);
    let mut diagnostic = Diagnostic::warning(
        format!(
            "min_weight {} with {name}, which reflects and transmits, at max_depth {}: a \
             sample could take up to {} rays, past the budget of {} rays per sample, so \
             `render` stops each such sample's recursion there and keeps the colour so far",
            settings.min_weight,
            settings.max_depth,
            rays_text(worst.rays),
            MAX_RAYS_PER_SAMPLE
        ),
        span,
    )
    .with_label(if at_setting {
        format!("min_weight is {} here", settings.min_weight)
    } else {
        format!("{name} splits every ray in two")
    })
    .with_hint(format!(
        "raise min_weight (0.001 is usual) so that weak paths end, or lower max_depth to {} \
         or less",
        depth_ok
    ));
    if at_setting {
        diagnostic =
            diagnostic.with_secondary(material_span, format!("{name} splits every ray in two"));
    }
    if let Some(max_depth) = setting_span(scene, "max_depth") {
        diagnostic = diagnostic.with_secondary(
            max_depth,
            format!("max_depth is {} here", settings.max_depth),
        );
    }
    lints.push(Lint::new(LintKind::RayBudget, diagnostic));
}

/// What makes samples of `scene` reach the ray budget at `min_weight` and `max_depth` (the
/// render's, after its flags), for `render`'s report of cut pixels:
/// `min_weight 0 at FILE:LINE:COL with max_depth 64 at ... and material `glass` (FILE:LINE:COL),
/// which reflects and transmits (up to 3.7e19 rays a sample)`. Settings that are not
/// written are given as defaults. Call it while the IR is at hand; it reads the sources
/// only when the worst case is past the budget.
pub fn ray_budget_cause(scene: &Scene, min_weight: f64, max_depth: u32) -> String {
    let worst = worst_case_at(scene, min_weight, max_depth)
        .filter(|w| w.rays > f64::from(MAX_RAYS_PER_SAMPLE));
    let Some(worst) = worst else {
        return format!("min_weight {min_weight} with max_depth {max_depth}");
    };
    let at = |name: &str| match setting_span(scene, name) {
        Some(span) => format!(" at {}", scene.sources.location(span)),
        None => " (the default)".to_string(),
    };
    let name = match &scene.materials[worst.material].name {
        Some(name) => format!("material `{name}`"),
        None => format!("the material {}", worst.material),
    };
    format!(
        "min_weight {}{} with max_depth {}{} and {name} ({}), which reflects and transmits \
         (up to {} rays a sample)",
        min_weight,
        at("min_weight"),
        max_depth,
        at("max_depth"),
        scene.sources.location(scene.materials.span(worst.material)),
        rays_text(worst.rays)
    )
}

/// A ray count for people: exact up to a billion, then in scientific notation.
fn rays_text(rays: f64) -> String {
    if rays < 1e9 {
        let digits = format!("{rays:.0}");
        let mut out = String::new();
        for (i, c) in digits.chars().enumerate() {
            if i > 0 && (digits.len() - i) % 3 == 0 {
                out.push(',');
            }
            out.push(c);
        }
        out
    } else {
        format!("{rays:.1e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_path_counts_without_a_minimum_weight() {
        // 2 + 4 + ... + 2^d = 2^(d+1) − 2.
        assert_eq!(traced_rays(0.5, 0.5, 0.0, 10), 2046.0);
        // Past 2^53 the sum of binomials rounds: equal to a part in 10^12.
        let deep = traced_rays(0.5, 0.5, 0.0, 64);
        assert!((deep / (2f64.powi(65) - 2.0) - 1.0).abs() < 1e-12, "{deep}");
    }

    #[test]
    fn a_minimum_weight_ends_the_paths_that_fall_under_it() {
        // 0.5^n >= 0.001 for n <= 9: levels 1 to 9 of the tree.
        assert_eq!(traced_rays(0.5, 0.5, 0.001, 64), 1022.0);
        // Weak reflections end at once; the transmitted chain goes on.
        assert_eq!(traced_rays(0.01, 0.99, 0.5, 3), 3.0);
    }

    #[test]
    fn big_counts_read_as_powers_of_ten() {
        assert_eq!(rays_text(1022.0), "1,022");
        assert_eq!(rays_text(3.7e19), "3.7e19");
    }
}
