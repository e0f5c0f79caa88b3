//! What-if (`w`): change one value of the scene (a setting, the picked ray's material, a
//! light's colour) and see the pixel and its ray tree before and after, then write the
//! change back into the scene file (`W`). One folder for the feature: the values and their
//! table rows ([`params`]), the popup's state and keys ([`state`]), where a change goes in
//! the scene's text ([`write_back`]) and the popup's drawing (`draw.rs`).

pub(crate) mod draw;
pub mod params;
pub mod state;
pub mod write_back;

pub use params::{params, value_text, Owner, Param, Row, Value};
