//! The scene IR itself: settings, camera, lights, materials and objects, as plain data.
//!
//! Everything is resolved: material inheritance is flattened, `let`/`for`/functions are gone,
//! and every object carries its full `world_from_object` transform, so the tracer needs no
//! knowledge of the language that produced it.

use glam::{DMat4, DVec3};
use serde::Serialize;

use crate::arena::{Arena, Handle};
use crate::mesh::Mesh;
use crate::object_shape::{NameId, Names, ObjectShape};
use crate::provenance::Provenance;
use crate::source::{SourceMap, Span};
use crate::written::Written;

/// A linear RGB triple. Not clamped: light intensities may exceed 1.
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize)]
pub struct Color {
    pub r: f64,
    pub g: f64,
    pub b: f64,
}

impl Color {
    pub const BLACK: Color = Color::gray(0.0);
    pub const WHITE: Color = Color::gray(1.0);

    pub const fn new(r: f64, g: f64, b: f64) -> Self {
        Color { r, g, b }
    }

    pub const fn gray(v: f64) -> Self {
        Color { r: v, g: v, b: v }
    }

    pub fn is_black(&self) -> bool {
        self.r == 0.0 && self.g == 0.0 && self.b == 0.0
    }

    pub fn components(&self) -> [f64; 3] {
        [self.r, self.g, self.b]
    }
}

/// How a transparent object shadows the light behind it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ShadowMode {
    /// Every object blocks light completely (the classic model).
    Opaque,
    /// A transmissive blocker lets light through, multiplied by its transmissive colour.
    Filtered,
    /// No shadow rays at all: every light reaches every surface that faces it (MIT 6.837's
    /// default without `-shadows`).
    None,
}

/// The specular highlight's model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Highlight {
    /// Phong: `ks·(R·V)^n`, with R the light direction mirrored about the normal.
    Phong,
    /// Blinn-Phong: `ks·(N·H)^n`, with H halfway between the light and the viewer.
    Blinn,
}

/// Where a pixel's samples fall.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// Stratified and jittered (Kensler's correlated multi-jitter): no grid pattern to alias.
    Jittered,
    /// A regular grid of sample positions at the centres of equal cells (the course's
    /// uniform sampler): repeatable by hand, and aliasing a fine pattern the same way in
    /// every pixel.
    Grid,
    /// Each sample anywhere in the pixel, independently (the course's random sampler):
    /// noisier than jittered for the same count. Hashed, so still the same on every run.
    Random,
}

/// How a pixel's value is made from the samples around it (the course's reconstruction
/// filters, assignment 7). Sample positions are measured in pixels from the pixel's centre.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Filter {
    /// Weight 1 for a sample inside the square `-r <= dx < r`, `-r <= dy < r`, 0 outside.
    /// With radius 0.5 (the default) that is exactly the pixel's own samples, averaged.
    Box,
    /// Weight `1 - d/r` at distance `d` from the centre, 0 from `r` on.
    Tent,
    /// Weight `exp(-d²/(2σ²))` with σ the filter radius, 0 from `2σ` on.
    Gaussian,
}

