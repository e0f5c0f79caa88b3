//! A ray: an origin and a unit direction in f32, so that `t` is a distance in world units.

use glam::Vec3A;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3A,
    /// Unit length in world space (object-space copies of a ray are not renormalised, so
    /// that `t` means the same point in both spaces).
    pub direction: Vec3A,
}

impl Ray {
    pub fn new(origin: Vec3A, direction: Vec3A) -> Ray {
        Ray { origin, direction }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3A {
        self.origin + t * self.direction
    }
}
