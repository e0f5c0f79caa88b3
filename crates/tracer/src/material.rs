//! Materials in the tracer's f32 form, and procedural patterns resolved at a hit point.

use glam::{Affine3A, DAffine3, DVec3, Vec3A};
use whitted_ir::{Color, Fresnel, Handle, Material, Object, PatternKind};

use crate::shapes::Part;

/// An IR material with colours as `Vec3A`.
#[derive(Clone, Debug, PartialEq)]
pub struct PreparedMaterial {
    pub ambient: Vec3A,
    pub diffuse: Vec3A,
    pub specular: Vec3A,
    pub shininess: f32,
    /// The same exponent when it is a small whole number, for the faster `powi`.
    pub shininess_integer: Option<i32>,
    pub reflective: Vec3A,
    pub transmissive: Vec3A,
    pub ior: f32,
    pub fresnel: Fresnel,
    /// The nested-media rank: the material's priority, with 0 (plain) above every other.
    pub rank: u32,
    pub absorption: Vec3A,
    /// Light the surface gives off by itself, added to its local colour.
    pub emission: Vec3A,
    pub pattern: Option<PreparedPattern>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct PreparedPattern {
    pub kind: PatternKind,
    pub a: Handle<Material>,
    pub b: Handle<Material>,
    /// `pattern_from_object` followed by the division by `scale`.
    pub cell_from_object: Affine3A,
}

pub fn color(c: &Color) -> Vec3A {
    Vec3A::new(c.r as f32, c.g as f32, c.b as f32)
}

impl PreparedMaterial {
    /// The Phong specular factor `max(R·V, 0)^n`.
    #[inline]
    pub fn phong(&self, r_dot_v: f32) -> f32 {
        let x = r_dot_v.max(0.0);
        match self.shininess_integer {
            Some(n) => powi(x, n),
            None => x.powf(self.shininess),
        }
    }

    pub fn new(m: &Material) -> PreparedMaterial {
        PreparedMaterial {
            ambient: color(&m.ambient),
            diffuse: color(&m.diffuse),
            specular: color(&m.specular),
            shininess: m.shininess as f32,
            shininess_integer: (m.shininess.fract() == 0.0 && m.shininess <= 4096.0)
                .then_some(m.shininess as i32),
            reflective: color(&m.reflective),
            transmissive: color(&m.transmissive),
            ior: m.ior as f32,
            fresnel: m.fresnel,
            rank: if m.priority == 0 {
                u32::MAX
            } else {
                m.priority
            },
            absorption: color(&m.absorption),
            emission: color(&m.emission),
            pattern: m.pattern.as_ref().map(|p| PreparedPattern {
                kind: p.kind,
                a: p.a,
                b: p.b,
                cell_from_object: (DAffine3::from_scale(DVec3::splat(1.0 / p.scale))
                    * DAffine3::from_mat4(p.pattern_from_object))
                .as_affine3a(),
            }),
        }
    }
}

/// `x.powi(n)`, computed inline by exactly the multiplications of the runtime routine that
/// `powi` calls for an exponent only known at run time (compiler-builtins' `__powisf2`:
/// square-and-multiply from the lowest bit, reciprocal last for negative `n`), so the result
/// is bit-identical without a call that makes the caller save every vector register.
#[inline]
pub fn powi(x: f32, n: i32) -> f32 {
    let mut base = x;
    let mut bits = n.unsigned_abs();
    let mut result = if bits & 1 != 0 { base } else { 1.0 };
    bits >>= 1;
    while bits != 0 {
        base *= base;
        if bits & 1 != 0 {
            result *= base;
        }
        bits >>= 1;
    }
    if n < 0 {
        1.0 / result
    } else {
        result
    }
}

/// What a pattern makes of a point: one of its two materials, or (the course's blending
/// patterns) the weight of its second material in a blend of the two.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pick {
    One(Handle<Material>),
    Blend(f32),
}

/// A blend of two materials, each resolved by choosing patterns alone: `(1 - weight)` of
/// `first` and `weight` of `second`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Blend {
    pub first: Handle<Material>,
    pub second: Handle<Material>,
    pub weight: f32,
}

impl Blend {
    /// The material with the larger weight (`first` at one half): it stands for the blend
    /// where one material must (the medium inside a solid, its index of refraction).
    pub fn dominant(&self) -> Handle<Material> {
        if self.weight > 0.5 {
            self.second
        } else {
            self.first
        }
    }
}

impl PreparedPattern {
    /// Which of the two materials covers the object-space point (for a pattern that
    /// chooses and reads object space; the tests' shorthand for [`PreparedPattern::pick`]).
    #[cfg(test)]
    pub fn choose(&self, object_point: Vec3A) -> Handle<Material> {
        match self.pick(object_point, object_point) {
            Pick::One(h) => h,
            Pick::Blend(w) => {
                if w > 0.5 {
                    self.b
                } else {
                    self.a
                }
            }
        }
    }

