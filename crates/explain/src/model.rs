//! What an explanation holds: the pixel, its main contributions and the findings, as plain
//! data that the text form and the JSON form (docs/explain.md) both print.

use serde::Serialize;
use whitted_tracer::RayKind;

/// Why pixel `pixel` has colour `color`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Explanation {
    pub pixel: [u32; 2],
    pub image_size: [u32; 2],
    /// The pixel's linear RGB exactly as `render` produced it.
    pub color: [f32; 3],
    pub samples_per_pixel: u32,
    pub max_depth: u32,
    pub min_weight: f32,
    /// Rays traced but not recorded (the ray tree's node budget); their light is one
    /// `unrecorded` contribution.
    pub unrecorded: u64,
    /// The main paths first, then one `other` line for the rest: they sum to `color`.
    pub contributions: Vec<Contribution>,
    /// Most significant first.
    pub findings: Vec<Finding>,
}

/// The light one path (or, for `other`, several) brings to the pixel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Contribution {
    pub term: Term,
    /// The light, for `diffuse` and `specular` terms.
    pub light: Option<String>,
    /// The rays from the eye to where the term arises (empty for `other` and
    /// `unrecorded`); repeated identical steps are one step with `repeat`.
    pub path: Vec<Step>,
    /// Linear RGB, already weighted by the path and divided by the samples: the pixel's
    /// colour is the sum of every contribution's.
    pub color: [f32; 3],
    /// `color`'s share of the pixel (its channel sum over the pixel's channel sum); `None`
    /// for a black pixel.
    pub share: Option<f32>,
    /// How many distinct recorded paths this line adds up (1 for a single path).
    pub paths: u32,
}

/// What a path's light is at its end.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Term {
    /// `ka·Ia·kd` at the last surface.
    Ambient,
    /// The last surface's own emission.
    Emission,
    /// A light's diffuse term at the last surface.
    Diffuse,
    /// A light's specular term at the last surface.
    Specular,
    /// The path left the scene: the background colour.
    Background,
    /// Every path not shown on a line of its own.
    Other,
    /// Light of rays traced but not recorded (the node budget).
    Unrecorded,
}

impl Term {
    pub fn name(self) -> &'static str {
        match self {
            Term::Ambient => "ambient",
            Term::Emission => "emission",
            Term::Diffuse => "diffuse",
            Term::Specular => "specular",
            Term::Background => "background",
            Term::Other => "other",
            Term::Unrecorded => "unrecorded",
        }
    }
}

/// One ray of a path: how it left the previous surface and what it hit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Step {
    /// `camera`, `reflected` or `transmitted`.
    pub ray: RayKind,
    /// Whether the ray was reflected by total internal reflection.
    pub tir: bool,
    /// The object hit (its name or kind and handle); `None` when the ray left the scene.
    pub object: Option<String>,
    /// `file:line:col` of that object.
    pub location: Option<String>,
    /// How many times this same step repeats in a row (1 usually; bounces inside a solid).
    pub repeat: u32,
    /// The object's instantiation stack, innermost first, each step as `i = 7 at
    /// file:line:col` (docs/ray-tree.md): which loop iteration, call or import made it.
    /// Left out of the JSON when empty (an object written at the top level of the root file).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub made_by: Vec<String>,
}

/// A likely cause of the pixel's colour, located in the scene, with a fix.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    pub kind: FindingKind,
    pub message: String,
    /// `file:line:col` of the object, light or setting concerned.
    pub location: String,
    pub fix: String,
    /// How much of the pixel the finding concerns (the largest channel of the path weight
    /// involved), for ordering; not in the JSON.
    #[serde(skip)]
    pub weight: f32,
    /// The text of the line at `location`, for people; not in the JSON (scripts have the
    /// location).
    #[serde(skip)]
    pub source_line: Option<String>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FindingKind {
    MaxDepth,
    WeightCutoff,
    RayBudget,
    LightBehind,
    OutsideSpotCone,
    ShadowBlocked,
    LightInsideSolid,
    SelfHit,
    CoincidentSurfaces,
    TirTrapped,
    Absorption,
    Background,
}

impl FindingKind {
    pub fn name(self) -> &'static str {
        match self {
            FindingKind::MaxDepth => "max_depth",
            FindingKind::WeightCutoff => "weight_cutoff",
            FindingKind::RayBudget => "ray_budget",
            FindingKind::LightBehind => "light_behind",
            FindingKind::OutsideSpotCone => "outside_spot_cone",
            FindingKind::ShadowBlocked => "shadow_blocked",
            FindingKind::LightInsideSolid => "light_inside_solid",
            FindingKind::SelfHit => "self_hit",
            FindingKind::CoincidentSurfaces => "coincident_surfaces",
            FindingKind::TirTrapped => "tir_trapped",
            FindingKind::Absorption => "absorption",
            FindingKind::Background => "background",
        }
    }
}
