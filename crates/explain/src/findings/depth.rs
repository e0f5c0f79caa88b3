//! Findings about where recursion stopped: the depth limit or the weight cut-off dropped a
//! path that matters (`max_depth`, `weight_cutoff`), light was trapped by total internal
//! reflection (`tir_trapped`), or the sample reached its ray budget (`ray_budget`). The
//! first two ask the tracer, through [`crate::probe`], which setting would bring the light
//! back and what the pixel would then be.

use whitted_tracer::ray_tree::RayNode;
use whitted_tracer::{RayKind, RenderOptions, Termination};

use super::{
    material_location, material_of, push_unique, rgb, walk, weight_of, Context, SIGNIFICANT,
};
use crate::locate::setting_or_scene;
use crate::model::{Finding, FindingKind};
use crate::probe::{color_with, depth_needed, largest, DepthSearch};

pub(super) fn find(context: &Context<'_>, findings: &mut Vec<Finding>) {
    max_depth(context, findings);
    weight_cutoff(context, findings);
    tir_trapped(context, findings);
    ray_budget(context, findings);
}

/// A sample that cast its whole budget of rays: recursion stopped wherever it was, however
/// much the rays left out weighed, so this is reported whatever their weight.
fn ray_budget(context: &Context<'_>, findings: &mut Vec<Finding>) {
    let scale = 1.0 / context.tree.samples_per_pixel.max(1) as f32;
    let mut total = [0.0f32; 3];
    let mut count = 0u32;
    walk(context.tree, &mut |node, _| {
        for skipped in node
            .skipped
            .iter()
            .filter(|s| s.reason == Termination::RayBudget)
        {
            count += 1;
            for (t, w) in total.iter_mut().zip(skipped.weight) {
                *t += w * scale;
            }
        }
    });
    if count == 0 {
        return;
    }
    let tree = context.tree;
    let (location, written) = setting_or_scene(context.scene, "min_weight");
    let message = format!(
        "the ray budget ({} reflected, transmitted and shadow rays per sample) stopped \
         recursion: {count} ray{} not traced, carrying a path weight of {:.2}% of the pixel; \
         with min_weight {} and max_depth {} a sample can take up to 2^{} rays",
        whitted_ir::limits::MAX_RAYS_PER_SAMPLE,
        if count == 1 { " was" } else { "s were" },
        largest(total) * 100.0,
        tree.min_weight,
        tree.max_depth,
        // 2 + 4 + ... + 2^max_depth reflected and transmitted rays.
        tree.max_depth + 1
    );
    let fix = format!(
        "raise min_weight so that weak paths end (0.001 is usual): {}; or lower max_depth",
        how_to_set("min_weight", "0.001", &location, written)
    );
    push_unique(
        findings,
        Finding {
            kind: FindingKind::RayBudget,
            message,
            location,
            fix,
            weight: largest(total),
            source_line: None,
        },
    );
}

fn is_tir(node: &RayNode) -> bool {
    node.interface
        .as_ref()
        .is_some_and(|i| i.total_internal_reflection)
}

/// How to set a setting, for fixes.
/// `location` is where the setting is written (`written`), which may be a `--set` flag's
/// pseudo-file (`<--set max_depth=4>`).
fn how_to_set(name: &str, value: &str, location: &str, written: bool) -> String {
    // A setting given on the command line is changed there: `<--max-depth 1>:1:1`.
    let flag = location
        .strip_prefix('<')
        .and_then(|rest| rest.split([' ', '>']).next())
        .filter(|flag| flag.starts_with("--"));
    if let Some(flag) = flag {
        match flag {
            "--set" => format!("run with --set {name}={value} instead"),
            _ => format!("run with {flag} {value} instead"),
        }
    } else if written {
        format!("set `{name} {value}` there (or run with --set {name}={value})")
    } else {
        // Not written: the default (or, for a 6.837 scene, the course's flag) applies, and
        // the way to change it that works for every front end is the flag.
        format!(
            "run with --set {name}={value} ({name} is not written in the scene, so its default \
             applies: a .scene file can add `{name} {value}` to its `settings` block, or write \
             `settings {{ {name} {value} }}`; `whitted mit6837` takes -bounces and -weight)"
        )
    }
}

