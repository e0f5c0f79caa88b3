//! `p`: following the path that matters down the picked pixel's tree, one heaviest child at
//! a time. What all the keys that follow what matters (`a`, `p`, `[ ] { }`, `x`) do to the
//! [`App`](crate::app::App) is in [`update`].

pub(crate) mod update;

use crate::tree::state::{NodeId, TreeView};

/// The child of `id` that brings the most to the pixel ([`TreeView::contribution`], summed
/// over the channels); the first of equals. `None` for a ray without children.
pub fn heaviest_child(view: &TreeView, id: NodeId) -> Option<NodeId> {
    let mut best: Option<(NodeId, f32)> = None;
    for &child in view.children(id) {
        let amount: f32 = view.contribution(child).iter().sum();
        if best.is_none_or(|(_, most)| amount > most) {
            best = Some((child, amount));
        }
    }
    best.map(|(child, _)| child)
}

/// Moves the selection to the selected ray's heaviest child (showing it even when it is
/// light); the child, or `None` when the selected ray has none.
pub fn follow_heaviest(view: &mut TreeView) -> Option<NodeId> {
    let child = heaviest_child(view, view.selected())?;
    view.select(child);
    Some(child)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::glass_pixel_tree;
    use whitted_tracer::ray_tree::RayNode;
    use whitted_tracer::RayKind;

    /// A camera ray with three leaf children of chosen weights and colours, one sample.
    fn small_tree() -> TreeView {
        let mut tree = glass_pixel_tree();
        tree.samples.truncate(1);
        tree.samples_per_pixel = 1;
        let root = &mut tree.samples[0].root;
        let mut leaf = root.clone();
        leaf.children.clear();
        leaf.local = None;
        leaf.skipped.clear();
        let child = |kind, weight: f32, color: [f32; 3]| RayNode {
            kind,
            depth: 1,
            weight: [weight; 3],
            color,
            ..leaf.clone()
        };
        root.children = vec![
            // 0.9 × (0.2 + 0.1 + 0) = 0.27: the heaviest path weight, not the most light.
            child(RayKind::Transmitted, 0.9, [0.2, 0.1, 0.0]),
            // 0.1 × (1 + 1 + 1) = 0.3: the most light.
            child(RayKind::Reflected, 0.1, [1.0, 1.0, 1.0]),
            // 0.5 × 0.5 = 0.25 on one channel.
            child(RayKind::Reflected, 0.5, [0.5, 0.0, 0.0]),
        ];
        TreeView::new(tree)
    }

    #[test]
    fn the_heaviest_child_is_the_one_bringing_most_light_not_the_heaviest_weight() {
        let view = small_tree();
        assert_eq!(view.children(0), &[1, 2, 3]);
        let sums: Vec<f32> = (1..=3)
            .map(|id| view.contribution(id).iter().sum())
            .collect();
        for (sum, hand) in sums.iter().zip([0.27f32, 0.3, 0.25]) {
            assert!((sum - hand).abs() < 1e-6, "{sums:?}");
        }
        assert_eq!(heaviest_child(&view, 0), Some(2));
        assert_eq!(heaviest_child(&view, 2), None, "a leaf has no children");
    }

    #[test]
    fn p_walks_down_the_heaviest_path_until_a_leaf() {
        let mut view = small_tree();
        assert_eq!(follow_heaviest(&mut view), Some(2));
        assert_eq!(view.selected(), 2);
        assert_eq!(follow_heaviest(&mut view), None);
        assert_eq!(view.selected(), 2, "the selection stays on the leaf");

        // On the glass pixel every step goes to the child with the largest contribution.
        let mut view = TreeView::new(glass_pixel_tree());
        let mut steps = 0;
        while let Some(child) = follow_heaviest(&mut view) {
            let parent = view.parent(child).unwrap();
            let amount = |id| view.contribution(id).iter().sum::<f32>();
            for &sibling in view.children(parent) {
                assert!(amount(sibling) <= amount(child));
            }
            steps += 1;
        }
        assert!(steps >= 2, "the glass pixel's heavy path has several rays");
    }
}
