//! `whitted farm plan`: write DIR/plan.json and the chosen engine's ready job (a shell
//! script, a Slurm array with its merge, or a Kubernetes Indexed Job), with time and memory
//! estimated from a small sample render.
//!
//! The engines only ever run `whitted render SCENE ... --task I/N --parts DIR/parts`; what a
//! task renders is decided by the task itself (see `task.rs`), so the files here are plain
//! text that any scheduler can run again: a task whose part is complete and fresh exits at
//! once.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use whitted_tracer::{PreparedScene, RenderOptions};

use crate::cli::{Engine, FarmPlanArgs, RenderOverrides, SceneArgs};
use crate::scene_input::load_scene;
use crate::setting_flags::apply_render_flags;
use crate::Failure;

/// The plan's format version.
const PLAN_FORMAT: u32 = 1;

/// DIR/plan.json: what to render and how it was split; status and merge read it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Plan {
    pub format: u32,
    pub whitted_version: String,
    /// The whitted executable the job files call (absolute).
    pub whitted: String,
    /// The scene (absolute; for Kubernetes, the path inside the container).
    pub scene: String,
    pub defines: Vec<(String, String)>,
    pub sets: Vec<(String, String)>,
    /// `--frame N`: one frame of an animation, rendered as a still.
    #[serde(default)]
    pub frame: Option<u32>,
    /// The frames of an animation the plan renders, first and last; none for a still.
    #[serde(default)]
    pub frames: Option<[u32; 2]>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub spp: Option<u32>,
    pub max_depth: Option<u32>,
    /// Threads per task (`None`: one per core the task may use).
    pub threads: Option<u32>,
    pub tasks: u32,
    pub engine: String,
    /// Where the tasks write their parts (absolute; for Kubernetes, inside the container).
    pub parts: String,
    /// The merged image the job's last step writes (for an animation, a pattern with a
    /// `{frame}` hole).
    pub merged: String,
    /// The sample render's estimate for one task: seconds on one core and memory in MiB.
    pub estimated_task_cpu_seconds: f64,
    pub estimated_task_memory_mib: u64,
}

impl Plan {
    /// The scene arguments the tasks were given, to compile the scene again as they did.
    pub fn scene_args(&self) -> SceneArgs {
        SceneArgs {
            scene: PathBuf::from(&self.scene),
            define: self.defines.clone(),
            set: self.sets.clone(),
            frame: self.frame,
        }
    }

    /// The frames of an animation plan.
    pub fn frame_range(&self) -> Option<std::ops::RangeInclusive<u32>> {
        self.frames.map(|[first, last]| first..=last)
    }

    /// The scene arguments at the render's first frame, whose compile fingerprints the
    /// parts (every frame is made from the same files, flags and whitted).
    pub fn fingerprint_args(&self) -> SceneArgs {
        SceneArgs {
            frame: self.frames.map(|[first, _]| first).or(self.frame),
            ..self.scene_args()
        }
    }

    pub fn overrides(&self) -> RenderOverrides {
        RenderOverrides {
            width: self.width,
            height: self.height,
            spp: self.spp,
            max_depth: self.max_depth,
        }
    }

    /// The render arguments after `whitted render`, without the task: the scene, `-D`,
    /// `--set` and the size flags.
    pub fn render_args(&self) -> Vec<String> {
        let mut args = vec![self.scene.clone()];
        for (name, value) in &self.defines {
            args.push("-D".into());
            args.push(format!("{name}={value}"));
        }
        for (name, value) in &self.sets {
            args.push("--set".into());
            args.push(format!("{name}={value}"));
        }
        if let Some(frame) = self.frame {
            args.push("--frame".into());
            args.push(frame.to_string());
        }
        if let Some([first, last]) = self.frames {
            args.push("--frames".into());
            args.push(format!("{first}..={last}"));
        }
        for (flag, value) in [
            ("--width", self.width),
            ("--height", self.height),
            ("--spp", self.spp),
            ("--max-depth", self.max_depth),
            ("--threads", self.threads),
        ] {
            if let Some(value) = value {
                args.push(flag.into());
                args.push(value.to_string());
            }
        }
        args
    }
}

pub fn plan_path(dir: &Path) -> PathBuf {
    dir.join("plan.json")
}

