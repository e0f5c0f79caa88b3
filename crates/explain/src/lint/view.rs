//! Objects the camera cannot see: their world bounds lie behind the camera or outside the
//! view frustum, and no sampled ray (camera, reflected, transmitted or shadow) met them, so
//! they show neither in a mirror nor as a shadow. Objects inside the view that other objects
//! hide completely are not looked for (that would take a ray per pixel).

use glam::DVec3;
use whitted_ir::{Diagnostic, Handle, Object, ObjectKind, Projection, Scene};

use super::bounds::world_bounds;
use super::geometry::object_name;
use super::sampled::Samples;
use super::{Lint, LintKind};

/// Where an object is, seen from the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Outside {
    Behind,
    Left,
    Right,
    Above,
    Below,
}

impl Outside {
    fn words(self) -> &'static str {
        match self {
            Outside::Behind => "behind the camera",
            Outside::Left | Outside::Right => "beside the view (outside the field of view)",
            Outside::Above => "above the view (outside the field of view)",
            Outside::Below => "below the view (outside the field of view)",
        }
    }
}

pub(super) fn unseen_objects(scene: &Scene, samples: &Samples, lints: &mut Vec<Lint>) {
    let camera = &scene.camera;
    let Some(forward) = (camera.look_at - camera.eye).try_normalize() else {
        return;
    };
    let Some(right) = forward.cross(camera.up).try_normalize() else {
        return;
    };
    let up = right.cross(forward);
    let aspect = f64::from(scene.settings.width) / f64::from(scene.settings.height.max(1));
    // A group is one thing to its author (a cue whose end leaves the picture is fine):
    // it is unseen only when none of its objects is seen.
    for &handle in &scene.roots {
        if met(scene, samples, handle) {
            continue;
        }
        let Some(bounds) = world_bounds(scene, handle) else {
            continue;
        };
        let local = bounds.corners().map(|c| {
            let d = c - camera.eye;
            DVec3::new(d.dot(right), d.dot(up), d.dot(forward))
        });
        let Some(outside) = outside(&local, camera.projection, aspect) else {
            continue;
        };
        let name = object_name(scene, handle);
        let diagnostic = Diagnostic::warning(
            format!(
                "the camera cannot see {name}: it is {}, and no sampled reflection, refraction \
                 or shadow shows it",
                outside.words()
            ),
            scene.objects.span(handle),
        )
        .with_label(format!("{name} is {}", outside.words()))
        .with_hint(
            "move it (or the camera's eye, look_at or fov) so that it is in view, or remove it"
                .to_string(),
        );
        lints.push(Lint::new(LintKind::UnseenObject, diagnostic));
    }
}

/// The objects a sampled ray can report for `root`: itself, or a group's members.
fn descendants(scene: &Scene, root: Handle<Object>) -> Vec<Handle<Object>> {
    let mut out = vec![root];
    let mut next = 0;
    while let Some(&handle) = out.get(next) {
        next += 1;
        if let Some(ObjectKind::Group { children }) = scene.objects.get(handle).map(|o| &o.kind) {
            out.extend(children);
        }
    }
    out
}

/// Whether a sampled ray met `root` or, for a group, any of its members.
fn met(scene: &Scene, samples: &Samples, root: Handle<Object>) -> bool {
    let met_one = |h: Handle<Object>| samples.met.get(h.index()).copied().unwrap_or(true);
    match scene.objects.get(root).map(|o| &o.kind) {
        Some(ObjectKind::Group { .. }) => descendants(scene, root).into_iter().any(met_one),
        _ => met_one(root),
    }
}

/// Which side of the view every corner (in camera space: x right, y up, z forward) is on.
fn outside(corners: &[DVec3; 8], projection: Projection, aspect: f64) -> Option<Outside> {
    if corners.iter().all(|c| c.z <= 0.0) {
        return Some(Outside::Behind);
    }
    // The view's half width and half height at depth z: growing with z in perspective,
    // fixed in orthographic projection.
    let half_size = |z: f64| -> (f64, f64) {
        match projection {
            Projection::Perspective {
                vertical_fov_degrees,
            } => {
                let tan = (vertical_fov_degrees.to_radians() / 2.0).tan();
                (z * tan * aspect, z * tan)
            }
            Projection::Orthographic { view_height } => {
                (view_height / 2.0 * aspect, view_height / 2.0)
            }
        }
    };
    let half_width = |z: f64| half_size(z).0;
    let half_height = |z: f64| half_size(z).1;
    let all = |f: &dyn Fn(&DVec3) -> bool| corners.iter().all(f);
    if all(&|c| c.x > half_width(c.z)) {
        Some(Outside::Right)
    } else if all(&|c| c.x < -half_width(c.z)) {
        Some(Outside::Left)
    } else if all(&|c| c.y > half_height(c.z)) {
        Some(Outside::Above)
    } else if all(&|c| c.y < -half_height(c.z)) {
        Some(Outside::Below)
    } else {
        None
    }
}
