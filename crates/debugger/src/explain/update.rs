//! How `x` and, in the explanation, ↑↓ and Enter change the [`App`]: the explanation in
//! the inspector's place, its selected entry, and going to an entry's ray or line. Called
//! from [`crate::update::update`].

use crate::action::Focus;
use crate::app::App;
use crate::explain::state::{self as explain_view, Jump};
use crate::tree::update::with_tree;

/// `x`: the explanation in the inspector's place, with the keyboard (as `v` gives it to the
/// 3D view), so that the keys that follow (`z`, ↑↓, Enter) act on what was just opened and
/// not on the pane that had the focus before; `x` again brings the inspector back.
pub fn toggle_explain(app: &mut App) {
    app.explain_open = !app.explain_open;
    if app.explain_open {
        app.focus = Focus::Inspector;
    }
    if app.explain_open && app.picked.is_none() {
        app.set_message("pick a pixel (Enter) to explain it", false);
    }
}

/// ↑↓ in the explanation: moves the selected entry (`i32::MIN`, Home, to the first).
pub fn move_explain_selection(app: &mut App, lines: i32) {
    let count = app
        .picked
        .as_ref()
        .and_then(|p| p.explanation.ready())
        .map_or(0, |e| explain_view::entries(e).len());
    app.explain_selected = if lines == i32::MIN || count == 0 {
        0
    } else {
        let moved = app.explain_selected as i64 + i64::from(lines);
        moved.clamp(0, count as i64 - 1) as usize
    };
}

/// Enter in the explanation: selects the entry's ray in the tree (and gives the tree the
/// keyboard), or shows a finding's line in the source pane.
pub fn go(app: &mut App) {
    if !app.explain_open {
        return;
    }
    let jump = {
        let Some(picked) = &app.picked else {
            return;
        };
        let Some(explanation) = picked.explanation.ready() else {
            return;
        };
        let entries = explain_view::entries(explanation);
        let Some(&entry) = entries.get(app.explain_selected) else {
            return;
        };
        explain_view::jump(entry, &picked.tree, &app.loaded.scene.sources)
    };
    match jump {
        Jump::Ray(id) => {
            with_tree(app, |tree| tree.select(id));
            app.focus = Focus::Tree;
        }
        Jump::Source { span, what } => app.source_focus = Some((span, what)),
        Jump::Nowhere(why) => app.set_message(why, false),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::action::Action;

    use crate::test_scene::{finish_trace, picked_app, GLASS_PIXEL};
    use crate::update::update;

    #[test]
    fn the_trace_worker_explains_the_tree_it_recorded() {
        let app = picked_app();
        let picked = app.picked.as_ref().unwrap();
        let explanation = picked.explanation.ready().expect("an explanation");
        assert_eq!(explanation.pixel, picked.tree.tree().pixel);
        assert_eq!(explanation.color, picked.tree.tree().color);
        // The same as the explain command's, which traces the pixel itself.
        let f = crate::test_scene::fixture();
        let cli = whitted_explain::explain(
            &f.prepared,
            &f.scene,
            &f.options,
            GLASS_PIXEL.0,
            GLASS_PIXEL.1,
        )
        .unwrap();
        assert_eq!(&cli, explanation);
    }

    #[test]
    fn an_explanation_is_kept_only_for_the_tree_it_explains() {
        let mut app = picked_app();
        let job_of = |app: &mut App| {
            app.trace_cursor();
            app.trace_job().unwrap()
        };
        // A late explanation of an earlier trace is dropped.
        let old = job_of(&mut app);
        let old_tree = old.run().result.unwrap().0;
        app.trace_cursor();
        finish_trace(&mut app);
        let current = app.picked.as_ref().unwrap().generation;
        assert_ne!(old.generation, current);
        let before = app.picked.as_ref().unwrap().explanation.clone();
        let mut late = old.explain(&old_tree);
        if let Ok(explanation) = &mut late.result {
            explanation.findings.clear();
        }
        app.apply_explained(late);
        assert_eq!(app.picked.as_ref().unwrap().explanation, before);
        // Until its explanation arrives a new tree says it is being worked out.
        let job = job_of(&mut app);
        let traced = job.run();
        app.apply_trace(traced);
        assert_eq!(
            app.picked.as_ref().unwrap().explanation,
            crate::app::ExplanationState::Working
        );
        app.apply_explained(crate::trace_job::Explained {
            generation: job.generation,
            result: Err("boom".into()),
        });
        assert_eq!(
            app.picked.as_ref().unwrap().explanation,
            crate::app::ExplanationState::Failed("boom".into())
        );
    }

    #[test]
    fn enter_on_a_contribution_selects_its_ray_and_on_a_finding_shows_its_line() {
        let mut app = picked_app();
        update(&mut app, Action::ToggleExplain);
        assert!(app.explain_open);
        assert_eq!(app.focus, Focus::Inspector, "x gives it the keyboard");
        let picked = app.picked.as_ref().unwrap();
        let explanation = picked.explanation.ready().unwrap().clone();
        // The second contribution (the first is usually the camera ray's own light).
        let second = &explanation.contributions[1];
        update(&mut app, Action::InspectorScroll(1));
        assert_eq!(app.explain_selected, 1);
        update(&mut app, Action::ExplainGo);
        assert_eq!(app.focus, Focus::Tree);
        let tree = &app.picked.as_ref().unwrap().tree;
        assert_eq!(
            Some(tree.selected()),
            explain_view::contribution_ray(tree, second)
        );
        assert_ne!(tree.selected(), 0);

        let Some(finding) = explanation.findings.first() else {
            panic!("the glass pixel has findings: {explanation:#?}");
        };
        app.focus = Focus::Inspector;
        update(&mut app, Action::InspectorScroll(i32::MIN));
        update(
            &mut app,
            Action::InspectorScroll(explanation.contributions.len() as i32),
        );
        update(&mut app, Action::ExplainGo);
        let (span, what) = app.source_focus.clone().expect("the finding's line");
        assert_eq!(app.loaded.scene.sources.location(span), finding.location);
        assert!(what.contains(finding.kind.name()));
        // Moving in the tree shows the ray's definition again.
        update(&mut app, Action::Step { forward: true });
        assert_eq!(app.source_focus, None);
        // The selection stops at the last entry.
        update(&mut app, Action::InspectorScroll(1000));
        assert_eq!(
            app.explain_selected,
            explanation.contributions.len() + explanation.findings.len() - 1
        );
    }
}
