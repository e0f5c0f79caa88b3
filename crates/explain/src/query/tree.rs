//! The query on a recorded ray tree: the same predicates read off `RayNode`s instead of the
//! tracer's hooks. Tests hold `run` (the streaming recorder) to this, pixel by pixel.

use whitted_tracer::ray_tree::{RayNode, RayTree, ShadowOutcome};
use whitted_tracer::{RayKind, Termination};

use super::watch::{finite, tiny};
use super::{Observed, Query, Test};

/// The predicates' bits and the deepest ray of every sample of `tree`.
pub(crate) fn observe(query: &Query, tree: &RayTree) -> Observed {
    let mut observed = Observed::default();
    let set = |test: &dyn Fn(&Test) -> bool, bits: &mut u64| {
        for (i, atom) in query.atoms.iter().enumerate() {
            if test(atom) {
                *bits |= 1 << i;
            }
        }
    };
    let mut stack: Vec<(&RayNode, Option<&RayNode>)> =
        tree.samples.iter().rev().map(|s| (&s.root, None)).collect();
    while let Some((node, parent)) = stack.pop() {
        let bits = &mut observed.bits;
        let from = parent.and_then(|p| p.hit.as_ref());
        if node.kind == RayKind::Shadow {
            if let Some(shadow) = &node.shadow {
                if shadow.result == ShadowOutcome::Blocked {
                    if let Some(blocker) = &shadow.blocker {
                        let (object, leaf) = (blocker.object.handle, blocker.leaf.handle);
                        let transparent = query.is_transparent(leaf);
                        set(
                            &|t| match t {
                                Test::ShadowBlocked => true,
                                Test::ShadowBlockedBy(s) => {
                                    s.contains(&object) || s.contains(&leaf)
                                }
                                Test::ShadowBlockedByTransparent => transparent,
                                _ => false,
                            },
                            bits,
                        );
                        if from
                            .is_some_and(|f| f.object.handle == object && tiny(blocker.t, f.point))
                        {
                            set(&|t| *t == Test::SelfHit, bits);
                        }
                    }
                }
            }
            continue;
        }
        observed.deepest = observed.deepest.max(node.depth);
        if node
            .interface
            .as_ref()
            .is_some_and(|i| i.total_internal_reflection)
        {
            set(&|t| *t == Test::Tir, bits);
        }
        if !finite(node.color) {
            set(&|t| *t == Test::Nan, bits);
        }
        if let Some(hit) = &node.hit {
            let (object, leaf) = (hit.object.handle, hit.leaf.handle);
            set(
                &|t| matches!(t, Test::Hit(s) if s.contains(&object) || s.contains(&leaf)),
                bits,
            );
            if from.is_some_and(|f| f.object.handle == object && tiny(hit.t, f.point)) {
                set(&|t| *t == Test::SelfHit, bits);
            }
        }
        for skipped in &node.skipped {
            let wanted = match skipped.reason {
                Termination::MaxDepth => Test::MaxDepth,
                Termination::WeightCutoff => Test::WeightCutoff,
                Termination::TotalInternalReflection => Test::Tir,
                _ => continue,
            };
            set(&|t| *t == wanted, bits);
        }
        for child in node.children.iter().rev() {
            stack.push((child, Some(node)));
        }
    }
    if !finite(tree.color) {
        for (i, atom) in query.atoms.iter().enumerate() {
            if *atom == Test::Nan {
                observed.bits |= 1 << i;
            }
        }
    }
    observed
}
