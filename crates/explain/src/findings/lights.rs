//! Findings about lights at the surfaces that matter: a light behind the surface
//! (`light_behind`, N·L <= 0), a spot light whose cone does not reach the point
//! (`outside_spot_cone`), a shadow ray stopped by an object (`shadow_blocked`, and
//! whether that object is transparent while shadows are opaque), and a light inside a
//! solid (`light_inside_solid`).

use glam::DVec3;
use whitted_ir::{Handle, LightKind, Object, ShadowMode};
use whitted_tracer::ray_tree::{RayNode, ShadowOutcome, Visibility};
use whitted_tracer::RayKind;

use super::{material_of, push_unique, walk, weight_of, Context, SIGNIFICANT};
use crate::inside::contains;
use crate::model::{Finding, FindingKind};

pub(super) fn find(context: &Context<'_>, findings: &mut Vec<Finding>) {
    walk(context.tree, &mut |node, _| {
        if weight_of(node) < SIGNIFICANT {
            return;
        }
        // Glass with only a highlight has lights behind it and shadow rays stopped by its
        // own walls all the time, which explains nothing about the pixel.
        if !diffuse_surface(context, node) {
            return;
        }
        light_behind(node, findings);
        outside_cone(node, findings);
        blocked(context, node, findings);
    });
}

/// Whether the surface a ray hit has a diffuse colour.
fn diffuse_surface(context: &Context<'_>, node: &RayNode) -> bool {
    let Some(hit) = &node.hit else {
        return false;
    };
    let handle = Handle::from_index(hit.resolved_material.handle as usize);
    context
        .scene
        .materials
        .get(handle)
        .is_some_and(|m| !m.diffuse.is_black())
}

/// Who sees the point a ray hit, for messages: the camera, or the path that reached it.
fn seen_by(node: &RayNode) -> &'static str {
    if node.kind == RayKind::Camera {
        "the camera"
    } else {
        "this path"
    }
}

fn light_behind(node: &RayNode, findings: &mut Vec<Finding>) {
    let (Some(hit), Some(local)) = (&node.hit, &node.local) else {
        return;
    };
    // Seen from inside a solid (through glass), every light outside is "behind" the wall:
    // that is the model at work, not a cause.
    if !hit.front_face && hit.object.kind != "plane" {
        return;
    }
    let seen_by = seen_by(node);
    for light in &local.lights {
        if light.visibility != Visibility::FacingAway {
            continue;
        }
        let what = match hit.object.kind.as_str() {
            "plane" | "disk" | "triangle" => "side",
            _ => "point",
        };
        push_unique(
            findings,
            Finding {
                kind: FindingKind::LightBehind,
                message: format!(
                    "{} ({}) is behind the surface of {} ({}) at the {what} {seen_by} sees \
                     (N·L = {:.3}): it adds nothing there",
                    light.light.label,
                    light.light.location,
                    hit.object.label,
                    hit.object.location,
                    light.n_dot_l
                ),
                location: light.light.location.clone(),
                fix: format!(
                    "if it should be lit, move {} to the side of {} that {seen_by} sees, or add \
                     a light there",
                    light.light.label, hit.object.label
                ),
                weight: weight_of(node),
                source_line: None,
            },
        );
    }
}

/// A spot light whose cone does not reach the point: the tracer said so
/// (`outside_cone`), whatever N·L is; the angles come from the tree.
fn outside_cone(node: &RayNode, findings: &mut Vec<Finding>) {
    let (Some(hit), Some(local)) = (&node.hit, &node.local) else {
        return;
    };
    let seen_by = seen_by(node);
    for light in &local.lights {
        if light.visibility != Visibility::OutsideCone {
            continue;
        }
        let label = &light.light.label;
        let (angles, widen) = match &light.cone {
            Some(cone) => (
                format!(
                    "{} from the spot's axis, beyond its cone of {}",
                    degrees(cone.angle_degrees),
                    degrees(cone.outer_degrees)
                ),
                format!(
                    "widen {label}'s cone (`outer` to more than {}) or aim it at the point",
                    degrees(cone.angle_degrees.ceil())
                ),
            ),
            None => (
                "beyond the spot's cone".to_string(),
                format!("widen {label}'s cone (`outer`) or aim it at the point"),
            ),
        };
        push_unique(
            findings,
            Finding {
                kind: FindingKind::OutsideSpotCone,
                message: format!(
                    "the point of {} ({}) {seen_by} sees is outside the cone of spot light \
                     {label} ({}): {angles}, so it adds nothing there (N·L = {:.3})",
                    hit.object.label, hit.object.location, light.light.location, light.n_dot_l
                ),
                location: light.light.location.clone(),
                fix: format!(
                    "{widen} (its `direction`) if it should light {}",
                    hit.object.label
                ),
                weight: weight_of(node),
                source_line: None,
            },
        );
    }
}

