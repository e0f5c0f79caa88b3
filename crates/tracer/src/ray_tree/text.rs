//! The readable form of a ray tree (`whitted trace` without `--json`): an indented tree, one
//! header line per ray and a few detail lines under it, numbers rounded for reading.

use std::fmt::Write;

use super::model::{
    HitInfo, InterfaceInfo, LightContribution, LightRef, ObjectRef, RayNode, RayTree, ShadowInfo,
    ShadowOutcome, Visibility,
};
use crate::recorder::{RayKind, Termination};
use whitted_ir::{Highlight, ShadowMode};

/// How to print a tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TextOptions {
    /// Put a coloured swatch (ANSI truecolor background) before every colour. Only for
    /// terminals that asked for colour.
    pub swatches: bool,
}

/// The whole tree as text, ending with a newline.
pub fn format_text(tree: &RayTree, options: TextOptions) -> String {
    let printer = Printer { options };
    let mut out = String::new();
    let [x, y] = tree.pixel;
    let [width, height] = tree.image_size;
    let _ = writeln!(
        out,
        "pixel ({x}, {y}) of {width}x{height}: {}",
        printer.color(tree.color)
    );
    let _ = writeln!(
        out,
        "{} per pixel, max depth {}, min weight {}",
        plural(tree.samples_per_pixel, "sample"),
        tree.max_depth,
        num(tree.min_weight)
    );
    // Only the switches that leave the classic model are named, so that a tree traced with
    // the defaults reads as it always did.
    let model = &tree.model;
    let mut switches = Vec::new();
    match model.shadows {
        ShadowMode::Opaque => {}
        ShadowMode::Filtered => switches.push("filtered shadows"),
        ShadowMode::None => switches.push("no shadow rays (shadows none)"),
    }
    if model.highlight == Highlight::Blinn {
        switches.push("Blinn-Phong highlights");
    }
    if !model.shade_back {
        switches.push("back faces unlit (shade_back off)");
    }
    if !model.attenuation_clamp {
        switches.push("attenuation not clamped at 1");
    }
    if !model.energy_clamp {
        switches.push("reflective + transmissive as given (energy_clamp off)");
    }
    if !switches.is_empty() {
        let _ = writeln!(out, "model: {}", switches.join(", "));
    }
    if tree.unrecorded > 0 {
        let _ = writeln!(
            out,
            "cut at the ray-tree budget of {} nodes: {} not recorded (traced, and in the \
             colours); look for `not recorded` below",
            tree.node_budget,
            plural_u64(tree.unrecorded, "more ray"),
        );
    }
    for sample in &tree.samples {
        out.push('\n');
        let _ = writeln!(
            out,
            "sample {} of {}: {}",
            sample.index,
            tree.samples_per_pixel,
            printer.color(sample.color)
        );
        printer.node(&mut out, &sample.root, "", None);
    }
    out
}

struct Printer {
    options: TextOptions,
}

impl Printer {
    /// Prints `node` and its subtree. `prefix` is the indentation of the node's own line;
    /// `last` is `None` for the root, otherwise whether it is its parent's last child.
    fn node(&self, out: &mut String, node: &RayNode, prefix: &str, last: Option<bool>) {
        let (connector, below) = match last {
            None => ("", prefix.to_string()),
            Some(false) => ("├─ ", format!("{prefix}│  ")),
            Some(true) => ("└─ ", format!("{prefix}   ")),
        };
        let _ = writeln!(out, "{prefix}{connector}{}", self.header(node));
        let detail_prefix = if node.children.is_empty() {
            format!("{below}  ")
        } else {
            format!("{below}│ ")
        };
        for line in self.details(node) {
            let _ = writeln!(out, "{detail_prefix}{line}");
        }
        let count = node.children.len();
        for (i, child) in node.children.iter().enumerate() {
            self.node(out, child, &below, Some(i + 1 == count));
        }
    }

    fn header(&self, node: &RayNode) -> String {
        let kind = node.kind.name();
        if let Some(shadow) = &node.shadow {
            return format!(
                "{kind} to {}: {}",
                printable(&shadow.light.label),
                self.shadow_outcome(shadow)
            );
        }
        let target = match &node.hit {
            Some(hit) => format!("hit {} at t {}", printable(&hit.object.label), num(hit.t)),
            None => "miss".to_string(),
        };
        format!(
            "{kind} depth {}: {target} -> {} ({})",
            node.depth,
            self.color(node.color),
            termination_text(node.termination)
        )
    }

