//! The 3D ray view's geometry: the picked pixel's rays as world-space segments (each ray
//! from its origin to what it hit, its light or its blocker), and their projection through a
//! camera onto a grid of dots, clipped to the near plane and to the screen.
//!
//! The camera basis is the tracer's (forward, right = forward × up, up = right × forward),
//! so a point projects where the tracer's camera would see it.

use whitted_ir::{Camera, DVec3, Projection};
use whitted_tracer::ray_tree::{RayTree, ShadowOutcome};
use whitted_tracer::RayKind;

use crate::tree::state::NodeId;

/// What a segment is, for its colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SegmentKind {
    Camera,
    Reflected,
    Transmitted,
    /// A shadow ray that reached its light (clear or through filters).
    ShadowLit,
    /// A shadow ray stopped by a blocker: the segment ends at the blocker.
    ShadowBlocked,
}

/// One recorded ray as a line in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// The node of the tree this is (numbered like [`crate::tree::state::TreeView`]).
    pub node: NodeId,
    pub kind: SegmentKind,
    pub from: DVec3,
    pub to: DVec3,
}

fn vector(v: [f32; 3]) -> DVec3 {
    DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]))
}

/// Every ray of `tree` as a segment, in the tree view's pre-order numbering. Rays that hit
/// nothing, and shadow rays towards directional lights, are drawn `miss_length` long.
pub fn segments(tree: &RayTree, miss_length: f64) -> Vec<Segment> {
    let mut segments = Vec::new();
    let mut id = 0;
    for sample in &tree.samples {
        // Pre-order with an explicit stack (children pushed in reverse), as the tree view
        // numbers its nodes; a deep tree must not overflow the call stack.
        let mut stack = vec![&sample.root];
        while let Some(node) = stack.pop() {
            let from = vector(node.origin);
            let direction = vector(node.direction);
            let along = |t: f64| from + direction * t;
            let (kind, to) = match node.kind {
                RayKind::Shadow => match &node.shadow {
                    Some(shadow) if shadow.result == ShadowOutcome::Blocked => {
                        let t = shadow
                            .blocker
                            .as_ref()
                            .map_or(miss_length, |b| f64::from(b.t));
                        (SegmentKind::ShadowBlocked, along(t))
                    }
                    Some(shadow) => {
                        let t = shadow.max_t.map_or(miss_length, f64::from);
                        (SegmentKind::ShadowLit, along(t))
                    }
                    None => (SegmentKind::ShadowLit, along(miss_length)),
                },
                other => {
                    let kind = match other {
                        RayKind::Reflected => SegmentKind::Reflected,
                        RayKind::Transmitted => SegmentKind::Transmitted,
                        _ => SegmentKind::Camera,
                    };
                    match &node.hit {
                        Some(hit) => (kind, vector(hit.point)),
                        None => (kind, along(miss_length)),
                    }
                }
            };
            if to.is_finite() && from.is_finite() {
                segments.push(Segment {
                    node: id,
                    kind,
                    from,
                    to,
                });
            }
            id += 1;
            stack.extend(node.children.iter().rev());
        }
    }
    segments
}

/// How far in front of the eye (in world units) the near plane is: points nearer than this
/// are not drawn, so nothing divides by a depth near zero.
pub const NEAR: f64 = 1e-3;

/// A camera's projection onto a `width × height` grid (of dots, pixels or cells, square
/// in shape), x to the right and y downwards, (0, 0) at the top left corner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewProjection {
    eye: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    /// Half the view's height at depth 1 (perspective) or in world units (orthographic).
    half_height: f64,
    perspective: bool,
    width: f64,
    height: f64,
}

