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
            assert!(
                light.no_shadow_ray == Some(crate::NoShadowRay::Unshaded)
                    && light.shadow_ray.is_none(),
                "{light:?}"
            );
        }
        assert_eq!(light.diffuse + light.specular, Vec3A::ZERO);
    }
}

/// A clear filter: transmissive `kt`, nothing else, ior 1 (rays go straight through).
fn filter(kt: f64) -> Material {
    Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        specular: Color::BLACK,
        transmissive: Color::gray(kt),
        ior: 1.0,
        ..Material::default()
    }
}

/// The 12 triangles of the box `[min, max]`.
fn box_triangles(min: DVec3, max: DVec3) -> Vec<whitted_ir::Shape> {
    let corner = |i: usize| {
        DVec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    };
    let faces = [
        [0, 2, 6, 4],
        [1, 5, 7, 3],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 6, 7, 5],
    ];
    let mut triangles = Vec::new();
    for [a, b, c, d] in faces {
        for [p, q, r] in [[a, b, c], [a, c, d]] {
            triangles.push(whitted_ir::Shape::Triangle {
                a: corner(p),
                b: corner(q),
                c: corner(r),
            });
        }
    }
    triangles
}

/// How the filter is built: one solid box, 12 triangles, or a CSG union of two
/// overlapping boxes (whose inner faces are not surfaces of the solid).
#[derive(Clone, Copy, Debug)]
enum Filter {
    SolidBox,
    Triangles,
    CsgUnion,
}

/// A scene with nothing but the filter around `[-1, 1]³` (and a white sky for the camera
/// to see through it), built the given way.
fn filter_scene(build: Filter, camera: Option<(DVec3, DVec3)>) -> PreparedScene {
    let mut b = SceneBuilder::new();
    b.settings().background = Color::WHITE;
    b.settings().ambient = Color::BLACK;
    if let Some((eye, look_at)) = camera {
        b.camera(eye, look_at, 30.0);
    }
    let glass = b.material(filter(0.5));
    let (min, max) = (DVec3::splat(-1.0), DVec3::splat(1.0));
    match build {
        Filter::SolidBox => {
            b.add(whitted_ir::Shape::Box { min, max }, DMat4::IDENTITY, glass);
        }
        Filter::Triangles => {
            for triangle in box_triangles(min, max) {
                b.add(triangle, DMat4::IDENTITY, glass);
            }
        }
        Filter::CsgUnion => {
            let left = b.part(
                whitted_ir::Shape::Box {
                    min,
                    max: DVec3::new(0.3, 1.0, 1.0),
                },
                DMat4::IDENTITY,
                glass,
            );
            let right = b.part(
                whitted_ir::Shape::Box {
                    min: DVec3::new(-0.3, -1.0, -1.0),
                    max,
                },
                DMat4::IDENTITY,
                glass,
            );
            b.csg(whitted_ir::CsgOp::Union, vec![left, right], glass);
        }
    }
    prepare(b)
}

/// What a shadow ray from `from` towards `to` lets through.
fn shadow_transmittance(scene: &PreparedScene, from: DVec3, to: DVec3) -> Vec3A {
    let direction = (to - from).normalize().as_vec3a();
    let ray = whitted_bvh::Ray::new(from.as_vec3a(), direction);
    let mut scratch = crate::query::Scratch::default();
    match scene.filter_shadow(&ray, 0.0, f32::INFINITY, &mut scratch) {
        crate::query::Shadow::Clear => Vec3A::ONE,
        crate::query::Shadow::Blocked(_) => Vec3A::ZERO,
        crate::query::Shadow::Filtered { transmittance, .. } => transmittance,
    }
}

/// What a camera ray from `from` towards `to` brings back from the white sky behind the
/// filter: the product of `kt` at every surface it crosses.
fn camera_transmission(build: Filter, from: DVec3, to: DVec3) -> Vec3A {
    let scene = filter_scene(build, Some((from, to)));
    let options = RenderOptions {
        width: 1,
        height: 1,
        samples_per_pixel: 1,
        max_depth: 10,
        min_weight: 0.0,
    };
    super::trace_tree(&scene, &options, 0, 0, true).color
}

#[test]
fn filtered_shadows_filter_at_every_surface_like_camera_rays() {
    // Straight through the middle, and on a slant through two faces that meet at an edge.
    let segments = [
        (DVec3::new(0.1, 0.2, -3.0), DVec3::new(0.1, 0.2, 3.0)),
        (DVec3::new(-3.0, -2.5, 0.3), DVec3::new(2.0, 3.0, -0.4)),
    ];
    for (from, to) in segments {
        let camera = camera_transmission(Filter::SolidBox, from, to);
        // kt at the entry and again at the exit.
        assert_eq!(camera, Vec3A::splat(0.25), "camera ray {from} -> {to}");
        for build in [Filter::SolidBox, Filter::Triangles, Filter::CsgUnion] {
            let scene = filter_scene(build, None);
            let shadow = shadow_transmittance(&scene, from, to);
            assert_eq!(shadow, camera, "{build:?} shadow {from} -> {to}");
            assert_eq!(
                camera_transmission(build, from, to),
                camera,
                "{build:?} camera {from} -> {to}"
            );
        }
    }
}

#[test]
fn a_shadow_ray_starting_inside_a_filter_counts_only_the_exit() {
    let scene = filter_scene(Filter::SolidBox, None);
    let inside = shadow_transmittance(&scene, DVec3::ZERO, DVec3::new(0.0, 5.0, 0.0));
    assert_eq!(inside, Vec3A::splat(0.5));
}
