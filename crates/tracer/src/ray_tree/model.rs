//! The ray tree as plain data: what `whitted trace` prints, what its JSON holds and what the
//! debugger shows. Built by the tree recorder; no behaviour here beyond small helpers.
//!
//! Vectors and colours are `[f32; 3]` (linear RGB for colours), exactly the f32 values the
//! tracer computed, so a serialised tree round-trips bit for bit. Fields marked
//! `#[serde(skip)]` are for in-process users (the debugger's source pane) only.

use serde::Serialize;
use whitted_ir::Span;

use crate::recorder::{NoShadowRay, RayKind, Termination};

/// The version of the JSON document (`docs/ray-tree.md`); bumped on any incompatible change.
pub const RAY_TREE_JSON_VERSION: u32 = 2;

/// Every recorded ray of one pixel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RayTree {
    /// `[x, y]`, x from the left, y from the top.
    pub pixel: [u32; 2],
    /// `[width, height]` of the image the pixel belongs to.
    pub image_size: [u32; 2],
    /// The pixel's linear RGB exactly as `render` produced it (the mean of all its samples).
    pub color: [f32; 3],
    pub samples_per_pixel: u32,
    /// The limits the tree was traced with.
    pub max_depth: u32,
    pub min_weight: f32,
    /// The scene's shading-model switches the tree was traced with.
    pub model: ShadingModel,
    /// The most nodes the tree may hold (`ray tree nodes` in docs/language.md).
    pub node_budget: usize,
    /// Rays traced but not recorded because the tree reached `node_budget` (the sum of every
    /// node's `unrecorded`); 0 when the tree is complete.
    pub unrecorded: u64,
    /// Every sample recorded: all of the pixel's samples, or just the one asked for.
    pub samples: Vec<SampleTree>,
}

/// The settings that change how a hit is shaded (docs/language.md, Settings), so that a tree
/// read on its own says which model made its numbers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ShadingModel {
    /// `opaque`, `filtered` or `none`.
    pub shadows: whitted_ir::ShadowMode,
    /// `phong` or `blinn`.
    pub highlight: whitted_ir::Highlight,
    /// Whether lights shade a surface seen from its back.
    pub shade_back: bool,
    /// Whether point and spot lights' attenuation is clamped at 1.
    pub attenuation_clamp: bool,
    /// Whether a surface's `kr + kt` is scaled down to at most 1; written only when off, so
    /// that trees of the default model read as they did before the switch existed.
    #[serde(skip_serializing_if = "is_on")]
    pub energy_clamp: bool,
}

fn is_on(switch: &bool) -> bool {
    *switch
}

impl ShadingModel {
    pub fn of(settings: &whitted_ir::Settings) -> ShadingModel {
        ShadingModel {
            shadows: settings.shadows,
            highlight: settings.highlight,
            shade_back: settings.shade_back,
            attenuation_clamp: settings.attenuation_clamp,
            energy_clamp: settings.energy_clamp,
        }
    }
}

/// The tree of one sample (one camera ray) of a pixel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampleTree {
    /// The sample's index, `0..samples_per_pixel`.
    pub index: u32,
    /// What this sample contributed before averaging (equals `root.color`).
    pub color: [f32; 3],
    /// The camera ray.
    pub root: RayNode,
}

/// One ray: the camera ray, a reflected or transmitted ray, or a shadow ray.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RayNode {
    pub kind: RayKind,
    /// 0 for the camera ray; a reflected or transmitted ray is one deeper than its parent.
    /// A shadow ray has its parent's depth: it belongs to that hit's local illumination and
    /// the depth limit does not apply to it.
    pub depth: u32,
    pub origin: [f32; 3],
    /// A unit vector.
    pub direction: [f32; 3],
    /// The path weight: the product of every coefficient (and absorption factor) from the eye
    /// up to and including this ray's own coefficient: how much its colour counts in the pixel.
    /// A shadow ray carries the weight of the ray whose hit cast it.
    pub weight: [f32; 3],
    /// This ray's own coefficient: `kr` or `kt` after Fresnel and total internal reflection;
    /// `[1, 1, 1]` for camera and shadow rays.
    pub coefficient: [f32; 3],
    /// The optics of the surface this ray leaves from (reflected and transmitted rays only).
    pub interface: Option<InterfaceInfo>,
    /// What the ray hit; `None` on a miss (and always on shadow rays, see `shadow`).
    pub hit: Option<HitInfo>,
    /// The local illumination at the hit (`None` on a miss and on shadow rays).
    pub local: Option<LocalIllumination>,
    /// Only on shadow rays: which light, and what the ray found on its way there.
    pub shadow: Option<ShadowInfo>,
    /// The colour this ray returned to its parent (or to the pixel). For a shadow ray, the
    /// fraction of the light that got through: 1 unblocked, 0 blocked, the filter colour
    /// otherwise.
    pub color: [f32; 3],
    /// Why recursion stopped here. Shadow rays never recurse: `miss` when they reach the
    /// light (clear or filtered), `absorbed` when a blocker stops them.
    pub termination: Termination,
    /// Rays traced below this one (children and their subtrees) that are not in
    /// `children`: the tree reached its node budget here. 0 in a tree that was not cut.
    pub unrecorded: u64,
    /// Reflected or transmitted rays the material asked for but that were not traced.
    pub skipped: Vec<SkippedInfo>,
    /// Shadow rays first (in light order), then the reflected ray, then the transmitted one.
    pub children: Vec<RayNode>,
}

