//! `cargo xtask ci`: everything CI checks, in the order that fails fastest.

use std::collections::BTreeSet;
use std::time::Instant;

use anyhow::{bail, Context};

use crate::{cargo, run_cargo, workspace_root};

/// Which crates each workspace crate must never depend on. Dependencies flow one way, from
/// the scene description towards the pictures: `ir <- lang`, `ir <- mit6837`,
/// `ir <- bvh <- tracer <- debugger`, `tracer <- explain <- debugger`. The BVH knows boxes and
/// rays, not scenes; the tracer never sees syntax, the debugger never parses, and the two
/// front ends know nothing of each other or of what comes after the IR.
const FORBIDDEN: &[(&str, &[&str])] = &[
    (
        "whitted-ir",
        &[
            "whitted-lang",
            "whitted-mit6837",
            "whitted-bvh",
            "whitted-tracer",
            "whitted-debugger",
            "whitted-lsp",
            "pest",
        ],
    ),
    (
        "whitted-mit6837",
        &[
            "whitted-lang",
            "whitted-bvh",
            "whitted-tracer",
            "whitted-debugger",
            "whitted-lsp",
            "pest",
            "ratatui",
        ],
    ),
    (
        "whitted-lang",
        &[
            "whitted-mit6837",
            "whitted-bvh",
            "whitted-tracer",
            "whitted-debugger",
            "whitted-lsp",
            "ratatui",
        ],
    ),
    // The BVH is geometry only: boxes in, primitive indices out, whoever the caller is.
    (
        "whitted-bvh",
        &[
            "whitted-lang",
            "whitted-mit6837",
            "whitted-tracer",
            "whitted-explain",
            "whitted-debugger",
            "whitted-lsp",
            "pest",
            "ratatui",
        ],
    ),
    (
        "whitted-tracer",
        &[
            "whitted-lang",
            "whitted-mit6837",
            "whitted-debugger",
            "whitted-explain",
            "whitted-lsp",
            "pest",
            "pest_derive",
            "ratatui",
        ],
    ),
    // Analysis reads recorded ray trees and the IR; it never sees syntax or the terminal,
    // and the debugger may use it later, never the other way round.
    (
        "whitted-explain",
        &[
            "whitted-lang",
            "whitted-mit6837",
            "whitted-debugger",
            "whitted-lsp",
            "pest",
            "pest_derive",
            "ratatui",
        ],
    ),
    (
        "whitted-debugger",
        &[
            "whitted-lang",
            "whitted-mit6837",
            "whitted-lsp",
            "pest",
            "pest_derive",
        ],
    ),
    // The language server answers from the compiler's own tables and diagnostics; it never
    // renders, and no library depends on it (only the binary, for `whitted lsp`).
    (
        "whitted-lsp",
        &[
            "whitted-bvh",
            "whitted-tracer",
            "whitted-explain",
            "whitted-debugger",
            "ratatui",
        ],
    ),
];

/// Edges that must exist, so that a renamed crate cannot make the checks above vacuous.
const REQUIRED: &[(&str, &str)] = &[
    ("whitted-lang", "whitted-ir"),
    ("whitted-mit6837", "whitted-ir"),
    ("whitted-tracer", "whitted-ir"),
    ("whitted-tracer", "whitted-bvh"),
    ("whitted-debugger", "whitted-tracer"),
    ("whitted-debugger", "whitted-explain"),
    ("whitted-explain", "whitted-tracer"),
    ("whitted-lsp", "whitted-lang"),
    ("whitted-lsp", "whitted-mit6837"),
    // The debugger explains the picked pixel (`x`) with the explain library.
    ("whitted-debugger", "whitted-explain"),
];

pub fn run(args: &[String]) -> anyhow::Result<()> {
    if let Some(arg) = args.first() {
        bail!("`cargo xtask ci` takes no arguments (got `{arg}`)");
    }
    let started = Instant::now();
    step("format", || run_cargo(&["fmt", "--all", "--check"]))?;
    step("clippy", || {
        run_cargo(&[
            "clippy",
            "--workspace",
            "--all-targets",
            "--locked",
            "--",
            "-D",
            "warnings",
        ])
    })?;
    step("tests", || run_cargo(&["test", "--workspace", "--locked"]))?;
    step("VS Code grammar", check_textmate_grammar)?;
    step("dependency directions", check_dependency_directions)?;
    step("golden images and ray trees", || crate::golden::run(&[]))?;
    eprintln!(
        "\nci: all checks passed in {:.0} s",
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The TextMate grammar (editors/vscode/syntaxes) under VS Code's own engine: a Node script
/// over every scene (under a second). `.ci/run` installs its two npm packages (`npm ci`); on a
/// machine without Node the step says so and is skipped, but with Node and without the
/// packages it fails and says how to install them.
fn check_textmate_grammar() -> anyhow::Result<()> {
    let root = workspace_root();
    let folder = root.join("editors/vscode");
    if std::process::Command::new("node")
        .arg("--version")
        .output()
        .is_err()
    {
        eprintln!("VS Code grammar: skipped, `node` is not installed");
        return Ok(());
    }
    if !folder.join("node_modules/vscode-textmate").is_dir() {
        bail!(
            "the VS Code grammar's test needs its packages: run `npm ci` in {}",
            folder.display()
        );
    }
    eprintln!("$ node editors/vscode/test/grammar.test.js");
    let status = std::process::Command::new("node")
        .arg("editors/vscode/test/grammar.test.js")
        .current_dir(&root)
        .status()
        .context("cannot run node")?;
    anyhow::ensure!(
        status.success(),
        "the VS Code grammar's test failed ({status})"
    );
    Ok(())
}

fn step(name: &str, f: impl FnOnce() -> anyhow::Result<()>) -> anyhow::Result<()> {
    eprintln!("\n== {name}");
    let started = Instant::now();
    f().with_context(|| format!("ci step `{name}` failed"))?;
    eprintln!("== {name}: ok ({:.1} s)", started.elapsed().as_secs_f64());
    Ok(())
}

/// The names of every crate `package` depends on through normal dependencies, transitively.
fn normal_dependencies(package: &str) -> anyhow::Result<BTreeSet<String>> {
    let output = std::process::Command::new(cargo())
        .args([
            "tree", "--locked", "-p", package, "-e", "normal", "--prefix", "none", "--format",
            "{p}",
        ])
        .current_dir(workspace_root())
        .output()
        .context("cannot run cargo tree")?;
    if !output.status.success() {
        bail!(
            "cargo tree -p {package} failed: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
    let text = String::from_utf8_lossy(&output.stdout);
    Ok(text
        .lines()
        .skip(1) // the package itself
        .filter_map(|line| line.split_whitespace().next())
        .map(str::to_string)
        .collect())
}

pub fn check_dependency_directions() -> anyhow::Result<()> {
    let mut problems = Vec::new();
    for (package, forbidden) in FORBIDDEN {
        let deps = normal_dependencies(package)?;
        for name in *forbidden {
            if deps.contains(*name) {
                problems.push(format!("{package} must not depend on {name}, but it does"));
            }
        }
        for (from, to) in REQUIRED.iter().filter(|(from, _)| from == package) {
            if !deps.contains(*to) {
                problems.push(format!(
                    "{from} is expected to depend on {to}, and does not"
                ));
            }
        }
    }
    if problems.is_empty() {
        eprintln!(
            "dependency directions: ok ({} crates checked)",
            FORBIDDEN.len()
        );
        Ok(())
    } else {
        bail!("dependency directions broken:\n  {}", problems.join("\n  "))
    }
}
