//! The student-facing words for a reading: what the reference pixel has that the student's
//! lacks (or the other way round), named by the objects, lights and lines of the recorded
//! ray tree, and what the student's tracer must do differently. Never a change to the
//! scene: the scene is the assignment.

use whitted_ir::{Highlight, ShadowMode};
use whitted_tracer::ray_tree::{trace_pixel, RayNode, RayTree, SampleChoice, Visibility};
use whitted_tracer::RayKind;

use super::{Behaviour, Behaviours};
use crate::findings::{walk, weight_of};

/// A reading in words.
pub(super) struct Worded {
    pub message: String,
    pub tracer: String,
    pub location: Option<String>,
}

fn worded(message: String, tracer: &str, location: Option<String>) -> Worded {
    Worded {
        message,
        tracer: tracer.to_string(),
        location,
    }
}

/// Words for `behaviour` (or, with none, for a difference no behaviour explains).
pub(super) fn word(
    behaviours: &Behaviours,
    tree: &RayTree,
    behaviour: Option<Behaviour>,
) -> Worded {
    let first_hit = tree.samples.first().and_then(|s| s.root.hit.as_ref());
    let seen = first_hit.map(|h| {
        (
            format!("{} at {}", h.object.label, h.object.location),
            h.object.location.clone(),
        )
    });
    let (seen_text, seen_location) =
        seen.unwrap_or_else(|| ("the background".into(), String::new()));
    let seen_location = (!seen_location.is_empty()).then_some(seen_location);
    let reference_shadows = tree.model.shadows;
    match behaviour {
        Some(Behaviour::Shadows { mode: ShadowMode::None }) => match heaviest_shadow(tree, Visibility::Blocked)
            .or_else(|| heaviest_shadow(tree, Visibility::Filtered))
        {
            Some(shadow) => worded(
                format!(
                    "the reference is in the shadow of {} ({}); the student cast no shadow ray there, or ignored what it hit",
                    shadow.blocker, shadow.light
                ),
                "for each light, cast a shadow ray from the hit point towards the light and leave the light out when an object is hit before it (the course's -shadows)",
                shadow.location,
            ),
            None => worded(
                "the reference's shadow rays darken this point; the student's pixel is as if no shadow ray had been cast".into(),
                "cast a shadow ray towards each light and leave the light out when an object is hit before it (the course's -shadows)",
                seen_location,
            ),
        },
        Some(Behaviour::Shadows { mode }) if reference_shadows == ShadowMode::None => {
            // The reference casts none: the student's shadow rays are found by tracing the
            // pixel as the student's tracer would.
            let blocker = behaviours
                .variant(Behaviour::Shadows { mode })
                .and_then(|v| trace_pixel(&v.prepared, &v.scene, &v.options, tree.pixel[0], tree.pixel[1], SampleChoice::All).ok())
                .and_then(|t| heaviest_shadow(&t, Visibility::Blocked).or_else(|| heaviest_shadow(&t, Visibility::Filtered)));
            let what = blocker.as_ref().map_or_else(
                || "the student's pixel is darkened as if by shadow rays".to_string(),
                |b| format!("the student's tracer put {seen_text} in the shadow of {} ({})", b.blocker, b.light),
            );
            worded(
                format!("the reference casts no shadow rays (the command line asks for none); {what}"),
                "cast shadow rays only when asked (the course's -shadows): without it every light reaches every surface that faces it",
                blocker.and_then(|b| b.location).or(seen_location),
            )
        }
        Some(Behaviour::Shadows { mode: ShadowMode::Opaque }) => {
            let shadow = heaviest_shadow(tree, Visibility::Filtered);
            worded(
                format!(
                    "in the reference, {} reaches {seen_text} through {}, tinted by its transparent colour; the student's shadow ray stopped there",
                    shadow.as_ref().map_or("the light".to_string(), |s| s.light.clone()),
                    shadow.as_ref().map_or("a transparent object".to_string(), |s| s.blocker.clone()),
                ),
                "let shadow rays pass through transparent objects, multiplying the light by each one's transparent colour (the course's -transparent_shadows)",
                shadow.and_then(|s| s.location).or(seen_location),
            )
        }
        Some(Behaviour::Shadows { mode: _ }) => {
            let shadow = heaviest_shadow(tree, Visibility::Blocked);
            worded(
                format!(
                    "in the reference, {} blocks {} completely; the student's shadow ray let light through it",
                    shadow.as_ref().map_or("an object".to_string(), |s| s.blocker.clone()),
                    shadow.as_ref().map_or("the light".to_string(), |s| s.light.clone()),
                ),
                "stop a shadow ray at the first object it hits, transparent or not, unless transparent shadows are asked for (the course's -transparent_shadows)",
                shadow.and_then(|s| s.location).or(seen_location),
            )
        }
        Some(Behaviour::Depth { max_depth, lowest }) if max_depth < tree.max_depth => {
            let stopped = if lowest < max_depth {
                format!("at a depth from {lowest} to {max_depth} (they give this pixel the same colour)")
            } else {
                format!("at depth {max_depth}")
            };
            let cut = heaviest_at_depth(tree, max_depth + 1);
            let what = cut.as_ref().map_or_else(
                || format!("rays of depth {}", max_depth + 1),
                |c| format!("the {} ray leaving {}", c.kind, c.from),
            );
            worded(
                format!(
                    "the reference follows {what} (depth {}), which brings light; the student's tracer stopped recursing {stopped}",
                    max_depth + 1
                ),
                &format!(
                    "trace reflected and refracted rays recursively until depth {} (max_depth {}, the course's -bounces; the camera ray is depth 0)",
                    tree.max_depth, tree.max_depth
                ),
                cut.and_then(|c| c.location).or(seen_location),
            )
        }
        Some(Behaviour::Depth { max_depth, .. }) => worded(
            format!(
                "the student's pixel has light of rays deeper than the reference's limit of {} (it matches a trace to depth {max_depth})",
                tree.max_depth
            ),
            &format!(
                "stop spawning reflected and refracted rays past depth {} (max_depth {}, the course's -bounces; the camera ray is depth 0)",
                tree.max_depth, tree.max_depth
            ),
            seen_location,
        ),
        Some(Behaviour::NoAmbient) => worded(
            format!(
                "the reference has the ambient term (ambient light times diffuse colour) of {seen_text}; the student's pixel lacks it"
            ),
            "add the ambient light times the material's diffuse colour at every hit, lit or in shadow",
            seen_location,
        ),
        Some(Behaviour::NoSpecular) => {
            let highlight = heaviest_specular(tree);
            worded(
                format!(
                    "the reference has a specular highlight{}; the student's pixel has none",
                    highlight.as_ref().map_or(String::new(), |h| format!(" of {} on {}", h.light, h.blocker))
                ),
                &format!(
                    "add each light's specular term, specular colour times ({})^exponent, where the light reaches the point",
                    if tree.model.highlight == Highlight::Blinn { "N·H" } else { "R·V" }
                ),
                highlight.and_then(|h| h.location).or(seen_location),
            )
        }
        Some(Behaviour::Highlight { model }) => {
            let (theirs, ours) = match model {
                Highlight::Phong => ("Phong's (R·V)^n", "Blinn-Phong's (N·H)^n, H halfway between the light and the eye"),
                Highlight::Blinn => ("Blinn-Phong's (N·H)^n", "Phong's (R·V)^n, R the light mirrored about the normal"),
            };
            worded(
                format!("the highlight on {seen_text} differs: the student's matches {theirs}"),
                &format!("compute the specular term as {ours}"),
                seen_location,
            )
        }
        Some(Behaviour::ShadeBack { on: true }) => worded(
            format!("the reference leaves the back face of {seen_text} unlit (lights skip surfaces seen from behind); the student's tracer lit it"),
            "give no diffuse or specular light to a surface seen from behind, unless asked to (the course's -shade_back)",
            seen_location,
        ),
        Some(Behaviour::ShadeBack { on: false }) => worded(
            format!("the reference lights the back face of {seen_text} with its normal turned towards the eye; the student's tracer left it unlit"),
            "when shading back faces is asked for (the course's -shade_back), turn the normal towards the eye and light the surface",
            seen_location,
        ),
        Some(Behaviour::NoTotalInternalReflection) => {
            let inside = tir_object(tree);
            worded(
                format!(
                    "in the reference, the ray inside {} is totally internally reflected (past the critical angle) and brings light; the student's tracer lost that light",
                    inside.as_ref().map_or("a transparent object".to_string(), |(object, _)| object.clone())
                ),
                "when Snell's law has no refracted direction, reflect the ray instead (with the transmitted weight) rather than returning black",
                inside.map(|(_, l)| l).or(seen_location),
            )
        }
        Some(Behaviour::Missed) => worded(
            format!("the reference's camera ray hits {seen_text}; the student's pixel is the background colour: its ray missed"),
            "check the camera ray through this pixel and the intersection test of that object (and the nearest-hit bookkeeping)",
            seen_location,
        ),
        Some(Behaviour::HitWhereReferenceMisses) => worded(
            "the reference's camera ray leaves the scene here and shows the background colour; the student's pixel is not the background: its ray hit something, or its background colour differs".into(),
            "check the camera ray through this pixel, the intersection tests (a hit behind the eye, t below the minimum) and the background colour",
            None,
        ),
        None => Worded {
            message: "no single difference of tracer behaviour that whitted tries (shadows, depth, ambient, highlights, back faces, total internal reflection, a missed hit) explains it".into(),
            tracer: format!(
                "compare its terms with the reference's ray by ray: whitted trace SCENE --pixel {},{} with the same switches",
                tree.pixel[0], tree.pixel[1]
            ),
            location: seen_location,
        },
    }
}

