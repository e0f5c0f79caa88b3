//! Assignment 7's pictures for `whitted mit6837`: `-render_samples FILE ZOOM` (every sample
//! as a dot where its camera ray went, in its colour, over a checkerboard of the pixels) and
//! `-render_filter FILE ZOOM` (the filter's weight around the centre pixel), both `ZOOM`
//! times the image's size, as the course's `Film::renderSamples` and `renderFilter` drew them.
//!
//! Both are linear RGB (top row first), for `image_output::to_linear8` like the render.

use whitted_tracer::{Film, PixelFilter};

/// The largest zoom: each pixel becomes at most a 64 x 64 block.
pub const MAX_ZOOM: u32 = 64;

/// The most pixels a picture may have (4096 x 4096): 48 MiB of linear RGB.
pub const MAX_PICTURE_PIXELS: u64 = 1 << 24;

/// The checkerboard's light squares (the course's 0.2 grey); the dark ones are black.
const CHECK: [f32; 3] = [0.2, 0.2, 0.2];
/// The filter picture's background (pixels beyond the filter's reach) and grid lines.
const FAR: [f32; 3] = [0.0, 0.0, 0.5];
const GRID: [f32; 3] = [0.0, 0.0, 1.0];

/// A picture: its size and linear RGB pixels, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Picture {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl Picture {
    fn filled(width: u32, height: u32, color: [f32; 3]) -> Self {
        Picture {
            width,
            height,
            pixels: vec![color; width as usize * height as usize],
        }
    }

    fn set(&mut self, x: u32, y: u32, color: [f32; 3]) {
        if x < self.width && y < self.height {
            self.pixels[y as usize * self.width as usize + x as usize] = color;
        }
    }

    #[cfg(test)]
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[y as usize * self.width as usize + x as usize]
    }
}

/// The size of the samples picture (`zoom` times the image) and of the filter picture (one
/// more for the closing grid line), or why it is refused.
pub fn picture_size(
    flag: &str,
    (width, height): (u32, u32),
    zoom: u32,
) -> Result<(u32, u32), String> {
    if !(1..=MAX_ZOOM).contains(&zoom) {
        return Err(format!(
            "{flag}: the zoom must be from 1 to {MAX_ZOOM}, not {zoom}"
        ));
    }
    let extra = u32::from(flag == "-render_filter");
    let (w, h) = (
        u64::from(width) * u64::from(zoom) + u64::from(extra),
        u64::from(height) * u64::from(zoom) + u64::from(extra),
    );
    if w * h > MAX_PICTURE_PIXELS {
        return Err(format!(
            "{flag}: a {width}x{height} image zoomed {zoom} times is a {w}x{h} picture, more \
             than {MAX_PICTURE_PIXELS} pixels (4096x4096): use a smaller -size or zoom (the \
             course drew 9x9 images zoomed 20 times)"
        ));
    }
    Ok((w as u32, h as u32))
}

/// `-render_samples`: each pixel a `zoom` x `zoom` block of a checkerboard (grey where
/// x + y is even), each sample a dot in its own colour at its position in the pixel. A dot
/// is a square of side `zoom / 8` (at least 1; the course drew one picture pixel), kept
/// inside its pixel's block.
pub fn samples_picture(film: &Film, zoom: u32) -> Picture {
    let mut picture = Picture::filled(film.width * zoom, film.height * zoom, [0.0; 3]);
    let side = (zoom / 8).max(1);
    for y in 0..film.height {
        for x in 0..film.width {
            if (x + y) % 2 == 0 {
                for py in y * zoom..(y + 1) * zoom {
                    for px in x * zoom..(x + 1) * zoom {
                        picture.set(px, py, CHECK);
                    }
                }
            }
            for k in 0..film.samples_per_pixel {
                let (ox, oy) = film.offset(x, y, k);
                let place = |corner: u32, offset: f32| {
                    let centre = corner * zoom + (offset * zoom as f32) as u32;
                    centre
                        .saturating_sub(side / 2)
                        .clamp(corner * zoom, (corner + 1) * zoom - side)
                };
                let (left, top) = (place(x, ox), place(y, oy));
                let color = film.color(x, y, k);
                for py in top..top + side {
                    for px in left..left + side {
                        picture.set(px, py, color);
                    }
                }
            }
        }
    }
    picture
}

