//! A material's `emission` against colours worked out by hand: a lone emissive sphere with
//! no lights renders exactly its emission, emission adds linearly to a lit pixel, and a
//! shadow does not dim it.

use glam::{DMat4, DVec3, Vec3A};
use whitted_ir::{Color, Material};

use super::{options, prepare, trace_tree};
use crate::render::{render, NoObserver, RenderOptions};
use crate::testing::{sphere, SceneBuilder};

const EMISSION: Color = Color {
    r: 0.25,
    g: 0.5,
    b: 2.0,
};

fn glowing(diffuse: f64, emission: Color) -> Material {
    Material {
        ambient: Color::gray(0.1),
        diffuse: Color::gray(diffuse),
        emission,
        ..Material::default()
    }
}

fn rgb(c: Color) -> [f32; 3] {
    [c.r as f32, c.g as f32, c.b as f32]
}

/// With no lights and no ambient term (diffuse black), every pixel on the sphere is exactly
/// the emission and every other pixel the (black) background.
#[test]
fn a_lone_emissive_sphere_renders_exactly_its_emission() {
    let mut b = SceneBuilder::new();
    let m = b.material(glowing(0.0, EMISSION));
    b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, m);
    b.camera(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 40.0);
    let scene = prepare(b);
    let options = RenderOptions {
        max_depth: 5,
        ..options(24, 18)
    };
    let Some((image, _)) = render(&scene, &options, &NoObserver) else {
        panic!("the render was cancelled");
    };
    let (mut on, mut off) = (0, 0);
    for y in 0..options.height {
        for x in 0..options.width {
            let hits = trace_tree(&scene, &options, x, y, true).hit.is_some();
            let expected = if hits { rgb(EMISSION) } else { [0.0; 3] };
            assert_eq!(image.pixel(x, y), Some(expected), "pixel ({x}, {y})");
            if hits {
                on += 1;
            } else {
                off += 1;
            }
        }
    }
    assert!(
        on > 20 && off > 20,
        "{on} pixels on the sphere, {off} off it"
    );
}

/// The centre ray hits (0, 0, 1) with normal +z, and the light at (0, 0, 5) gives N·L = 1 at
/// distance 4 with no attenuation: local = ka·Ia·kd + kd·I·(N·L) = 0.1·1·0.5 + 0.5 = 0.55
/// per channel, and the emission adds on top of it.
#[test]
fn emission_adds_linearly_to_a_lit_pixel() {
    let centre = |emission: Color| {
        let mut b = SceneBuilder::new();
        let m = b.material(glowing(0.5, emission));
        b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, m);
        b.point_light(DVec3::new(0.0, 0.0, 5.0), 1.0);
        b.camera(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 30.0);
        let scene = prepare(b);
        trace_tree(&scene, &options(1, 1), 0, 0, true).color
    };
    let lit = centre(Color::BLACK);
    assert!(
        (lit - Vec3A::splat(0.55)).abs().max_element() < 1e-6,
        "lit without emission: {lit}"
    );
    for (k, emission) in [EMISSION, Color::gray(3.0), Color::new(0.0, 1e-3, 7.0)]
        .into_iter()
        .enumerate()
    {
        let e = Vec3A::from(rgb(emission));
        let glowing = centre(emission);
        let error = (glowing - (lit + e)).abs().max_element();
        assert!(error < 1e-6, "case {k}: {glowing} is not {lit} + {e}");
        // Twice the emission adds twice as much.
        let double = centre(Color::new(
            2.0 * emission.r,
            2.0 * emission.g,
            2.0 * emission.b,
        ));
        let error = (double - (lit + 2.0 * e)).abs().max_element();
        assert!(error < 1e-6, "case {k}: {double} is not {lit} + 2·{e}");
    }
}

/// A sphere whose only light is blocked keeps its ambient term plus all of its emission:
/// lights and shadows do not touch it.
#[test]
fn a_shadow_does_not_dim_emission() {
    let mut b = SceneBuilder::new();
    let m = b.material(glowing(0.5, EMISSION));
    b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, m);
    // The camera ray hits (0, 0.8, 0.6); the blocker sits on the way from there to the light
    // straight above.
    let blocker = b.material(glowing(0.5, Color::BLACK));
    b.add(sphere(0.0, 3.0, 0.0, 1.0), DMat4::IDENTITY, blocker);
    b.point_light(DVec3::new(0.0, 10.0, 0.0), 1.0);
    b.camera(DVec3::new(0.0, 0.8, 10.0), DVec3::new(0.0, 0.8, 0.0), 1.0);
    let scene = prepare(b);
    let root = trace_tree(&scene, &options(1, 1), 0, 0, true);
    assert!(root.hit.is_some(), "the ray misses: {root:#?}");
    assert!(
        root.lights.iter().all(|l| l.diffuse == Vec3A::ZERO),
        "the light is not blocked: {:#?}",
        root.lights
    );
    let expected = Vec3A::splat(0.1 * 0.5) + Vec3A::from(rgb(EMISSION));
    assert!(
        (root.color - expected).abs().max_element() < 1e-6,
        "{} is not {expected}",
        root.color
    );
}
