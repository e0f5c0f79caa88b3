//! Lights in the tracer's f32 form: where light comes from as seen from a surface point.

use glam::Vec3A;
use whitted_ir::{Attenuation, Handle, Light, LightKind, Settings};

use crate::material::color;
use crate::optics;

#[derive(Clone, Debug, PartialEq)]
pub struct PreparedLight {
    pub handle: Handle<Light>,
    /// The intensity `Ii`.
    pub intensity: Vec3A,
    pub kind: PreparedLightKind,
}

#[derive(Clone, Debug, PartialEq)]
pub enum PreparedLightKind {
    Point {
        position: Vec3A,
        attenuation: [f32; 3],
        clamp: bool,
    },
    Directional {
        /// Unit vector towards the light (against its direction of travel).
        to_light: Vec3A,
    },
    Spot {
        position: Vec3A,
        /// Unit vector along which the spot shines.
        axis: Vec3A,
        cos_inner: f32,
        cos_outer: f32,
        attenuation: [f32; 3],
        clamp: bool,
    },
}

/// How a light reaches a surface point, before shadows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incidence {
    /// Unit vector from the point towards the light.
    pub to_light: Vec3A,
    /// Distance to the light (infinite for directional lights): shadow rays stop there.
    pub distance: f32,
    /// `fatt`, 1 for directional lights.
    pub attenuation: f32,
    /// The spot cone's factor, 1 for other lights.
    pub spot: f32,
    /// The cosine of the angle between a spot's axis and the direction from the light to
    /// the point, 1 for other lights (the ray tree reports the angle when the cone misses).
    pub cos_axis: f32,
}

fn terms(a: &Attenuation) -> [f32; 3] {
    [a.constant as f32, a.linear as f32, a.quadratic as f32]
}

impl PreparedLight {
    /// The scene's `attenuation_clamp` and `attenuation` settings shape the fall-off.
    pub fn new(handle: Handle<Light>, light: &Light, settings: &Settings) -> PreparedLight {
        let clamp = settings.attenuation_clamp;
        // `attenuation off`: every light at full colour at any distance.
        let terms = |a: &Attenuation| {
            if settings.light_falloff {
                terms(a)
            } else {
                [1.0, 0.0, 0.0]
            }
        };
        let kind = match &light.kind {
            LightKind::Point {
                position,
                attenuation,
            } => PreparedLightKind::Point {
                position: position.as_vec3a(),
                attenuation: terms(attenuation),
                clamp,
            },
            LightKind::Directional { direction } => PreparedLightKind::Directional {
                to_light: (-direction.normalize()).as_vec3a(),
            },
            LightKind::Spot {
                position,
                direction,
                inner_angle_degrees,
                outer_angle_degrees,
                attenuation,
            } => PreparedLightKind::Spot {
                position: position.as_vec3a(),
                axis: direction.normalize().as_vec3a(),
                cos_inner: inner_angle_degrees.to_radians().cos() as f32,
                cos_outer: outer_angle_degrees.to_radians().cos() as f32,
                attenuation: terms(attenuation),
                clamp,
            },
        };
        PreparedLight {
            handle,
            intensity: color(&light.color),
            kind,
        }
    }

    /// The direction, distance, attenuation and cone factor of this light at `point`.
    #[inline]
    pub fn incidence(&self, point: Vec3A) -> Incidence {
        match &self.kind {
            PreparedLightKind::Directional { to_light } => Incidence {
                to_light: *to_light,
                distance: f32::INFINITY,
                attenuation: 1.0,
                spot: 1.0,
                cos_axis: 1.0,
            },
            PreparedLightKind::Point {
                position,
                attenuation,
                clamp,
            } => {
                let (to_light, distance) = towards(*position, point);
                Incidence {
                    to_light,
                    distance,
                    attenuation: fatt(attenuation, distance, *clamp),
                    spot: 1.0,
                    cos_axis: 1.0,
                }
            }
            PreparedLightKind::Spot {
                position,
                axis,
                cos_inner,
                cos_outer,
                attenuation,
                clamp,
            } => {
                let (to_light, distance) = towards(*position, point);
                let cos_angle = (-to_light).dot(*axis);
                Incidence {
                    to_light,
                    distance,
                    attenuation: fatt(attenuation, distance, *clamp),
                    spot: optics::spot_factor(cos_angle, *cos_inner, *cos_outer),
                    cos_axis: cos_angle,
                }
            }
        }
    }
}

fn towards(position: Vec3A, point: Vec3A) -> (Vec3A, f32) {
    let offset = position - point;
    let distance = offset.length();
    if distance > 0.0 {
        (offset / distance, distance)
    } else {
        // The point is at the light: any direction will do, and nothing can shadow it.
        (Vec3A::Y, 0.0)
    }
}

fn fatt(terms: &[f32; 3], distance: f32, clamp: bool) -> f32 {
    optics::attenuation(terms[0], terms[1], terms[2], distance, clamp)
}
