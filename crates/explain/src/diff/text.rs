//! The readable form of a ray-tree diff: the two colours, the settings that differ, the
//! first divergence in full (both values, both scene lines, what it changes in the pixel)
//! and the other divergences one line each.

use std::fmt::Write;

use whitted_tracer::RayKind;

use super::{Divergence, TreeDiff};

/// At most this many further divergences are listed (a raised `max_depth` adds one per
/// ray that was cut).
pub const MAX_LISTED: usize = 12;

fn rgb(c: [f32; 3]) -> String {
    format!("rgb({:.4}, {:.4}, {:.4})", c[0], c[1], c[2])
}

fn route(d: &Divergence) -> String {
    let names: Vec<&str> = d.route.iter().map(|k: &RayKind| k.name()).collect();
    format!(
        "sample {}, {} (depth {})",
        d.sample,
        names.join(" > "),
        d.depth
    )
}

fn change(d: &Divergence) -> String {
    let [a, b] = d.contribution;
    format!(
        "these rays give the pixel {} in A and {} in B (change {})",
        rgb(a),
        rgb(b),
        rgb(std::array::from_fn(|i| b[i] - a[i]))
    )
}

/// `A` and `B` name the two sides in the text (file names, or `--set` settings).
pub fn format_text(diff: &TreeDiff, name_a: &str, name_b: &str) -> String {
    let mut out = String::new();
    let [x, y] = diff.pixel;
    let [ca, cb] = diff.color;
    let _ = writeln!(out, "pixel ({x}, {y})");
    let _ = writeln!(out, "  A {name_a}: {} ({} rays)", rgb(ca), diff.rays[0]);
    let _ = writeln!(out, "  B {name_b}: {} ({} rays)", rgb(cb), diff.rays[1]);
    let _ = writeln!(
        out,
        "  change: {}",
        rgb(std::array::from_fn(|i| cb[i] - ca[i]))
    );
    if !diff.settings.is_empty() {
        let _ = writeln!(out, "\nsettings that differ:");
        for [name, a, b] in &diff.settings {
            let _ = writeln!(out, "  {name}: {a} in A, {b} in B");
        }
    }
    let Some(first) = diff.divergences.first() else {
        let _ = writeln!(out, "\nthe two ray trees are the same, ray by ray");
        return out;
    };
    let _ = writeln!(out, "\nfirst divergence: {}", route(first));
    let _ = writeln!(
        out,
        "  {}: {} in A, {} in B",
        first.what, first.values[0], first.values[1]
    );
    for (side, label) in [(0, "A"), (1, "B")] {
        if let Some(location) = &first.location[side] {
            let _ = writeln!(out, "  {label} at {location}");
            if let Some(line) = &first.source_line[side] {
                let _ = writeln!(out, "    | {line}");
            }
        }
    }
    let _ = writeln!(out, "  {}", change(first));
    let rest = &diff.divergences[1..];
    if !rest.is_empty() {
        let _ = writeln!(
            out,
            "\nthen {} more divergence{}:",
            rest.len(),
            if rest.len() == 1 { "" } else { "s" }
        );
        for d in rest.iter().take(MAX_LISTED) {
            let [a, b] = d.contribution;
            let delta: [f32; 3] = std::array::from_fn(|i| b[i] - a[i]);
            let _ = writeln!(
                out,
                "  {}: {}: {} in A, {} in B; change {}",
                route(d),
                d.what,
                d.values[0],
                d.values[1],
                rgb(delta)
            );
        }
        if rest.len() > MAX_LISTED {
            let _ = writeln!(
                out,
                "  ... and {} more (--json lists every one)",
                rest.len() - MAX_LISTED
            );
        }
    }
    out
}