/// Render settings. Defaults live here so that the language, the CLI and tests agree.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Settings {
    pub width: u32,
    pub height: u32,
    /// Rays deeper than this are not spawned; the camera ray has depth 0.
    pub max_depth: u32,
    /// The contribution cut-off: a reflected or transmitted ray whose path weight (the
    /// product of coefficients from the eye) is below this on every channel is not traced.
    pub min_weight: f64,
    pub samples_per_pixel: u32,
    /// Where those samples fall in the pixel.
    pub sampling: Sampling,
    /// How the samples around a pixel make its value.
    pub filter: Filter,
    /// The box's and tent's radius, the gaussian's σ, in pixels.
    pub filter_radius: f64,
    pub background: Color,
    /// The global ambient light `Ia`.
    pub ambient: Color,
    /// When set, secondary rays start exactly this far off the surface along the normal;
    /// when not, the tracer uses the floating-point error bound of each hit point.
    pub epsilon: Option<f64>,
    pub shadows: ShadowMode,
    pub highlight: Highlight,
    /// Whether a surface seen from its back is lit by the lights (with its normal turned to
    /// face the viewer). When false, lights add nothing there; its ambient and emission
    /// terms and its reflected and transmitted rays stay (MIT 6.837 without `-shade_back`).
    pub shade_back: bool,
    /// Whether point and spot lights' distance attenuation is clamped at 1, so that a light
    /// never gets brighter than its colour close up (MIT 6.837 does not clamp).
    pub attenuation_clamp: bool,
    /// Whether a surface's reflected and transmitted coefficients are scaled down to add up
    /// to at most 1 (so that no bounce returns more light than arrives). MIT 6.837 adds
    /// `reflective·trace + transparent·trace` as given.
    pub energy_clamp: bool,
    /// With `shade_back` off, whether a surface seen from its back keeps its ambient and
    /// emission terms. When false its own colour is black (MIT 6.837's handout); its
    /// reflected and transmitted rays stay either way.
    pub back_ambient: bool,
    /// Whether a light behind the surface (N·L <= 0) adds no highlight. MIT 6.837's Phong
    /// adds `ks·(N·H)^n` whatever N·L is.
    pub highlight_gate: bool,
    /// Where in its pixel a single sample (and the pattern of several) is placed.
    pub sample_position: SamplePosition,
    /// Whether a surface hit from its back has its normal turned to face the ray before
    /// shading and bouncing. False is the classic student bug (a normal never flipped
    /// inside a solid), kept as a switch so that `whitted grade` can render it.
    pub flip_normals: bool,
    /// Whether a ray leaving a solid uses the inverted ratio of indices (ior → 1). False is
    /// the classic bug of refracting out of glass as if entering it.
    pub exit_ior_inverted: bool,
    /// Whether total internal reflection stops the transmitted ray. False is the classic
    /// bug of tracing it anyway: its direction is the square root of a negative number, so
    /// it meets nothing and returns the background.
    pub total_internal_reflection: bool,
    /// Whether point and spot lights fade with distance (their `attenuation`); false: every
    /// light at full colour everywhere (a student's missing attenuation).
    pub light_falloff: bool,
    /// A Fresnel rule for every material, replacing each material's own; `None`: each its own.
    pub fresnel_rule: Option<Fresnel>,
    /// The animation's first frame number (`first_frame`); with `frames` it gives the frame
    /// range the scene's `frame` and `clock` run over. Left out of the JSON at its default,
    /// so that still scenes' dumps read as before.
    #[serde(skip_serializing_if = "is_zero")]
    pub first_frame: u32,
    /// How many frames the animation has (`frames`); 1 is a still.
    #[serde(skip_serializing_if = "is_one")]
    pub frames: u32,
    /// Frames per second of the animation (`fps`), for animated images and videos.
    #[serde(skip_serializing_if = "is_default_fps")]
    pub fps: u32,
}

fn is_zero(n: &u32) -> bool {
    *n == 0
}

fn is_one(n: &u32) -> bool {
    *n == 1
}

fn is_default_fps(n: &u32) -> bool {
    *n == DEFAULT_FPS
}

/// Frames per second when a scene does not say.
pub const DEFAULT_FPS: u32 = 24;

/// Where a pixel's samples are placed relative to the pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SamplePosition {
    /// One sample at the pixel's centre; a pattern of several spread over the pixel.
    Centre,
    /// Everything half a pixel up and to the left: one sample at the pixel's corner, as a
    /// tracer that maps pixel `i` to `i / width` does.
    Corner,
}

impl Settings {
    /// The frames of the animation, first to last (one frame for a still). The last frame
    /// saturates at `u32::MAX`; the setting's ranges keep it well below.
    pub fn frame_range(&self) -> std::ops::RangeInclusive<u32> {
        let last = self
            .first_frame
            .saturating_add(self.frames.saturating_sub(1));
        self.first_frame..=last
    }

    /// Whether the scene is an animation (more than one frame).
    pub fn is_animated(&self) -> bool {
        self.frames > 1
    }