    fn details(&self, node: &RayNode) -> Vec<String> {
        let mut lines = vec![format!(
            "ray        origin {} direction {}",
            vector(node.origin),
            vector(node.direction)
        )];
        if node.kind == RayKind::Shadow {
            if let Some(shadow) = &node.shadow {
                lines.extend(shadow_details(shadow));
            }
            return lines;
        }
        if node.kind != RayKind::Camera {
            lines.push(format!(
                "weight     {} (coefficient {})",
                self.color(node.weight),
                self.color(node.coefficient)
            ));
        }
        if let Some(interface) = &node.interface {
            lines.push(format!("interface  {}", interface_text(interface)));
        }
        if let Some(hit) = &node.hit {
            lines.extend(self.hit_details(hit));
        }
        if let Some(local) = &node.local {
            lines.push(format!("ambient    {}", self.color(local.ambient)));
            if local.emission != [0.0; 3] {
                lines.push(format!("emission   {}", self.color(local.emission)));
            }
            for light in &local.lights {
                lines.push(self.light_line(light));
            }
            lines.push(format!("local      {}", self.color(local.total)));
        }
        if node.unrecorded > 0 {
            lines.push(format!(
                "not recorded {} below this ray (the tree's node budget was reached)",
                plural_u64(node.unrecorded, "ray")
            ));
        }
        for skipped in &node.skipped {
            // A transmission lost to total internal reflection: dropped (no Fresnel), or
            // went to the reflected ray.
            let weight = match skipped.reason {
                Termination::TotalInternalReflection if skipped.coefficient == [0.0; 3] => {
                    " (Fresnel R = 1: the transmission went to the reflected ray)".to_string()
                }
                Termination::TotalInternalReflection => {
                    format!(" (weight {} dropped)", self.color(skipped.weight))
                }
                Termination::RayBudget => format!(
                    " (the sample had cast its {} rays; weight {})",
                    whitted_ir::limits::MAX_RAYS_PER_SAMPLE,
                    self.color(skipped.weight)
                ),
                _ => format!(" (weight {})", self.color(skipped.weight)),
            };
            lines.push(format!(
                "skipped    {} ray at depth {}: {}{weight}",
                skipped.kind.name(),
                skipped.depth,
                termination_text(skipped.reason),
            ));
        }
        lines
    }

    fn hit_details(&self, hit: &HitInfo) -> Vec<String> {
        let mut lines = vec![
            format!(
                "point      {} ({} face)",
                vector(hit.point),
                if hit.front_face { "front" } else { "back" }
            ),
            format!(
                "normal     {} (shading {})",
                vector(hit.geometric_normal),
                vector(hit.shading_normal)
            ),
            format!("object     {}", object_text(&hit.object)),
        ];
        push_made_by(&mut lines, &hit.object);
        if hit.leaf.handle != hit.object.handle {
            let path: Vec<String> = hit.csg_path.iter().map(|o| printable(&o.label)).collect();
            lines.push(format!(
                "leaf       {} via {}",
                object_text(&hit.leaf),
                path.join(" > ")
            ));
            push_made_by(&mut lines, &hit.leaf);
        }
        let material = &hit.material;
        if hit.resolved_material.handle == material.handle {
            lines.push(printable(&format!(
                "material   {} ({})",
                material.label, material.location
            )));
        } else {
            lines.push(printable(&format!(
                "material   {} ({}), here {} ({})",
                material.label,
                material.location,
                hit.resolved_material.label,
                hit.resolved_material.location
            )));
        }
        if let Some(blend) = &hit.blend {
            lines.push(printable(&format!(
                "blend      {}·{} ({}) + {}·{} ({})",
                num(1.0 - blend.weight),
                blend.first.label,
                blend.first.location,
                num(blend.weight),
                blend.second.label,
                blend.second.location
            )));
        }
        if hit.absorption != [1.0; 3] {
            lines.push(format!("absorption {}", self.color(hit.absorption)));
        }
        for other in &hit.coincident {
            lines.push(printable(&format!(
                "coincident {} ({}, {}) at t {}: the same place, within the error bound {:.1e}",
                other.object.label,
                other.object.kind,
                other.object.location,
                num(other.t),
                hit.error_bound
            )));
        }
        lines
    }