fn max_depth(context: &Context<'_>, findings: &mut Vec<Finding>) {
    // The heaviest ray cut by the depth limit, with its surface and the TIR bounces above.
    let mut worst: Option<(f32, &RayNode, RayKind, usize)> = None;
    walk(context.tree, &mut |node, above| {
        for skipped in &node.skipped {
            let weight = largest(skipped.weight);
            if skipped.reason != Termination::MaxDepth || weight < SIGNIFICANT {
                continue;
            }
            if worst.as_ref().is_some_and(|w| w.0 >= weight) {
                continue;
            }
            let bounces = above.iter().filter(|n| is_tir(n)).count() + usize::from(is_tir(node));
            worst = Some((weight, node, skipped.kind, bounces));
        }
    });
    let Some((weight, node, kind, bounces)) = worst else {
        return;
    };
    let object = node.hit.as_ref().map_or("the scene".to_string(), |h| {
        format!("{} ({})", h.object.label, h.object.location)
    });
    let depth = context.tree.max_depth;
    let (location, written) = setting_or_scene(context.scene, "max_depth");
    let tir = match bounces {
        0 => String::new(),
        1 => " after 1 total internal reflection".to_string(),
        n => format!(" after {n} total internal reflections"),
    };
    let message = format!(
        "the depth limit (max_depth {depth}) cut the {} ray leaving {object}{tir}; it carried a \
         path weight of {:.1}% of the pixel",
        kind.name(),
        weight * 100.0
    );
    let [x, y] = context.tree.pixel;
    let fix = match depth_needed(context.prepared, context.options, x, y, SIGNIFICANT) {
        DepthSearch::Found { max_depth, color } => format!(
            "raise max_depth to {max_depth}: {}; the pixel then becomes {} (now {})",
            how_to_set("max_depth", &max_depth.to_string(), &location, written),
            rgb(color),
            rgb(context.tree.color)
        ),
        DepthSearch::NotFound { tried } => format!(
            "no max_depth up to {tried} lets this path end: the light is trapped (see \
             tir_trapped); raising max_depth will not help"
        ),
        DepthSearch::TooManyRays { max_depth } => format!(
            "raise max_depth, together with min_weight: by max_depth {max_depth} the search \
             for the depth that reaches the light had traced over {} rays",
            crate::probe::PROBE_RAY_BUDGET
        ),
    };
    push_unique(
        findings,
        Finding {
            kind: FindingKind::MaxDepth,
            message,
            location,
            fix,
            weight,
            source_line: None,
        },
    );
}

fn weight_cutoff(context: &Context<'_>, findings: &mut Vec<Finding>) {
    let scale = 1.0 / context.tree.samples_per_pixel.max(1) as f32;
    let mut total = [0.0f32; 3];
    let mut count = 0u32;
    let mut heaviest: Option<(f32, &RayNode, RayKind)> = None;
    walk(context.tree, &mut |node, _| {
        for skipped in &node.skipped {
            if skipped.reason != Termination::WeightCutoff {
                continue;
            }
            count += 1;
            for (t, w) in total.iter_mut().zip(skipped.weight) {
                *t += w * scale;
            }
            let weight = largest(skipped.weight);
            if heaviest.as_ref().is_none_or(|h| h.0 < weight) {
                heaviest = Some((weight, node, skipped.kind));
            }
        }
    });
    let weight = largest(total);
    let Some((_, node, kind)) = heaviest.filter(|_| weight >= SIGNIFICANT) else {
        return;
    };
    let min_weight = context.tree.min_weight;
    // Two digits, rounded down, so that the advice prints as written (`0.03`, never
    // `0.030000001`) and still lowers the cut-off tenfold.
    let value = crate::numbers::shortest_down((min_weight / 10.0).max(1e-6));
    let lower: f32 = value.parse().unwrap_or(1e-6);
    let (location, written) = setting_or_scene(context.scene, "min_weight");
    let object = node
        .hit
        .as_ref()
        .map_or("the scene".to_string(), |h| h.object.label.clone());
    let message = format!(
        "the weight cut-off (min_weight {}) dropped {count} ray{} that together carry \
         a path weight of {:.1}% of the pixel (the heaviest: a {} ray leaving {object})",
        crate::numbers::shortest(min_weight),
        if count == 1 { "" } else { "s" },
        weight * 100.0,
        kind.name()
    );
    let [x, y] = context.tree.pixel;
    let options = RenderOptions {
        min_weight: lower,
        ..context.options.clone()
    };
    let fix = match color_with(context.prepared, &options, x, y) {
        Some(color) => format!(
            "lower min_weight to {value}: {}; the pixel then becomes {} (now {})",
            how_to_set("min_weight", &value, &location, written),
            rgb(color),
            rgb(context.tree.color)
        ),
        None => format!(
            "lower min_weight to {value} ({}), and expect a slow pixel: it then takes over {} \
             rays",
            how_to_set("min_weight", &value, &location, written),
            crate::probe::PROBE_RAY_BUDGET
        ),
    };
    push_unique(
        findings,
        Finding {
            kind: FindingKind::WeightCutoff,
            message,
            location,
            fix,
            weight,
            source_line: None,
        },
    );
}

