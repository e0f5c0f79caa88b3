//! The prepared scene: everything a render needs that depends only on the scene, built once
//! from a validated IR scene: f32 shapes with their transforms folded in, resolved materials
//! and lights, the camera basis, CSG trees, and the BVH over bounded objects.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use glam::{DAffine3, Vec3A};
use obvhs::aabb::Aabb;
use rayon::prelude::*;
use whitted_ir::{
    CsgOp, Handle, Material, Object, ObjectKind, Scene, Settings, ShadowMode, Shape, ValidScene,
};

use crate::camera::PreparedCamera;
use crate::csg::{ChildAccel, CsgNode, CsgTree, NO_ACCEL};
use crate::hit_error;
use crate::light::{PreparedLight, PreparedLightKind};
use crate::light_buffer::LightBuffer;
use crate::material::{color, PatternFrame, PatternFrames, PreparedMaterial, Snap};
use crate::mesh::{MeshInstance, PreparedMesh};
use crate::query::{Surface, LINEAR_LIMIT};
use crate::shapes::Geometry;
use whitted_bvh::{Bound, Bvh, PrimitiveBox};

/// A primitive shape ready to intersect, with what shading needs to know about it. (A
/// patterned leaf's frame is in [`PreparedScene`]'s `pattern_frames`, by `object`.)
#[derive(Clone, Debug)]
pub struct Leaf {
    pub geometry: Geometry,
    /// The IR object of this shape (a CSG leaf reports itself, not the CSG root).
    pub object: Handle<Object>,
    pub material: Handle<Material>,
}

/// One top-level thing to intersect: a shape or a whole CSG solid. Groups are flattened
/// into their members, so they never appear here. Kept small (32 bytes): a million of them
/// must fit in cache-friendly memory.
#[derive(Clone, Debug)]
pub enum Item {
    Shape(Leaf),
    Csg {
        /// The CSG root object.
        object: Handle<Object>,
        tree: Box<CsgTree>,
    },
}

impl Item {
    /// The IR object this item stands for (the shape, or the CSG root).
    #[inline]
    pub fn object(&self) -> Handle<Object> {
        match self {
            Item::Shape(leaf) => leaf.object,
            Item::Csg { object, .. } => *object,
        }
    }

    /// The leaf that made a hit: the shape itself, or leaf `index` of the CSG tree.
    #[inline]
    pub fn leaf(&self, index: u32) -> &Leaf {
        match self {
            Item::Shape(leaf) => leaf,
            Item::Csg { tree, .. } => &tree.leaves[index as usize],
        }
    }
}

/// Everything a render needs that depends only on the scene: f32 copies of shapes with
/// inverse transforms, resolved materials, lights, the camera basis, and the obvhs BVH.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    pub(crate) settings: Settings,
    pub(crate) camera: PreparedCamera,
    pub(crate) lights: Vec<PreparedLight>,
    pub(crate) materials: Vec<PreparedMaterial>,
    /// Items with a finite bound, in BVH primitive order (so BVH ids index it directly).
    pub(crate) bounded: Vec<Item>,
    /// Planes, unbounded quadrics and CSG solids with an infinite bound: tested one by one.
    pub(crate) unbounded: Vec<Item>,
    /// The frames of the leaves whose material has a pattern.
    pub(crate) pattern_frames: PatternFrames,
    pub(crate) bvh: Option<Bvh>,
    /// Each light's light buffer (see `light_buffer.rs`), when it has one: the lights of
    /// scenes with opaque shadows and at most [`LIGHT_BUFFER_MAX_ITEMS`] bounded
    /// items.
    pub(crate) light_buffers: Vec<Option<LightBuffer>>,
    /// The bounded items' boxes, when there are light buffers: a blocker they find is
    /// taken when the shadow ray passes well inside its box.
    pub(crate) light_buffer_boxes: Vec<Aabb>,
    pub(crate) background: Vec3A,
    pub(crate) ambient: Vec3A,
    /// The scene's explicit surface offset; `None` for error-bounded offsets.
    pub(crate) epsilon: Option<f32>,
    pub(crate) shadows: ShadowMode,
    /// Whether any material has a nested-media priority: only then are coincident
    /// surfaces looked for and crossed together.
    pub(crate) nested_media: bool,
    /// Distinct meshes prepared, their triangles and their BVHs' nodes (each counted once
    /// however many objects instance it).
    mesh_count: usize,
    mesh_triangles: usize,
    mesh_bvh_nodes: usize,
    build_seconds: f64,
    shapes_seconds: f64,
    light_buffer_seconds: f64,
}

impl PreparedScene {
    /// How far a secondary or shadow ray starts off `surface`: the scene's explicit
    /// `epsilon`, or else just outside the hit point's error bound along the normal.
    #[inline]
    pub(crate) fn offset_at(&self, surface: &Surface<'_>) -> f32 {
        match self.epsilon {
            Some(epsilon) => epsilon,
            None => hit_error::spawn_offset(surface.geometric_normal, surface.error, surface.point),
        }
    }