    /// Whether each pixel is the plain mean of its own samples (the box filter of radius
    /// 0.5, the default): the render then keeps no samples beyond the pixel.
    pub fn filter_is_own_pixel(&self) -> bool {
        self.filter == Filter::Box && self.filter_radius == 0.5
    }
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            width: 640,
            height: 480,
            max_depth: 5,
            min_weight: 0.001,
            samples_per_pixel: 1,
            sampling: Sampling::Jittered,
            filter: Filter::Box,
            filter_radius: 0.5,
            background: Color::BLACK,
            ambient: Color::WHITE,
            epsilon: None,
            shadows: ShadowMode::Opaque,
            highlight: Highlight::Phong,
            shade_back: true,
            attenuation_clamp: true,
            energy_clamp: true,
            back_ambient: true,
            highlight_gate: true,
            sample_position: SamplePosition::Centre,
            flip_normals: true,
            exit_ior_inverted: true,
            total_internal_reflection: true,
            light_falloff: true,
            fresnel_rule: None,
            first_frame: 0,
            frames: 1,
            fps: DEFAULT_FPS,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Projection {
    Perspective { vertical_fov_degrees: f64 },
    Orthographic { view_height: f64 },
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Camera {
    pub eye: DVec3,
    pub look_at: DVec3,
    pub up: DVec3,
    pub projection: Projection,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            eye: DVec3::new(0.0, 0.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            projection: Projection::Perspective {
                vertical_fov_degrees: 45.0,
            },
        }
    }
}

/// Distance attenuation `fatt = min(1, 1 / (constant + linear·d + quadratic·d²))` (without the
/// `min` when [`Settings::attenuation_clamp`] is off).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Attenuation {
    pub constant: f64,
    pub linear: f64,
    pub quadratic: f64,
}

