//! The recorder that builds a ray tree: it listens to the one tracing code path (see
//! `recorder.rs` for the order of hooks) and turns each ray's hooks into a [`RayNode`].
//!
//! Rays nest: a stack holds the rays started but not yet finished; a finished ray becomes
//! the last child of the ray below it, or the tree's root when the stack is empty.
//!
//! A tree holds at most `budget` nodes plus one camera ray per sample (a hall of mirrors with
//! no minimum weight has millions of rays). Past the budget the tracer goes on, so every colour stays exact, but
//! new rays are only counted: each recorded ray says in `unrecorded` how many rays below it
//! were traced and not kept, which is where the tree was cut.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::Vec3A;
use whitted_ir::{LightKind, Scene};

use super::model::{
    BlendInfo, Blocker, CoincidentInfo, ConeInfo, HitInfo, InterfaceInfo, LightContribution,
    LocalIllumination, RayNode, ShadowInfo, ShadowOutcome, SkippedInfo, Visibility,
};
use super::scene_refs::{csg_path, light_ref, material_ref, object_ref};
use crate::recorder::{
    CoincidentSurface, Interface, LightSample, NoShadowRay, RayKind, RayStart, Recorder,
    ShadowResult, SkippedRay, SurfaceHit, Termination,
};

/// Records every ray of one camera ray's tree. Names and source locations come from
/// `scene`, which must be the scene the traced `PreparedScene` was made from.
pub struct TreeRecorder<'s> {
    scene: &'s Scene,
    open: Vec<RayNode>,
    /// The local colour summed so far for each open ray, in the tracer's order (so that
    /// `LocalIllumination::total` is bit-identical to what the tracer added).
    local_sums: Vec<Vec3A>,
    root: Option<RayNode>,
    /// The most nodes to keep, and how many were kept so far (over every camera ray).
    budget: usize,
    recorded: usize,
    /// Rays started and not yet finished that are not recorded (past the budget).
    dropped_open: usize,
    /// Rays traced but not recorded, over every camera ray.
    unrecorded: u64,
    /// Set by another thread to stop the trace early (see [`Recorder::should_stop`]).
    cancel: Option<&'s AtomicBool>,
}

impl<'s> TreeRecorder<'s> {
    /// A recorder with the default budget, [`whitted_ir::limits::MAX_RAY_TREE_NODES`].
    pub fn new(scene: &'s Scene) -> TreeRecorder<'s> {
        TreeRecorder::with_budget(scene, whitted_ir::limits::MAX_RAY_TREE_NODES, None)
    }

    /// A recorder that keeps at most `budget` nodes and stops the trace when `cancel` is set.
    pub fn with_budget(
        scene: &'s Scene,
        budget: usize,
        cancel: Option<&'s AtomicBool>,
    ) -> TreeRecorder<'s> {
        TreeRecorder {
            scene,
            open: Vec::new(),
            local_sums: Vec::new(),
            root: None,
            budget,
            recorded: 0,
            dropped_open: 0,
            unrecorded: 0,
            cancel,
        }
    }

    /// Rays traced but not recorded because the budget was reached, over every camera ray.
    pub fn unrecorded(&self) -> u64 {
        self.unrecorded
    }

    /// Whether the budget has room for one more node; if not, counts the ray as unrecorded
    /// on the nearest recorded ray.
    fn admit(&mut self) -> bool {
        if self.dropped_open == 0 && self.recorded < self.budget {
            self.recorded += 1;
            return true;
        }
        self.unrecorded += 1;
        if let Some(node) = self.open.last_mut() {
            node.unrecorded += 1;
        }
        false
    }

    /// The finished camera ray's tree, once the tracer has returned; the recorder is then
    /// ready for another camera ray.
    pub fn take_root(&mut self) -> Option<RayNode> {
        self.root.take()
    }
}

