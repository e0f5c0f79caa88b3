//! Where a world point lands in the image: the inverse of the camera's primary rays, so the
//! inspector can mark a ray's hit point on the picture, and the check that nothing nearer
//! hides it from the camera.
//!
//! The camera basis is built exactly as the tracer builds it (forward, right = forward × up,
//! up = right × forward), so a projected hit point of a camera ray lands on its own pixel.

use whitted_ir::{Camera, DVec3, Handle, Object, Projection};
use whitted_tracer::{trace_pixel_with, PreparedScene, Recorder, RenderOptions, SurfaceHit};

/// Where a point falls relative to the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projected {
    /// Inside the image, at this pixel.
    Pixel(u32, u32),
    /// In front of the camera but outside the frame.
    OffScreen,
    /// Behind the camera (or in its image plane).
    Behind,
}

/// Projects `point` into a `width × height` image of `camera`.
pub fn project(camera: &Camera, width: u32, height: u32, point: DVec3) -> Projected {
    let forward = (camera.look_at - camera.eye).normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    let (w, h) = (f64::from(width.max(1)), f64::from(height.max(1)));
    let aspect = w / h;
    let offset = point - camera.eye;
    let depth = offset.dot(forward);
    if depth.is_nan() || depth <= 0.0 {
        return Projected::Behind;
    }
    let (u, v) = match camera.projection {
        Projection::Perspective {
            vertical_fov_degrees,
        } => {
            let tan_half_fov = (vertical_fov_degrees.to_radians() / 2.0).tan();
            (
                offset.dot(right) / (depth * tan_half_fov * aspect),
                offset.dot(up) / (depth * tan_half_fov),
            )
        }
        Projection::Orthographic { view_height } => {
            let half_height = view_height / 2.0;
            (
                offset.dot(right) / (half_height * aspect),
                offset.dot(up) / half_height,
            )
        }
    };
    let x = (u + 1.0) / 2.0 * w;
    let y = (1.0 - v) / 2.0 * h;
    let inside = x >= 0.0 && y >= 0.0 && x < w && y < h;
    if inside {
        Projected::Pixel(x as u32, y as u32)
    } else {
        Projected::OffScreen
    }
}

/// Whether the camera sees a point at a pixel, or something nearer is in the way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sight {
    Visible,
    /// The camera ray through the pixel stops at this object first (possibly the point's
    /// own object: the near side of a sphere hides its far side).
    HiddenBy(Handle<Object>),
}

/// Records the first surface a camera ray hits.
#[derive(Default)]
struct FirstHit(Option<SurfaceHit>);

impl Recorder for FirstHit {
    fn surface_hit(&mut self, hit: &SurfaceHit) {
        if self.0.is_none() {
            self.0 = Some(*hit);
        }
    }
}

/// How much nearer than the point (as a fraction of its distance) the camera's own hit must
/// be to hide it. The pixel's ray passes near, not exactly through, the point, so a surface
/// seen at a grazing angle lands a little in front of or behind it.
const HIDDEN_MARGIN: f64 = 0.02;

/// Traces the camera ray of pixel (`x`, `y`) and says whether it reaches `point` before
/// anything else.
pub fn sight(
    prepared: &PreparedScene,
    options: &RenderOptions,
    eye: DVec3,
    (x, y): (u32, u32),
    point: DVec3,
) -> Sight {
    let mut first = FirstHit::default();
    trace_pixel_with(prepared, options, x, y, 0, &mut first);
    let Some(hit) = first.0 else {
        return Sight::Visible;
    };
    let point_distance = (point - eye).length();
    let hit_distance = (hit.point.as_dvec3() - eye).length();
    if hit_distance < point_distance * (1.0 - HIDDEN_MARGIN) {
        Sight::HiddenBy(hit.object)
    } else {
        Sight::Visible
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_tracer::testing::whitted_classic;

    fn camera() -> Camera {
        Camera {
            eye: DVec3::new(0.0, 0.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            projection: Projection::Perspective {
                vertical_fov_degrees: 90.0,
            },
        }
    }

    #[test]
    fn the_look_at_point_lands_in_the_middle_and_world_x_on_the_left() {
        assert_eq!(
            project(&camera(), 200, 100, DVec3::ZERO),
            Projected::Pixel(100, 50)
        );
        // Looking along -z here, so +x is on the right; up is up.
        match project(&camera(), 200, 100, DVec3::new(1.0, 1.0, 0.0)) {
            Projected::Pixel(x, y) => assert!(x > 100 && y < 50, "{x},{y}"),
            other => panic!("{other:?}"),
        }
        assert_eq!(
            project(&camera(), 200, 100, DVec3::new(0.0, 0.0, 6.0)),
            Projected::Behind
        );
        assert_eq!(
            project(&camera(), 200, 100, DVec3::new(100.0, 0.0, 0.0)),
            Projected::OffScreen
        );
    }

    #[test]
    fn orthographic_points_project_without_perspective() {
        let camera = Camera {
            projection: Projection::Orthographic { view_height: 4.0 },
            ..camera()
        };
        // The view is 8 units wide and 4 high over 200x100 pixels: 25 pixels per unit.
        assert_eq!(
            project(&camera, 200, 100, DVec3::new(-2.0, 1.0, -30.0)),
            Projected::Pixel(50, 25)
        );
    }

    /// The camera ray of a pixel hits a point that projects back onto that pixel: the
    /// projection is the inverse of the tracer's own camera.
    #[test]
    fn a_camera_hit_projects_back_to_its_pixel() {
        let builder = whitted_classic();
        let scene = builder.clone().build().unwrap();
        let prepared = PreparedScene::new(&scene);
        let options = RenderOptions::from_settings(&scene.settings);
        let mut hits = 0;
        for (x, y) in [(100, 200), (320, 240), (410, 270), (600, 450), (20, 470)] {
            let mut first = FirstHit::default();
            trace_pixel_with(&prepared, &options, x, y, 0, &mut first);
            let Some(hit) = first.0 else { continue };
            hits += 1;
            let projected = project(
                &scene.camera,
                options.width,
                options.height,
                hit.point.as_dvec3(),
            );
            assert_eq!(projected, Projected::Pixel(x, y));
            let seen = sight(
                &prepared,
                &options,
                scene.camera.eye,
                (x, y),
                hit.point.as_dvec3(),
            );
            assert_eq!(seen, Sight::Visible);
        }
        assert!(hits >= 3, "only {hits} of the pixels hit anything");
    }
}