impl RayNode {
    /// The number of rays in this subtree, this one included.
    pub fn ray_count(&self) -> usize {
        1 + self.children.iter().map(RayNode::ray_count).sum::<usize>()
    }

    /// The deepest `depth` in this subtree.
    pub fn deepest(&self) -> u32 {
        self.children
            .iter()
            .map(RayNode::deepest)
            .fold(self.depth, u32::max)
    }

    /// The first child of `kind`, if any.
    pub fn child(&self, kind: RayKind) -> Option<&RayNode> {
        self.children.iter().find(|c| c.kind == kind)
    }
}

/// The surface a reflected or transmitted ray leaves from.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InterfaceInfo {
    /// The angle between the incoming ray and the shading normal, in degrees (0 = head on).
    pub incidence_degrees: f32,
    pub cos_incidence: f32,
    /// `[from, to]` refractive indices when the material transmits: the medium left and the
    /// medium beyond (air is 1).
    pub ior: Option<[f32; 2]>,
    /// Whether the incoming ray hit the outside of a solid (always false on thin surfaces).
    pub entering: bool,
    /// The material's Fresnel model: `off`, `schlick` or `exact`.
    pub fresnel: whitted_ir::Fresnel,
    /// The Fresnel `R` (Schlick's or the exact one) when the material uses Fresnel.
    pub fresnel_reflectance: Option<f32>,
    /// `1 − R` when the material uses Fresnel.
    pub fresnel_transmittance: Option<f32>,
    pub total_internal_reflection: bool,
}

/// Where a ray hit and what it hit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HitInfo {
    /// Distance along the (unit) direction.
    pub t: f32,
    pub point: [f32; 3],
    /// The solid's outward normal (reversed on subtracted CSG surfaces).
    pub geometric_normal: [f32; 3],
    /// The normal used for shading: the geometric normal turned to face the ray.
    pub shading_normal: [f32; 3],
    /// Whether the ray hit the outside of the surface.
    pub front_face: bool,
    /// The top-level object (a shape or a CSG root; groups are flattened away).
    pub object: ObjectRef,
    /// The shape whose surface was hit: the CSG leaf, or the object itself.
    pub leaf: ObjectRef,
    /// The CSG operations from `object` down to `leaf` (empty for a plain shape).
    pub csg_path: Vec<ObjectRef>,
    /// The leaf's material as the scene gives it.
    pub material: MaterialRef,
    /// The material in effect at the point once patterns are resolved (with a blend, the
    /// one with the larger weight: the medium inside is its).
    pub resolved_material: MaterialRef,
    /// The course's blend (`Noise`, `Marble`, `Wood` of a 6.837 scene): shading used
    /// `(1 - weight)·first + weight·second` of the two materials' colours and numbers.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blend: Option<BlendInfo>,
    /// Beer-Lambert transmittance over this ray's path inside an absorbing solid (1 in air);
    /// the returned colour includes it.
    pub absorption: [f32; 3],
    /// How far `point` may be from the true surface along the normal: its floating-point
    /// error bound, worked out for the shape that was hit.
    pub error_bound: f32,
    /// How far this hit's shadow, reflected and transmitted rays start off the surface:
    /// the scene's `epsilon` when it sets one, else a margin over `error_bound`.
    pub offset: f32,
    /// Other surfaces the ray crosses within the hit's error bound: which of them it meets
    /// is rounding (z-fighting). Empty almost always.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub coincident: Vec<CoincidentInfo>,
}

/// A surface in the same place as a hit, as far as f32 can tell.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CoincidentInfo {
    /// Its distance along the ray.
    pub t: f32,
    /// The top-level object and the shape whose surface it is.
    pub object: ObjectRef,
    pub leaf: ObjectRef,
    /// The material in effect there.
    pub material: MaterialRef,
}

