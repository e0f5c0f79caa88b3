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

use crate::material::PreparedMaterial;
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

/// What the recursion carries from ray to ray: all that a ray's colour depends on.
#[derive(Clone, Copy, Debug)]
struct Path {
    kind: RayKind,
    depth: u32,
    weight: Vec3A,
    medium: Vec3A,
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
        let path = Path {
            kind: path.kind,
            depth: path.depth,
            weight: path.weight,
            medium: path.medium,
        };
        self.count(&path);
        self.trace_started(ray, &path, rec)
    }

    /// Counts a ray about to be traced (its caller has reported it to the recorder).
    #[inline(always)]
    fn count(&mut self, path: &Path) {
        match path.kind {
            RayKind::Camera => self.counters.camera += 1,
            RayKind::Reflected => self.counters.reflected += 1,
            RayKind::Transmitted => self.counters.transmitted += 1,
            // Shadow rays are queries, not traced paths; they are counted where they are cast.
            RayKind::Shadow => {}
        }
        self.counters.deepest = self.counters.deepest.max(path.depth);
    }

    /// The body of [`Tracer::trace`], once the recorder has heard of the ray: the recursion
    /// passes only what the colour depends on, and each caller reports the rest.
    fn trace_started<R: Recorder>(&mut self, ray: &Ray, path: &Path, rec: &mut R) -> Vec3A {
        let scene = self.scene;
        // Most rays travel in air; then nothing is absorbed and multiplying by the
        // transmittance (exactly 1) can be skipped without changing a bit.
        let in_air = path.medium == Vec3A::ZERO;

        let Some(hit) = scene.intersect(ray, 0.0, f32::INFINITY, &mut self.scratch) else {
            let color = if in_air {
                scene.background
            } else {
                scene.background * beer_lambert(path.medium, f32::INFINITY)
            };
            rec.ray_missed(scene.background);
            rec.ray_finished(color, Termination::Miss);
            return color;
        };
        let absorption = if in_air {
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

        let offset = match scene.epsilon {
            Some(epsilon) => epsilon,
            None => surface_offset(ray.origin, hit.t, point),
        } * self.offset_scale;
        let outside = point + offset * n;
        let mut color = self.local_illumination(m, outside, n, -d, rec);

        // Secondary rays.
        let solid = surface.leaf.geometry.is_solid();
        let split = split_weights(m, d, n, solid, front_face);
        let mut outcome = Outcome::default();
        let carried = if in_air {
            path.weight
        } else {
            path.weight * absorption
        };
        let depth = path.depth + 1;
        if split.reflect != Vec3A::ZERO {
            let child = Path {
                kind: RayKind::Reflected,
                depth,
                weight: carried * split.reflect,
                medium: path.medium,
            };
            // Unit already: a reflection preserves length (to a few ulps).
            let reflected = Ray::new(outside, reflect(d, n));
            if let Some(c) = self.spawn(&reflected, &child, &split, &mut outcome, rec) {
                color += split.reflect * c;
            }
        }
        if split.interface.total_internal_reflection {
            let reason = Termination::TotalInternalReflection;
            rec.secondary_skipped(&SkippedRay {
                kind: RayKind::Transmitted,
                depth,
                weight: Vec3A::ZERO,
                coefficient: Vec3A::ZERO,
                reason,
            });
            outcome.skipped(reason);
        }
        if let Some(direction) = split.refracted.filter(|_| split.transmit != Vec3A::ZERO) {
            let medium = match (solid, front_face) {
                (false, _) => path.medium,
                (true, true) => m.absorption,
                (true, false) => Vec3A::ZERO,
            };
            let child = Path {
                kind: RayKind::Transmitted,
                depth,
                weight: carried * split.transmit,
                medium,
            };
            let transmitted = Ray::new(point - offset * n, direction);
            if let Some(c) = self.spawn(&transmitted, &child, &split, &mut outcome, rec) {
                color += split.transmit * c;
            }
        }

        if !in_air {
            color *= absorption;
        }
        let termination = if outcome.traced_any {
            Termination::NotEnded
        } else {
            outcome.first_skip.unwrap_or(Termination::Absorbed)
        };
        rec.ray_finished(color, termination);
        color
    }

    /// `ka·Ia·kd` plus, for every light on the visible side, `fatt·spot·Ii·(kd·(N·L) +
    /// ks·(R·V)^n)` times what the shadow ray lets through. `outside` is the hit point
    /// already moved off the surface along `n`, which faces the viewer. The order of the
    /// additions is part of the recorder contract (see `recorder.rs`): keep it.
    fn local_illumination<R: Recorder>(
        &mut self,
        m: &PreparedMaterial,
        outside: Vec3A,
        n: Vec3A,
        view: Vec3A,
        rec: &mut R,
    ) -> Vec3A {
        let scene = self.scene;
        let ambient = m.ambient * scene.ambient * m.diffuse;
        rec.ambient(ambient);
        let mut color = ambient;
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
            let (passed, shadow_ray) =
                self.cast_shadow::<R>(outside, incidence.to_light, incidence.distance);
            sample.shadow_ray = shadow_ray;
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
        color
    }

    /// Casts a shadow ray; returns what fraction of the light passes, and the record when
    /// the recorder wants one (finding the blocker's object is work for the recorder only).
    fn cast_shadow<R: Recorder>(
        &mut self,
        origin: Vec3A,
        to_light: Vec3A,
        distance: f32,
    ) -> (Vec3A, Option<ShadowRay>) {
        let scene = self.scene;
        let ray = Ray::new(origin, to_light);
        self.counters.shadow += 1;
        let shadow = match scene.shadows {
            ShadowMode::Opaque => match scene.occluded(&ray, 0.0, distance, &mut self.scratch) {
                Some(blocker) => Shadow::Blocked(blocker),
                None => Shadow::Clear,
            },
            ShadowMode::Filtered => scene.filter_shadow(&ray, 0.0, distance, &mut self.scratch),
        };
        let passed = match shadow {
            Shadow::Clear => Vec3A::ONE,
            Shadow::Blocked(_) => Vec3A::ZERO,
            Shadow::Filtered { transmittance, .. } => transmittance,
        };
        let record = R::RECORDS.then(|| ShadowRay {
            origin,
            direction: to_light,
            max_t: distance,
            result: shadow_result(scene, shadow),
        });
        (passed, record)
    }

    /// Traces a secondary ray unless a stopping criterion forbids it (then records why).
    /// `split` gives the ray's coefficient and the interface it leaves, for the recorder.
    #[inline(always)]
    fn spawn<R: Recorder>(
        &mut self,
        ray: &Ray,
        child: &Path,
        split: &Split,
        outcome: &mut Outcome,
        rec: &mut R,
    ) -> Option<Vec3A> {
        let coefficient = match child.kind {
            RayKind::Transmitted => split.transmit,
            _ => split.reflect,
        };
        match self.secondary_verdict(child) {
            None => {
                outcome.traced_any = true;
                rec.ray_started(&RayStart {
                    kind: child.kind,
                    depth: child.depth,
                    origin: ray.origin,
                    direction: ray.direction,
                    weight: child.weight,
                    coefficient,
                    interface: Some(split.interface),
                });
                self.count(child);
                Some(self.trace_started(ray, child, rec))
            }
            Some(reason) => {
                rec.secondary_skipped(&SkippedRay {
                    kind: child.kind,
                    depth: child.depth,
                    weight: child.weight,
                    coefficient,
                    reason,
                });
                outcome.skipped(reason);
                None
            }
        }
    }

    /// `None` when the secondary ray may be traced; otherwise why not.
    #[inline]
    fn secondary_verdict(&self, child: &Path) -> Option<Termination> {
        if child.depth > self.max_depth {
            Some(Termination::MaxDepth)
        } else if max_channel(child.weight) < self.min_weight {
            Some(Termination::WeightCutoff)
        } else {
            None
        }
    }
}

