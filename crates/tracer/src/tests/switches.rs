//! The shading-model switches courses use, each against an oracle: `shadows none` (no shadow
//! rays, and every pixel as if nothing blocked the light), `shade_back` (back faces lit with
//! the turned normal, or unlit) and `attenuation_clamp` (the hand formula above 1).

use glam::{DMat4, DVec3, Vec3A};
use whitted_ir::{Attenuation, Color, Light, LightKind, Material, ShadowMode};

use super::{prepare, trace_tree, Node};
use crate::recorder::{NoRecord, RayKind};
use crate::render::{trace_sample, RenderOptions};
use crate::scene::PreparedScene;
use crate::testing::{matte, plane_y, sphere, SceneBuilder};
use crate::trace::{RayCounters, Tracer};

const OPTIONS: RenderOptions = RenderOptions {
    width: 40,
    height: 30,
    samples_per_pixel: 1,
    max_depth: 5,
    min_weight: 0.001,
};

/// A matte ball over a matte floor, lit from above so that the ball shadows the floor.
/// Nothing reflects, so every pixel sees one surface.
fn ball_over_floor(shadows: ShadowMode, with_ball: bool) -> PreparedScene {
    let mut b = SceneBuilder::new();
    b.settings().shadows = shadows;
    b.camera(DVec3::new(0.0, 3.0, -7.0), DVec3::new(0.0, 0.5, 0.0), 45.0);
    b.point_light(DVec3::new(1.0, 6.0, -1.0), 0.9);
    let floor = b.material(matte(0.8, 0.7, 0.6));
    b.add(plane_y(0.0), DMat4::IDENTITY, floor);
    if with_ball {
        let ball = b.material(matte(0.3, 0.5, 0.9));
        b.add(sphere(0.0, 1.2, 0.0, 1.0), DMat4::IDENTITY, ball);
    }
    prepare(b)
}

/// Every pixel's colour bits, and the ray counts.
fn render(scene: &PreparedScene) -> (Vec<[u32; 3]>, RayCounters) {
    let mut tracer = Tracer::new(scene, OPTIONS.depth_limit(), OPTIONS.min_weight);
    let mut pixels = Vec::new();
    for y in 0..OPTIONS.height {
        for x in 0..OPTIONS.width {
            let c = trace_sample(&mut tracer, scene, &OPTIONS, x, y, 0, &mut NoRecord);
            pixels.push(c.to_array().map(f32::to_bits));
        }
    }
    (pixels, tracer.counters)
}

#[test]
fn shadows_none_casts_no_shadow_rays_and_renders_as_if_nothing_blocked_the_light() {
    let none = ball_over_floor(ShadowMode::None, true);
    let (image, counters) = render(&none);
    assert_eq!(counters.shadow, 0, "shadows none cast shadow rays");
    for y in 0..OPTIONS.height {
        for x in 0..OPTIONS.width {
            let root = trace_tree(&none, &OPTIONS, x, y, true);
            for node in root.walk() {
                for light in &node.lights {
                    assert!(light.shadow_ray.is_none(), "a shadow ray at ({x}, {y})");
                    // Every light that faces the surface is marked as counted unblocked.
                    if light.n_dot_l > 0.0 {
                        assert_eq!(
                            light.no_shadow_ray,
                            Some(crate::NoShadowRay::ShadowsOff),
                            "({x}, {y}): {light:?}"
                        );
                    }
                }
            }
        }
    }

    // The oracle: with opaque shadows, the ball is never shadowed (the floor is below it
    // and the light above), and the floor without the ball is never shadowed either. So
    // each pixel must equal, bit for bit, the opaque render with the ball where the camera
    // sees the ball, and the opaque render without the ball where it sees the floor.
    let with_ball = ball_over_floor(ShadowMode::Opaque, true);
    let (opaque, _) = render(&with_ball);
    let (no_ball, _) = render(&ball_over_floor(ShadowMode::Opaque, false));
    let mut shadowed = 0;
    for y in 0..OPTIONS.height {
        for x in 0..OPTIONS.width {
            let i = (y * OPTIONS.width + x) as usize;
            let sees_ball = trace_tree(&with_ball, &OPTIONS, x, y, true)
                .hit
                .is_some_and(|hit| hit.object.index() == 1);
            let expected = if sees_ball { opaque[i] } else { no_ball[i] };
            assert_eq!(image[i], expected, "pixel ({x}, {y})");
            shadowed += usize::from(opaque[i] != image[i]);
        }
    }
    // Otherwise the comparison above would not show that shadows were switched off.
    assert!(shadowed > 20, "the ball shadows only {shadowed} pixels");
}

