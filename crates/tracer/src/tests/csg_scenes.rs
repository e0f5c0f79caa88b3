//! CSG through the whole tracer: which surface a ray hits, its normal and its leaf, checked
//! against exact membership tests for every operation and for nested trees.

use glam::{DMat4, DVec3, Vec3A};
use whitted_ir::{CsgOp, Handle, Object, Quadric, QuadricForm, Shape};

use super::prepare;
use crate::query::Scratch;
use crate::scene::PreparedScene;
use crate::testing::{matte, sphere, SceneBuilder};
use whitted_bvh::Ray;

struct Hit {
    t: f32,
    point: Vec3A,
    normal: Vec3A,
    object: Handle<Object>,
    leaf: Handle<Object>,
}

fn first_hit(scene: &PreparedScene, origin: Vec3A, direction: Vec3A) -> Option<Hit> {
    let ray = Ray::new(origin, direction.normalize());
    let mut scratch = Scratch::default();
    let hit = scene.intersect(&ray, 0.0, f32::INFINITY, &mut scratch)?;
    let surface = scene.surface(&ray, &hit);
    Some(Hit {
        t: hit.t,
        point: surface.point,
        normal: surface.geometric_normal,
        object: surface.item.object(),
        leaf: surface.leaf.object,
    })
}

fn unit_box(half: f64) -> Shape {
    Shape::Box {
        min: DVec3::splat(-half),
        max: DVec3::splat(half),
    }
}

#[test]
fn difference_shows_the_inside_of_the_subtracted_solid() {
    let mut b = SceneBuilder::new();
    let m = b.material(matte(0.5, 0.5, 0.5));
    let cube = b.part(unit_box(1.0), DMat4::IDENTITY, m);
    let bite = b.part(sphere(0.0, 0.0, 1.0, 0.6), DMat4::IDENTITY, m);
    let solid = b.csg(CsgOp::Difference, vec![cube, bite], m);
    let scene = prepare(b);
    // Through the bite: the sphere's surface at z = 0.4, normal flipped towards the viewer.
    let h =
        first_hit(&scene, Vec3A::new(0.0, 0.0, 5.0), -Vec3A::Z).unwrap_or_else(|| panic!("miss"));
    assert!((h.point.z - 0.4).abs() < 1e-5, "{}", h.point);
    assert!(h.normal.abs_diff_eq(Vec3A::Z, 1e-5), "{}", h.normal);
    assert_eq!((h.object, h.leaf), (solid, bite));
    // Beside the bite: the cube's own face.
    let h =
        first_hit(&scene, Vec3A::new(0.8, 0.8, 5.0), -Vec3A::Z).unwrap_or_else(|| panic!("miss"));
    assert!((h.point.z - 1.0).abs() < 1e-5);
    assert!(h.normal.abs_diff_eq(Vec3A::Z, 1e-5));
    assert_eq!(h.leaf, cube);
    // Inside the crater, looking sideways: the crater wall faces the axis.
    let h =
        first_hit(&scene, Vec3A::new(0.0, 0.0, 0.7), Vec3A::X).unwrap_or_else(|| panic!("miss"));
    assert_eq!(h.leaf, bite);
    assert!(h.normal.x < -0.5, "{}", h.normal);
}

#[test]
fn intersection_keeps_the_common_part() {
    let mut b = SceneBuilder::new();
    let m = b.material(matte(0.5, 0.5, 0.5));
    let ball = b.part(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, m);
    let cube = b.part(unit_box(0.7), DMat4::IDENTITY, m);
    b.csg(CsgOp::Intersection, vec![ball, cube], m);
    let scene = prepare(b);
    // It is bounded: the BVH holds it.
    assert_eq!(scene.unbounded_count(), 0);
    let h =
        first_hit(&scene, Vec3A::new(0.0, 0.0, 5.0), -Vec3A::Z).unwrap_or_else(|| panic!("miss"));
    assert_eq!(h.leaf, cube);
    assert!((h.point.z - 0.7).abs() < 1e-5);
    // Near the cube's corner the ball's surface is the boundary.
    let h =
        first_hit(&scene, Vec3A::new(0.69, 0.69, 5.0), -Vec3A::Z).unwrap_or_else(|| panic!("miss"));
    assert_eq!(h.leaf, ball);
    let expected_z = (1.0f32 - 2.0 * 0.69 * 0.69).sqrt();
    assert!((h.point.z - expected_z).abs() < 1e-4);
    // Outside the ball: nothing.
    assert!(first_hit(&scene, Vec3A::new(0.75, 0.75, 5.0), -Vec3A::Z).is_none());
}

