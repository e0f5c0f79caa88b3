//! The whole-pipeline fuzzer (issue 10, deliver 5; issue 26, deliver 6): generated and
//! mutated scenes, with the mesh files they read, run in-process through compile, validate,
//! prepare, lint, render, trace and explain (`case.rs`), each on a worker thread under a
//! time, step and memory budget. Any panic, hang, memory blow-up, NaN pixel or unlocated
//! error fails and prints the case. `cargo xtask fuzz --cases N [--seed S] [--save]`;
//! `--save` shrinks each new kind of failure and keeps it in `tests/fuzz-regressions/`
//! (`NNN.scene`, or a folder NNN holding case.scene with its mesh files beside it), which
//! `xtask/tests/fuzz.rs` replays.

pub mod case;
pub mod generate;
pub mod memory;
pub mod mutate;
pub mod rng;

use std::collections::BTreeMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex, Once};
use std::time::{Duration, Instant};

pub use case::{Failure, Passed};
use rng::Rng;

/// How long one case may take before it counts as a hang. Generous for debug builds on a
/// busy machine: a normal case takes milliseconds.
pub const CASE_TIMEOUT: Duration = Duration::from_secs(20);

/// Live bytes one case may add at its peak.
pub const MEMORY_BUDGET_BYTES: usize = 512 << 20;

/// The directory of regression inputs, relative to the workspace root.
pub const REGRESSIONS: &str = "tests/fuzz-regressions";

/// The last panic's message and location, captured by the fuzzer's panic hook.
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);
static HOOK: Once = Once::new();

/// Replaces the panic hook once, so that caught panics are recorded rather than printed.
fn install_panic_hook() {
    HOOK.call_once(|| {
        std::panic::set_hook(Box::new(|info| {
            let message = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "(no message)".to_string());
            let location = info
                .location()
                .map(|l| format!("{}:{}", short_path(l.file()), l.line()))
                .unwrap_or_else(|| "unknown place".to_string());
            if let Ok(mut last) = LAST_PANIC.lock() {
                *last = Some(format!("{location}\u{0}{message}"));
            }
        }));
    });
}

/// A source path without the machine's cargo registry prefix (`obvhs-0.4.0/src/...`).
fn short_path(file: &str) -> &str {
    match file.find("index.crates.io") {
        Some(at) => file[at..].split_once('/').map_or(file, |(_, rest)| rest),
        None => file,
    }
}

/// One fuzz input: a scene and the files it reads (meshes), by file name.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Case {
    pub text: String,
    pub files: Vec<(String, Vec<u8>)>,
    /// How it was made: `valid`, `wild`, `mutated` or `regression`.
    pub origin: &'static str,
}

impl Case {
    /// A scene that reads no files of its own.
    pub fn scene(text: impl Into<String>, origin: &'static str) -> Case {
        Case {
            text: text.into(),
            files: Vec::new(),
            origin,
        }
    }

    /// Writes the case as files: the scene as `scene`, its files beside it.
    pub fn write(&self, scene: &Path) -> std::io::Result<()> {
        let dir = scene.parent().unwrap_or(Path::new("."));
        std::fs::create_dir_all(dir)?;
        std::fs::write(scene, &self.text)?;
        for (name, bytes) in &self.files {
            std::fs::write(dir.join(name), bytes)?;
        }
        Ok(())
    }
}

/// Where the case being run is written first (its mesh files beside it), so that a case
/// that aborts the process (a stack overflow, the allocator's hard cap) can be found, and
/// run with `whitted`, afterwards.
pub fn current_case_file() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/fuzz-current/case.scene")
}

/// What a case came to.
#[derive(Debug)]
pub enum Verdict {
    Passed(Passed),
    Failed(Failure),
    /// It did not finish within [`CASE_TIMEOUT`]; its thread may still be running.
    Hung,
}

