//! The course's rules and the classic student bugs as settings (`back_ambient`,
//! `highlight_gate`, `sample_position`, `flip_normals`, `exit_ior`,
//! `total_internal_reflection`, `light_falloff`, `fresnel_rule`, `epsilon 0`), each against
//! a value worked out by hand from the formula the setting names.

use glam::{DMat4, DVec3, Vec3A};
use whitted_ir::{Attenuation, Color, Fresnel, Highlight, Light, LightKind, Material};
use whitted_ir::{SamplePosition, Settings, ShadowMode};

use super::{prepare, trace_tree, Node};
use crate::camera::PreparedCamera;
use crate::recorder::{RayKind, Termination};
use crate::render::RenderOptions;
use crate::testing::{matte, plane_y, sphere, SceneBuilder};

const ONE_PIXEL: RenderOptions = RenderOptions {
    width: 1,
    height: 1,
    samples_per_pixel: 1,
    max_depth: 5,
    min_weight: 0.001,
};

fn one_pixel(b: SceneBuilder) -> Node {
    trace_tree(&prepare(b), &ONE_PIXEL, 0, 0, true)
}

fn directional(direction: DVec3, grey: f64) -> Light {
    Light {
        name: None,
        color: Color::gray(grey),
        kind: LightKind::Directional { direction },
    }
}

#[test]
fn back_ambient_off_makes_a_back_face_black() {
    let floor_from_below = |back_ambient: bool| {
        let mut b = SceneBuilder::new();
        b.settings().shade_back = false;
        b.settings().back_ambient = back_ambient;
        b.light(directional(DVec3::new(0.0, 1.0, 0.5), 0.8));
        let floor = b.material(matte(0.5, 0.6, 0.7));
        b.add(plane_y(0.0), DMat4::IDENTITY, floor);
        b.camera(DVec3::new(0.0, -3.0, -3.0), DVec3::ZERO, 30.0);
        one_pixel(b)
    };
    // `matte` has ka = 0.1 under a white ambient light: ka·Ia·kd.
    let kept = floor_from_below(true);
    assert!(kept.color.abs_diff_eq(Vec3A::new(0.05, 0.06, 0.07), 1e-7));
    let black = floor_from_below(false);
    assert!(black.hit.is_some_and(|h| !h.front_face));
    assert_eq!(black.color, Vec3A::ZERO);
    assert_eq!(black.ambient, Vec3A::ZERO);
}

/// A shiny floor seen from straight above (V = +y), lit by a directional light from below
/// the horizon, Blinn-Phong as the course's.
fn shiny_floor_lit_from_below(gate: bool) -> Node {
    let mut b = SceneBuilder::new();
    b.settings().highlight = Highlight::Blinn;
    b.settings().highlight_gate = gate;
    // The course's default: no shadow rays. (With them, whitted's shadow ray starts on the
    // viewer's side of the floor, so the floor itself blocks a light below it.)
    b.settings().shadows = ShadowMode::None;
    // L = normalise(1, -0.2, 0): the light travels along -L.
    b.light(directional(-DVec3::new(1.0, -0.2, 0.0), 0.8));
    let floor = b.material(Material {
        ambient: Color::BLACK,
        diffuse: Color::gray(0.5),
        specular: Color::gray(0.6),
        shininess: 2.0,
        ..Material::default()
    });
    b.add(plane_y(0.0), DMat4::IDENTITY, floor);
    b.set_camera(whitted_ir::Camera {
        eye: DVec3::new(0.0, 5.0, 0.0),
        look_at: DVec3::ZERO,
        up: DVec3::Z,
        projection: whitted_ir::Projection::Orthographic { view_height: 1.0 },
    });
    one_pixel(b)
}

#[test]
fn without_the_gate_a_light_below_the_horizon_still_gives_its_highlight() {
    let gated = shiny_floor_lit_from_below(true);
    assert_eq!(gated.color, Vec3A::ZERO);

    // By hand: L = (1, -0.2, 0)/|.|, V = (0, 1, 0), H = (L + V)/|L + V|, N·H = H.y.
    let l = DVec3::new(1.0, -0.2, 0.0).normalize();
    let h = (l + DVec3::Y).normalize();
    assert!(l.y < 0.0 && h.y > 0.0);
    // Ii·ks·(N·H)^2, and no diffuse: kd·max(0, N·L) = 0.
    let expected = (0.8 * 0.6 * h.y * h.y) as f32;
    let ungated = shiny_floor_lit_from_below(false);
    assert!(
        (ungated.color.x - expected).abs() < 1e-6,
        "{} vs {expected}",
        ungated.color.x
    );
    assert_eq!(ungated.lights[0].diffuse, Vec3A::ZERO);
}