/// An IR object, named for people and located in the source.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ObjectRef {
    /// Its index in the IR's object arena.
    pub handle: u32,
    pub name: Option<String>,
    /// The name, or the kind and handle (`sphere #3`).
    pub label: String,
    /// `sphere`, `box`, `difference`, ...
    pub kind: String,
    /// `file:line:column` of its definition, or `<built-in>`.
    pub location: String,
    /// Its instantiation stack, innermost first: the loop iterations, calls and imports that
    /// were running when it was made (empty for an object written at the top level of the
    /// root file, and for scenes from the 6.837 front end).
    pub made_by: Vec<StackStep>,
    #[serde(skip)]
    pub span: Span,
}

/// One step of an object's instantiation stack. Keys that do not apply to the step's kind
/// are `null`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StackStep {
    /// `"loop"`, `"call"` or `"import"`.
    pub kind: &'static str,
    /// As `whitted ir` writes it: `i = 7`, `ring(12, 2)`, `import`.
    pub text: String,
    /// `file:line:column` of the loop, the call or the import line.
    pub location: String,
    /// A loop's variable and its value in this iteration.
    pub var: Option<String>,
    pub value: Option<f64>,
    /// A call's function and its arguments, by parameter name.
    pub function: Option<String>,
    pub args: Option<Vec<StackArg>>,
    #[serde(skip)]
    pub span: Span,
}

/// A call's argument: the parameter's name and the value as the scene language writes it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StackArg {
    pub name: String,
    pub value: String,
}

/// An IR material, named for people and located in the source.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MaterialRef {
    pub handle: u32,
    pub name: Option<String>,
    pub label: String,
    pub location: String,
    #[serde(skip)]
    pub span: Span,
}

/// Two materials blended at a point, and the second's weight.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BlendInfo {
    pub first: MaterialRef,
    pub second: MaterialRef,
    /// The second material's weight, in [0, 1].
    pub weight: f32,
}

/// An IR light, named for people and located in the source.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LightRef {
    pub handle: u32,
    pub name: Option<String>,
    /// The name, or `light #N`.
    pub label: String,
    /// `point`, `directional` or `spot`.
    pub kind: String,
    pub location: String,
    #[serde(skip)]
    pub span: Span,
}

/// The local part of a hit's colour: ambient plus each light's share.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LocalIllumination {
    /// `ka·Ia·kd`.
    pub ambient: [f32; 3],
    /// The material's emission; left out of the JSON when black, as most surfaces are.
    #[serde(skip_serializing_if = "is_black")]
    pub emission: [f32; 3],
    /// One entry per light, in scene order.
    pub lights: Vec<LightContribution>,
    /// `ambient + emission + Σ (diffuse + specular)`: the local colour before absorption.
    pub total: [f32; 3],
}

/// One light's share of the local illumination at a hit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LightContribution {
    pub light: LightRef,
    /// Unit vector from the (offset) hit point towards the light.
    pub to_light: [f32; 3],
    /// Distance to the light; `None` for directional lights (infinitely far).
    pub distance: Option<f32>,
    /// `N·L` with the shading normal; the light counts only when it is positive.
    pub n_dot_l: f32,
    /// `fatt` (1 for directional lights).
    pub attenuation: f32,
    /// The spot cone factor (1 for other lights).
    pub spot: f32,
    /// For spot lights, where the point lies in the cone (`None` for other lights).
    pub cone: Option<ConeInfo>,
    /// `fatt·spot·Ii·shadow·kd·(N·L)`.
    pub diffuse: [f32; 3],
    /// `fatt·spot·Ii·shadow·ks·(R·V)^n`.
    pub specular: [f32; 3],
    /// Whether and why the light reaches the point.
    pub visibility: Visibility,
    /// The index in the node's `children` of this light's shadow ray (`None` when no shadow
    /// ray was cast).
    pub shadow_child: Option<usize>,
}

/// Where a point lies in a spot light's cone.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ConeInfo {
    /// The angle between the spot's axis and the direction from the light to the point.
    pub angle_degrees: f32,
    /// The spot's inner angle (full strength within it) and outer angle (nothing beyond it),
    /// from the axis, as the scene gives them.
    pub inner_degrees: f32,
    pub outer_degrees: f32,
}

