//! `whitted render --task I/N` and `whitted farm`: a render split into tasks and merged is
//! byte-identical to a single render, for several task counts and a filter that reaches
//! past the pixel; status tells done from missing, stale and corrupt parts; the merge
//! refuses parts of another scene; the Slurm and Kubernetes files hold what a scheduler
//! reads; bad input gets a clear message, never a panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::support::{ok, run};

const SIZE: [&str; 4] = ["--width", "48", "--height", "36"];

fn scene() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/whitted.scene")
}

fn text(output: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// `whitted farm plan SCENE --tasks N -o DIR` with `extra` flags; DIR as a string.
fn plan(scene: &Path, dir: &Path, tasks: u32, extra: &[&str]) -> String {
    let dir_text = dir.display().to_string();
    let scene_text = scene.display().to_string();
    let tasks = tasks.to_string();
    let mut args = vec![
        "farm",
        "plan",
        &scene_text,
        "--tasks",
        &tasks,
        "-o",
        &dir_text,
    ];
    args.extend(SIZE);
    args.extend(extra);
    ok(&args);
    dir_text
}

/// A single render of `scene` at the test's size with `extra` flags, as PNG bytes.
fn single_render(scene: &Path, out: &Path, extra: &[&str]) -> Vec<u8> {
    let scene_text = scene.display().to_string();
    let out_text = out.display().to_string();
    let mut args = vec!["render", &scene_text, "-o", &out_text, "--quiet"];
    args.extend(SIZE);
    args.extend(extra);
    ok(&args);
    std::fs::read(out).expect("the single render's image")
}

#[test]
fn merged_tasks_are_byte_identical_to_a_single_render() {
    let temp = tempfile::tempdir().unwrap();
    let tent = ["--set", "filter=tent", "--set", "filter_radius=1.5"];
    let cases: [(u32, &[&str]); 6] = [
        (1, &[]),
        (3, &[]),
        (4, &[]),
        (7, &[]),
        (3, &tent),
        (7, &tent),
    ];
    for (case, (tasks, extra)) in cases.iter().enumerate() {
        let dir = temp.path().join(format!("farm-{case}"));
        let mut flags = vec!["--jobs", "2"];
        flags.extend(*extra);
        plan(&scene(), &dir, *tasks, &flags);
        let script = dir.join("run.sh");
        let output = Command::new("bash").arg(&script).output().unwrap();
        assert!(output.status.success(), "run.sh: {}", text(&output));
        let merged = std::fs::read(dir.join("whitted.png")).expect("the merged image");
        let single = single_render(
            &scene(),
            &temp.path().join(format!("single-{case}.png")),
            extra,
        );
        assert!(
            merged == single,
            "{tasks} tasks {extra:?}: the merged PNG differs from the single render's"
        );
    }
}

#[test]
fn merge_writes_every_format_and_verify_passes() {
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path().join("farm");
    let dir_text = plan(&scene(), &dir, 3, &[]);
    ok(&["farm", "run", &dir_text]);
    for format in ["exr", "ppm", "tga", "hdr"] {
        let merged = temp.path().join(format!("merged.{format}"));
        let merged_text = merged.display().to_string();
        ok(&[
            "farm",
            "merge",
            &dir_text,
            "-o",
            &merged_text,
            "--verify",
            "--samples",
            "16",
        ]);
        let single = single_render(&scene(), &temp.path().join(format!("single.{format}")), &[]);
        assert!(
            std::fs::read(&merged).unwrap() == single,
            "{format} differs"
        );
    }
}

/// One task's status line from `farm status`.
fn status_of(dir: &str, task: u32) -> (bool, String) {
    let output = run(&["farm", "status", dir]);
    let out = String::from_utf8_lossy(&output.stdout).into_owned();
    let line = out
        .lines()
        .find(|l| l.starts_with(&format!("task {task}/")))
        .unwrap_or_default()
        .to_string();
    (output.status.success(), line)
}

#[test]
fn status_tells_missing_stale_and_corrupt_parts_and_a_rerun_mends_them() {
    let temp = tempfile::tempdir().unwrap();
    let scene = temp.path().join("scene.scene");
    std::fs::copy(self::scene(), &scene).unwrap();
    let dir = temp.path().join("farm");
    let dir_text = plan(&scene, &dir, 3, &[]);
    ok(&["farm", "run", &dir_text]);
    let output = run(&["farm", "status", &dir_text]);
    assert!(output.status.success(), "{}", text(&output));
    assert!(
        text(&output).contains("3 of 3 tasks done"),
        "{}",
        text(&output)
    );

    let parts = dir.join("parts");
    std::fs::remove_file(parts.join("part-0001-of-0003.f32")).unwrap();
    let (success, line) = status_of(&dir_text, 1);
    assert!(!success);
    assert_eq!(line, "task 1/3: missing");

    let pixels = parts.join("part-0002-of-0003.f32");
    let mut bytes = std::fs::read(&pixels).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x01;
    std::fs::write(&pixels, bytes).unwrap();
    let (_, line) = status_of(&dir_text, 2);
    assert!(line.starts_with("task 2/3: corrupt"), "{line}");
    let merged = temp.path().join("m.png").display().to_string();
    let output = run(&["farm", "merge", &dir_text, "-o", &merged]);
    assert_eq!(output.status.code(), Some(1));
    assert!(text(&output).contains("task 1/3"), "{}", text(&output));

    // A run renders the missing and the corrupt parts again, and only those.
    let untouched = std::fs::read(parts.join("part-0000-of-0003.json")).unwrap();
    ok(&["farm", "run", &dir_text]);
    assert_eq!(
        std::fs::read(parts.join("part-0000-of-0003.json")).unwrap(),
        untouched
    );
    assert!(run(&["farm", "status", &dir_text]).status.success());

    // An edited scene makes every part stale, and the merge refuses them.
    let source = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&scene, source.replace("width 640", "width 640 // edited")).unwrap();
    let (success, line) = status_of(&dir_text, 0);
    assert!(!success);
    assert!(line.starts_with("task 0/3: stale"), "{line}");
    let output = run(&["farm", "merge", &dir_text, "-o", &merged]);
    assert_eq!(output.status.code(), Some(1));
    assert!(
        text(&output).contains("task 0/3: refused"),
        "{}",
        text(&output)
    );
}