/// A shadow query's outcome as the recorder reports it.
fn shadow_result(scene: &PreparedScene, shadow: Shadow) -> ShadowResult {
    match shadow {
        Shadow::Clear => ShadowResult::Unblocked,
        Shadow::Blocked(blocker) => {
            let item = scene.item(blocker.item);
            ShadowResult::Blocked {
                object: item.object(),
                leaf: item.leaf(blocker.leaf).object,
                t: blocker.t,
            }
        }
        Shadow::Filtered {
            transmittance,
            blockers,
        } => ShadowResult::Filtered {
            transmittance,
            blockers,
        },
    }
}

/// What happened to a ray's secondary rays, for its termination.
#[derive(Default)]
struct Outcome {
    traced_any: bool,
    first_skip: Option<Termination>,
}

impl Outcome {
    fn skipped(&mut self, reason: Termination) {
        self.first_skip = self.first_skip.or(Some(reason));
    }
}

/// How a surface divides a ray's weight between reflection and transmission.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Split {
    pub interface: Interface,
    /// `kr`, plus `kt·R` with Fresnel, plus all of `kt` on total internal reflection.
    pub reflect: Vec3A,
    /// `kt`, times `1 − R` with Fresnel; zero on total internal reflection.
    pub transmit: Vec3A,
    /// The refracted direction, when the material transmits and refraction is possible.
    pub refracted: Option<Vec3A>,
}