impl Attenuation {
    /// No fall-off with distance.
    pub const NONE: Attenuation = Attenuation {
        constant: 1.0,
        linear: 0.0,
        quadratic: 0.0,
    };
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum LightKind {
    Point {
        position: DVec3,
        attenuation: Attenuation,
    },
    /// Light from infinitely far away, travelling along `direction`.
    Directional { direction: DVec3 },
    /// A point light limited to a cone: full inside `inner`, fading to zero at `outer`.
    Spot {
        position: DVec3,
        direction: DVec3,
        inner_angle_degrees: f64,
        outer_angle_degrees: f64,
        attenuation: Attenuation,
    },
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Light {
    pub name: Option<String>,
    /// The intensity `Ii` per channel.
    pub color: Color,
    pub kind: LightKind,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Fresnel {
    /// Reflection and transmission use the reflective and transmissive colours as given.
    Off,
    /// Schlick's approximation splits the weight between reflection and transmission.
    Schlick,
    /// The exact Fresnel equations for a dielectric (the average of the s- and
    /// p-polarised reflectances) split the weight between reflection and transmission.
    Exact,
}

impl Fresnel {
    /// The word the scene language uses for it.
    pub fn name(self) -> &'static str {
        match self {
            Fresnel::Off => "off",
            Fresnel::Schlick => "schlick",
            Fresnel::Exact => "exact",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PatternKind {
    /// Alternating cubes of side `scale` in pattern space.
    Checker,
    /// Alternating slabs of width `scale` along pattern-space x.
    Stripes,
    /// Bands across pattern-space x, bent by turbulence (deterministic noise).
    Marble,
    /// Rings around pattern-space y, made irregular by turbulence.
    Wood,
    /// Blotches where fractal noise is at least 0.
    Turbulence,
    /// The MIT 6.837 course's `Checkerboard`: `a` where `floor(x) + floor(y) + floor(z)` of
    /// the texture-space point is even, `b` where it is odd.
    CourseCheckerboard,
    /// The course's `Noise`: `a` and `b` blended by `v = clamp(N(p), 0, 1)`, where `N` sums
    /// `octaves` octaves of Perlin's improved noise (`N(p) = Σ noise(2^i·p) / 2^i`).
    CourseNoise { octaves: u32 },
    /// The course's `Marble`: blended by `v = (1 + sin(frequency·x + amplitude·N(p))) / 2`.
    CourseMarble {
        octaves: u32,
        frequency: f64,
        amplitude: f64,
    },
    /// The course's `Wood`: rings around texture-space y, blended by
    /// `v = (1 + sin(frequency·sqrt(x² + z²) + amplitude·N(p))) / 2`.
    CourseWood {
        octaves: u32,
        frequency: f64,
        amplitude: f64,
    },
}

impl PatternKind {
    /// The course's four read the world-space hit point (the course's hit point is in world
    /// space, whatever `Transform` the object is under); whitted's own read the object-space
    /// point, so that a pattern moves with its object.
    pub fn world_space(self) -> bool {
        matches!(
            self,
            PatternKind::CourseCheckerboard
                | PatternKind::CourseNoise { .. }
                | PatternKind::CourseMarble { .. }
                | PatternKind::CourseWood { .. }
        )
    }

    /// Whether the pattern blends its two materials (a weight in [0, 1] at each point)
    /// rather than choosing one of them.
    pub fn blends(self) -> bool {
        matches!(
            self,
            PatternKind::CourseNoise { .. }
                | PatternKind::CourseMarble { .. }
                | PatternKind::CourseWood { .. }
        )
    }

    /// The noise octaves of a blending pattern.
    pub fn octaves(self) -> Option<u32> {
        match self {
            PatternKind::CourseNoise { octaves }
            | PatternKind::CourseMarble { octaves, .. }
            | PatternKind::CourseWood { octaves, .. } => Some(octaves),
            _ => None,
        }
    }

    /// The name `whitted ir` shows: the scene language's word, or the course's block name.
    pub fn name(self) -> &'static str {
        match self {
            PatternKind::Checker => "checker",
            PatternKind::Stripes => "stripes",
            PatternKind::Marble => "marble",
            PatternKind::Wood => "wood",
            PatternKind::Turbulence => "turbulence",
            PatternKind::CourseCheckerboard => "Checkerboard",
            PatternKind::CourseNoise { .. } => "Noise",
            PatternKind::CourseMarble { .. } => "Marble",
            PatternKind::CourseWood { .. } => "Wood",
        }
    }
}

/// A procedural choice between two materials at each surface point, or (the course's
/// `Noise`, `Marble` and `Wood`) a blend of the two.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Pattern {
    pub kind: PatternKind,
    pub a: Handle<Material>,
    pub b: Handle<Material>,
    pub scale: f64,
    /// Maps the object-space hit point into pattern space (before dividing by `scale`); for
    /// the course's kinds ([`PatternKind::world_space`]) it maps the world-space point.
    pub pattern_from_object: DMat4,
}

/// A fully resolved material (inheritance already applied).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Material {
    pub name: Option<String>,
    /// `ka`: the ambient term is `ka·Ia·diffuse`.
    pub ambient: Color,
    /// `kd`: the diffuse colour.
    pub diffuse: Color,
    /// `ks`: the Phong specular colour.
    pub specular: Color,
    /// The Phong exponent `n`.
    pub shininess: f64,
    /// `kr`: weight of the mirror-reflected ray.
    pub reflective: Color,
    /// `kt`: weight of the refracted ray.
    pub transmissive: Color,
    pub ior: f64,
    pub fresnel: Fresnel,
    /// Which medium fills the overlap of two solids (nested media): the higher priority
    /// wins and the other solid's surfaces inside it are skipped. 0 (the default) is a plain
    /// solid, whose surfaces are always surfaces and whose own medium applies inside it.
    pub priority: u32,
    /// Beer-Lambert absorption per unit distance inside a transmissive solid.
    pub absorption: Color,
    /// Light the surface gives off by itself: added to its local colour whatever the lights
    /// and shadows (a self-lit surface; it lights nothing else).
    pub emission: Color,
    /// When set, the surface takes pattern.a or pattern.b at each point instead of this.
    pub pattern: Option<Pattern>,
}

impl Default for Material {
    /// The documented default: a matte light grey.
    fn default() -> Self {
        Material {
            name: None,
            ambient: Color::gray(0.1),
            diffuse: Color::gray(0.8),
            specular: Color::BLACK,
            shininess: 32.0,
            reflective: Color::BLACK,
            transmissive: Color::BLACK,
            ior: 1.0,
            fresnel: Fresnel::Off,
            priority: 0,
            absorption: Color::BLACK,
            emission: Color::BLACK,
            pattern: None,
        }
    }
}

/// Which named quadric a [`Quadric`] was written as (informative: the coefficients rule).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum QuadricForm {
    General,
    Ellipsoid,
    EllipticParaboloid,
    HyperboloidOneSheet,
    HyperboloidTwoSheets,
}

/// `A·x² + B·y² + C·z² + D·xy + E·xz + F·yz + G·x + H·y + I·z + J = 0`, a solid that is
/// inside where the polynomial is negative.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Quadric {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub d: f64,
    pub e: f64,
    pub f: f64,
    pub g: f64,
    pub h: f64,
    pub i: f64,
    pub j: f64,
}

