//! What the user asked for, independent of how: the pure map from keys and mouse events to
//! [`Action`]s, and the key list that `?` shows (kept beside the map so they agree).

use ratatui::crossterm::event::{
    KeyCode, KeyEvent, KeyEventKind, KeyModifiers, MouseButton, MouseEvent, MouseEventKind,
};

use crate::heat_map::HeatMapKind;

/// The pane that arrow keys act on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Focus {
    Image,
    Tree,
    Inspector,
}

impl Focus {
    pub fn next(self) -> Focus {
        match self {
            Focus::Image => Focus::Tree,
            Focus::Tree => Focus::Inspector,
            Focus::Inspector => Focus::Image,
        }
    }

    pub fn previous(self) -> Focus {
        match self {
            Focus::Image => Focus::Inspector,
            Focus::Tree => Focus::Image,
            Focus::Inspector => Focus::Tree,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Quit,
    /// Esc: cancels the trace under way, or quits when there is none.
    Cancel,
    ToggleHelp,
    /// Moves the image cursor by pixels.
    MoveCursor {
        dx: i32,
        dy: i32,
    },
    /// Records the ray tree of the pixel under the cursor.
    TraceCursor,
    /// A mouse click at a terminal cell: picks a pixel or a tree row.
    Click {
        column: u16,
        row: u16,
    },
    /// The mouse wheel at a terminal cell: zooms the image or scrolls a pane.
    Wheel {
        column: u16,
        row: u16,
        lines: i32,
    },
    ZoomIn,
    ZoomOut,
    /// Moves the view by terminal cells.
    Pan {
        columns: i32,
        rows: i32,
    },
    Fit,
    FocusNext,
    FocusPrevious,
    TreeUp,
    TreeDown,
    /// Collapses the selected ray, or goes to its parent.
    TreeLeft,
    /// Expands the selected ray, or goes to its first child.
    TreeRight,
    TreeFirst,
    TreeLast,
    TreePage(i32),
    TreeToggle,
    InspectorScroll(i32),
    ToggleOverlay(HeatMapKind),
    ToggleHitPoint,
    /// Shows the material's definition in the source pane instead of the object's, or back.
    ToggleSourceTarget,
    Reload,
    Export,
    /// Opens the what-if popup on the picked pixel.
    WhatIf,
    /// Opens the query prompt on the status line.
    QueryPrompt,
    /// A key for the open popup or prompt (it takes every key).
    InputKey(KeyEvent),
    /// Moves the cursor to the next (or previous) pixel the query matched, and traces it.
    NextMatch,
    PreviousMatch,
}

/// The keys `?` lists: (section, keys, what they do). Every binding in
/// [`action_for_key`] appears here.
pub const KEY_HELP: &[(&str, &str, &str)] = &[
    ("Image", "←↑↓→ hjkl", "move the cursor one pixel"),
    ("Image", "Shift+move HJKL", "move the cursor ten pixels"),
    ("Image", "Enter, click", "trace the pixel: its ray tree"),
    ("Image", "+ - f, wheel", "zoom in / out; f: fit the pane"),
    ("Image", "Ctrl/Alt+arrows", "pan the view"),
    ("Image", "o / d", "overlay: rays / deepest level"),
    ("Image", "n / N", "next / previous query match"),
    ("Image", "s", "mark the selected hit point"),
    ("Ray tree", "↑↓ jk", "previous / next ray"),
    ("Ray tree", "← h / → l", "collapse or parent / expand"),
    ("Ray tree", "Enter", "expand or collapse"),
    ("Ray tree", "Home End PgUp/Dn", "first / last / page"),
    ("Inspector", "↑↓ PgUp/Dn", "scroll"),
    ("Source", "m", "material / object definition"),
    ("Anywhere", "Tab Shift+Tab", "next / previous pane"),
    ("Anywhere", "r", "reload (automatic on save)"),
    ("Anywhere", "e", "write the ray tree as JSON"),
    ("Anywhere", "w", "what-if: change a value"),
    ("Anywhere", ":", "query: mark matching pixels"),
    ("Anywhere", "?", "this help"),
    ("Anywhere", "q, Esc", "quit (Esc: cancel a trace)"),
];

/// The action for a key, given which pane has focus and whether the help is open (then any
/// key closes it).
pub fn action_for_key(key: KeyEvent, focus: Focus, help_open: bool) -> Option<Action> {
    if key.kind == KeyEventKind::Release {
        return None;
    }
    let control = key.modifiers.contains(KeyModifiers::CONTROL);
    let alt = key.modifiers.contains(KeyModifiers::ALT);
    let shift = key.modifiers.contains(KeyModifiers::SHIFT);
    if control && matches!(key.code, KeyCode::Char('c' | 'C')) {
        return Some(Action::Quit);
    }
    if help_open {
        return Some(Action::ToggleHelp);
    }
    if control || alt {
        return pan_for(key.code);
    }
    let global = match key.code {
        KeyCode::Char('q') => Some(Action::Quit),
        KeyCode::Esc => Some(Action::Cancel),
        KeyCode::Char('?') => Some(Action::ToggleHelp),
        KeyCode::Tab => Some(Action::FocusNext),
        KeyCode::BackTab => Some(Action::FocusPrevious),
        KeyCode::Char('r') => Some(Action::Reload),
        KeyCode::Char('e') => Some(Action::Export),
        KeyCode::Char('o') => Some(Action::ToggleOverlay(HeatMapKind::RaysPerPixel)),
        KeyCode::Char('d') => Some(Action::ToggleOverlay(HeatMapKind::DeepestLevel)),
        KeyCode::Char('s') => Some(Action::ToggleHitPoint),
        KeyCode::Char('m') => Some(Action::ToggleSourceTarget),
        KeyCode::Char('+' | '=') => Some(Action::ZoomIn),
        KeyCode::Char('-' | '_') => Some(Action::ZoomOut),
        KeyCode::Char('f') => Some(Action::Fit),
        KeyCode::Char('w') => Some(Action::WhatIf),
        KeyCode::Char(':') => Some(Action::QueryPrompt),
        _ => None,
    };
    if global.is_some() {
        return global;
    }
    match focus {
        Focus::Image => image_key(key.code, shift),
        Focus::Tree => tree_key(key.code),
        Focus::Inspector => inspector_key(key.code),
    }
}

fn pan_for(code: KeyCode) -> Option<Action> {
    let (columns, rows) = match code {
        KeyCode::Left | KeyCode::Char('h') => (-4, 0),
        KeyCode::Right | KeyCode::Char('l') => (4, 0),
        KeyCode::Up | KeyCode::Char('k') => (0, -2),
        KeyCode::Down | KeyCode::Char('j') => (0, 2),
        _ => return None,
    };
    Some(Action::Pan { columns, rows })
}

fn image_key(code: KeyCode, shift: bool) -> Option<Action> {
    let step = if shift { 10 } else { 1 };
    let (dx, dy) = match code {
        KeyCode::Left | KeyCode::Char('h') => (-step, 0),
        KeyCode::Right | KeyCode::Char('l') => (step, 0),
        KeyCode::Up | KeyCode::Char('k') => (0, -step),
        KeyCode::Down | KeyCode::Char('j') => (0, step),
        // Shift+h arrives as 'H' (with or without the SHIFT flag, depending on the terminal).
        KeyCode::Char('H') => (-10, 0),
        KeyCode::Char('L') => (10, 0),
        KeyCode::Char('K') => (0, -10),
        KeyCode::Char('J') => (0, 10),
        KeyCode::Enter => return Some(Action::TraceCursor),
        KeyCode::Char('n') => return Some(Action::NextMatch),
        KeyCode::Char('N') => return Some(Action::PreviousMatch),
        _ => return None,
    };
    Some(Action::MoveCursor { dx, dy })
}

fn tree_key(code: KeyCode) -> Option<Action> {
    Some(match code {
        KeyCode::Up | KeyCode::Char('k' | 'K') => Action::TreeUp,
        KeyCode::Down | KeyCode::Char('j' | 'J') => Action::TreeDown,
        KeyCode::Left | KeyCode::Char('h' | 'H') => Action::TreeLeft,
        KeyCode::Right | KeyCode::Char('l' | 'L') => Action::TreeRight,
        KeyCode::Home => Action::TreeFirst,
        KeyCode::End => Action::TreeLast,
        KeyCode::PageUp => Action::TreePage(-10),
        KeyCode::PageDown => Action::TreePage(10),
        KeyCode::Enter | KeyCode::Char(' ') => Action::TreeToggle,
        _ => return None,
    })
}

fn inspector_key(code: KeyCode) -> Option<Action> {
    Some(match code {
        KeyCode::Up | KeyCode::Char('k') => Action::InspectorScroll(-1),
        KeyCode::Down | KeyCode::Char('j') => Action::InspectorScroll(1),
        KeyCode::PageUp => Action::InspectorScroll(-10),
        KeyCode::PageDown => Action::InspectorScroll(10),
        KeyCode::Home => Action::InspectorScroll(i32::MIN),
        _ => return None,
    })
}

/// The action for a key while a popup or prompt is open: it takes every key (Ctrl+C still
/// quits).
pub fn input_action(key: KeyEvent) -> Option<Action> {
    if key.kind == KeyEventKind::Release {
        return None;
    }
    if key.modifiers.contains(KeyModifiers::CONTROL) && matches!(key.code, KeyCode::Char('c' | 'C'))
    {
        return Some(Action::Quit);
    }
    Some(Action::InputKey(key))
}

/// The action for a mouse event: left clicks and the wheel; everything else is ignored.
pub fn action_for_mouse(mouse: MouseEvent) -> Option<Action> {
    let (column, row) = (mouse.column, mouse.row);
    match mouse.kind {
        MouseEventKind::Down(MouseButton::Left) => Some(Action::Click { column, row }),
        MouseEventKind::ScrollUp => Some(Action::Wheel {
            column,
            row,
            lines: -1,
        }),
        MouseEventKind::ScrollDown => Some(Action::Wheel {
            column,
            row,
            lines: 1,
        }),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(code: KeyCode) -> KeyEvent {
        KeyEvent::new(code, KeyModifiers::NONE)
    }

    fn shifted(code: KeyCode) -> KeyEvent {
        KeyEvent::new(code, KeyModifiers::SHIFT)
    }

    #[test]
    fn arrows_move_the_cursor_in_the_image_and_the_selection_in_the_tree() {
        let right = key(KeyCode::Right);
        assert_eq!(
            action_for_key(right, Focus::Image, false),
            Some(Action::MoveCursor { dx: 1, dy: 0 })
        );
        assert_eq!(
            action_for_key(shifted(KeyCode::Up), Focus::Image, false),
            Some(Action::MoveCursor { dx: 0, dy: -10 })
        );
        assert_eq!(
            action_for_key(shifted(KeyCode::Char('J')), Focus::Image, false),
            Some(Action::MoveCursor { dx: 0, dy: 10 })
        );
        assert_eq!(
            action_for_key(right, Focus::Tree, false),
            Some(Action::TreeRight)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char('k')), Focus::Tree, false),
            Some(Action::TreeUp)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Down), Focus::Inspector, false),
            Some(Action::InspectorScroll(1))
        );
    }

    #[test]
    fn global_keys_work_in_every_pane() {
        for focus in [Focus::Image, Focus::Tree, Focus::Inspector] {
            assert_eq!(
                action_for_key(key(KeyCode::Char('q')), focus, false),
                Some(Action::Quit)
            );
            assert_eq!(
                action_for_key(key(KeyCode::Esc), focus, false),
                Some(Action::Cancel)
            );
            assert_eq!(
                action_for_key(key(KeyCode::Char('e')), focus, false),
                Some(Action::Export)
            );
            assert_eq!(
                action_for_key(key(KeyCode::Tab), focus, false),
                Some(Action::FocusNext)
            );
            assert_eq!(
                action_for_key(
                    KeyEvent::new(KeyCode::Left, KeyModifiers::CONTROL),
                    focus,
                    false
                ),
                Some(Action::Pan {
                    columns: -4,
                    rows: 0
                })
            );
        }
    }

    #[test]
    fn with_help_open_any_key_closes_it_but_ctrl_c_still_quits() {
        assert_eq!(
            action_for_key(key(KeyCode::Char('x')), Focus::Image, true),
            Some(Action::ToggleHelp)
        );
        assert_eq!(
            action_for_key(
                KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL),
                Focus::Image,
                true
            ),
            Some(Action::Quit)
        );
    }

    #[test]
    fn key_releases_and_unbound_keys_do_nothing() {
        let mut release = key(KeyCode::Char('q'));
        release.kind = KeyEventKind::Release;
        assert_eq!(action_for_key(release, Focus::Image, false), None);
        assert_eq!(
            action_for_key(key(KeyCode::Char('z')), Focus::Image, false),
            None
        );
    }

    #[test]
    fn what_if_query_and_match_keys() {
        assert_eq!(
            action_for_key(key(KeyCode::Char('w')), Focus::Tree, false),
            Some(Action::WhatIf)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char(':')), Focus::Inspector, false),
            Some(Action::QueryPrompt)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char('n')), Focus::Image, false),
            Some(Action::NextMatch)
        );
        assert_eq!(
            action_for_key(shifted(KeyCode::Char('N')), Focus::Image, false),
            Some(Action::PreviousMatch)
        );
        // An open popup or prompt takes every key, `q` included; Ctrl+C still quits.
        let q = key(KeyCode::Char('q'));
        assert_eq!(input_action(q), Some(Action::InputKey(q)));
        assert_eq!(
            input_action(KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL)),
            Some(Action::Quit)
        );
    }

    #[test]
    fn clicks_and_the_wheel_become_actions() {
        let mouse = |kind| MouseEvent {
            kind,
            column: 3,
            row: 4,
            modifiers: KeyModifiers::NONE,
        };
        assert_eq!(
            action_for_mouse(mouse(MouseEventKind::Down(MouseButton::Left))),
            Some(Action::Click { column: 3, row: 4 })
        );
        assert_eq!(
            action_for_mouse(mouse(MouseEventKind::ScrollDown)),
            Some(Action::Wheel {
                column: 3,
                row: 4,
                lines: 1
            })
        );
        assert_eq!(action_for_mouse(mouse(MouseEventKind::Moved)), None);
    }
}