impl ViewProjection {
    pub fn new(camera: &Camera, width: f64, height: f64) -> ViewProjection {
        let forward = (camera.look_at - camera.eye)
            .try_normalize()
            .unwrap_or(DVec3::Z);
        let right = forward.cross(camera.up).try_normalize().unwrap_or(DVec3::X);
        let up = right.cross(forward);
        let (half_height, perspective) = match camera.projection {
            Projection::Perspective {
                vertical_fov_degrees,
            } => ((vertical_fov_degrees.to_radians() / 2.0).tan(), true),
            Projection::Orthographic { view_height } => (view_height / 2.0, false),
        };
        ViewProjection {
            eye: camera.eye,
            forward,
            right,
            up,
            half_height,
            perspective,
            width: width.max(1.0),
            height: height.max(1.0),
        }
    }

    /// A point in camera space: (right, up, depth).
    fn camera_space(&self, point: DVec3) -> DVec3 {
        let offset = point - self.eye;
        DVec3::new(
            offset.dot(self.right),
            offset.dot(self.up),
            offset.dot(self.forward),
        )
    }

    /// A camera-space point (in front of the near plane) on the grid.
    fn grid_point(&self, p: DVec3) -> (f64, f64) {
        let aspect = self.width / self.height;
        let scale = if self.perspective {
            self.half_height * p.z
        } else {
            self.half_height
        };
        let u = p.x / (scale * aspect);
        let v = p.y / scale;
        ((u + 1.0) / 2.0 * self.width, (1.0 - v) / 2.0 * self.height)
    }

    /// Where `point` lands on the grid; `None` behind the near plane (perspective only: an
    /// orthographic view sees behind its eye as well).
    pub fn project(&self, point: DVec3) -> Option<(f64, f64)> {
        let p = self.camera_space(point);
        // NaN depths fail the test too.
        if self.perspective && p.z.partial_cmp(&NEAR).is_none_or(|o| o.is_lt()) {
            return None;
        }
        Some(self.grid_point(p))
    }

    /// The part of the segment `a`–`b` in front of the near plane and on the grid, as grid
    /// points; `None` when no part of it is.
    pub fn project_segment(&self, a: DVec3, b: DVec3) -> Option<((f64, f64), (f64, f64))> {
        let (mut pa, mut pb) = (self.camera_space(a), self.camera_space(b));
        if !(pa.is_finite() && pb.is_finite()) {
            return None;
        }
        if self.perspective {
            // Cut at the near plane: keep the part with depth >= NEAR.
            match (pa.z >= NEAR, pb.z >= NEAR) {
                (false, false) => return None,
                (true, true) => {}
                (a_in, _) => {
                    let t = (NEAR - pa.z) / (pb.z - pa.z);
                    let cut = pa + (pb - pa) * t;
                    if a_in {
                        pb = cut;
                    } else {
                        pa = cut;
                    }
                }
            }
        }
        clip_to_rect(
            self.grid_point(pa),
            self.grid_point(pb),
            self.width,
            self.height,
        )
    }
}

