//! The ray tree pane: the picked pixel's rays, one row each, indented under the ray that
//! spawned them. One folder for the feature: the flattened tree, its open rays, selection and
//! scroll ([`state`]), running a navigation on it (`update.rs`) and its drawing (`draw.rs`).

pub(crate) mod draw;
pub mod state;
pub(crate) mod update;
