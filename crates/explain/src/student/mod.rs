//! A student's pixel read against the reference's, as a teacher reads it: which behaviour of
//! a ray tracer, different from the reference's, gives the student's colour, said in terms
//! of what the student's tracer must do, never of what to change in the scene.
//!
//! The reference pixel's ray tree is recorded once; each candidate behaviour
//! ([`Behaviour`]) then gives the colour the pixel would have under it, either by tracing
//! the pixel again through the one code path with the scene's settings changed
//! (`variants.rs`: shadow rays, recursion depth, ambient term, highlight model, back faces)
//! or by leaving terms out of the recorded tree (`variants.rs`: no specular term, light lost
//! at total internal reflection, a camera ray that missed). The behaviour whose colour comes
//! closest to the student's, when it comes much closer than the reference does, is the
//! reading; `wording.rs` says it with the objects and lines of the reference tree.

mod variants;
mod wording;

pub use variants::Behaviours;

use serde::Serialize;
use whitted_ir::Scene;
use whitted_tracer::ray_tree::RayTree;
use whitted_tracer::{PreparedScene, RenderOptions};

/// A behaviour of the student's tracer that differs from the reference's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Behaviour {
    /// Shadow rays as this mode casts them (`none`: no shadow rays at all).
    Shadows { mode: whitted_ir::ShadowMode },
    /// Reflected and refracted rays followed to `max_depth` (the camera ray is depth 0);
    /// every depth from `lowest` to `max_depth` gives the pixel the same colour.
    Depth { max_depth: u32, lowest: u32 },
    /// No ambient term.
    NoAmbient,
    /// Highlights by this model.
    Highlight { model: whitted_ir::Highlight },
    /// Back faces lit (`true`) or left unlit.
    ShadeBack { on: bool },
    /// No specular term at all.
    NoSpecular,
    /// The light of totally internally reflected rays lost.
    NoTotalInternalReflection,
    /// The camera ray missed what the reference's hits: the background colour.
    Missed,
    /// The camera ray hit something where the reference's leaves the scene.
    HitWhereReferenceMisses,
}

/// Which way the student's pixel differs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    Brighter,
    Darker,
    /// Neither clearly: another hue at about the same brightness.
    Different,
}

impl Direction {
    pub fn word(self) -> &'static str {
        match self {
            Direction::Brighter => "student brighter",
            Direction::Darker => "student darker",
            Direction::Different => "student differs",
        }
    }
}

/// How a student's pixel reads against the reference's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StudentReading {
    pub direction: Direction,
    /// The behaviour that explains the student's colour; `None` when none of those tried
    /// comes close.
    pub behaviour: Option<Behaviour>,
    /// What the reference pixel has that the student's lacks, or the other way round.
    pub message: String,
    /// What the student's tracer must do to match the reference.
    pub tracer: String,
    /// `file:line:col` of the object or light concerned, when there is one.
    pub location: Option<String>,
    /// The reference pixel's colour under `behaviour`, in the compared 8-bit space, and how
    /// far the student's still is from it (largest channel, 8-bit steps).
    pub behaviour_color: Option<[u8; 3]>,
    pub remaining_difference: Option<u8>,
}

/// The reference side of a comparison: the scene as the reference renders it.
#[derive(Clone, Copy)]
pub struct Reference<'a> {
    pub prepared: &'a PreparedScene,
    pub scene: &'a Scene,
    pub options: &'a RenderOptions,
}

/// The student's pixel (8-bit, in the space the comparison is made in) against the
/// reference's recorded ray tree `tree` (every sample). `encode` turns a linear colour into
/// that space's 8 bits, the way the reference image was encoded for the comparison.
pub fn read_student_pixel(
    reference: Reference<'_>,
    behaviours: &Behaviours,
    tree: &RayTree,
    student: [u8; 3],
    encode: &dyn Fn([f32; 3]) -> [u8; 3],
) -> StudentReading {
    let ours = encode(tree.color);
    let direction = direction(ours, student);
    let now = difference(ours, student);
    let candidates = behaviours.colors(reference, tree);
    let best = candidates
        .iter()
        .map(|(behaviour, color)| {
            let bytes = encode(*color);
            (*behaviour, bytes, difference(bytes, student))
        })
        // The first among equals: the list is in order of how common the mistake is.
        .fold(None::<(Behaviour, [u8; 3], u8)>, |best, c| match best {
            Some(b) if b.2 <= c.2 => Some(b),
            _ => Some(c),
        });
    // A behaviour explains the pixel when it takes away most of the difference: half is
    // not enough (two mistakes at once would each look half right).
    let mut explains = best.filter(|(_, _, left)| u32::from(*left) * 3 <= u32::from(now));
    // Depths that give this pixel the same colour cannot be told apart here: say all.
    if let Some((Behaviour::Depth { max_depth, lowest }, bytes, _)) = &mut explains {
        for (behaviour, color) in &candidates {
            if let Behaviour::Depth { max_depth: d, .. } = behaviour {
                if *d < *lowest && *d < *max_depth && encode(*color) == *bytes {
                    *lowest = *d;
                }
            }
        }
    }
    // Where the reference's camera rays all leave the scene, a student's pixel that is not
    // the background hit something: no traced behaviour gives that colour.
    let missing = explains.is_none() && tree.samples.iter().all(|s| s.root.hit.is_none());
    let behaviour = explains
        .map(|b| b.0)
        .or(missing.then_some(Behaviour::HitWhereReferenceMisses));
    let worded = wording::word(behaviours, tree, behaviour);
    StudentReading {
        direction,
        behaviour,
        message: format!("{}: {}", direction.word(), worded.message),
        tracer: worded.tracer,
        location: worded.location,
        behaviour_color: explains.map(|b| b.1),
        remaining_difference: explains.map(|b| b.2),
    }
}

/// The largest channel difference.
fn difference(a: [u8; 3], b: [u8; 3]) -> u8 {
    (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0)
}

fn direction(reference: [u8; 3], student: [u8; 3]) -> Direction {
    let sum = |c: [u8; 3]| c.iter().map(|&v| i32::from(v)).sum::<i32>();
    let delta = sum(student) - sum(reference);
    // A few steps over three channels is rounding, not a brighter pixel.
    match delta {
        d if d > 3 => Direction::Brighter,
        d if d < -3 => Direction::Darker,
        _ => Direction::Different,
    }
}

#[cfg(test)]
mod tests;
