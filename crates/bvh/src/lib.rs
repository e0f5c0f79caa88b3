//! whitted-bvh: the bounding volume hierarchy the tracer walks, with the boxes and the ray
//! type it needs.
//!
//! [`Bvh::build`] makes a binary tree (`binary`: binned SAH, Morton-ordered top for large
//! inputs), converts it into obvhs's compressed wide layout (`wide`) and keeps each node's
//! child boxes as f32 planes; [`Bvh::traverse`] and [`Bvh::traverse_packet`] walk it in
//! obvhs's visit order with the fastest child test the CPU has (`simd`, see
//! [`TraversalPath`]). [`Bound`] is what an object's box can be (empty, finite, infinite).
//!
//! This crate knows nothing of scenes: callers work out their objects' bounds (with
//! [`Bound`]), hand over the finite boxes, and get back primitive indices in walk order. It
//! is the one library crate with `unsafe` code (the SIMD walks in `simd`), kept apart so
//! that everything else can deny it.

mod binary;
mod bounds;
mod permute;
mod ray;
mod simd;
#[cfg(any(test, feature = "testing"))]
pub mod testing;
mod walk;
mod wide;

pub use binary::PrimitiveBox;
pub use bounds::{inverse_direction, Bound};
pub use ray::Ray;
pub use walk::{
    force_traversal_path, Bvh, PacketEntry, PathUnavailable, Step, TraversalPath, MAX_PRIMITIVES,
    PACKET,
};
