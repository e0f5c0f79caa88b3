//! Stepping through the picked pixel's rays in the order the tracer ran them (`[` `]`), the
//! colour they add up to so far, and the rays where something notable happened (`{` `}`).
//!
//! The order. The tracer starts a ray, finds its hit and shades it: ambient, emission, then
//! each light in scene order, casting that light's shadow ray; then it traces the reflected
//! ray (its whole subtree), then the transmitted one (`crates/tracer/src/trace.rs`; the
//! recorder's call order is written down in `crates/tracer/src/recorder.rs`). The tree
//! recorder appends a child when it starts, so a node's children are in that order (shadow
//! rays in light order, reflected, transmitted), and samples come in index order. Pre-order
//! over the recorded tree, which is how [`TreeView`] numbers its nodes, is therefore the
//! order the tracer started the rays in: stepping walks node numbers up and down.

use whitted_tracer::ray_tree::{RayNode, ShadowOutcome};
use whitted_tracer::{PixelAccumulator, RayKind, Termination, Vec3A};

use crate::tree::state::{NodeId, TreeView};

/// Moves the selection to the next (or previous) ray in the tracer's order, opening its
/// ancestors; whether it moved.
pub fn step(view: &mut TreeView, forward: bool) -> bool {
    view.set_stepping(true);
    let selected = view.selected();
    let target = if forward {
        selected + 1
    } else {
        match selected.checked_sub(1) {
            Some(previous) => previous,
            None => return false,
        }
    };
    if target >= view.len() {
        return false;
    }
    view.select(target);
    true
}

/// The pixel's colour counting only the rays up to `upto` in the tracer's order: what the
/// pixel would be if every later ray had returned black. Each visited ray adds its own
/// terms (a hit its ambient and emission and the lights that cast no shadow ray, a shadow
/// ray its light's diffuse and specular, a miss the background), weighted by its path.
///
/// The terms are added in the tracer's own order and f32 arithmetic (`recorder.rs`: local
/// terms, `+=` each light, `+= coefficient × child` for the reflected then the transmitted
/// ray, `× absorption`; samples averaged as `render` does), so at the last ray the sum is the
/// pixel's colour bit for bit. A subtree cut by the node budget lacks rays: once all of it
/// is visited, it counts with the colour the tracer recorded for it.
pub fn running_color(view: &TreeView, upto: NodeId) -> [f32; 3] {
    let mut pixel = PixelAccumulator::new();
    let mut root = 0;
    for sample in &view.tree().samples {
        pixel.add(partial(view, &sample.root, root, upto).to_array());
        root = view.subtree_end(root) + 1;
    }
    // The debugger records every sample (`SampleChoice::All`), so this is the mean over
    // the pixel's samples, as `render` takes it.
    pixel.mean()
}

/// The colour `node` (number `id`) returns counting only rays numbered up to `upto`.
/// Recursion is bounded by the depth limit (`limits::MAX_DEPTH`).
fn partial(view: &TreeView, node: &RayNode, id: NodeId, upto: NodeId) -> Vec3A {
    if id > upto {
        return Vec3A::ZERO;
    }
    if node.unrecorded > 0 && view.subtree_end(id) <= upto {
        return Vec3A::from(node.color);
    }
    let (Some(hit), Some(local)) = (&node.hit, &node.local) else {
        // A miss returns the background through its medium, as recorded.
        return Vec3A::from(node.color);
    };
    let children = view.children(id);
    let mut color = Vec3A::from(local.ambient) + Vec3A::from(local.emission);
    for light in &local.lights {
        let counted = match light.shadow_child.and_then(|index| children.get(index)) {
            Some(&shadow) => shadow <= upto,
            None => true,
        };
        if counted {
            color += Vec3A::from(light.diffuse) + Vec3A::from(light.specular);
        }
    }
    for (child, &child_id) in node.children.iter().zip(children) {
        if child.kind != RayKind::Shadow && child_id <= upto {
            color += Vec3A::from(child.coefficient) * partial(view, child, child_id, upto);
        }
    }
    color * Vec3A::from(hit.absorption)
}

/// Something worth stopping at (`{` `}`): where recursion was cut or light was lost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayEvent {
    /// The ray met a surface where refraction was impossible.
    TotalInternalReflection,
    /// A secondary ray would have been deeper than `max_depth`.
    MaxDepth,
    /// A secondary ray's path weight was under `min_weight`.
    WeightCutoff,
    /// The sample had cast its budget of rays (`rays per sample`): recursion stopped.
    RayBudget,
    /// A shadow ray found an opaque blocker.
    ShadowBlocked,
    /// The ray met the surface it left at once (surface acne), as the explain library
    /// judges it (`whitted_explain::findings::is_self_hit`).
    SelfHit,
}

