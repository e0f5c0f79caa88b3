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
    /// `a`: shows the light rays of the tree, or collapses them again.
    ToggleShowAll,
    /// `p`: selects the selected ray's child that brings the most to the pixel.
    FollowHeaviest,
    /// `x`: the inspector's area shows the pixel's explanation, or the inspector again.
    ToggleExplain,
    /// `]` / `[`: the next / previous ray in the order the tracer ran them.
    Step {
        forward: bool,
    },
    /// `}` / `{`: the next / previous ray where something notable happened.
    RunToEvent {
        forward: bool,
    },
    /// Enter in the explanation: goes to the selected entry's ray or source line.
    ExplainGo,
    /// Shows the 3D ray view in the image pane, or the image again.
    ToggleRayView,
    /// Puts the 3D view's camera back at the scene's camera.
    ResetRayView,
    /// The mouse moved with the left button down, to this cell: orbits the 3D view.
    Drag {
        column: u16,
        row: u16,
    },
}

/// The keys `?` lists: (section, keys, what they do). Every binding in
/// [`action_for_key`] appears here.
pub const KEY_HELP: &[(&str, &str, &str)] = &[
    ("Image", "←↑↓→ hjkl", "move the cursor one pixel"),
    ("Image", "Shift+move HJKL", "move the cursor ten pixels"),
    ("Image", "Enter, click", "trace the pixel: its ray tree"),
    ("Image", "+ / -, wheel", "zoom in / out at the cursor"),
    ("Image", "Ctrl/Alt+arrows", "pan the view"),
    ("Image", "f", "fit the image to the pane"),
    ("Image", "o / d", "overlay: rays / deepest level"),
    ("Image", "s", "mark the selected hit point"),
    ("Image", "v", "3D ray view (keys in its title)"),
    ("Ray tree", "↑↓ jk", "previous / next ray"),
    ("Ray tree", "← h", "collapse, or go to the parent"),
    ("Ray tree", "→ l", "expand, or go to the first child"),
    ("Ray tree", "Enter", "expand or collapse"),
    ("Ray tree", "Home End PgUp/Dn", "first / last / page"),
    ("Ray tree", "a  p", "all rays; follow heaviest child"),
    ("Ray tree", "] [  } {", "step, run to event: fwd / back"),
    ("Inspector", "↑↓ PgUp/Dn", "scroll"),
    ("Inspector", "x  Enter", "explain pixel; go to entry"),
    ("Source", "m", "material / object definition"),
    ("Anywhere", "Tab Shift+Tab", "next / previous pane"),
    ("Anywhere", "r  e", "reload; write the tree as JSON"),
    ("Anywhere", "?  q  Esc", "help; quit (Esc: cancel trace)"),
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
        KeyCode::Char('a') => Some(Action::ToggleShowAll),
        KeyCode::Char('p') => Some(Action::FollowHeaviest),
        KeyCode::Char('x') => Some(Action::ToggleExplain),
        KeyCode::Char(']') => Some(Action::Step { forward: true }),
        KeyCode::Char('[') => Some(Action::Step { forward: false }),
        KeyCode::Char('}') => Some(Action::RunToEvent { forward: true }),
        KeyCode::Char('{') => Some(Action::RunToEvent { forward: false }),
        KeyCode::Char('v') => Some(Action::ToggleRayView),
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
        KeyCode::Char('0') => return Some(Action::ResetRayView),
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
        KeyCode::Enter => Action::ExplainGo,
        _ => return None,
    })
}

/// The action for a mouse event: left clicks and the wheel; everything else is ignored.
pub fn action_for_mouse(mouse: MouseEvent) -> Option<Action> {
    let (column, row) = (mouse.column, mouse.row);
    match mouse.kind {
        MouseEventKind::Down(MouseButton::Left) => Some(Action::Click { column, row }),
        MouseEventKind::Drag(MouseButton::Left) => Some(Action::Drag { column, row }),
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
    fn follow_keys_work_in_every_pane_and_enter_goes_in_the_inspector() {
        let bindings = [
            ('a', Action::ToggleShowAll),
            ('p', Action::FollowHeaviest),
            ('x', Action::ToggleExplain),
            (']', Action::Step { forward: true }),
            ('[', Action::Step { forward: false }),
            ('}', Action::RunToEvent { forward: true }),
            ('{', Action::RunToEvent { forward: false }),
        ];
        for focus in [Focus::Image, Focus::Tree, Focus::Inspector] {
            for (c, action) in bindings {
                assert_eq!(
                    action_for_key(key(KeyCode::Char(c)), focus, false),
                    Some(action)
                );
            }
        }
        assert_eq!(
            action_for_key(key(KeyCode::Enter), Focus::Inspector, false),
            Some(Action::ExplainGo)
        );
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

    #[test]
    fn v_shows_the_3d_view_0_resets_it_and_left_drags_orbit_it() {
        assert_eq!(
            action_for_key(key(KeyCode::Char('v')), Focus::Tree, false),
            Some(Action::ToggleRayView)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char('0')), Focus::Image, false),
            Some(Action::ResetRayView)
        );
        let drag = MouseEvent {
            kind: MouseEventKind::Drag(MouseButton::Left),
            column: 7,
            row: 2,
            modifiers: KeyModifiers::NONE,
        };
        assert_eq!(
            action_for_mouse(drag),
            Some(Action::Drag { column: 7, row: 2 })
        );
    }
}