impl Recorder for TreeRecorder<'_> {
    fn ray_started(&mut self, ray: &RayStart) {
        // Camera rays are the samples' roots and always kept, so that every sample says
        // where its tree was cut.
        if ray.kind == RayKind::Camera {
            self.recorded += 1;
        } else if !self.admit() {
            self.dropped_open += 1;
            return;
        }
        self.open.push(RayNode {
            kind: ray.kind,
            depth: ray.depth,
            origin: ray.origin.to_array(),
            direction: ray.direction.to_array(),
            weight: ray.weight.to_array(),
            coefficient: ray.coefficient.to_array(),
            interface: ray.interface.as_ref().map(interface_info),
            hit: None,
            local: None,
            shadow: None,
            color: [0.0; 3],
            termination: Termination::NotEnded,
            skipped: Vec::new(),
            children: Vec::new(),
            unrecorded: 0,
        });
        self.local_sums.push(Vec3A::ZERO);
    }

    fn should_stop(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
    }

    fn surface_hit(&mut self, hit: &SurfaceHit) {
        if self.dropped_open > 0 {
            return;
        }
        let scene = self.scene;
        let Some(node) = self.open.last_mut() else {
            return;
        };
        node.hit = Some(HitInfo {
            t: hit.t,
            point: hit.point.to_array(),
            geometric_normal: hit.geometric_normal.to_array(),
            shading_normal: hit.shading_normal.to_array(),
            front_face: hit.front_face,
            object: object_ref(scene, hit.object),
            leaf: object_ref(scene, hit.leaf),
            csg_path: csg_path(scene, hit.object, hit.leaf),
            material: material_ref(scene, hit.material),
            resolved_material: material_ref(scene, hit.resolved_material),
            blend: hit.blend.map(|b| BlendInfo {
                first: material_ref(scene, b.first),
                second: material_ref(scene, b.second),
                weight: b.weight,
            }),
            absorption: hit.absorption.to_array(),
            error_bound: hit.error_bound,
            offset: hit.offset,
            coincident: Vec::new(),
        });
    }

    fn coincident_surface(&mut self, other: &CoincidentSurface) {
        if self.dropped_open > 0 {
            return;
        }
        let scene = self.scene;
        let Some(hit) = self.open.last_mut().and_then(|node| node.hit.as_mut()) else {
            return;
        };
        hit.coincident.push(CoincidentInfo {
            t: other.t,
            object: object_ref(scene, other.object),
            leaf: object_ref(scene, other.leaf),
            material: material_ref(scene, other.material),
        });
    }

    fn ambient(&mut self, ambient: Vec3A) {
        if self.dropped_open > 0 {
            return;
        }
        let (Some(node), Some(sum)) = (self.open.last_mut(), self.local_sums.last_mut()) else {
            return;
        };
        *sum = ambient;
        node.local = Some(LocalIllumination {
            ambient: ambient.to_array(),
            emission: [0.0; 3],
            lights: Vec::new(),
            total: ambient.to_array(),
        });
    }

    fn emission(&mut self, emission: Vec3A) {
        if self.dropped_open > 0 {
            return;
        }
        let (Some(node), Some(sum)) = (self.open.last_mut(), self.local_sums.last_mut()) else {
            return;
        };
        // The tracer's own order: `ambient + emission`, before any light.
        *sum += emission;
        if let Some(local) = node.local.as_mut() {
            local.emission = emission.to_array();
            local.total = sum.to_array();
        }
    }

    fn light_sampled(&mut self, sample: &LightSample) {
        // The light's terms are part of the recorded ray's colour and are kept; only its
        // shadow ray is a node of its own, and needs room in the budget (or is counted).
        let keep_shadow_ray = sample.shadow_ray.is_none() || self.admit();
        if self.dropped_open > 0 {
            return;
        }
        let scene = self.scene;
        let (Some(node), Some(sum)) = (self.open.last_mut(), self.local_sums.last_mut()) else {
            return;
        };
        let light = light_ref(scene, sample.light);
        let mut shadow_child = None;
        let visibility = match &sample.shadow_ray {
            // The tracer always gives a reason when it casts no shadow ray.
            None => Visibility::without_shadow_ray(
                sample.no_shadow_ray.unwrap_or(NoShadowRay::FacingAway),
            ),
            Some(shadow_ray) => {
                let (result, blocker, transmittance, filters, passed, termination) =
                    match shadow_ray.result {
                        ShadowResult::Unblocked => (
                            ShadowOutcome::Unblocked,
                            None,
                            None,
                            None,
                            Vec3A::ONE,
                            Termination::Miss,
                        ),
                        ShadowResult::Blocked { object, leaf, t } => (
                            ShadowOutcome::Blocked,
                            Some(Blocker {
                                object: object_ref(scene, object),
                                leaf: object_ref(scene, leaf),
                                t,
                            }),
                            None,
                            None,
                            Vec3A::ZERO,
                            Termination::Absorbed,
                        ),
                        ShadowResult::Filtered {
                            transmittance,
                            blockers,
                        } => (
                            ShadowOutcome::Filtered,
                            None,
                            Some(transmittance.to_array()),
                            Some(blockers),
                            transmittance,
                            Termination::Miss,
                        ),
                    };
                if keep_shadow_ray {
                    shadow_child = Some(node.children.len());
                    node.children.push(RayNode {
                        kind: RayKind::Shadow,
                        depth: node.depth,
                        origin: shadow_ray.origin.to_array(),
                        direction: shadow_ray.direction.to_array(),
                        weight: node.weight,
                        coefficient: [1.0; 3],
                        interface: None,
                        hit: None,
                        local: None,
                        shadow: Some(ShadowInfo {
                            light: light.clone(),
                            max_t: finite(shadow_ray.max_t),
                            result,
                            blocker,
                            transmittance,
                            filters,
                        }),
                        color: passed.to_array(),
                        termination,
                        skipped: Vec::new(),
                        children: Vec::new(),
                        unrecorded: 0,
                    });
                }
                match result {
                    ShadowOutcome::Unblocked => Visibility::Lit,
                    ShadowOutcome::Blocked => Visibility::Blocked,
                    ShadowOutcome::Filtered => Visibility::Filtered,
                }
            }
        };
        // The tracer adds a light's terms only when some light passed; adding zeros
        // instead would still be exact, but following it keeps the sums obviously equal.
        if sample.diffuse != Vec3A::ZERO || sample.specular != Vec3A::ZERO {
            *sum += sample.diffuse + sample.specular;
        }
        let local = node.local.get_or_insert_with(|| LocalIllumination {
            ambient: [0.0; 3],
            emission: [0.0; 3],
            lights: Vec::new(),
            total: [0.0; 3],
        });
        local.total = sum.to_array();
        local.lights.push(LightContribution {
            light,
            to_light: sample.to_light.to_array(),
            distance: finite(sample.distance),
            n_dot_l: sample.n_dot_l,
            attenuation: sample.attenuation,
            spot: sample.spot,
            cone: cone_info(scene, sample),
            diffuse: sample.diffuse.to_array(),
            specular: sample.specular.to_array(),
            visibility,
            shadow_child,
        });
    }

    fn secondary_skipped(&mut self, skipped: &SkippedRay) {
        if self.dropped_open > 0 {
            return;
        }
        if let Some(node) = self.open.last_mut() {
            node.skipped.push(SkippedInfo {
                kind: skipped.kind,
                depth: skipped.depth,
                weight: skipped.weight.to_array(),
                coefficient: skipped.coefficient.to_array(),
                reason: skipped.reason,
            });
        }
    }

    fn ray_finished(&mut self, color: Vec3A, termination: Termination) {
        if self.dropped_open > 0 {
            self.dropped_open -= 1;
            return;
        }
        let Some(mut node) = self.open.pop() else {
            return;
        };
        self.local_sums.pop();
        node.color = color.to_array();
        node.termination = termination;
        match self.open.last_mut() {
            Some(parent) => parent.children.push(node),
            None => self.root = Some(node),
        }
    }
}