    /// Prepares a validated scene: converts shapes (in parallel on the current rayon pool)
    /// and builds the BVH. The IR stays with the caller (the debugger, `trace` and the
    /// explanations need its names, spans and provenance).
    pub fn new(valid: &ValidScene) -> PreparedScene {
        PreparedScene::prepare(valid, Purpose::Render)
    }

    /// [`PreparedScene::new`] for a caller that records every ray it traces (`trace`,
    /// `explain`, `query`, `diff`): a recorder names each shadow ray's blocker, so it walks
    /// the BVH and never asks a light buffer, and building them would only add time and
    /// memory (on a grid of 65,025 spheres with two lights, about 20-40 ms and 9 MiB). Any
    /// unrecorded ray it traces is answered by the walk, with the same result.
    pub fn for_ray_trees(valid: &ValidScene) -> PreparedScene {
        PreparedScene::prepare(valid, Purpose::RayTrees)
    }

    fn prepare(valid: &ValidScene, purpose: Purpose) -> PreparedScene {
        let started = Instant::now();
        let shapes = Shapes::new(valid.scene());
        let shapes_seconds = started.elapsed().as_secs_f64();
        shapes.finish(started, shapes_seconds, purpose)
    }

    /// [`PreparedScene::new`] for a caller that needs nothing of the IR afterwards (`render`
    /// of a large scene): the IR is dropped as soon as the shapes are prepared, before the
    /// BVH build, whose temporary arrays are the peak of memory. The result is the same.
    pub fn new_releasing_ir(valid: ValidScene) -> PreparedScene {
        let started = Instant::now();
        // Only the objects, materials and meshes are read from here on.
        let mut scene = valid.into_inner();
        scene.provenance = Default::default();
        let shapes = Shapes::new_releasing(scene, RELEASE_CHUNK);
        let shapes_seconds = started.elapsed().as_secs_f64();
        shapes.finish(started, shapes_seconds, Purpose::Render)
    }

    /// The same scene answering every shadow ray by walking the BVH, as recorders do: for
    /// tests and measurements that compare the two (the image must be the same).
    pub fn without_light_buffers(mut self) -> PreparedScene {
        self.light_buffers = Vec::new();
        self.light_buffer_boxes = Vec::new();
        self
    }

    /// The scene's lights.
    pub fn light_count(&self) -> usize {
        self.lights.len()
    }

    /// How many lights have a light buffer, the candidates in them all, and the bytes
    /// they take (their cells and candidates, and the objects' boxes they share).
    pub fn light_buffer_sizes(&self) -> (usize, usize, usize) {
        let buffers = self.light_buffers.iter().flatten();
        let bytes = buffers.clone().map(LightBuffer::bytes).sum::<usize>()
            + std::mem::size_of_val(self.light_buffer_boxes.as_slice());
        (
            buffers.clone().count(),
            buffers.map(LightBuffer::len).sum(),
            bytes,
        )
    }

    /// Seconds spent in [`PreparedScene::new`]: shape preparation and the BVH build.
    pub fn build_seconds(&self) -> f64 {
        self.build_seconds
    }

    /// The part of [`PreparedScene::build_seconds`] spent building the light buffers (after
    /// the BVH, whose boxes they take).
    pub fn light_buffer_seconds(&self) -> f64 {
        self.light_buffer_seconds
    }

    /// The part of [`PreparedScene::build_seconds`] spent preparing the shapes (and, for a
    /// released IR, freeing it); the rest built the BVH.
    pub fn shapes_seconds(&self) -> f64 {
        self.shapes_seconds
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Top-level objects after flattening groups (a CSG solid counts once).
    pub fn object_count(&self) -> usize {
        self.bounded.len() + self.unbounded.len()
    }

    /// Nodes in the BVH (0 when there is none).
    pub fn bvh_node_count(&self) -> usize {
        self.bvh.as_ref().map_or(0, Bvh::node_count)
    }

    /// Distinct meshes the scene holds (instances share one).
    pub fn mesh_count(&self) -> usize {
        self.mesh_count
    }

    /// Triangles over the distinct meshes (instances do not add any).
    pub fn mesh_triangle_count(&self) -> usize {
        self.mesh_triangles
    }

    /// Nodes over the distinct meshes' own BVHs.
    pub fn mesh_bvh_node_count(&self) -> usize {
        self.mesh_bvh_nodes
    }

    /// How many of those are unbounded (planes and the like) and kept out of the BVH.
    pub fn unbounded_count(&self) -> usize {
        self.unbounded.len()
    }
}

/// Items prepared between two releases of objects by [`PreparedScene::new_releasing_ir`]:
/// large enough for rayon to share out, small beside a million.
const RELEASE_CHUNK: usize = 1 << 16;

/// A scene's shapes prepared but not yet in BVH order: what [`PreparedScene`] needs of the
/// IR, taken out of it, so that the IR can be dropped before the BVH build.
struct Shapes {
    settings: Settings,
    camera: PreparedCamera,
    lights: Vec<PreparedLight>,
    materials: Vec<PreparedMaterial>,
    nested_media: bool,
    mesh_count: usize,
    mesh_triangles: usize,
    mesh_bvh_nodes: usize,
    /// Bounded items in scene order, with their boxes (the same length).
    bounded: Vec<Item>,
    boxes: Vec<PrimitiveBox>,
    unbounded: Vec<Item>,
    pattern_frames: PatternFrames,
}

impl Shapes {
    fn new(scene: &Scene) -> Shapes {
        let (shapes, meshes) = Shapes::without_items(scene);
        let shared = Shared {
            materials: &shapes.materials,
            meshes: &meshes,
            frames: Mutex::default(),
        };
        let roots = flatten_groups(scene);
        let (items, boxes) = prepare_items(scene, &shared, &roots);
        let frames = shared.into_frames();
        shapes.with_items(items, boxes, frames)
    }