impl RayEvent {
    pub fn name(self) -> &'static str {
        match self {
            RayEvent::TotalInternalReflection => "total internal reflection",
            RayEvent::MaxDepth => "max depth",
            RayEvent::WeightCutoff => "weight cut-off",
            RayEvent::RayBudget => "ray budget",
            RayEvent::ShadowBlocked => "blocked shadow ray",
            RayEvent::SelfHit => "self-hit",
        }
    }
}

/// The events at ray `id`: read off what the tracer recorded (its termination, the
/// secondary rays it skipped and why, a shadow ray's outcome).
pub fn events(view: &TreeView, id: NodeId) -> Vec<RayEvent> {
    let Some(node) = view.node(id) else {
        return Vec::new();
    };
    let ended = |reason: Termination| {
        node.termination == reason || node.skipped.iter().any(|s| s.reason == reason)
    };
    let mut found = Vec::new();
    if ended(Termination::TotalInternalReflection) {
        found.push(RayEvent::TotalInternalReflection);
    }
    if ended(Termination::MaxDepth) {
        found.push(RayEvent::MaxDepth);
    }
    if ended(Termination::WeightCutoff) {
        found.push(RayEvent::WeightCutoff);
    }
    if ended(Termination::RayBudget) {
        found.push(RayEvent::RayBudget);
    }
    if node
        .shadow
        .as_ref()
        .is_some_and(|s| s.result == ShadowOutcome::Blocked)
    {
        found.push(RayEvent::ShadowBlocked);
    }
    let parent = view.parent(id).and_then(|p| view.node(p));
    if parent.is_some_and(|parent| whitted_explain::findings::is_self_hit(node, parent)) {
        found.push(RayEvent::SelfHit);
    }
    found
}

/// Selects the next (or previous) ray in the tracer's order that has an event; the ray and
/// its events, or `None` (the selection stays) when there is none that way.
pub fn run_to_event(view: &mut TreeView, forward: bool) -> Option<(NodeId, Vec<RayEvent>)> {
    view.set_stepping(true);
    let selected = view.selected();
    let found = if forward {
        (selected + 1..view.len()).find_map(|id| with_events(view, id))
    } else {
        (0..selected).rev().find_map(|id| with_events(view, id))
    };
    if let Some((id, _)) = &found {
        view.select(*id);
    }
    found
}

