//! The recorder: hooks through which the one tracing code path reports every ray it traces.
//!
//! Rendering uses [`NoRecord`], whose empty methods inline away, so the renderer pays
//! nothing. Ray trees (`whitted trace`, the debugger) and per-pixel statistics implement the
//! same trait and see exactly the rays the renderer traced: there is no second tracer.
//!
//! # Order of calls for one ray
//!
//! ```text
//! ray_started
//! ├─ ray_missed                                  (then ray_finished with Miss)
//! └─ surface_hit
//!    ambient
//!    emission
//!    light_sampled           × every light, in scene order (with its shadow ray, if any)
//!    reflected ray:   ray_started … ray_finished (nested), or secondary_skipped
//!    transmitted ray: ray_started … ray_finished (nested), or secondary_skipped
//! ray_finished
//! ```
//!
//! A secondary ray that the material does not ask for (a zero coefficient) is neither
//! started nor skipped.
//!
//! The colour a ray returns is computed in exactly this order (f32, per channel), so a
//! recorder can re-add the parts bit for bit:
//! `c = ambient + emission; c += diffuse + specular` for each light in order; `c += coefficient ×
//! returned colour` for the reflected, then the transmitted ray; finally `c × absorption`
//! (the [`SurfaceHit::absorption`] factor). A miss returns the background times the
//! medium's transmittance over an infinite distance. Colours are linear RGB; "weight" is always the path weight: the
//! product of every coefficient (and Beer-Lambert factor) from the eye up to and including
//! this ray's own coefficient, i.e. how much this ray's returned colour counts in the pixel.

use glam::Vec3A;
use serde::Serialize;
use whitted_ir::{Fresnel, Handle, Light, Material, Object};

/// What a ray is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RayKind {
    Camera,
    Reflected,
    Transmitted,
    Shadow,
}

impl RayKind {
    pub fn name(self) -> &'static str {
        match self {
            RayKind::Camera => "camera",
            RayKind::Reflected => "reflected",
            RayKind::Transmitted => "transmitted",
            RayKind::Shadow => "shadow",
        }
    }
}

/// Why recursion stopped at a ray (or why a secondary ray was not traced).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// The ray spawned at least one secondary ray.
    NotEnded,
    /// The ray left the scene: it returns the background colour.
    Miss,
    /// A secondary ray would have been deeper than the maximum depth.
    MaxDepth,
    /// A secondary ray's path weight was below the minimum on every channel.
    WeightCutoff,
    /// Refraction was impossible. Without Fresnel the transmitted term is dropped; with
    /// Fresnel (R = 1) it went to the reflected ray.
    TotalInternalReflection,
    /// The surface neither reflects nor transmits: only its local colour returns.
    Absorbed,
    /// The sample had already cast its budget of rays
    /// ([`whitted_ir::limits::MAX_RAYS_PER_SAMPLE`]): the secondary ray was not traced and
    /// the colour gathered so far is kept.
    RayBudget,
}

impl Termination {
    pub const ALL: [Termination; 7] = [
        Termination::NotEnded,
        Termination::Miss,
        Termination::MaxDepth,
        Termination::WeightCutoff,
        Termination::TotalInternalReflection,
        Termination::Absorbed,
        Termination::RayBudget,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Termination::NotEnded => "not_ended",
            Termination::Miss => "miss",
            Termination::MaxDepth => "max_depth",
            Termination::WeightCutoff => "weight_cutoff",
            Termination::TotalInternalReflection => "total_internal_reflection",
            Termination::Absorbed => "absorbed",
            Termination::RayBudget => "ray_budget",
        }
    }

    fn bit(self) -> u8 {
        1 << (self as u8)
    }
}

/// A small set of terminations (a bit mask).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
pub struct TerminationSet(u8);

impl TerminationSet {
    pub fn insert(&mut self, termination: Termination) {
        self.0 |= termination.bit();
    }

    pub fn contains(self, termination: Termination) -> bool {
        self.0 & termination.bit() != 0
    }

    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    pub fn iter(self) -> impl Iterator<Item = Termination> {
        Termination::ALL
            .into_iter()
            .filter(move |t| self.contains(*t))
    }

    pub fn bits(self) -> u8 {
        self.0
    }
}

/// The optics at the surface a reflected or transmitted ray leaves from.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Interface {
    /// Cosine of the angle between the incoming ray and the shading normal (1 = head on).
    pub cos_incidence: f32,
    /// The refractive indices (from, to) when the material transmits: the medium the ray
    /// leaves and the one beyond (nested media; air is 1.0). Thin surfaces (disks,
    /// triangles, open cylinders and cones) have the current medium on both sides.
    pub ior: Option<(f32, f32)>,
    /// Whether the incoming ray was entering a solid (it hit the outside of a solid's
    /// surface; always false on thin surfaces).
    pub entering: bool,
    /// The material's Fresnel model.
    pub fresnel: Fresnel,
    /// The Fresnel reflectance `R` (Schlick's or the exact one) when the material asks for
    /// Fresnel (transmission is `1 − R`; `R` is 1 on total internal reflection).
    pub fresnel_reflectance: Option<f32>,
    pub total_internal_reflection: bool,
}

