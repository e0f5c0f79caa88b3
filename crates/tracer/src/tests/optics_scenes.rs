//! The optics through the whole tracer, read back from recorded ray trees: Snell's law at
//! both surfaces of a glass ball, total internal reflection in a glass cube, Schlick's
//! split, Beer-Lambert absorption, attenuation and spot cones, filtered shadows, and both
//! stopping criteria.

use glam::{DMat4, DVec3, Vec3A};
use whitted_ir::{
    Attenuation, Color, Fresnel, Highlight, Light, LightKind, Material, ShadowMode, Shape,
};

use super::{prepare, trace_tree, Node};
use crate::optics;
use crate::recorder::{RayKind, ShadowResult, Termination};
use crate::render::RenderOptions;
use crate::testing::{matte, plane_y, sphere, SceneBuilder};

/// Traces the single ray from `eye` through `look_at` (the centre of a 1×1 image).
fn shoot(mut builder: SceneBuilder, eye: DVec3, look_at: DVec3, max_depth: u32) -> Node {
    builder.camera(eye, look_at, 30.0);
    let scene = prepare(builder);
    let options = RenderOptions {
        width: 1,
        height: 1,
        samples_per_pixel: 1,
        max_depth,
        min_weight: 0.0,
    };
    trace_tree(&scene, &options, 0, 0, true)
}

fn clear_glass(fresnel: Fresnel) -> Material {
    Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        transmissive: Color::WHITE,
        ior: 1.5,
        fresnel,
        ..Material::default()
    }
}

fn child(node: &Node, kind: RayKind) -> &Node {
    match node.children.iter().find(|c| c.start.kind == kind) {
        Some(c) => c,
        None => panic!("no {kind:?} child: {node:#?}"),
    }
}

fn sin_between(d: Vec3A, n: Vec3A) -> f32 {
    d.cross(n).length()
}

#[test]
fn refraction_through_a_ball_obeys_snell_at_both_surfaces() {
    let mut b = SceneBuilder::new();
    let glass = b.material(clear_glass(Fresnel::Off));
    b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, glass);
    let root = shoot(b, DVec3::new(0.0, 0.5, 5.0), DVec3::new(0.0, 0.5, 0.0), 5);
    let hit = root
        .hit
        .unwrap_or_else(|| panic!("the ray misses the ball"));
    assert!(hit.front_face);
    let inside = child(&root, RayKind::Transmitted);
    let interface = inside
        .start
        .interface
        .unwrap_or_else(|| panic!("no interface"));
    assert_eq!(interface.ior, Some((1.0, 1.5)));
    assert!(interface.entering);
    // sin θi = 0.5 at this offset; n1·sin θi = n2·sin θt.
    let sin_i = sin_between(root.start.direction, hit.shading_normal);
    let sin_t = sin_between(inside.start.direction, hit.shading_normal);
    assert!((sin_i - 0.5).abs() < 1e-5, "{sin_i}");
    assert!((sin_i - 1.5 * sin_t).abs() < 1e-5, "{sin_i} vs 1.5·{sin_t}");
    // The transmitted ray starts just inside the surface.
    let back_off = (inside.start.origin - hit.point).dot(hit.geometric_normal);
    assert!(back_off < 0.0 && back_off > -1e-3, "{back_off}");
    // Leaving: the back face, the reverse ior pair, and Snell again.
    let exit_hit = inside.hit.unwrap_or_else(|| panic!("the ray never leaves"));
    assert!(!exit_hit.front_face);
    let out = child(inside, RayKind::Transmitted);
    let out_interface = out
        .start
        .interface
        .unwrap_or_else(|| panic!("no interface"));
    assert_eq!(out_interface.ior, Some((1.5, 1.0)));
    let sin_i2 = sin_between(inside.start.direction, exit_hit.shading_normal);
    let sin_t2 = sin_between(out.start.direction, exit_hit.shading_normal);
    assert!((1.5 * sin_i2 - sin_t2).abs() < 1e-5);
    // By symmetry the ray leaves deflected by 2(θi − θt) towards the axis.
    let deviation = 2.0 * (0.5f32.asin() - (0.5f32 / 1.5).asin());
    let turned = out.start.direction.dot(root.start.direction).acos();
    assert!((turned - deviation).abs() < 1e-4, "{turned} vs {deviation}");
    assert_eq!(out.termination, Termination::Miss);
}

