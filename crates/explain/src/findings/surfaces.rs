//! Findings about surfaces met again at once: a secondary or shadow ray that hits its own
//! surface where it left (`self_hit`: surface acne), judged against the hit point's error
//! bound and the object's shape rather than a fixed distance, or another surface there
//! (`coincident_surfaces`: two surfaces in the same place), including the surfaces a ray
//! could not tell apart from the one it hit (z-fighting, seen by camera rays too).

use whitted_tracer::ray_tree::{CoincidentInfo, HitInfo, ObjectRef, RayNode, ShadowOutcome};
use whitted_tracer::{trace_pixel_preferring, NoRecord};

use whitted_ir::{Handle, Material, Object, ObjectKind, QuadricForm, Scene, Shape};

use crate::numbers::{shortest, shortest_up};

use super::{material_of, push_unique, rgb, walk, weight_of, Context, SIGNIFICANT};
use crate::locate::setting_location;
use crate::model::{Finding, FindingKind};

/// A hit closer than this fraction of the point's largest coordinate (or of 1, if larger)
/// is "at once": far more than the tracer's error-bounded offset, far less than any
/// object's own size in a sensible scene.
pub const TINY: f32 = 1e-4;

/// A ray that meets the surface it left within this many of the hit point's error bounds
/// met it again through rounding: acne, however large the object (a planet's bound is a
/// thousandth where a ball's is a millionth).
pub const ACNE_BOUNDS: f32 = 64.0;

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
        let outward = node.kind.name() == "reflected" && from.front_face;
        if is_acne(context.scene, from, hit.object.handle, hit.t, outward) {
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
    // Every ray, camera rays included: a surface the tracer could not tell apart from the
    // one hit (z-fighting).
    walk(context.tree, &mut |node, above| {
        let Some(hit) = &node.hit else {
            return;
        };
        if weight_of(node) < SIGNIFICANT {
            return;
        }
        for other in &hit.coincident {
            // Media given priorities are meant to touch (water in a glass): the tracer
            // crosses both surfaces as one interface there.
            let prioritised = |handle: u32| {
                context
                    .scene
                    .materials
                    .get(Handle::<Material>::from_index(handle as usize))
                    .is_some_and(|m| m.priority > 0)
            };
            if prioritised(hit.resolved_material.handle) && prioritised(other.material.handle) {
                continue;
            }
            // For a camera ray, the sample's colour either way, through the tracer.
            let colours = above
                .is_empty()
                .then(|| either_colour(context, node, other))
                .flatten();
            z_fighting(
                hit,
                other,
                node.kind.name(),
                weight_of(node),
                colours,
                findings,
            );
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
            // A shadow ray leaves outwards from a hit on the outside (it goes towards a
            // light the surface faces); from the inside it may meet the far wall.
            if is_acne(
                context.scene,
                from,
                blocker.object.handle,
                blocker.t,
                from.front_face,
            ) {
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

/// The colour of the camera ray `root` as traced, and as traced had it met `other` first:
/// the two sides of a z-fight, through the tracer's one code path.
fn either_colour(
    context: &Context<'_>,
    root: &RayNode,
    other: &CoincidentInfo,
) -> Option<([f32; 3], [f32; 3])> {
    let sample = context
        .tree
        .samples
        .iter()
        .find(|s| std::ptr::eq(&s.root, root))?;
    let [x, y] = context.tree.pixel;
    let with_other = trace_pixel_preferring(
        context.prepared,
        context.options,
        (x, y, sample.index),
        Handle::<Object>::from_index(other.object.handle as usize),
        &mut NoRecord,
    )?;
    Some((root.color, with_other))
}

/// Two surfaces in one place along a ray: which one it meets is rounding, so neighbouring
/// pixels alternate between them.
fn z_fighting(
    hit: &HitInfo,
    other: &CoincidentInfo,
    ray: &str,
    weight: f32,
    colours: Option<([f32; 3], [f32; 3])>,
    findings: &mut Vec<Finding>,
) {
    let (shown, would) = match colours {
        Some((now, with_other)) => (format!(", {}", rgb(now)), format!(", {}", rgb(with_other))),
        None => (String::new(), String::new()),
    };
    push_unique(
        findings,
        Finding {
            kind: FindingKind::CoincidentSurfaces,
            message: format!(
                "{} ({}) and {} ({}) are in the same place here: the {ray} ray meets {} at \
                 t = {} and {} at t = {}, within rounding of each other, so which one it shows \
                 is chance and neighbouring pixels alternate (z-fighting): this ray shows {} \
                 ({}{shown}); with {} in front it would show {} ({}{would})",
                hit.object.label,
                hit.object.location,
                other.object.label,
                other.object.location,
                hit.object.label,
                shortest(hit.t),
                other.object.label,
                shortest(other.t),
                hit.resolved_material.label,
                hit.object.label,
                other.object.label,
                other.material.label,
                other.object.label
            ),
            location: other.object.location.clone(),
            fix: format!(
                "move {} off {} along the surface's normal by {} or more, so that one is in \
                 front, or remove one of them",
                other.object.label,
                hit.object.label,
                shortest_up((1000.0 * hit.error_bound).max(1e-3))
            ),
            weight,
            source_line: None,
        },
    );
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
        ObjectKind::Shape { shape } => context.scene.is_solid_shape(&shape.get()),
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
/// it left within [`ACNE_BOUNDS`] error bounds of the hit point (or a hair by the scene's
/// scale): surface acne as the tree alone shows it, without the scene's shapes (see
/// [`is_acne`]). The debugger's `{`/`}` stop at such rays.
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
    met.is_some_and(|(object, t)| object == from.object.handle && near_by_error(t, from))
}

/// Whether a ray that left `from` and met `object` at distance `t` met the surface it left
/// through rounding. It did when the object is the one it left and either the ray left a
/// convex solid outwards (a shadow ray towards a light the surface faces, a reflection off
/// its outside: no true path can meet it again, however far), or `t` is within
/// [`ACNE_BOUNDS`] error bounds of the hit point, or a hair by the scene's own scale.
pub fn is_acne(scene: &Scene, from: &HitInfo, object: u32, t: f32, outward: bool) -> bool {
    if object != from.object.handle {
        return false;
    }
    if outward && is_convex(scene, object) {
        return true;
    }
    near_by_error(t, from)
}

/// Whether `t` is within rounding of the hit point `from`: [`ACNE_BOUNDS`] error bounds,
/// or a hair by the scene's scale.
fn near_by_error(t: f32, from: &HitInfo) -> bool {
    t < ACNE_BOUNDS * from.error_bound || tiny(t, from)
}

/// Whether an object is a convex solid or a flat surface: no ray leaving its outside
/// outwards can meet it again.
fn is_convex(scene: &Scene, handle: u32) -> bool {
    let Some(object) = scene
        .objects
        .get(Handle::<Object>::from_index(handle as usize))
    else {
        return false;
    };
    match &object.kind {
        ObjectKind::Shape { shape } => match shape.get() {
            Shape::Sphere { .. }
            | Shape::Box { .. }
            | Shape::Plane { .. }
            | Shape::Disk { .. }
            | Shape::Triangle { .. } => true,
            Shape::Cylinder { capped, .. } | Shape::Cone { capped, .. } => capped,
            Shape::Quadric { form, .. } => form == QuadricForm::Ellipsoid,
            _ => false,
        },
        ObjectKind::Csg { .. } | ObjectKind::Group { .. } => false,
    }
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
        let bound = from.error_bound;
        let fix = match (&epsilon, context.scene.settings.epsilon) {
            (Some(at), Some(value)) if (value as f32) < 2.0 * bound => format!(
                "the surface offset `epsilon {}` ({at}) is smaller than this hit point's error \
                 bound ({}): remove it, so that rays start off each hit by its own bound, or \
                 raise it to at least {}",
                shortest(value as f32),
                shortest_up(bound),
                shortest_up(4.0 * bound)
            ),
            (Some(at), _) => format!(
                "the surface offset `epsilon` ({at}) is too small for this scene's size: \
                 remove it (the tracer then offsets by each hit's error bound) or raise it \
                 above {}",
                shortest_up(2.0 * t)
            ),
            (None, _) => format!(
                "the automatic offset ({}) did not clear {}'s surface here: set `epsilon {}` \
                 in the settings block, or make {} smaller or move it nearer the origin",
                shortest_up(from.offset),
                object.label,
                shortest_up(2.0 * t),
                object.label
            ),
        };
        push_unique(
            findings,
            Finding {
                kind: FindingKind::SelfHit,
                message: format!(
                    "a {ray} ray leaving {} meets {} again at t = {}, where it started: surface \
                     acne (the hit point's error bound there is {}; rays start {} off the surface)",
                    from.object.label,
                    object.label,
                    shortest(t),
                    shortest_up(bound),
                    shortest_up(from.offset)
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
