//! The scene linter behind `whitted check`'s warnings: likely mistakes in a valid scene,
//! each a located `Diagnostic` (severity warning) with a hint that says the fix.
//!
//! Two families, each bounded so that a scene of a million objects stays fast:
//! `geometry.rs` reads the IR alone (lights inside solids, materials that return more
//! light than they receive, planes and triangles turned away from every light), and
//! `sampled.rs` traces a fixed grid of camera rays through the tracer's one code path with a
//! recorder of its own (coincident surfaces, `max_depth` too low for the glass a camera
//! ray crosses) and remembers every object a sampled ray met, which `view.rs` uses to say
//! which objects the camera cannot see. The rules are in docs/explain.md ("Lints").

mod bounds;
mod budget;
mod empty;
mod geometry;
mod sampled;
mod view;

pub use budget::{ray_budget_cause, worst_case, worst_case_at, WorstCase};

use whitted_ir::{Diagnostic, Scene};
use whitted_tracer::{PreparedScene, RenderOptions};

/// What a lint warns about; its name starts the warning's message.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum LintKind {
    LightInsideSolid,
    CoincidentSurfaces,
    MaxDepthTooLow,
    MaterialGain,
    UnseenObject,
    FacingAwayFromLights,
    RayBudget,
    NothingToSee,
}

impl LintKind {
    pub const ALL: [LintKind; 8] = [
        LintKind::LightInsideSolid,
        LintKind::CoincidentSurfaces,
        LintKind::MaxDepthTooLow,
        LintKind::MaterialGain,
        LintKind::UnseenObject,
        LintKind::FacingAwayFromLights,
        LintKind::RayBudget,
        LintKind::NothingToSee,
    ];

    pub fn name(self) -> &'static str {
        match self {
            LintKind::LightInsideSolid => "light_inside_solid",
            LintKind::CoincidentSurfaces => "coincident_surfaces",
            LintKind::MaxDepthTooLow => "max_depth_too_low",
            LintKind::MaterialGain => "material_gain",
            LintKind::UnseenObject => "unseen_object",
            LintKind::FacingAwayFromLights => "facing_away_from_lights",
            LintKind::RayBudget => "ray_budget",
            LintKind::NothingToSee => "nothing_to_see",
        }
    }
}

/// One warning: its kind and the diagnostic to show.
#[derive(Clone, Debug, PartialEq)]
pub struct Lint {
    pub kind: LintKind,
    pub diagnostic: Diagnostic,
}

impl Lint {
    fn new(kind: LintKind, diagnostic: Diagnostic) -> Lint {
        let message = format!("{}: {}", kind.name(), diagnostic.message);
        Lint {
            kind,
            diagnostic: Diagnostic {
                message,
                ..diagnostic
            },
        }
    }
}

/// At most this many warnings of one kind; the last one says how many more there were
/// (a scene of a thousand spheres behind the camera needs one warning, not a thousand).
pub const MAX_PER_KIND: usize = 5;

/// Scenes with more objects than this are not linted unless asked (`whitted check --lint`):
/// the lints need the scene's BVH, which `check` does not otherwise build, and their
/// per-object passes; on a million spheres they made `check` three times slower (0.68 s ->
/// 2.1-2.5 s) and doubled its peak memory. Scenes that big are written by programs, and the
/// lints are for scenes written by hand.
pub const MAX_OBJECTS: usize = 50_000;

/// Whether `scene` is small enough to lint without being asked (see [`MAX_OBJECTS`]).
pub fn lints_by_default(scene: &Scene) -> bool {
    scene.objects.len() <= MAX_OBJECTS
}

/// Every lint of `scene`, in a fixed order (kind, then scene order), at the scene's own
/// image size and depth. `prepared` must be made from `scene`.
pub fn lint(prepared: &PreparedScene, scene: &Scene) -> Vec<Lint> {
    lint_at(
        prepared,
        scene,
        &RenderOptions::from_settings(&scene.settings),
    )
}

/// [`lint`] for the image being made with `options` (the command line's `--width`,
/// `--height` and `--max-depth` applied): the pixels the warnings name are pixels of that
/// image, and the depth they judge is the depth it is traced with.
pub fn lint_at(prepared: &PreparedScene, scene: &Scene, options: &RenderOptions) -> Vec<Lint> {
    let mut lints = Vec::new();
    geometry::lights_inside_solids(scene, &mut lints);
    let options = sampled::grid_options(options);
    let samples = sampled::sample(prepared, scene, &options);
    sampled::coincident_surfaces(scene, &samples, &mut lints);
    sampled::max_depth_too_low(prepared, scene, &samples, &options, &mut lints);
    geometry::material_gain(scene, &mut lints);
    view::unseen_objects(scene, &samples, &mut lints);
    empty::nothing_to_see(scene, &samples, &mut lints);
    geometry::facing_away_from_lights(scene, &mut lints);
    budget::ray_budget(scene, &mut lints);
    cap_per_kind(&mut lints);
    lints
}

/// Keeps [`MAX_PER_KIND`] warnings of each kind; the last kept says how many were left out.
fn cap_per_kind(lints: &mut Vec<Lint>) {
    for kind in LintKind::ALL {
        let total = lints.iter().filter(|l| l.kind == kind).count();
        if total <= MAX_PER_KIND {
            continue;
        }
        let mut seen = 0;
        lints.retain_mut(|l| {
            if l.kind != kind {
                return true;
            }
            seen += 1;
            if seen == MAX_PER_KIND {
                l.diagnostic.hints.push(format!(
                    "{} more {} warnings are not shown",
                    total - MAX_PER_KIND,
                    kind.name()
                ));
            }
            seen <= MAX_PER_KIND
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::{FileId, Span};

    fn warning(kind: LintKind, n: usize) -> Lint {
        Lint::new(
            kind,
            Diagnostic::warning(format!("number {n}"), Span::new(FileId(0), n, n + 1)),
        )
    }

    #[test]
    fn at_most_five_of_a_kind_and_the_last_says_how_many_more() {
        let mut lints: Vec<Lint> = (0..8)
            .map(|n| warning(LintKind::UnseenObject, n))
            .chain([warning(LintKind::LightInsideSolid, 9)])
            .collect();
        cap_per_kind(&mut lints);
        let unseen: Vec<&Lint> = lints
            .iter()
            .filter(|l| l.kind == LintKind::UnseenObject)
            .collect();
        assert_eq!(unseen.len(), MAX_PER_KIND);
        assert_eq!(unseen[4].diagnostic.message, "unseen_object: number 4");
        assert_eq!(
            unseen[4].diagnostic.hints,
            ["3 more unseen_object warnings are not shown"]
        );
        assert!(unseen[..4].iter().all(|l| l.diagnostic.hints.is_empty()));
        assert_eq!(lints.len(), MAX_PER_KIND + 1);
    }
}
