//! Ray trees on hand-built scenes: the recorded colour is the rendered pixel, the tree has
//! the structure the hooks describe, and bad requests are errors.

use glam::{DMat4, DVec3};
use whitted_ir::{Color, CsgOp, Material, ValidScene};

use super::*;
use crate::recorder::{RayKind, Termination};
use crate::render::{render, NoObserver, RenderOptions};
use crate::scene::PreparedScene;
use crate::testing::{glass, matte, plane_y, sphere, whitted_classic, SceneBuilder};

fn prepared(builder: SceneBuilder) -> (ValidScene, PreparedScene) {
    let valid = match builder.build() {
        Ok(valid) => valid,
        Err(invalid) => panic!("test scene is invalid: {:?}", invalid.diagnostics),
    };
    let prepared = PreparedScene::new(&valid);
    (valid, prepared)
}

fn options(width: u32, height: u32, spp: u32, max_depth: u32) -> RenderOptions {
    RenderOptions {
        width,
        height,
        samples_per_pixel: spp,
        max_depth,
        min_weight: 0.001,
    }
}

fn bits(c: [f32; 3]) -> [u32; 3] {
    c.map(f32::to_bits)
}

/// Every node's own invariants: depths, the colour sum of secondary rays, shadow indices.
fn check_node(node: &RayNode) {
    for child in &node.children {
        match child.kind {
            RayKind::Shadow => assert_eq!(child.depth, node.depth),
            RayKind::Reflected | RayKind::Transmitted => {
                assert_eq!(child.depth, node.depth + 1)
            }
            RayKind::Camera => panic!("a camera ray cannot be a child"),
        }
        check_node(child);
    }
    // A tree cut at its node budget (`unrecorded > 0`) may lack shadow rays and secondary
    // rays that were traced.
    let cut = node.unrecorded > 0;
    if let Some(local) = &node.local {
        for light in &local.lights {
            match light.shadow_child {
                Some(i) => assert_eq!(node.children[i].kind, RayKind::Shadow),
                None => assert!(
                    cut || !matches!(
                        light.visibility,
                        Visibility::Lit | Visibility::Blocked | Visibility::Filtered
                    )
                ),
            }
        }
    }
    let traced = node.children.iter().any(|c| c.kind != RayKind::Shadow);
    if !cut {
        assert_eq!(
            traced,
            node.termination == Termination::NotEnded,
            "{node:?}"
        );
    } else if traced {
        assert_eq!(node.termination, Termination::NotEnded, "{node:?}");
    }
}

/// The sum of `unrecorded` over a subtree.
fn unrecorded_below(node: &RayNode) -> u64 {
    node.unrecorded + node.children.iter().map(unrecorded_below).sum::<u64>()
}

