//! The ray-tree pane's state: the picked pixel's tree flattened into numbered nodes, which of
//! them are open, which one is selected, and how far the pane is scrolled.
//!
//! Kept apart from drawing so that navigation is plain data manipulation, testable without a
//! terminal. Nodes are numbered in pre-order over every recorded sample; a node is found
//! again from its sample and its path of child indices.
//!
//! Light rays are collapsed by default (`a` shows them): a tree of hundreds of rays buries
//! the few that make the pixel. A ray is light when its path weight counts for less than
//! [`LIGHT_SHARE`] of the pixel and no ray below it counts for more.

use whitted_tracer::ray_tree::{LightContribution, RayNode, RayTree, SampleTree};

/// A node's number in pre-order.
pub type NodeId = usize;

/// The share of the pixel under which a ray is light: its path weight (largest channel)
/// divided by the samples per pixel, i.e. how much its returned colour counts in the pixel.
pub const LIGHT_SHARE: f32 = 0.01;

#[derive(Clone, Debug, PartialEq)]
struct Entry {
    sample: usize,
    /// Child indices from the sample's camera ray down to this node.
    path: Vec<usize>,
    parent: Option<NodeId>,
    children: Vec<NodeId>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct TreeView {
    tree: RayTree,
    entries: Vec<Entry>,
    open: Vec<bool>,
    /// Whether the node or a ray below it counts for at least [`LIGHT_SHARE`] of the pixel
    /// (camera rays always do): the nodes shown while light rays are collapsed.
    heavy: Vec<bool>,
    /// `a`: light rays shown too.
    show_all: bool,
    /// Whether the user is stepping (`[ ] { }`): the tree pane then shows the running colour.
    stepping: bool,
    selected: NodeId,
    scroll: usize,
}

impl TreeView {
    /// Every node of the first sample open (the usual single-sample case shows the whole
    /// tree); further samples start closed. The first camera ray is selected.
    pub fn new(tree: RayTree) -> TreeView {
        let mut entries = Vec::new();
        // Each node's largest path-weight channel, read while the node is at hand.
        let mut weights = Vec::new();
        for (sample_index, sample) in tree.samples.iter().enumerate() {
            // An explicit stack: a deep tree must not overflow the call stack.
            let mut stack: Vec<(&RayNode, Vec<usize>, Option<NodeId>)> =
                vec![(&sample.root, Vec::new(), None)];
            while let Some((node, path, parent)) = stack.pop() {
                let id = entries.len();
                weights.push(node.weight.iter().fold(0.0f32, |m, &w| m.max(w)));
                entries.push(Entry {
                    sample: sample_index,
                    path: path.clone(),
                    parent,
                    children: Vec::new(),
                });
                if let Some(parent) = parent {
                    entries[parent].children.push(id);
                }
                for (child_index, child) in node.children.iter().enumerate().rev() {
                    let mut child_path = path.clone();
                    child_path.push(child_index);
                    stack.push((child, child_path, Some(id)));
                }
            }
        }
        let open = entries.iter().map(|e| e.sample == 0).collect();
        let heavy = heavy_nodes(&entries, &weights, tree.samples_per_pixel);
        TreeView {
            tree,
            entries,
            open,
            heavy,
            show_all: false,
            stepping: false,
            selected: 0,
            scroll: 0,
        }
    }

    /// A view of `tree` that keeps what it can of `previous`: the open and closed nodes and
    /// the selection, matched by sample and path (used when a reload re-traces the pixel).
    pub fn new_like(tree: RayTree, previous: &TreeView) -> TreeView {
        let mut view = TreeView::new(tree);
        for id in 0..view.entries.len() {
            let entry = &view.entries[id];
            if let Some(old) = previous.find(entry.sample, &entry.path) {
                view.open[id] = previous.open[old];
            }
        }
        view.show_all = previous.show_all;
        let selected = &previous.entries[previous.selected];
        if let Some(id) = view.find(selected.sample, &selected.path) {
            view.select(id);
        }
        view.scroll = previous.scroll;
        view
    }

