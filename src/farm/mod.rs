//! `whitted farm`: plan a render as tasks for a laptop, Slurm or Kubernetes, see which tasks
//! are done, and merge their parts into the image a single render makes (docs/farm.md).
//!
//! A task is some frames and, of each, a band of rows (`task::share`): a still is one
//! frame cut into N bands; an animation is cut into whole frames, or each frame into bands
//! when N is a multiple of the frame count. A part is one frame's band of one task; the
//! merge writes one image per frame.

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

/// The scene of `plan` compiled as its tasks compile it (at the first frame of an
/// animation), and its fingerprint.
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
    let loaded = load_scene(&plan.fingerprint_args(), true)?;
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

/// A task's status: the worst of its parts' (corrupt, then stale, then missing), naming
/// the frame for an animation.
fn task_status(
    parts: &Path,
    task: task::TaskIndex,
    frames: &[Option<u32>],
    now: &task::Fingerprint,
) -> TaskStatus {
    let mut worst = TaskStatus::Done;
    for &frame in frames {
        let of_frame = |why: String| match frame {
            Some(f) => format!("frame {f}: {why}"),
            None => why,
        };
        let status = match part::read_part(parts, task.index, task.count, frame, false) {
            PartState::Missing => TaskStatus::Missing,
            PartState::Corrupt(why) => TaskStatus::Corrupt(of_frame(why)),
            PartState::Intact(manifest, _) => match task::staleness(&manifest, now) {
                Some(why) => TaskStatus::Stale(of_frame(why)),
                None => TaskStatus::Done,
            },
        };
        let rank = |s: &TaskStatus| match s {
            TaskStatus::Done => 0,
            TaskStatus::Missing => 1,
            TaskStatus::Stale(_) => 2,
            TaskStatus::Corrupt(_) => 3,
        };
        if rank(&status) > rank(&worst) {
            worst = status;
        }
    }
    worst
}

/// `whitted farm status DIR`: one line per task, a summary, and exit 1 unless every task
/// is done.
fn status(args: &FarmDirArgs) -> Result<(), Failure> {
    let plan = read_plan(&args.dir)?;
    let (_, _, now) = compile_plan_scene(&plan)?;
    let parts = Path::new(&plan.parts);
    let (mut done, mut missing, mut stale, mut corrupt) = (0u32, 0u32, 0u32, 0u32);
    let mut text = String::new();
    let frames = plan.frame_range();
    for task in 0..plan.tasks {
        let index = task::TaskIndex {
            index: task,
            count: plan.tasks,
        };
        let share = task::share(frames.as_ref(), index).map_err(Failure::Message)?;
        let line = match task_status(parts, index, &share.frames, &now) {
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