#[test]
fn merge_refuses_a_part_of_another_scene_naming_the_task() {
    let temp = tempfile::tempdir().unwrap();
    let other_scene = temp.path().join("other.scene");
    let source = std::fs::read_to_string(scene()).unwrap();
    std::fs::write(
        &other_scene,
        source.replace("width 640", "width 640 // other"),
    )
    .unwrap();
    let dir = temp.path().join("farm");
    let other = temp.path().join("other");
    let dir_text = plan(&scene(), &dir, 3, &[]);
    let other_text = plan(&other_scene, &other, 3, &[]);
    ok(&["farm", "run", &dir_text]);
    ok(&["farm", "run", &other_text]);
    for ext in ["f32", "json"] {
        let name = format!("part-0001-of-0003.{ext}");
        std::fs::copy(
            other.join("parts").join(&name),
            dir.join("parts").join(&name),
        )
        .unwrap();
    }
    let merged = temp.path().join("m.png").display().to_string();
    let output = run(&["farm", "merge", &dir_text, "-o", &merged]);
    assert_eq!(output.status.code(), Some(1), "{}", text(&output));
    let message = text(&output);
    assert!(
        message.contains("task 1/3: refused") && message.contains("another scene"),
        "{message}"
    );
    assert!(!Path::new(&merged).exists());
}

#[test]
fn the_kubernetes_job_has_the_indexed_job_fields() {
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path().join("farm");
    plan(
        &scene(),
        &dir,
        5,
        &[
            "--engine",
            "k8s",
            "--max-concurrent",
            "2",
            "--container-image",
            "reg/whitted:1",
            "--pvc",
            "render-claim",
        ],
    );
    let text = std::fs::read_to_string(dir.join("job.yaml")).unwrap();
    // The job is JSON, which is YAML too (kubectl reads either).
    let job: serde_json::Value = serde_json::from_str(&text).expect("job.yaml parses");
    assert_eq!(job["apiVersion"], "batch/v1");
    assert_eq!(job["kind"], "Job");
    assert_eq!(job["metadata"]["name"], "whitted-whitted");
    let spec = &job["spec"];
    assert_eq!(spec["completionMode"], "Indexed");
    assert_eq!(spec["completions"], 5);
    assert_eq!(spec["parallelism"], 2);
    let pod = &spec["template"]["spec"];
    assert!(["Never", "OnFailure"].contains(&pod["restartPolicy"].as_str().unwrap_or("")));
    let container = &pod["containers"][0];
    assert_eq!(container["image"], "reg/whitted:1");
    let command: Vec<&str> = container["command"]
        .as_array()
        .expect("a command list")
        .iter()
        .filter_map(|w| w.as_str())
        .collect();
    assert_eq!(&command[..3], ["whitted", "render", "/farm/whitted.scene"]);
    let joined = command.join(" ");
    assert!(
        joined.contains("--task-from-env --tasks 5 --parts /farm/parts"),
        "{joined}"
    );
    assert_eq!(
        pod["volumes"][0]["persistentVolumeClaim"]["claimName"],
        "render-claim"
    );
    assert_eq!(container["volumeMounts"][0]["mountPath"], "/farm");
}