/// One case at a time per process: the panic record and the memory peak are global, so two
/// tests running cases at once would blame each other's panics and allocations.
static ONE_CASE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Runs one case on a worker thread with the time and memory budgets.
pub fn run_case(case: &Case) -> Verdict {
    install_panic_hook();
    // A case that panicked while holding the lock poisons nothing we rely on.
    let _turn = ONE_CASE_AT_A_TIME
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let (send, receive) = mpsc::channel();
    let cancel = Arc::new(AtomicBool::new(false));
    let worker_cancel = Arc::clone(&cancel);
    let owned = case.clone();
    let before = memory::reset_peak();
    // A stack overflow aborts the process: leave the case where it can be found.
    let _ = case.write(&current_case_file());
    let spawned = std::thread::Builder::new()
        .name("fuzz case".into())
        // The stack of a main thread (8 MiB on Linux), where the CLI runs the same code.
        .stack_size(8 << 20)
        .spawn(move || {
            let observer = case::Cancel(&worker_cancel);
            let result = catch_unwind(AssertUnwindSafe(|| case::run(&owned, &observer)));
            let _ = send.send(result);
        });
    if let Err(e) = spawned {
        return Verdict::Failed(Failure {
            class: "could not start a worker thread".into(),
            detail: e.to_string(),
        });
    }
    let verdict = match receive.recv_timeout(CASE_TIMEOUT) {
        Ok(Ok(Ok(passed))) => Verdict::Passed(passed),
        Ok(Ok(Err(failure))) => Verdict::Failed(failure),
        Ok(Err(_)) => {
            let recorded = LAST_PANIC.lock().ok().and_then(|mut p| p.take());
            let (location, message) = recorded
                .as_deref()
                .and_then(|r| r.split_once('\u{0}'))
                .map(|(l, m)| (l.to_string(), m.to_string()))
                .unwrap_or_else(|| ("unknown place".into(), "(no message)".into()));
            Verdict::Failed(Failure {
                class: format!("panic at {location}"),
                detail: message,
            })
        }
        Err(_) => {
            cancel.store(true, Ordering::Relaxed);
            Verdict::Hung
        }
    };
    if let (Verdict::Passed(_), Some(peak)) = (&verdict, memory::peak()) {
        let used = peak.saturating_sub(before);
        if used > MEMORY_BUDGET_BYTES {
            return Verdict::Failed(Failure {
                class: "memory budget".into(),
                detail: format!("{} MiB at the peak", used >> 20),
            });
        }
    }
    verdict
}

/// The valid scenes mutations start from: the feature scenes and the docs' examples.
pub fn corpus(root: &Path) -> Vec<String> {
    let mut texts = Vec::new();
    if let Ok(entries) = std::fs::read_dir(root.join("scenes")) {
        let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        paths.sort();
        for path in paths {
            if path.extension().is_some_and(|e| e == "scene") {
                if let Ok(text) = std::fs::read_to_string(&path) {
                    texts.push(text);
                }
            }
        }
    }
    if let Ok(docs) = std::fs::read_to_string(root.join("docs/language.md")) {
        let mut inside = None::<String>;
        for line in docs.lines() {
            match (&mut inside, line.starts_with("```")) {
                (None, true) if line.starts_with("```scene") => inside = Some(String::new()),
                (Some(block), true) => {
                    texts.push(std::mem::take(block));
                    inside = None;
                }
                (Some(block), false) => {
                    block.push_str(line);
                    block.push('\n');
                }
                _ => {}
            }
        }
    }
    texts
}

/// Case `index` of the run with `seed`: generated or mutated, a pure function of both.
/// Most generated scenes are valid (they reach the tracer, lints and explain); a minority
/// are written wild, with numbers at the edges and constructs that end in errors.
pub fn make_case(seed: u64, index: u64, corpus: &[String]) -> Case {
    let mut rng = Rng::new(seed ^ index.wrapping_mul(0x2545_f491_4f6c_dd1d));
    if corpus.is_empty() || rng.chance(0.8) {
        generate::case(&mut rng)
    } else {
        let base = rng.pick(corpus).clone();
        Case::scene(mutate::mutate(&mut rng, &base), "mutated")
    }
}

/// Counts over a run.
#[derive(Debug, Default)]
pub struct Summary {
    pub cases: u64,
    pub compiled: u64,
    /// Cases that reached the tracer (and lint, trace and explain).
    pub rendered: u64,
    /// Rendered cases with meshes read from their `.obj` and `.ply` files.
    pub with_meshes: u64,
    /// Lints found over the rendered cases.
    pub lints: u64,
    /// Findings of explain over the rendered cases.
    pub findings: u64,
    /// Cases and cases that reached the tracer, by how they were made.
    pub by_origin: BTreeMap<&'static str, (u64, u64)>,
    /// Why cases stopped at compilation: their first error's class and how many.
    pub stopped_by: BTreeMap<String, u64>,
    /// Failures by class: how many, and the first case's index and input.
    pub failures: BTreeMap<String, (u64, u64, String, Case)>,
    /// Cases that did not finish in time (the run stops after [`MAX_HANGS`]).
    pub hung: Vec<(u64, Case)>,
    pub seconds: f64,
    /// The slowest cases: seconds and index.
    pub slowest: Vec<(f64, u64)>,
}

