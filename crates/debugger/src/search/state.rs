//! `/` search over the picked pixel's ray tree: which rays match a query (by ray kind, the
//! object hit and its material, the light a shadow ray goes to and what blocks it), and
//! stepping through the matches with `n` / `N`.

use whitted_tracer::ray_tree::RayNode;

use crate::tree::state::{NodeId, TreeView};

/// A submitted search: the query, its matches in pre-order, and the one shown.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Search {
    pub query: String,
    pub matches: Vec<NodeId>,
    pub current: usize,
}

impl Search {
    /// Runs `query` over `tree` (case-insensitive, words in any place of a ray's text).
    pub fn new(query: &str, tree: &TreeView) -> Search {
        Search {
            query: query.to_string(),
            matches: matching_rays(tree, query),
            current: 0,
        }
    }

    /// The match shown now, if any.
    pub fn current_match(&self) -> Option<NodeId> {
        self.matches.get(self.current).copied()
    }

    /// Steps to the next (`forward`) or previous match, wrapping around.
    pub fn step(&mut self, forward: bool) -> Option<NodeId> {
        let count = self.matches.len();
        if count == 0 {
            return None;
        }
        self.current = if forward {
            (self.current + 1) % count
        } else {
            (self.current + count - 1) % count
        };
        self.current_match()
    }

    /// What the status line says: "match 2 of 5 for `glass`" or "no ray matches `foo`".
    pub fn describe(&self) -> String {
        match self.matches.len() {
            0 => format!("no ray matches `{}`", self.query),
            count => format!(
                "match {} of {count} for `{}` (n / N: next / previous)",
                self.current + 1,
                self.query
            ),
        }
    }
}

/// The text a ray is found by: its kind, what it hit (object, CSG leaf, material), and for a
/// shadow ray its light and blocker; "miss" for a ray that left the scene.
fn searchable_text(node: &RayNode) -> String {
    let mut words = vec![node.kind.name().to_string()];
    match &node.hit {
        Some(hit) => {
            words.push(hit.object.label.clone());
            words.push(hit.leaf.label.clone());
            words.push(hit.material.label.clone());
        }
        None if node.shadow.is_none() => words.push("miss background".to_string()),
        None => {}
    }
    if let Some(shadow) = &node.shadow {
        words.push(shadow.light.label.clone());
        if let Some(blocker) = &shadow.blocker {
            words.push(blocker.object.label.clone());
        }
    }
    words.join(" ").to_lowercase()
}

/// The rays whose text contains `query` (ignoring case and surrounding blanks), in
/// pre-order; none for an empty query.
pub fn matching_rays(tree: &TreeView, query: &str) -> Vec<NodeId> {
    let query = query.trim().to_lowercase();
    if query.is_empty() {
        return Vec::new();
    }
    (0..tree.len())
        .filter(|&id| {
            tree.node(id)
                .is_some_and(|node| searchable_text(node).contains(&query))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::glass_pixel_tree;
    use whitted_tracer::RayKind;

    #[test]
    fn rays_are_found_by_kind_and_by_object_name_ignoring_case() {
        let tree = TreeView::new(glass_pixel_tree());
        let transmitted = matching_rays(&tree, "Transmitted");
        assert!(!transmitted.is_empty());
        assert!(transmitted
            .iter()
            .all(|&id| tree.node(id).unwrap().kind == RayKind::Transmitted));
        let count = (0..tree.len())
            .filter(|&id| tree.node(id).unwrap().kind == RayKind::Transmitted)
            .count();
        assert_eq!(transmitted.len(), count);
        // The camera ray hits the glass sphere: the first match, in pre-order.
        assert_eq!(matching_rays(&tree, " glass SPHERE ").first(), Some(&0));
        assert!(!matching_rays(&tree, "floor").is_empty());
        assert!(matching_rays(&tree, "no such thing").is_empty());
        assert!(matching_rays(&tree, "  ").is_empty());
    }

    #[test]
    fn stepping_wraps_and_the_description_counts() {
        let tree = TreeView::new(glass_pixel_tree());
        let mut search = Search::new("shadow", &tree);
        let count = search.matches.len();
        assert!(count > 2, "{count}");
        assert!(search
            .describe()
            .starts_with(&format!("match 1 of {count}")));
        let first = search.current_match();
        assert_eq!(search.step(false), search.matches.last().copied());
        assert_eq!(search.step(true), first);
        search.step(true);
        assert!(search
            .describe()
            .starts_with(&format!("match 2 of {count}")));
        let none = Search::new("foo", &tree);
        assert_eq!(none.describe(), "no ray matches `foo`");
        assert_eq!(none.clone().step(true), None);
    }
}