/// A light's shadow ray at one hit, named for people.
struct Shadow {
    /// The blocker (or, for a highlight, the object lit).
    blocker: String,
    light: String,
    location: Option<String>,
}

/// The heaviest light whose visibility is `visibility`, with what its shadow ray met.
fn heaviest_shadow(tree: &RayTree, visibility: Visibility) -> Option<Shadow> {
    let mut best: Option<(f32, Shadow)> = None;
    walk(tree, &mut |node, _| {
        let Some(local) = &node.local else { return };
        for light in local.lights.iter().filter(|l| l.visibility == visibility) {
            let ray = light.shadow_child.and_then(|i| node.children.get(i));
            let blocker = ray
                .and_then(|r| r.shadow.as_ref())
                .and_then(|s| s.blocker.as_ref());
            let weight = weight_of(node);
            if best.as_ref().is_some_and(|(w, _)| *w >= weight) {
                continue;
            }
            let shadow = match blocker {
                Some(b) => Shadow {
                    blocker: format!("{} at {}", b.object.label, b.object.location),
                    light: light_name(&light.light.label),
                    location: Some(b.object.location.clone()),
                },
                None => Shadow {
                    blocker: "an object".into(),
                    light: light_name(&light.light.label),
                    location: Some(light.light.location.clone()),
                },
            };
            best = Some((weight, shadow));
        }
    });
    best.map(|(_, s)| s)
}