/// `-render_filter`: the filter's weight around the centre pixel (`width / 2`,
/// `height / 2`), over the pixels within its reach: each picture pixel grey at the weight
/// of a sample at its centre (white is weight 1, the peak of every filter), dark blue
/// beyond the reach, with a blue line between pixels. The weights are the filter's own;
/// the pixel's value divides by their sum, so the picture shows the kernel's shape.
pub fn filter_picture(filter: &PixelFilter, (width, height): (u32, u32), zoom: u32) -> Picture {
    let mut picture = Picture::filled(width * zoom + 1, height * zoom + 1, FAR);
    let (cx, cy) = (width / 2, height / 2);
    let reach = filter.reach();
    let rows = cy.saturating_sub(reach)..=(cy + reach).min(height - 1);
    for y in rows {
        for x in cx.saturating_sub(reach)..=(cx + reach).min(width - 1) {
            for j in 0..zoom {
                for i in 0..zoom {
                    let dx = x as f32 + (i as f32 + 0.5) / zoom as f32 - (cx as f32 + 0.5);
                    let dy = y as f32 + (j as f32 + 0.5) / zoom as f32 - (cy as f32 + 0.5);
                    let w = filter.weight(dx, dy);
                    picture.set(x * zoom + i, y * zoom + j, [w; 3]);
                }
            }
        }
    }
    for py in 0..picture.height {
        for px in 0..picture.width {
            if px % zoom == 0 || py % zoom == 0 {
                picture.set(px, py, GRID);
            }
        }
    }
    picture
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::{Filter, Sampling};

    #[test]
    fn sizes_are_zoomed_and_bounded() {
        assert_eq!(picture_size("-render_samples", (9, 9), 20), Ok((180, 180)));
        assert_eq!(picture_size("-render_filter", (9, 9), 20), Ok((181, 181)));
        let zero = picture_size("-render_samples", (9, 9), 0).unwrap_err();
        assert!(
            zero.contains("the zoom must be from 1 to 64, not 0"),
            "{zero}"
        );
        let big = picture_size("-render_filter", (1000, 1000), 10).unwrap_err();
        assert!(big.contains("a 10001x10001 picture"), "{big}");
    }

    /// Two pixels of four grid samples each, every sample its own colour: each dot is where
    /// the course's uniform sampler puts it, and the squares between are the checkerboard.
    #[test]
    fn samples_are_dots_of_their_colour_at_their_positions() {
        let colors: Vec<[f32; 3]> = (0..8).map(|i| [i as f32 / 8.0, 1.0, 0.0]).collect();
        let film = Film {
            width: 2,
            height: 1,
            samples_per_pixel: 4,
            sampling: Sampling::Grid,
            colors,
        };
        let picture = samples_picture(&film, 16);
        assert_eq!((picture.width, picture.height), (32, 16));
        // Dots of side 2 centred on (4, 4), (12, 4), (4, 12), (12, 12) in pixel 0, and
        // 16 further right in pixel 1.
        assert_eq!(picture.pixel(3, 3), film.color(0, 0, 0));
        assert_eq!(picture.pixel(4, 4), film.color(0, 0, 0));
        assert_eq!(picture.pixel(12, 12), film.color(0, 0, 3));
        assert_eq!(picture.pixel(16 + 11, 3), film.color(1, 0, 1));
        assert_eq!(picture.pixel(8, 8), CHECK, "pixel 0 is a light square");
        assert_eq!(picture.pixel(16 + 8, 8), [0.0; 3], "pixel 1 a dark one");
    }

    /// A box of radius 1 seen at zoom 4 around the centre of a 5x5 image: weight 1 over the
    /// 2 x 2 pixel square around the centre pixel's centre, 0 elsewhere within reach, blue
    /// beyond it and on the grid lines.
    #[test]
    fn the_filter_picture_draws_the_weights_around_the_centre_pixel() {
        let filter = PixelFilter {
            filter: Filter::Box,
            radius: 1.0,
        };
        let picture = filter_picture(&filter, (5, 5), 4);
        assert_eq!((picture.width, picture.height), (21, 21));
        assert_eq!(picture.pixel(10, 10), [1.0; 3], "the centre");
        assert_eq!(
            picture.pixel(7, 7),
            [1.0; 3],
            "half a pixel up and left of it"
        );
        assert_eq!(picture.pixel(5, 5), [0.0; 3], "in reach, outside the box");
        assert_eq!(picture.pixel(1, 1), FAR, "beyond the reach");
        assert_eq!(picture.pixel(8, 10), GRID, "a line between pixels");
        let tent = PixelFilter {
            filter: Filter::Tent,
            radius: 1.0,
        };
        let picture = filter_picture(&tent, (5, 5), 4);
        let centre = picture.pixel(10, 10)[0];
        assert!((centre - (1.0 - 0.125f32.hypot(0.125) / 1.0)).abs() < 1e-6);
    }
}