/// Reads DIR/plan.json, with a message that says what is wrong.
pub fn read_plan(dir: &Path) -> Result<Plan, Failure> {
    let path = plan_path(dir);
    let text = std::fs::read(&path).map_err(|e| {
        Failure::Message(format!(
            "cannot read {}: {e} (is {} a folder made by `whitted farm plan`?)",
            path.display(),
            dir.display()
        ))
    })?;
    let plan: Plan = serde_json::from_slice(&text)
        .map_err(|e| Failure::Message(format!("{} is not a farm plan: {e}", path.display())))?;
    if plan.format != PLAN_FORMAT {
        return Err(Failure::Message(format!(
            "{} has plan format {}; this whitted reads {PLAN_FORMAT}: plan again",
            path.display(),
            plan.format
        )));
    }
    Ok(plan)
}

/// Quotes `text` for a POSIX shell.
pub fn shell_quote(text: &str) -> String {
    if !text.is_empty()
        && text
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c))
    {
        return text.to_string();
    }
    format!("'{}'", text.replace('\'', r"'\''"))
}

fn quoted(args: &[String]) -> String {
    args.iter()
        .map(|a| shell_quote(a))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A name Kubernetes and Slurm accept: lowercase letters, digits and dashes.
fn job_name(scene: &Path) -> String {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let cleaned: String = stem
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    let cleaned = cleaned.trim_matches('-');
    let mut name = format!("whitted-{cleaned}");
    name.truncate(50);
    name.trim_end_matches('-').to_string()
}

/// What the sample render says one task will need.
struct Estimate {
    task_cpu_seconds: f64,
    task_memory_mib: u64,
    merge_memory_mib: u64,
}

/// Renders the scene at a small size (at most about 64x64, same samples and settings),
/// takes its CPU time per pixel, and scales it to a task's share: `frames` frames, each cut
/// into `bands` bands (the largest band counted 1.5 times the mean). Memory: a task's
/// pixels of one frame (12 bytes each, and 12 per sample of the filter's margin film), the
/// scene, and a base of 64 MiB.
fn estimate(
    prepared: &PreparedScene,
    options: &RenderOptions,
    (bands, frames): (u32, u32),
    objects: usize,
) -> Estimate {
    let (w, h) = (options.width.max(1), options.height.max(1));
    let scale = (f64::from(w) * f64::from(h) / 4096.0).sqrt().max(1.0);
    let mut sample = options.clone();
    sample.width = ((f64::from(w) / scale).round() as u32).max(1);
    sample.height = ((f64::from(h) / scale).round() as u32).max(1);
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build();
    let started = std::time::Instant::now();
    let _ = match &one_thread {
        Ok(pool) => {
            pool.install(|| whitted_tracer::render(prepared, &sample, &whitted_tracer::NoObserver))
        }
        Err(_) => whitted_tracer::render(prepared, &sample, &whitted_tracer::NoObserver),
    };
    let seconds = started.elapsed().as_secs_f64();
    let per_pixel = seconds / (f64::from(sample.width) * f64::from(sample.height));
    let pixels = f64::from(w) * f64::from(h);
    let task_pixels = match bands {
        0 | 1 => pixels,
        bands => pixels / f64::from(bands) * 1.5,
    };
    let film = if whitted_tracer::PixelFilter::from_settings(prepared.settings()).is_own_pixel() {
        0.0
    } else {
        12.0 * f64::from(options.samples_per_pixel.max(1))
    };
    let scene_bytes = objects as f64 * 512.0;
    let mib = |bytes: f64| (bytes / (1u64 << 20) as f64).ceil() as u64;
    Estimate {
        task_cpu_seconds: per_pixel * task_pixels * f64::from(frames.max(1)),
        task_memory_mib: mib(task_pixels * (24.0 + film) + scene_bytes) + 64,
        merge_memory_mib: mib(pixels * 15.0 * 2.0 + scene_bytes) + 64,
    }
}

/// Slurm's `--time`: ten times the estimate on the task's cores, at least 10 minutes.
fn slurm_time(cpu_seconds: f64, threads: u32) -> String {
    let seconds = (cpu_seconds / f64::from(threads.max(1)) * 10.0 + 120.0).max(600.0) as u64;
    let minutes = seconds.div_ceil(60);
    let (days, hours, minutes) = (minutes / 1440, minutes / 60 % 24, minutes % 60);
    if days > 0 {
        format!("{days}-{hours:02}:{minutes:02}:00")
    } else {
        format!("{hours:02}:{minutes:02}:00")
    }
}

/// Slurm's and Kubernetes' memory: twice the estimate, at least 256 MiB.
fn memory_mib(estimate: u64) -> u64 {
    (estimate * 2).max(256)
}

/// `whitted farm plan`.
pub fn plan(args: &FarmPlanArgs) -> Result<(), Failure> {
    let dir = &args.dir;
    std::fs::create_dir_all(dir.join("logs"))
        .and_then(|()| std::fs::create_dir_all(dir.join("parts")))
        .map_err(|e| Failure::Message(format!("cannot create {}: {e}", dir.display())))?;
    let dir = std::fs::canonicalize(dir)
        .map_err(|e| Failure::Message(format!("cannot read {}: {e}", dir.display())))?;
    let mut scene_args = args.scene.clone();
    scene_args.scene = crate::farm::task::absolute_scene(&args.scene.scene)?;
    let loaded = load_scene(&scene_args, true)?;
    let frames = crate::farm::task::render_frames(args.frames.clone(), &scene_args, &loaded);
    let first_task = crate::farm::task::TaskIndex {
        index: 0,
        count: args.tasks,
    };
    let share = crate::farm::task::share(frames.as_ref(), first_task)
        .map_err(|e| Failure::Usage(format!("--tasks {}: {e}", args.tasks)))?;
    let (loaded, options) = apply_render_flags(loaded, &args.overrides)?;
    if share.band.count > options.height {
        return Err(Failure::Usage(format!(
            "--tasks {}: each image would be cut into {} bands, but it has {} rows and each band \
             needs at least one",
            args.tasks, share.band.count, options.height
        )));
    }
    let objects = loaded.scene.objects.len();
    let pool = crate::render_cmd::thread_pool(None)?;
    let prepared = pool.install(|| PreparedScene::new_releasing_ir(loaded.scene));
    let frames_per_task = frames.as_ref().map_or(1, |range| {
        let count = u64::from(*range.end()) - u64::from(*range.start()) + 1;
        count.div_ceil(u64::from(args.tasks)) as u32
    });
    let estimate = estimate(
        &prepared,
        &options,
        (share.band.count, frames_per_task),
        objects,
    );

    let whitted = std::env::current_exe()
        .map_err(|e| Failure::Message(format!("cannot find the whitted executable: {e}")))?;
    let stem = scene_args.scene.file_stem().map_or_else(
        || "render".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let k8s = args.engine == Engine::K8s;
    let (scene, parts, merged) = if k8s {
        let scene = args.container_scene.clone().unwrap_or_else(|| {
            let name = scene_args.scene.file_name().map_or_else(
                || "scene.scene".to_string(),
                |n| n.to_string_lossy().into_owned(),
            );
            format!("/farm/{name}")
        });
        (
            scene,
            "/farm/parts".to_string(),
            format!("/farm/{stem}{}.png", frame_hole(&frames)),
        )
    } else {
        let merged = match &args.merged {
            Some(path) if frames.is_some() && !path.to_string_lossy().contains("{frame") => {
                return Err(Failure::Usage(format!(
                    "--merged {}: an animation merges into one image per frame: put the frame \
                     number in the name, like frame-{{frame:04}}.png",
                    path.display()
                )))
            }
            Some(path) => absolute(path)?,
            None => dir.join(format!("{stem}{}.png", frame_hole(&frames))),
        };
        (
            scene_args.scene.display().to_string(),
            dir.join("parts").display().to_string(),
            merged.display().to_string(),
        )
    };
    let plan = Plan {
        format: PLAN_FORMAT,
        whitted_version: env!("CARGO_PKG_VERSION").to_string(),
        whitted: if k8s {
            "whitted".to_string()
        } else {
            whitted.display().to_string()
        },
        scene,
        defines: args.scene.define.clone(),
        sets: args.scene.set.clone(),
        frame: args.scene.frame,
        frames: frames.as_ref().map(|r| [*r.start(), *r.end()]),
        width: args.overrides.width,
        height: args.overrides.height,
        spp: args.overrides.spp,
        max_depth: args.overrides.max_depth,
        threads: args.threads,
        tasks: args.tasks,
        engine: args.engine.name().to_string(),
        parts,
        merged,
        estimated_task_cpu_seconds: estimate.task_cpu_seconds,
        estimated_task_memory_mib: estimate.task_memory_mib,
    };
    let name = job_name(&scene_args.scene);
    let files: Vec<(&str, String, bool)> = match args.engine {
        Engine::Shell => vec![("run.sh", shell_script(&plan, &dir, args.jobs), true)],
        Engine::Slurm => {
            let (tasks, merge, submit) =
                slurm_files(&plan, &dir, &name, &estimate, args.max_concurrent);
            vec![
                ("task.sbatch", tasks, false),
                ("merge.sbatch", merge, false),
                ("submit.sh", submit, true),
            ]
        }
        Engine::K8s => {
            let job = k8s_job(&plan, &name, args, &estimate);
            let mut text = serde_json::to_string_pretty(&job)
                .map_err(|e| Failure::Message(format!("cannot write the Kubernetes job: {e}")))?;
            text.push('\n');
            vec![("job.yaml", text, false)]
        }
    };
    let mut json = serde_json::to_string_pretty(&plan)
        .map_err(|e| Failure::Message(format!("cannot write the plan: {e}")))?;
    json.push('\n');
    crate::farm::part::write_atomically(&plan_path(&dir), json.as_bytes())
        .map_err(Failure::Message)?;
    for (file, text, executable) in &files {
        let path = dir.join(file);
        crate::farm::part::write_atomically(&path, text.as_bytes()).map_err(Failure::Message)?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = if *executable { 0o755 } else { 0o644 };
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(mode))
                .map_err(|e| Failure::Message(format!("cannot write {}: {e}", path.display())))?;
        }
        #[cfg(not(unix))]
        let _ = executable;
    }
    let next = match args.engine {
        Engine::Shell => format!("whitted farm run {}", dir.display()),
        Engine::Slurm => format!("{}", dir.join("submit.sh").display()),
        Engine::K8s => format!("kubectl apply -f {}", dir.join("job.yaml").display()),
    };
    eprintln!(
        "planned {} tasks of {}x{} in {} (about {:.1} CPU-seconds and {} MiB each); next: {next}",
        args.tasks,
        options.width,
        options.height,
        dir.display(),
        estimate.task_cpu_seconds,
        estimate.task_memory_mib
    );
    Ok(())
}