fn with_events(view: &TreeView, id: NodeId) -> Option<(NodeId, Vec<RayEvent>)> {
    let found = events(view, id);
    (!found.is_empty()).then_some((id, found))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::{fixture, glass_pixel_tree, GLASS_PIXEL};
    use whitted_tracer::ray_tree::{trace_pixel, SampleChoice};

    fn view_of(pixel: (u32, u32)) -> TreeView {
        let f = fixture();
        let tree = trace_pixel(
            &f.prepared,
            &f.scene,
            &f.options,
            pixel.0,
            pixel.1,
            SampleChoice::All,
        )
        .expect("inside the image");
        TreeView::new(tree)
    }

    #[test]
    fn stepping_walks_every_ray_in_pre_order_and_stops_at_the_ends() {
        let mut view = TreeView::new(glass_pixel_tree());
        let mut seen = vec![view.selected()];
        while step(&mut view, true) {
            seen.push(view.selected());
        }
        assert_eq!(seen, (0..view.len()).collect::<Vec<_>>());
        assert!(view.is_stepping());
        // Every ray stepped to is shown, light or not.
        assert!(view.visible().contains(&view.selected()));
        assert!(!step(&mut view, true), "no ray after the last");
        assert!(step(&mut view, false));
        assert_eq!(view.selected(), view.len() - 2);
    }

    #[test]
    fn the_order_is_the_tracers_shadow_rays_then_reflected_then_transmitted() {
        let mut view = TreeView::new(glass_pixel_tree());
        step(&mut view, true);
        let kinds: Vec<RayKind> = view.tree().samples[0]
            .root
            .children
            .iter()
            .map(|c| c.kind)
            .collect();
        assert_eq!(
            kinds,
            [RayKind::Shadow, RayKind::Reflected, RayKind::Transmitted]
        );
        assert_eq!(view.node(view.selected()).map(|n| n.kind), Some(kinds[0]));
        // After the shadow ray comes the reflected ray, then its whole subtree, then the
        // transmitted ray.
        step(&mut view, true);
        assert_eq!(
            view.selected_node().map(|n| n.kind),
            Some(RayKind::Reflected)
        );
        let reflected = view.selected();
        let transmitted = view.subtree_end(reflected) + 1;
        assert_eq!(view.parent(transmitted), Some(0));
        assert_eq!(
            view.node(transmitted).map(|n| n.kind),
            Some(RayKind::Transmitted)
        );
    }

    #[test]
    fn the_running_colour_grows_to_exactly_the_pixel() {
        // The glass, the mirror, the floor in shadow and in light, and the sky.
        for pixel in [(400, 270), (250, 250), (320, 400), (100, 420), (320, 20)] {
            let view = view_of(pixel);
            let last = view.len() - 1;
            let pixel_color = view.tree().color;
            assert_eq!(running_color(&view, last), pixel_color, "pixel {pixel:?}");
            assert_ne!(pixel_color, [0.0; 3]);
            // Before any ray is counted, black; it never decreases along the way.
            let mut previous = [0.0f32; 3];
            for id in 0..=last {
                let now = running_color(&view, id);
                for c in 0..3 {
                    assert!(now[c] >= previous[c] - 1e-6, "{pixel:?} ray {id}");
                }
                previous = now;
            }
        }
    }

    #[test]
    fn the_running_colour_ends_at_the_pixel_with_several_samples_and_in_a_cut_tree() {
        let f = fixture();
        let mut options = f.options.clone();
        options.samples_per_pixel = 4;
        let tree = trace_pixel(&f.prepared, &f.scene, &options, 400, 270, SampleChoice::All)
            .expect("inside the image");
        assert_eq!(tree.samples.len(), 4);
        let view = TreeView::new(tree);
        assert_eq!(running_color(&view, view.len() - 1), view.tree().color);
        // Half way, less than the whole pixel.
        let half = running_color(&view, view.len() / 2);
        assert!(half.iter().sum::<f32>() < view.tree().color.iter().sum::<f32>());

        // A tree cut by its node budget: the cut subtrees count with their recorded colour.
        let request = whitted_tracer::ray_tree::TraceRequest {
            x: 400,
            y: 270,
            which: SampleChoice::All,
            node_budget: 5,
            cancel: None,
        };
        let tree = whitted_tracer::ray_tree::trace_pixel_request(
            &f.prepared,
            &f.scene,
            &f.options,
            &request,
        )
        .expect("inside the image");
        assert!(tree.unrecorded > 0);
        let view = TreeView::new(tree);
        assert_eq!(running_color(&view, view.len() - 1), view.tree().color);
    }

    #[test]
    fn the_running_colour_counts_a_light_when_its_shadow_ray_is_visited() {
        let view = TreeView::new(glass_pixel_tree());
        let root = view.node(0).unwrap();
        let local = root.local.as_ref().unwrap();
        // After the camera ray alone: its ambient and emission, weight 1, in air.
        let camera_only = running_color(&view, 0);
        let expected = Vec3A::from(local.ambient) + Vec3A::from(local.emission);
        assert_eq!(camera_only, expected.to_array());
        // After its shadow ray: plus the sun's diffuse and specular.
        let sun = &local.lights[0];
        assert_eq!(sun.shadow_child, Some(0));
        let with_sun = expected + Vec3A::from(sun.diffuse) + Vec3A::from(sun.specular);
        assert_eq!(running_color(&view, 1), with_sun.to_array());
    }

    fn view_with(pixel: (u32, u32), max_depth: u32, min_weight: f32) -> TreeView {
        let f = fixture();
        let mut options = f.options.clone();
        options.max_depth = max_depth;
        options.min_weight = min_weight;
        let tree = trace_pixel(
            &f.prepared,
            &f.scene,
            &options,
            pixel.0,
            pixel.1,
            SampleChoice::All,
        )
        .expect("inside the image");
        TreeView::new(tree)
    }

    /// Every ray with an event, in order, as `}` finds them from the camera ray.
    fn walk_events(view: &mut TreeView) -> Vec<(NodeId, Vec<RayEvent>)> {
        let mut found = Vec::new();
        while let Some((id, events)) = run_to_event(view, true) {
            assert_eq!(view.selected(), id);
            found.push((id, events));
        }
        found
    }

    #[test]
    fn events_are_found_forward_and_backward() {
        // The glass pixel with a shallow depth limit: rays cut at depth 2, and the floor's
        // shadow rays under the glass blocked.
        let mut view = view_with(GLASS_PIXEL, 2, 0.0);
        let found = walk_events(&mut view);
        let kinds: Vec<RayEvent> = found.iter().flat_map(|(_, e)| e.clone()).collect();
        assert!(kinds.contains(&RayEvent::MaxDepth), "{kinds:?}");
        assert!(kinds.contains(&RayEvent::ShadowBlocked), "{kinds:?}");
        // Every event ray and no other, in the tracer's order.
        let expected: Vec<NodeId> = (0..view.len())
            .filter(|&id| !events(&view, id).is_empty())
            .collect();
        assert_eq!(
            found.iter().map(|(id, _)| *id).collect::<Vec<_>>(),
            expected
        );
        // Each is what the tracer recorded.
        for (id, events) in &found {
            let node = view.node(*id).unwrap();
            for event in events {
                let recorded = match event {
                    RayEvent::MaxDepth => node
                        .skipped
                        .iter()
                        .any(|s| s.reason == Termination::MaxDepth),
                    RayEvent::ShadowBlocked => node
                        .shadow
                        .as_ref()
                        .is_some_and(|s| s.result == ShadowOutcome::Blocked),
                    _ => true,
                };
                assert!(recorded, "ray {id}: {event:?}");
                if *event == RayEvent::MaxDepth {
                    assert_eq!(node.depth, 2);
                }
            }
        }
        // `{` from the last event goes back to the one before it; from the first, nowhere.
        assert!(expected.len() >= 2);
        let (id, _) = run_to_event(&mut view, false).expect("an earlier event");
        assert_eq!(id, expected[expected.len() - 2]);
        view.select(expected[0]);
        assert_eq!(run_to_event(&mut view, false), None);
        assert_eq!(
            view.selected(),
            expected[0],
            "no event before: the selection stays"
        );
        // The default scene's glass pixel: light under 1% is cut by the weight limit.
        let mut view = TreeView::new(glass_pixel_tree());
        let kinds: Vec<RayEvent> = walk_events(&mut view)
            .into_iter()
            .flat_map(|(_, e)| e)
            .collect();
        assert!(kinds.contains(&RayEvent::WeightCutoff), "{kinds:?}");
    }

    #[test]
    fn total_internal_reflection_is_an_event() {
        // A sphere never traps light by total internal reflection (a ray meets its inside at
        // the angle it entered), so the transmitted ray's record is edited as the tracer
        // writes it for a ray that met a denser medium's surface too steeply.
        let mut tree = glass_pixel_tree();
        let root = &mut tree.samples[0].root;
        let transmitted = root
            .children
            .iter_mut()
            .find(|c| c.kind == RayKind::Transmitted)
            .unwrap();
        let mut skipped = whitted_tracer::ray_tree::SkippedInfo {
            kind: RayKind::Transmitted,
            depth: transmitted.depth + 1,
            weight: [0.0; 3],
            coefficient: [0.0; 3],
            reason: Termination::TotalInternalReflection,
        };
        transmitted.skipped.push(skipped.clone());
        let mut view = TreeView::new(tree);
        let id = (0..view.len())
            .find(|&id| view.node(id).unwrap().kind == RayKind::Transmitted)
            .unwrap();
        let found = walk_events(&mut view);
        let tir: Vec<NodeId> = found
            .iter()
            .filter(|(_, e)| e.contains(&RayEvent::TotalInternalReflection))
            .map(|(id, _)| *id)
            .collect();
        assert_eq!(tir, [id]);
        // A skip for another reason is another event.
        skipped.reason = Termination::MaxDepth;
        let mut tree = glass_pixel_tree();
        tree.samples[0].root.skipped.push(skipped);
        let view = TreeView::new(tree);
        assert_eq!(events(&view, 0), [RayEvent::MaxDepth]);
    }

    /// A ray refused because its sample had cast its budget of rays is an event of its own,
    /// named as the ray tree names it.
    #[test]
    fn the_ray_budget_is_an_event() {
        let mut tree = glass_pixel_tree();
        tree.samples[0]
            .root
            .skipped
            .push(whitted_tracer::ray_tree::SkippedInfo {
                kind: RayKind::Reflected,
                depth: 1,
                weight: [0.5; 3],
                coefficient: [0.5; 3],
                reason: Termination::RayBudget,
            });
        let view = TreeView::new(tree);
        assert_eq!(events(&view, 0), [RayEvent::RayBudget]);
        assert_eq!(RayEvent::RayBudget.name(), "ray budget");
    }

    #[test]
    fn a_hit_on_the_surface_just_left_is_a_self_hit_event() {
        let mut tree = glass_pixel_tree();
        let root = &mut tree.samples[0].root;
        let glass = root.hit.clone().unwrap();
        let reflected = root
            .children
            .iter_mut()
            .find(|c| c.kind == RayKind::Reflected)
            .unwrap();
        let mut acne = glass.clone();
        acne.t = 1e-7;
        reflected.hit = Some(acne);
        let view = TreeView::new(tree);
        let reflected = (0..view.len())
            .find(|&id| {
                view.node(id).unwrap().kind == RayKind::Reflected && view.parent(id) == Some(0)
            })
            .unwrap();
        assert!(events(&view, reflected).contains(&RayEvent::SelfHit));
        // The untouched tree has none.
        let view = TreeView::new(glass_pixel_tree());
        assert!(!events(&view, reflected).contains(&RayEvent::SelfHit));
    }
}
