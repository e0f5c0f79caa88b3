//! The explanation (`x`, in the inspector's place): why the picked pixel has its colour, from
//! the explain library. One folder for the feature: its entries and jumps ([`state`]), what
//! its keys do (`update.rs`) and its drawing (`draw.rs`).

pub(crate) mod draw;
pub mod state;
pub(crate) mod update;