#[test]
fn union_has_no_inner_surfaces() {
    let mut b = SceneBuilder::new();
    let m = b.material(matte(0.5, 0.5, 0.5));
    let left = b.part(sphere(-0.5, 0.0, 0.0, 1.0), DMat4::IDENTITY, m);
    let right = b.part(sphere(0.5, 0.0, 0.0, 1.0), DMat4::IDENTITY, m);
    b.csg(CsgOp::Union, vec![left, right], m);
    let scene = prepare(b);
    // From inside the left ball, along +x: the next surface is the right ball's far side,
    // not the left ball's surface buried in the right one.
    let h =
        first_hit(&scene, Vec3A::new(-0.5, 0.0, 0.0), Vec3A::X).unwrap_or_else(|| panic!("miss"));
    assert_eq!(h.leaf, right);
    assert!((h.point.x - 1.5).abs() < 1e-5);
}

/// Membership of the nested solid used below, with every primitive grown by `e` (or
/// shrunk, for negative `e`; the subtracted part changes the other way). `e > 0` answers
/// "possibly inside", `e < 0` "surely inside": between the two lies the rounding margin.
fn inside_nested(p: DVec3, e: f64) -> bool {
    let ball = |c: DVec3, r: f64, e: f64| (p - c).length() < r + e;
    let in_box = |lo: DVec3, hi: DVec3, e: f64| {
        p.cmpgt(lo - DVec3::splat(e)).all() && p.cmplt(hi + DVec3::splat(e)).all()
    };
    let union = ball(DVec3::new(-0.4, 0.0, 0.0), 0.9, e) || ball(DVec3::new(0.5, 0.1, 0.0), 0.8, e);
    let cutter = in_box(DVec3::new(-0.3, -1.0, -0.3), DVec3::new(0.3, 1.0, 2.0), -e)
        && ball(DVec3::new(0.0, 0.0, 0.3), 0.7, -e);
    let slab = in_box(DVec3::new(-2.0, -0.6, -2.0), DVec3::new(2.0, 0.6, 2.0), e);
    (union && !cutter) && slab
}

/// The first `t` (in steps of `step`) where the ray is inside by `inside_nested(·, e)`.
fn first_inside(origin: DVec3, direction: DVec3, e: f64, step: f64) -> Option<f64> {
    let mut t = 0.0;
    while t < 8.0 {
        if inside_nested(origin + direction * t, e) {
            return Some(t);
        }
        t += step;
    }
    None
}

