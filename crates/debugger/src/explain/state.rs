//! The explanation pane's state and its jumps (`x`): the picked pixel's explanation (from
//! `whitted_explain`, computed on the trace worker from the very tree the debugger shows) as
//! a list of entries, contributions then findings; Enter on a contribution selects its ray
//! in the tree, on a finding shows its line in the source pane.

use whitted_explain::{Contribution, Explanation, Finding, Term};
use whitted_ir::{SourceMap, Span};
use whitted_tracer::RayKind;

use crate::tree::state::{NodeId, TreeView};

/// One selectable line of the pane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Entry<'e> {
    Contribution(&'e Contribution),
    Finding(&'e Finding),
}

/// The entries in the order shown: contributions (largest first), then findings.
pub fn entries(explanation: &Explanation) -> Vec<Entry<'_>> {
    explanation
        .contributions
        .iter()
        .map(Entry::Contribution)
        .chain(explanation.findings.iter().map(Entry::Finding))
        .collect()
}

/// Where Enter on an entry goes.
#[derive(Clone, Debug, PartialEq)]
pub enum Jump {
    /// The ray where the contribution's light arises (for a light's term, that light's
    /// shadow ray when one was cast).
    Ray(NodeId),
    /// A finding's line (or a contribution whose path ends nowhere recorded): the span to
    /// show in the source pane and what to call it.
    Source { span: Span, what: String },
    /// Nothing to go to, and why.
    Nowhere(String),
}

pub fn jump(entry: Entry<'_>, view: &TreeView, sources: &SourceMap) -> Jump {
    match entry {
        Entry::Contribution(contribution) => match contribution_ray(view, contribution) {
            Some(id) => Jump::Ray(id),
            None => Jump::Nowhere(match contribution.term {
                Term::Other => "this line adds up the smaller paths: it has no single ray".into(),
                Term::Unrecorded => "these rays were traced but not recorded".into(),
                _ => "this path is not in the recorded tree".into(),
            }),
        },
        Entry::Finding(finding) => match location_span(sources, &finding.location) {
            Some(span) => Jump::Source {
                span,
                what: format!("finding {}", finding.kind.name()),
            },
            None => Jump::Nowhere(format!("{} is not in a scene file", finding.location)),
        },
    }
}

/// The ray a contribution's path ends at: in the first sample that has the path, from its
/// camera ray down the children of each step's kind (repeated steps repeated), checking
/// what each ray hit. A light's term goes on to that light's shadow ray, when one was cast.
pub fn contribution_ray(view: &TreeView, contribution: &Contribution) -> Option<NodeId> {
    if contribution.path.is_empty() {
        return None;
    }
    let roots = (0..view.len()).filter(|&id| view.parent(id).is_none());
    let end = roots
        .into_iter()
        .find_map(|root| follow_path(view, root, contribution))?;
    let light = match contribution.term {
        Term::Diffuse | Term::Specular => contribution.light.as_deref(),
        _ => None,
    };
    let shadow = light.and_then(|light| {
        view.children(end).iter().copied().find(|&child| {
            view.node(child)
                .and_then(|n| n.shadow.as_ref())
                .is_some_and(|s| s.light.label == light)
        })
    });
    Some(shadow.unwrap_or(end))
}

fn follow_path(view: &TreeView, root: NodeId, contribution: &Contribution) -> Option<NodeId> {
    let mut at: Option<NodeId> = None;
    for step in &contribution.path {
        for _ in 0..step.repeat.max(1) {
            let next = match at {
                None => Some(root).filter(|_| step.ray == RayKind::Camera),
                Some(id) => view
                    .children(id)
                    .iter()
                    .copied()
                    .find(|&child| view.node(child).is_some_and(|n| n.kind == step.ray)),
            }?;
            let node = view.node(next)?;
            let object = node.hit.as_ref().map(|h| h.object.label.as_str());
            if object != step.object.as_deref() {
                return None;
            }
            at = Some(next);
        }
    }
    at
}

/// The span of a `file:line:col` location: from the column to the end of that line.
pub fn location_span(sources: &SourceMap, location: &str) -> Option<Span> {
    let mut parts = location.rsplitn(3, ':');
    let column: usize = parts.next()?.parse().ok()?;
    let line: usize = parts.next()?.parse().ok()?;
    let path = parts.next()?;
    let (id, file) = sources.files().find(|(_, f)| f.path == path)?;
    let mut start = 0;
    for (number, text) in file.text.split_inclusive('\n').enumerate() {
        if number + 1 == line {
            let body = text.trim_end_matches(['\n', '\r']);
            let from = body
                .char_indices()
                .nth(column.saturating_sub(1))
                .map_or(body.len(), |(at, _)| at);
            return Some(Span::new(id, start + from, start + body.len()));
        }
        start += text.len();
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::{fixture, glass_pixel_tree};
    use whitted_ir::SourceFile;

    fn explained() -> (TreeView, Explanation) {
        let f = fixture();
        let tree = glass_pixel_tree();
        let explanation = whitted_explain::explain_tree(&f.prepared, &f.scene, &f.options, &tree);
        (TreeView::new(tree), explanation)
    }

    #[test]
    fn every_path_contribution_jumps_to_a_ray_that_ends_its_path() {
        let (view, explanation) = explained();
        let f = fixture();
        let with_paths: Vec<&Contribution> = explanation
            .contributions
            .iter()
            .filter(|c| !c.path.is_empty())
            .collect();
        assert!(with_paths.len() >= 2, "{explanation:#?}");
        for contribution in with_paths {
            let Jump::Ray(id) = jump(Entry::Contribution(contribution), &view, &f.scene.sources)
            else {
                panic!("no ray for {contribution:?}");
            };
            let node = view.node(id).unwrap();
            // The ray (or, for a light's term, its parent) is as deep as the path is long.
            let steps: u32 = contribution.path.iter().map(|s| s.repeat).sum();
            // A light's term is that light's shadow ray, whenever one was cast.
            if matches!(contribution.term, Term::Diffuse | Term::Specular) {
                assert_eq!(node.kind, RayKind::Shadow, "{contribution:?}");
            }
            let surface = if node.kind == RayKind::Shadow {
                assert_eq!(
                    node.shadow.as_ref().map(|s| s.light.label.as_str()),
                    contribution.light.as_deref()
                );
                view.node(view.parent(id).unwrap()).unwrap()
            } else {
                node
            };
            assert_eq!(surface.depth + 1, steps, "{contribution:?}");
            let last = contribution.path.last().unwrap();
            assert_eq!(surface.kind, last.ray);
        }
    }

    #[test]
    fn a_finding_jumps_to_its_line() {
        let mut sources = SourceMap::new();
        let file = sources.add(SourceFile::new(
            "a.scene",
            "one\nsettings { max_depth 5 }\n",
        ));
        let span = location_span(&sources, "a.scene:2:12").unwrap();
        assert_eq!(span, Span::new(file, 15, 28));
        assert_eq!(&sources.get(file).unwrap().text[15..28], "max_depth 5 }");
        assert_eq!(location_span(&sources, "b.scene:2:1"), None);
        assert_eq!(location_span(&sources, "a.scene:9:1"), None);
        assert_eq!(location_span(&sources, "nonsense"), None);
    }
}
