//! The render farm on a real Slurm cluster (`slurm_cluster.rs`): `whitted farm plan
//! --engine slurm` and its `submit.sh` run by the real `sbatch`, the parts merged by the
//! dependent merge job, and the result (a still, and a 12-frame animation) compared byte for
//! byte with one `whitted render`;
//! then a cancelled task, reported by `farm status`, redone by submitting the plan again.
//! Without Slurm the test says so and runs the same plan through the shell engine, unless
//! `WHITTED_REQUIRE_SLURM` is set (`.ci/run` sets it, having installed Slurm).

use std::path::Path;
use std::process::Output;
use std::time::Duration;

use crate::slurm_cluster::SlurmCluster;
use crate::support::{ok, run};

const SCENE: &str = "scenes/whitted.scene";
const SIZE: [&str; 4] = ["--width", "96", "--height", "72"];

/// `whitted farm plan SCENE --tasks N -o DIR` with the test's size, and `extra` flags.
fn plan(dir: &Path, tasks: u32, extra: &[&str]) {
    let tasks = tasks.to_string();
    let mut args = vec![
        "farm",
        "plan",
        SCENE,
        "--tasks",
        &tasks,
        "-o",
        dir.to_str().unwrap(),
    ];
    args.extend(SIZE);
    args.extend(extra);
    ok(&args);
}

/// The one-process render the farm's merge must equal, byte for byte.
fn single_render(dir: &Path) -> Vec<u8> {
    let out = dir.join("single.png");
    let mut args = vec!["render", SCENE, "-o", out.to_str().unwrap(), "--quiet"];
    args.extend(SIZE);
    ok(&args);
    std::fs::read(out).unwrap()
}

fn text(output: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// Runs a plan's submit.sh against the cluster; the array's and the merge's job ids, read
/// from its last line ("submitted the tasks as job A and the merge as job M").
fn submit(cluster: &SlurmCluster, dir: &Path) -> (String, String) {
    let output = cluster
        .command("bash")
        .arg(dir.join("submit.sh"))
        .output()
        .unwrap();
    assert!(output.status.success(), "submit.sh: {}", text(&output));
    let words: Vec<String> = String::from_utf8_lossy(&output.stdout)
        .split_whitespace()
        .map(str::to_string)
        .collect();
    let after = |word: &str| {
        let at = words.iter().position(|w| w == word).unwrap();
        words[at + 3].clone()
    };
    (after("tasks"), after("merge"))
}

fn status(dir: &Path) -> Output {
    run(&["farm", "status", dir.to_str().unwrap()])
}

#[test]
fn a_slurm_plan_merges_byte_identical_to_one_render_and_redoes_a_cancelled_task() {
    let work = tempfile::tempdir().unwrap();
    let single = single_render(work.path());
    let cluster = match SlurmCluster::start() {
        Ok(cluster) => cluster,
        Err(why) => {
            assert!(
                std::env::var_os("WHITTED_REQUIRE_SLURM").is_none(),
                "WHITTED_REQUIRE_SLURM is set but no Slurm cluster could start: {why}"
            );
            eprintln!("no Slurm cluster here ({why}); the plan runs through the shell engine");
            let dir = work.path().join("shell");
            plan(&dir, 4, &["--engine", "shell"]);
            ok(&["farm", "run", dir.to_str().unwrap()]);
            assert!(std::fs::read(dir.join("whitted.png")).unwrap() == single);
            return;
        }
    };
    let limit = Duration::from_secs(120);

    // Four tasks and the dependent merge, as a user submits them.
    let dir = work.path().join("still");
    plan(&dir, 4, &["--engine", "slurm"]);
    let (array, merge) = submit(&cluster, &dir);
    cluster.wait_for(&array, limit);
    cluster.wait_for(&merge, limit);
    assert_eq!(cluster.job_state(&merge), "COMPLETED", "{}", cluster.logs());
    let merged = std::fs::read(dir.join("whitted.png")).unwrap();
    assert!(merged == single, "the merged image differs from one render");
    let report = status(&dir);
    assert!(report.status.success(), "{}", text(&report));

    // A 12-frame animation in 4 tasks of 3 whole frames, each frame equal to one render's.
    let dir = work.path().join("animation");
    let turntable = "scenes/turntable.scene";
    let frames = ["--frames", "0..=11"];
    let mut args = vec![
        "farm", "plan", turntable, "--tasks", "4", "--engine", "slurm", "-o",
    ];
    let dir_text = dir.display().to_string();
    args.push(&dir_text);
    args.extend(SIZE);
    args.extend(frames);
    ok(&args);
    let (array, merge) = submit(&cluster, &dir);
    cluster.wait_for(&array, limit);
    cluster.wait_for(&merge, limit);
    assert_eq!(cluster.job_state(&merge), "COMPLETED", "{}", cluster.logs());
    let pattern = work.path().join("single-{frame}.png");
    let mut args = vec![
        "render",
        turntable,
        "-o",
        pattern.to_str().unwrap(),
        "--quiet",
    ];
    args.extend(SIZE);
    args.extend(frames);
    ok(&args);
    for frame in 0..12 {
        let merged = std::fs::read(dir.join(format!("turntable-{frame:04}.png"))).unwrap();
        let single = std::fs::read(work.path().join(format!("single-{frame}.png"))).unwrap();
        assert!(merged == single, "frame {frame} differs from one render's");
    }

    // Task 2 cancelled before it runs (the node is held so that it cannot run first): the
    // merge waits forever on it, and status names it.
    let dir = work.path().join("cancelled");
    plan(&dir, 4, &["--engine", "slurm"]);
    cluster.hold_node(true);
    let (array, merge) = submit(&cluster, &dir);
    let output = cluster.run("scancel", &[&format!("{array}_2")]);
    assert!(output.status.success(), "scancel: {}", text(&output));
    cluster.hold_node(false);
    cluster.wait_for(&array, limit);
    assert_eq!(cluster.job_state(&merge), "PENDING", "the merge must wait");
    let report = status(&dir);
    assert_eq!(report.status.code(), Some(1), "{}", text(&report));
    let lines = text(&report);
    let line = |task: &str| {
        lines
            .lines()
            .find(|l| l.contains(task))
            .unwrap_or_else(|| panic!("no line for {task} in {lines}"))
            .to_string()
    };
    assert!(line("2/4").contains("missing"), "{lines}");
    assert!(line("0/4").contains("done"), "{lines}");
    assert!(!dir.join("whitted.png").exists());
    let manifest = |i: u32| dir.join(format!("parts/part-{i:04}-of-0004.json"));
    let before = std::fs::metadata(manifest(0)).unwrap().modified().unwrap();

    // Submitting the plan again renders only task 2, then merges.
    let output = cluster.run("scancel", &[&merge]);
    assert!(output.status.success(), "scancel: {}", text(&output));
    let (array, merge) = submit(&cluster, &dir);
    cluster.wait_for(&array, limit);
    cluster.wait_for(&merge, limit);
    assert_eq!(cluster.job_state(&merge), "COMPLETED", "{}", cluster.logs());
    let after = std::fs::metadata(manifest(0)).unwrap().modified().unwrap();
    assert_eq!(before, after, "task 0 was done and must not run again");
    assert!(std::fs::read(dir.join("whitted.png")).unwrap() == single);
}