/// `((A ∪ B) − (C ∩ D)) ∩ E` along many rays: the first hit the tracer reports must be the
/// first place where exact membership changes.
#[test]
fn nested_operations_match_exact_membership() {
    let mut b = SceneBuilder::new();
    let m = b.material(matte(0.5, 0.5, 0.5));
    let a = b.part(sphere(-0.4, 0.0, 0.0, 0.9), DMat4::IDENTITY, m);
    let bb = b.part(sphere(0.5, 0.1, 0.0, 0.8), DMat4::IDENTITY, m);
    let union = b.csg(CsgOp::Union, vec![a, bb], m);
    let c = b.part(
        Shape::Box {
            min: DVec3::new(-0.3, -1.0, -0.3),
            max: DVec3::new(0.3, 1.0, 2.0),
        },
        DMat4::IDENTITY,
        m,
    );
    let d = b.part(sphere(0.0, 0.0, 0.3, 0.7), DMat4::IDENTITY, m);
    let cutter = b.csg(CsgOp::Intersection, vec![c, d], m);
    let carved = b.csg(CsgOp::Difference, vec![union, cutter], m);
    let slab = b.part(
        Shape::Box {
            min: DVec3::new(-2.0, -0.6, -2.0),
            max: DVec3::new(2.0, 0.6, 2.0),
        },
        DMat4::IDENTITY,
        m,
    );
    for handle in [union, cutter, carved] {
        b.demote(handle);
    }
    b.csg(CsgOp::Intersection, vec![carved, slab], m);
    let scene = prepare(b);

    let mut checked = 0;
    for i in 0..400u32 {
        // Rays from a sphere of radius 4 towards jittered points near the solid.
        let a1 = i as f64 * 2.399_963;
        let a2 = (i as f64 * 0.618_034).fract() * std::f64::consts::PI;
        let origin = DVec3::new(a1.cos() * a2.sin(), a2.cos(), a1.sin() * a2.sin()) * 4.0;
        let target = DVec3::new(
            ((i * 7) % 11) as f64 / 11.0 - 0.5,
            ((i * 3) % 7) as f64 / 7.0 - 0.5,
            ((i * 5) % 13) as f64 / 13.0 - 0.5,
        );
        let direction = (target - origin).normalize();
        let hit = first_hit(&scene, origin.as_vec3a(), direction.as_vec3a());
        // March in small steps to find where the ray surely and possibly enters.
        let step = 1e-3;
        let margin = 1e-4;
        let surely = first_inside(origin, direction, -margin, step);
        let possibly = first_inside(origin, direction, margin, step);
        match hit {
            None => assert!(
                surely.is_none(),
                "ray {i}: the tracer misses but the ray enters at {surely:?}"
            ),
            Some(h) => {
                let t = f64::from(h.t);
                let earliest = possibly.unwrap_or_else(|| {
                    panic!("ray {i}: the tracer hits at {t} but the ray never comes near")
                });
                assert!(t >= earliest - step, "ray {i}: hit {t} before {earliest}");
                if let Some(latest) = surely {
                    assert!(t <= latest + step, "ray {i}: hit {t} after {latest}");
                }
                // The normal points out of the solid: a little way along it is outside.
                let p = h.point.as_dvec3();
                let n = h.normal.as_dvec3();
                assert!(
                    !inside_nested(p + n * 1e-2, -margin),
                    "ray {i}: the normal points inwards"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 150, "only {checked} rays hit the solid");
}

#[test]
fn csg_with_unbounded_children_is_bounded_when_it_can_be() {
    let mut b = SceneBuilder::new();
    let m = b.material(matte(0.5, 0.5, 0.5));
    // A hemisphere: ball ∩ half-space y < 0 → bounded, in the BVH.
    let ball = b.part(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, m);
    let half = b.part(
        Shape::Plane {
            normal: DVec3::Y,
            offset: 0.0,
        },
        DMat4::IDENTITY,
        m,
    );
    b.csg(CsgOp::Intersection, vec![ball, half], m);
    // A hyperboloid of one sheet cut by a box: bounded too.
    let hyperboloid = b.part(
        Shape::Quadric {
            form: QuadricForm::HyperboloidOneSheet,
            quadric: Quadric::from_coefficients([
                1.0, -1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.25,
            ]),
        },
        DMat4::from_translation(DVec3::new(5.0, 0.0, 0.0)),
        m,
    );
    let clip = b.part(
        unit_box(1.0),
        DMat4::from_translation(DVec3::new(5.0, 0.0, 0.0)),
        m,
    );
    let waist = b.csg(CsgOp::Intersection, vec![hyperboloid, clip], m);
    // A floor with a hole (away from the others): unbounded.
    let floor = b.part(
        Shape::Plane {
            normal: DVec3::Y,
            offset: -2.0,
        },
        DMat4::IDENTITY,
        m,
    );
    let hole = b.part(sphere(-5.0, -2.0, 0.0, 1.0), DMat4::IDENTITY, m);
    b.csg(CsgOp::Difference, vec![floor, hole], m);
    let scene = prepare(b);
    assert_eq!(scene.object_count(), 3);
    assert_eq!(scene.unbounded_count(), 1);
    // The hemisphere's flat face, seen from below.
    let h =
        first_hit(&scene, Vec3A::new(0.2, -0.5, 0.0), Vec3A::Y).unwrap_or_else(|| panic!("miss"));
    assert_eq!(h.leaf, half);
    assert!(h.normal.abs_diff_eq(Vec3A::Y, 1e-6));
    // Through the floor's hole from above: the hole's bowl, then past it nothing else.
    let h =
        first_hit(&scene, Vec3A::new(-5.0, 5.0, 0.0), -Vec3A::Y).unwrap_or_else(|| panic!("miss"));
    assert_eq!(h.leaf, hole);
    assert!((h.point.y + 3.0).abs() < 1e-5, "{}", h.point);
    // The hyperboloid's waist: radius 0.5 at y = 0.
    let h =
        first_hit(&scene, Vec3A::new(5.0, 0.0, 5.0), -Vec3A::Z).unwrap_or_else(|| panic!("miss"));
    assert_eq!(h.object, waist);
    assert!((h.point.z - 0.5).abs() < 1e-5, "{}", h.point);
}
