//! Lines drawn in braille dots (2 × 4 per cell) over whatever a pane already shows: unlike
//! ratatui's `Canvas`, which paints every cell of its area, only the cells a line passes
//! through are written, so the backdrop stays visible between the rays.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier};

/// The braille bit of the dot at (`x`, `y`) of a cell, x in 0..2 and y in 0..4 (Unicode's
/// dot numbering: 1 2 3 7 down the left column, 4 5 6 8 down the right).
const DOT_BITS: [[u8; 4]; 2] = [[0x01, 0x02, 0x04, 0x40], [0x08, 0x10, 0x20, 0x80]];

/// A cell's dots and the style of the last line drawn through it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct DotCell {
    bits: u8,
    color: Option<Color>,
    bold: bool,
}

/// A grid of `columns × rows` cells, `2·columns × 4·rows` dots.
pub struct BrailleCanvas {
    columns: u16,
    rows: u16,
    cells: Vec<DotCell>,
}

impl BrailleCanvas {
    pub fn new(columns: u16, rows: u16) -> BrailleCanvas {
        BrailleCanvas {
            columns,
            rows,
            cells: vec![DotCell::default(); usize::from(columns) * usize::from(rows)],
        }
    }

    /// Sets the dot at (`x`, `y`) (dots from the top left); outside the grid it is ignored.
    pub fn dot(&mut self, x: i64, y: i64, color: Color, bold: bool) {
        let (column, row) = (x.div_euclid(2), y.div_euclid(4));
        if x < 0 || y < 0 || column >= i64::from(self.columns) || row >= i64::from(self.rows) {
            return;
        }
        let index = row as usize * usize::from(self.columns) + column as usize;
        let cell = &mut self.cells[index];
        cell.bits |= DOT_BITS[(x % 2) as usize][(y % 4) as usize];
        cell.color = Some(color);
        cell.bold = bold;
    }

    /// A line between two points given in dots (a DDA: one dot per step along the longer
    /// axis, so the line has no gaps).
    pub fn line(&mut self, from: (f64, f64), to: (f64, f64), color: Color, bold: bool) {
        let (dx, dy) = (to.0 - from.0, to.1 - from.1);
        if !(dx.is_finite() && dy.is_finite() && from.0.is_finite() && from.1.is_finite()) {
            return;
        }
        // Clipped lines are at most a pane's diagonal long; the cap only guards bad input.
        let steps = dx.abs().max(dy.abs()).ceil().min(1e5) as i64;
        for step in 0..=steps {
            let t = if steps == 0 {
                0.0
            } else {
                step as f64 / steps as f64
            };
            let (x, y) = (from.0 + dx * t, from.1 + dy * t);
            self.dot(x.floor() as i64, y.floor() as i64, color, bold);
        }
    }

    /// Writes every cell with a dot into `area` of `buf`: the braille character in the
    /// line's colour, over the background `background` gives for that cell.
    pub fn draw(&self, area: Rect, buf: &mut Buffer, background: impl Fn(u16, u16) -> Color) {
        for row in 0..self.rows.min(area.height) {
            for column in 0..self.columns.min(area.width) {
                let cell =
                    self.cells[usize::from(row) * usize::from(self.columns) + usize::from(column)];
                let Some(color) = cell.color else { continue };
                let Some(target) = buf.cell_mut((area.x + column, area.y + row)) else {
                    continue;
                };
                let symbol = char::from_u32(0x2800 + u32::from(cell.bits)).unwrap_or(' ');
                target
                    .set_char(symbol)
                    .set_fg(color)
                    .set_bg(background(column, row));
                if cell.bold {
                    target.modifier.insert(Modifier::BOLD);
                } else {
                    target.modifier.remove(Modifier::BOLD);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn symbols(buf: &Buffer) -> String {
        buf.content().iter().map(|c| c.symbol()).collect()
    }

    #[test]
    fn dots_map_to_their_braille_bits() {
        let mut canvas = BrailleCanvas::new(2, 1);
        canvas.dot(0, 0, Color::Red, false);
        canvas.dot(1, 3, Color::Red, false);
        canvas.dot(2, 3, Color::Green, true);
        canvas.dot(-1, 0, Color::Red, false);
        canvas.dot(4, 0, Color::Red, false);
        let mut buf = Buffer::empty(Rect::new(0, 0, 3, 1));
        canvas.draw(buf.area, &mut buf, |_, _| Color::Black);
        // Dot 1 and dot 8 in the first cell, dot 7 in the second; the third is untouched.
        assert_eq!(symbols(&buf), "\u{2881}\u{2840} ");
        assert_eq!(buf[(1, 0)].fg, Color::Green);
        assert!(buf[(1, 0)].modifier.contains(Modifier::BOLD));
        assert_eq!(buf[(0, 0)].bg, Color::Black);
    }

    #[test]
    fn a_line_has_no_gaps() {
        let mut canvas = BrailleCanvas::new(4, 1);
        canvas.line((0.0, 0.5), (7.9, 0.5), Color::White, false);
        let mut buf = Buffer::empty(Rect::new(0, 0, 4, 1));
        canvas.draw(buf.area, &mut buf, |_, _| Color::Reset);
        // The top row of dots, both columns, in every cell.
        assert_eq!(symbols(&buf), "\u{2809}".repeat(4));
        // Bad input draws nothing and does not hang.
        canvas.line((f64::NAN, 0.0), (1e300, 0.0), Color::White, false);
    }
}
