//! The image pane: one folder for the feature. `view.rs` maps a framebuffer onto half-block
//! cells (fit, zoom, pan, colour depth) and cells back to pixels for picking; `draw.rs`
//! draws the pane: the render or a heat map, the cursor and the hit point marked.

pub(crate) mod draw;
pub mod view;

pub use view::{draw_image, ColorDepth, PixelSource, Viewport};