#[test]
fn the_slurm_files_hold_the_array_and_the_merge_after_it() {
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path().join("farm");
    plan(
        &scene(),
        &dir,
        6,
        &["--engine", "slurm", "--max-concurrent", "3"],
    );
    let tasks = std::fs::read_to_string(dir.join("task.sbatch")).unwrap();
    assert!(tasks.starts_with("#!/bin/bash\n"), "{tasks}");
    assert!(tasks.contains("\n#SBATCH --array=0-5%3\n"), "{tasks}");
    for option in [
        "--time=",
        "--mem=",
        "--output=",
        "--error=",
        "--cpus-per-task=1",
    ] {
        assert!(
            tasks.contains(&format!("\n#SBATCH {option}")),
            "{option}: {tasks}"
        );
    }
    let exe = std::fs::canonicalize(env!("CARGO_BIN_EXE_whitted")).unwrap();
    assert!(
        tasks.contains(&format!("exec {} render", exe.display())),
        "{tasks}"
    );
    assert!(
        tasks.contains("--task \"${SLURM_ARRAY_TASK_ID}\"/6"),
        "{tasks}"
    );
    let merge = std::fs::read_to_string(dir.join("merge.sbatch")).unwrap();
    assert!(merge.contains(" farm merge "), "{merge}");
    let submit = std::fs::read_to_string(dir.join("submit.sh")).unwrap();
    assert!(submit.contains("sbatch --parsable task.sbatch"), "{submit}");
    assert!(
        submit.contains("sbatch --parsable --dependency=afterok:\"$array\" merge.sbatch"),
        "{submit}"
    );
    // The #SBATCH lines must come before the first command, or sbatch ignores them.
    let first_command = tasks.find("\nset ").unwrap();
    assert!(tasks.rfind("#SBATCH").unwrap() < first_command);
    let output = Command::new("bash")
        .arg("-n")
        .arg(dir.join("submit.sh"))
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", text(&output));
}

#[test]
fn bad_task_input_gets_a_clear_message() {
    let temp = tempfile::tempdir().unwrap();
    let scene_text = scene().display().to_string();
    let parts = temp.path().join("parts").display().to_string();
    let out = temp.path().join("whole.png").display().to_string();
    let small = ["--width", "8", "--height", "6", "-o"];
    let force: Vec<&str> = ["render", scene_text.as_str(), "--force"]
        .into_iter()
        .chain(small)
        .chain([out.as_str()])
        .collect();
    let parts_alone: Vec<&str> = ["render", scene_text.as_str(), "--parts", parts.as_str()]
        .into_iter()
        .chain(small)
        .chain([out.as_str()])
        .collect();
    let cases: [(&[&str], i32, &str); 8] = [
        // --force and --parts mean nothing without a task: refused, not silently ignored.
        (&force, 2, "<--task <I/N>|--task-from-env>"),
        (&parts_alone, 2, "<--task <I/N>|--task-from-env>"),
        (
            &["render", &scene_text, "--task", "5/4", "--parts", &parts],
            2,
            "the last is 3",
        ),
        (
            &["render", &scene_text, "--task", "x", "--parts", &parts],
            2,
            "not a task: write I/N",
        ),
        (
            &["render", &scene_text, "--task", "0/0", "--parts", &parts],
            2,
            "at least 1",
        ),
        (
            &["farm", "plan", &scene_text, "--tasks", "0", "-o", &parts],
            2,
            "--tasks",
        ),
        (
            &["render", &scene_text, "--task-from-env", "--parts", &parts],
            2,
            "SLURM_ARRAY_TASK_ID",
        ),
        (
            &[
                "render",
                &scene_text,
                "--height",
                "4",
                "--task",
                "0/5",
                "--parts",
                &parts,
            ],
            2,
            "each task needs at least one row",
        ),
    ];
    for (args, code, says) in cases {
        let output = Command::new(env!("CARGO_BIN_EXE_whitted"))
            .env_remove("SLURM_ARRAY_TASK_ID")
            .env_remove("AWS_BATCH_JOB_ARRAY_INDEX")
            .env_remove("JOB_COMPLETION_INDEX")
            .args(args)
            .output()
            .unwrap();
        let message = text(&output);
        assert_eq!(output.status.code(), Some(code), "{args:?}: {message}");
        assert!(message.contains(says), "{args:?}: {message}");
        assert!(!message.contains("panicked"), "{args:?}: {message}");
    }
    let empty = temp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let empty_text = empty.display().to_string();
    let out = temp.path().join("m.png").display().to_string();
    for args in [
        vec!["farm", "merge", &empty_text, "-o", &out],
        vec!["farm", "status", &empty_text],
    ] {
        let output = run(&args);
        let message = text(&output);
        assert_eq!(output.status.code(), Some(1), "{args:?}: {message}");
        assert!(message.contains("plan.json"), "{message}");
        assert!(!message.contains("panicked"), "{message}");
    }
}