/// An angle as people read it: `52.3°`.
fn degrees(value: f32) -> String {
    let text = format!("{value:.1}");
    format!("{}°", text.strip_suffix(".0").unwrap_or(&text))
}

/// A point or spot light's position.
fn light_position(context: &Context<'_>, handle: u32) -> Option<DVec3> {
    let light = context
        .scene
        .lights
        .get(Handle::from_index(handle as usize))?;
    match light.kind {
        LightKind::Point { position, .. } | LightKind::Spot { position, .. } => Some(position),
        LightKind::Directional { .. } => None,
    }
}

fn blocked(context: &Context<'_>, node: &RayNode, findings: &mut Vec<Finding>) {
    let scene = context.scene;
    let weight = weight_of(node);
    for shadow_ray in node.children.iter().filter_map(|c| c.shadow.as_ref()) {
        if shadow_ray.result != ShadowOutcome::Blocked {
            continue;
        }
        let Some(blocker) = &shadow_ray.blocker else {
            continue;
        };
        // A blocker that is the surface itself, met through rounding, is acne:
        // `self_hit` says so, not this. One met a hair away is another surface in the same
        // place: `coincident_surfaces` says so.
        if let Some(from) = &node.hit {
            let scale = from.point.iter().fold(1.0f32, |m, c| m.max(c.abs()));
            if super::surfaces::is_acne(
                scene,
                from,
                blocker.object.handle,
                blocker.t,
                from.front_face,
            ) || blocker.t < super::surfaces::TINY * scale
            {
                continue;
            }
        }
        let light = &shadow_ray.light;
        let inside = light_position(context, light.handle).is_some_and(|p| {
            contains(
                scene,
                Handle::<Object>::from_index(blocker.object.handle as usize),
                p,
            ) == Some(true)
        });
        let transparent = material_of(scene, blocker.leaf.handle)
            .filter(|(m, _)| !m.transmissive.is_black())
            .map(|(_, handle)| scene.material_label(handle));
        let opaque_shadows = scene.settings.shadows == ShadowMode::Opaque;
        if inside {
            // As `check` says for the same light: both fixes when the solid lets light
            // through and only opaque shadows keep it in.
            let through = match &transparent {
                Some(material) if opaque_shadows => format!(
                    ", or set `shadows filtered` in settings (or run with --set \
                     shadows=filtered) so that its light shines out through {} (material \
                     {material}), which is transparent",
                    blocker.object.label
                ),
                _ => String::new(),
            };
            push_unique(
                findings,
                Finding {
                    kind: FindingKind::LightInsideSolid,
                    message: format!(
                        "{} ({}) is inside {}: every shadow ray to it from outside is stopped \
                         by {}'s surface",
                        light.label, light.location, blocker.object.label, blocker.object.label
                    ),
                    location: blocker.object.location.clone(),
                    fix: format!(
                        "move {} out of {} (or make {} smaller){through}",
                        light.label, blocker.object.label, blocker.object.label
                    ),
                    weight,
                    source_line: None,
                },
            );
            continue;
        }
        let surface = node
            .hit
            .as_ref()
            .map_or("the surface".to_string(), |h| h.object.label.clone());
        let (message, fix) = match transparent {
            Some(material) if opaque_shadows => (
                format!(
                    "the shadow ray from {surface} to {} is blocked by {} ({}), which is \
                     transparent (material {material}), but shadows are opaque",
                    light.label, blocker.object.label, blocker.object.location
                ),
                "set `shadows filtered` in settings (or run with --set shadows=filtered) so \
                 that light passes through transparent objects"
                    .to_string(),
            ),
            _ => (
                format!(
                    "the shadow ray from {surface} to {} is blocked by {} ({}) at distance {:.3}",
                    light.label, blocker.object.label, blocker.object.location, blocker.t
                ),
                format!(
                    "if this point should be lit by {}, move {} or {} ({}) so that nothing \
                     stands between them",
                    light.label, blocker.object.label, light.label, light.location
                ),
            ),
        };
        push_unique(
            findings,
            Finding {
                kind: FindingKind::ShadowBlocked,
                message,
                location: blocker.object.location.clone(),
                fix,
                weight,
                source_line: None,
            },
        );
    }
}