#[test]
fn a_tree_over_its_node_budget_is_cut_says_where_and_keeps_the_pixel_colour() {
    let (valid, prepared) = prepared(whitted_classic());
    let mut options = options(16, 12, 2, 12);
    // No minimum weight: the glass sphere's rays split at every level.
    options.min_weight = 0.0;
    let request = |x, y, node_budget| TraceRequest {
        x,
        y,
        which: SampleChoice::All,
        node_budget,
        cancel: None,
    };
    let nodes = |tree: &RayTree| {
        tree.samples
            .iter()
            .map(|s| s.root.ray_count())
            .sum::<usize>()
    };
    // The busiest pixel, by its complete tree.
    let (x, y, full) = (0..12)
        .flat_map(|y| (0..16).map(move |x| (x, y)))
        .map(|(x, y)| {
            let tree = trace_pixel_request(&prepared, &valid, &options, &request(x, y, usize::MAX))
                .expect("a valid pixel");
            (x, y, tree)
        })
        .max_by_key(|(_, _, tree)| nodes(tree))
        .expect("pixels");
    let all = nodes(&full);
    assert!(all > 60, "the busiest pixel has only {all} rays");
    assert_eq!(full.unrecorded, 0);
    for budget in [1, 2, 7, 50, all - 1, all] {
        let cut = trace_pixel_request(&prepared, &valid, &options, &request(x, y, budget))
            .expect("a valid pixel");
        let kept = nodes(&cut);
        // Camera rays, the samples' roots (2 here), are always kept.
        assert!(kept <= budget + 2, "budget {budget}: {kept} nodes kept");
        // Every traced ray is either kept or counted where it was left out.
        assert_eq!(kept as u64 + cut.unrecorded, all as u64, "budget {budget}");
        let counted: u64 = cut.samples.iter().map(|s| unrecorded_below(&s.root)).sum();
        assert_eq!(counted, cut.unrecorded, "budget {budget}");
        assert_eq!(cut.node_budget, budget);
        // Tracing went on past the budget: the colours are the complete tree's.
        assert_eq!(bits(cut.color), bits(full.color), "budget {budget}");
        for (a, b) in cut.samples.iter().zip(&full.samples) {
            assert_eq!(bits(a.root.color), bits(b.root.color), "budget {budget}");
        }
        for sample in &cut.samples {
            check_node(&sample.root);
        }
        let text = format_text(&cut, TextOptions::default());
        if budget < all {
            assert!(
                text.contains(&format!("cut at the ray-tree budget of {budget} nodes")),
                "{text}"
            );
            assert!(text.contains("not recorded"), "{text}");
        } else {
            assert!(!text.contains("not recorded"), "{text}");
        }
    }
}

#[test]
fn a_cancelled_trace_stops_and_says_so() {
    let (valid, prepared) = prepared(whitted_classic());
    let options = options(16, 12, 1, 5);
    let cancel = std::sync::atomic::AtomicBool::new(true);
    let request = TraceRequest {
        x: 8,
        y: 6,
        which: SampleChoice::All,
        node_budget: 100,
        cancel: Some(&cancel),
    };
    assert_eq!(
        trace_pixel_request(&prepared, &valid, &options, &request),
        Err(TraceError::Cancelled)
    );
}

#[test]
fn tree_colour_is_the_rendered_pixel_bit_for_bit() {
    for spp in [1, 4] {
        let (valid, prepared) = prepared(whitted_classic());
        let options = options(40, 30, spp, 5);
        let Some((image, _)) = render(&prepared, &options, &NoObserver) else {
            panic!("render cancelled");
        };
        for y in (0..30).step_by(3) {
            for x in (0..40).step_by(3) {
                let tree = trace_pixel(&prepared, &valid, &options, x, y, SampleChoice::All)
                    .unwrap_or_else(|e| panic!("{e}"));
                let rendered = image.pixel(x, y).unwrap_or_default();
                assert_eq!(
                    bits(tree.color),
                    bits(rendered),
                    "pixel ({x}, {y}) spp {spp}"
                );
                assert_eq!(tree.samples.len(), spp as usize);
                for sample in &tree.samples {
                    assert_eq!(bits(sample.color), bits(sample.root.color));
                    assert_eq!(sample.root.kind, RayKind::Camera);
                    check_node(&sample.root);
                }
                // One sample recorded still gives the whole pixel's colour.
                let last = spp - 1;
                let one = trace_pixel(&prepared, &valid, &options, x, y, SampleChoice::One(last))
                    .unwrap_or_else(|e| panic!("{e}"));
                assert_eq!(bits(one.color), bits(rendered));
                assert_eq!(one.samples.len(), 1);
                assert_eq!(one.samples[0], tree.samples[last as usize]);
            }
        }
    }
}

#[test]
fn out_of_range_pixels_and_samples_are_errors() {
    let (valid, prepared) = prepared(whitted_classic());
    let options = options(40, 30, 2, 5);
    let error = trace_pixel(&prepared, &valid, &options, 40, 0, SampleChoice::All);
    assert_eq!(
        error.map_err(|e| e.to_string()),
        Err("pixel (40, 0) is outside the 40x30 image (x must be 0 to 39, y 0 to 29)".into())
    );
    assert!(trace_pixel(&prepared, &valid, &options, 0, 30, SampleChoice::All).is_err());
    let error = trace_pixel(&prepared, &valid, &options, 0, 0, SampleChoice::One(2));
    assert_eq!(
        error.map_err(|e| e.to_string()),
        Err("there is no sample 2: the image has 2 samples per pixel (0 to 1)".into())
    );
}