    fn find(&self, sample: usize, path: &[usize]) -> Option<NodeId> {
        self.entries
            .iter()
            .position(|e| e.sample == sample && e.path == path)
    }

    pub fn tree(&self) -> &RayTree {
        &self.tree
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    pub fn sample(&self, id: NodeId) -> Option<&SampleTree> {
        self.tree.samples.get(self.entries.get(id)?.sample)
    }

    pub fn node(&self, id: NodeId) -> Option<&RayNode> {
        node_at(&self.tree, self.entries.get(id)?)
    }

    pub fn parent(&self, id: NodeId) -> Option<NodeId> {
        self.entries.get(id)?.parent
    }

    /// How far the node is indented: 0 for camera rays.
    pub fn level(&self, id: NodeId) -> usize {
        self.entries.get(id).map_or(0, |e| e.path.len())
    }

    /// Whether the node has children shown (light ones count only when shown).
    pub fn has_children(&self, id: NodeId) -> bool {
        self.children(id).iter().any(|&c| self.is_shown(c))
    }

    /// Every recorded child, shown or not, in the tracer's order.
    pub fn children(&self, id: NodeId) -> &[NodeId] {
        self.entries.get(id).map_or(&[], |e| e.children.as_slice())
    }

    /// Whether the node has a row when its ancestors are open: it is heavy, or `a` shows all.
    pub fn is_shown(&self, id: NodeId) -> bool {
        self.show_all || self.heavy.get(id).copied().unwrap_or(false)
    }

    pub fn is_stepping(&self) -> bool {
        self.stepping
    }

    pub fn set_stepping(&mut self, stepping: bool) {
        self.stepping = stepping;
    }

    pub fn shows_all(&self) -> bool {
        self.show_all
    }

    /// How many rays the collapse hides (0 while `a` shows all).
    pub fn hidden_count(&self) -> usize {
        if self.show_all {
            0
        } else {
            self.heavy.iter().filter(|&&h| !h).count()
        }
    }

    /// How many rays are light (hidden unless `a` shows all).
    pub fn light_count(&self) -> usize {
        self.heavy.iter().filter(|&&h| !h).count()
    }

    /// `a`: shows the light rays, or collapses them again. A selection that the collapse
    /// hides moves up to the nearest ray still shown.
    pub fn toggle_show_all(&mut self) {
        self.show_all = !self.show_all;
        while !self.is_shown(self.selected) {
            match self.parent(self.selected) {
                Some(parent) => self.selected = parent,
                None => break,
            }
        }
    }

    /// How much of the pixel this ray accounts for: its path weight times the colour it
    /// returned, over the sample count. A shadow ray accounts for its light's diffuse and
    /// specular terms at the hit that cast it.
    pub fn contribution(&self, id: NodeId) -> [f32; 3] {
        let Some(node) = self.node(id) else {
            return [0.0; 3];
        };
        let samples = self.tree.samples_per_pixel.max(1) as f32;
        let share = if node.kind == whitted_tracer::RayKind::Shadow {
            match self.light_of_shadow(id) {
                Some(light) => mul(node.weight, add(light.diffuse, light.specular)),
                None => [0.0; 3],
            }
        } else {
            mul(node.weight, node.color)
        };
        share.map(|c| c / samples)
    }

    pub fn is_open(&self, id: NodeId) -> bool {
        self.open.get(id).copied().unwrap_or(false)
    }

    /// For a shadow ray: its light's share of the parent's local illumination.
    pub fn light_of_shadow(&self, id: NodeId) -> Option<&LightContribution> {
        let entry = self.entries.get(id)?;
        let index = *entry.path.last()?;
        let parent = self.node(entry.parent?)?;
        parent
            .local
            .as_ref()?
            .lights
            .iter()
            .find(|light| light.shadow_child == Some(index))
    }

    /// The nodes shown as rows, top to bottom: every node whose ancestors are all open.
    pub fn visible(&self) -> Vec<NodeId> {
        let mut rows = Vec::with_capacity(self.entries.len());
        let mut id = 0;
        while id < self.entries.len() {
            // A light ray's subtree is all light (see `heavy_nodes`): skip it whole.
            if !self.is_shown(id) {
                id = self.after_subtree(id);
                continue;
            }
            rows.push(id);
            id = if self.is_open(id) {
                id + 1
            } else {
                self.after_subtree(id)
            };
        }
        rows
    }

    /// The last node of `id`'s subtree in pre-order (`id` itself for a leaf).
    pub fn subtree_end(&self, id: NodeId) -> NodeId {
        self.after_subtree(id) - 1
    }

    /// The first node after `id`'s subtree in pre-order.
    fn after_subtree(&self, id: NodeId) -> NodeId {
        let mut last = id;
        while let Some(&child) = self.entries.get(last).and_then(|e| e.children.last()) {
            last = child;
        }
        last + 1
    }

    pub fn selected(&self) -> NodeId {
        self.selected
    }

    pub fn selected_node(&self) -> Option<&RayNode> {
        self.node(self.selected)
    }

    pub fn scroll(&self) -> usize {
        self.scroll
    }

    /// Selects a node, opening its ancestors so that it is shown (and showing every ray
    /// when it is a light one).
    pub fn select(&mut self, id: NodeId) {
        if id >= self.entries.len() {
            return;
        }
        if !self.is_shown(id) {
            self.show_all = true;
        }
        let mut ancestor = self.entries[id].parent;
        while let Some(a) = ancestor {
            self.open[a] = true;
            ancestor = self.entries[a].parent;
        }
        self.selected = id;
    }

    fn move_by(&mut self, rows: isize) {
        let visible = self.visible();
        let Some(position) = visible.iter().position(|&id| id == self.selected) else {
            return;
        };
        let target = position
            .saturating_add_signed(rows)
            .min(visible.len().saturating_sub(1));
        self.selected = visible[target];
    }

    pub fn select_next(&mut self) {
        self.move_by(1);
    }

    pub fn select_previous(&mut self) {
        self.move_by(-1);
    }

    pub fn page(&mut self, rows: isize) {
        self.move_by(rows);
    }

    pub fn select_first(&mut self) {
        self.selected = 0;
    }

    pub fn select_last(&mut self) {
        if let Some(&last) = self.visible().last() {
            self.selected = last;
        }
    }

    /// Left: closes an open node, otherwise goes to the parent.
    pub fn left(&mut self) {
        let id = self.selected;
        if self.has_children(id) && self.is_open(id) {
            self.open[id] = false;
        } else if let Some(parent) = self.parent(id) {
            self.selected = parent;
        }
    }

    /// Right: opens a closed node, otherwise goes to its first child.
    pub fn right(&mut self) {
        let id = self.selected;
        if !self.has_children(id) {
            return;
        }
        if self.is_open(id) {
            if let Some(&first) = self.children(id).iter().find(|&&c| self.is_shown(c)) {
                self.selected = first;
            }
        } else {
            self.open[id] = true;
        }
    }

    /// Opens or closes the selected node.
    pub fn toggle(&mut self) {
        let id = self.selected;
        if self.has_children(id) {
            self.open[id] = !self.open[id];
        }
    }

    /// Scrolls just enough that the selected row is among `height` rows shown.
    pub fn keep_selection_in_view(&mut self, height: usize) {
        let visible = self.visible();
        let position = visible
            .iter()
            .position(|&id| id == self.selected)
            .unwrap_or(0);
        let height = height.max(1);
        if position < self.scroll {
            self.scroll = position;
        } else if position >= self.scroll + height {
            self.scroll = position + 1 - height;
        }
        // Never leave empty rows below the last one when the tree would fill the pane.
        self.scroll = self.scroll.min(visible.len().saturating_sub(height));
    }
}

/// For each node (entries in pre-order), whether it or a ray below it counts for at least
/// [`LIGHT_SHARE`] of the pixel. Camera rays always count, so that every sample has a row.
/// Computed bottom-up: in pre-order a node's children come after it.
fn heavy_nodes(entries: &[Entry], weights: &[f32], samples_per_pixel: u32) -> Vec<bool> {
    let samples = samples_per_pixel.max(1) as f32;
    let mut heavy = vec![false; entries.len()];
    for id in (0..entries.len()).rev() {
        let entry = &entries[id];
        let own = entry.parent.is_none() || weights[id] / samples >= LIGHT_SHARE;
        heavy[id] = own || entry.children.iter().any(|&c| heavy[c]);
    }
    heavy
}

fn node_at<'t>(tree: &'t RayTree, entry: &Entry) -> Option<&'t RayNode> {
    let mut node = &tree.samples.get(entry.sample)?.root;
    for &index in &entry.path {
        node = node.children.get(index)?;
    }
    Some(node)
}

