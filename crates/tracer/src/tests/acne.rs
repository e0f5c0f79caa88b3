//! Surface acne and speckle: renders of grazing and coincident cases, checked pixel by pixel.
//!
//! Each check is paired with the same render without the surface offset, which must show
//! the defect: that proves the check can fail, and that the offset is what prevents it.

use glam::{DMat4, DVec3};
use whitted_ir::{Handle, Material, Object, Pattern, PatternKind, Shape};

use super::{options, prepare, trace_all, trace_all_scaled, Node};
use crate::recorder::{RayKind, ShadowResult};
use crate::testing::{glass, matte, mirror, plane_y, sphere, SceneBuilder};

/// Hits closer than this to the surface a ray left count as self-intersection.
const SELF_HIT: f32 = 1e-3;

/// Shadow rays blocked by the object they left, and secondary rays hitting the object they
/// left, within [`SELF_HIT`]: the signature of acne.
fn self_hits(trees: &[Node]) -> usize {
    let mut count = 0;
    for tree in trees {
        for node in tree.walk() {
            let Some(hit) = node.hit else { continue };
            for light in &node.lights {
                if let Some(shadow) = light.shadow_ray {
                    if let ShadowResult::Blocked { object, t, .. } = shadow.result {
                        if object == hit.object && t < SELF_HIT {
                            count += 1;
                        }
                    }
                }
            }
            for child in &node.children {
                if let Some(child_hit) = child.hit {
                    if child_hit.object == hit.object && child_hit.t < SELF_HIT {
                        count += 1;
                    }
                }
            }
        }
    }
    count
}

/// A sphere resting on a checkered plane, a box face-on, a box turned 40°, a mirror and a
/// glass sphere, all moved by `shift` (far from the origin, f32 has fewer digits to spare).
fn showcase(shift: DVec3, eye: DVec3, look_at: DVec3) -> SceneBuilder {
    let mut b = SceneBuilder::new();
    b.camera(eye + shift, look_at + shift, 50.0);
    b.point_light(DVec3::new(-5.0, 10.0, 6.0) + shift, 1.0);
    let white = b.material(matte(0.9, 0.9, 0.9));
    let dark = b.material(matte(0.2, 0.2, 0.2));
    let checker = b.material(Material {
        pattern: Some(Pattern {
            kind: PatternKind::Checker,
            a: white,
            b: dark,
            scale: 1.0,
            pattern_from_object: DMat4::IDENTITY,
        }),
        ..Material::default()
    });
    let red = b.material(matte(0.8, 0.2, 0.2));
    let mirror = b.material(mirror());
    let glass = b.material(glass());
    let at = DMat4::from_translation(shift);
    b.add(plane_y(0.0), at, checker);
    b.add(sphere(0.0, 1.0, 0.0, 1.0), at, red);
    b.add(
        Shape::Box {
            min: DVec3::new(1.5, 0.0, -1.0),
            max: DVec3::new(3.5, 2.0, 1.0),
        },
        at,
        red,
    );
    b.add(
        Shape::Box {
            min: DVec3::new(-1.0, 0.0, -1.0),
            max: DVec3::new(1.0, 1.5, 1.0),
        },
        at * DMat4::from_translation(DVec3::new(-3.0, 0.0, 0.0))
            * DMat4::from_rotation_y(40f64.to_radians()),
        red,
    );
    b.add(sphere(-1.5, 0.6, 2.2, 0.6), at, mirror);
    b.add(sphere(1.2, 0.5, 2.5, 0.5), at, glass);
    b
}

fn assert_acne_free_and_sensitive(builder: SceneBuilder, what: &str) {
    let scene = prepare(builder);
    let opts = options(64, 48);
    let clean = self_hits(&trace_all(&scene, &opts, true));
    assert_eq!(
        clean, 0,
        "{what}: {clean} self-intersections at the default epsilon"
    );
    let without_offset = self_hits(&trace_all(&scene, &opts, false));
    assert!(
        without_offset > 50,
        "{what}: removing the offset should cause acne, found only {without_offset}"
    );
}

