//! Nested media through the whole tracer: a glass of water whose water touches the glass
//! exactly (or reaches into its wall). With priorities (glass 2, water 1) the touching
//! surfaces are one interface with the ior pair (1.5, 1.33). Before nested media every
//! solid sat in air: the same rays saw (1.5, 1.0) and (1.0, 1.33), an air film.

use glam::{DMat4, DVec3};
use whitted_ir::{Color, CsgOp, Fresnel, Material, Shape};

use super::{prepare, trace_tree, Node};
use crate::recorder::RayKind;
use crate::render::RenderOptions;
use crate::testing::SceneBuilder;

fn clear(ior: f64, priority: u32) -> Material {
    Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        specular: Color::BLACK,
        transmissive: Color::WHITE,
        ior,
        fresnel: Fresnel::Off,
        priority,
        ..Material::default()
    }
}

fn cylinder(y0: f64, y1: f64, radius: f64) -> Shape {
    Shape::Cylinder {
        base: DVec3::new(0.0, y0, 0.0),
        apex: DVec3::new(0.0, y1, 0.0),
        radius,
        capped: true,
    }
}

/// A glass cup (a cylinder minus a narrower one above its 0.2-thick bottom) filled to 1.5
/// with water that touches the inner wall and the bottom exactly; one ray from `eye`
/// towards `look_at`.
fn glass_of_water(glass_priority: u32, water_priority: u32, eye: DVec3, look_at: DVec3) -> Node {
    glass_of_water_with(0.9, glass_priority, water_priority, eye, look_at)
}

/// [`glass_of_water`] with the water's radius given (0.9 touches the wall exactly).
fn glass_of_water_with(
    water_radius: f64,
    glass_priority: u32,
    water_priority: u32,
    eye: DVec3,
    look_at: DVec3,
) -> Node {
    let mut b = SceneBuilder::new();
    b.settings().background = Color::WHITE;
    b.camera(eye, look_at, 20.0);
    let glass = b.material(clear(1.5, glass_priority));
    let water = b.material(clear(1.33, water_priority));
    let outer = b.part(cylinder(0.0, 2.0, 1.0), DMat4::IDENTITY, glass);
    let inner = b.part(cylinder(0.2, 2.5, 0.9), DMat4::IDENTITY, glass);
    b.csg(CsgOp::Difference, vec![outer, inner], glass);
    b.add(cylinder(0.2, 1.5, water_radius), DMat4::IDENTITY, water);
    let scene = prepare(b);
    let options = RenderOptions {
        width: 1,
        height: 1,
        samples_per_pixel: 1,
        max_depth: 12,
        min_weight: 0.0,
    };
    trace_tree(&scene, &options, 0, 0, true)
}

/// The ior pairs of the chain of transmitted rays from the camera ray, and the shortest
/// distance any of those rays travelled to its hit.
fn transmitted_chain(root: &Node) -> (Vec<(f32, f32)>, f32) {
    let mut pairs = Vec::new();
    let mut shortest = root.hit.map_or(f32::INFINITY, |h| h.t);
    let mut node = root;
    while let Some(next) = node
        .children
        .iter()
        .find(|c| c.start.kind == RayKind::Transmitted)
    {
        if let Some(ior) = next.start.interface.and_then(|i| i.ior) {
            pairs.push(ior);
        }
        if let Some(hit) = next.hit {
            shortest = shortest.min(hit.t);
        }
        node = next;
    }
    (pairs, shortest)
}

/// Horizontal rays through the wall and the water, head-on and slanted (then refraction
/// bends them at every interface).
const RAYS: [(DVec3, DVec3); 3] = [
    (DVec3::new(-5.0, 0.8, 0.0), DVec3::new(0.0, 0.8, 0.0)),
    (DVec3::new(-5.0, 0.8, 0.35), DVec3::new(0.0, 0.8, 0.35)),
    (DVec3::new(-5.0, 1.1, -0.5), DVec3::new(0.0, 0.9, -0.45)),
];

#[test]
fn touching_glass_and_water_are_one_interface_with_both_iors() {
    for (eye, look_at) in RAYS {
        let root = glass_of_water(2, 1, eye, look_at);
        let (pairs, shortest) = transmitted_chain(&root);
        assert_eq!(
            pairs,
            vec![(1.0, 1.5), (1.5, 1.33), (1.33, 1.5), (1.5, 1.0)],
            "ray {eye} -> {look_at}"
        );
        // No ray stops between the touching surfaces.
        assert!(shortest > 0.05, "ray {eye} -> {look_at}: {shortest}");
        // The glass-water interface is the glass's surface, left towards the water.
        let into_glass = &root.children[0];
        let boundary = into_glass
            .hit
            .unwrap_or_else(|| panic!("no inner wall hit"));
        assert!(!boundary.front_face);
    }
}

#[test]
fn water_overlapping_the_glass_wall_is_skipped_inside_the_glass() {
    // Schmidt & Budge's way of modelling it: the water reaches into the wall, and its
    // surface there is a false hit because the glass has the higher priority.
    for (eye, look_at) in RAYS {
        let root = glass_of_water_with(0.95, 2, 1, eye, look_at);
        let (pairs, shortest) = transmitted_chain(&root);
        assert_eq!(
            pairs,
            vec![(1.0, 1.5), (1.5, 1.33), (1.33, 1.5), (1.5, 1.0)],
            "ray {eye} -> {look_at}"
        );
        assert!(shortest > 0.01, "ray {eye} -> {look_at}: {shortest}");
    }
}