/// A ray entering the top face of a glass cube at 80°; inside, it meets the side face
/// x = 1 at 90° − asin(sin 80° / 1.5) ≈ 48.96°, beyond the critical angle of 41.81°.
fn tir_in_a_cube(glass: Material) -> Node {
    let mut b = SceneBuilder::new();
    let glass = b.material(glass);
    b.add(
        Shape::Box {
            min: DVec3::splat(-1.0),
            max: DVec3::splat(1.0),
        },
        DMat4::IDENTITY,
        glass,
    );
    let theta = 80f64.to_radians();
    let d = DVec3::new(theta.sin(), -theta.cos(), 0.0);
    let entry = DVec3::new(0.2, 1.0, 0.0);
    shoot(b, entry - 5.0 * d, entry, 6)
}

fn tir_skip(inside: &Node) -> &crate::recorder::SkippedRay {
    inside
        .skipped
        .iter()
        .find(|s| s.kind == RayKind::Transmitted)
        .unwrap_or_else(|| panic!("no skipped transmission: {inside:#?}"))
}

#[test]
fn total_internal_reflection_without_fresnel_drops_the_transmitted_term() {
    // kr 0.5, kt 0.9: the textbook drops kt at total internal reflection; only kr reflects.
    let root = tir_in_a_cube(Material {
        reflective: Color::gray(0.5),
        transmissive: Color::gray(0.9),
        ..clear_glass(Fresnel::Off)
    });
    let inside = child(&root, RayKind::Transmitted);
    let side = inside.hit.unwrap_or_else(|| panic!("no side hit"));
    assert!(side.geometric_normal.abs_diff_eq(Vec3A::X, 1e-6));
    let skipped = tir_skip(inside);
    assert_eq!(skipped.reason, Termination::TotalInternalReflection);
    // The record says what was lost: kt, at the weight the transmitted ray would have had.
    assert_eq!(skipped.coefficient, Vec3A::splat(0.9));
    assert!(skipped
        .weight
        .abs_diff_eq(inside.start.weight * Vec3A::splat(0.9), 1e-6));
    let reflected = child(inside, RayKind::Reflected);
    let interface = reflected
        .start
        .interface
        .unwrap_or_else(|| panic!("no interface"));
    assert!(interface.total_internal_reflection);
    assert_eq!(interface.fresnel_reflectance, None);
    let critical = optics::critical_angle(1.5, 1.0).unwrap_or(0.0).to_degrees();
    let incidence = interface.incidence_degrees();
    assert!(incidence > critical, "{incidence}° vs critical {critical}°");
    assert!((incidence - 48.96).abs() < 0.01, "{incidence}");
    assert_eq!(reflected.start.coefficient, Vec3A::splat(0.5));
    assert_eq!(inside.termination, Termination::NotEnded);

    // Clear glass without Fresnel (kr 0) keeps nothing: the ray ends there.
    let root = tir_in_a_cube(clear_glass(Fresnel::Off));
    let inside = child(&root, RayKind::Transmitted);
    assert!(inside
        .children
        .iter()
        .all(|c| c.start.kind == RayKind::Shadow));
    assert_eq!(inside.termination, Termination::TotalInternalReflection);
}