impl Quadric {
    pub fn coefficients(&self) -> [f64; 10] {
        [
            self.a, self.b, self.c, self.d, self.e, self.f, self.g, self.h, self.i, self.j,
        ]
    }

    pub fn from_coefficients(c: [f64; 10]) -> Self {
        Quadric {
            a: c[0],
            b: c[1],
            c: c[2],
            d: c[3],
            e: c[4],
            f: c[5],
            g: c[6],
            h: c[7],
            i: c[8],
            j: c[9],
        }
    }

    /// The polynomial's value at `p` (negative inside).
    pub fn eval(&self, p: DVec3) -> f64 {
        let (x, y, z) = (p.x, p.y, p.z);
        self.a * x * x
            + self.b * y * y
            + self.c * z * z
            + self.d * x * y
            + self.e * x * z
            + self.f * y * z
            + self.g * x
            + self.h * y
            + self.i * z
            + self.j
    }

    /// The gradient at `p`: the outward (unnormalised) surface normal.
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        let (x, y, z) = (p.x, p.y, p.z);
        DVec3::new(
            2.0 * self.a * x + self.d * y + self.e * z + self.g,
            2.0 * self.b * y + self.d * x + self.f * z + self.h,
            2.0 * self.c * z + self.e * x + self.f * y + self.i,
        )
    }
}

/// A primitive in object space. Solids (everything but disk, triangle and the open
/// cylinder and cone) may take part in CSG.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Shape {
    Sphere {
        center: DVec3,
        radius: f64,
    },
    /// The points with `normal·p = offset`; the solid is the half-space `normal·p < offset`.
    Plane {
        normal: DVec3,
        offset: f64,
    },
    Box {
        min: DVec3,
        max: DVec3,
    },
    /// A circular cylinder from `base` to `apex`; `capped: false` leaves the ends open.
    Cylinder {
        base: DVec3,
        apex: DVec3,
        radius: f64,
        capped: bool,
    },
    /// A (possibly truncated) circular cone from `base` to `apex`.
    Cone {
        base: DVec3,
        base_radius: f64,
        apex: DVec3,
        apex_radius: f64,
        capped: bool,
    },
    /// A flat disk, facing `normal`. Not a solid.
    Disk {
        center: DVec3,
        normal: DVec3,
        radius: f64,
    },
    /// A single triangle. Not a solid.
    Triangle {
        a: DVec3,
        b: DVec3,
        c: DVec3,
    },
    Quadric {
        form: QuadricForm,
        quadric: Quadric,
    },
    /// A ring around the y axis, centred at the origin: the points within `minor` of the
    /// circle of radius `major` in the xz plane (as POV-Ray's torus). A quartic; a solid.
    Torus {
        major: f64,
        minor: f64,
    },
    /// An instance of a triangle mesh of [`Scene::meshes`]. A solid when the mesh is one
    /// ([`Mesh::solid`]); otherwise thin triangles, like `triangle`.
    Mesh {
        mesh: Handle<Mesh>,
        /// Normals interpolated across each triangle (from the file's vertex normals, or
        /// else the area-weighted average of the faces around each vertex); `false` uses
        /// each triangle's own normal.
        smooth: bool,
    },
}

impl Shape {
    /// Whether the shape encloses a volume, so it has an inside for CSG and refraction. A
    /// mesh's answer is in its data, so outside this crate ask [`Scene::is_solid_shape`]
    /// (a reshading oracle that asked the shape took every glass mesh for thin sheets).
    pub(crate) fn is_solid(&self) -> bool {
        match self {
            Shape::Disk { .. } | Shape::Triangle { .. } | Shape::Mesh { .. } => false,
            Shape::Cylinder { capped, .. } | Shape::Cone { capped, .. } => *capped,
            _ => true,
        }
    }

