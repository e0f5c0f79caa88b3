//! How the keys that follow what matters change the [`App`]: `a` (light rays), `p` (the
//! heaviest child), `[ ] { }` (stepping in the tracer's order); `x` and the explanation's keys
//! are in `explain/update.rs`. Called from [`crate::update::update`]; the tree logic itself
//! is in `tree/state.rs`, `follow/mod.rs` and `stepping.rs`.

use crate::app::App;
use crate::follow;
use crate::stepping;
use crate::tree::update::with_tree;

pub fn toggle_show_all(app: &mut App) {
    let Some(hidden) = with_tree(app, |tree| {
        tree.toggle_show_all();
        tree.light_count()
    }) else {
        return;
    };
    if hidden == 0 {
        app.set_message("no ray here counts for under 1% of the pixel", false);
    }
}

pub fn follow_heaviest(app: &mut App) {
    if with_tree(app, follow::follow_heaviest) == Some(None) {
        app.set_message("the selected ray has no children to follow", false);
    }
}

pub fn step(app: &mut App, forward: bool) {
    let moved = with_tree(app, |tree| stepping::step(tree, forward));
    if moved == Some(false) {
        let end = if forward { "last" } else { "first" };
        app.set_message(format!("this is the {end} ray the tracer traced"), false);
    }
}

pub fn run_to_event(app: &mut App, forward: bool) {
    let Some(found) = with_tree(app, |tree| {
        let found = stepping::run_to_event(tree, forward)?;
        let node = tree.node(found.0)?;
        Some((found, node.kind.name(), node.depth, tree.len()))
    }) else {
        return;
    };
    match found {
        Some(((id, events), kind, depth, rays)) => {
            let names: Vec<&str> = events.iter().map(|e| e.name()).collect();
            app.set_message(
                format!(
                    "{}: {kind} ray, depth {depth} (ray {} of {rays} in trace order)",
                    names.join(", "),
                    id + 1
                ),
                false,
            );
        }
        None => {
            let way = if forward { "after" } else { "before" };
            app.set_message(
                format!(
                    "no event {way} this ray (total internal reflection, max depth, \
                     weight cut-off, blocked shadow ray, self-hit)"
                ),
                false,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::action::Action;
    use crate::app::LoadedScene;
    use crate::test_scene::{picked_app, whitted_scene};
    use crate::update::update;
    use ratatui::layout::Rect;

    #[test]
    fn follow_keys_without_a_tree_say_how_to_get_one() {
        let mut app = App::new(
            "scenes/whitted.scene".into(),
            LoadedScene::new(whitted_scene()),
            Rect::new(0, 0, 120, 40),
            "/tmp/out".into(),
        );
        for action in [
            Action::ToggleShowAll,
            Action::FollowHeaviest,
            Action::Step { forward: true },
            Action::RunToEvent { forward: false },
        ] {
            update(&mut app, action);
            assert!(app.message.as_ref().unwrap().text.contains("Enter"));
        }
    }

    #[test]
    fn run_to_event_says_what_it_found() {
        let mut app = picked_app();
        update(&mut app, Action::RunToEvent { forward: true });
        let text = &app.message.as_ref().unwrap().text;
        assert!(text.contains("in trace order"), "{text}");
        assert_ne!(app.picked.as_ref().unwrap().tree.selected(), 0);
        update(&mut app, Action::RunToEvent { forward: false });
        update(&mut app, Action::RunToEvent { forward: false });
        assert!(app
            .message
            .as_ref()
            .unwrap()
            .text
            .contains("no event before"));
    }
}