/// The frame number's place in the merged file names of an animation (nothing for a still).
fn frame_hole(frames: &Option<std::ops::RangeInclusive<u32>>) -> &'static str {
    match frames {
        Some(_) => "-{frame:04}",
        None => "",
    }
}

fn absolute(path: &Path) -> Result<PathBuf, Failure> {
    if path.is_absolute() {
        return Ok(path.to_path_buf());
    }
    let here = std::env::current_dir()
        .map_err(|e| Failure::Message(format!("cannot read the current folder: {e}")))?;
    Ok(here.join(path))
}

/// The command of one task, `$index` standing for the task's index (a shell word).
fn task_command(plan: &Plan, index: &str) -> String {
    format!(
        "{} render {} --task {index}/{} --parts {} --quiet",
        shell_quote(&plan.whitted),
        quoted(&plan.render_args()),
        plan.tasks,
        shell_quote(&plan.parts)
    )
}

fn merge_command(plan: &Plan, dir: &Path) -> String {
    format!(
        "{} farm merge {} -o {}",
        shell_quote(&plan.whitted),
        shell_quote(&dir.display().to_string()),
        shell_quote(&plan.merged)
    )
}

/// run.sh: every task, `jobs` at a time (`xargs -P`), then the merge.
fn shell_script(plan: &Plan, dir: &Path, jobs: Option<u32>) -> String {
    let jobs =
        jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get() as u32));
    format!(
        "#!/usr/bin/env bash\n\
         # Made by `whitted farm plan`: renders the {tasks} tasks {jobs} at a time, then merges\n\
         # them. Run again, it renders only the tasks whose parts are missing or stale.\n\
         set -euo pipefail\n\
         seq 0 {last} | xargs -P {jobs} -I '{{}}' {command}\n\
         {merge}\n",
        tasks = plan.tasks,
        last = plan.tasks - 1,
        command = task_command(plan, "{}"),
        merge = merge_command(plan, dir),
    )
}

