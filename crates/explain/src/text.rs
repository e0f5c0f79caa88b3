//! The text form of an explanation: the pixel, one line per main contribution with its
//! share, then each finding with its location and fix.

use std::fmt::Write;

use crate::contributions::describe_path;
use crate::model::{Contribution, Explanation, Term};

fn rgb(c: [f32; 3]) -> String {
    format!("rgb({:.4}, {:.4}, {:.4})", c[0], c[1], c[2])
}

/// What a contribution's light is, in words: `diffuse from sun`, `background`, ...
pub fn describe_term(contribution: &Contribution) -> String {
    let light = contribution.light.as_deref().unwrap_or("a light");
    match contribution.term {
        Term::Ambient => "ambient".to_string(),
        Term::Emission => "emission".to_string(),
        Term::Diffuse => format!("diffuse from {light}"),
        Term::Specular => format!("specular from {light}"),
        Term::Background => "background".to_string(),
        Term::Other if contribution.paths == 1 => "1 other path".to_string(),
        Term::Other => format!("{} other paths", contribution.paths),
        Term::Unrecorded => "rays not recorded (the ray tree's node budget)".to_string(),
    }
}

/// The explanation for people.
pub fn format_text(explanation: &Explanation) -> String {
    let mut out = String::new();
    let [x, y] = explanation.pixel;
    let [w, h] = explanation.image_size;
    let _ = writeln!(
        out,
        "pixel ({x}, {y}) of {w}x{h}: {}",
        rgb(explanation.color)
    );
    let _ = writeln!(
        out,
        "{} sample{} per pixel, max depth {}, min weight {}",
        explanation.samples_per_pixel,
        if explanation.samples_per_pixel == 1 {
            ""
        } else {
            "s"
        },
        explanation.max_depth,
        explanation.min_weight
    );
    out.push('\n');
    if explanation.contributions.is_empty() {
        out.push_str("no recorded path brings any light to this pixel\n");
    } else {
        out.push_str("contributions (they sum to the pixel):\n");
        for c in &explanation.contributions {
            let share = c
                .share
                .map_or("     ".to_string(), |s| format!("{:5.1}%", s * 100.0));
            let path = describe_path(&c.path);
            let line = if path.is_empty() {
                describe_term(c)
            } else {
                format!("{path}: {}", describe_term(c))
            };
            let _ = writeln!(out, "  {share}  {}  {line}", rgb(c.color));
        }
    }
    push_made_by(&mut out, explanation);
    out.push('\n');
    if explanation.findings.is_empty() {
        out.push_str("no findings\n");
    } else {
        out.push_str("findings:\n");
        for f in &explanation.findings {
            let _ = writeln!(out, "  {} at {}", f.kind.name(), f.location);
            if let Some(line) = &f.source_line {
                let _ = writeln!(out, "    | {line}");
            }
            let _ = writeln!(out, "    {}", f.message);
            let _ = writeln!(out, "    fix: {}", f.fix);
        }
    }
    out
}

/// Where the objects on the lines above came from, when a loop, a call or an import made
/// them (`sphere #14` alone does not say which of a loop's spheres it is): each object once.
fn push_made_by(out: &mut String, explanation: &Explanation) {
    let mut seen: Vec<(&str, &str)> = Vec::new();
    for step in explanation.contributions.iter().flat_map(|c| &c.path) {
        let (Some(object), Some(location)) = (&step.object, &step.location) else {
            continue;
        };
        if step.made_by.is_empty() || seen.contains(&(object.as_str(), location.as_str())) {
            continue;
        }
        if seen.is_empty() {
            out.push_str("made by:\n");
        }
        seen.push((object, location));
        let _ = writeln!(out, "  {object}: {}", step.made_by.join(", "));
    }
}

/// A short form for lists of pixels (the image comparison): the main path with its share,
/// then each finding on one line with its location and fix.
pub fn format_summary(explanation: &Explanation) -> String {
    let mut out = String::new();
    if let Some(c) = explanation.contributions.first() {
        let share = c
            .share
            .map_or(String::new(), |s| format!("{:.0}% ", s * 100.0));
        let path = describe_path(&c.path);
        let line = if path.is_empty() {
            describe_term(c)
        } else {
            format!("{path}: {}", describe_term(c))
        };
        let _ = writeln!(out, "main light: {share}{line}");
    } else {
        out.push_str("main light: none (no recorded path brings light)\n");
    }
    for f in &explanation.findings {
        let _ = writeln!(out, "{} at {}: {}", f.kind.name(), f.location, f.message);
        let _ = writeln!(out, "  fix: {}", f.fix);
    }
    out
}
