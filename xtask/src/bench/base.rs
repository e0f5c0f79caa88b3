//! The base the bench compares with (issue 31): which revision, and its release binary, built
//! once from `git archive` under target/bench/base/ and kept there.
//!
//! target/bench/base/src holds the sources of the last base built (re-extracted when the
//! revision changes, with fresh modification times so cargo rebuilds what changed),
//! target/bench/base/target is its own CARGO_TARGET_DIR (so the dependencies stay compiled
//! between bases and the work tree's target is untouched), and target/bench/base/SHA/whitted
//! is each revision's binary, reused whenever that revision is the base again.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, ensure, Context};

use super::options::BaseRequest;
use crate::cargo;

/// A revision to compare with, and why it is the one.
#[derive(Debug, PartialEq, Eq)]
pub(super) struct Choice {
    pub revision: String,
    pub why: &'static str,
}

/// The base revision for a request; `None` for `--no-base`.
pub(super) fn choose(request: &BaseRequest, work_tree_changed: bool) -> Option<Choice> {
    match request {
        BaseRequest::Nothing => None,
        BaseRequest::Revision(revision) => Some(Choice {
            revision: revision.clone(),
            why: "--base",
        }),
        BaseRequest::Default if work_tree_changed => Some(Choice {
            revision: "HEAD".to_string(),
            why: "the work tree has uncommitted changes, so against its last commit",
        }),
        BaseRequest::Default => Some(Choice {
            revision: "HEAD~1".to_string(),
            why: "the work tree is clean, so its last commit against the one before",
        }),
    }
}

/// A built base: the binary and the revision it is, for the table's heading.
pub(super) struct Base {
    pub exe: PathBuf,
    pub short_sha: String,
}

/// Whether `git status` lists anything (untracked files included: they may be new sources).
pub(super) fn work_tree_changed(root: &Path) -> anyhow::Result<bool> {
    Ok(!git(root, &["status", "--porcelain"])?.trim().is_empty())
}

/// The base's release binary: the cached one for its commit, or built now.
pub(super) fn build(root: &Path, bench_dir: &Path, revision: &str) -> anyhow::Result<Base> {
    let sha = git(
        root,
        &["rev-parse", "--verify", &format!("{revision}^{{commit}}")],
    )
    .with_context(|| format!("`{revision}` is not a commit here"))?
    .trim()
    .to_string();
    let short_sha = sha.chars().take(10).collect();
    let dir = bench_dir.join("base");
    let exe = dir.join(&sha).join("whitted");
    if exe.exists() {
        return Ok(Base { exe, short_sha });
    }
    let src = dir.join("src");
    // The sources are extracted again only for another commit: the same sources keep their
    // times, so a build that was interrupted goes on where it stopped.
    let marker = src.join(".bench-base-sha");
    if std::fs::read_to_string(&marker)
        .ok()
        .as_deref()
        .map(str::trim)
        != Some(sha.as_str())
    {
        if src.exists() {
            std::fs::remove_dir_all(&src)
                .with_context(|| format!("cannot remove {}", src.display()))?;
        }
        std::fs::create_dir_all(&src)?;
        let archive = dir.join("src.tar");
        git(
            root,
            &[
                "archive",
                "--format=tar",
                "-o",
                &archive.to_string_lossy(),
                &sha,
            ],
        )?;
        // -m: the files get the time of extraction, not of the commit, so cargo never takes
        // an older commit's artefacts for these sources.
        let status = Command::new("tar")
            .arg("-x")
            .arg("-m")
            .arg("-f")
            .arg(&archive)
            .arg("-C")
            .arg(&src)
            .status()
            .context("cannot run tar")?;
        ensure!(
            status.success(),
            "tar could not extract {}",
            archive.display()
        );
        let _ = std::fs::remove_file(&archive);
        std::fs::write(&marker, &sha)?;
    }
    let target = dir.join("target");
    eprintln!(
        "$ (in {}) CARGO_TARGET_DIR={} cargo build --release --locked --bin whitted",
        src.display(),
        target.display()
    );
    let status = Command::new(cargo())
        .args(["build", "--release", "--locked", "--bin", "whitted"])
        .env("CARGO_TARGET_DIR", &target)
        .current_dir(&src)
        .status()
        .context("cannot run cargo")?;
    ensure!(
        status.success(),
        "the base {revision} ({sha}) does not build"
    );
    std::fs::create_dir_all(exe.parent().context("the base binary has a folder")?)?;
    std::fs::copy(target.join("release/whitted"), &exe)
        .with_context(|| format!("cannot copy the base binary to {}", exe.display()))?;
    Ok(Base { exe, short_sha })
}

/// `git ARGS` in `root`; its standard output, or its first line of error.
fn git(root: &Path, args: &[&str]) -> anyhow::Result<String> {
    let output = Command::new("git")
        .args(args)
        .current_dir(root)
        .output()
        .context("cannot run git")?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        bail!(
            "git {}: {}",
            args.join(" "),
            stderr.lines().next().unwrap_or("failed")
        );
    }
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_clean_tree_compares_its_commit_with_the_one_before() {
        let choice = choose(&BaseRequest::Default, false).expect("a base");
        assert_eq!(choice.revision, "HEAD~1");
    }

    #[test]
    fn a_changed_tree_compares_with_its_own_commit() {
        let choice = choose(&BaseRequest::Default, true).expect("a base");
        assert_eq!(choice.revision, "HEAD");
        assert!(choice.why.contains("uncommitted"));
    }

    #[test]
    fn an_explicit_base_wins_and_no_base_is_none() {
        let asked = BaseRequest::Revision("v0.3".to_string());
        for changed in [false, true] {
            assert_eq!(
                choose(&asked, changed),
                Some(Choice {
                    revision: "v0.3".to_string(),
                    why: "--base"
                })
            );
            assert_eq!(choose(&BaseRequest::Nothing, changed), None);
        }
    }
}
