//! `cargo xtask fuzz [--cases N] [--seed S] [--save] [--replay]`: runs the whole-pipeline
//! fuzzer and prints what failed; `--save` shrinks each new kind of failure into
//! `tests/fuzz-regressions/`; `--replay` only replays the regression inputs.

use std::collections::BTreeSet;

use anyhow::{bail, Context};
use xtask::fuzz;

use crate::workspace_root;

pub fn run(args: &[String]) -> anyhow::Result<()> {
    let mut cases = 1000u64;
    let mut seed = None;
    let mut save = false;
    let mut replay_only = false;
    let mut only_case = None;
    let mut args = args.iter();
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--cases" => cases = number(args.next(), "--cases")?,
            "--seed" => seed = Some(number(args.next(), "--seed")?),
            "--save" => save = true,
            "--replay" => replay_only = true,
            "--case" => only_case = Some(number(args.next(), "--case")?),
            other => bail!(
                "unknown argument `{other}` (expected --cases N, --seed S, --save or --replay)"
            ),
        }
    }
    let root = workspace_root();
    if replay_only {
        let failing = fuzz::replay(&root);
        let total = fuzz::regressions(&root).len();
        for line in &failing {
            eprintln!("{line}");
        }
        eprintln!("fuzz: {} of {total} regression inputs fail", failing.len());
        if failing.is_empty() {
            return Ok(());
        }
        bail!("{} regression inputs fail", failing.len());
    }
    let seed = seed.unwrap_or_else(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(1, |d| d.as_nanos() as u64)
    });
    eprintln!(
        "fuzz: seed {seed}; if the process aborts, the case it was running is in {}",
        fuzz::current_case_file().display()
    );
    let corpus = fuzz::corpus(&root);
    let step = (cases / 20).max(1);
    if let Some(index) = only_case {
        let case = fuzz::make_case(seed, index, &corpus);
        let mut summary = fuzz::Summary {
            cases: 1,
            ..fuzz::Summary::default()
        };
        match fuzz::run_case(&case) {
            fuzz::Verdict::Passed(_) => eprintln!("case {index} of seed {seed} passes"),
            fuzz::Verdict::Failed(f) => {
                eprintln!("case {index} of seed {seed}: {}: {}", f.class, f.detail);
                summary.failures.insert(f.class, (1, index, f.detail, case));
            }
            fuzz::Verdict::Hung => {
                eprintln!("case {index} of seed {seed} hangs");
                summary.hung.push((index, case));
            }
        }
        if save {
            save_new(&root, seed, &summary)?;
        }
        return Ok(());
    }
    let summary = fuzz::run_cases(seed, cases, &corpus, |i| {
        if (i + 1) % step == 0 {
            eprint!("\r{} / {cases}", i + 1);
        }
    });
    eprintln!();
    eprint!("{}", summary.report(seed));
    for (class, (_, index, detail, case)) in &summary.failures {
        eprintln!(
            "\n--- first case of `{class}` (case {index}: {detail}):\n{}",
            excerpt(case)
        );
    }
    for (index, case) in &summary.hung {
        eprintln!("\n--- case {index} hung:\n{}", excerpt(case));
    }
    if save {
        save_new(&root, seed, &summary)?;
    }
    if summary.failed() > 0 {
        bail!("{} cases failed", summary.failed());
    }
    Ok(())
}

/// The first 40 lines of a case's scene (mutations can repeat a line a thousand times),
/// and the names of its files.
fn excerpt(case: &fuzz::Case) -> String {
    let lines: Vec<&str> = case.text.lines().collect();
    let mut out = if lines.len() <= 40 {
        case.text.clone()
    } else {
        format!(
            "{}\n... ({} more lines)",
            lines[..40].join("\n"),
            lines.len() - 40
        )
    };
    for (name, bytes) in &case.files {
        out.push_str(&format!("\n(with {name}, {} bytes)", bytes.len()));
    }
    out
}

fn number(value: Option<&String>, flag: &str) -> anyhow::Result<u64> {
    let value = value.with_context(|| format!("{flag} needs a number"))?;
    value
        .parse()
        .with_context(|| format!("{flag} needs a whole number, not `{value}`"))
}

/// Shrinks and saves the first case of every failure class that no regression input shows.
fn save_new(root: &std::path::Path, seed: u64, summary: &fuzz::Summary) -> anyhow::Result<()> {
    let known: BTreeSet<String> = fuzz::regressions(root)
        .iter()
        .filter_map(|(_, case)| match fuzz::run_case(case) {
            fuzz::Verdict::Failed(f) => Some(f.class),
            fuzz::Verdict::Hung => Some("hang".into()),
            fuzz::Verdict::Passed(_) => None,
        })
        .collect();
    let mut new = Vec::new();
    for (class, (_, index, _, case)) in &summary.failures {
        if !known.contains(class) {
            new.push((class.clone(), *index, case.clone()));
        }
    }
    if let Some((index, case)) = summary.hung.first() {
        if !known.contains("hang") {
            new.push(("hang".to_string(), *index, case.clone()));
        }
    }
    for (class, index, case) in new {
        // A hang is not shrunk: every try would cost the whole timeout.
        let small = if class == "hang" {
            case
        } else {
            fuzz::shrink(&case, &class)
        };
        let path =
            fuzz::save_regression(root, &small, &class, &format!("seed {seed}, case {index}"))?;
        eprintln!("saved {} ({class})", path.display());
    }
    Ok(())
}
