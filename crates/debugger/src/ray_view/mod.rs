//! The 3D ray view (`v`), in the image pane: the picked pixel's rays drawn from a camera the
//! user moves, the way MIT 6.837's RayTree showed them. One folder for the feature: the
//! camera ([`orbit`]), the rays as segments and their projection ([`geometry`]), the view's
//! state and its backdrop render ([`state`]), what the keys do to it (`update.rs`) and its
//! drawing (`draw.rs`).

pub(crate) mod draw;
pub mod geometry;
pub mod orbit;
pub mod state;
pub(crate) mod update;
