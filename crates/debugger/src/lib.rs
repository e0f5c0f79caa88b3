//! whitted-debugger: the terminal ray-tree debugger (`whitted debug`), built on ratatui.
//!
//! The shape is ratatui's demo2 / gitui: the state ([`app::App`]), a pure map from keys to
//! [`action::Action`]s, [`update::update`] applying them, and drawing (`impl Widget for &App`
//! in `ui`) kept apart. [`run`] owns the terminal and the one event loop over
//! [`event::Event`]; rendering, recompiling and file watching happen on other threads and
//! report back as events. The binary hands over a compiled scene and a way to recompile it
//! ([`Session`]): this crate never parses.

pub mod action;
pub mod app;
pub mod event;
pub mod explain;
pub mod follow;
pub mod framebuffer;
pub mod heat_map;
pub mod hit_point;
pub mod image;
pub mod layout;
pub mod line_input;
pub mod palette;
pub mod projection;
pub mod query_job;
pub mod ray_view;
mod reload;
mod render_job;
mod run;
pub mod search;
mod session;
pub mod stepping;
mod terminal;
pub mod trace_job;
pub mod tree;
pub mod ui;
pub mod update;
mod watch;
pub mod what_if;

#[cfg(test)]
mod test_provenance_scene;
#[cfg(test)]
mod test_scene;

pub use run::{run, DebugError};
pub use session::{Compiled, Recompile, Session};