/// A hung case's thread keeps a core busy until the process ends: stop after this many.
pub const MAX_HANGS: usize = 2;

impl Summary {
    pub fn failed(&self) -> u64 {
        self.failures.values().map(|f| f.0).sum::<u64>() + self.hung.len() as u64
    }

    pub fn report(&self, seed: u64) -> String {
        let share = |n: u64| 100.0 * n as f64 / self.cases.max(1) as f64;
        let mut out = format!(
            "fuzz: seed {seed}, {} cases in {:.1} s: {} compiled ({:.0}%), {} reached the \
             tracer ({:.0}%; {} with meshes, {} lints, {} explain findings), {} failed\n",
            self.cases,
            self.seconds,
            self.compiled,
            share(self.compiled),
            self.rendered,
            share(self.rendered),
            self.with_meshes,
            self.lints,
            self.findings,
            self.failed()
        );
        let origins: Vec<String> = self
            .by_origin
            .iter()
            .map(|(origin, (cases, rendered))| format!("{origin} {rendered} of {cases}"))
            .collect();
        out.push_str(&format!("  reached the tracer: {}\n", origins.join(", ")));
        let mut stopped: Vec<(&String, &u64)> = self.stopped_by.iter().collect();
        stopped.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        for (reason, count) in stopped.iter().take(6) {
            out.push_str(&format!("  stopped at compilation {count} x: {reason}\n"));
        }
        for (class, (count, index, detail, _)) in &self.failures {
            out.push_str(&format!(
                "  {count} x {class} (first: case {index}: {detail})\n"
            ));
        }
        for (index, _) in &self.hung {
            out.push_str(&format!(
                "  hang: case {index} did not finish in {} s\n",
                CASE_TIMEOUT.as_secs()
            ));
        }
        if self.hung.len() >= MAX_HANGS {
            out.push_str("  (the run stopped after the hangs)\n");
        }
        let slowest: Vec<String> = self
            .slowest
            .iter()
            .map(|(s, i)| format!("case {i} {s:.2} s"))
            .collect();
        out.push_str(&format!("  slowest: {}\n", slowest.join(", ")));
        out
    }
}

/// Runs `cases` cases from `seed`. Stops after [`MAX_HANGS`] hangs (a hung thread cannot
/// be stopped).
pub fn run_cases(
    seed: u64,
    cases: u64,
    corpus: &[String],
    mut progress: impl FnMut(u64),
) -> Summary {
    let started = Instant::now();
    let mut summary = Summary::default();
    for index in 0..cases {
        let case = make_case(seed, index, corpus);
        summary.cases += 1;
        let case_started = Instant::now();
        let verdict = run_case(&case);
        let origin = summary.by_origin.entry(case.origin).or_default();
        origin.0 += 1;
        origin.1 += u64::from(matches!(&verdict, Verdict::Passed(p) if p.rendered));
        summary
            .slowest
            .push((case_started.elapsed().as_secs_f64(), index));
        summary.slowest.sort_by(|a, b| b.0.total_cmp(&a.0));
        summary.slowest.truncate(5);
        match verdict {
            Verdict::Passed(passed) => {
                summary.compiled += u64::from(passed.compiled);
                summary.rendered += u64::from(passed.rendered);
                summary.with_meshes += u64::from(passed.rendered && passed.meshes > 0);
                summary.lints += passed.lints as u64;
                summary.findings += passed.findings as u64;
                if let Some(reason) = passed.stopped_by {
                    let reason = format!("({}) {reason}", case.origin);
                    *summary.stopped_by.entry(reason).or_default() += 1;
                }
            }
            Verdict::Failed(failure) => {
                let entry = summary.failures.entry(failure.class).or_insert((
                    0,
                    index,
                    failure.detail,
                    case,
                ));
                entry.0 += 1;
            }
            Verdict::Hung => {
                summary.hung.push((index, case));
                if summary.hung.len() >= MAX_HANGS {
                    break;
                }
            }
        }
        progress(index);
    }
    summary.seconds = started.elapsed().as_secs_f64();
    summary
}

/// The class a case fails with, for shrinking (`None` when it passes).
fn failure_class(case: &Case) -> Option<String> {
    match run_case(case) {
        Verdict::Passed(_) => None,
        Verdict::Failed(f) => Some(f.class),
        Verdict::Hung => Some("hang".into()),
    }
}

