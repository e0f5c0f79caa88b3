//! What `/` and `n` / `N` do to the [`App`]: the prompt on the status line, the search run
//! when Enter submits it, and stepping through its matches. Called from
//! [`crate::update::update`].

use ratatui::crossterm::event::KeyEvent;

use crate::action::Focus;
use crate::app::App;
use crate::line_input::{InputOutcome, LineInput};
use crate::search::state::Search;
use crate::tree::update::with_tree;

/// `/`: opens the prompt, when there is a tree to search.
pub(crate) fn start(app: &mut App) {
    if app.picked.is_some() {
        app.search_prompt = Some(LineInput::new(""));
    } else {
        app.set_message(
            "no ray tree to search: move the cursor and press Enter",
            false,
        );
    }
}

/// A key for the `/` prompt: editing keys edit, Enter searches, Esc closes it.
pub(crate) fn prompt_key(app: &mut App, key: KeyEvent) {
    let Some(prompt) = &mut app.search_prompt else {
        return;
    };
    match prompt.handle(key) {
        InputOutcome::Edited | InputOutcome::Ignored => {}
        InputOutcome::Cancelled => app.search_prompt = None,
        InputOutcome::Submitted => {
            let query = prompt.text().trim().to_string();
            app.search_prompt = None;
            if query.is_empty() {
                return;
            }
            let Some(picked) = &app.picked else {
                return;
            };
            let search = Search::new(&query, &picked.tree);
            app.set_message(search.describe(), false);
            if let Some(id) = search.current_match() {
                select_ray(app, id);
                // The match is a tree row: n / N step from there.
                app.focus = Focus::Tree;
            }
            app.search = Some(search);
        }
    }
}

/// `n` / `N`: the next or previous ray matching the last search.
pub(crate) fn step(app: &mut App, forward: bool) {
    let Some(search) = &mut app.search else {
        app.set_message("no search yet: / searches the ray tree", false);
        return;
    };
    let target = search.step(forward);
    let description = search.describe();
    app.set_message(description, false);
    if let Some(id) = target {
        select_ray(app, id);
    }
}

/// Selects a ray of the picked tree (opening its ancestors) and shows it.
fn select_ray(app: &mut App, id: crate::tree::state::NodeId) {
    with_tree(app, |t| t.select(id));
}
