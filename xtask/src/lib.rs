//! The parts of xtask that tests use too: the whole-pipeline fuzzer (`cargo xtask fuzz`,
//! replayed by `xtask/tests/fuzz.rs`).

pub mod fuzz;