#[test]
fn no_self_intersection_near_the_origin() {
    assert_acne_free_and_sensitive(
        showcase(
            DVec3::ZERO,
            DVec3::new(0.0, 2.5, 9.0),
            DVec3::new(0.0, 0.8, 0.0),
        ),
        "near the origin",
    );
}

#[test]
fn no_self_intersection_far_from_the_origin() {
    assert_acne_free_and_sensitive(
        showcase(
            DVec3::new(3000.0, 0.0, -2000.0),
            DVec3::new(0.0, 2.5, 9.0),
            DVec3::new(0.0, 0.8, 0.0),
        ),
        "far from the origin",
    );
}

#[test]
fn no_self_intersection_at_grazing_angles() {
    // The eye just above the plane, looking along it: the plane, the box faces and the
    // spheres' silhouettes are all seen almost edge-on.
    assert_acne_free_and_sensitive(
        showcase(
            DVec3::ZERO,
            DVec3::new(0.3, 0.08, 12.0),
            DVec3::new(-0.4, 0.3, -8.0),
        ),
        "grazing view",
    );
}

/// Whether the segment from `p` to `light` passes through the ball (f64, exact enough),
/// and how far it stays from the ball's surface.
fn segment_vs_ball(p: DVec3, light: DVec3, center: DVec3, radius: f64) -> (bool, f64) {
    let d = light - p;
    let t = ((center - p).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    let closest = (p + d * t - center).length();
    (closest < radius, (closest - radius).abs())
}

/// Every lit point of a plane in view must be lit, every point in the sphere's shadow dark;
/// compared with an exact f64 test away from the shadow's edge.
#[test]
fn plane_shadows_match_the_exact_answer() {
    let light = DVec3::new(-4.0, 7.0, 3.0);
    let center = DVec3::new(0.0, 1.0, 0.0);
    let mut b = SceneBuilder::new();
    b.camera(DVec3::new(0.0, 3.0, 8.0), DVec3::new(0.0, 0.0, 0.0), 60.0);
    b.point_light(light, 1.0);
    let floor = b.material(matte(0.8, 0.8, 0.8));
    let ball = b.material(matte(0.8, 0.2, 0.2));
    let plane = b.add(plane_y(0.0), DMat4::IDENTITY, floor);
    b.add(sphere(0.0, 1.0, 0.0, 1.0), DMat4::IDENTITY, ball);
    let scene = prepare(b);
    let opts = options(80, 60);
    let mismatches = |offset_scale: f32| {
        let mut compared = 0;
        let mut wrong = 0;
        for tree in trace_all_scaled(&scene, &opts, offset_scale) {
            let Some(hit) = tree.hit else { continue };
            if hit.object != plane {
                continue;
            }
            let p = hit.point.as_dvec3();
            let (inside, margin) = segment_vs_ball(p, light, center, 1.0);
            if margin < 1e-3 {
                continue;
            }
            compared += 1;
            let shadowed = tree.lights.iter().any(|l| {
                matches!(
                    l.shadow_ray.map(|s| s.result),
                    Some(ShadowResult::Blocked { .. })
                )
            });
            if shadowed != inside {
                wrong += 1;
            }
        }
        (compared, wrong)
    };
    let (compared, wrong) = mismatches(1.0);
    assert!(compared > 2000, "only {compared} plane pixels compared");
    assert_eq!(
        wrong, 0,
        "{wrong} of {compared} plane pixels shaded wrongly"
    );
    // The plane's hit points lie on it exactly, so even no offset is safe there; shadow
    // rays started below it must fail, which proves the check.
    let (_, wrong_below) = mismatches(-1e4);
    assert!(
        wrong_below > 100,
        "shadow rays started below the plane should shadow it, got {wrong_below}"
    );
}

/// The checker on the plane y = 0 must follow the exact cells: the computed hit point is a
/// hair above or below 0, and without snapping it back onto the plane `floor(y)` flips
/// between −1 and 0 from pixel to pixel.
#[test]
fn checker_on_a_plane_has_no_speckle() {
    let mut b = SceneBuilder::new();
    b.camera(DVec3::new(0.3, 1.5, 6.0), DVec3::new(0.0, 0.0, -3.0), 60.0);
    b.point_light(DVec3::new(0.0, 10.0, 0.0), 1.0);
    let white = b.material(matte(1.0, 1.0, 1.0));
    let black = b.material(matte(0.0, 0.0, 0.0));
    let checker = b.material(Material {
        pattern: Some(Pattern {
            kind: PatternKind::Checker,
            a: white,
            b: black,
            scale: 1.0,
            pattern_from_object: DMat4::IDENTITY,
        }),
        ..Material::default()
    });
    b.add(plane_y(0.0), DMat4::IDENTITY, checker);
    let scene = prepare(b);
    let opts = options(96, 64);
    let mut compared = 0;
    for tree in trace_all(&scene, &opts, true) {
        let Some(hit) = tree.hit else { continue };
        let p = hit.point.as_dvec3();
        let near_edge = |v: f64| (v - v.round()).abs() < 1e-3;
        if near_edge(p.x) || near_edge(p.z) {
            continue;
        }
        compared += 1;
        let even = (p.x.floor() + p.z.floor()).rem_euclid(2.0) == 0.0;
        let expected: Handle<Material> = if even { white } else { black };
        assert_eq!(hit.resolved_material, expected, "at {p}");
    }
    assert!(compared > 3000, "only {compared} pixels compared");
}

/// On boxes seen face-on and edge-on, every hit gets the normal of the face it lies on.
#[test]
fn box_faces_get_their_own_normals_at_every_angle() {
    for (eye, look_at) in [
        (DVec3::new(0.0, 1.0, 6.0), DVec3::new(0.0, 1.0, 0.0)),
        (DVec3::new(6.0, 1.01, 1.05), DVec3::new(-6.0, 1.0, 0.95)),
        (DVec3::new(2.0, 2.02, 5.0), DVec3::new(-1.0, 1.98, -5.0)),
    ] {
        let mut b = SceneBuilder::new();
        b.camera(eye, look_at, 40.0);
        b.point_light(DVec3::new(3.0, 8.0, 6.0), 1.0);
        let red = b.material(matte(0.8, 0.2, 0.2));
        let (min, max) = (DVec3::new(-1.0, 0.0, -1.0), DVec3::new(1.0, 2.0, 1.0));
        let cube: Handle<Object> = b.add(Shape::Box { min, max }, DMat4::IDENTITY, red);
        let scene = prepare(b);
        let opts = options(64, 64);
        let mut hits = 0;
        for tree in trace_all(&scene, &opts, true) {
            let Some(hit) = tree.hit.filter(|h| h.object == cube) else {
                continue;
            };
            hits += 1;
            let n = hit.geometric_normal;
            let axis = n.abs().max_position();
            assert!(
                (n[axis].abs() - 1.0).abs() < 1e-5,
                "normal {n} is not a face normal"
            );
            let face = if n[axis] > 0.0 { max[axis] } else { min[axis] };
            assert!(
                (f64::from(hit.point[axis]) - face).abs() < 1e-4,
                "point {} is not on the face of normal {n}",
                hit.point
            );
        }
        assert!(hits > 100, "the box should fill part of the view");
    }
}

/// Mirrors and glass must not re-hit themselves. Every object in the showcase is convex,
/// so a ray reflected off the outside of one never meets it again, and a transmitted ray
/// meets it again only on the far side.
#[test]
fn secondary_rays_leave_their_surface() {
    let scene = prepare(showcase(
        DVec3::ZERO,
        DVec3::new(0.0, 1.0, 6.0),
        DVec3::new(-0.2, 0.6, 2.0),
    ));
    let opts = options(64, 48);
    let mut secondary = 0;
    for tree in trace_all(&scene, &opts, true) {
        for node in tree.walk() {
            let Some(hit) = node.hit else { continue };
            for child in &node.children {
                secondary += 1;
                let Some(child_hit) = child.hit else { continue };
                if child_hit.object != hit.object {
                    continue;
                }
                assert!(
                    !(child.start.kind == RayKind::Reflected && hit.front_face),
                    "a reflected ray re-hit the convex object it left, at t = {}",
                    child_hit.t
                );
                assert!(child_hit.t > SELF_HIT, "self-hit at t = {}", child_hit.t);
            }
        }
    }
    assert!(secondary > 500, "only {secondary} secondary rays traced");
}

/// Whether the shadow ray from where a ray straight down meets the slab's top, at
/// `(-0.0002, 0, 0.3)`, is blocked: a slab with a rim 0.0024 thick that stands 5e-5 above
/// the top (one CSG union), lit by a directional light grazing the top at N·L = 0.03 from
/// beyond the rim. The straight line to the light enters the rim at height 3.6e-5.
fn thin_rim_blocks(epsilon: Option<f64>) -> bool {
    let mut b = SceneBuilder::new();
    b.settings().epsilon = epsilon;
    let n_dot_l: f64 = 0.03;
    let to_light = DVec3::new((1.0 - n_dot_l * n_dot_l).sqrt(), n_dot_l, 0.0);
    b.light(whitted_ir::Light {
        name: None,
        color: whitted_ir::Color::gray(1.0),
        kind: whitted_ir::LightKind::Directional {
            direction: -to_light,
        },
    });
    let m = b.material(matte(0.8, 0.8, 0.8));
    let slab = b.part(
        Shape::Box {
            min: DVec3::new(-1.0, -0.5, -1.0),
            max: DVec3::new(1.0, 0.0, 1.0),
        },
        DMat4::IDENTITY,
        m,
    );
    let rim = b.part(
        Shape::Box {
            min: DVec3::new(0.001, -0.5, -1.0),
            max: DVec3::new(0.0034, 5e-5, 1.0),
        },
        DMat4::IDENTITY,
        m,
    );
    b.csg(whitted_ir::CsgOp::Union, vec![slab, rim], m);
    let scene = prepare(b);
    let mut tracer = crate::trace::Tracer::new(&scene, 1, 0.001);
    let mut tape = super::Tape::default();
    let ray = whitted_bvh::Ray::new(
        glam::Vec3A::new(-0.0002, 0.5, 0.3),
        glam::Vec3A::new(0.0, -1.0, 0.0),
    );
    tracer.trace(&ray, &crate::trace::PathState::camera(), &mut tape);
    let Some(root) = tape.roots.pop() else {
        panic!("no ray recorded");
    };
    let Some(hit) = root.hit else {
        panic!("the ray missed the slab");
    };
    assert!(hit.point.y.abs() < 1e-6, "{}", hit.point);
    let Some(shadow) = root.lights.first().and_then(|l| l.shadow_ray) else {
        panic!("no shadow ray was cast");
    };
    matches!(shadow.result, ShadowResult::Blocked { .. })
}

/// Issue 9: shadow rays started 1e-4 along the normal and passed over a thin rim under a
/// grazing light. With error-bounded offsets the rim blocks; with the old fixed offset
/// (now only as an explicit `epsilon 1e-4`) the light leaks, which proves the check.
#[test]
fn thin_rim_blocks_a_grazing_light() {
    assert!(thin_rim_blocks(None), "the light leaks over the rim");
    assert!(
        !thin_rim_blocks(Some(1e-4)),
        "with an explicit epsilon of 1e-4 the shadow ray should start above the rim"
    );
}