    /// [`Shapes::new`] that frees the scene's objects as it goes: the items are prepared
    /// from the last to the first, a chunk at a time, and after each chunk the objects that
    /// no item still to come can reach are dropped (an object's parts come before it in the
    /// arena, so an item reaches no object after its own). For a million objects made by a
    /// loop the IR and the items then never coexist in full.
    fn new_releasing(mut scene: Scene, chunk_len: usize) -> Shapes {
        let (shapes, meshes) = Shapes::without_items(&scene);
        let shared = Shared {
            materials: &shapes.materials,
            meshes: &meshes,
            frames: Mutex::default(),
        };
        let roots = flatten_groups(&scene);
        // The last object each chunk's predecessors can reach.
        let mut reach_before = Vec::with_capacity(roots.len().div_ceil(chunk_len));
        let mut reach = None;
        for chunk in roots.chunks(chunk_len) {
            reach_before.push(reach);
            reach = chunk.iter().map(|h| h.index()).chain(reach).max();
        }
        // The chunks come last first, so the arrays are filled backwards (each chunk's
        // items reversed, straight into the arrays' spare room) and turned round at the
        // end, in place: no chunk is held apart and copied.
        let mut reversed = (
            Vec::with_capacity(roots.len()),
            Vec::with_capacity(roots.len()),
        );
        // The items without a finite bound leave as each chunk is made, so that only the
        // items after them in their chunk move (all million after the floor, moved at the
        // end, took 8 ms).
        let mut unbounded = Vec::new();
        for (chunk, reach) in roots.chunks(chunk_len).zip(reach_before).rev() {
            let start = reversed.0.len();
            reversed.par_extend(
                chunk
                    .par_iter()
                    .rev()
                    .map(|&handle| prepare_boxed_item(&scene, &shared, handle)),
            );
            unbounded.extend(split_unbounded(&mut reversed.0, &mut reversed.1, start));
            scene.objects.truncate(reach.map_or(0, |last| last + 1));
        }
        drop(scene);
        let frames = shared.into_frames();
        let (mut items, mut boxes): (Vec<Item>, Vec<PrimitiveBox>) = reversed;
        items.reverse();
        boxes.reverse();
        unbounded.reverse();
        shapes.with_split_items(items, boxes, unbounded, frames)
    }

    /// Everything but the items, and the prepared meshes the items will share.
    fn without_items(scene: &Scene) -> (Shapes, Vec<Arc<PreparedMesh>>) {
        let materials: Vec<PreparedMaterial> = scene
            .materials
            .iter()
            .map(|(_, m)| {
                let mut prepared = PreparedMaterial::new(m);
                // `fresnel` in the settings overrides every material's own.
                if let Some(fresnel) = scene.settings.fresnel_rule {
                    prepared.fresnel = fresnel;
                }
                prepared
            })
            .collect();
        let lights = scene
            .lights
            .iter()
            .map(|(handle, light)| PreparedLight::new(handle, light, &scene.settings))
            .collect();
        // Each mesh once (in parallel), shared by every object that instances it.
        let meshes: Vec<Arc<PreparedMesh>> = scene
            .meshes
            .iter()
            .collect::<Vec<_>>()
            .par_iter()
            .map(|(_, mesh)| Arc::new(PreparedMesh::new(mesh)))
            .collect();
        let shapes = Shapes {
            settings: scene.settings.clone(),
            camera: PreparedCamera::new(&scene.camera)
                .placing_samples(scene.settings.sample_position),
            lights,
            nested_media: scene.materials.iter().any(|(_, m)| m.priority != 0),
            mesh_count: meshes.len(),
            mesh_triangles: meshes.iter().map(|m| m.triangle_count()).sum(),
            mesh_bvh_nodes: meshes.iter().map(|m| m.bvh_node_count()).sum(),
            materials,
            bounded: Vec::new(),
            boxes: Vec::new(),
            unbounded: Vec::new(),
            pattern_frames: PatternFrames::default(),
        };
        (shapes, meshes)
    }