/// The heaviest specular term: the light and the object it lights.
fn heaviest_specular(tree: &RayTree) -> Option<Shadow> {
    let mut best: Option<(f32, Shadow)> = None;
    walk(tree, &mut |node, _| {
        let (Some(local), Some(hit)) = (&node.local, &node.hit) else {
            return;
        };
        for light in &local.lights {
            let strength = (0..3)
                .map(|c| light.specular[c] * node.weight[c])
                .fold(0.0f32, f32::max);
            if strength <= 0.0 || best.as_ref().is_some_and(|(w, _)| *w >= strength) {
                continue;
            }
            best = Some((
                strength,
                Shadow {
                    blocker: format!("{} at {}", hit.object.label, hit.object.location),
                    light: light_name(&light.light.label),
                    location: Some(hit.object.location.clone()),
                },
            ));
        }
    });
    best.map(|(_, s)| s)
}

/// A reflected or refracted ray, named by what it leaves.
struct Cut {
    kind: &'static str,
    from: String,
    location: Option<String>,
}

/// The heaviest reflected or transmitted ray at `depth`, with the surface it leaves.
fn heaviest_at_depth(tree: &RayTree, depth: u32) -> Option<Cut> {
    let mut best: Option<(f32, Cut)> = None;
    walk(tree, &mut |node: &RayNode, above: &[&RayNode]| {
        if node.depth != depth || !matches!(node.kind, RayKind::Reflected | RayKind::Transmitted) {
            return;
        }
        let weight = weight_of(node);
        let Some(parent) = above.last().and_then(|p| p.hit.as_ref()) else {
            return;
        };
        if best.as_ref().is_some_and(|(w, _)| *w >= weight) {
            return;
        }
        best = Some((
            weight,
            Cut {
                kind: if node.kind == RayKind::Reflected {
                    "reflected"
                } else {
                    "refracted"
                },
                from: format!("{} at {}", parent.object.label, parent.object.location),
                location: Some(parent.object.location.clone()),
            },
        ));
    });
    best.map(|(_, c)| c)
}

/// The object inside which the heaviest total internal reflection happens.
fn tir_object(tree: &RayTree) -> Option<(String, String)> {
    let mut best: Option<(f32, (String, String))> = None;
    walk(tree, &mut |node, above| {
        let tir = node.kind == RayKind::Reflected
            && node
                .interface
                .as_ref()
                .is_some_and(|i| i.total_internal_reflection);
        let Some(parent) = above.last().and_then(|p| p.hit.as_ref()) else {
            return;
        };
        let weight = weight_of(node);
        if tir && !best.as_ref().is_some_and(|(w, _)| *w >= weight) {
            best = Some((
                weight,
                (
                    format!("{} at {}", parent.object.label, parent.object.location),
                    parent.object.location.clone(),
                ),
            ));
        }
    });
    best.map(|(_, o)| o)
}

/// A light's label as a noun: `light #0` as it is, a named light `warm` as `light warm`.
fn light_name(label: &str) -> String {
    if label.starts_with("light") {
        label.to_string()
    } else {
        format!("light {label}")
    }
}