/// A floor seen from below (its back face), a directional light shining up from below.
fn floor_from_below(shade_back: bool) -> Node {
    let mut b = SceneBuilder::new();
    b.settings().shade_back = shade_back;
    b.light(Light {
        name: None,
        color: Color::gray(0.8),
        kind: LightKind::Directional {
            direction: DVec3::new(0.0, 1.0, 0.5),
        },
    });
    let floor = b.material(matte(0.5, 0.6, 0.7));
    b.add(plane_y(0.0), DMat4::IDENTITY, floor);
    b.camera(DVec3::new(0.0, -3.0, -3.0), DVec3::ZERO, 30.0);
    let scene = prepare(b);
    let options = RenderOptions {
        width: 1,
        height: 1,
        ..OPTIONS
    };
    trace_tree(&scene, &options, 0, 0, true)
}

#[test]
fn shade_back_lights_a_back_face_with_the_turned_normal_or_not_at_all() {
    let lit = floor_from_below(true);
    let hit = lit
        .hit
        .unwrap_or_else(|| panic!("the ray misses the floor"));
    assert!(!hit.front_face, "the camera is below the floor");
    // By hand: the turned normal is -y, the light comes from -(0, 1, 0.5) normalised.
    let n_dot_l = DVec3::new(0.0, -1.0, 0.0).dot(-DVec3::new(0.0, 1.0, 0.5).normalize());
    let ambient = Vec3A::new(0.05, 0.06, 0.07);
    let diffuse = Vec3A::new(0.5, 0.6, 0.7) * 0.8 * n_dot_l as f32;
    assert!(
        lit.color.abs_diff_eq(ambient + diffuse, 1e-6),
        "{}",
        lit.color
    );

    let unlit = floor_from_below(false);
    assert!(unlit.color.abs_diff_eq(ambient, 1e-7), "{}", unlit.color);
    let light = unlit.lights[0];
    assert!(
        light.no_shadow_ray == Some(crate::NoShadowRay::BackFace) && light.shadow_ray.is_none(),
        "{light:?}"
    );
    assert_eq!(light.diffuse, Vec3A::ZERO);
}

#[test]
fn shade_back_off_leaves_front_faces_and_secondary_rays_alone() {
    // The camera above the floor sees its front: the switch changes nothing there.
    let front = |shade_back: bool| {
        let mut b = SceneBuilder::new();
        b.settings().shade_back = shade_back;
        b.point_light(DVec3::new(0.0, 4.0, 0.0), 1.0);
        let floor = b.material(matte(0.5, 0.6, 0.7));
        b.add(plane_y(0.0), DMat4::IDENTITY, floor);
        b.camera(DVec3::new(0.0, 3.0, -3.0), DVec3::ZERO, 30.0);
        let options = RenderOptions {
            width: 1,
            height: 1,
            ..OPTIONS
        };
        trace_tree(&prepare(b), &options, 0, 0, true).color
    };
    assert_eq!(front(true), front(false));
    assert!(front(false).max_element() > 0.2);

    // Glass seen from inside keeps refracting: a ray through a ball still leaves it.
    let mut b = SceneBuilder::new();
    b.settings().shade_back = false;
    let glass = b.material(Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        transmissive: Color::WHITE,
        ior: 1.5,
        ..Material::default()
    });
    b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, glass);
    b.camera(DVec3::new(0.0, 0.0, -5.0), DVec3::ZERO, 30.0);
    let options = RenderOptions {
        width: 1,
        height: 1,
        ..OPTIONS
    };
    let root = trace_tree(&prepare(b), &options, 0, 0, true);
    let inside = root
        .children
        .iter()
        .find(|c| c.start.kind == RayKind::Transmitted)
        .unwrap_or_else(|| panic!("no transmitted ray: {root:#?}"));
    assert!(inside.hit.is_some_and(|h| !h.front_face));
    assert!(inside
        .children
        .iter()
        .any(|c| c.start.kind == RayKind::Transmitted));
}