#[test]
fn total_internal_reflection_with_fresnel_reflects_the_transmitted_share() {
    for fresnel in [Fresnel::Schlick, Fresnel::Exact] {
        let root = tir_in_a_cube(clear_glass(fresnel));
        let inside = child(&root, RayKind::Transmitted);
        let skipped = tir_skip(inside);
        assert_eq!(skipped.coefficient, Vec3A::ZERO);
        assert_eq!(skipped.weight, Vec3A::ZERO);
        let reflected = child(inside, RayKind::Reflected);
        let interface = reflected
            .start
            .interface
            .unwrap_or_else(|| panic!("no interface"));
        assert!(interface.total_internal_reflection);
        assert_eq!(interface.fresnel, fresnel);
        assert_eq!(interface.fresnel_reflectance, Some(1.0));
        // kr + kt·R = 0 + 1·1: all the weight is reflected.
        assert_eq!(reflected.start.coefficient, Vec3A::ONE);
    }
}

#[test]
fn schlick_splits_the_weight_between_reflection_and_transmission() {
    let mut b = SceneBuilder::new();
    let glass = b.material(clear_glass(Fresnel::Schlick));
    b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, glass);
    // Head on: R = R0 = 0.04.
    let root = shoot(b.clone(), DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 1);
    let r = child(&root, RayKind::Reflected).start.coefficient;
    let t = child(&root, RayKind::Transmitted).start.coefficient;
    assert!(r.abs_diff_eq(Vec3A::splat(0.04), 1e-6), "{r}");
    assert!(t.abs_diff_eq(Vec3A::splat(0.96), 1e-6), "{t}");
    // Obliquely: R from the recorded angle, R + T = kt.
    let root = shoot(b, DVec3::new(0.0, 0.9, 5.0), DVec3::new(0.0, 0.9, 0.0), 1);
    let reflected = child(&root, RayKind::Reflected);
    let interface = reflected
        .start
        .interface
        .unwrap_or_else(|| panic!("no interface"));
    let expected = optics::schlick(interface.cos_incidence, 1.0, 1.5);
    assert_eq!(interface.fresnel_reflectance, Some(expected));
    // cos θ = √0.19: R = 0.04 + 0.96·(1 − cos θ)⁵ ≈ 0.095, more than head on.
    assert!(
        expected > 0.09,
        "oblique incidence reflects more: {expected}"
    );
    let t = child(&root, RayKind::Transmitted).start.coefficient;
    assert!((reflected.start.coefficient + t).abs_diff_eq(Vec3A::ONE, 1e-6));
}

#[test]
fn absorption_follows_beer_lambert_inside_the_solid() {
    let mut b = SceneBuilder::new();
    let tinted = b.material(Material {
        absorption: Color::new(0.5, 1.0, 2.0),
        ..clear_glass(Fresnel::Off)
    });
    // A slab 1 unit thick along z.
    b.add(
        Shape::Box {
            min: DVec3::new(-2.0, -2.0, -0.5),
            max: DVec3::new(2.0, 2.0, 0.5),
        },
        DMat4::IDENTITY,
        tinted,
    );
    let root = shoot(b, DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 5);
    assert_eq!(root.hit.map(|h| h.absorption), Some(Vec3A::ONE));
    let inside = child(&root, RayKind::Transmitted);
    let far = inside.hit.unwrap_or_else(|| panic!("no far face"));
    let thickness = far.t;
    assert!((thickness - 1.0).abs() < 1e-3, "{thickness}");
    let expected = Vec3A::new(
        (-0.5 * thickness).exp(),
        (-thickness).exp(),
        (-2.0 * thickness).exp(),
    );
    assert!(
        far.absorption.abs_diff_eq(expected, 1e-6),
        "{}",
        far.absorption
    );
    // The colour coming back through the slab carries the factor, and the ray that leaves
    // travels in air again.
    let out = child(inside, RayKind::Transmitted);
    assert_eq!(out.termination, Termination::Miss);
    assert!(inside.color.abs_diff_eq(out.color * expected, 1e-6));
}