/// A glass ball in front of a matte wall, lit from the camera's side, a blocker between
/// the wall and the light.
fn glass_ball_scene() -> SceneBuilder {
    let mut b = SceneBuilder::new();
    b.settings().background = Color::new(0.2, 0.3, 0.4);
    b.camera(DVec3::new(0.0, 0.0, 6.0), DVec3::ZERO, 40.0);
    b.point_light(DVec3::new(0.0, 0.0, 10.0), 1.0);
    let glass = b.material(glass());
    let wall = b.material(matte(0.8, 0.8, 0.8));
    let ball = b.add(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, glass);
    b.name(ball, "ball");
    let back = b.add(
        whitted_ir::Shape::Plane {
            normal: DVec3::Z,
            offset: -3.0,
        },
        DMat4::IDENTITY,
        wall,
    );
    b.name(back, "wall");
    b
}

#[test]
fn a_ray_through_glass_enters_then_leaves_and_the_wall_is_shadowed_by_the_ball() {
    let (valid, prepared) = prepared(glass_ball_scene());
    let options = options(21, 21, 1, 5);
    // Slightly off centre so that the incidence is not zero.
    let tree = trace_pixel(&prepared, &valid, &options, 11, 11, SampleChoice::All)
        .unwrap_or_else(|e| panic!("{e}"));
    let root = &tree.samples[0].root;
    assert_eq!(
        root.hit.as_ref().map(|h| h.object.label.as_str()),
        Some("ball")
    );
    assert_eq!(root.termination, Termination::NotEnded);

    let entering = root
        .child(RayKind::Transmitted)
        .unwrap_or_else(|| panic!("{root:#?}"));
    let interface = entering
        .interface
        .as_ref()
        .unwrap_or_else(|| panic!("no interface"));
    assert!(interface.entering);
    assert_eq!(interface.ior, Some([1.0, 1.5]));
    let (r, t) = (
        interface.fresnel_reflectance,
        interface.fresnel_transmittance,
    );
    assert!(r.is_some_and(|r| r > 0.0 && r < 0.1), "{r:?}");
    assert_eq!(r.zip(t).map(|(r, t)| r + t), Some(1.0));
    let inside = entering
        .hit
        .as_ref()
        .unwrap_or_else(|| panic!("no hit inside"));
    assert!(!inside.front_face);

    let leaving = entering
        .child(RayKind::Transmitted)
        .unwrap_or_else(|| panic!("{entering:#?}"));
    let interface = leaving
        .interface
        .as_ref()
        .unwrap_or_else(|| panic!("no interface"));
    assert!(!interface.entering);
    assert_eq!(interface.ior, Some([1.5, 1.0]));
    assert_eq!(leaving.depth, 2);
    let wall_hit = leaving
        .hit
        .as_ref()
        .unwrap_or_else(|| panic!("{leaving:#?}"));
    assert_eq!(wall_hit.object.label, "wall");

    // The wall's shadow ray towards the light is blocked by the ball.
    let local = leaving.local.as_ref().unwrap_or_else(|| panic!("no local"));
    assert_eq!(local.lights.len(), 1);
    assert_eq!(local.lights[0].visibility, Visibility::Blocked);
    assert_eq!(local.lights[0].diffuse, [0.0; 3]);
    let shadow = &leaving.children[local.lights[0].shadow_child.unwrap_or(usize::MAX)];
    let info = shadow
        .shadow
        .as_ref()
        .unwrap_or_else(|| panic!("no shadow info"));
    assert_eq!(info.result, ShadowOutcome::Blocked);
    let blocker = info
        .blocker
        .as_ref()
        .unwrap_or_else(|| panic!("no blocker"));
    assert_eq!(blocker.object.label, "ball");
    assert!(blocker.t > 0.0 && Some(blocker.t) < info.max_t);
    assert_eq!(shadow.color, [0.0; 3]);
    assert_eq!(shadow.termination, Termination::Absorbed);
    assert_eq!(local.total, local.ambient);
}