    fn light_line(&self, light: &LightContribution) -> String {
        let shadow = match (light.visibility, light.shadow_child) {
            (Visibility::FacingAway, _) => {
                "no shadow ray (faces away: N.L <= 0): unlit".to_string()
            }
            (Visibility::OutsideCone, _) => match &light.cone {
                Some(cone) => format!(
                    "no shadow ray (outside the spot cone: {}° from its axis, cone {}°): unlit",
                    num(cone.angle_degrees),
                    num(cone.outer_degrees)
                ),
                None => "no shadow ray (outside the spot cone): unlit".to_string(),
            },
            (Visibility::BlackLight, _) => "no shadow ray (the light is black): unlit".to_string(),
            (Visibility::TooFaint, _) => {
                "no shadow ray (fatt times spot rounds to 0): unlit".to_string()
            }
            (Visibility::Unshaded, _) => {
                "no shadow ray (no diffuse or specular colour to light)".to_string()
            }
            (Visibility::NoShadows, _) => "no shadow ray (shadows none): lit".to_string(),
            (Visibility::BackFace, _) => {
                "no shadow ray (seen from its back, shade_back off): unlit".to_string()
            }
            (visibility, Some(index)) => {
                format!("shadow ray {index}: {}", visibility_text(visibility))
            }
            (visibility, None) => visibility_text(visibility).to_string(),
        };
        format!(
            "{}: N.L {} fatt {} spot {} diffuse {} specular {}, {shadow}",
            light_text(&light.light),
            num(light.n_dot_l),
            num(light.attenuation),
            num(light.spot),
            self.color(light.diffuse),
            self.color(light.specular),
        )
    }

    fn shadow_outcome(&self, shadow: &ShadowInfo) -> String {
        match (shadow.result, &shadow.blocker) {
            (ShadowOutcome::Blocked, Some(blocker)) => {
                format!(
                    "blocked by {} at t {}",
                    printable(&blocker.object.label),
                    num(blocker.t)
                )
            }
            (ShadowOutcome::Blocked, None) => "blocked".to_string(),
            (ShadowOutcome::Unblocked, _) => "unblocked".to_string(),
            (ShadowOutcome::Filtered, _) => {
                let through = shadow.filters.map_or(String::new(), |n| {
                    format!(" through {}", plural(n, "transmissive surface"))
                });
                let transmittance = shadow.transmittance.map_or(String::new(), |t| {
                    format!(", transmittance {}", self.color(t))
                });
                format!("filtered{through}{transmittance}")
            }
        }
    }

    fn color(&self, c: [f32; 3]) -> String {
        let numbers = format!("rgb({}, {}, {})", num(c[0]), num(c[1]), num(c[2]));
        if self.options.swatches {
            let [r, g, b] = c.map(crate::display::linear_to_srgb8);
            format!("\x1b[48;2;{r};{g};{b}m  \x1b[0m {numbers}")
        } else {
            numbers
        }
    }
}

fn shadow_details(shadow: &ShadowInfo) -> Vec<String> {
    let mut lines = vec![match shadow.max_t {
        Some(t) => format!(
            "light      {} at distance {}",
            printable(&shadow.light.label),
            num(t)
        ),
        None => format!(
            "light      {} (directional)",
            printable(&shadow.light.label)
        ),
    }];
    if let Some(blocker) = &shadow.blocker {
        lines.push(format!("blocker    {}", object_text(&blocker.object)));
        if blocker.leaf.handle != blocker.object.handle {
            lines.push(format!("leaf       {}", object_text(&blocker.leaf)));
        }
    }
    lines
}