/// Whether a light reaches a hit point, and when no shadow ray was cast, why not (the
/// tracer's own reason, `NoShadowRay`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Visibility {
    /// The shadow ray reached the light.
    Lit,
    /// The shadow ray passed through transmissive objects only (filtered shadows).
    Filtered,
    /// The shadow ray was stopped by an opaque object.
    Blocked,
    /// No shadow ray was cast: the light is behind the surface (`N·L <= 0`).
    FacingAway,
    /// No shadow ray was cast: a spot light whose cone does not reach the point (`cone`
    /// says by how much).
    OutsideCone,
    /// No shadow ray was cast: the light's colour is black.
    BlackLight,
    /// No shadow ray was cast: `fatt·spot` rounds to 0 in f32 though neither is 0 (only at
    /// the very edge of a wide cone, far from the light).
    TooFaint,
    /// No shadow ray was cast: the light faces the surface, but the material has no diffuse
    /// and no specular colour, so it could add nothing.
    Unshaded,
    /// No shadow ray was cast because the scene has `shadows none`: the light counts as
    /// unblocked.
    NoShadows,
    /// The light adds nothing and no shadow ray was cast: the surface is seen from its back
    /// and the scene has `shade_back off`.
    BackFace,
}

impl Visibility {
    /// Every visibility, in declaration order.
    pub const ALL: [Visibility; 10] = [
        Visibility::Lit,
        Visibility::Filtered,
        Visibility::Blocked,
        Visibility::FacingAway,
        Visibility::OutsideCone,
        Visibility::BlackLight,
        Visibility::TooFaint,
        Visibility::Unshaded,
        Visibility::NoShadows,
        Visibility::BackFace,
    ];

    /// The word the JSON form uses.
    pub fn name(self) -> &'static str {
        match self {
            Visibility::Lit => "lit",
            Visibility::Filtered => "filtered",
            Visibility::Blocked => "blocked",
            Visibility::FacingAway => "facing_away",
            Visibility::OutsideCone => "outside_cone",
            Visibility::BlackLight => "black_light",
            Visibility::TooFaint => "too_faint",
            Visibility::Unshaded => "unshaded",
            Visibility::NoShadows => "no_shadows",
            Visibility::BackFace => "back_face",
        }
    }

    /// The visibility of a light that cast no shadow ray, for the tracer's reason.
    pub fn without_shadow_ray(reason: NoShadowRay) -> Visibility {
        match reason {
            NoShadowRay::BackFace => Visibility::BackFace,
            NoShadowRay::FacingAway => Visibility::FacingAway,
            NoShadowRay::OutsideCone => Visibility::OutsideCone,
            NoShadowRay::BlackLight => Visibility::BlackLight,
            NoShadowRay::TooFaint => Visibility::TooFaint,
            NoShadowRay::Unshaded => Visibility::Unshaded,
            NoShadowRay::ShadowsOff => Visibility::NoShadows,
        }
    }
}

/// What a shadow ray was cast for and what it found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShadowInfo {
    pub light: LightRef,
    /// The distance to the light, where the ray stops; `None` for directional lights.
    pub max_t: Option<f32>,
    pub result: ShadowOutcome,
    /// The blocker found, on `blocked` results (the first found, not necessarily the nearest).
    pub blocker: Option<Blocker>,
    /// The product of the transmissive colours passed through, on `filtered` results.
    pub transmittance: Option<[f32; 3]>,
    /// How many transmissive surfaces it crossed, on `filtered` results (a solid counts
    /// twice: where the ray enters it and where it leaves).
    pub filters: Option<u32>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ShadowOutcome {
    Unblocked,
    Blocked,
    Filtered,
}

/// The object that stopped a shadow ray.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Blocker {
    pub object: ObjectRef,
    /// The shape actually hit (the CSG leaf, or the object itself).
    pub leaf: ObjectRef,
    pub t: f32,
}

/// A reflected or transmitted ray the material asked for but that was not traced.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SkippedInfo {
    pub kind: RayKind,
    pub depth: u32,
    /// The path weight it would have had. On total internal reflection, the weight lost:
    /// `kt` times the parent's weight without Fresnel (the transmitted term is dropped), zero
    /// with Fresnel (R = 1: the weight went to the reflected ray).
    pub weight: [f32; 3],
    pub coefficient: [f32; 3],
    /// `max_depth`, `weight_cutoff` or `total_internal_reflection`.
    pub reason: Termination,
}

/// Which samples of a pixel to record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleChoice {
    /// Every sample, `0..samples_per_pixel`.
    All,
    /// Only this one (the others are still traced, unrecorded, for the pixel's colour).
    One(u32),
}

fn is_black(c: &[f32; 3]) -> bool {
    *c == [0.0; 3]
}
