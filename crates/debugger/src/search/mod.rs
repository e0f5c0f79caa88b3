//! `/` search over the picked pixel's ray tree. One folder for the feature: which rays match
//! ([`state`]) and what its keys do (`update.rs`); its prompt is drawn on the status line
//! (`ui/status.rs`) and its matches underlined in the tree (`tree/draw.rs`).

pub mod state;
pub(crate) mod update;