fn lit_floor(light: Light) -> SceneBuilder {
    let mut b = SceneBuilder::new();
    b.light(light);
    let floor = b.material(matte(0.5, 0.5, 0.5));
    b.add(plane_y(0.0), DMat4::IDENTITY, floor);
    b
}

#[test]
fn point_light_attenuation_and_spot_cone() {
    let attenuation = Attenuation {
        constant: 1.0,
        linear: 0.1,
        quadratic: 0.01,
    };
    let spot = Light {
        name: None,
        color: Color::gray(2.0),
        kind: LightKind::Spot {
            position: DVec3::new(0.0, 4.0, 0.0),
            direction: DVec3::new(0.0, -1.0, 0.0),
            inner_angle_degrees: 20.0,
            outer_angle_degrees: 30.0,
            attenuation,
        },
    };
    let at = |x: f64| {
        shoot(
            lit_floor(spot.clone()),
            DVec3::new(x, 3.0, 0.01),
            DVec3::new(x, 0.0, 0.0),
            0,
        )
    };
    // Straight below: fatt = 1 / (1 + 0.1·4 + 0.01·16), full cone, N·L = 1.
    let below = at(0.0);
    let sample = below.lights[0];
    let fatt = 1.0 / (1.0 + 0.4 + 0.16);
    assert!(
        (sample.attenuation - fatt).abs() < 1e-4,
        "{}",
        sample.attenuation
    );
    assert_eq!(sample.spot, 1.0);
    assert!(sample
        .diffuse
        .abs_diff_eq(Vec3A::splat(2.0 * fatt * 0.5 * sample.n_dot_l), 1e-4));
    // Between the cones: the smoothstep of the cosines.
    let x = 4.0 * 25f64.to_radians().tan();
    let between = at(x).lights[0];
    let cos = 25f32.to_radians().cos();
    let expected = optics::spot_factor(cos, 20f32.to_radians().cos(), 30f32.to_radians().cos());
    assert!(
        (between.spot - expected).abs() < 1e-3,
        "{} vs {expected}",
        between.spot
    );
    assert!(between.spot > 0.0 && between.spot < 1.0);
    // Outside the outer cone: no shadow ray, no light.
    let outside = at(4.0 * 35f64.to_radians().tan()).lights[0];
    assert_eq!(outside.spot, 0.0);
    assert!(outside.shadow_ray.is_none());
    assert_eq!(outside.diffuse, Vec3A::ZERO);
}

#[test]
fn directional_light_is_not_attenuated() {
    let sun = Light {
        name: None,
        color: Color::WHITE,
        kind: LightKind::Directional {
            direction: DVec3::new(0.0, -1.0, -1.0),
        },
    };
    let root = shoot(lit_floor(sun), DVec3::new(0.0, 3.0, 3.0), DVec3::ZERO, 0);
    let sample = root.lights[0];
    assert_eq!(sample.attenuation, 1.0);
    assert!(sample.distance.is_infinite());
    assert!(sample
        .to_light
        .abs_diff_eq(Vec3A::new(0.0, 1.0, 1.0).normalize(), 1e-6));
    let shadow = sample.shadow_ray.unwrap_or_else(|| panic!("no shadow ray"));
    assert!(shadow.max_t.is_infinite());
    assert_eq!(shadow.result, ShadowResult::Unblocked);
}

