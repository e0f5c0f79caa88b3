//! The camera: an orthonormal basis from the IR camera, and the primary ray through any
//! point of the image plane.

use glam::Vec3A;
use whitted_ir::{Camera, Projection, SamplePosition};

use whitted_bvh::Ray;

#[derive(Clone, Debug, PartialEq)]
pub struct PreparedCamera {
    eye: Vec3A,
    forward: Vec3A,
    right: Vec3A,
    up: Vec3A,
    projection: CameraProjection,
    /// Added to every image-plane point, in pixels: zero, or half a pixel towards the
    /// pixel's lower-left corner with `sample_position corner`.
    shift: (f32, f32),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum CameraProjection {
    /// `tan(fov / 2)`: the half-height of the image plane at distance 1.
    Perspective { tan_half_fov: f32 },
    /// Half the view height in world units.
    Orthographic { half_height: f32 },
}

impl PreparedCamera {
    pub fn new(camera: &Camera) -> PreparedCamera {
        let forward = (camera.look_at - camera.eye).normalize();
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        let projection = match camera.projection {
            Projection::Perspective {
                vertical_fov_degrees,
            } => CameraProjection::Perspective {
                tan_half_fov: (vertical_fov_degrees.to_radians() / 2.0).tan() as f32,
            },
            Projection::Orthographic { view_height } => CameraProjection::Orthographic {
                half_height: (view_height / 2.0) as f32,
            },
        };
        PreparedCamera {
            eye: camera.eye.as_vec3a(),
            forward: forward.as_vec3a(),
            right: right.as_vec3a(),
            up: up.as_vec3a(),
            projection,
            shift: (0.0, 0.0),
        }
    }

    /// The ray through the image-plane point `(x, y)` of a `width × height` image, measured
    /// in pixels from the top-left corner (so pixel centres are at `i + 0.5`).
    #[inline]
    /// The camera whose samples are moved as `position` says. `Corner` is the lower-left
    /// corner: where a tracer samples that maps pixel (i, j), j counted from the bottom
    /// row as the course's images are, to the image-plane point (i / width, j / height).
    pub fn placing_samples(self, position: SamplePosition) -> PreparedCamera {
        let shift = match position {
            SamplePosition::Centre => (0.0, 0.0),
            SamplePosition::Corner => (-0.5, 0.5),
        };
        PreparedCamera { shift, ..self }
    }

    pub fn ray(&self, x: f32, y: f32, width: u32, height: u32) -> Ray {
        let (w, h) = (width.max(1) as f32, height.max(1) as f32);
        let aspect = w / h;
        // Screen coordinates in [-1, 1], +v upwards.
        let u = 2.0 * (x + self.shift.0) / w - 1.0;
        let v = 1.0 - 2.0 * (y + self.shift.1) / h;
        match self.projection {
            CameraProjection::Perspective { tan_half_fov } => {
                let direction = self.forward
                    + (u * tan_half_fov * aspect) * self.right
                    + (v * tan_half_fov) * self.up;
                Ray::new(self.eye, direction.normalize())
            }
            CameraProjection::Orthographic { half_height } => {
                let origin = self.eye
                    + (u * half_height * aspect) * self.right
                    + (v * half_height) * self.up;
                Ray::new(origin, self.forward)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn centre_ray_looks_at_the_target_and_corners_span_the_fov() {
        let camera = PreparedCamera::new(&Camera {
            eye: DVec3::new(0.0, 0.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            projection: Projection::Perspective {
                vertical_fov_degrees: 90.0,
            },
        });
        let centre = camera.ray(100.0, 50.0, 200, 100);
        assert!(centre.direction.abs_diff_eq(-Vec3A::Z, 1e-6));
        // The top edge is 45° up; the right edge is further out by the aspect ratio 2.
        let top = camera.ray(100.0, 0.0, 200, 100);
        assert!(top
            .direction
            .abs_diff_eq(Vec3A::new(0.0, 1.0, -1.0).normalize(), 1e-6));
        let right = camera.ray(200.0, 50.0, 200, 100);
        assert!(right
            .direction
            .abs_diff_eq(Vec3A::new(2.0, 0.0, -1.0).normalize(), 1e-6));
    }

    #[test]
    fn orthographic_rays_are_parallel() {
        let camera = PreparedCamera::new(&Camera {
            eye: DVec3::new(0.0, 0.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            projection: Projection::Orthographic { view_height: 4.0 },
        });
        let a = camera.ray(0.0, 0.0, 100, 100);
        let b = camera.ray(100.0, 100.0, 100, 100);
        assert_eq!(a.direction, b.direction);
        assert!(a.origin.abs_diff_eq(Vec3A::new(-2.0, 2.0, 5.0), 1e-6));
        assert!(b.origin.abs_diff_eq(Vec3A::new(2.0, -2.0, 5.0), 1e-6));
    }
}