/// task.sbatch (the array), merge.sbatch, and submit.sh, which submits the merge to run
/// after every task of the array succeeded.
fn slurm_files(
    plan: &Plan,
    dir: &Path,
    name: &str,
    estimate: &Estimate,
    max_concurrent: Option<u32>,
) -> (String, String, String) {
    let logs = dir.join("logs");
    let logs = logs.display();
    let throttle = max_concurrent.map_or(String::new(), |c| format!("%{c}"));
    let threads = plan.threads.unwrap_or(1);
    let tasks = format!(
        "#!/bin/bash\n\
         # Made by `whitted farm plan`: task I of {n} renders its band of the image into\n\
         # {parts}; a task whose part is already complete and fresh exits at once.\n\
         #SBATCH --job-name={name}\n\
         #SBATCH --array=0-{last}{throttle}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task={threads}\n\
         #SBATCH --time={time}\n\
         #SBATCH --mem={mem}M\n\
         #SBATCH --output={logs}/task-%A_%a.out\n\
         #SBATCH --error={logs}/task-%A_%a.err\n\
         set -euo pipefail\n\
         exec {command}\n",
        n = plan.tasks,
        parts = plan.parts,
        last = plan.tasks - 1,
        time = slurm_time(estimate.task_cpu_seconds, threads),
        mem = memory_mib(estimate.task_memory_mib),
        command = task_command(plan, "\"${SLURM_ARRAY_TASK_ID}\""),
    );
    let merge = format!(
        "#!/bin/bash\n\
         # Made by `whitted farm plan`: assembles the parts into {merged}.\n\
         #SBATCH --job-name={name}-merge\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --time=00:30:00\n\
         #SBATCH --mem={mem}M\n\
         #SBATCH --output={logs}/merge-%j.out\n\
         #SBATCH --error={logs}/merge-%j.err\n\
         set -euo pipefail\n\
         exec {command}\n",
        merged = plan.merged,
        mem = memory_mib(estimate.merge_memory_mib),
        command = merge_command(plan, dir),
    );
    let dir_text = shell_quote(&dir.display().to_string());
    let submit = format!(
        "#!/usr/bin/env bash\n\
         # Made by `whitted farm plan`: submits the {n} tasks as one array job, and the merge\n\
         # to run once every task has succeeded. Submitting again renders only the tasks\n\
         # whose parts are missing or stale.\n\
         set -euo pipefail\n\
         cd {dir_text}\n\
         array=$(sbatch --parsable task.sbatch)\n\
         array=${{array%%;*}}\n\
         merge=$(sbatch --parsable --dependency=afterok:\"$array\" merge.sbatch)\n\
         merge=${{merge%%;*}}\n\
         echo \"submitted the tasks as job $array and the merge as job $merge\"\n",
        n = plan.tasks,
    );
    (tasks, merge, submit)
}