#[test]
fn transparent_blockers_filter_or_block_by_setting() {
    let build = |mode: ShadowMode| {
        let mut b = SceneBuilder::new();
        b.settings().shadows = mode;
        b.point_light(DVec3::new(0.0, 10.0, 0.0), 1.0);
        let floor = b.material(matte(0.5, 0.5, 0.5));
        let tinted = b.material(Material {
            transmissive: Color::new(0.9, 0.5, 0.2),
            ..clear_glass(Fresnel::Off)
        });
        b.add(plane_y(0.0), DMat4::IDENTITY, floor);
        b.add(sphere(0.0, 3.0, 0.0, 1.0), DMat4::IDENTITY, tinted);
        b
    };
    // A camera ray to the floor right under the ball, from the side.
    let eye = DVec3::new(5.0, 1.0, 0.0);
    let floor_point = DVec3::new(0.0, 0.0, 0.0);
    let filtered = shoot(build(ShadowMode::Filtered), eye, floor_point, 0).lights[0];
    let shadow = filtered
        .shadow_ray
        .unwrap_or_else(|| panic!("no shadow ray"));
    // The ball filters where the shadow ray enters it and again where it leaves.
    let kt = Vec3A::new(0.9, 0.5, 0.2);
    assert_eq!(
        shadow.result,
        ShadowResult::Filtered {
            transmittance: kt * kt,
            blockers: 2
        }
    );
    let fatt_kd = 0.5 * filtered.n_dot_l;
    assert!(filtered.diffuse.abs_diff_eq(kt * kt * fatt_kd, 1e-6));
    let opaque = shoot(build(ShadowMode::Opaque), eye, floor_point, 0).lights[0];
    assert!(matches!(
        opaque.shadow_ray.map(|s| s.result),
        Some(ShadowResult::Blocked { .. })
    ));
    assert_eq!(opaque.diffuse, Vec3A::ZERO);
}

/// Two mirrors facing each other: the ray bounces until a stopping criterion ends it.
fn mirror_corridor() -> SceneBuilder {
    let mut b = SceneBuilder::new();
    b.point_light(DVec3::new(0.0, 1.0, 0.0), 1.0);
    let mirror = b.material(Material {
        reflective: Color::gray(0.9),
        ..matte(0.1, 0.1, 0.1)
    });
    b.add(plane_y(0.0), DMat4::IDENTITY, mirror);
    // The half-space y > 2, whose surface faces down.
    b.add(
        Shape::Plane {
            normal: -DVec3::Y,
            offset: -2.0,
        },
        DMat4::IDENTITY,
        mirror,
    );
    b
}

fn deepest(root: &Node) -> &Node {
    root.walk()
        .into_iter()
        .max_by_key(|n| n.start.depth)
        .unwrap_or(root)
}

#[test]
fn maximum_depth_stops_the_recursion() {
    let root = shoot(
        mirror_corridor(),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        5,
    );
    let last = deepest(&root);
    assert_eq!(last.start.depth, 5);
    assert_eq!(last.termination, Termination::MaxDepth);
    assert_eq!(last.skipped[0].reason, Termination::MaxDepth);
    assert_eq!(last.skipped[0].depth, 6);
    // The path weight is the product of the coefficients: 0.9⁵.
    assert!(last
        .start
        .weight
        .abs_diff_eq(Vec3A::splat(0.9f32.powi(5)), 1e-6));
}

#[test]
fn minimum_weight_stops_the_recursion() {
    let mut b = mirror_corridor();
    b.camera(DVec3::new(0.0, 1.0, 0.0), DVec3::new(1.0, 0.0, 0.0), 30.0);
    let scene = prepare(b);
    let options = RenderOptions {
        width: 1,
        height: 1,
        samples_per_pixel: 1,
        max_depth: 100,
        min_weight: 0.5,
    };
    let root = trace_tree(&scene, &options, 0, 0, true);
    // 0.9⁶ = 0.53 is traced; 0.9⁷ = 0.48 is not.
    let last = deepest(&root);
    assert_eq!(last.start.depth, 6);
    assert_eq!(last.termination, Termination::WeightCutoff);
    assert!(last.skipped[0].weight.max_element() < 0.5);
}