fn mul(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

fn add(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::glass_pixel_tree;
    use whitted_tracer::RayKind;

    #[test]
    fn nodes_are_numbered_in_pre_order_and_all_open() {
        let mut view = TreeView::new(glass_pixel_tree());
        view.toggle_show_all();
        assert_eq!(view.len(), view.tree().samples[0].root.ray_count());
        assert_eq!(view.visible().len(), view.len());
        assert_eq!(view.node(0).map(|n| n.kind), Some(RayKind::Camera));
        // The camera ray's first children are its shadow rays, then reflected, transmitted.
        let kinds: Vec<RayKind> = view.tree().samples[0]
            .root
            .children
            .iter()
            .map(|c| c.kind)
            .collect();
        assert_eq!(kinds.last(), Some(&RayKind::Transmitted));
        assert_eq!(view.node(1).map(|n| n.kind), Some(kinds[0]));
    }

    /// The glass pixel's tree with the path weights of one ray and its subtree scaled down
    /// so that they count for under 1% of the pixel: the reflected ray of the camera ray
    /// (weight 0.1 × `scale`).
    fn with_light_reflection(scale: f32) -> RayTree {
        fn scale_weights(node: &mut RayNode, scale: f32) {
            node.weight = node.weight.map(|w| w * scale);
            for child in &mut node.children {
                scale_weights(child, scale);
            }
        }
        let mut tree = glass_pixel_tree();
        let root = &mut tree.samples[0].root;
        let reflected = root
            .children
            .iter_mut()
            .find(|c| c.kind == RayKind::Reflected)
            .expect("the glass reflects");
        scale_weights(reflected, scale);
        tree
    }

    #[test]
    fn light_rays_are_collapsed_and_counted_until_a_shows_them() {
        let view = TreeView::new(glass_pixel_tree());
        // With the scene as it is, some rays count for under 1% of the pixel.
        let light: Vec<NodeId> = (0..view.len())
            .filter(|&id| {
                let weight = view.node(id).unwrap().weight;
                id != 0 && weight.iter().all(|&w| w < LIGHT_SHARE)
            })
            .collect();
        // A light ray is hidden unless a heavy ray is below it.
        let hidden: Vec<NodeId> = (0..view.len()).filter(|&id| !view.is_shown(id)).collect();
        for &id in &hidden {
            assert!(light.contains(&id), "ray {id} is hidden but heavy");
        }
        assert_eq!(view.hidden_count(), hidden.len());
        assert_eq!(view.visible().len(), view.len() - hidden.len());

        // Make the camera ray's reflection and everything below it light: exactly that
        // subtree is hidden, and `a` shows it again.
        let mut view = TreeView::new(with_light_reflection(0.05));
        let reflected = view
            .children(0)
            .iter()
            .copied()
            .find(|&c| view.node(c).unwrap().kind == RayKind::Reflected)
            .unwrap();
        let subtree: Vec<NodeId> = (reflected..=view.subtree_end(reflected)).collect();
        for &id in &subtree {
            assert!(
                !view.is_shown(id),
                "ray {id} of the light reflection is shown"
            );
            assert!(!view.visible().contains(&id));
        }
        assert!(view.hidden_count() >= subtree.len());
        view.toggle_show_all();
        assert!(view.shows_all());
        assert_eq!(view.hidden_count(), 0);
        assert_eq!(view.visible().len(), view.len());
        // Collapsing again with a hidden ray selected moves the selection up to its parent.
        view.select(subtree[subtree.len() - 1]);
        view.toggle_show_all();
        assert_eq!(view.selected(), 0);
        // Selecting a hidden ray (stepping to it) shows every ray.
        view.select(reflected);
        assert!(view.shows_all());
        assert_eq!(view.selected(), reflected);
        // At 1.5% of the pixel the reflection is heavy again: not hidden.
        let view = TreeView::new(with_light_reflection(0.15));
        assert!(view.is_shown(reflected));
    }

    #[test]
    fn left_closes_then_climbs_and_right_opens_then_descends() {
        let mut view = TreeView::new(glass_pixel_tree());
        let all = view.len() - view.hidden_count();
        view.left();
        assert!(!view.is_open(0));
        assert_eq!(view.visible(), vec![0]);
        view.left();
        assert_eq!(view.selected(), 0, "the root has no parent");
        view.right();
        assert!(view.is_open(0));
        assert_eq!(view.visible().len(), all);
        view.right();
        assert_eq!(view.selected(), 1);
        assert_eq!(view.parent(1), Some(0));
        view.left();
        assert_eq!(view.selected(), 0);
    }

    #[test]
    fn up_and_down_walk_visible_rows_and_stop_at_the_ends() {
        let mut view = TreeView::new(glass_pixel_tree());
        view.select_previous();
        assert_eq!(view.selected(), 0);
        view.select_next();
        view.select_next();
        assert_eq!(view.selected(), view.visible()[2]);
        view.select_last();
        let last = *view.visible().last().unwrap();
        assert_eq!(view.selected(), last);
        view.select_next();
        assert_eq!(view.selected(), last);
        view.select_first();
        assert_eq!(view.selected(), 0);
    }

    #[test]
    fn shadow_rays_know_their_light() {
        let view = TreeView::new(glass_pixel_tree());
        let shadow = (0..view.len())
            .find(|&id| view.node(id).is_some_and(|n| n.kind == RayKind::Shadow))
            .expect("the glass pixel casts a shadow ray");
        let light = view.light_of_shadow(shadow).expect("a light");
        assert_eq!(light.light.label, "sun");
        assert_eq!(view.light_of_shadow(0), None);
    }

    #[test]
    fn the_scroll_follows_the_selection() {
        let mut view = TreeView::new(glass_pixel_tree());
        assert!(view.len() > 4, "the test needs a tree taller than the pane");
        view.select_last();
        view.keep_selection_in_view(3);
        assert_eq!(view.scroll(), view.visible().len() - 3);
        view.select_first();
        view.keep_selection_in_view(3);
        assert_eq!(view.scroll(), 0);
    }

    #[test]
    fn a_retraced_tree_keeps_the_selection_and_closed_nodes() {
        let mut view = TreeView::new(glass_pixel_tree());
        let last = *view.visible().last().unwrap();
        view.select(last);
        let parent = view.parent(last).unwrap();
        view.select(parent);
        view.left();
        let again = TreeView::new_like(glass_pixel_tree(), &view);
        assert_eq!(again.selected(), parent);
        assert!(!again.is_open(parent));
        assert!(again.is_open(0));
    }
}