/// Shrinks a case's scene text while it still fails with `class` (its files are kept):
/// drops whole lines while that keeps the failure, then ever smaller chunks of characters
/// (a bounded number of tries).
pub fn shrink(case: &Case, class: &str) -> Case {
    const TRIES: u32 = 1500;
    let tries = std::cell::Cell::new(0u32);
    let still_fails = |candidate: &str| {
        tries.set(tries.get() + 1);
        let candidate = Case {
            text: candidate.to_string(),
            ..case.clone()
        };
        !candidate.text.trim().is_empty() && failure_class(&candidate).as_deref() == Some(class)
    };
    let mut best = case.text.clone();
    // Lines, last first (later statements depend on earlier ones, not the other way).
    loop {
        let lines: Vec<&str> = best.lines().collect();
        let mut removed = false;
        for i in (0..lines.len()).rev() {
            let candidate: Vec<&str> = lines
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .map(|(_, l)| *l)
                .collect();
            let candidate = candidate.join("\n");
            if still_fails(&candidate) {
                best = candidate;
                removed = true;
                break;
            }
        }
        if !removed || tries.get() > TRIES {
            break;
        }
    }
    let mut chunk = 64;
    while chunk >= 1 && tries.get() < TRIES {
        let mut start = 0;
        while start < best.len() && tries.get() < TRIES {
            let mut end = (start + chunk).min(best.len());
            while !best.is_char_boundary(end) {
                end += 1;
            }
            let candidate = format!("{}{}", &best[..start], &best[end..]);
            if still_fails(&candidate) {
                best = candidate;
            } else {
                start = end;
            }
        }
        chunk /= 2;
    }
    Case {
        text: best,
        ..case.clone()
    }
}

/// The regression inputs, sorted by name: every `NNN.scene`, and every folder NNN holding case.scene
/// with the other files of its directory (its meshes).
pub fn regressions(root: &Path) -> Vec<(PathBuf, Case)> {
    let mut found = Vec::new();
    if let Ok(entries) = std::fs::read_dir(root.join(REGRESSIONS)) {
        for entry in entries.flatten() {
            let path = entry.path();
            if path.extension().is_some_and(|e| e == "scene") {
                if let Ok(text) = std::fs::read_to_string(&path) {
                    found.push((path, Case::scene(text, "regression")));
                }
            } else if path.is_dir() {
                let scene = path.join("case.scene");
                let Ok(text) = std::fs::read_to_string(&scene) else {
                    continue;
                };
                let mut files = Vec::new();
                for file in std::fs::read_dir(&path).into_iter().flatten().flatten() {
                    let name = file.file_name().to_string_lossy().into_owned();
                    if name != "case.scene" {
                        if let Ok(bytes) = std::fs::read(file.path()) {
                            files.push((name, bytes));
                        }
                    }
                }
                files.sort();
                found.push((
                    scene,
                    Case {
                        text,
                        files,
                        origin: "regression",
                    },
                ));
            }
        }
    }
    found.sort_by(|a, b| a.0.cmp(&b.0));
    found
}

/// Replays every regression input; returns one line per failing file.
pub fn replay(root: &Path) -> Vec<String> {
    regressions(root)
        .into_iter()
        .filter_map(|(path, case)| {
            let name = path.display();
            match run_case(&case) {
                Verdict::Passed(_) => None,
                Verdict::Failed(f) => Some(format!("{name}: {}: {}", f.class, f.detail)),
                Verdict::Hung => Some(format!("{name}: hang")),
            }
        })
        .collect()
}

/// Writes `case` as the next regression input, with a header saying what it failed with
/// when found: `NNN.scene`, or a folder NNN holding case.scene with its files beside it.
pub fn save_regression(
    root: &Path,
    case: &Case,
    class: &str,
    origin: &str,
) -> std::io::Result<PathBuf> {
    let dir = root.join(REGRESSIONS);
    std::fs::create_dir_all(&dir)?;
    let next = regressions(root)
        .iter()
        .filter_map(|(p, _)| {
            let stem = if p.file_name().is_some_and(|n| n == "case.scene") {
                p.parent()?.file_name()?.to_str()?
            } else {
                p.file_stem()?.to_str()?
            };
            let digits: String = stem.chars().take_while(char::is_ascii_digit).collect();
            digits.parse::<u32>().ok()
        })
        .max()
        .map_or(1, |n| n + 1);
    let header: String = format!("// Found by `cargo xtask fuzz` ({origin}): {class}")
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    let saved = Case {
        text: format!("{header}\n{}", case.text),
        ..case.clone()
    };
    let path = if case.files.is_empty() {
        dir.join(format!("{next:03}.scene"))
    } else {
        dir.join(format!("{next:03}")).join("case.scene")
    };
    saved.write(&path)?;
    Ok(path)
}
