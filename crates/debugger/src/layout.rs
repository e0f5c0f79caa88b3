//! Where each pane goes for a terminal size: the image over the ray tree on the left, the
//! inspector over the source (or the scene's errors) on the right, a status line at the
//! bottom; or, zoomed (`z`), the focused pane over the whole body. A pure function of the
//! size and the [`Arrangement`], so that key handling (scrolling, mouse picking) and drawing
//! agree on it without sharing mutable state.

use ratatui::layout::Rect;

use crate::action::Focus;

/// The smallest terminal the layout works in; below it the debugger shows a message.
pub const MIN_WIDTH: u16 = 64;
pub const MIN_HEIGHT: u16 = 23;

/// Below this width or height the layout is compact: the focused pane's column and row
/// get the larger share (see [`panes`]).
const COMPACT_WIDTH: u16 = 100;
const COMPACT_HEIGHT: u16 = 36;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Panes {
    pub image: Rect,
    pub tree: Rect,
    pub inspector: Rect,
    /// The source pane, or the scene's errors after a failed reload.
    pub source: Rect,
    pub status: Rect,
}

/// What besides the size decides the layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Arrangement {
    /// After a failed reload: the lower right pane gets more room, for diagnostics.
    pub errors: bool,
    pub focus: Focus,
    /// The focused pane fills the body; the others are empty rectangles (not drawn).
    pub zoomed: bool,
}

/// The panes for a terminal of `area`, showing an image of `image_size`; `None` when the
/// terminal is too small.
///
/// At 120x40 and up both columns are half the width and the image pane is as tall as the
/// fitted image needs. Below that (80x24 is the common case) an even split leaves every
/// pane too small to use: the tree showed 6 rows and the inspector's lines were cut at 38
/// columns. There the focused pane takes the larger share, the way lazygit widens its
/// focused panel: its column gets 3/5 of the width, and in the left column the focused one
/// of image and tree gets most of the height. The panes never move between columns, so
/// Tab only changes their sizes, and everything stays visible; `z` gives one pane the
/// whole body when even that is not enough.
pub fn panes(area: Rect, image_size: (u32, u32), arrangement: Arrangement) -> Option<Panes> {
    if area.width < MIN_WIDTH || area.height < MIN_HEIGHT {
        return None;
    }
    let body_height = area.height - 1;
    let status = Rect::new(area.x, area.y + body_height, area.width, 1);
    if arrangement.zoomed {
        let body = Rect::new(area.x, area.y, area.width, body_height);
        let hidden = Rect::new(area.x, area.y, 0, 0);
        let only = |focus: Focus| {
            if arrangement.focus == focus {
                body
            } else {
                hidden
            }
        };
        return Some(Panes {
            image: only(Focus::Image),
            tree: only(Focus::Tree),
            inspector: only(Focus::Inspector),
            source: only(Focus::Source),
            status,
        });
    }
    let compact = area.width < COMPACT_WIDTH || area.height < COMPACT_HEIGHT;
    let focus = arrangement.focus;

    let left_width = match (compact, focus) {
        (false, _) => area.width / 2,
        (true, Focus::Image | Focus::Tree) => area.width * 3 / 5,
        (true, Focus::Inspector | Focus::Source) => area.width * 2 / 5,
    };
    let right_width = area.width - left_width;

    // The image pane is as tall as the fitted image needs (two pixel rows per cell),
    // within bounds that keep rows for the tree below it.
    let (image_width, image_height) = (image_size.0.max(1), image_size.1.max(1));
    let inner_width = u32::from(left_width.saturating_sub(2));
    let half_rows = (inner_width * image_height).div_ceil(image_width);
    let wanted = u16::try_from(half_rows.div_ceil(2))
        .unwrap_or(u16::MAX)
        .saturating_add(2);
    let image_rows = match (compact, focus) {
        (false, _) => wanted.clamp(body_height * 2 / 5, body_height * 13 / 20),
        // The tree has the keyboard: it gets two thirds or more.
        (true, Focus::Tree) => wanted.min(body_height / 3).max(4),
        (true, _) => wanted.clamp(body_height * 2 / 5, body_height * 7 / 10),
    };
    let image = Rect::new(area.x, area.y, left_width, image_rows);
    let tree = Rect::new(
        area.x,
        area.y + image_rows,
        left_width,
        body_height - image_rows,
    );

    let source_rows = if arrangement.errors {
        body_height * 11 / 20
    } else if compact && focus == Focus::Inspector {
        // Three lines of source: the definition and one line either side.
        body_height / 4
    } else if compact && focus == Focus::Source {
        // The source has the keyboard: most of its column.
        body_height * 3 / 5
    } else {
        body_height * 7 / 20
    }
    .max(5);
    let inspector_rows = body_height - source_rows;
    let right_x = area.x + left_width;
    let inspector = Rect::new(right_x, area.y, right_width, inspector_rows);
    let source = Rect::new(right_x, area.y + inspector_rows, right_width, source_rows);
    Some(Panes {
        image,
        tree,
        inspector,
        source,
        status,
    })
}

