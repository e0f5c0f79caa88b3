//! The ray budget per sample: past it no reflected or transmitted ray starts, the colour
//! gathered so far is kept, the ray says why it stopped, and the tracer counts the cut.

use glam::{DMat4, DVec3};
use whitted_ir::{Color, Material, Shape};

use super::{prepare, Tape};
use crate::recorder::{NoRecord, Termination};
use crate::render::{trace_sample, RenderOptions};
use crate::testing::{mirror, sphere, SceneBuilder};
use crate::trace::Tracer;

/// Glass that reflects half and transmits half in a box of six mirrors (as
/// scenes/ray-explosion.scene): every hit on the glass splits, and no ray leaves.
fn mirror_box() -> SceneBuilder {
    let mut b = SceneBuilder::new();
    b.camera(DVec3::new(0.0, 0.0, -2.5), DVec3::ZERO, 60.0);
    b.point_light(DVec3::new(1.5, 2.0, -2.0), 1.0);
    let walls = b.material(mirror());
    for normal in [DVec3::X, DVec3::Y, DVec3::Z] {
        for normal in [normal, -normal] {
            let wall = Shape::Plane {
                normal,
                offset: -3.0,
            };
            b.add(wall, DMat4::IDENTITY, walls);
        }
    }
    let glass = b.material(Material {
        diffuse: Color::BLACK,
        specular: Color::BLACK,
        reflective: Color::gray(0.5),
        transmissive: Color::gray(0.5),
        ior: 1.5,
        ..Material::default()
    });
    b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, glass);
    b
}

/// No minimum weight, as in the explosion scene.
fn options() -> RenderOptions {
    RenderOptions {
        width: 16,
        height: 12,
        samples_per_pixel: 1,
        max_depth: 20,
        min_weight: 0.0,
    }
}

/// The rays a sample cast besides its camera ray, as the budget counts them.
fn rays_below(node: &super::Node) -> u32 {
    let shadows = node
        .lights
        .iter()
        .filter(|l| l.shadow_ray.is_some())
        .count() as u32;
    shadows + node.children.iter().map(|c| 1 + rays_below(c)).sum::<u32>()
}

#[test]
fn past_the_budget_recursion_stops_and_says_so() {
    let scene = prepare(mirror_box());
    let options = options();
    let budget = 40;
    let mut cut_any = false;
    for (x, y) in (0..12).flat_map(|y| (0..16).map(move |x| (x, y))) {
        let mut full = Tracer::new(&scene, options.depth_limit(), options.min_weight);
        let mut full_tape = Tape::default();
        trace_sample(&mut full, &scene, &options, x, y, 0, &mut full_tape);
        let mut tracer =
            Tracer::new(&scene, options.depth_limit(), options.min_weight).with_ray_budget(budget);
        let mut tape = Tape::default();
        let color = trace_sample(&mut tracer, &scene, &options, x, y, 0, &mut tape);
        let root = &tape.roots[0];
        let all = rays_below(&full_tape.roots[0]);
        let kept = rays_below(root);
        let cut = root.walk().into_iter().any(|n| {
            n.termination == Termination::RayBudget
                || n.skipped.iter().any(|s| s.reason == Termination::RayBudget)
        });
        if !cut {
            // Not cut: nothing changes, bit for bit. Only the last ray's own shadow ray (one
            // light) can pass the budget without a secondary ray being refused.
            assert!(all <= budget + 1, "({x}, {y}): {all} rays and no cut");
            assert_eq!(kept, all, "({x}, {y})");
            assert_eq!(color, full_tape.roots[0].color, "({x}, {y})");
            assert_eq!(tracer.counters.samples_cut, 0);
            continue;
        }
        cut_any = true;
        assert_eq!(tracer.counters.samples_cut, 1, "({x}, {y})");
        // Once a ray is refused no other starts; the ray under way cast its shadow ray.
        assert!(
            kept >= budget && kept <= budget + 1,
            "({x}, {y}): {kept} rays"
        );
        // The colour is what the kept rays returned.
        assert_eq!(color, root.color);
        // The same cut without a recorder gives the same colour.
        let mut plain =
            Tracer::new(&scene, options.depth_limit(), options.min_weight).with_ray_budget(budget);
        let plain_color = trace_sample(&mut plain, &scene, &options, x, y, 0, &mut NoRecord);
        assert_eq!(plain_color.to_array(), color.to_array());
    }
    assert!(cut_any, "no pixel reached a budget of {budget} rays");
}

#[test]
fn each_sample_has_its_own_budget() {
    let scene = prepare(mirror_box());
    let options = options();
    // One tracer for the whole image, as a render worker keeps it.
    let mut tracer =
        Tracer::new(&scene, options.depth_limit(), options.min_weight).with_ray_budget(40);
    let mut cut = 0;
    for (x, y) in (0..12).flat_map(|y| (0..16).map(move |x| (x, y))) {
        let before = tracer.counters.samples_cut;
        let mut fresh =
            Tracer::new(&scene, options.depth_limit(), options.min_weight).with_ray_budget(40);
        let alone = trace_sample(&mut fresh, &scene, &options, x, y, 0, &mut NoRecord);
        let shared = trace_sample(&mut tracer, &scene, &options, x, y, 0, &mut NoRecord);
        assert_eq!(alone.to_array(), shared.to_array(), "({x}, {y})");
        cut += tracer.counters.samples_cut - before;
        assert_eq!(
            tracer.counters.samples_cut - before,
            fresh.counters.samples_cut
        );
    }
    assert!(cut > 0);
}

/// `render` counts the pixels cut at the real budget and finds the first in row-major
/// order, whatever the tiles and threads; the cut pixels are the ones whose trees say so.
#[test]
fn render_reports_the_pixels_cut_and_the_first() {
    let scene = prepare(mirror_box());
    let options = RenderOptions {
        max_depth: 64,
        ..options()
    };
    let mut expected = Vec::new();
    for (x, y) in (0..12).flat_map(|y| (0..16).map(move |x| (x, y))) {
        let mut tracer = Tracer::new(&scene, options.depth_limit(), options.min_weight);
        trace_sample(&mut tracer, &scene, &options, x, y, 0, &mut NoRecord);
        if tracer.counters.samples_cut > 0 {
            expected.push([x, y]);
        }
    }
    assert!(!expected.is_empty(), "no pixel reached the budget");
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a pool");
        let (_, stats) = pool
            .install(|| crate::render::render(&scene, &options, &crate::render::NoObserver))
            .expect("not cancelled");
        assert_eq!(stats.pixels_cut_at_ray_budget, expected.len() as u64);
        assert_eq!(
            stats.first_pixel_cut_at_ray_budget,
            expected.first().copied()
        );
    }
    // With a minimum weight the paths end long before the budget: nothing is cut.
    let (_, stats) = crate::render::render(
        &scene,
        &RenderOptions {
            min_weight: 0.001,
            ..options
        },
        &crate::render::NoObserver,
    )
    .expect("not cancelled");
    assert_eq!(stats.pixels_cut_at_ray_budget, 0);
    assert_eq!(stats.first_pixel_cut_at_ray_budget, None);
}