#[test]
fn a_corner_sample_is_the_pixel_s_lower_left_corner() {
    let camera = whitted_ir::Camera {
        eye: DVec3::new(0.0, 0.0, -5.0),
        look_at: DVec3::ZERO,
        up: DVec3::Y,
        projection: whitted_ir::Projection::Orthographic { view_height: 2.0 },
    };
    let corner = PreparedCamera::new(&camera).placing_samples(SamplePosition::Corner);
    // Pixel (0, 0) of a 2 x 2 image of a 2 x 2 view: its centre is at (-0.5, 0.5) on the
    // image plane (x to the camera's right), its lower-left corner at (-1, 0).
    let ray = corner.ray(0.5, 0.5, 2, 2);
    assert!((ray.origin.y - 0.0).abs() < 1e-6, "{}", ray.origin);
    assert!((ray.origin.x.abs() - 1.0).abs() < 1e-6, "{}", ray.origin);
    let centre = PreparedCamera::new(&camera).ray(0.5, 0.5, 2, 2);
    assert!((centre.origin.y - 0.5).abs() < 1e-6, "{}", centre.origin);
    assert!(
        (centre.origin.x.abs() - 0.5).abs() < 1e-6,
        "{}",
        centre.origin
    );
}

/// A clear glass ball (no Fresnel) seen through its centre, or `offset` off it.
fn through_a_ball(settings: impl Fn(&mut Settings), offset: f64) -> Node {
    let mut b = SceneBuilder::new();
    settings(b.settings());
    let glass = b.material(Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        transmissive: Color::WHITE,
        ior: 1.5,
        fresnel: Fresnel::Off,
        ..Material::default()
    });
    b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, glass);
    b.set_camera(whitted_ir::Camera {
        eye: DVec3::new(offset, 0.0, -5.0),
        look_at: DVec3::new(offset, 0.0, 0.0),
        up: DVec3::Y,
        projection: whitted_ir::Projection::Orthographic { view_height: 0.001 },
    });
    one_pixel(b)
}

fn transmitted(node: &Node) -> Option<&Node> {
    node.children
        .iter()
        .find(|c| c.start.kind == RayKind::Transmitted)
}

#[test]
fn unflipped_normals_trap_every_ray_inside_glass() {
    // Inside, with the outward normal kept, cos(incidence) clamps to 0 and sin²θt is
    // (1.5/1)² > 1: total internal reflection at every exit.
    let flipped = through_a_ball(|_| {}, 0.0);
    let inside = transmitted(&flipped).unwrap_or_else(|| panic!("{flipped:#?}"));
    assert!(transmitted(inside).is_some(), "the ray leaves the ball");

    let unflipped = through_a_ball(|s| s.flip_normals = false, 0.0);
    let inside = transmitted(&unflipped).unwrap_or_else(|| panic!("{unflipped:#?}"));
    assert!(transmitted(inside).is_none(), "{inside:#?}");
    assert!(inside
        .skipped
        .iter()
        .any(|s| s.reason == Termination::TotalInternalReflection));
}

#[test]
fn an_uninverted_exit_ior_bends_the_ray_as_if_entering() {
    // A ray parallel to the axis at height h enters at θi = asin(h) and meets the far
    // side at θt = asin(h / 1.5) from its normal (the chord is symmetric). Leaving with
    // the right indices it comes out at θi; with 1 → 1.5 again, at asin(sin θt / 1.5).
    let h: f64 = 0.6;
    let theta_t = (h / 1.5).asin();
    let exit_angle = |node: &Node| {
        let inside = transmitted(node).unwrap_or_else(|| panic!("{node:#?}"));
        let hit = inside.hit.unwrap_or_else(|| panic!("{inside:#?}"));
        let out = transmitted(inside).unwrap_or_else(|| panic!("{inside:#?}"));
        // The outward normal at the exit point of a unit ball is the point itself.
        let outward = hit.point.normalize();
        f64::from(out.start.direction.dot(outward)).acos()
    };
    let right = exit_angle(&through_a_ball(|_| {}, h));
    assert!((right - h.asin()).abs() < 1e-4, "{right} vs {}", h.asin());
    let wrong = exit_angle(&through_a_ball(|s| s.exit_ior_inverted = false, h));
    let expected = (theta_t.sin() / 1.5).asin();
    assert!((wrong - expected).abs() < 1e-4, "{wrong} vs {expected}");
}

