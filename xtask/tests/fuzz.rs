//! The fuzzer in CI: every input that ever failed (tests/fuzz-regressions/) must now pass,
//! and a fixed-seed run of generated and mutated scenes must find nothing.
// A program, not a library: it prints its results and sets its exit status.
#![allow(clippy::print_stdout, clippy::print_stderr, clippy::exit)]

use xtask::fuzz::{self, memory::CountingAllocator};

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// Enough to reach every generator branch many times: about 30-50 ms a case in a debug
/// build on a shared 2-core machine, so 20-40 s.
const CASES: u64 = 600;
const SEED: u64 = 0x5eed_f022;

fn root() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(|p| p.to_path_buf())
        .unwrap_or_default()
}

#[test]
fn every_regression_input_passes() {
    let root = root();
    let inputs = fuzz::regressions(&root);
    assert!(
        !inputs.is_empty(),
        "no regression inputs in {}",
        fuzz::REGRESSIONS
    );
    let failing = fuzz::replay(&root);
    assert!(
        failing.is_empty(),
        "{} of {} regression inputs fail:\n{}",
        failing.len(),
        inputs.len(),
        failing.join("\n")
    );
}

#[test]
fn a_fixed_seed_run_finds_nothing() {
    let root = root();
    let corpus = fuzz::corpus(&root);
    assert!(corpus.len() > 20, "the corpus has {} scenes", corpus.len());
    let summary = fuzz::run_cases(SEED, CASES, &corpus, |_| {});
    eprint!("{}", summary.report(SEED));
    assert_eq!(summary.cases, CASES, "the run stopped early (a hang)");
    // The run must reach the tracer, not only the compiler's error paths (today about 30%
    // of the cases render; validation that refuses more edge values lowers that a little).
    assert!(
        summary.rendered > CASES / 8,
        "only {} cases rendered",
        summary.rendered
    );
    assert_eq!(summary.failed(), 0, "{}", summary.report(SEED));
}
