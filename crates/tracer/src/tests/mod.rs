//! Whole-tracer tests that need the crate's internals (the surface offset switch), and the
//! tree-building recorder they share.

mod acne;
mod bvh_oracle;
mod csg_oracle;
mod csg_scenes;
mod emission;
mod energy;
mod error_bounds;
mod media_scenes;
mod optics_scenes;
mod ray_budget;
mod shadow_rays;
mod student_switches;
mod switches;

use glam::Vec3A;

use crate::recorder::{LightSample, RayStart, Recorder, SkippedRay, SurfaceHit, Termination};
use crate::render::{trace_sample, RenderOptions};
use crate::scene::PreparedScene;
use crate::testing::SceneBuilder;
use crate::trace::Tracer;

/// One recorded ray with everything the hooks reported about it.
#[derive(Clone, Debug)]
pub struct Node {
    pub start: RayStart,
    pub hit: Option<SurfaceHit>,
    pub ambient: Vec3A,
    pub lights: Vec<LightSample>,
    pub children: Vec<Node>,
    pub skipped: Vec<SkippedRay>,
    pub color: Vec3A,
    pub termination: Termination,
}

impl Node {
    /// This node and all its descendants, depth first.
    pub fn walk(&self) -> Vec<&Node> {
        let mut out = vec![self];
        let mut i = 0;
        while i < out.len() {
            let node = out[i];
            out.extend(node.children.iter());
            i += 1;
        }
        out
    }
}

/// A recorder that builds the full ray tree (a simple stand-in for issue 4's recorder).
#[derive(Default)]
pub struct Tape {
    stack: Vec<Node>,
    pub roots: Vec<Node>,
}

impl Recorder for Tape {
    fn ray_started(&mut self, ray: &RayStart) {
        self.stack.push(Node {
            start: *ray,
            hit: None,
            ambient: Vec3A::ZERO,
            lights: Vec::new(),
            children: Vec::new(),
            skipped: Vec::new(),
            color: Vec3A::ZERO,
            termination: Termination::NotEnded,
        });
    }
    fn surface_hit(&mut self, hit: &SurfaceHit) {
        if let Some(top) = self.stack.last_mut() {
            top.hit = Some(*hit);
        }
    }
    fn ambient(&mut self, ambient: Vec3A) {
        if let Some(top) = self.stack.last_mut() {
            top.ambient = ambient;
        }
    }
    fn light_sampled(&mut self, sample: &LightSample) {
        if let Some(top) = self.stack.last_mut() {
            top.lights.push(*sample);
        }
    }
    fn secondary_skipped(&mut self, skipped: &SkippedRay) {
        if let Some(top) = self.stack.last_mut() {
            top.skipped.push(*skipped);
        }
    }
    fn ray_finished(&mut self, color: Vec3A, termination: Termination) {
        let Some(mut node) = self.stack.pop() else {
            return;
        };
        node.color = color;
        node.termination = termination;
        match self.stack.last_mut() {
            Some(parent) => parent.children.push(node),
            None => self.roots.push(node),
        }
    }
}

pub fn prepare(builder: SceneBuilder) -> PreparedScene {
    match builder.prepare() {
        Ok(scene) => scene,
        Err(message) => panic!("test scene is invalid: {message}"),
    }
}

pub fn options(width: u32, height: u32) -> RenderOptions {
    RenderOptions {
        width,
        height,
        samples_per_pixel: 1,
        max_depth: 5,
        min_weight: 0.001,
    }
}

/// The recorded tree of one pixel (sample 0), optionally with the surface offset removed.
pub fn trace_tree(
    scene: &PreparedScene,
    options: &RenderOptions,
    x: u32,
    y: u32,
    with_offset: bool,
) -> Node {
    trace_tree_scaled(scene, options, x, y, if with_offset { 1.0 } else { 0.0 })
}

/// The recorded tree of one pixel (sample 0) with `scale` times the surface offset.
pub fn trace_tree_scaled(
    scene: &PreparedScene,
    options: &RenderOptions,
    x: u32,
    y: u32,
    offset_scale: f32,
) -> Node {
    let tracer = Tracer::new(scene, options.depth_limit(), options.min_weight);
    let mut tracer = tracer.with_surface_offset_scale(offset_scale);
    let mut tape = Tape::default();
    trace_sample(&mut tracer, scene, options, x, y, 0, &mut tape);
    match tape.roots.pop() {
        Some(root) => root,
        None => panic!("the tracer recorded no camera ray"),
    }
}

/// Every pixel's tree, row by row.
pub fn trace_all(scene: &PreparedScene, options: &RenderOptions, with_offset: bool) -> Vec<Node> {
    trace_all_scaled(scene, options, if with_offset { 1.0 } else { 0.0 })
}

/// Every pixel's tree, row by row, with `offset_scale` times the surface offset.
pub fn trace_all_scaled(
    scene: &PreparedScene,
    options: &RenderOptions,
    offset_scale: f32,
) -> Vec<Node> {
    let mut trees = Vec::new();
    for y in 0..options.height {
        for x in 0..options.width {
            trees.push(trace_tree_scaled(scene, options, x, y, offset_scale));
        }
    }
    trees
}