/// The camera inside a big glass ball, looking along +x at height 9: the ray meets the
/// inside at cos θ = sqrt(19)/10 (sin θ = 0.9 > 1/1.5), past the critical angle.
fn grazing_inside_glass(tir: bool) -> Node {
    let mut b = SceneBuilder::new();
    b.settings().total_internal_reflection = tir;
    b.settings().background = Color::new(0.2, 0.4, 0.6);
    b.settings().shadows = ShadowMode::None;
    let glass = b.material(Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        transmissive: Color::gray(0.5),
        ior: 1.5,
        fresnel: Fresnel::Off,
        ..Material::default()
    });
    b.add(sphere(0.0, 0.0, 0.0, 10.0), DMat4::IDENTITY, glass);
    b.camera(DVec3::new(0.0, 9.0, 0.0), DVec3::new(1.0, 9.0, 0.0), 10.0);
    one_pixel(b)
}

#[test]
fn without_total_internal_reflection_the_impossible_ray_brings_the_background() {
    let right = grazing_inside_glass(true);
    assert!(right
        .skipped
        .iter()
        .any(|s| s.reason == Termination::TotalInternalReflection));
    assert_eq!(right.color, Vec3A::ZERO);
    // kt·background = 0.5·(0.2, 0.4, 0.6).
    let wrong = grazing_inside_glass(false);
    assert!(
        wrong.color.abs_diff_eq(Vec3A::new(0.1, 0.2, 0.3), 1e-7),
        "{}",
        wrong.color
    );
}

#[test]
fn without_light_falloff_a_point_light_is_its_colour_at_any_distance() {
    let floor_under_light = |falloff: bool| {
        let mut b = SceneBuilder::new();
        b.settings().light_falloff = falloff;
        b.light(Light {
            name: None,
            color: Color::gray(0.5),
            kind: LightKind::Point {
                position: DVec3::new(0.0, 4.0, 0.0),
                attenuation: Attenuation {
                    constant: 0.1,
                    linear: 0.2,
                    quadratic: 0.2,
                },
            },
        });
        let floor = b.material(Material {
            ambient: Color::BLACK,
            ..matte(0.4, 0.4, 0.4)
        });
        b.add(plane_y(0.0), DMat4::IDENTITY, floor);
        b.set_camera(whitted_ir::Camera {
            eye: DVec3::new(0.0, 3.0, 0.0),
            look_at: DVec3::ZERO,
            up: DVec3::Z,
            projection: whitted_ir::Projection::Orthographic { view_height: 0.001 },
        });
        one_pixel(b).color.x
    };
    // d = 4: Ii·kd·(N·L)/(0.1 + 0.2·4 + 0.2·16) = 0.2/4.1; without falloff 0.2.
    assert!((floor_under_light(true) - 0.2 / 4.1).abs() < 1e-6);
    assert!((floor_under_light(false) - 0.2).abs() < 1e-6);
}

#[test]
fn the_fresnel_rule_replaces_every_material_s_own() {
    let reflected_share = |rule: Option<Fresnel>| {
        let root = through_a_ball(|s| s.fresnel_rule = rule, 0.0);
        root.children
            .iter()
            .find(|c| c.start.kind == RayKind::Reflected)
            .map(|c| c.start.coefficient.x)
    };
    // The material's own rule is off and it has no reflective colour: no reflected ray.
    assert_eq!(reflected_share(None), None);
    // Schlick at normal incidence: R0 = ((1 - 1.5)/(1 + 1.5))² = 0.04 of kt = 1.
    let schlick = reflected_share(Some(Fresnel::Schlick)).unwrap_or(-1.0);
    assert!((schlick - 0.04).abs() < 1e-6, "{schlick}");
}

#[test]
fn epsilon_zero_gives_shadow_acne_on_a_lit_ball() {
    // A ball lit from the camera's side: every visible point faces the light, so with any
    // offset no shadow ray is blocked; with none, rounding puts some origins just inside.
    let blocked = |epsilon: Option<f64>| {
        let mut b = SceneBuilder::new();
        b.settings().epsilon = epsilon;
        b.light(directional(DVec3::new(0.0, 0.0, 1.0), 1.0));
        let ball = b.material(matte(0.5, 0.5, 0.5));
        b.add(sphere(0.3, -0.2, 0.1, 1.0), DMat4::IDENTITY, ball);
        b.camera(DVec3::new(0.0, 0.0, -6.0), DVec3::ZERO, 25.0);
        let scene = prepare(b);
        let options = RenderOptions {
            width: 24,
            height: 24,
            ..ONE_PIXEL
        };
        let mut blocked = 0;
        for y in 0..options.height {
            for x in 0..options.width {
                let root = trace_tree(&scene, &options, x, y, true);
                blocked += root
                    .lights
                    .iter()
                    .filter(|l| {
                        l.n_dot_l > 0.0
                            && l.shadow_ray.is_some_and(|s| {
                                matches!(s.result, crate::recorder::ShadowResult::Blocked { .. })
                            })
                    })
                    .count();
            }
        }
        blocked
    };
    assert_eq!(blocked(None), 0);
    assert!(blocked(Some(0.0)) > 10, "{}", blocked(Some(0.0)));
}