#[test]
fn a_task_from_the_environment_needs_the_flag() {
    let temp = tempfile::tempdir().unwrap();
    let scene_text = scene().display().to_string();
    let parts = temp.path().join("parts");
    let parts_text = parts.display().to_string();
    let out = temp.path().join("whole.png");
    let out_text = out.display().to_string();
    let mut args = vec!["render", &scene_text, "-o", &out_text, "--quiet"];
    args.extend(SIZE);
    // Inside an array job, a plain render still renders the whole image.
    let status = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .env("SLURM_ARRAY_TASK_ID", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "2")
        .args(&args)
        .status()
        .unwrap();
    assert!(status.success() && out.exists() && !parts.exists());
    let mut args = vec![
        "render",
        &scene_text,
        "--task-from-env",
        "--parts",
        &parts_text,
        "--quiet",
    ];
    args.extend(SIZE);
    let status = Command::new(env!("CARGO_BIN_EXE_whitted"))
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("AWS_BATCH_JOB_ARRAY_INDEX")
        .env("JOB_COMPLETION_INDEX", "1")
        .env("WHITTED_TASKS", "2")
        .args(&args)
        .status()
        .unwrap();
    assert!(status.success());
    assert!(parts.join("part-0001-of-0002.json").exists());
}

#[test]
fn an_animation_merges_frame_by_frame_byte_identical_to_one_render() {
    let temp = tempfile::tempdir().unwrap();
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/turntable.scene");
    let frames = ["--frames", "3..=8"];
    let single = temp.path().join("single-{frame}.png");
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        single.to_str().unwrap(),
    ];
    args.extend(SIZE);
    args.extend(frames);
    args.push("--quiet");
    ok(&args);
    // 6 frames: runs of whole frames (4 tasks), one frame each (6), bands of each (12).
    for tasks in [4, 6, 12] {
        let dir = temp.path().join(format!("farm-{tasks}"));
        let dir_text = plan(&scene, &dir, tasks, &frames);
        ok(&["farm", "run", &dir_text]);
        for frame in 3..=8 {
            let merged = std::fs::read(dir.join(format!("turntable-{frame:04}.png")))
                .unwrap_or_else(|e| panic!("{tasks} tasks: frame {frame}: {e}"));
            let single = std::fs::read(temp.path().join(format!("single-{frame}.png"))).unwrap();
            assert!(merged == single, "{tasks} tasks: frame {frame} differs");
        }
        assert!(!dir.join("turntable-0002.png").exists());
        assert!(!dir.join("turntable-0009.png").exists());
    }
    // Parts are ordinary files that another user of the cluster's folder can read.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let part = temp
            .path()
            .join("farm-4/parts/part-0001-of-0004-frame-000005.f32");
        let mode = std::fs::metadata(part).unwrap().permissions().mode();
        assert_ne!(mode & 0o044, 0, "the part is private: {mode:o}");
    }
    // A lost frame's part: status names the task and the merge writes no frame at all.
    let dir = temp.path().join("farm-4");
    let dir_text = dir.display().to_string();
    std::fs::remove_file(dir.join("parts/part-0001-of-0004-frame-000005.json")).unwrap();
    let (done, report) = status_of(&dir_text, 1);
    assert!(!done && report.contains("missing"), "{report}");
    let again = temp.path().join("again-{frame}.png");
    let output = run(&["farm", "merge", &dir_text, "-o", again.to_str().unwrap()]);
    assert!(!output.status.success());
    assert!(
        text(&output).contains("task 1/4, frame 5"),
        "{}",
        text(&output)
    );
    assert!(
        !temp.path().join("again-3.png").exists(),
        "nothing is written"
    );
    // Tasks that do not split 6 frames evenly are refused when planning.
    let output = run(&[
        "farm",
        "plan",
        scene.to_str().unwrap(),
        "--tasks",
        "9",
        "--frames",
        "3..=8",
        "-o",
        temp.path().join("nine").to_str().unwrap(),
    ]);
    assert_eq!(output.status.code(), Some(2), "{}", text(&output));
    assert!(text(&output).contains("multiple of 6"), "{}", text(&output));
}
