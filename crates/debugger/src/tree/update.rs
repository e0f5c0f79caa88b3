//! Running a navigation on the picked tree: every key that moves the selection (the tree's
//! own, search, stepping, following, the explanation's jumps) goes through [`with_tree`], so
//! that the selection stays in view and what follows the selected ray starts afresh.

use crate::app::App;
use crate::tree::state::TreeView;

/// Runs `change` on the picked tree, keeps the selection in view, and resets what follows
/// the selected ray (the inspector's scroll, a finding's line) when it moved. What `change`
/// returns is handed back; `None` with a message when no pixel is picked.
pub(crate) fn with_tree<T>(app: &mut App, change: impl FnOnce(&mut TreeView) -> T) -> Option<T> {
    let rows = app.tree_rows();
    let Some(picked) = &mut app.picked else {
        app.set_message("no ray tree yet: move the cursor and press Enter", false);
        return None;
    };
    let before = picked.tree.selected();
    let answer = change(&mut picked.tree);
    picked.tree.keep_selection_in_view(rows);
    if picked.tree.selected() != before {
        app.inspector_scroll = 0;
        app.source_focus = None;
    }
    Some(answer)
}