#[test]
fn rays_not_traced_are_listed_with_their_reason() {
    let (valid, prepared) = prepared(glass_ball_scene());
    let options = options(21, 21, 1, 1);
    let tree = trace_pixel(&prepared, &valid, &options, 11, 11, SampleChoice::All)
        .unwrap_or_else(|e| panic!("{e}"));
    let root = &tree.samples[0].root;
    let entering = root
        .child(RayKind::Transmitted)
        .unwrap_or_else(|| panic!("{root:#?}"));
    assert_eq!(entering.depth, 1);
    assert_eq!(entering.termination, Termination::MaxDepth);
    assert!(entering
        .children
        .iter()
        .all(|child| child.kind == RayKind::Shadow));
    let reasons: Vec<_> = entering
        .skipped
        .iter()
        .map(|s| (s.kind, s.reason, s.depth))
        .collect();
    assert_eq!(
        reasons,
        vec![
            (RayKind::Reflected, Termination::MaxDepth, 2),
            (RayKind::Transmitted, Termination::MaxDepth, 2)
        ]
    );
    assert_eq!(root.deepest(), 1);
}

#[test]
fn a_csg_hit_names_the_leaf_and_the_operations_above_it() {
    let mut b = SceneBuilder::new();
    b.camera(DVec3::new(0.0, 0.0, 6.0), DVec3::ZERO, 40.0);
    b.point_light(DVec3::new(0.0, 5.0, 10.0), 1.0);
    let red = b.material(matte(0.8, 0.1, 0.1));
    let blue = b.material(Material {
        name: Some("blue".into()),
        ..matte(0.1, 0.1, 0.8)
    });
    let big = b.part(sphere(0.0, 0.0, 0.0, 1.0), DMat4::IDENTITY, red);
    let bite = b.part(sphere(0.0, 0.0, 1.0, 0.6), DMat4::IDENTITY, blue);
    b.name(bite, "bite");
    let inner = b.csg(CsgOp::Difference, vec![big, bite], red);
    b.demote(inner);
    let floor = b.part(plane_y(-5.0), DMat4::IDENTITY, red);
    let outer = b.csg(CsgOp::Union, vec![inner, floor], red);
    b.name(outer, "bitten");
    let (valid, prepared) = prepared(b);
    let options = options(21, 21, 1, 5);
    let tree = trace_pixel(&prepared, &valid, &options, 10, 10, SampleChoice::All)
        .unwrap_or_else(|e| panic!("{e}"));
    let hit = tree.samples[0]
        .root
        .hit
        .as_ref()
        .unwrap_or_else(|| panic!("miss"));
    assert_eq!(hit.object.label, "bitten");
    assert_eq!(hit.object.kind, "union");
    assert_eq!(hit.leaf.label, "bite");
    assert_eq!(hit.material.label, "blue");
    assert_eq!(hit.material.location, "<built-in>");
    let path: Vec<&str> = hit.csg_path.iter().map(|o| o.kind.as_str()).collect();
    assert_eq!(path, ["union", "difference"]);
    // The bite's surface is the inside of a subtracted sphere: the normal faces the camera.
    assert!(hit.geometric_normal[2] > 0.9, "{hit:?}");
}

#[test]
fn the_json_document_has_the_version_and_the_first_samples_root() {
    let (valid, prepared) = prepared(whitted_classic());
    let options = options(20, 15, 4, 5);
    let tree = trace_pixel(&prepared, &valid, &options, 10, 7, SampleChoice::One(2))
        .unwrap_or_else(|e| panic!("{e}"));
    let document = tree.document();
    assert_eq!(document.version, RAY_TREE_JSON_VERSION);
    assert_eq!(document.root_sample, Some(2));
    assert_eq!(document.root, Some(&tree.samples[0].root));
}