fn interface_info(interface: &Interface) -> InterfaceInfo {
    InterfaceInfo {
        incidence_degrees: interface.incidence_degrees(),
        cos_incidence: interface.cos_incidence,
        ior: interface.ior.map(|(from, to)| [from, to]),
        entering: interface.entering,
        fresnel: interface.fresnel,
        fresnel_reflectance: interface.fresnel_reflectance,
        fresnel_transmittance: interface.fresnel_reflectance.map(|r| 1.0 - r),
        total_internal_reflection: interface.total_internal_reflection,
    }
}

/// Where the point lies in a spot light's cone: the angle from the tracer's own cosine, the
/// cone's angles from the scene.
fn cone_info(scene: &Scene, sample: &LightSample) -> Option<ConeInfo> {
    match &scene.lights.get(sample.light)?.kind {
        LightKind::Spot {
            inner_angle_degrees,
            outer_angle_degrees,
            ..
        } => Some(ConeInfo {
            angle_degrees: sample.cos_axis.clamp(-1.0, 1.0).acos().to_degrees(),
            inner_degrees: *inner_angle_degrees as f32,
            outer_degrees: *outer_angle_degrees as f32,
        }),
        _ => None,
    }
}

/// Infinite distances (directional lights) become `None`: JSON has no infinity.
fn finite(value: f32) -> Option<f32> {
    value.is_finite().then_some(value)
}