    /// Takes the prepared items with their bounds stored as boxes (see [`bound_as_box`]),
    /// in scene order, and keeps them apart by bound, in place.
    fn with_items(
        self,
        mut bounded: Vec<Item>,
        mut boxes: Vec<PrimitiveBox>,
        pattern_frames: PatternFrames,
    ) -> Shapes {
        let unbounded = split_unbounded(&mut bounded, &mut boxes, 0);
        self.with_split_items(bounded, boxes, unbounded, pattern_frames)
    }

    /// Takes the prepared items already kept apart by bound, in scene order.
    fn with_split_items(
        self,
        bounded: Vec<Item>,
        boxes: Vec<PrimitiveBox>,
        unbounded: Vec<Item>,
        pattern_frames: PatternFrames,
    ) -> Shapes {
        Shapes {
            bounded,
            boxes,
            unbounded,
            pattern_frames,
            ..self
        }
    }

    /// Builds the BVH and puts the bounded items in its primitive order.
    fn finish(self, started: Instant, shapes_seconds: f64, purpose: Purpose) -> PreparedScene {
        let Shapes {
            settings,
            camera,
            lights,
            materials,
            nested_media,
            mesh_count,
            mesh_triangles,
            mesh_bvh_nodes,
            bounded,
            boxes,
            unbounded,
            pattern_frames,
        } = self;
        let wants_buffers = purpose == Purpose::Render
            && LIGHT_BUFFERS.load(Ordering::Relaxed)
            && settings.shadows == ShadowMode::Opaque
            && bounded.len() > LINEAR_LIMIT
            && bounded.len() <= LIGHT_BUFFER_MAX_ITEMS
            && !lights.is_empty();
        let (bounded, bvh, kept_boxes) = build_bvh(bounded, boxes, wants_buffers);
        let buffers_started = Instant::now();
        let (light_buffers, light_buffer_boxes) = match (&bvh, kept_boxes) {
            (Some(_), Some(boxes)) => (light_buffers(&lights, &boxes), boxes),
            _ => (Vec::new(), Vec::new()),
        };
        let light_buffer_seconds = buffers_started.elapsed().as_secs_f64();
        PreparedScene {
            light_buffers,
            light_buffer_boxes,
            mesh_count,
            mesh_triangles,
            mesh_bvh_nodes,
            camera,
            lights,
            materials,
            bounded,
            unbounded,
            pattern_frames,
            bvh,
            background: color(&settings.background),
            ambient: color(&settings.ambient),
            epsilon: settings.epsilon.map(|e| e as f32),
            shadows: settings.shadows,
            nested_media,
            settings,
            build_seconds: started.elapsed().as_secs_f64(),
            shapes_seconds,
            light_buffer_seconds,
        }
    }
}

/// Takes the items from `from` on whose bound (stored as a box, see [`bound_as_box`]) is
/// not finite out of `items`, and their boxes out of `boxes`, keeping the others' order:
/// returns the unbounded ones in order (they are tested one by one) and drops the empty
/// ones (never hit).
fn split_unbounded(items: &mut Vec<Item>, boxes: &mut Vec<PrimitiveBox>, from: usize) -> Vec<Item> {
    let finite = |stored: &PrimitiveBox| matches!(box_as_bound(stored), Bound::Finite(_));
    if boxes.get(from..).unwrap_or_default().iter().all(finite) {
        return Vec::new();
    }
    let mut position = from;
    let mut infinite = Vec::new();
    let extracted: Vec<Item> = items
        .extract_if(from.., |_| {
            let bound = boxes.get(position).map_or(Bound::Empty, box_as_bound);
            position += 1;
            let finite = matches!(bound, Bound::Finite(_));
            if !finite {
                infinite.push(bound == Bound::Infinite);
            }
            !finite
        })
        .collect();
    // The boxes' part of the same compaction, in place.
    let mut kept = from;
    for i in from..boxes.len() {
        let stored = boxes[i];
        if finite(&stored) {
            boxes[kept] = stored;
            kept += 1;
        }
    }
    boxes.truncate(kept);
    extracted
        .into_iter()
        .zip(infinite)
        .filter_map(|(item, infinite)| infinite.then_some(item))
        .collect()
}

/// The objects to render, with groups replaced by their members (depth first, in source
/// order). An explicit stack, so deep nesting cannot overflow the call stack.
fn flatten_groups(scene: &Scene) -> Vec<Handle<Object>> {
    let mut out = Vec::with_capacity(scene.roots.len());
    let mut stack: Vec<Handle<Object>> = scene.roots.iter().rev().copied().collect();
    while let Some(handle) = stack.pop() {
        match &scene.objects[handle].kind {
            ObjectKind::Group { children } => stack.extend(children.iter().rev().copied()),
            ObjectKind::Shape { .. } | ObjectKind::Csg { .. } => out.push(handle),
        }
    }
    out
}

/// A bound as the BVH build's plain box, so that a million of them take 28 bytes each (a
/// `Bound` takes 48) and the build takes them over as they are: a finite bound is its box;
/// the empty and the unbounded are boxes with a NaN corner, which no finite bound has (one
/// that did would be tested as unbounded: always right).
fn bound_as_box(bound: Bound) -> PrimitiveBox {
    let marked = |max: f32| Aabb::new(Vec3A::splat(f32::NAN), Vec3A::splat(max));
    PrimitiveBox::new(&match bound {
        Bound::Finite(aabb) if !(aabb.min.is_nan_mask().any() || aabb.max.is_nan_mask().any()) => {
            aabb
        }
        Bound::Empty => marked(0.0),
        Bound::Finite(_) | Bound::Infinite => marked(1.0),
    })
}

/// The bound [`bound_as_box`] stored.
fn box_as_bound(stored: &PrimitiveBox) -> Bound {
    let aabb = stored.aabb();
    if !aabb.min.x.is_nan() {
        Bound::Finite(aabb)
    } else if aabb.max.x == 0.0 {
        Bound::Empty
    } else {
        Bound::Infinite
    }
}

/// The items of `roots` (in parallel), each beside its bound stored as a box. Memory
/// dominates scenes of a million objects: an item is made once, and its bound takes 28
/// bytes this way (a `Bound` takes 48).
fn prepare_items(
    scene: &Scene,
    shared: &Shared<'_>,
    roots: &[Handle<Object>],
) -> (Vec<Item>, Vec<PrimitiveBox>) {
    roots
        .par_iter()
        .map(|&handle| prepare_boxed_item(scene, shared, handle))
        .unzip()
}

/// An item beside its bound stored as a box (see [`bound_as_box`]).
fn prepare_boxed_item(
    scene: &Scene,
    shared: &Shared<'_>,
    handle: Handle<Object>,
) -> (Item, PrimitiveBox) {
    let (item, bound) = prepare_item(scene, shared, handle);
    (item, bound_as_box(bound))
}

/// What every item's preparation reads (the prepared materials and meshes), and where it
/// leaves the patterned leaves' frames (in any order: preparation is parallel).
struct Shared<'a> {
    materials: &'a [PreparedMaterial],
    meshes: &'a [Arc<PreparedMesh>],
    frames: Mutex<Vec<(Handle<Object>, PatternFrame)>>,
}

