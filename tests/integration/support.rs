//! What many of the tests do the same way: run the `whitted` binary from the repository's
//! root (so that `scenes/...` paths work) without colours, and insist it succeeded.

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs `whitted ARGS` in the repository's root with `NO_COLOR`.
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")))
        .env("NO_COLOR", "1")
        .args(args)
        .output()
        .expect("the whitted binary runs")
}

/// [`run`], which must succeed; its standard output.
pub fn ok(args: &[&str]) -> String {
    let output = run(args);
    assert!(
        output.status.success(),
        "{args:?}: {}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}
