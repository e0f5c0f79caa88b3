//! The image pane: draws a linear-light framebuffer with half-block cells (`▀`, foreground =
//! top pixel, background = bottom pixel), with fit, zoom, pan, a cursor and overlays, and maps
//! terminal cells back to image pixels for mouse picking.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::Color;

/// How image pixels map onto the pane: `scale` image pixels per half-cell (both directions),
/// with the pane's top-left half-cell showing pixel (`origin_x`, `origin_y`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    pub scale: f32,
    pub origin_x: f32,
    pub origin_y: f32,
}

/// The smallest scale: one image pixel drawn as 8x8 half-cells.
pub const MIN_SCALE: f32 = 0.125;

impl Viewport {
    /// The viewport that shows the whole image, centred, as large as the pane allows.
    pub fn fit(image_width: u32, image_height: u32, pane: Rect) -> Viewport {
        let columns = f32::from(pane.width.max(1));
        let half_rows = f32::from(pane.height.max(1)) * 2.0;
        let scale = (image_width as f32 / columns)
            .max(image_height as f32 / half_rows)
            .max(MIN_SCALE);
        let origin_x = (image_width as f32 - columns * scale) / 2.0;
        let origin_y = (image_height as f32 - half_rows * scale) / 2.0;
        Viewport {
            scale,
            origin_x: origin_x.min(0.0),
            origin_y: origin_y.min(0.0),
        }
    }

    /// The image pixel under half-cell (`column`, `half_row`) of the pane, if any.
    pub fn pixel_at(
        &self,
        column: u16,
        half_row: u32,
        image_width: u32,
        image_height: u32,
    ) -> Option<(u32, u32)> {
        let x = self.origin_x + (f32::from(column) + 0.5) * self.scale;
        let y = self.origin_y + (half_row as f32 + 0.5) * self.scale;
        if x < 0.0 || y < 0.0 {
            return None;
        }
        let (x, y) = (x as u32, y as u32);
        (x < image_width && y < image_height).then_some((x, y))
    }

    /// The pane half-cell (column, half-row) whose centre shows pixel (x, y), if visible.
    pub fn cell_of(&self, x: u32, y: u32, pane: Rect) -> Option<(u16, u32)> {
        let column = ((x as f32 + 0.5 - self.origin_x) / self.scale).floor();
        let half_row = ((y as f32 + 0.5 - self.origin_y) / self.scale).floor();
        let visible = column >= 0.0
            && half_row >= 0.0
            && column < f32::from(pane.width)
            && half_row < f32::from(pane.height) * 2.0;
        visible.then_some((column as u16, half_row as u32))
    }

    /// Zooms by `factor` (2 = twice as large) keeping pixel (`x`, `y`) where it is on screen.
    pub fn zoom_about(&mut self, factor: f32, x: f32, y: f32) {
        let new_scale = (self.scale / factor).max(MIN_SCALE);
        let ratio = new_scale / self.scale;
        self.origin_x = x - (x - self.origin_x) * ratio;
        self.origin_y = y - (y - self.origin_y) * ratio;
        self.scale = new_scale;
    }

    /// Moves the view by a number of half-cells.
    pub fn pan(&mut self, columns: f32, half_rows: f32) {
        self.origin_x += columns * self.scale;
        self.origin_y += half_rows * self.scale;
    }
}

/// Whether the terminal shows 24-bit colour; otherwise colours go to the nearest xterm-256
/// palette entry ([`crate::palette`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorDepth {
    TrueColor,
    Indexed256,
}

impl ColorDepth {
    /// From `COLORTERM`, the variable terminals set when they support 24-bit colour.
    pub fn from_colorterm(value: Option<&str>) -> ColorDepth {
        match value {
            Some(v) if v.eq_ignore_ascii_case("truecolor") || v.eq_ignore_ascii_case("24bit") => {
                ColorDepth::TrueColor
            }
            _ => ColorDepth::Indexed256,
        }
    }

    /// The terminal colour for 8-bit sRGB.
    pub fn color(self, [r, g, b]: [u8; 3]) -> Color {
        match self {
            ColorDepth::TrueColor => Color::Rgb(r, g, b),
            ColorDepth::Indexed256 => {
                Color::Indexed(crate::palette::nearest_xterm_index([r, g, b]))
            }
        }
    }
}

/// Anything the image pane can draw: an 8-bit sRGB colour per pixel, or None where the
/// render has not reached yet.
pub trait PixelSource {
    fn size(&self) -> (u32, u32);
    fn srgb(&self, x: u32, y: u32) -> Option<[u8; 3]>;
}

