//! Where each pane goes for a terminal size: the image over the ray tree on the left, the
//! inspector over the source (or the scene's errors) on the right, a status line at the
//! bottom. A pure function of the size, so that key handling (scrolling, mouse picking) and
//! drawing agree on it without sharing mutable state.

use ratatui::layout::Rect;

/// The smallest terminal the layout works in; below it the debugger shows a message.
pub const MIN_WIDTH: u16 = 64;
pub const MIN_HEIGHT: u16 = 23;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Panes {
    pub image: Rect,
    pub tree: Rect,
    pub inspector: Rect,
    /// The source pane, or the scene's errors after a failed reload.
    pub source: Rect,
    pub status: Rect,
}

/// The panes for a terminal of `area`, showing an image of `image_size`; `None` when the
/// terminal is too small. `errors` gives the lower right pane more room, for diagnostics.
pub fn panes(area: Rect, image_size: (u32, u32), errors: bool) -> Option<Panes> {
    if area.width < MIN_WIDTH || area.height < MIN_HEIGHT {
        return None;
    }
    let body_height = area.height - 1;
    let status = Rect::new(area.x, area.y + body_height, area.width, 1);

    let left_width = area.width / 2;
    let right_width = area.width - left_width;

    // The image pane is as tall as the fitted image needs (two pixels rows per cell), within
    // 40% to 65% of the height so that the tree below always has rows.
    let (image_width, image_height) = (image_size.0.max(1), image_size.1.max(1));
    let inner_width = u32::from(left_width.saturating_sub(2));
    let half_rows = (inner_width * image_height).div_ceil(image_width);
    let wanted = u16::try_from(half_rows.div_ceil(2)).unwrap_or(u16::MAX);
    let image_rows = wanted
        .saturating_add(2)
        .clamp(body_height * 2 / 5, body_height * 13 / 20);
    let image = Rect::new(area.x, area.y, left_width, image_rows);
    let tree = Rect::new(
        area.x,
        area.y + image_rows,
        left_width,
        body_height - image_rows,
    );

    let lower_share = if errors { 11 } else { 7 };
    let source_rows = (body_height * lower_share / 20).max(5);
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

    #[test]
    fn the_panes_tile_the_usual_sizes() {
        for (w, h) in [(120, 40), (80, 24), (64, 23), (250, 70)] {
            let area = Rect::new(0, 0, w, h);
            let panes = panes(area, (640, 480), false).unwrap();
            covers_without_overlap(area, &panes);
            assert!(panes.tree.height >= 4, "{w}x{h}: {panes:?}");
            assert!(panes.source.height >= 5, "{w}x{h}: {panes:?}");
            let with_errors = super::panes(area, (640, 480), true).unwrap();
            covers_without_overlap(area, &with_errors);
        }
    }

    #[test]
    fn at_120x40_the_image_pane_fits_a_4_by_3_image() {
        let panes = panes(Rect::new(0, 0, 120, 40), (640, 480), false).unwrap();
        assert_eq!(panes.image, Rect::new(0, 0, 60, 24));
        assert_eq!(panes.status, Rect::new(0, 39, 120, 1));
    }

    #[test]
    fn a_small_terminal_has_no_layout() {
        assert_eq!(panes(Rect::new(0, 0, 40, 10), (640, 480), false), None);
        assert_eq!(panes(Rect::new(0, 0, 63, 30), (640, 480), false), None);
    }
}