/// Liang–Barsky: the part of the 2D segment `a`–`b` inside `[0, width] × [0, height]`.
pub fn clip_to_rect(
    a: (f64, f64),
    b: (f64, f64),
    width: f64,
    height: f64,
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut enter, mut leave) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0),
        (dx, width - a.0),
        (-dy, a.1),
        (dy, height - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                enter = enter.max(t);
            } else {
                leave = leave.min(t);
            }
        }
    }
    if enter.partial_cmp(&leave).is_none_or(|o| o.is_gt()) {
        return None;
    }
    let at = |t: f64| (a.0 + dx * t, a.1 + dy * t);
    Some((at(enter), at(leave)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ray_view::orbit::OrbitCamera;

    fn camera() -> Camera {
        Camera {
            eye: DVec3::new(0.0, 0.0, -5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            projection: Projection::Perspective {
                vertical_fov_degrees: 90.0,
            },
        }
    }

    fn close(a: (f64, f64), b: (f64, f64)) -> bool {
        (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9
    }

    #[test]
    fn a_point_straight_ahead_lands_in_the_centre() {
        let view = ViewProjection::new(&camera(), 200.0, 100.0);
        assert_eq!(view.project(DVec3::new(0.0, 0.0, 3.0)), Some((100.0, 50.0)));
        // fov 90°: at depth 5, y = 5 is the top edge; the right (-x here) edge is at x = -10.
        assert!(close(
            view.project(DVec3::new(0.0, 5.0, 0.0)).unwrap(),
            (100.0, 0.0)
        ));
        assert!(close(
            view.project(DVec3::new(-10.0, 0.0, 0.0)).unwrap(),
            (200.0, 50.0)
        ));
        assert_eq!(view.project(DVec3::new(0.0, 0.0, -6.0)), None, "behind");
    }

    /// A quarter turn round the origin moves the eye to x = -5 looking along +x: the point
    /// (0, 0, 2), straight ahead before, is then 2 units to the camera's right at depth 5:
    /// at fov 90° that is 2/5 of the way from the centre to the right edge.
    #[test]
    fn orbiting_a_quarter_turn_moves_a_point_to_a_known_place() {
        let mut orbit = OrbitCamera::new(camera(), DVec3::ZERO);
        let point = DVec3::new(0.0, 0.0, 2.0);
        let before = ViewProjection::new(orbit.camera(), 100.0, 100.0);
        assert!(close(before.project(point).unwrap(), (50.0, 50.0)));
        orbit.orbit(std::f64::consts::FRAC_PI_2, 0.0);
        let after = ViewProjection::new(orbit.camera(), 100.0, 100.0);
        let (x, y) = after.project(point).unwrap();
        assert!(close((x, y), (50.0 + 0.4 * 50.0, 50.0)), "{x}, {y}");
    }

    #[test]
    fn a_segment_crossing_the_near_plane_is_cut_there() {
        let view = ViewProjection::new(&camera(), 100.0, 100.0);
        // From behind the eye (depth -1, 1 below the axis) to depth 1, 0.5 above it. Cut at
        // depth NEAR the line is still 0.25 below the axis, far below the screen at that
        // depth, so the screen clip starts it on the bottom edge, in the centre column.
        let behind = DVec3::new(0.0, -1.0, -6.0);
        let ahead = DVec3::new(0.0, 0.5, -4.0);
        let (a, b) = view.project_segment(behind, ahead).expect("a visible part");
        assert!(close(b, view.project(ahead).unwrap()));
        assert!(close(b, (50.0, 25.0)), "{b:?}");
        assert!(close(a, (50.0, 100.0)), "{a:?}");
        // Wholly behind: nothing.
        assert_eq!(
            view.project_segment(DVec3::new(0.0, 0.0, -7.0), DVec3::new(1.0, 1.0, -6.0)),
            None
        );
        // Wholly in front and on screen: unchanged.
        let (a, b) = view
            .project_segment(DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.0, 2.5, 0.0))
            .unwrap();
        assert!(close(a, (50.0, 50.0)) && close(b, (50.0, 25.0)));
    }

    #[test]
    fn the_near_cut_lands_at_the_near_depth() {
        let view = ViewProjection::new(&camera(), 100.0, 100.0);
        // Along the view axis from behind the eye to depth 2, offset sideways by 1: every
        // point of it is at x = -1 (the camera's right), so after the cut it still is; at
        // depth NEAR that is far off screen, so the clip leaves only the on-screen part.
        let from = DVec3::new(-1.0, 0.0, -7.0);
        let to = DVec3::new(-1.0, 0.0, -3.0);
        let (a, b) = view.project_segment(from, to).unwrap();
        assert!(close(b, (75.0, 50.0)), "{b:?}");
        assert!(close(a, (100.0, 50.0)), "{a:?}");
    }

    #[test]
    fn two_dimensional_clipping() {
        assert_eq!(
            clip_to_rect((-10.0, 5.0), (20.0, 5.0), 10.0, 10.0),
            Some(((0.0, 5.0), (10.0, 5.0)))
        );
        assert_eq!(clip_to_rect((-10.0, -5.0), (-1.0, 20.0), 10.0, 10.0), None);
        assert_eq!(
            clip_to_rect((1.0, 1.0), (2.0, 2.0), 10.0, 10.0),
            Some(((1.0, 1.0), (2.0, 2.0)))
        );
    }
}