    /// What the pattern makes of a surface point, given in object space and in world space
    /// (whitted's own patterns read the first, the course's the second).
    #[inline]
    pub fn pick(&self, object_point: Vec3A, world_point: Vec3A) -> Pick {
        let space = if self.kind.world_space() {
            world_point
        } else {
            object_point
        };
        let p = self.cell_from_object.transform_point3a(space);
        let first = match self.kind {
            PatternKind::Checker | PatternKind::CourseCheckerboard => {
                cell(p.x).wrapping_add(cell(p.y)).wrapping_add(cell(p.z)) & 1 == 0
            }
            PatternKind::Stripes => cell(p.x) & 1 == 0,
            PatternKind::Marble => crate::noise::marble(p.x, p.y, p.z),
            PatternKind::Wood => crate::noise::wood(p.x, p.y, p.z),
            PatternKind::Turbulence => crate::noise::blotches(p.x, p.y, p.z),
            PatternKind::CourseNoise { .. }
            | PatternKind::CourseMarble { .. }
            | PatternKind::CourseWood { .. } => {
                let weight = crate::perlin::course_weight(self.kind, p.x, p.y, p.z);
                return Pick::Blend(weight.unwrap_or(0.0));
            }
        };
        Pick::One(if first { self.a } else { self.b })
    }
}

impl PreparedMaterial {
    /// The course's blend of two (pattern-free) materials: every colour and number
    /// interpolated linearly, which is the course's blend of the two materials' Phong
    /// results wherever their exponents are equal (with different exponents the exponent is
    /// interpolated too). The Fresnel model, the index of refraction and the medium's rank
    /// and absorption are the dominant material's (a medium is one material).
    pub fn blend(first: &PreparedMaterial, second: &PreparedMaterial, blend: &Blend) -> Self {
        let w = blend.weight;
        let mix = |a: Vec3A, b: Vec3A| a + (b - a) * w;
        let dominant = if blend.dominant() == blend.second {
            second
        } else {
            first
        };
        let shininess = first.shininess + (second.shininess - first.shininess) * w;
        PreparedMaterial {
            ambient: mix(first.ambient, second.ambient),
            diffuse: mix(first.diffuse, second.diffuse),
            specular: mix(first.specular, second.specular),
            shininess,
            shininess_integer: (shininess.fract() == 0.0 && shininess <= 4096.0)
                .then_some(shininess as i32),
            reflective: mix(first.reflective, second.reflective),
            transmissive: mix(first.transmissive, second.transmissive),
            ior: dominant.ior,
            fresnel: dominant.fresnel,
            rank: dominant.rank,
            absorption: dominant.absorption,
            emission: mix(first.emission, second.emission),
            pattern: None,
        }
    }
}

/// `floor(x)` as an integer, without a libm call (x86-64's baseline SSE2 has no rounding
/// instruction). Values beyond ±2⁶³ saturate, NaN gives 0: either way a valid cell.
#[inline]
fn cell(x: f32) -> i64 {
    let truncated = x as i64;
    if (truncated as f32) > x {
        truncated.saturating_sub(1)
    } else {
        truncated
    }
}

/// What a patterned leaf needs to find its object-space hit point: the inverse of its
/// transform, and how to put the point exactly back onto flat faces. Without that last
/// step a checker on the plane `y = 0` speckles, because the computed hit point lands a
/// hair above or below 0 and `floor` flips between the two cells.
#[derive(Clone, Debug, PartialEq)]
pub struct PatternFrame {
    pub object_from_world: Affine3A,
    /// Back to world space, for the course's patterns, which read the world-space point:
    /// the object-space point is snapped first, so a checker on a plane does not speckle.
    pub world_from_object: Affine3A,
    pub snap: Snap,
}

/// The pattern frames of a scene's patterned leaves, by IR object (a CSG leaf is an object
/// of its own): kept beside the items rather than in each leaf, where a boxed frame cost
/// every leaf of a million 8 bytes that almost all leave empty. Found in one step (a
/// subtraction and two range checks, for every shaded leaf): a slot per object from the
/// first patterned one to the last (4 bytes each, and none at all in a scene without
/// patterns).
#[derive(Clone, Debug, Default)]
pub struct PatternFrames {
    /// The first object with a frame.
    first: usize,
    /// For each object from `first` on: 1 + the index of its frame, or 0 for none.
    slots: Vec<u32>,
    frames: Vec<PatternFrame>,
}

impl PatternFrames {
    /// The frames in any order (parallel preparation hands them over as it finishes); an
    /// object given twice keeps its first frame (an object's frame is the same wherever
    /// it is prepared).
    pub fn new(frames: Vec<(Handle<Object>, PatternFrame)>) -> PatternFrames {
        let indices = frames.iter().map(|(object, _)| object.index());
        let (Some(first), Some(last)) = (indices.clone().min(), indices.max()) else {
            return PatternFrames::default();
        };
        let mut slots = vec![0u32; last - first + 1];
        let mut kept = Vec::with_capacity(frames.len());
        for (object, frame) in frames {
            let slot = &mut slots[object.index() - first];
            if *slot == 0 {
                kept.push(frame);
                // At most one frame per object, so this stays within the arena's u32 handles.
                *slot = kept.len() as u32;
            }
        }
        PatternFrames {
            first,
            slots,
            frames: kept,
        }
    }