impl Interface {
    pub fn incidence_degrees(&self) -> f32 {
        self.cos_incidence.clamp(-1.0, 1.0).acos().to_degrees()
    }
}

/// A camera, reflected or transmitted ray about to be traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayStart {
    pub kind: RayKind,
    /// 0 for camera rays; a secondary ray is one deeper than the ray that spawned it.
    pub depth: u32,
    pub origin: Vec3A,
    pub direction: Vec3A,
    /// The path weight, including this ray's own coefficient.
    pub weight: Vec3A,
    /// This ray's own coefficient: the reflective or transmissive colour, after Fresnel
    /// and total internal reflection (1 for camera rays).
    pub coefficient: Vec3A,
    /// The surface this ray leaves from (`None` for camera rays).
    pub interface: Option<Interface>,
}

/// Full data about the surface a ray hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    pub t: f32,
    pub point: Vec3A,
    /// The outward normal of the solid at the point (reversed on subtracted CSG surfaces).
    pub geometric_normal: Vec3A,
    /// The normal used for shading: the geometric normal turned to face the incoming ray.
    pub shading_normal: Vec3A,
    /// Whether the ray hit the outside of the surface.
    pub front_face: bool,
    /// The top-level object hit (a shape, or the root of a CSG solid; groups are flattened).
    pub object: Handle<Object>,
    /// The shape whose surface was hit (the CSG leaf; the object itself otherwise).
    pub leaf: Handle<Object>,
    /// The leaf's material, as the scene gives it.
    pub material: Handle<Material>,
    /// The material in effect at the point once patterns are resolved (with a blend, the
    /// one with the larger weight).
    pub resolved_material: Handle<Material>,
    /// The course's blend of two materials, when its `Noise`, `Marble` or `Wood` made one:
    /// shading used their interpolation.
    pub blend: Option<crate::material::Blend>,
    /// Beer-Lambert transmittance over this ray's path when it travels inside an
    /// absorbing solid (1 otherwise); the returned colour includes it.
    pub absorption: Vec3A,
    /// How far the hit point may be from the true surface along the normal: its error
    /// bound (`hit_error.rs`), whatever the scene's `epsilon`.
    pub error_bound: f32,
    /// How far this hit's shadow, reflected and transmitted rays start off the surface: the
    /// scene's `epsilon`, or else a margin over `error_bound`.
    pub offset: f32,
}

/// A surface within a hit's error bound along the ray: the other side of a z-fight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoincidentSurface {
    /// Its distance along the ray (the hit's own `t` give or take rounding).
    pub t: f32,
    /// The top-level object and the shape whose surface it is.
    pub object: Handle<Object>,
    pub leaf: Handle<Object>,
    /// The material in effect there, patterns resolved.
    pub material: Handle<Material>,
}

/// What a shadow ray found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowResult {
    Unblocked,
    /// Stopped at the first blocker found (not necessarily the nearest).
    Blocked {
        object: Handle<Object>,
        leaf: Handle<Object>,
        t: f32,
    },
    /// Filtered shadows: the light passed through transmissive surfaces only, filtered by
    /// `kt` at each (`blockers` counts surfaces: a solid filters where the ray enters and
    /// again where it leaves).
    Filtered {
        transmittance: Vec3A,
        blockers: u32,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowRay {
    pub origin: Vec3A,
    pub direction: Vec3A,
    /// The distance to the light (infinite for directional lights).
    pub max_t: f32,
    pub result: ShadowResult,
}

/// One light's share of the local illumination at a hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    pub light: Handle<Light>,
    pub to_light: Vec3A,
    pub distance: f32,
    /// `N·L` with the shading normal; the light counts only when it is positive.
    pub n_dot_l: f32,
    /// `fatt` (1 for directional lights).
    pub attenuation: f32,
    /// The spot cone factor (1 for other lights).
    pub spot: f32,
    /// The cosine of the angle between a spot light's axis and the direction from the light
    /// to the point (1 for other lights).
    pub cos_axis: f32,
    /// The shadow ray cast towards the light, if one was (see `no_shadow_ray` otherwise).
    pub shadow_ray: Option<ShadowRay>,
    /// Why no shadow ray was cast, when none was (`None` when `shadow_ray` is `Some`).
    pub no_shadow_ray: Option<NoShadowRay>,
    /// `fatt·spot·Ii·shadow·kd·(N·L)`, as added to the colour.
    pub diffuse: Vec3A,
    /// `fatt·spot·Ii·shadow·ks·(R·V)^n`, as added to the colour.
    pub specular: Vec3A,
}

