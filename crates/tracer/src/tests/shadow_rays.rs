//! Shadow rays: which are cast, and what filtered shadows let through.

use glam::{DMat4, DVec3, Vec3A};
use whitted_ir::{Color, Material};

use super::prepare;
use crate::recorder::NoRecord;
use crate::render::{trace_sample, RenderOptions};
use crate::scene::PreparedScene;
use crate::testing::{matte, plane_y, sphere, SceneBuilder};
use crate::trace::{RayCounters, Tracer};

/// Every pixel's colour bits and the ray counts, with or without the unshaded skip.
fn render_counting(
    scene: &PreparedScene,
    options: &RenderOptions,
    skip: bool,
) -> (Vec<[u32; 3]>, RayCounters) {
    let mut tracer = Tracer::new(scene, options.depth_limit(), options.min_weight);
    if !skip {
        tracer = tracer.casting_every_shadow_ray();
    }
    let mut pixels = Vec::new();
    for y in 0..options.height {
        for x in 0..options.width {
            let c = trace_sample(&mut tracer, scene, options, x, y, 0, &mut NoRecord);
            pixels.push(c.to_array().map(f32::to_bits));
        }
    }
    (pixels, tracer.counters)
}

/// Pure mirrors (no diffuse, no specular colour) over a lit floor, two lights.
fn mirror_scene() -> PreparedScene {
    let mut b = SceneBuilder::new();
    b.camera(DVec3::new(0.0, 2.0, -6.0), DVec3::new(0.0, 0.8, 0.0), 45.0);
    b.point_light(DVec3::new(-4.0, 6.0, -3.0), 0.7);
    b.point_light(DVec3::new(4.0, 5.0, -5.0), 0.5);
    let floor = b.material(matte(0.8, 0.7, 0.6));
    b.add(plane_y(0.0), DMat4::IDENTITY, floor);
    let mirror = b.material(Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        specular: Color::BLACK,
        reflective: Color::gray(0.9),
        ..Material::default()
    });
    b.add(sphere(-1.1, 1.0, 0.0, 1.0), DMat4::IDENTITY, mirror);
    b.add(sphere(1.1, 1.0, 0.5, 1.0), DMat4::IDENTITY, mirror);
    prepare(b)
}

#[test]
fn unshaded_surfaces_cast_no_shadow_rays_and_no_pixel_changes() {
    let scene = mirror_scene();
    let options = RenderOptions {
        width: 48,
        height: 36,
        samples_per_pixel: 1,
        max_depth: 5,
        min_weight: 0.001,
    };
    let (skipped, with_skip) = render_counting(&scene, &options, true);
    let (cast, without_skip) = render_counting(&scene, &options, false);
    assert!(
        skipped == cast,
        "skipping unshaded shadow rays changed pixels"
    );
    assert_eq!(with_skip.reflected, without_skip.reflected);
    // The mirrors fill much of the image: many shadow rays are saved.
    assert!(
        with_skip.shadow * 10 < without_skip.shadow * 9,
        "shadow rays {} with the skip, {} without",
        with_skip.shadow,
        without_skip.shadow
    );
}

#[test]
fn the_tree_says_why_an_unshaded_surface_has_no_shadow_ray() {
    let scene = mirror_scene();
    let options = RenderOptions {
        width: 48,
        height: 36,
        samples_per_pixel: 1,
        max_depth: 2,
        min_weight: 0.001,
    };
    // The centre of the left mirror.
    let node = super::trace_tree(&scene, &options, 31, 18, true);
    let hit = node.hit.unwrap_or_else(|| panic!("missed the mirror"));
    assert!(hit.point.y > 0.1, "{:?}", hit.point);
    assert!(!node.lights.is_empty());
    for light in &node.lights {
        if light.n_dot_l > 0.0 {
            assert!(light.unshaded && light.shadow_ray.is_none(), "{light:?}");
        }
        assert_eq!(light.diffuse + light.specular, Vec3A::ZERO);
    }
}