/// The reflection/transmission split at a surface hit along `d`, with `n` the unit normal
/// facing the incoming ray. Solids refract between air (1.0) and the material's ior, the
/// direction decided by `front_face`; thin surfaces (no inside) have 1.0 on both sides.
pub fn split_weights(
    m: &PreparedMaterial,
    d: Vec3A,
    n: Vec3A,
    solid: bool,
    front_face: bool,
) -> Split {
    let cos_incidence = (-d).dot(n).clamp(0.0, 1.0);
    let mut split = Split {
        interface: Interface {
            cos_incidence,
            ior: None,
            entering: solid && front_face,
            fresnel_reflectance: None,
            total_internal_reflection: false,
        },
        reflect: m.reflective,
        transmit: Vec3A::ZERO,
        refracted: None,
    };
    if m.transmissive == Vec3A::ZERO {
        return split;
    }
    let (from, to) = match (solid, front_face) {
        (false, _) => (1.0, 1.0),
        (true, true) => (1.0, m.ior),
        (true, false) => (m.ior, 1.0),
    };
    split.interface.ior = Some((from, to));
    match refract(d, n, from, to) {
        None => {
            split.interface.total_internal_reflection = true;
            if m.schlick {
                split.interface.fresnel_reflectance = Some(1.0);
            }
            split.reflect = m.reflective + m.transmissive;
        }
        Some(direction) => {
            if m.schlick {
                let r = schlick(cos_incidence, from, to);
                split.interface.fresnel_reflectance = Some(r);
                split.reflect = m.reflective + m.transmissive * r;
                split.transmit = m.transmissive * (1.0 - r);
            } else {
                split.transmit = m.transmissive;
            }
            split.refracted = Some(direction);
        }
    }
    split
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::{Color, Fresnel, Material};

    fn glass(reflective: f64, fresnel: Fresnel) -> PreparedMaterial {
        PreparedMaterial::new(&Material {
            reflective: Color::gray(reflective),
            transmissive: Color::gray(0.9),
            ior: 1.5,
            fresnel,
            ..Material::default()
        })
    }

    fn incoming(degrees: f32) -> Vec3A {
        let theta = degrees.to_radians();
        Vec3A::new(theta.sin(), -theta.cos(), 0.0)
    }

    #[test]
    fn without_fresnel_the_coefficients_are_the_material_s() {
        let split = split_weights(
            &glass(0.1, Fresnel::Off),
            incoming(30.0),
            Vec3A::Y,
            true,
            true,
        );
        assert_eq!(split.reflect, Vec3A::splat(0.1));
        assert_eq!(split.transmit, Vec3A::splat(0.9));
        assert_eq!(split.interface.ior, Some((1.0, 1.5)));
        assert!(split.interface.entering);
        assert!(split.refracted.is_some());
    }

    #[test]
    fn schlick_moves_part_of_the_transmission_into_reflection() {
        let split = split_weights(
            &glass(0.1, Fresnel::Schlick),
            incoming(60.0),
            Vec3A::Y,
            true,
            true,
        );
        let r = split.interface.fresnel_reflectance.unwrap_or(-1.0);
        assert!(r > 0.04 && r < 1.0, "{r}");
        assert!(split.reflect.abs_diff_eq(Vec3A::splat(0.1 + 0.9 * r), 1e-6));
        assert!(split
            .transmit
            .abs_diff_eq(Vec3A::splat(0.9 * (1.0 - r)), 1e-6));
    }

    #[test]
    fn total_internal_reflection_reflects_everything() {
        // Leaving glass (a back face) at 60°, beyond the critical angle of 41.8°.
        let split = split_weights(
            &glass(0.1, Fresnel::Schlick),
            incoming(60.0),
            Vec3A::Y,
            true,
            false,
        );
        assert!(split.interface.total_internal_reflection);
        assert_eq!(split.interface.ior, Some((1.5, 1.0)));
        assert_eq!(split.interface.fresnel_reflectance, Some(1.0));
        assert_eq!(split.reflect, Vec3A::splat(0.1 + 0.9));
        assert_eq!(split.transmit, Vec3A::ZERO);
        assert!(split.refracted.is_none());
    }

    #[test]
    fn thin_surfaces_pass_light_straight_through() {
        let d = incoming(50.0);
        let split = split_weights(&glass(0.0, Fresnel::Off), d, Vec3A::Y, false, true);
        assert_eq!(split.interface.ior, Some((1.0, 1.0)));
        assert!(!split.interface.entering);
        assert!(split.refracted.unwrap_or(Vec3A::ZERO).abs_diff_eq(d, 1e-6));
    }
}
