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
    /// The source pane (or the scene's errors): scrolls, and zooms with `z`.
    Source,
}

impl Focus {
    pub fn next(self) -> Focus {
        match self {
            Focus::Image => Focus::Tree,
            Focus::Tree => Focus::Inspector,
            Focus::Inspector => Focus::Source,
            Focus::Source => Focus::Image,
        }
    }

    pub fn previous(self) -> Focus {
        match self {
            Focus::Image => Focus::Source,
            Focus::Tree => Focus::Image,
            Focus::Inspector => Focus::Tree,
            Focus::Source => Focus::Inspector,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    Quit,
    /// `<` `>`: compiles the previous or next frame of an animated scene.
    StepFrame {
        forward: bool,
    },
    /// Esc: cancels the trace under way, else leaves the zoomed pane, else ends the search.
    /// It never quits (q does).
    Cancel,
    ToggleHelp,
    /// Scrolls the help by lines.
    HelpScroll(i32),
    /// Moves the image cursor by pixels.
    MoveCursor {
        dx: i32,
        dy: i32,
    },
    /// Moves the image cursor by display cells: one column across, one half-block row down.
    MoveCursorByCells {
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
    /// Scrolls the inspector sideways by columns.
    InspectorScrollSideways(i32),
    /// Zooms the focused pane to the whole body, or restores the layout.
    ToggleZoom,
    /// Opens the `/` prompt to search the ray tree.
    StartSearch,
    /// A key for the open prompt.
    PromptKey(KeyEvent),
    /// Selects the next (`forward`) or previous ray matching the search.
    SearchStep {
        forward: bool,
    },
    ToggleOverlay(HeatMapKind),
    ToggleHitPoint,
    /// Shows the material's definition in the source pane instead of the object's, or back.
    ToggleSourceTarget,
    /// Scrolls the source pane by lines and columns from where the definition shows.
    SourceScroll {
        lines: i32,
        columns: i32,
    },
    /// The source pane back at the definition.
    SourceScrollHome,
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
    /// Opens the what-if popup on the picked pixel.
    WhatIf,
    /// Opens the query prompt on the status line.
    QueryPrompt,
    /// Moves the cursor to the next (or previous) pixel the query matched, and traces it.
    NextMatch,
    PreviousMatch,
}

/// The keys `?` lists: (section, keys, what they do). Every binding in
/// [`action_for_key`] appears here.
pub const KEY_HELP: &[(&str, &str, &str)] = &[
    ("Image", "←↑↓→ hjkl", "move the cursor one cell"),
    ("Image", "Shift+move HJKL", "move the cursor one pixel"),
    ("Image", "Enter, click", "trace the pixel: its ray tree"),
    ("Image", "+ / -, wheel", "zoom in / out at the cursor"),
    ("Image", "Ctrl/Alt+arrows", "pan the view"),
    ("Image", "f", "fit the image to the pane"),
    ("Image", "o / d", "overlay: rays / deepest level"),
    ("Image", "n / N", "next / previous query match"),
    ("Image", "s", "mark the selected hit point"),
    ("Image", "v", "3D ray view (keys in its title)"),
    ("Ray tree", "↑↓ jk", "previous / next ray"),
    ("Ray tree", "← h", "collapse, or go to the parent"),
    ("Ray tree", "→ l", "expand, or go to the first child"),
    ("Ray tree", "Enter", "expand or collapse"),
    ("Ray tree", "Home End PgUp/Dn", "first / last / page"),
    ("Ray tree", "n N", "next / previous match of /"),
    ("Ray tree", "a", "all rays / collapse light ones"),
    ("Ray tree", "p", "follow the heaviest child"),
    ("Ray tree", "] [", "step forward / back, trace order"),
    ("Ray tree", "} {", "run to the next / previous event"),
    ("Inspector", "↑↓ PgUp/Dn", "scroll"),
    ("Inspector", "←→ hl", "scroll sideways"),
    ("Inspector", "x", "explain the pixel (Enter: go)"),
    ("Source", "m", "material / object definition"),
    ("Source", "↑↓ ←→ PgUp/Dn", "scroll (Home: back)"),
    ("Anywhere", "Tab Shift+Tab", "next / previous pane"),
    ("Anywhere", "z", "zoom the pane (Tab: next pane)"),
    ("Anywhere", "/", "search rays: kind, object, light"),
    ("Anywhere", "w", "what-if: change a value"),
    ("Anywhere", ":", "query: mark matching pixels"),
    ("Anywhere", "r", "reload (automatic on save)"),
    ("Anywhere", "< >", "previous / next animation frame"),
    ("Anywhere", "e", "export the tree (JSON, by scene)"),
    ("Anywhere", "?", "this help"),
    ("Anywhere", "Esc", "close, leave a mode, cancel"),
    ("Anywhere", "q", "quit"),
];

/// The action for a key, given which pane has focus, whether the help is open (then
/// ↑↓ PgUp/PgDn scroll it and any other key closes it) and whether a prompt is open (then
/// it takes every key).
pub fn action_for_key(
    key: KeyEvent,
    focus: Focus,
    help_open: bool,
    prompt_open: bool,
) -> Option<Action> {
    if key.kind == KeyEventKind::Release {
        return None;
    }
    let control = key.modifiers.contains(KeyModifiers::CONTROL);
    let alt = key.modifiers.contains(KeyModifiers::ALT);
    let shift = key.modifiers.contains(KeyModifiers::SHIFT);
    if control && matches!(key.code, KeyCode::Char('c' | 'C')) {
        return Some(Action::Quit);
    }
    if prompt_open {
        return Some(Action::PromptKey(key));
    }
    if help_open {
        return Some(match key.code {
            KeyCode::Up | KeyCode::Char('k') => Action::HelpScroll(-1),
            KeyCode::Down | KeyCode::Char('j') => Action::HelpScroll(1),
            KeyCode::PageUp => Action::HelpScroll(-10),
            KeyCode::PageDown => Action::HelpScroll(10),
            _ => Action::ToggleHelp,
        });
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
        KeyCode::Char('>') => Some(Action::StepFrame { forward: true }),
        KeyCode::Char('<') => Some(Action::StepFrame { forward: false }),
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
        KeyCode::Char('z') => Some(Action::ToggleZoom),
        KeyCode::Char('/') => Some(Action::StartSearch),
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
        Focus::Source => source_key(key.code),
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

/// Plain moves go by display cells (at fit zoom one pixel is a fraction of a cell, too
/// small a step to see); Shift+move and HJKL go by single image pixels.
fn image_key(code: KeyCode, shift: bool) -> Option<Action> {
    let (dx, dy) = match code {
        KeyCode::Left | KeyCode::Char('h') => (-1, 0),
        KeyCode::Right | KeyCode::Char('l') => (1, 0),
        KeyCode::Up | KeyCode::Char('k') => (0, -1),
        KeyCode::Down | KeyCode::Char('j') => (0, 1),
        // Shift+h arrives as 'H' (with or without the SHIFT flag, depending on the terminal).
        KeyCode::Char('H') => return Some(Action::MoveCursor { dx: -1, dy: 0 }),
        KeyCode::Char('L') => return Some(Action::MoveCursor { dx: 1, dy: 0 }),
        KeyCode::Char('K') => return Some(Action::MoveCursor { dx: 0, dy: -1 }),
        KeyCode::Char('J') => return Some(Action::MoveCursor { dx: 0, dy: 1 }),
        KeyCode::Enter => return Some(Action::TraceCursor),
        KeyCode::Char('0') => return Some(Action::ResetRayView),
        KeyCode::Char('n') => return Some(Action::NextMatch),
        KeyCode::Char('N') => return Some(Action::PreviousMatch),
        _ => return None,
    };
    Some(if shift {
        Action::MoveCursor { dx, dy }
    } else {
        Action::MoveCursorByCells { dx, dy }
    })
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
        KeyCode::Char('n') => Action::SearchStep { forward: true },
        KeyCode::Char('N') => Action::SearchStep { forward: false },
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
        KeyCode::Left | KeyCode::Char('h') => Action::InspectorScrollSideways(-8),
        KeyCode::Right | KeyCode::Char('l') => Action::InspectorScrollSideways(8),
        KeyCode::Char('n') => Action::SearchStep { forward: true },
        KeyCode::Char('N') => Action::SearchStep { forward: false },
        _ => return None,
    })
}

fn source_key(code: KeyCode) -> Option<Action> {
    let (lines, columns) = match code {
        KeyCode::Up | KeyCode::Char('k') => (-1, 0),
        KeyCode::Down | KeyCode::Char('j') => (1, 0),
        KeyCode::PageUp => (-10, 0),
        KeyCode::PageDown => (10, 0),
        KeyCode::Left | KeyCode::Char('h') => (0, -8),
        KeyCode::Right | KeyCode::Char('l') => (0, 8),
        KeyCode::Home => return Some(Action::SourceScrollHome),
        _ => return None,
    };
    Some(Action::SourceScroll { lines, columns })
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
            action_for_key(right, Focus::Image, false, false),
            Some(Action::MoveCursorByCells { dx: 1, dy: 0 })
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char('j')), Focus::Image, false, false),
            Some(Action::MoveCursorByCells { dx: 0, dy: 1 })
        );
        // Shift and HJKL go by single pixels, however the terminal reports the shift.
        assert_eq!(
            action_for_key(shifted(KeyCode::Up), Focus::Image, false, false),
            Some(Action::MoveCursor { dx: 0, dy: -1 })
        );
        assert_eq!(
            action_for_key(shifted(KeyCode::Char('J')), Focus::Image, false, false),
            Some(Action::MoveCursor { dx: 0, dy: 1 })
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char('H')), Focus::Image, false, false),
            Some(Action::MoveCursor { dx: -1, dy: 0 })
        );
        assert_eq!(
            action_for_key(right, Focus::Tree, false, false),
            Some(Action::TreeRight)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char('k')), Focus::Tree, false, false),
            Some(Action::TreeUp)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Down), Focus::Inspector, false, false),
            Some(Action::InspectorScroll(1))
        );
        assert_eq!(
            action_for_key(key(KeyCode::Right), Focus::Inspector, false, false),
            Some(Action::InspectorScrollSideways(8))
        );
    }

    #[test]
    fn search_zoom_and_matches_have_their_keys() {
        for focus in [Focus::Image, Focus::Tree, Focus::Inspector] {
            assert_eq!(
                action_for_key(key(KeyCode::Char('/')), focus, false, false),
                Some(Action::StartSearch)
            );
            assert_eq!(
                action_for_key(key(KeyCode::Char('z')), focus, false, false),
                Some(Action::ToggleZoom)
            );
        }
        for focus in [Focus::Tree, Focus::Inspector] {
            assert_eq!(
                action_for_key(key(KeyCode::Char('N')), focus, false, false),
                Some(Action::SearchStep { forward: false })
            );
        }
        // n in the image goes to the query's next matching pixel instead.
        assert_eq!(
            action_for_key(key(KeyCode::Char('n')), Focus::Image, false, false),
            Some(Action::NextMatch)
        );
    }

    #[test]
    fn an_open_prompt_takes_every_key_even_q_and_esc() {
        for code in [KeyCode::Char('q'), KeyCode::Esc, KeyCode::Char('?')] {
            assert_eq!(
                action_for_key(key(code), Focus::Tree, false, true),
                Some(Action::PromptKey(key(code)))
            );
        }
    }

    #[test]
    fn global_keys_work_in_every_pane() {
        for focus in [Focus::Image, Focus::Tree, Focus::Inspector] {
            assert_eq!(
                action_for_key(key(KeyCode::Char('q')), focus, false, false),
                Some(Action::Quit)
            );
            assert_eq!(
                action_for_key(key(KeyCode::Esc), focus, false, false),
                Some(Action::Cancel)
            );
            assert_eq!(
                action_for_key(key(KeyCode::Char('e')), focus, false, false),
                Some(Action::Export)
            );
            assert_eq!(
                action_for_key(key(KeyCode::Tab), focus, false, false),
                Some(Action::FocusNext)
            );
            assert_eq!(
                action_for_key(
                    KeyEvent::new(KeyCode::Left, KeyModifiers::CONTROL),
                    focus,
                    false,
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
                    action_for_key(key(KeyCode::Char(c)), focus, false, false),
                    Some(action)
                );
            }
        }
        assert_eq!(
            action_for_key(key(KeyCode::Enter), Focus::Inspector, false, false),
            Some(Action::ExplainGo)
        );
    }

    #[test]
    fn with_help_open_arrows_scroll_it_other_keys_close_it_and_ctrl_c_still_quits() {
        assert_eq!(
            action_for_key(key(KeyCode::Char('x')), Focus::Image, true, false),
            Some(Action::ToggleHelp)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Esc), Focus::Image, true, false),
            Some(Action::ToggleHelp)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Down), Focus::Image, true, false),
            Some(Action::HelpScroll(1))
        );
        assert_eq!(
            action_for_key(
                KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL),
                Focus::Image,
                true,
                false
            ),
            Some(Action::Quit)
        );
    }

    #[test]
    fn key_releases_and_unbound_keys_do_nothing() {
        let mut release = key(KeyCode::Char('q'));
        release.kind = KeyEventKind::Release;
        assert_eq!(action_for_key(release, Focus::Image, false, false), None);
        assert_eq!(
            action_for_key(key(KeyCode::Char('y')), Focus::Image, false, false),
            None
        );
    }

    #[test]
    fn what_if_query_and_match_keys() {
        assert_eq!(
            action_for_key(key(KeyCode::Char('w')), Focus::Tree, false, false),
            Some(Action::WhatIf)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char(':')), Focus::Inspector, false, false),
            Some(Action::QueryPrompt)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char('n')), Focus::Image, false, false),
            Some(Action::NextMatch)
        );
        assert_eq!(
            action_for_key(shifted(KeyCode::Char('N')), Focus::Image, false, false),
            Some(Action::PreviousMatch)
        );
        // An open popup or prompt takes every key, `q` included; Ctrl+C still quits.
        let q = key(KeyCode::Char('q'));
        assert_eq!(
            action_for_key(q, Focus::Image, false, true),
            Some(Action::PromptKey(q))
        );
        assert_eq!(
            action_for_key(
                KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL),
                Focus::Image,
                false,
                true
            ),
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

    #[test]
    fn v_shows_the_3d_view_0_resets_it_and_left_drags_orbit_it() {
        assert_eq!(
            action_for_key(key(KeyCode::Char('v')), Focus::Tree, false, false),
            Some(Action::ToggleRayView)
        );
        assert_eq!(
            action_for_key(key(KeyCode::Char('0')), Focus::Image, false, false),
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