/// Draws `source` into `area` of `buffer` through `viewport`; `marked` pixels (the cursor,
/// a hit point) are drawn in the given colour instead.
pub fn draw_image(
    source: &dyn PixelSource,
    viewport: &Viewport,
    depth: ColorDepth,
    marked: &[((u32, u32), Color)],
    area: Rect,
    buffer: &mut Buffer,
) {
    let (width, height) = source.size();
    let not_yet = depth.color([40, 40, 40]);
    for row in 0..area.height {
        for column in 0..area.width {
            // `None` outside the image: that half shows the terminal's own background.
            let half_color = |half: u32| -> Option<Color> {
                let pixel = viewport.pixel_at(column, u32::from(row) * 2 + half, width, height)?;
                Some(match marked.iter().find(|(p, _)| *p == pixel) {
                    Some((_, color)) => *color,
                    None => source
                        .srgb(pixel.0, pixel.1)
                        .map_or(not_yet, |c| depth.color(c)),
                })
            };
            let Some(cell) = buffer.cell_mut((area.x + column, area.y + row)) else {
                continue;
            };
            // The foreground of `▀` must never be `Reset`: terminals draw it in their
            // default text colour, not their background.
            match (half_color(0), half_color(1)) {
                (Some(top), Some(bottom)) => cell.set_char('▀').set_fg(top).set_bg(bottom),
                (Some(top), None) => cell.set_char('▀').set_fg(top).set_bg(Color::Reset),
                (None, Some(bottom)) => cell.set_char('▄').set_fg(bottom).set_bg(Color::Reset),
                (None, None) => cell.set_char(' ').set_fg(Color::Reset).set_bg(Color::Reset),
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Checker {
        width: u32,
        height: u32,
    }

    impl PixelSource for Checker {
        fn size(&self) -> (u32, u32) {
            (self.width, self.height)
        }
        fn srgb(&self, x: u32, y: u32) -> Option<[u8; 3]> {
            Some(if (x + y).is_multiple_of(2) {
                [255, 255, 255]
            } else {
                [0, 0, 0]
            })
        }
    }

    #[test]
    fn fit_shows_the_whole_image_and_picks_back_the_same_pixels() {
        let pane = Rect::new(0, 0, 80, 30);
        let v = Viewport::fit(160, 120, pane);
        // 160 px over 80 columns = 2; 120 px over 60 half-rows = 2.
        assert_eq!(v.scale, 2.0);
        assert_eq!(v.pixel_at(0, 0, 160, 120), Some((1, 1)));
        assert_eq!(v.pixel_at(79, 59, 160, 120), Some((159, 119)));
        for (x, y) in [(0, 0), (37, 90), (159, 119)] {
            let (column, half_row) = v.cell_of(x, y, pane).unwrap();
            let back = v.pixel_at(column, half_row, 160, 120).unwrap();
            assert!(
                back.0.abs_diff(x) <= 1 && back.1.abs_diff(y) <= 1,
                "{x},{y} -> {back:?}"
            );
        }
    }

    #[test]
    fn zoom_keeps_the_focus_pixel_in_place() {
        let pane = Rect::new(0, 0, 80, 30);
        let mut v = Viewport::fit(160, 120, pane);
        let before = v.cell_of(100, 60, pane).unwrap();
        v.zoom_about(2.0, 100.5, 60.5);
        assert_eq!(v.scale, 1.0);
        let after = v.cell_of(100, 60, pane).unwrap();
        assert!(before.0.abs_diff(after.0) <= 1 && before.1.abs_diff(after.1) <= 1);
        for _ in 0..10 {
            v.zoom_about(2.0, 100.5, 60.5);
        }
        assert_eq!(v.scale, MIN_SCALE);
    }

    #[test]
    fn half_blocks_carry_top_and_bottom_pixels() {
        let source = Checker {
            width: 4,
            height: 4,
        };
        let area = Rect::new(0, 0, 4, 2);
        let mut buffer = Buffer::empty(area);
        let viewport = Viewport {
            scale: 1.0,
            origin_x: 0.0,
            origin_y: 0.0,
        };
        draw_image(
            &source,
            &viewport,
            ColorDepth::TrueColor,
            &[((1, 1), Color::Magenta)],
            area,
            &mut buffer,
        );
        let cell = &buffer[(0, 0)];
        assert_eq!(cell.symbol(), "▀");
        assert_eq!(
            (cell.fg, cell.bg),
            (Color::Rgb(255, 255, 255), Color::Rgb(0, 0, 0))
        );
        // The marked pixel (1, 1) is the bottom half of cell (1, 0).
        assert_eq!(buffer[(1, 0)].bg, Color::Magenta);
    }

    #[test]
    fn colours_fall_back_to_the_256_palette() {
        assert_eq!(
            ColorDepth::from_colorterm(Some("truecolor")),
            ColorDepth::TrueColor
        );
        assert_eq!(ColorDepth::from_colorterm(None), ColorDepth::Indexed256);
        assert_eq!(
            ColorDepth::Indexed256.color([255, 0, 0]),
            Color::Indexed(196)
        );
        assert_eq!(
            ColorDepth::Indexed256.color([128, 128, 128]),
            Color::Indexed(244)
        );
    }

    #[test]
    fn outside_the_image_cells_are_blank_not_default_coloured_blocks() {
        let source = Checker {
            width: 2,
            height: 3,
        };
        let area = Rect::new(0, 0, 4, 2);
        let mut buffer = Buffer::empty(area);
        let viewport = Viewport {
            scale: 1.0,
            origin_x: 0.0,
            origin_y: -1.0,
        };
        draw_image(
            &source,
            &viewport,
            ColorDepth::TrueColor,
            &[],
            area,
            &mut buffer,
        );
        // Row 0: top half above the image, bottom half its first row.
        assert_eq!(buffer[(0, 0)].symbol(), "▄");
        assert_eq!(buffer[(0, 0)].fg, Color::Rgb(255, 255, 255));
        assert_eq!(buffer[(0, 0)].bg, Color::Reset);
        // Column 3 is right of the image: blank.
        assert_eq!(buffer[(3, 0)].symbol(), " ");
        assert_eq!(buffer[(3, 1)].bg, Color::Reset);
        // Row 1 holds image rows 1 and 2 in full.
        assert_eq!(buffer[(0, 1)].symbol(), "▀");
    }
}
