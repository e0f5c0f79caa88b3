//! The ray-tree pane's state: the picked pixel's tree flattened into numbered nodes, which of
//! them are open, which one is selected, and how far the pane is scrolled.
//!
//! Kept apart from drawing so that navigation is plain data manipulation, testable without a
//! terminal. Nodes are numbered in pre-order over every recorded sample; a node is found
//! again from its sample and its path of child indices.

use whitted_tracer::ray_tree::{LightContribution, RayNode, RayTree, SampleTree};

/// A node's number in pre-order.
pub type NodeId = usize;

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
    selected: NodeId,
    scroll: usize,
}

impl TreeView {
    /// Every node of the first sample open (the usual single-sample case shows the whole
    /// tree); further samples start closed. The first camera ray is selected.
    pub fn new(tree: RayTree) -> TreeView {
        let mut entries = Vec::new();
        for (sample_index, sample) in tree.samples.iter().enumerate() {
            // An explicit stack: a deep tree must not overflow the call stack.
            let mut stack: Vec<(&RayNode, Vec<usize>, Option<NodeId>)> =
                vec![(&sample.root, Vec::new(), None)];
            while let Some((node, path, parent)) = stack.pop() {
                let id = entries.len();
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
        TreeView {
            tree,
            entries,
            open,
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
        let entry = self.entries.get(id)?;
        let mut node = &self.tree.samples.get(entry.sample)?.root;
        for &index in &entry.path {
            node = node.children.get(index)?;
        }
        Some(node)
    }

    pub fn parent(&self, id: NodeId) -> Option<NodeId> {
        self.entries.get(id)?.parent
    }

    /// How far the node is indented: 0 for camera rays.
    pub fn level(&self, id: NodeId) -> usize {
        self.entries.get(id).map_or(0, |e| e.path.len())
    }

    pub fn has_children(&self, id: NodeId) -> bool {
        self.entries.get(id).is_some_and(|e| !e.children.is_empty())
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
            rows.push(id);
            id = if self.is_open(id) {
                id + 1
            } else {
                self.after_subtree(id)
            };
        }
        rows
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

    /// Selects a node, opening its ancestors so that it is shown.
    pub fn select(&mut self, id: NodeId) {
        if id >= self.entries.len() {
            return;
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
            self.selected = self.entries[id].children[0];
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::glass_pixel_tree;
    use whitted_tracer::RayKind;

    #[test]
    fn nodes_are_numbered_in_pre_order_and_all_open() {
        let view = TreeView::new(glass_pixel_tree());
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

    #[test]
    fn left_closes_then_climbs_and_right_opens_then_descends() {
        let mut view = TreeView::new(glass_pixel_tree());
        let all = view.len();
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
