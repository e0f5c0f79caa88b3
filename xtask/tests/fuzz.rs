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
    // The run must reach the tracer, lint and explain, not only the compiler's error paths:
    // most generated scenes are valid (about 70% of all cases reach the tracer; before
    // issue 26, 13%), and many read mesh files.
    assert!(
        summary.rendered > CASES / 2,
        "only {} cases reached the tracer",
        summary.rendered
    );
    assert!(
        summary.with_meshes > CASES / 10,
        "only {} cases with meshes reached the tracer",
        summary.with_meshes
    );
    assert_eq!(summary.failed(), 0, "{}", summary.report(SEED));
}

/// A failing case is kept whole: a scene alone as `NNN.scene`, a scene with mesh files as
/// `NNN/case.scene` with its files beside it (so `whitted render` runs it as it is), and
/// both are read back as they were saved and replayed with their meshes.
#[test]
fn a_case_with_mesh_files_is_kept_and_read_back_whole() {
    let root = tempfile::tempdir().unwrap_or_else(|e| panic!("{e}"));
    let plain = fuzz::Case::scene("sphere { }\n", "wild");
    let with_mesh = fuzz::Case {
        text: "mesh { file \"m0.obj\" }\n".into(),
        files: vec![(
            "m0.obj".into(),
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n".to_vec(),
        )],
        origin: "valid",
    };
    let save = |case: &fuzz::Case, class: &str| {
        fuzz::save_regression(root.path(), case, class, "seed 1, case 2")
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let first = save(&plain, "class a");
    let second = save(&with_mesh, "class b");
    assert!(
        first.ends_with("tests/fuzz-regressions/001.scene"),
        "{first:?}"
    );
    assert!(
        second.ends_with("tests/fuzz-regressions/002/case.scene"),
        "{second:?}"
    );
    assert!(second.with_file_name("m0.obj").is_file());
    let read = fuzz::regressions(root.path());
    assert_eq!(read.len(), 2);
    assert_eq!(read[0].1.files, []);
    assert_eq!(read[1].1.files, with_mesh.files);
    assert!(read[1].1.text.starts_with("// Found by `cargo xtask fuzz`"));
    assert!(read[1].1.text.ends_with(&with_mesh.text));
    match fuzz::run_case(&read[1].1) {
        fuzz::Verdict::Passed(passed) => assert_eq!((passed.rendered, passed.meshes), (true, 1)),
        other => panic!("{other:?}"),
    }
}