/// Why a light cast no shadow ray at a hit, in the order the tracer tests them: the first
/// that applies is the one reported.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoShadowRay {
    /// The surface is seen from its back and the scene has `shade_back off`: the light adds
    /// nothing.
    BackFace,
    /// The light is behind the surface (`N·L <= 0`): it adds nothing.
    FacingAway,
    /// A spot light whose cone does not reach the point (its cone factor is 0): it adds
    /// nothing.
    OutsideCone,
    /// The light's colour is black: it adds nothing.
    BlackLight,
    /// `fatt·spot` rounds to 0 in f32 though neither factor is 0 (only at the very edge of
    /// a wide cone, far from the light; `fatt` itself is never 0 within the number limits):
    /// the light adds nothing.
    TooFaint,
    /// The light reaches the point, but the material has no diffuse and no specular colour:
    /// it could add nothing whatever a shadow ray found.
    Unshaded,
    /// The scene has `shadows none`: the light counts as unblocked.
    ShadowsOff,
}

/// A reflected or transmitted ray the material asked for but that was not traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkippedRay {
    pub kind: RayKind,
    pub depth: u32,
    pub weight: Vec3A,
    pub coefficient: Vec3A,
    pub reason: Termination,
}

/// Hooks called by the tracer; every method has an empty default. See the module
/// documentation for the order of calls.
pub trait Recorder {
    /// Whether the hooks look at what they are given. When false (plain rendering), the
    /// tracer skips work whose only use is a hook's argument, such as naming the object that
    /// blocked a shadow ray; the colours it computes are the same either way.
    const RECORDS: bool = true;

    /// Whether the trace should stop early (a cancelled trace in the debugger): secondary
    /// rays are then no longer started, so the colours are no longer the render's.
    #[inline(always)]
    fn should_stop(&self) -> bool {
        false
    }

    #[inline(always)]
    fn ray_started(&mut self, _ray: &RayStart) {}
    #[inline(always)]
    fn surface_hit(&mut self, _hit: &SurfaceHit) {}
    /// Another surface crossed within the hit's error bound along the ray (after
    /// `surface_hit`): the two cannot be told apart, and which one a ray meets is rounding
    /// (z-fighting). Only looked for when [`Recorder::RECORDS`] is true.
    #[inline(always)]
    fn coincident_surface(&mut self, _other: &CoincidentSurface) {}
    #[inline(always)]
    fn ray_missed(&mut self, _background: Vec3A) {}
    /// The ambient term `ka·Ia·kd` at the hit.
    #[inline(always)]
    fn ambient(&mut self, _ambient: Vec3A) {}
    /// The material's own emission at the hit (black for most surfaces).
    #[inline(always)]
    fn emission(&mut self, _emission: Vec3A) {}
    #[inline(always)]
    fn light_sampled(&mut self, _sample: &LightSample) {}
    #[inline(always)]
    fn secondary_skipped(&mut self, _skipped: &SkippedRay) {}
    /// The colour this ray returns to its parent (or to the pixel), and why it ended.
    #[inline(always)]
    fn ray_finished(&mut self, _color: Vec3A, _termination: Termination) {}
}

/// The recorder of plain rendering: records nothing and costs nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NoRecord;

impl Recorder for NoRecord {
    const RECORDS: bool = false;
}

/// Per-pixel statistics, cheap enough to gather on a whole render: rays traced (camera,
/// secondary and shadow), the deepest level reached, and which terminations occurred
/// (including secondary rays skipped for depth, weight or total internal reflection).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct PixelStats {
    pub rays: u32,
    pub deepest: u32,
    pub terminations: TerminationSet,
}

impl Recorder for PixelStats {
    /// The counts need no blocker named and no coincident surface looked for, so a render
    /// with per-pixel statistics asks the light buffers as a plain render does (on the grid
    /// of 10,000 spheres it had taken half as long again).
    const RECORDS: bool = false;

    #[inline]
    fn ray_started(&mut self, ray: &RayStart) {
        self.rays = self.rays.saturating_add(1);
        self.deepest = self.deepest.max(ray.depth);
    }

    #[inline]
    fn light_sampled(&mut self, sample: &LightSample) {
        // A shadow ray was cast unless the sample says why not (its record is left out
        // when `RECORDS` is false).
        if sample.no_shadow_ray.is_none() {
            self.rays = self.rays.saturating_add(1);
        }
    }

    #[inline]
    fn secondary_skipped(&mut self, skipped: &SkippedRay) {
        self.terminations.insert(skipped.reason);
    }

    #[inline]
    fn ray_finished(&mut self, _color: Vec3A, termination: Termination) {
        self.terminations.insert(termination);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn termination_set_round_trips() {
        let mut set = TerminationSet::default();
        assert!(set.is_empty());
        set.insert(Termination::Miss);
        set.insert(Termination::MaxDepth);
        set.insert(Termination::Miss);
        assert!(set.contains(Termination::Miss));
        assert!(!set.contains(Termination::Absorbed));
        assert_eq!(
            set.iter().collect::<Vec<_>>(),
            vec![Termination::Miss, Termination::MaxDepth]
        );
    }
}