fn tir_trapped(context: &Context<'_>, findings: &mut Vec<Finding>) {
    let scene = context.scene;
    walk(context.tree, &mut |node, above| {
        let Some(hit) = &node.hit else {
            return;
        };
        // Without Fresnel, total internal reflection drops the transmitted share: light
        // that should have been mirrored inside the solid is lost (a black glass).
        for skipped in &node.skipped {
            let lost = largest(skipped.weight);
            if skipped.reason != Termination::TotalInternalReflection || lost < SIGNIFICANT {
                continue;
            }
            let Some((material, handle)) = material_of(scene, hit.leaf.handle) else {
                continue;
            };
            let name = scene.material_label(handle);
            let at = material_location(scene, handle);
            push_unique(
                findings,
                Finding {
                    kind: FindingKind::TirTrapped,
                    message: format!(
                        "total internal reflection inside {} ({}) with `fresnel off` drops the \
                         transmitted share: a path weight of {:.1}% of the pixel is lost there",
                        hit.object.label,
                        hit.object.location,
                        lost * 100.0
                    ),
                    location: at.clone(),
                    fix: if material.reflective.is_black() {
                        format!(
                            "set `fresnel exact` in material {name} ({at}), so that total \
                             internal reflection mirrors the light instead of dropping it"
                        )
                    } else {
                        format!(
                            "set `fresnel exact` in material {name} ({at}): only its \
                             `reflective` part is mirrored now"
                        )
                    },
                    weight: lost,
                    source_line: None,
                },
            );
        }
        // Bounce after bounce inside the same solid.
        if node.kind != RayKind::Reflected || !is_tir(node) {
            return;
        }
        let in_a_row = 1 + above.iter().rev().take_while(|n| is_tir(n)).count();
        let weight = weight_of(node);
        // Trapped means the light never got out: the chain was cut where it stands. A
        // chain that escapes (as it does through a glass's walls) is just a reflection.
        let cut = node.skipped.iter().find(|s| {
            matches!(s.reason, Termination::MaxDepth | Termination::WeightCutoff)
                && s.kind == RayKind::Reflected
        });
        let Some(cut) = cut.filter(|_| in_a_row >= 2 && weight >= SIGNIFICANT) else {
            return;
        };
        let critical = node
            .interface
            .as_ref()
            .and_then(|i| i.ior)
            .filter(|[from, to]| from > to)
            .map(|[from, to]| (to / from).asin().to_degrees());
        let critical = critical.map_or(String::new(), |c| {
            format!(" (the critical angle is {c:.1}°)")
        });
        let (name, at) = match material_of(scene, hit.leaf.handle) {
            Some((_, handle)) => (
                scene.material_label(handle),
                material_location(scene, handle),
            ),
            None => (hit.material.label.clone(), hit.material.location.clone()),
        };
        push_unique(
            findings,
            Finding {
                kind: FindingKind::TirTrapped,
                message: format!(
                    "light is trapped in {} by total internal reflection: {in_a_row} bounces in \
                     a row{critical}, carrying a path weight of {:.1}% of the pixel, until {} cut \
                     the path",
                    hit.object.label,
                    weight * 100.0,
                    cut.reason.name()
                ),
                location: hit.object.location.clone(),
                fix: format!(
                    "raise max_depth to follow the light until it leaves (see max_depth), or, \
                     to let it out sooner, tilt or round the faces of {} or lower the ior of \
                     material {name} ({at})",
                    hit.object.label
                ),
                weight,
                source_line: None,
            },
        );
    });
}
