//! The 3D ray view's camera: starts as the scene's camera and orbits (yaw about the scene's up,
//! pitch about the view's right), zooms towards and pans with a target point, the way
//! RayTree's viewer moved around a ray tree. Each move changes the camera in place, so reset
//! gives back the scene's camera exactly.

use whitted_ir::{Camera, DVec3, Projection};

/// How close (in radians) the view may pitch to straight up or down: past the pole the
/// view would flip over, and at it `up` is undefined.
const POLE_MARGIN: f64 = 0.05;

/// The orbit camera of the 3D view.
#[derive(Clone, Debug, PartialEq)]
pub struct OrbitCamera {
    home: Camera,
    home_target: DVec3,
    camera: Camera,
    target: DVec3,
}

impl OrbitCamera {
    /// Starts at `home` (the scene's camera), orbiting about `target`.
    pub fn new(home: Camera, target: DVec3) -> OrbitCamera {
        OrbitCamera {
            camera: home.clone(),
            home,
            home_target: target,
            target,
        }
    }

    /// The camera to draw from.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The point the camera orbits about and zooms towards.
    pub fn target(&self) -> DVec3 {
        self.target
    }

    /// Whether the camera is where it started.
    pub fn is_home(&self) -> bool {
        self.camera == self.home && self.target == self.home_target
    }

    /// Back to the scene's camera and the first target.
    pub fn reset(&mut self) {
        self.camera = self.home.clone();
        self.target = self.home_target;
    }

    fn up_axis(&self) -> DVec3 {
        self.home.up.try_normalize().unwrap_or(DVec3::Y)
    }

    fn forward(&self) -> DVec3 {
        (self.camera.look_at - self.camera.eye)
            .try_normalize()
            .unwrap_or(DVec3::Z)
    }

    fn right(&self) -> DVec3 {
        self.forward()
            .cross(self.camera.up)
            .try_normalize()
            .unwrap_or(DVec3::X)
    }

    /// Rotates the eye and the point looked at by `angle` radians about the line through the
    /// target along the unit `axis` (right-handed).
    fn rotate(&mut self, axis: DVec3, angle: f64) {
        let target = self.target;
        self.camera.eye = target + rotate_about(self.camera.eye - target, axis, angle);
        self.camera.look_at = target + rotate_about(self.camera.look_at - target, axis, angle);
    }

    /// Orbits by `yaw` radians about the scene's up (positive: the camera moves to its right,
    /// so the scene turns left) and `pitch` radians about the view's right (positive: the
    /// camera rises and looks down more). A pitch that would pass straight up or down stops
    /// short of it.
    pub fn orbit(&mut self, yaw: f64, pitch: f64) {
        let up = self.up_axis();
        if yaw.is_finite() && yaw != 0.0 {
            // About up, +yaw takes the eye offset (-forward) towards forward × up: the right.
            self.rotate(up, yaw);
        }
        if pitch.is_finite() && pitch != 0.0 {
            // The angle between the view direction and up, kept inside (margin, π - margin).
            let elevation = self.forward().dot(up).clamp(-1.0, 1.0).acos();
            let wanted = (elevation + pitch).clamp(POLE_MARGIN, std::f64::consts::PI - POLE_MARGIN);
            let allowed = wanted - elevation;
            if allowed != 0.0 {
                // About right, a positive angle turns forward towards the camera's up.
                let right = self.right();
                self.rotate(right, -allowed);
            }
        }
    }

    /// Moves towards the target (`factor` > 1) or away from it (< 1), keeping the direction
    /// of view, so the target stays where it is on screen.
    pub fn zoom(&mut self, factor: f64) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let target = self.target;
        let distance = (self.camera.eye - target).length();
        // Not so near that the camera sits on the target, nor so far that it is lost.
        let new_distance = (distance / factor).clamp(1e-3, 1e6);
        let scale = if distance > 0.0 {
            new_distance / distance
        } else {
            1.0
        };
        self.camera.eye = target + (self.camera.eye - target) * scale;
        self.camera.look_at = target + (self.camera.look_at - target) * scale;
        if let Projection::Orthographic { view_height } = &mut self.camera.projection {
            *view_height *= scale;
        }
    }

    /// Moves the camera and its target sideways and up by fractions of the view's height at
    /// the target (positive: the scene moves left / down on screen).
    pub fn pan(&mut self, right: f64, up: f64) {
        let distance = (self.camera.eye - self.target).length();
        let view_height = match self.camera.projection {
            Projection::Perspective {
                vertical_fov_degrees,
            } => 2.0 * distance * (vertical_fov_degrees.to_radians() / 2.0).tan(),
            Projection::Orthographic { view_height } => view_height,
        };
        let camera_up = self.right().cross(self.forward());
        let offset = (self.right() * right + camera_up * up) * view_height;
        if offset.is_finite() {
            self.camera.eye += offset;
            self.camera.look_at += offset;
            self.target += offset;
        }
    }
}