impl Shared<'_> {
    fn into_frames(self) -> PatternFrames {
        PatternFrames::new(self.frames.into_inner().unwrap_or_else(|e| e.into_inner()))
    }
}

fn prepare_item(scene: &Scene, shared: &Shared<'_>, handle: Handle<Object>) -> (Item, Bound) {
    match &scene.objects[handle].kind {
        ObjectKind::Csg { .. } => {
            let tree = build_csg(scene, shared, handle);
            let bound = match tree.nodes.last() {
                Some(CsgNode::Leaf { bound, .. } | CsgNode::Op { bound, .. }) => *bound,
                None => Bound::Empty,
            };
            let item = Item::Csg {
                object: handle,
                tree: Box::new(tree),
            };
            (item, bound)
        }
        ObjectKind::Shape { .. } | ObjectKind::Group { .. } => {
            let (leaf, bound) = prepare_leaf(scene, shared, handle);
            (Item::Shape(leaf), bound)
        }
    }
}

/// A leaf and its bound; its pattern frame, when its material has a pattern, goes to
/// `shared.frames`.
fn prepare_leaf(scene: &Scene, shared: &Shared<'_>, handle: Handle<Object>) -> (Leaf, Bound) {
    let materials = shared.materials;
    let object = &scene.objects[handle];
    // Projective rows are ignored: the language only makes affine transforms.
    let world_from_object = DAffine3::from_mat4(object.world_from_object.matrix());
    let (geometry, bound, snap) = match object.kind.shape() {
        Some(Shape::Mesh { mesh, smooth }) => match shared.meshes.get(mesh.index()) {
            Some(prepared) => {
                let (instance, bound) =
                    MeshInstance::new(Arc::clone(prepared), smooth, &world_from_object);
                (Geometry::Mesh(Box::new(instance)), bound, Snap::None)
            }
            // Validation refuses a missing mesh; should one arrive, it is nothing.
            None => (
                Geometry::Plane {
                    normal: glam::Vec3::Y,
                    offset: 0.0,
                },
                Bound::Empty,
                Snap::None,
            ),
        },
        Some(shape) => {
            let (geometry, bound) = Geometry::new(&shape, &world_from_object);
            let snap = match shape {
                Shape::Plane { normal, offset } => Snap::plane(normal, offset),
                Shape::Box { min, max } => Snap::Box {
                    min: min.as_vec3a(),
                    max: max.as_vec3a(),
                },
                _ => Snap::None,
            };
            (geometry, bound, snap)
        }
        // Validation keeps groups out of CSG and flattening keeps them out of items; should
        // one arrive anyway it is an empty solid.
        None => (
            Geometry::Plane {
                normal: glam::Vec3::Y,
                offset: 0.0,
            },
            Bound::Empty,
            Snap::None,
        ),
    };
    let patterned = materials
        .get(object.material.index())
        .is_some_and(|m| m.pattern.is_some());
    if patterned {
        let frame = PatternFrame {
            object_from_world: world_from_object.inverse().as_affine3a(),
            world_from_object: world_from_object.as_affine3a(),
            snap,
        };
        // A worker that panicked has already taken the preparation down with it.
        let mut frames = shared.frames.lock().unwrap_or_else(|e| e.into_inner());
        frames.push((handle, frame));
    }
    let leaf = Leaf {
        geometry,
        object: handle,
        material: object.material,
    };
    (leaf, bound)
}