fn interface_text(interface: &InterfaceInfo) -> String {
    // Which side was hit shows on the parent's hit (front or back face), and the ior pair
    // says which way light crosses; `entering` is in the JSON.
    let mut text = format!("incidence {}°", num(interface.incidence_degrees));
    if let Some([from, to]) = interface.ior {
        let _ = write!(text, ", ior {} -> {}", num(from), num(to));
    }
    if let (Some(r), Some(t)) = (
        interface.fresnel_reflectance,
        interface.fresnel_transmittance,
    ) {
        // Schlick's is the common case and keeps the short form.
        let model = match interface.fresnel {
            whitted_ir::Fresnel::Exact => "exact ",
            _ => "",
        };
        let _ = write!(text, ", {model}Fresnel R {} T {}", num(r), num(t));
    }
    if interface.total_internal_reflection {
        text.push_str(", total internal reflection");
    }
    text
}

/// The `made by` line of an object made inside a loop, call or import: its instantiation
/// stack, innermost first. Objects written at the top level of the root file have none.
fn push_made_by(lines: &mut Vec<String>, object: &ObjectRef) {
    if object.made_by.is_empty() {
        return;
    }
    let steps: Vec<String> = object
        .made_by
        .iter()
        .map(|step| format!("{} at {}", step.text, step.location))
        .collect();
    lines.push(printable(&format!("made by    {}", steps.join(", "))));
}

fn object_text(object: &ObjectRef) -> String {
    printable(&match &object.name {
        Some(name) => format!(
            "{name} ({} #{}, {})",
            object.kind, object.handle, object.location
        ),
        None => format!("{} ({})", object.label, object.location),
    })
}

/// `light sun`, or `light #0` for an unnamed light.
fn light_text(light: &LightRef) -> String {
    printable(&match &light.name {
        Some(name) => format!("light {name}"),
        None => light.label.clone(),
    })
}

/// Names (and file names) come from the scene: their control characters are escaped
/// (`\u{1b}`) so that an ESC in a name cannot send commands to the user's terminal.
fn printable(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

fn visibility_text(visibility: Visibility) -> &'static str {
    match visibility {
        Visibility::Lit => "lit",
        Visibility::Filtered => "filtered",
        Visibility::Blocked => "blocked",
        Visibility::FacingAway => "faces away",
        Visibility::OutsideCone => "outside the spot cone",
        Visibility::BlackLight => "black light",
        Visibility::TooFaint => "too faint",
        Visibility::Unshaded => "unshaded",
        Visibility::NoShadows => "no shadows",
        Visibility::BackFace => "back face",
    }
}

fn termination_text(termination: Termination) -> &'static str {
    match termination {
        Termination::NotEnded => "not ended",
        Termination::Miss => "miss",
        Termination::MaxDepth => "max depth",
        Termination::WeightCutoff => "weight cut-off",
        Termination::TotalInternalReflection => "total internal reflection",
        Termination::Absorbed => "absorbed",
        Termination::RayBudget => "ray budget",
    }
}

fn plural(n: u32, noun: &str) -> String {
    plural_u64(u64::from(n), noun)
}

fn plural_u64(n: u64, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// At most four decimals, trailing zeros dropped, and no `-0`.
fn num(value: f32) -> String {
    if !value.is_finite() {
        return value.to_string();
    }
    let text = format!("{value:.4}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    if text == "-0" {
        "0".to_string()
    } else {
        text.to_string()
    }
}

fn vector(v: [f32; 3]) -> String {
    format!("({}, {}, {})", num(v[0]), num(v[1]), num(v[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short_and_never_negative_zero() {
        assert_eq!(num(1.0), "1");
        assert_eq!(num(0.5), "0.5");
        assert_eq!(num(-0.00001), "0");
        assert_eq!(num(2.123_456), "2.1235");
        assert_eq!(num(-3.25), "-3.25");
        assert_eq!(num(f32::INFINITY), "inf");
    }

    #[test]
    fn swatches_are_ansi_truecolor_backgrounds() {
        let printer = Printer {
            options: TextOptions { swatches: true },
        };
        assert_eq!(
            printer.color([1.0, 0.0, 0.5]),
            "\x1b[48;2;255;0;188m  \x1b[0m rgb(1, 0, 0.5)"
        );
        let plain = Printer {
            options: TextOptions::default(),
        };
        assert_eq!(plain.color([0.5, 0.25, 0.0]), "rgb(0.5, 0.25, 0)");
    }
}