/// The Indexed Job: `completions` tasks, each container running task
/// `$JOB_COMPLETION_INDEX` (through `--task-from-env --tasks N`), parts on a volume.
fn k8s_job(plan: &Plan, name: &str, args: &FarmPlanArgs, estimate: &Estimate) -> serde_json::Value {
    let mut command = vec![plan.whitted.clone(), "render".to_string()];
    command.extend(plan.render_args());
    command.extend(
        [
            "--task-from-env",
            "--tasks",
            &plan.tasks.to_string(),
            "--parts",
            &plan.parts,
            "--quiet",
        ]
        .map(String::from),
    );
    let parallelism = args.max_concurrent.unwrap_or(plan.tasks).min(plan.tasks);
    let memory = format!("{}Mi", memory_mib(estimate.task_memory_mib));
    serde_json::json!({
        "apiVersion": "batch/v1",
        "kind": "Job",
        "metadata": { "name": name, "labels": { "app": "whitted-farm" } },
        "spec": {
            "completionMode": "Indexed",
            "completions": plan.tasks,
            "parallelism": parallelism,
            // Two retries a task on average; `backoffLimitPerIndex` would say it per task,
            // but needs Kubernetes 1.29 or later.
            "backoffLimit": plan.tasks.saturating_mul(2),
            "template": {
                "metadata": { "labels": { "app": "whitted-farm" } },
                "spec": {
                    "restartPolicy": "Never",
                    "containers": [{
                        "name": "whitted",
                        "image": args.container_image,
                        "command": command,
                        "resources": {
                            "requests": { "cpu": plan.threads.unwrap_or(1).to_string(), "memory": memory },
                            "limits": { "memory": memory },
                        },
                        "volumeMounts": [{ "name": "farm", "mountPath": "/farm" }],
                    }],
                    "volumes": [{
                        "name": "farm",
                        "persistentVolumeClaim": { "claimName": args.pvc },
                    }],
                },
            },
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_words_are_quoted_only_when_needed() {
        assert_eq!(shell_quote("/a/b.scene"), "/a/b.scene");
        assert_eq!(shell_quote("N=3"), "N=3");
        assert_eq!(shell_quote("a b"), "'a b'");
        assert_eq!(shell_quote("it's"), r"'it'\''s'");
        assert_eq!(shell_quote("rgb(0,0,1)"), "'rgb(0,0,1)'");
        assert_eq!(shell_quote(""), "''");
    }

    #[test]
    fn slurm_times_have_a_floor_and_days() {
        assert_eq!(slurm_time(1.0, 1), "00:10:00");
        assert_eq!(slurm_time(3600.0, 1), "10:02:00");
        assert_eq!(slurm_time(3600.0 * 24.0, 2), "5-00:02:00");
    }

    #[test]
    fn job_names_are_lowercase_words() {
        assert_eq!(
            job_name(Path::new("/x/My Scene_2.scene")),
            "whitted-my-scene-2"
        );
        assert_eq!(job_name(Path::new("/x/.scene")), "whitted-scene");
    }
}
