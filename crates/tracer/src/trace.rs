//! Whitted's recursion: the one code path that computes the colour of every ray, generic
//! over a [`Recorder`] so that rendering, ray trees and statistics all run this code.
//!
//! `I = ka·Ia·kd + Σ visible lights fatt·spot·Ii·(kd·(N·L) + ks·(R·V)^n) + kr·I_r + kt·I_t`,
//! with Beer-Lambert absorption on rays travelling inside an absorbing solid.
//!
//! Media: a transmitted ray that enters a solid travels in that solid's material; one that
//! leaves a solid travels in air (ior 1.0, no absorption); a reflected ray stays where its
//! parent was. Nested media (glass in water) are therefore approximated as each solid
//! against air: the ior pair at a surface is (1.0, ior) entering and (ior, 1.0) leaving.

use glam::Vec3A;
use whitted_ir::ShadowMode;

use crate::optics::{beer_lambert, max_channel, reflect, refract, schlick, surface_offset};
use crate::query::{Scratch, Shadow};
use crate::ray::Ray;
use crate::recorder::{
    Interface, LightSample, RayKind, RayStart, Recorder, ShadowRay, ShadowResult, SkippedRay,
    SurfaceHit, Termination,
};
use crate::scene::PreparedScene;

/// Ray counts kept by the tracer itself (cheap, always on).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounters {
    pub camera: u64,
    pub shadow: u64,
    pub reflected: u64,
    pub transmitted: u64,
    pub deepest: u32,
}

impl RayCounters {
    pub fn add(&mut self, other: &RayCounters) {
        self.camera += other.camera;
        self.shadow += other.shadow;
        self.reflected += other.reflected;
        self.transmitted += other.transmitted;
        self.deepest = self.deepest.max(other.deepest);
    }
}

/// What a ray carries down the recursion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathState {
    pub kind: RayKind,
    pub depth: u32,
    /// The path weight including this ray's own coefficient.
    pub weight: Vec3A,
    pub coefficient: Vec3A,
    /// Absorption per unit distance of the medium the ray travels in (0 in air).
    pub medium: Vec3A,
    pub interface: Option<Interface>,
}

impl PathState {
    pub fn camera() -> PathState {
        PathState {
            kind: RayKind::Camera,
            depth: 0,
            weight: Vec3A::ONE,
            coefficient: Vec3A::ONE,
            medium: Vec3A::ZERO,
            interface: None,
        }
    }
}

/// One worker's tracing context: the scene, the limits, CSG scratch space and counters.
pub struct Tracer<'a> {
    scene: &'a PreparedScene,
    max_depth: u32,
    min_weight: f32,
    scratch: Scratch,
    pub counters: RayCounters,
    /// 1, except in tests that prove the acne checks can fail by removing the offset.
    offset_scale: f32,
}

