//! whitted-debugger: the terminal ray-tree debugger (ratatui).

pub mod image_view;
