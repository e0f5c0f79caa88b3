//! The image the debugger shows: linear pixels that the background render fills in tile by
//! tile. sRGB is encoded when drawing, only for the few thousand pixels a pane samples.
//!
//! A new render writes over the previous image of the same size instead of clearing it, so the
//! last good image stays on screen while its replacement streams in.

use whitted_tracer::display::linear_to_srgb8_rgb;
use whitted_tracer::TileResult;

use crate::image::PixelSource;

#[derive(Clone, Debug, PartialEq)]
pub struct Framebuffer {
    width: u32,
    height: u32,
    linear: Vec<[f32; 3]>,
    /// Whether a render has reached each pixel yet.
    filled: Vec<bool>,
}

impl Framebuffer {
    /// An empty (not yet rendered) image.
    pub fn new(width: u32, height: u32) -> Framebuffer {
        let count = width as usize * height as usize;
        Framebuffer {
            width,
            height,
            linear: vec![[0.0; 3]; count],
            filled: vec![false; count],
        }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    fn index(&self, x: u32, y: u32) -> Option<usize> {
        (x < self.width && y < self.height).then(|| y as usize * self.width as usize + x as usize)
    }

    /// Copies a finished tile in. Pixels outside the image are ignored, so a tile from a
    /// render of another size cannot write out of bounds.
    pub fn put_tile(&mut self, tile: &TileResult) {
        let tile_width = tile.width.max(1) as usize;
        for (offset, &color) in tile.pixels.iter().enumerate() {
            let x = tile.x + (offset % tile_width) as u32;
            let y = tile.y + (offset / tile_width) as u32;
            if let Some(index) = self.index(x, y) {
                self.linear[index] = color;
                self.filled[index] = true;
            }
        }
    }

    /// The linear colour of a rendered pixel.
    pub fn linear(&self, x: u32, y: u32) -> Option<[f32; 3]> {
        let index = self.index(x, y)?;
        self.filled[index].then(|| self.linear[index])
    }

    /// How many pixels a render has reached.
    pub fn filled_count(&self) -> usize {
        self.filled.iter().filter(|&&f| f).count()
    }
}

impl PixelSource for Framebuffer {
    fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    fn srgb(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        let index = self.index(x, y)?;
        self.filled[index].then(|| linear_to_srgb8_rgb(self.linear[index]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_fill_their_pixels_and_nothing_else() {
        let mut image = Framebuffer::new(4, 3);
        assert_eq!(image.srgb(0, 0), None);
        image.put_tile(&TileResult {
            x: 2,
            y: 1,
            width: 2,
            height: 2,
            pixels: vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.5; 3]],
        });
        assert_eq!(image.filled_count(), 4);
        assert_eq!(image.srgb(2, 1), Some([255, 0, 0]));
        assert_eq!(image.srgb(3, 1), Some([0, 255, 0]));
        assert_eq!(image.linear(2, 2), Some([0.0, 0.0, 1.0]));
        assert_eq!(image.srgb(3, 2), Some([188, 188, 188]));
        assert_eq!(image.linear(1, 1), None);
        assert_eq!(image.linear(4, 0), None);
    }

    #[test]
    fn tiles_reaching_past_the_edge_are_clipped() {
        let mut image = Framebuffer::new(2, 2);
        image.put_tile(&TileResult {
            x: 1,
            y: 1,
            width: 2,
            height: 2,
            pixels: vec![[1.0; 3]; 4],
        });
        assert_eq!(image.filled_count(), 1);
    }
}
