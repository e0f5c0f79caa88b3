//! `whitted farm`: plan a render as tasks for a laptop, Slurm or Kubernetes, see which tasks
//! are done, and merge their parts into the image a single render makes (docs/farm.md).
//!
//! Where animation plugs in: a task is "a set of frames and a pixel region". Today every
//! plan is one frame (the still) cut into row bands; frames add a frame range to
//! [`part::Manifest`] and to the task plan (task I of N = frames x bands), and the merge
//! writes one image per frame. Nothing here assumes a task is a band of one image beyond
//! the plan and the merge's coverage check.

pub mod merge;
pub mod part;
pub mod plan;
pub mod task;

use std::path::Path;

use crate::cli::{FarmArgs, FarmCommand, FarmDirArgs};
use crate::farm::part::PartState;
use crate::farm::plan::{read_plan, Plan};
use crate::scene_input::load_scene;
use crate::setting_flags::apply_render_flags;
use crate::Failure;

pub fn farm(args: &FarmArgs) -> Result<(), Failure> {
    match &args.command {
        FarmCommand::Plan(args) => plan::plan(args),
        FarmCommand::Run(args) => run(args),
        FarmCommand::Status(args) => status(args),
        FarmCommand::Merge(args) => merge::merge(args),
    }
}

/// The scene of `plan` compiled as its tasks compile it, and its fingerprint.
pub fn compile_plan_scene(
    plan: &Plan,
) -> Result<
    (
        whitted_ir::ValidScene,
        whitted_tracer::RenderOptions,
        task::Fingerprint,
    ),
    Failure,
> {
    let loaded = load_scene(&plan.scene_args(), true)?;
    let (loaded, options) = apply_render_flags(loaded, &plan.overrides())?;
    let fingerprint = task::fingerprint(&loaded.scene);
    Ok((loaded.scene, options, fingerprint))
}

/// What `farm status` says of one task.
enum TaskStatus {
    Done,
    Missing,
    Stale(String),
    Corrupt(String),
}

fn task_status(parts: &Path, task: u32, tasks: u32, now: &task::Fingerprint) -> TaskStatus {
    match part::read_part(parts, task, tasks, false) {
        PartState::Missing => TaskStatus::Missing,
        PartState::Corrupt(why) => TaskStatus::Corrupt(why),
        PartState::Intact(manifest, _) => match task::staleness(&manifest, now) {
            Some(why) => TaskStatus::Stale(why),
            None => TaskStatus::Done,
        },
    }
}

/// `whitted farm status DIR`: one line per task, a summary, and exit 1 unless every task
/// is done.
fn status(args: &FarmDirArgs) -> Result<(), Failure> {
    let plan = read_plan(&args.dir)?;
    let (_, _, now) = compile_plan_scene(&plan)?;
    let parts = Path::new(&plan.parts);
    let (mut done, mut missing, mut stale, mut corrupt) = (0u32, 0u32, 0u32, 0u32);
    let mut text = String::new();
    for task in 0..plan.tasks {
        let line = match task_status(parts, task, plan.tasks, &now) {
            TaskStatus::Done => {
                done += 1;
                "done".to_string()
            }
            TaskStatus::Missing => {
                missing += 1;
                "missing".to_string()
            }
            TaskStatus::Stale(why) => {
                stale += 1;
                format!("stale: {why}")
            }
            TaskStatus::Corrupt(why) => {
                corrupt += 1;
                format!("corrupt: {why}")
            }
        };
        text.push_str(&format!("task {task}/{}: {line}\n", plan.tasks));
    }
    text.push_str(&format!(
        "{done} of {} tasks done, {missing} missing, {stale} stale, {corrupt} corrupt\n",
        plan.tasks
    ));
    crate::scene_input::write_stdout(&text)?;
    if done == plan.tasks {
        Ok(())
    } else {
        Err(Failure::Message(format!(
            "{} of {} tasks are not done: run the plan again (it renders only those)",
            plan.tasks - done,
            plan.tasks
        )))
    }
}

/// `whitted farm run DIR`: runs a shell plan's run.sh (the tasks not yet done, then the
/// merge) and passes its exit status on.
fn run(args: &FarmDirArgs) -> Result<(), Failure> {
    let plan = read_plan(&args.dir)?;
    if plan.engine != "shell" {
        let how = match plan.engine.as_str() {
            "slurm" => "submit it with its submit.sh on the cluster",
            _ => "apply its job.yaml with kubectl",
        };
        return Err(Failure::Usage(format!(
            "{} is a {} plan: {how} (`farm run` runs shell plans)",
            args.dir.display(),
            plan.engine
        )));
    }
    let script = args.dir.join("run.sh");
    let status = std::process::Command::new("bash")
        .arg(&script)
        .status()
        .map_err(|e| Failure::Message(format!("cannot run {}: {e}", script.display())))?;
    if status.success() {
        Ok(())
    } else {
        Err(Failure::Message(format!(
            "{} failed ({status}); `whitted farm status {}` says which tasks are done",
            script.display(),
            args.dir.display()
        )))
    }
}