/// The floor point below a point light at height `height`, with attenuation `<a, b, c>`.
fn under_a_point_light(clamp: bool, height: f64, terms: [f64; 3]) -> Node {
    let mut b = SceneBuilder::new();
    b.settings().attenuation_clamp = clamp;
    b.light(Light {
        name: None,
        color: Color::gray(0.5),
        kind: LightKind::Point {
            position: DVec3::new(0.0, height, 0.0),
            attenuation: Attenuation {
                constant: terms[0],
                linear: terms[1],
                quadratic: terms[2],
            },
        },
    });
    let floor = b.material(Material {
        ambient: Color::BLACK,
        ..matte(0.4, 0.4, 0.4)
    });
    b.add(plane_y(0.0), DMat4::IDENTITY, floor);
    b.set_camera(whitted_ir::Camera {
        eye: DVec3::new(0.0, 5.0, 0.0),
        look_at: DVec3::ZERO,
        up: DVec3::Z,
        projection: whitted_ir::Projection::Orthographic { view_height: 1.0 },
    });
    let options = RenderOptions {
        width: 1,
        height: 1,
        ..OPTIONS
    };
    trace_tree(&prepare(b), &options, 0, 0, true)
}

#[test]
fn unclamped_attenuation_follows_the_formula_above_one() {
    // d = 1: 1 / (0.1 + 0.2·1 + 0.2·1²) = 2.
    let terms = [0.1, 0.2, 0.2];
    let unclamped = under_a_point_light(false, 1.0, terms);
    let light = unclamped.lights[0];
    let d = f64::from(light.distance);
    let fatt = 1.0 / (terms[0] + terms[1] * d + terms[2] * d * d);
    assert!((fatt - 2.0).abs() < 1e-3, "{d}");
    assert!(
        (f64::from(light.attenuation) - fatt).abs() < 1e-5,
        "{light:?}"
    );
    // The whole pixel: Ii·kd·(N·L)·fatt, with N·L = 1 straight below the light.
    let expected = (0.5 * 0.4 * fatt) as f32;
    assert!(
        (unclamped.color.x - expected).abs() < 1e-5,
        "{} vs {expected}",
        unclamped.color.x
    );

    // Clamped (the default), the same light gives at most its colour.
    let clamped = under_a_point_light(true, 1.0, terms);
    assert_eq!(clamped.lights[0].attenuation, 1.0);
    assert!((clamped.color.x - 0.2).abs() < 1e-6, "{}", clamped.color.x);

    // Far from the light the two agree: 1 / (0.1 + 0.8 + 3.2) below 1.
    let far = |clamp| under_a_point_light(clamp, 4.0, terms).color;
    assert_eq!(far(true), far(false));
}

#[test]
fn unclamped_attenuation_stays_finite_at_the_light() {
    // No constant term, and the floor point almost at the light.
    let at_light = under_a_point_light(false, 1e-7, [0.0, 0.0, 1.0]);
    assert!(at_light.color.is_finite(), "{}", at_light.color);
    assert!(at_light.lights[0].attenuation <= whitted_ir::limits::MAX_UNCLAMPED_ATTENUATION as f32);
}