    pub fn kind_name(&self) -> &'static str {
        match self {
            Shape::Sphere { .. } => "sphere",
            Shape::Plane { .. } => "plane",
            Shape::Box { .. } => "box",
            Shape::Cylinder { .. } => "cylinder",
            Shape::Cone { .. } => "cone",
            Shape::Disk { .. } => "disk",
            Shape::Triangle { .. } => "triangle",
            Shape::Torus { .. } => "torus",
            Shape::Mesh { .. } => "mesh",
            Shape::Quadric { form, .. } => match form {
                QuadricForm::General => "quadric",
                QuadricForm::Ellipsoid => "ellipsoid",
                QuadricForm::EllipticParaboloid => "paraboloid",
                QuadricForm::HyperboloidOneSheet => "hyperboloid",
                QuadricForm::HyperboloidTwoSheets => "hyperboloid2",
            },
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CsgOp {
    /// Inside any child.
    Union,
    /// Inside every child.
    Intersection,
    /// Inside the first child and outside all the others.
    Difference,
}

impl CsgOp {
    pub fn name(&self) -> &'static str {
        match self {
            CsgOp::Union => "union",
            CsgOp::Intersection => "intersection",
            CsgOp::Difference => "difference",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ObjectKind {
    Shape {
        shape: ObjectShape,
    },
    /// A solid made from solid children; children come before the node in the arena.
    Csg {
        op: CsgOp,
        children: Vec<Handle<Object>>,
    },
    /// A plain collection that is not a solid; its children render as separate objects.
    Group {
        children: Vec<Handle<Object>>,
    },
}

impl ObjectKind {
    /// The shape of a shape object (`None` for CSG and groups).
    pub fn shape(&self) -> Option<Shape> {
        match self {
            ObjectKind::Shape { shape } => Some(shape.get()),
            ObjectKind::Csg { .. } | ObjectKind::Group { .. } => None,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Object {
    /// Its name in the scene's [`Scene::object_names`]; read it with [`Scene::object_name`].
    /// (The scene's JSON writes the name itself, beside the object's other fields.)
    #[serde(skip)]
    pub name: Option<NameId>,
    pub kind: ObjectKind,
    /// The full transform from this node's space to world space (parents already applied).
    pub world_from_object: WorldFromObject,
    /// The material of this node's surfaces (a CSG hit uses the leaf's material).
    pub material: Handle<Material>,
}

/// An object's full transform to world space, stored compactly: most objects of a large
/// scene (a sphere placed by its centre) have none, and a matrix inline would be 128 of an
/// object's bytes. The identity takes no heap; any other matrix is boxed. It reads as a
/// [`DMat4`] (`Deref`), and compares and serializes as one.
#[derive(Clone, Default)]
pub struct WorldFromObject(Option<Box<DMat4>>);

/// What the identity derefs to.
static IDENTITY: DMat4 = DMat4::IDENTITY;

impl WorldFromObject {
    pub const IDENTITY: WorldFromObject = WorldFromObject(None);

    pub fn new(matrix: DMat4) -> WorldFromObject {
        if matrix == DMat4::IDENTITY {
            WorldFromObject(None)
        } else {
            WorldFromObject(Some(Box::new(matrix)))
        }
    }

    /// The matrix, by value.
    pub fn matrix(&self) -> DMat4 {
        **self
    }
}

impl From<DMat4> for WorldFromObject {
    fn from(matrix: DMat4) -> WorldFromObject {
        WorldFromObject::new(matrix)
    }
}

impl std::ops::Deref for WorldFromObject {
    type Target = DMat4;

    fn deref(&self) -> &DMat4 {
        self.0.as_deref().unwrap_or(&IDENTITY)
    }
}

/// Writing through it boxes the identity first (only tests and transforms of whole
/// subtrees write).
impl std::ops::DerefMut for WorldFromObject {
    fn deref_mut(&mut self) -> &mut DMat4 {
        self.0.get_or_insert_with(|| Box::new(DMat4::IDENTITY))
    }
}

impl PartialEq for WorldFromObject {
    fn eq(&self, other: &WorldFromObject) -> bool {
        **self == **other
    }
}

impl std::fmt::Debug for WorldFromObject {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        (**self).fmt(f)
    }
}

impl Serialize for WorldFromObject {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        (**self).serialize(serializer)
    }
}

/// A whole scene: what one `.scene` file (with its imports) describes.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    pub settings: Settings,
    pub camera: Camera,
    /// Where the camera was defined (detached when the default camera is used).
    pub camera_span: Span,
    pub lights: Arena<Light>,
    pub materials: Arena<Material>,
    pub objects: Arena<Object>,
    /// Mesh geometry, each file once however many objects instance it.
    pub meshes: Arena<Mesh>,
    /// The top-level objects, in source order. Every other object is reachable from these.
    pub roots: Vec<Handle<Object>>,
    /// The names objects were given (an object holds an index into this).
    pub object_names: Names,
    pub sources: SourceMap,
    /// How each object was made: the imports, calls and loop iterations around it.
    pub provenance: Provenance,
    /// Where each setting and each property of the camera, lights and materials was written.
    pub written: Written,
    /// Which front end read the scene: write-back edits only the language it knows.
    pub format: SceneFormat,
}

/// The language a scene was written in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SceneFormat {
    /// whitted's scene language (`.scene`).
    #[default]
    Whitted,
    /// The MIT 6.837 course's scene files (`.txt`).
    Mit6837,
}

impl Default for Span {
    fn default() -> Self {
        Span::detached()
    }
}

impl Scene {
    /// The display name of an object: its own name, or its kind and handle.
    pub fn object_label(&self, handle: Handle<Object>) -> String {
        let object = &self.objects[handle];
        match self.name_of(object) {
            Some(name) => name.to_string(),
            None => {
                let kind = match &object.kind {
                    ObjectKind::Shape { shape } => shape.kind_name(),
                    ObjectKind::Csg { op, .. } => op.name(),
                    ObjectKind::Group { .. } => "group",
                };
                format!("{kind} {handle}")
            }
        }
    }

    /// The name `handle`'s object was given, if any.
    pub fn object_name(&self, handle: Handle<Object>) -> Option<&str> {
        self.objects
            .get(handle)
            .and_then(|object| self.name_of(object))
    }

    /// The name `object` (an object of this scene) was given, if any.
    pub fn name_of(&self, object: &Object) -> Option<&str> {
        object.name.map(|id| self.object_names.get(id))
    }

    /// Whether a shape encloses a volume: [`Shape::is_solid`], with meshes answered by
    /// their data (a missing mesh is no solid).
    pub fn is_solid_shape(&self, shape: &Shape) -> bool {
        match shape {
            Shape::Mesh { mesh, .. } => self.meshes.get(*mesh).is_some_and(|m| m.solid),
            _ => shape.is_solid(),
        }
    }

    /// The display name of a material: its own name or its handle.
    pub fn material_label(&self, handle: Handle<Material>) -> String {
        match &self.materials[handle].name {
            Some(name) => name.clone(),
            None => format!("material {handle}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A million objects placed by their own parameters carry no matrix at all.
    #[test]
    fn objects_without_a_transform_stay_small() {
        assert_eq!(std::mem::size_of::<WorldFromObject>(), 8);
        assert!(
            std::mem::size_of::<Object>() <= 136,
            "{}",
            std::mem::size_of::<Object>()
        );
        assert!(WorldFromObject::new(DMat4::IDENTITY).0.is_none());
    }

    /// It reads, compares and serializes exactly as the matrix it stands for.
    #[test]
    fn it_stands_for_its_matrix() {
        let matrices = [
            DMat4::IDENTITY,
            DMat4::from_translation(DVec3::new(1.0, -2.0, 0.5)),
            DMat4::from_scale(DVec3::new(2.0, 3.0, 0.25))
                * DMat4::from_rotation_y(0.3)
                * DMat4::from_translation(DVec3::Z),
        ];
        for m in matrices {
            let w = WorldFromObject::from(m);
            assert_eq!(*w, m);
            assert_eq!(w.matrix(), m);
            assert_eq!(w, WorldFromObject::new(m));
            assert_eq!(
                serde_json::to_string(&w).ok(),
                serde_json::to_string(&m).ok()
            );
        }
        // Writing through the identity boxes it, and it still equals the identity.
        let mut w = WorldFromObject::IDENTITY;
        w.w_axis.x = 0.0;
        assert_eq!(w, WorldFromObject::IDENTITY);
        w.w_axis.x = 4.0;
        assert_eq!(*w, DMat4::from_translation(DVec3::X * 4.0));
    }
}
