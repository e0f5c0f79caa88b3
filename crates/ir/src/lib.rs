//! whitted-ir: the validated scene IR that the language produces and the tracer consumes.
//!
//! Plain data only: arenas with typed handles, spans kept beside every node, and a validator
//! whose output type ([`ValidScene`]) is the proof that a scene is safe to render.

mod arena;
mod diagnostic;
mod json;
pub mod limits;
mod mesh;
mod object_shape;
mod print;
pub mod properties;
mod provenance;
mod ranges;
mod scene;
pub mod setting_rows;
mod source;
mod validate;
mod written;

pub use arena::{Arena, Handle};
pub use diagnostic::{Diagnostic, Label, Severity};
pub use json::{document as json_document, to_json, ArgJson, IrDocument, StepJson};
pub use mesh::{BadEdge, EdgeDefect, Mesh, NotSolid};
pub use object_shape::{NameId, Names, ObjectShape};
pub use print::print;
pub use provenance::{ArgValue, FrameId, Provenance, Site, SiteId, SiteKind, Step};
pub use scene::{
    Attenuation, Camera, Color, CsgOp, Filter, Fresnel, Highlight, Light, LightKind, Material,
    Object, ObjectKind, Pattern, PatternKind, Projection, Quadric, QuadricForm, SamplePosition,
    Sampling, Scene, SceneFormat, Settings, ShadowMode, Shape, WorldFromObject, DEFAULT_FPS,
};
pub use source::{FileId, LineCol, SourceFile, SourceMap, Span};
pub use validate::{validate, InvalidScene, ValidScene};
pub use written::{BlockId, BlockKind, Written, WrittenBlock, WrittenProperty};

/// Re-exported so that every crate names the same vector and matrix types.
pub use glam::{DMat4, DVec3};
