//! Findings about surfaces met again at once: a secondary or shadow ray that hits its own
//! surface a hair from where it left (`self_hit`: surface acne), or another surface there
//! (`coincident_surfaces`: two surfaces in the same place).

use whitted_tracer::ray_tree::{HitInfo, ObjectRef, RayNode, ShadowOutcome};

use whitted_ir::{Handle, Object, ObjectKind};

use super::{material_of, push_unique, walk, weight_of, Context, SIGNIFICANT};
use crate::locate::setting_location;
use crate::model::{Finding, FindingKind};

/// A hit closer than this fraction of the point's largest coordinate (or of 1, if larger)
/// is "at once": far more than the tracer's error-bounded offset, far less than any
/// object's own size in a sensible scene.
pub const TINY: f32 = 1e-4;

pub(super) fn find(context: &Context<'_>, findings: &mut Vec<Finding>) {
    walk(context.tree, &mut |node, above| {
        let Some(from) = above.last().and_then(|p| p.hit.as_ref()) else {
            return;
        };
        let Some(hit) = &node.hit else {
            return;
        };
        if weight_of(node) < SIGNIFICANT {
            return;
        }
        if tiny(hit.t, from) {
            report(
                context,
                from,
                &hit.object,
                hit.t,
                node.kind.name(),
                weight_of(node),
                findings,
            );
        } else if !hit.front_face
            && hit.object.handle != from.object.handle
            && opaque_solid(context, hit)
        {
            // No ray can enter an opaque solid, so one that meets its inside started
            // there: the surface it left is inside that solid or on its surface.
            starts_inside(from, hit, node.kind.name(), weight_of(node), findings);
        }
    });
    // Shadow rays leave from their parent's hit.
    walk(context.tree, &mut |node, _| {
        let Some(from) = &node.hit else {
            return;
        };
        if weight_of(node) < SIGNIFICANT {
            return;
        }
        for child in &node.children {
            let Some(shadow) = &child.shadow else {
                continue;
            };
            let Some(blocker) = shadow
                .blocker
                .as_ref()
                .filter(|_| shadow.result == ShadowOutcome::Blocked)
            else {
                continue;
            };
            if tiny(blocker.t, from) {
                report(
                    context,
                    from,
                    &blocker.object,
                    blocker.t,
                    "shadow",
                    weight_of(node),
                    findings,
                );
            }
        }
    });
}

/// Whether the hit object is a solid whose material lets no light through.
fn opaque_solid(context: &Context<'_>, hit: &HitInfo) -> bool {
    let Some(object) = context
        .scene
        .objects
        .get(Handle::<Object>::from_index(hit.leaf.handle as usize))
    else {
        return false;
    };
    let solid = match &object.kind {
        ObjectKind::Shape { shape } => context.scene.is_solid_shape(shape),
        ObjectKind::Csg { .. } => true,
        ObjectKind::Group { .. } => false,
    };
    solid
        && material_of(context.scene, hit.leaf.handle)
            .is_some_and(|(m, _)| m.transmissive.is_black())
}

fn starts_inside(
    from: &HitInfo,
    hit: &HitInfo,
    ray: &str,
    weight: f32,
    findings: &mut Vec<Finding>,
) {
    push_unique(
        findings,
        Finding {
            kind: FindingKind::CoincidentSurfaces,
            message: format!(
                "a {ray} ray leaving {} ({}) starts inside {}, which is opaque: it meets {}'s \
                 surface from inside at t = {:.4}, so the two surfaces coincide or overlap here",
                from.object.label, from.object.location, hit.object.label, hit.object.label, hit.t
            ),
            location: hit.object.location.clone(),
            fix: format!(
                "move {} off {} by more than a hair (for example 0.001), so that no surface of \
                 one lies on or inside the other",
                hit.object.label, from.object.label
            ),
            weight,
            source_line: None,
        },
    );
}

/// Whether `node` (a secondary or shadow ray cast from `parent`'s hit) met the very surface
/// it left at once (surface acne): the object it hit, or the shadow ray's blocker, is the
/// parent's object, closer than [`TINY`]. The debugger's `{`/`}` stop at such rays.
pub fn is_self_hit(node: &RayNode, parent: &RayNode) -> bool {
    let Some(from) = &parent.hit else {
        return false;
    };
    let met = match (&node.shadow, &node.hit) {
        (Some(shadow), _) => shadow
            .blocker
            .as_ref()
            .filter(|_| shadow.result == ShadowOutcome::Blocked)
            .map(|b| (b.object.handle, b.t)),
        (None, Some(hit)) => Some((hit.object.handle, hit.t)),
        (None, None) => None,
    };
    met.is_some_and(|(object, t)| object == from.object.handle && tiny(t, from))
}

fn tiny(t: f32, from: &HitInfo) -> bool {
    let scale = from.point.iter().fold(1.0f32, |m, c| m.max(c.abs()));
    t < TINY * scale
}

fn report(
    context: &Context<'_>,
    from: &HitInfo,
    object: &ObjectRef,
    t: f32,
    ray: &str,
    weight: f32,
    findings: &mut Vec<Finding>,
) {
    if object.handle == from.object.handle {
        let epsilon = setting_location(context.scene, "epsilon");
        let fix = match &epsilon {
            Some(at) => format!(
                "the surface offset `epsilon` ({at}) is too small for this scene's size: \
                 remove it (the tracer then offsets by each hit's error bound) or raise it"
            ),
            None => format!(
                "scale the scene so that {} is nearer the origin, or set `epsilon` in settings \
                 to an offset larger than {t:e}",
                object.label
            ),
        };
        push_unique(
            findings,
            Finding {
                kind: FindingKind::SelfHit,
                message: format!(
                    "a {ray} ray leaving {} hits {} again at t = {t:e}, where it started: \
                     surface acne",
                    from.object.label, object.label
                ),
                // The setting to change when the scene sets it; the object otherwise.
                location: epsilon.unwrap_or_else(|| object.location.clone()),
                fix,
                weight,
                source_line: None,
            },
        );
    } else {
        push_unique(
            findings,
            Finding {
                kind: FindingKind::CoincidentSurfaces,
                message: format!(
                    "{} ({}) and {} ({}) are in the same place here: a {ray} ray leaving one \
                     hits the other at t = {t:e}",
                    from.object.label, from.object.location, object.label, object.location
                ),
                location: object.location.clone(),
                fix: format!(
                    "move {} off {} by more than a hair (for example 0.001), or, if both are \
                     media meant to touch (water in a glass), give their materials a `priority`",
                    object.label, from.object.label
                ),
                weight,
                source_line: None,
            },
        );
    }
}