/// The area inside a pane's one-cell border.
pub fn inner(pane: Rect) -> Rect {
    Rect::new(
        pane.x.saturating_add(1),
        pane.y.saturating_add(1),
        pane.width.saturating_sub(2),
        pane.height.saturating_sub(2),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn covers_without_overlap(area: Rect, p: &Panes) {
        let all = [p.image, p.tree, p.inspector, p.source, p.status];
        let cells: u32 = all.iter().map(|r| r.area()).sum();
        assert_eq!(cells, area.area(), "{p:?}");
        for (i, a) in all.iter().enumerate() {
            assert!(area.contains(a.as_position()), "{a:?}");
            for b in &all[i + 1..] {
                assert!(!a.intersects(*b), "{a:?} overlaps {b:?}");
            }
        }
    }

    fn arranged(focus: Focus) -> Arrangement {
        Arrangement {
            errors: false,
            focus,
            zoomed: false,
        }
    }

    const FOCUSES: [Focus; 4] = [Focus::Image, Focus::Tree, Focus::Inspector, Focus::Source];

    #[test]
    fn the_panes_tile_the_usual_sizes() {
        for (w, h) in [(120, 40), (80, 24), (64, 23), (250, 70), (200, 60)] {
            let area = Rect::new(0, 0, w, h);
            for focus in FOCUSES {
                let panes = panes(area, (640, 480), arranged(focus)).unwrap();
                covers_without_overlap(area, &panes);
                assert!(panes.tree.height >= 5, "{w}x{h}: {panes:?}");
                assert!(panes.source.height >= 5, "{w}x{h}: {panes:?}");
                let errors = Arrangement {
                    errors: true,
                    ..arranged(focus)
                };
                covers_without_overlap(area, &super::panes(area, (640, 480), errors).unwrap());
            }
        }
    }

    #[test]
    fn at_120x40_the_image_pane_fits_a_4_by_3_image() {
        for focus in FOCUSES {
            let panes = panes(Rect::new(0, 0, 120, 40), (640, 480), arranged(focus)).unwrap();
            assert_eq!(panes.image, Rect::new(0, 0, 60, 24));
            assert_eq!(panes.status, Rect::new(0, 39, 120, 1));
        }
    }

    /// The 80x24: the focused pane is 48 columns wide, the focused tree shows 13
    /// rays (14 rows inside its border, one for the header: the glass pixel's whole tree),
    /// the focused inspector 16 lines (the source pane keeps 3), the focused source 11.
    #[test]
    fn at_80x24_the_focused_pane_gets_the_room() {
        let area = Rect::new(0, 0, 80, 24);
        let tree = panes(area, (640, 480), arranged(Focus::Tree)).unwrap().tree;
        assert_eq!((tree.width, inner(tree).height), (48, 14));
        let inspector = panes(area, (640, 480), arranged(Focus::Inspector)).unwrap();
        assert_eq!(
            (inspector.inspector.width, inner(inspector.inspector).height),
            (48, 16)
        );
        assert_eq!(inner(inspector.source).height, 3);
        let image = panes(area, (640, 480), arranged(Focus::Image))
            .unwrap()
            .image;
        assert_eq!((image.width, image.height), (48, 16));
        let source = panes(area, (640, 480), arranged(Focus::Source))
            .unwrap()
            .source;
        assert_eq!((source.width, inner(source).height), (48, 11));
    }

    #[test]
    fn zoomed_the_focused_pane_fills_the_body_and_the_others_are_empty() {
        let area = Rect::new(0, 0, 80, 24);
        for focus in FOCUSES {
            let zoomed = Arrangement {
                zoomed: true,
                ..arranged(focus)
            };
            let p = panes(area, (640, 480), zoomed).unwrap();
            let body = Rect::new(0, 0, 80, 23);
            let shown: Vec<Rect> = [p.image, p.tree, p.inspector, p.source]
                .into_iter()
                .filter(|r| !r.is_empty())
                .collect();
            assert_eq!(shown, vec![body], "{focus:?}");
            let focused = match focus {
                Focus::Image => p.image,
                Focus::Tree => p.tree,
                Focus::Inspector => p.inspector,
                Focus::Source => p.source,
            };
            assert_eq!(focused, body);
        }
    }

    #[test]
    fn a_small_terminal_has_no_layout() {
        let any = arranged(Focus::Image);
        assert_eq!(panes(Rect::new(0, 0, 40, 10), (640, 480), any), None);
        assert_eq!(panes(Rect::new(0, 0, 63, 30), (640, 480), any), None);
    }
}
