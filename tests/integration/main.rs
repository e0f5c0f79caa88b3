//! The one integration-test binary: runs the real `whitted` executable and the libraries
//! together, the way a user does.
// A program, not a library: it prints its results and sets its exit status.
#![allow(clippy::print_stdout, clippy::print_stderr, clippy::exit)]

mod animation;
mod cli;
mod conventions;
mod debug_cli;
mod debug_tmux;
mod diff;
mod diff_student;
mod exit_codes;
mod explain;
mod extremes;
mod farm;
mod farm_slurm;
mod fmt;
mod front_end_oracles;
mod grade;
mod guards;
mod json_schema;
mod lint;
mod lsp;
mod mit6837;
mod neovim;
mod neovim_treesitter;
mod provenance;
mod query;
mod ray_budget;
mod ray_trees;
mod report_browser;
mod reshade;
mod sampling;
mod slurm_cluster;
mod support;
mod tidy;
mod trace_cli;
mod traversal_paths;
mod write_back;