impl<'a> Tracer<'a> {
    pub fn new(scene: &'a PreparedScene, max_depth: u32, min_weight: f32) -> Tracer<'a> {
        Tracer {
            scene,
            max_depth,
            min_weight,
            scratch: Scratch::default(),
            counters: RayCounters::default(),
            offset_scale: 1.0,
        }
    }

    /// Starts secondary rays exactly on the surface: only for tests showing that the acne
    /// checks catch the missing offset.
    #[cfg(test)]
    pub fn without_surface_offset(mut self) -> Self {
        self.offset_scale = 0.0;
        self
    }

    /// Traces one ray and returns the colour it brings back to its origin.
    pub fn trace<R: Recorder>(&mut self, ray: &Ray, path: &PathState, rec: &mut R) -> Vec3A {
        rec.ray_started(&RayStart {
            kind: path.kind,
            depth: path.depth,
            origin: ray.origin,
            direction: ray.direction,
            weight: path.weight,
            coefficient: path.coefficient,
            interface: path.interface,
        });
        match path.kind {
            RayKind::Camera => self.counters.camera += 1,
            RayKind::Reflected => self.counters.reflected += 1,
            RayKind::Transmitted => self.counters.transmitted += 1,
            // Shadow rays are queries, not traced paths; they are counted where they are cast.
            RayKind::Shadow => {}
        }
        self.counters.deepest = self.counters.deepest.max(path.depth);
        let scene = self.scene;

        let Some(hit) = scene.intersect(ray, 0.0, f32::INFINITY, &mut self.scratch) else {
            let color = if path.medium == Vec3A::ZERO {
                scene.background
            } else {
                scene.background * beer_lambert(path.medium, f32::INFINITY)
            };
            rec.ray_missed(scene.background);
            rec.ray_finished(color, Termination::Miss);
            return color;
        };
        let absorption = if path.medium == Vec3A::ZERO {
            Vec3A::ONE
        } else {
            beer_lambert(path.medium, hit.t)
        };

        let surface = scene.surface(ray, &hit);
        let d = ray.direction;
        let front_face = surface.geometric_normal.dot(d) < 0.0;
        let n = if front_face {
            surface.geometric_normal
        } else {
            -surface.geometric_normal
        };
        let point = surface.point;
        let material_handle = scene.resolve_material(surface.leaf, point, hit.part);
        let m = &scene.materials[material_handle.index()];
        rec.surface_hit(&SurfaceHit {
            t: hit.t,
            point,
            geometric_normal: surface.geometric_normal,
            shading_normal: n,
            front_face,
            object: surface.item.object(),
            leaf: surface.leaf.object,
            material: surface.leaf.material,
            resolved_material: material_handle,
            absorption,
        });

        // Local illumination.
        let ambient = m.ambient * scene.ambient * m.diffuse;
        rec.ambient(ambient);
        let mut color = ambient;
        let offset = surface_offset(point, scene.epsilon) * self.offset_scale;
        let outside = point + offset * n;
        let view = -d;
        for light in &scene.lights {
            let incidence = light.incidence(outside);
            let n_dot_l = n.dot(incidence.to_light);
            let strength = incidence.attenuation * incidence.spot;
            let mut sample = LightSample {
                light: light.handle,
                to_light: incidence.to_light,
                distance: incidence.distance,
                n_dot_l,
                attenuation: incidence.attenuation,
                spot: incidence.spot,
                shadow_ray: None,
                diffuse: Vec3A::ZERO,
                specular: Vec3A::ZERO,
            };
            if n_dot_l <= 0.0 || strength <= 0.0 || light.intensity == Vec3A::ZERO {
                rec.light_sampled(&sample);
                continue;
            }
            let shadow_ray = Ray::new(outside, incidence.to_light);
            self.counters.shadow += 1;
            let shadow = match scene.shadows {
                ShadowMode::Opaque => {
                    match scene.occluded(&shadow_ray, 0.0, incidence.distance, &mut self.scratch) {
                        Some(blocker) => Shadow::Blocked(blocker),
                        None => Shadow::Clear,
                    }
                }
                ShadowMode::Filtered => {
                    scene.filter_shadow(&shadow_ray, 0.0, incidence.distance, &mut self.scratch)
                }
            };
            let (passed, result) = match shadow {
                Shadow::Clear => (Vec3A::ONE, ShadowResult::Unblocked),
                Shadow::Blocked(blocker) => {
                    let item = scene.item(blocker.item);
                    let result = ShadowResult::Blocked {
                        object: item.object(),
                        leaf: item.leaf(blocker.leaf).object,
                        t: blocker.t,
                    };
                    (Vec3A::ZERO, result)
                }
                Shadow::Filtered {
                    transmittance,
                    blockers,
                } => (
                    transmittance,
                    ShadowResult::Filtered {
                        transmittance,
                        blockers,
                    },
                ),
            };
            sample.shadow_ray = Some(ShadowRay {
                origin: outside,
                direction: incidence.to_light,
                max_t: incidence.distance,
                result,
            });
            if passed != Vec3A::ZERO {
                let light_in = light.intensity * strength * passed;
                sample.diffuse = light_in * m.diffuse * n_dot_l;
                if m.specular != Vec3A::ZERO {
                    let mirrored = reflect(-incidence.to_light, n);
                    sample.specular = light_in * m.specular * m.phong(mirrored.dot(view));
                }
                color += sample.diffuse + sample.specular;
            }
            rec.light_sampled(&sample);
        }

        // Secondary rays: split the weights, then reflect and refract.
        let cos_incidence = view.dot(n).clamp(0.0, 1.0);
        let mut reflect_coefficient = m.reflective;
        let mut transmit_coefficient = Vec3A::ZERO;
        let mut refracted = None;
        let solid = surface.leaf.geometry.is_solid();
        let mut interface = Interface {
            cos_incidence,
            ior: None,
            entering: solid && front_face,
            fresnel_reflectance: None,
            total_internal_reflection: false,
        };
        if m.transmissive != Vec3A::ZERO {
            let (from, to) = match (solid, front_face) {
                (false, _) => (1.0, 1.0),
                (true, true) => (1.0, m.ior),
                (true, false) => (m.ior, 1.0),
            };
            interface.ior = Some((from, to));
            match refract(d, n, from, to) {
                None => {
                    interface.total_internal_reflection = true;
                    if m.schlick {
                        interface.fresnel_reflectance = Some(1.0);
                    }
                    reflect_coefficient = m.reflective + m.transmissive;
                }
                Some(direction) => {
                    if m.schlick {
                        let r = schlick(cos_incidence, from, to);
                        interface.fresnel_reflectance = Some(r);
                        reflect_coefficient = m.reflective + m.transmissive * r;
                        transmit_coefficient = m.transmissive * (1.0 - r);
                    } else {
                        transmit_coefficient = m.transmissive;
                    }
                    refracted = Some(direction);
                }
            }
        }

        let mut traced_any = false;
        let mut first_skip: Option<Termination> = None;
        let carried = path.weight * absorption;
        let depth = path.depth + 1;
        if reflect_coefficient != Vec3A::ZERO {
            let child = PathState {
                kind: RayKind::Reflected,
                depth,
                weight: carried * reflect_coefficient,
                coefficient: reflect_coefficient,
                medium: path.medium,
                interface: Some(interface),
            };
            match self.secondary_verdict(&child) {
                None => {
                    let reflected = Ray::new(outside, reflect(d, n).normalize());
                    color += reflect_coefficient * self.trace(&reflected, &child, rec);
                    traced_any = true;
                }
                Some(reason) => {
                    skip(rec, &child, reason);
                    first_skip = first_skip.or(Some(reason));
                }
            }
        }
        if interface.total_internal_reflection {
            let reason = Termination::TotalInternalReflection;
            rec.secondary_skipped(&SkippedRay {
                kind: RayKind::Transmitted,
                depth,
                weight: Vec3A::ZERO,
                coefficient: Vec3A::ZERO,
                reason,
            });
            first_skip = first_skip.or(Some(reason));
        }
        if let Some(direction) = refracted.filter(|_| transmit_coefficient != Vec3A::ZERO) {
            let medium = match (solid, front_face) {
                (false, _) => path.medium,
                (true, true) => m.absorption,
                (true, false) => Vec3A::ZERO,
            };
            let child = PathState {
                kind: RayKind::Transmitted,
                depth,
                weight: carried * transmit_coefficient,
                coefficient: transmit_coefficient,
                medium,
                interface: Some(interface),
            };
            match self.secondary_verdict(&child) {
                None => {
                    let inside = point - offset * n;
                    let transmitted = Ray::new(inside, direction);
                    color += transmit_coefficient * self.trace(&transmitted, &child, rec);
                    traced_any = true;
                }
                Some(reason) => {
                    skip(rec, &child, reason);
                    first_skip = first_skip.or(Some(reason));
                }
            }
        }

        let color = color * absorption;
        let termination = if traced_any {
            Termination::NotEnded
        } else {
            first_skip.unwrap_or(Termination::Absorbed)
        };
        rec.ray_finished(color, termination);
        color
    }

    /// `None` when the secondary ray may be traced; otherwise why not.
    #[inline]
    fn secondary_verdict(&self, child: &PathState) -> Option<Termination> {
        if child.depth > self.max_depth {
            Some(Termination::MaxDepth)
        } else if max_channel(child.weight) < self.min_weight {
            Some(Termination::WeightCutoff)
        } else {
            None
        }
    }
}

fn skip<R: Recorder>(rec: &mut R, child: &PathState, reason: Termination) {
    rec.secondary_skipped(&SkippedRay {
        kind: child.kind,
        depth: child.depth,
        weight: child.weight,
        coefficient: child.coefficient,
        reason,
    });
}