/// Builds a CSG tree bottom-up (post-order over an explicit stack). Node bounds: a union
/// is bounded by its children's union, an intersection by their intersection, a
/// difference by its first child.
fn build_csg(scene: &Scene, shared: &Shared<'_>, root: Handle<Object>) -> CsgTree {
    let mut tree = CsgTree::default();
    let mut work: Vec<(Handle<Object>, bool)> = vec![(root, false)];
    let mut finished: Vec<u32> = Vec::new();
    while let Some((handle, expanded)) = work.pop() {
        match &scene.objects[handle].kind {
            ObjectKind::Csg { children, .. } if !expanded => {
                work.push((handle, true));
                work.extend(children.iter().rev().map(|&child| (child, false)));
            }
            ObjectKind::Csg { op, children } => {
                let child_nodes = finished.split_off(finished.len().saturating_sub(children.len()));
                let child_bounds: Vec<Bound> = child_nodes
                    .iter()
                    .map(|&n| node_bound(&tree.nodes[n as usize]))
                    .collect();
                let bounds = child_bounds.iter().copied();
                let bound = match op {
                    CsgOp::Union => bounds.fold(Bound::Empty, Bound::union),
                    CsgOp::Intersection => {
                        bounds.reduce(Bound::intersection).unwrap_or(Bound::Empty)
                    }
                    CsgOp::Difference => bounds.take(1).next().unwrap_or(Bound::Empty),
                };
                let accel = match ChildAccel::new(*op, &child_bounds) {
                    Some(accel) => {
                        tree.accels.push(accel);
                        tree.accels.len() as u32 - 1
                    }
                    None => NO_ACCEL,
                };
                let first_child = tree.children.len() as u32;
                tree.children.extend_from_slice(&child_nodes);
                tree.nodes.push(CsgNode::Op {
                    op: *op,
                    first_child,
                    child_count: child_nodes.len() as u32,
                    bound,
                    accel,
                });
                finished.push(tree.nodes.len() as u32 - 1);
            }
            ObjectKind::Shape { .. } | ObjectKind::Group { .. } => {
                let (leaf, bound) = prepare_leaf(scene, shared, handle);
                tree.leaves.push(leaf);
                tree.nodes.push(CsgNode::Leaf {
                    leaf: tree.leaves.len() as u32 - 1,
                    bound,
                });
                finished.push(tree.nodes.len() as u32 - 1);
            }
        }
    }
    tree
}

fn node_bound(node: &CsgNode) -> Bound {
    match node {
        CsgNode::Leaf { bound, .. } | CsgNode::Op { bound, .. } => *bound,
    }
}

/// Builds the BVH over `boxes` (one per item) and returns the items in BVH primitive
/// order. The boxes are handed to the build, which makes its leaves of them in place, and
/// the items are moved in place beside them, so that no second copy of a million boxes or
/// items exists at any time.
fn build_bvh(
    mut items: Vec<Item>,
    boxes: Vec<PrimitiveBox>,
    keep_boxes: bool,
) -> (Vec<Item>, Option<Bvh>, Option<Vec<Aabb>>) {
    if items.is_empty() || items.len() > whitted_bvh::MAX_PRIMITIVES {
        return (items, None, None);
    }
    if keep_boxes {
        // A scene small enough for light buffers: its boxes move with its items.
        let kept: Vec<Aabb> = boxes.iter().map(PrimitiveBox::aabb).collect();
        let mut paired: Vec<(Item, Aabb)> = items.into_iter().zip(kept).collect();
        let bvh = Bvh::build_ordering(boxes, &mut paired);
        let (items, kept) = paired.into_iter().unzip();
        return (items, bvh, Some(kept));
    }
    // No BVH (obvhs never fails to make one without spatial splits): every item is still
    // there once, and all are tested, which is slow but right.
    let bvh = Bvh::build_ordering(boxes, &mut items);
    (items, bvh, None)
}

/// What a scene is prepared for, which decides whether its lights get light buffers.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Purpose {
    /// Images: most shadow rays are unrecorded, and a light buffer answers them.
    Render,
    /// Ray trees: every shadow ray is recorded and walks the BVH.
    RayTrees,
}

/// Whether scenes prepared from now on get light buffers (see [`use_light_buffers`]).
static LIGHT_BUFFERS: AtomicBool = AtomicBool::new(true);

/// Whether scenes prepared from now on give their lights light buffers
/// (the default), or answer every shadow ray by walking the BVH: the image is the same
/// either way, so this is for comparing their speed (`WHITTED_LIGHT_BUFFERS=off`).
pub fn use_light_buffers(enabled: bool) {
    LIGHT_BUFFERS.store(enabled, Ordering::Relaxed);
}

