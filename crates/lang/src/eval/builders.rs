//! The things a block's properties fill in while its body runs: one builder per kind of
//! block, on a stack in the evaluator so that `if` and `for` inside a body reach the same one.

use whitted_ir::{Attenuation, Camera, Color, DMat4, DVec3, Material, Projection, Span};

use crate::schema::{CameraTag, ObjectTag, Prop};
use crate::value::{MaterialId, PatternId};

/// Which properties a block has set, and where each was first set (for "set twice").
#[derive(Clone, Copy)]
pub(super) struct PropSet {
    mask: u128,
    first: [(Prop, Span); 10],
    len: u8,
}

// One bit per property: a property past the 128th needs a wider mask.
const _: () = assert!(Prop::ALL.len() <= 128);

impl PropSet {
    pub(super) fn new() -> Self {
        PropSet {
            mask: 0,
            first: [(Prop::Center, Span::detached()); 10],
            len: 0,
        }
    }

    /// Records `prop`; if it was already set, returns where (detached if not remembered).
    pub(super) fn insert(&mut self, prop: Prop, span: Span) -> Result<(), Span> {
        let bit = 1u128 << (prop as u32);
        if self.mask & bit != 0 {
            let first = self.first[..self.len as usize]
                .iter()
                .find(|(p, _)| *p == prop)
                .map_or(Span::detached(), |(_, s)| *s);
            return Err(first);
        }
        self.mask |= bit;
        if (self.len as usize) < self.first.len() {
            self.first[self.len as usize] = (prop, span);
            self.len += 1;
        }
        Ok(())
    }

    pub(super) fn has(&self, prop: Prop) -> bool {
        self.mask & (1u128 << (prop as u32)) != 0
    }
}

/// Transforms and material: what any object (and the block after a call) can set.
#[derive(Clone, Copy)]
pub(super) struct Placement {
    /// Transforms compose in the order written: the first one is applied first.
    pub transform: DMat4,
    pub material: Option<MaterialId>,
}

impl Placement {
    pub(super) fn new() -> Self {
        Placement {
            transform: DMat4::IDENTITY,
            material: None,
        }
    }
}

/// Every shape field, with the documented defaults; each shape reads its own.
#[derive(Clone, Copy)]
pub(super) struct ShapeFields {
    pub center: DVec3,
    pub radius: f64,
    pub normal: DVec3,
    pub offset: f64,
    pub min: DVec3,
    pub max: DVec3,
    pub base: DVec3,
    pub apex: DVec3,
    pub base_radius: f64,
    pub apex_radius: f64,
    pub vertices: [DVec3; 3],
    pub coefficients: [f64; 10],
    pub radii: DVec3,
    pub major: f64,
    pub minor: f64,
    pub open: bool,
    /// A mesh's geometry, registered when its `file` is read.
    pub mesh: Option<whitted_ir::Handle<whitted_ir::Mesh>>,
    pub smooth: bool,
}

impl ShapeFields {
    pub(super) fn defaults(tag: ObjectTag) -> Self {
        ShapeFields {
            center: DVec3::ZERO,
            radius: 1.0,
            normal: DVec3::Y,
            offset: 0.0,
            min: DVec3::splat(-1.0),
            max: DVec3::ONE,
            base: DVec3::ZERO,
            apex: DVec3::Y,
            base_radius: 1.0,
            apex_radius: if tag == ObjectTag::Cone { 0.0 } else { 1.0 },
            vertices: [DVec3::ZERO; 3],
            coefficients: [0.0; 10],
            radii: DVec3::ONE,
            major: 1.0,
            minor: 0.25,
            open: false,
            mesh: None,
            smooth: true,
        }
    }
}

pub(super) struct ObjectBuilder {
    pub tag: ObjectTag,
    pub fields: ShapeFields,
    pub placement: Placement,
    pub set: PropSet,
}

pub(super) struct CameraBuilder {
    pub tag: CameraTag,
    pub eye: DVec3,
    pub look_at: DVec3,
    pub up: DVec3,
    pub fov: f64,
    pub height: f64,
    pub set: PropSet,
}

impl CameraBuilder {
    pub(super) fn new(tag: CameraTag) -> Self {
        let default = Camera::default();
        CameraBuilder {
            tag,
            eye: default.eye,
            look_at: default.look_at,
            up: default.up,
            fov: 45.0,
            height: 4.0,
            set: PropSet::new(),
        }
    }

    pub(super) fn build(&self) -> Camera {
        Camera {
            eye: self.eye,
            look_at: self.look_at,
            up: self.up,
            projection: match self.tag {
                CameraTag::Perspective => Projection::Perspective {
                    vertical_fov_degrees: self.fov,
                },
                CameraTag::Orthographic => Projection::Orthographic {
                    view_height: self.height,
                },
            },
        }
    }
}

pub(super) struct LightBuilder {
    pub position: DVec3,
    pub direction: DVec3,
    pub color: Color,
    pub attenuation: Attenuation,
    pub inner: f64,
    pub outer: f64,
    pub set: PropSet,
}

impl LightBuilder {
    pub(super) fn new() -> Self {
        LightBuilder {
            position: DVec3::ZERO,
            direction: DVec3::NEG_Y,
            color: Color::WHITE,
            attenuation: Attenuation::NONE,
            inner: 20.0,
            outer: 30.0,
            set: PropSet::new(),
        }
    }
}

pub(super) struct MaterialBuilder {
    pub material: Material,
    pub pattern: Option<PatternId>,
    pub set: PropSet,
}

/// The block whose properties are being set right now.
pub(super) enum Target {
    /// The big builders are boxed: a loop's million objects each push and pop a `Target`,
    /// and moving a pointer costs less than copying a builder (compiling the 1M-sphere grid
    /// went 0.50 -> 0.48 s).
    Object(Box<ObjectBuilder>),
    Modifiers(Placement, PropSet),
    Settings,
    Camera(CameraBuilder),
    Light(LightBuilder),
    Material(Box<MaterialBuilder>),
    PatternTransform(DMat4),
}
