//! The language's integration tests, in one binary: constructs compiled to IR, every class of
//! error rendered, the examples in docs/language.md, the scenes in scenes/, limits, and a
//! fuzz test that throws thousands of broken inputs at the compiler.

mod animation;
mod budgets;
mod constructs;
mod docs;
mod errors;
mod exporter_scale;
mod format;
mod fuzz;
mod limits;
mod material_colors;
mod meshes;
mod overrides;
mod programming_constructs;
mod provenance;
mod scenes;
mod support;
mod written;