#[test]
fn phong_highlight_matches_the_formula() {
    let mut b = SceneBuilder::new();
    b.point_light(DVec3::new(2.0, 3.0, 6.0), 1.0);
    let shiny = b.material(Material {
        specular: Color::gray(0.7),
        shininess: 25.0,
        ..matte(0.3, 0.3, 0.3)
    });
    b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, shiny);
    let root = shoot(b, DVec3::new(0.0, 0.0, 5.0), DVec3::new(0.2, 0.3, 0.0), 0);
    let hit = root.hit.unwrap_or_else(|| panic!("no hit"));
    let sample = root.lights[0];
    let l = sample.to_light;
    let n = hit.shading_normal;
    let r = 2.0 * n.dot(l) * n - l;
    let v = -root.start.direction;
    let expected = 0.7 * r.dot(v).max(0.0).powf(25.0);
    assert!(
        (sample.specular.x - expected).abs() < 1e-5,
        "{} vs {expected}",
        sample.specular.x
    );
    assert!(expected > 0.01, "the view should be near the highlight");
    // The colour is ambient plus the light's terms.
    let total = root.ambient + sample.diffuse + sample.specular;
    assert!(root.color.abs_diff_eq(total, 1e-6));
}

#[test]
fn blinn_highlight_matches_the_formula_and_is_broader_than_phong() {
    let specular_of = |highlight: Highlight| {
        let mut b = SceneBuilder::new();
        b.settings().highlight = highlight;
        b.point_light(DVec3::new(2.0, 3.0, 6.0), 1.0);
        let shiny = b.material(Material {
            specular: Color::gray(0.7),
            shininess: 25.0,
            ..matte(0.3, 0.3, 0.3)
        });
        b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, shiny);
        shoot(b, DVec3::new(0.0, 0.0, 5.0), DVec3::new(0.2, 0.3, 0.0), 0)
    };
    let root = specular_of(Highlight::Blinn);
    let hit = root.hit.unwrap_or_else(|| panic!("no hit"));
    let sample = root.lights[0];
    // By hand, in f64: H halfway between the light and the viewer.
    let l = sample.to_light.as_dvec3();
    let n = hit.shading_normal.as_dvec3();
    let v = -root.start.direction.as_dvec3();
    let h = (l + v).normalize();
    let expected = 0.7 * n.dot(h).max(0.0).powf(25.0);
    assert!(
        (f64::from(sample.specular.x) - expected).abs() < 1e-5,
        "{} vs {expected}",
        sample.specular.x
    );
    // The half-angle is half the angle between R and V, so for the same exponent the
    // Blinn-Phong highlight is brighter away from its centre.
    let phong = specular_of(Highlight::Phong).lights[0].specular.x;
    assert!(
        sample.specular.x > phong && phong > 0.0,
        "blinn {} vs phong {phong}",
        sample.specular.x
    );
}

#[test]
fn thin_transparent_surfaces_do_not_bend_or_absorb() {
    let mut b = SceneBuilder::new();
    let film = b.material(Material {
        absorption: Color::gray(3.0),
        ..clear_glass(Fresnel::Off)
    });
    b.add(
        Shape::Disk {
            center: DVec3::ZERO,
            normal: DVec3::new(0.3, 0.2, 1.0),
            radius: 2.0,
        },
        DMat4::IDENTITY,
        film,
    );
    let root = shoot(b, DVec3::new(0.5, 0.4, 5.0), DVec3::new(-0.2, 0.1, 0.0), 3);
    let through = child(&root, RayKind::Transmitted);
    let interface = through
        .start
        .interface
        .unwrap_or_else(|| panic!("no interface"));
    assert_eq!(interface.ior, Some((1.0, 1.0)));
    assert!(!interface.entering);
    assert!(through
        .start
        .direction
        .abs_diff_eq(root.start.direction, 1e-6));
    // It travels on in air: the background comes back unabsorbed.
    assert_eq!(through.termination, Termination::Miss);
    assert_eq!(through.color, Vec3A::ZERO);
    assert_eq!(root.color, Vec3A::ZERO);
}