/// Up to this many bounded items, lights get light buffers. A buffer takes about 0.2 µs an
/// item to build: the grid of 99,856 spheres, with two lights, built in 0.088 s instead
/// of 0.049 and rendered 640x480 8 ms faster (13.0 -> 14.4 Mrays per CPU-second), so above
/// this the build can cost more than the shadow rays save.
pub(crate) const LIGHT_BUFFER_MAX_ITEMS: usize = 1 << 16;
/// Most candidates (8 bytes each) and cells (4) in all the light buffers of a scene
/// together: at most 32 MiB.
const LIGHT_BUFFER_BUDGET: usize = 1 << 22;

/// The lights' buffers over the bounded items' boxes (in BVH order), in the lights' order,
/// while the budget lasts; each light's buffer holds at most 64 candidates an item.
fn light_buffers(lights: &[PreparedLight], boxes: &[Aabb]) -> Vec<Option<LightBuffer>> {
    let mut left = LIGHT_BUFFER_BUDGET;
    lights
        .iter()
        .map(|light| {
            let most = left.min(64 * boxes.len() + 4096);
            let buffer = match light.kind {
                PreparedLightKind::Point { position, .. }
                | PreparedLightKind::Spot { position, .. } => {
                    LightBuffer::new(position, boxes, most)
                }
                PreparedLightKind::Directional { to_light } => {
                    LightBuffer::new_parallel(to_light, boxes, most)
                }
            }?;
            left -= buffer.budget_used().min(left);
            Some(buffer)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{render, NoObserver, RenderOptions};
    use crate::testing::{sphere_grid, whitted_classic};

    /// A patterned leaf finds its frame alone and as a CSG leaf: a checkered sphere
    /// shows both its colours as a plain item, as the only child of a union, and as one of
    /// two children whose other has no pattern (a lost frame would leave the pattern
    /// material's own grey).
    #[test]
    fn patterned_leaves_keep_their_frames_alone_and_in_csg() {
        use crate::testing::{checker, matte, sphere, SceneBuilder};
        use glam::{DMat4, DVec3};
        use whitted_ir::CsgOp;
        let id = DMat4::IDENTITY;
        let scene = |csg: Option<bool>| {
            let mut b = SceneBuilder::new();
            b.camera(DVec3::new(0.0, 0.0, -4.0), DVec3::ZERO, 40.0);
            b.point_light(DVec3::new(0.0, 0.0, -10.0), 1.0);
            let checker = checker(&mut b, matte(1.0, 0.0, 0.0), matte(0.0, 0.0, 1.0), 0.25);
            let ball = sphere(0.0, 0.0, 0.0, 1.0);
            match csg {
                None => {
                    b.add(ball, id, checker);
                }
                Some(with_plain_sibling) => {
                    let mut children = Vec::new();
                    if with_plain_sibling {
                        let grey = b.material(matte(0.5, 0.5, 0.5));
                        children.push(b.part(sphere(5.0, 0.0, 0.0, 0.5), id, grey));
                    }
                    children.push(b.part(ball, id, checker));
                    b.csg(CsgOp::Union, children, checker);
                }
            }
            b.prepare().expect("valid")
        };
        for csg in [None, Some(false), Some(true)] {
            let prepared = scene(csg);
            let mut options = RenderOptions::from_settings(&prepared.settings);
            options.width = 32;
            options.height = 32;
            let pixels = render(&prepared, &options, &NoObserver)
                .expect("done")
                .0
                .pixels;
            let reds = pixels.iter().filter(|p| p[0] > 0.2 && p[2] < 0.01).count();
            let blues = pixels.iter().filter(|p| p[2] > 0.2 && p[0] < 0.01).count();
            assert!(reds > 20 && blues > 20, "{csg:?}: {reds} red, {blues} blue");
        }
    }

    /// Each patterned leaf finds its own frame, whatever order parallel preparation handed
    /// them over in; objects before, between and after them find none.
    #[test]
    fn pattern_frames_are_found_by_object() {
        let frame = |x: f32| PatternFrame {
            object_from_world: glam::Affine3A::from_translation(glam::Vec3::new(x, 0.0, 0.0)),
            world_from_object: glam::Affine3A::from_translation(glam::Vec3::new(-x, 0.0, 0.0)),
            snap: Snap::None,
        };
        let handles = [9, 3, 7, 5, 3].map(Handle::<Object>::from_index);
        let frames = PatternFrames::new(
            handles
                .iter()
                .map(|&h| (h, frame(h.index() as f32)))
                .collect(),
        );
        for h in handles {
            assert_eq!(frames.get(h), Some(&frame(h.index() as f32)), "{h}");
        }
        for missing in [0, 2, 4, 6, 8, 10, u32::MAX as usize] {
            assert_eq!(frames.get(Handle::from_index(missing)), None, "{missing}");
        }
        assert_eq!(PatternFrames::default().get(handles[0]), None);
        assert_eq!(PatternFrames::new(Vec::new()).get(handles[0]), None);
    }

    /// Dropping the IR before the BVH build changes nothing a render sees.
    #[test]
    fn releasing_the_ir_prepares_the_same_scene() {
        for builder in [whitted_classic(), sphere_grid(12)] {
            let valid = builder.build().expect("valid");
            let kept = PreparedScene::new(&valid);
            let mut options = RenderOptions::from_settings(&valid.scene().settings);
            options.width = 48;
            options.height = 36;
            let released = PreparedScene::new_releasing_ir(valid);
            assert_eq!(kept.object_count(), released.object_count());
            assert_eq!(kept.bvh_node_count(), released.bvh_node_count());
            let image =
                |scene: &PreparedScene| render(scene, &options, &NoObserver).expect("done").0;
            assert_eq!(image(&kept).pixels, image(&released).pixels);
        }
    }

    /// Preparing from the end while releasing objects gives the items, bounds and order of
    /// preparing with the whole IR, whatever the chunks, with CSG parts and group members
    /// before their parents, unbounded and empty objects among bounded ones, and top-level
    /// objects out of arena order.
    #[test]
    fn releasing_objects_chunk_by_chunk_prepares_the_same_shapes() {
        use crate::testing::{matte, plane_y, sphere, SceneBuilder};
        use glam::DMat4;
        use whitted_ir::CsgOp;
        let mut b = SceneBuilder::new();
        let m = b.material(matte(0.5, 0.5, 0.5));
        let id = DMat4::IDENTITY;
        let first = b.add(sphere(0.0, 0.0, 0.0, 1.0), id, m);
        let second = b.add(sphere(0.0, 0.0, 3.0, 1.0), id, m);
        for i in 0..4 {
            b.add(sphere(f64::from(i) * 3.0, 1.0, 0.0, 1.0), id, m);
        }
        let p = b.part(sphere(0.0, 5.0, 0.0, 1.0), id, m);
        let q = b.part(sphere(0.5, 5.0, 0.0, 1.0), id, m);
        b.csg(CsgOp::Difference, vec![p, q], m);
        b.add(plane_y(-1.0), id, m);
        let r = b.part(sphere(0.0, -5.0, 0.0, 1.0), id, m);
        let s = b.part(plane_y(2.0), id, m);
        b.group(vec![r, s]);
        let t = b.part(sphere(9.0, 0.0, 0.0, 1.0), id, m);
        let u = b.part(sphere(20.0, 0.0, 0.0, 1.0), id, m);
        // Disjoint: an empty solid.
        b.csg(CsgOp::Intersection, vec![t, u], m);
        for i in 0..4 {
            b.add(sphere(f64::from(i) * 3.0, -3.0, 1.0, 0.5), id, m);
        }
        // The first two objects last at the top level.
        for early in [first, second] {
            b.demote(early);
            b.promote(early);
        }
        let valid = b.build().expect("valid");
        let key = |shapes: &Shapes| {
            let objects = |items: &[Item]| items.iter().map(Item::object).collect::<Vec<_>>();
            let boxes: Vec<_> = shapes
                .boxes
                .iter()
                .map(|stored| {
                    let a = stored.aabb();
                    (a.min.to_array(), a.max.to_array())
                })
                .collect();
            (objects(&shapes.bounded), boxes, objects(&shapes.unbounded))
        };
        let whole = key(&Shapes::new(valid.scene()));
        assert_eq!(whole.0.len(), 12);
        assert_eq!(whole.2.len(), 2);
        for chunk_len in [1, 2, 3, 5, 100] {
            let scene = valid.scene().clone();
            let released = key(&Shapes::new_releasing(scene, chunk_len));
            assert!(released == whole, "chunks of {chunk_len}");
        }
    }

    /// Bounds stored as boxes come back as they went in; a finite box with a NaN corner
    /// (which no bound computation makes) comes back unbounded, which is tested by itself.
    #[test]
    fn bounds_survive_being_stored_as_boxes() {
        let aabb = Aabb::new(Vec3A::new(-1.0, -0.0, 2.0), Vec3A::new(0.0, 5.0, 2.5));
        for bound in [Bound::Empty, Bound::Infinite, Bound::Finite(aabb)] {
            assert_eq!(box_as_bound(&bound_as_box(bound)), bound);
        }
        let broken = Aabb::new(Vec3A::new(0.0, f32::NAN, 0.0), Vec3A::ONE);
        assert_eq!(
            box_as_bound(&bound_as_box(Bound::Finite(broken))),
            Bound::Infinite
        );
    }

    /// A million of these must stay cheap to build and to walk: 32 MB, not 48.
    #[test]
    fn items_stay_small() {
        assert_eq!(std::mem::size_of::<Geometry>(), 24);
        assert_eq!(std::mem::size_of::<Leaf>(), 32);
        assert_eq!(std::mem::size_of::<Item>(), 32);
        assert_eq!(
            std::mem::size_of::<Option<Item>>(),
            std::mem::size_of::<Item>()
        );
    }
}
