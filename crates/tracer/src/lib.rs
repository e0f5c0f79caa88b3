//! whitted-tracer: renders a validated scene with Whitted's recursive model.
//!
//! [`PreparedScene::new`] turns a `whitted_ir::ValidScene` into f32 shapes, materials,
//! lights, CSG trees and a BVH; [`render`] traces it over tiles in parallel. Tracing is one
//! code path generic over a [`Recorder`]: [`render`] uses [`NoRecord`], while
//! [`trace_pixel_with`] runs the same code for one pixel sample with any recorder (ray
//! trees, statistics), so a recorded tree is always what the renderer computed.

mod camera;
mod csg;
pub mod display;
mod filter;
mod hit_error;
mod light;
mod light_buffer;
mod material;
mod media;
mod mesh;
mod noise;
pub mod optics;
mod perlin;
mod query;
pub mod ray_tree;
mod recorder;
mod render;
mod sampling;
mod scene;
mod shapes;
mod solve;
pub mod task_plan;
pub mod testing;
mod torus;
mod trace;

#[cfg(test)]
mod tests;

// The BVH lives in whitted-bvh; the walk the renderer takes is part of this API.
pub use filter::{Film, PixelFilter};
pub use material::Blend;
pub use recorder::{
    CoincidentSurface, Interface, LightSample, NoRecord, NoShadowRay, PixelStats, RayKind,
    RayStart, Recorder, ShadowRay, ShadowResult, SkippedRay, SurfaceHit, Termination,
    TerminationSet,
};
pub use render::{
    render, render_film, render_from, render_region, render_with_pixel_stats,
    trace_pixel_preferring, trace_pixel_with, Image, NoObserver, PixelAccumulator, PixelRect,
    RenderObserver, RenderOptions, RenderStats, TileResult, TILE_SIZE,
};
pub use scene::{use_light_buffers, PreparedScene};
pub use whitted_bvh::{force_traversal_path, PathUnavailable, TraversalPath};

/// Re-exported so that recorder users name the same vector type as the tracer.
pub use glam::Vec3A;