    #[inline]
    pub fn get(&self, object: Handle<Object>) -> Option<&PatternFrame> {
        let slot = *self.slots.get(object.index().checked_sub(self.first)?)?;
        self.frames.get((slot as usize).checked_sub(1)?)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Snap {
    None,
    /// The object-space plane `normal·p = offset`; `step` is `normal / |normal|²`.
    Plane {
        normal: Vec3A,
        offset: f32,
        step: Vec3A,
    },
    /// The object-space box; the part names the face.
    Box {
        min: Vec3A,
        max: Vec3A,
    },
}

impl Snap {
    pub fn plane(normal: DVec3, offset: f64) -> Snap {
        Snap::Plane {
            normal: normal.as_vec3a(),
            offset: offset as f32,
            step: (normal / normal.length_squared()).as_vec3a(),
        }
    }
}

impl PatternFrame {
    #[inline]
    pub fn object_point(&self, world_point: Vec3A, part: Part) -> Vec3A {
        let mut p = self.object_from_world.transform_point3a(world_point);
        match self.snap {
            Snap::None => {}
            Snap::Plane {
                normal,
                offset,
                step,
            } => {
                p -= step * (normal.dot(p) - offset);
            }
            Snap::Box { min, max } => {
                let axis = (part / 2).min(2) as usize;
                p[axis] = if part % 2 == 1 { max[axis] } else { min[axis] };
            }
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat4;

    fn pattern(kind: PatternKind, scale: f64) -> PreparedPattern {
        let material = whitted_ir::Material {
            pattern: Some(whitted_ir::Pattern {
                kind,
                a: Handle::from_index(0),
                b: Handle::from_index(1),
                scale,
                pattern_from_object: DMat4::IDENTITY,
            }),
            ..whitted_ir::Material::default()
        };
        PreparedMaterial::new(&material)
            .pattern
            .unwrap_or_else(|| unreachable!("the material has a pattern"))
    }

    #[test]
    fn checker_alternates_in_every_direction() {
        let p = pattern(PatternKind::Checker, 1.0);
        let a = Handle::from_index(0);
        let b = Handle::from_index(1);
        assert_eq!(p.choose(Vec3A::new(0.5, 0.0, 0.5)), a);
        assert_eq!(p.choose(Vec3A::new(1.5, 0.0, 0.5)), b);
        assert_eq!(p.choose(Vec3A::new(1.5, 0.0, 1.5)), a);
        assert_eq!(p.choose(Vec3A::new(-0.5, 0.0, 0.5)), b);
        // The scale widens the cells.
        let wide = pattern(PatternKind::Checker, 2.0);
        assert_eq!(wide.choose(Vec3A::new(1.5, 0.0, 0.5)), a);
    }

    #[test]
    fn powi_is_bit_identical_to_the_runtime_routine() {
        use std::hint::black_box;
        let mut xs = vec![
            0.0f32, -0.0, 1.0, -1.0, 0.5, 0.999_999, 1.000_001, 2.0, -3.5,
        ];
        xs.extend([
            f32::MIN_POSITIVE,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ]);
        // Values of R·V as Phong sees them, spread over (0, 1].
        let mut state = 0x1234_5678u32;
        for _ in 0..2000 {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            xs.push((state >> 8) as f32 / (1u32 << 24) as f32);
        }
        for n in (-40..=300).chain([511, 512, 1000, 2047, 4096, i32::MAX, i32::MIN]) {
            for &x in &xs {
                let expected = black_box(x).powi(black_box(n));
                let got = powi(x, n);
                assert!(
                    got.to_bits() == expected.to_bits() || (got.is_nan() && expected.is_nan()),
                    "{x}^{n}: {got} != {expected}"
                );
            }
        }
    }

    #[test]
    fn cells_are_floors() {
        for x in [
            -2.5f32, -2.0, -1.0e-9, 0.0, 1.0e-9, 0.999, 1.0, 7.5, -1.0e30, 1.0e30,
        ] {
            let expected = f64::from(x).floor().clamp(i64::MIN as f64, i64::MAX as f64) as i64;
            assert_eq!(cell(x), expected, "{x}");
        }
        assert_eq!(cell(f32::NAN), 0);
    }

    #[test]
    fn stripes_depend_on_x_only() {
        let p = pattern(PatternKind::Stripes, 0.5);
        assert_eq!(p.choose(Vec3A::new(0.25, 9.0, -3.0)), Handle::from_index(0));
        assert_eq!(p.choose(Vec3A::new(0.75, 9.0, -3.0)), Handle::from_index(1));
    }

    #[test]
    fn plane_points_snap_onto_the_plane() {
        let frame = PatternFrame {
            object_from_world: Affine3A::IDENTITY,
            world_from_object: Affine3A::IDENTITY,
            snap: Snap::plane(DVec3::Y, 0.0),
        };
        let p = frame.object_point(Vec3A::new(0.3, -1e-7, 0.2), 0);
        assert_eq!(p.y, 0.0);
        let p = frame.object_point(Vec3A::new(0.3, 1e-7, 0.2), 0);
        assert_eq!(p.y, 0.0);
    }
}