/// Rodrigues' rotation of `v` by `angle` radians about the unit vector `axis`.
fn rotate_about(v: DVec3, axis: DVec3, angle: f64) -> DVec3 {
    let (sin, cos) = angle.sin_cos();
    v * cos + axis.cross(v) * sin + axis * axis.dot(v) * (1.0 - cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn home() -> Camera {
        Camera {
            eye: DVec3::new(0.0, 1.6, -6.5),
            look_at: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::Y,
            projection: Projection::Perspective {
                vertical_fov_degrees: 45.0,
            },
        }
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-9
    }

    #[test]
    fn reset_returns_exactly_the_scene_camera() {
        let mut orbit = OrbitCamera::new(home(), DVec3::new(-0.6, 1.0, -2.0));
        assert!(orbit.is_home());
        orbit.orbit(0.7, -0.3);
        orbit.zoom(2.0);
        orbit.pan(0.25, 0.1);
        assert!(!orbit.is_home());
        orbit.reset();
        assert_eq!(orbit.camera(), &home());
        assert_eq!(orbit.target(), DVec3::new(-0.6, 1.0, -2.0));
        assert!(orbit.is_home());
    }

    #[test]
    fn yaw_by_a_full_turn_returns_to_the_start() {
        let mut orbit = OrbitCamera::new(home(), DVec3::new(0.0, 1.0, 0.0));
        orbit.orbit(std::f64::consts::TAU, 0.0);
        assert!(
            close(orbit.camera().eye, home().eye),
            "{:?}",
            orbit.camera()
        );
        assert!(close(orbit.camera().look_at, home().look_at));
        let mut stepped = OrbitCamera::new(home(), DVec3::new(0.0, 1.0, 0.0));
        for _ in 0..36 {
            stepped.orbit(std::f64::consts::TAU / 36.0, 0.0);
        }
        assert!(close(stepped.camera().eye, home().eye));
    }

    /// Looking along +z from z = -5 at the origin, a quarter turn to the camera's right puts
    /// it at x = -5 (its right is -x in this right-handed world: forward × up = +z × +y).
    #[test]
    fn a_quarter_yaw_moves_the_eye_round_the_target() {
        let camera = Camera {
            eye: DVec3::new(0.0, 0.0, -5.0),
            look_at: DVec3::ZERO,
            ..home()
        };
        let mut orbit = OrbitCamera::new(camera, DVec3::ZERO);
        orbit.orbit(std::f64::consts::FRAC_PI_2, 0.0);
        assert!(
            close(orbit.camera().eye, DVec3::new(-5.0, 0.0, 0.0)),
            "{:?}",
            orbit.camera().eye
        );
        assert!(close(orbit.camera().look_at, DVec3::ZERO));
    }

    #[test]
    fn pitch_stops_short_of_the_pole_and_zoom_keeps_the_view_direction() {
        let mut orbit = OrbitCamera::new(home(), DVec3::new(0.0, 1.0, 0.0));
        orbit.orbit(0.0, 10.0);
        let forward = orbit.forward();
        assert!(forward.y < 0.0 && forward.y > -1.0, "{forward:?}");
        assert!(
            orbit.camera().eye.y > 1.0,
            "the camera rose above the target"
        );
        let before = orbit.forward();
        let distance = (orbit.camera().eye - orbit.target()).length();
        orbit.zoom(2.0);
        assert!(close(orbit.forward(), before));
        let after = (orbit.camera().eye - orbit.target()).length();
        assert!((after - distance / 2.0).abs() < 1e-9);
        // Bad input changes nothing.
        let kept = orbit.clone();
        orbit.zoom(0.0);
        orbit.zoom(f64::NAN);
        orbit.orbit(f64::NAN, f64::INFINITY);
        assert_eq!(orbit, kept);
    }

    #[test]
    fn pan_moves_camera_and_target_together() {
        let mut orbit = OrbitCamera::new(home(), DVec3::new(0.0, 1.0, 0.0));
        let offset_before = orbit.camera().eye - orbit.target();
        orbit.pan(0.5, 0.0);
        assert!(close(orbit.camera().eye - orbit.target(), offset_before));
        assert!(orbit.target().x < 0.0, "right of this camera is -x");
    }
}
