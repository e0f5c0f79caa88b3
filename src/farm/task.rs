//! `whitted render SCENE --task I/N`: render one task of a still or an animation split into
//! N parts of about the same cost, and write it with its manifests into the parts folder.
//!
//! Every task works the plan out on its own (`whitted_tracer::task_plan`, a pure function
//! of the compiled scene and N), so tasks need no coordinator; the merge checks that the
//! parts they wrote cover the image exactly once.

use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};
use whitted_ir::ValidScene;
use whitted_tracer::{PreparedScene, RenderOptions};

use crate::cli::{RenderArgs, SceneArgs};
use crate::farm::part::{self, hex, Manifest, PartState, Region, MANIFEST_FORMAT};
use crate::scene_input::{load_scene, Loaded};
use crate::setting_flags::apply_render_flags;
use crate::Failure;

/// Task `index` of `count`, `index` counted from 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TaskIndex {
    pub index: u32,
    pub count: u32,
}

/// `I/N` of `--task`: two whole numbers, N at least 1 and I below N.
pub fn parse_task(text: &str) -> Result<TaskIndex, String> {
    let usage = || {
        format!("`{text}` is not a task: write I/N, task I of N counted from 0 (for example --task 0/4 .. --task 3/4)")
    };
    let (index, count) = text.split_once('/').ok_or_else(usage)?;
    let index = index.trim().parse::<u32>().map_err(|_| usage())?;
    let count = count.trim().parse::<u32>().map_err(|_| usage())?;
    check_task(index, count)
}

fn check_task(index: u32, count: u32) -> Result<TaskIndex, String> {
    if count == 0 {
        return Err("a render split into 0 tasks has nothing to do: N must be at least 1".into());
    }
    if index >= count {
        return Err(format!(
            "task {index} of {count} does not exist: tasks count from 0, so the last is {}",
            count - 1
        ));
    }
    Ok(TaskIndex { index, count })
}

/// The environment variables `--task-from-env` reads, in order: the index and where the
/// count comes from.
const ARRAY_VARIABLES: [(&str, Option<&str>); 3] = [
    ("SLURM_ARRAY_TASK_ID", Some("SLURM_ARRAY_TASK_COUNT")),
    (
        "AWS_BATCH_JOB_ARRAY_INDEX",
        Some("AWS_BATCH_JOB_ARRAY_SIZE"),
    ),
    // Kubernetes' Indexed Jobs give the index only: the count is --tasks or WHITTED_TASKS.
    ("JOB_COMPLETION_INDEX", None),
];

/// The task `--task-from-env` names: the first array index set among
/// [`ARRAY_VARIABLES`], and the count from `--tasks`, else the engine's own count variable,
/// else `WHITTED_TASKS`.
pub fn task_from_env(
    tasks_flag: Option<u32>,
    var: impl Fn(&str) -> Option<String>,
) -> Result<TaskIndex, Failure> {
    let Some((index_name, count_name, index_text)) = ARRAY_VARIABLES
        .iter()
        .find_map(|&(name, count)| var(name).map(|value| (name, count, value)))
    else {
        return Err(Failure::Usage(
            "--task-from-env: none of SLURM_ARRAY_TASK_ID, AWS_BATCH_JOB_ARRAY_INDEX or \
             JOB_COMPLETION_INDEX is set; give --task I/N instead"
                .into(),
        ));
    };
    let index = index_text.trim().parse::<u32>().map_err(|_| {
        Failure::Usage(format!(
            "--task-from-env: {index_name}={index_text:?} is not a task index"
        ))
    })?;
    let count = match tasks_flag {
        Some(count) => count,
        None => {
            let (name, text) = count_name
                .and_then(|name| var(name).map(|text| (name, text)))
                .or_else(|| var("WHITTED_TASKS").map(|text| ("WHITTED_TASKS", text)))
                .ok_or_else(|| {
                    Failure::Usage(format!(
                        "--task-from-env: {index_name} is set but not the number of tasks: \
                         give --tasks N or set WHITTED_TASKS"
                    ))
                })?;
            text.trim().parse::<u32>().map_err(|_| {
                Failure::Usage(format!(
                    "--task-from-env: {name}={text:?} is not a number of tasks"
                ))
            })?
        }
    };
    check_task(index, count).map_err(|e| Failure::Usage(format!("--task-from-env: {e}")))
}

/// What identifies the scene a part was rendered from.
pub struct Fingerprint {
    pub scene_hash: String,
    pub settings_hash: String,
    pub settings: serde_json::Value,
}

/// Feeds what is written into a hash.
struct HashWriter<'a>(&'a mut Sha256);

impl std::io::Write for HashWriter<'_> {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.0.update(bytes);
        Ok(bytes.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The scene's fingerprint: SHA-256 of every source file's text (the scene, its imports
/// and the pseudo-files of the command line's settings, in the source map's order) and of
/// the compiled IR's JSON (settings, `-D` and `--set` included), so any change to what is
/// rendered, and any edit of the files, changes it.
pub fn fingerprint(scene: &ValidScene) -> Fingerprint {
    let mut hasher = Sha256::new();
    for (_, file) in scene.sources.files() {
        hasher.update((file.text.len() as u64).to_le_bytes());
        hasher.update(file.text.as_bytes());
    }
    // Serialising plain data into a hash cannot fail; were it to, the hash still differs.
    let _ = serde_json::to_writer(HashWriter(&mut hasher), &whitted_ir::json_document(scene));
    let settings = serde_json::to_value(&scene.settings).unwrap_or(serde_json::Value::Null);
    let settings_hash = hex(&Sha256::digest(settings.to_string().as_bytes()));
    Fingerprint {
        scene_hash: hex(&hasher.finalize()),
        settings_hash,
        settings,
    }
}

/// Why an intact part cannot stand for the scene as it is now, if it cannot.
pub fn staleness(manifest: &Manifest, now: &Fingerprint) -> Option<String> {
    if manifest.format != MANIFEST_FORMAT {
        return Some(format!(
            "manifest format {} (this whitted writes {MANIFEST_FORMAT})",
            manifest.format
        ));
    }
    if manifest.whitted_version != env!("CARGO_PKG_VERSION") {
        return Some(format!(
            "rendered by whitted {} (this is {})",
            manifest.whitted_version,
            env!("CARGO_PKG_VERSION")
        ));
    }
    if manifest.settings_hash != now.settings_hash {
        return Some("rendered with other settings than the scene has now".into());
    }
    if manifest.scene_hash != now.scene_hash {
        return Some("rendered from another scene (its files or -D values changed since)".into());
    }
    None
}

/// The scene path made absolute, so that the fingerprint (whose IR names its files) is the
/// same whichever folder a task runs in.
pub fn absolute_scene(scene: &Path) -> Result<PathBuf, Failure> {
    std::fs::canonicalize(scene)
        .map_err(|e| Failure::Message(format!("cannot read {}: {e}", scene.display())))
}

/// What one task renders: some frames (a still is the one frame `None`), and of each
/// frame one band of rows.
#[derive(Clone, Debug, PartialEq)]
pub struct Share {
    pub frames: Vec<Option<u32>>,
    /// The band of each frame: band `index` of `count` (a count of 1 is the whole image).
    pub band: TaskIndex,
}

/// Task `task`'s share of a render of `frames` (`None`: a still). A still is cut into N
/// bands. An animation of F frames is cut into whole frames when N <= F (contiguous runs of
/// F/N frames, give or take one), or, when N is a multiple of F, each frame into N/F bands.
pub fn share(frames: Option<&RangeInclusive<u32>>, task: TaskIndex) -> Result<Share, String> {
    let Some(range) = frames else {
        return Ok(Share {
            frames: vec![None],
            band: task,
        });
    };
    let count = u64::from(*range.end()) - u64::from(*range.start()) + 1;
    let (index, tasks) = (u64::from(task.index), u64::from(task.count));
    let frame = |k: u64| Some(range.start() + k as u32);
    if tasks <= count {
        let (first, end) = (index * count / tasks, (index + 1) * count / tasks);
        Ok(Share {
            frames: (first..end).map(frame).collect(),
            band: TaskIndex { index: 0, count: 1 },
        })
    } else if tasks % count == 0 {
        let per = (tasks / count) as u32;
        Ok(Share {
            frames: vec![frame(index / u64::from(per))],
            band: TaskIndex {
                index: task.index % per,
                count: per,
            },
        })
    } else {
        Err(format!(
            "an animation of {count} frames splits into at most {count} tasks of whole frames, \
             or into a multiple of {count} tasks (each frame in bands of rows); {tasks} is neither"
        ))
    }
}

/// The frames a render covers: `--frames`, else the scene's own range when it is animated
/// and no single `--frame` was asked for; `None` for a still.
pub fn render_frames(
    frames: Option<RangeInclusive<u32>>,
    scene: &SceneArgs,
    loaded: &Loaded,
) -> Option<RangeInclusive<u32>> {
    frames.or_else(|| {
        (scene.frame.is_none() && loaded.scene.settings.is_animated())
            .then(|| crate::animation::frame_range(loaded))
    })
}

/// `scene` compiled at `frame` (as it is, for a still).
pub fn load_frame(scene: &SceneArgs, frame: Option<u32>, quiet: bool) -> Result<Loaded, Failure> {
    match frame {
        None => load_scene(scene, quiet),
        Some(frame) => load_scene(
            &SceneArgs {
                frame: Some(frame),
                ..scene.clone()
            },
            quiet,
        ),
    }
}

/// Whether task `task`'s part of `frame` is intact and made from the scene as it is now.
fn is_fresh(parts: &Path, task: TaskIndex, frame: Option<u32>, now: &Fingerprint) -> bool {
    match part::read_part(parts, task.index, task.count, frame, false) {
        PartState::Intact(manifest, _) => staleness(&manifest, now).is_none(),
        _ => false,
    }
}

/// `whitted render --task I/N` (or `--task-from-env`): the task's share of a still or an
/// animation, each frame's band written as a part with its manifest.
pub fn render_task(args: &RenderArgs) -> Result<(), Failure> {
    let task = match args.task {
        Some(task) => task,
        None => task_from_env(args.tasks, |name| std::env::var(name).ok())?,
    };
    crate::interrupt::install();
    let mut scene_args = args.scene.clone();
    scene_args.scene = absolute_scene(&args.scene.scene)?;
    let loaded = load_scene(&scene_args, args.quiet)?;
    let frames = render_frames(args.frames.clone(), &scene_args, &loaded);
    let share = share(frames.as_ref(), task)
        .map_err(|e| Failure::Usage(format!("--task {}/{}: {e}", task.index, task.count)))?;
    // Parts are checked against the scene at the render's first frame: every other frame
    // is made from the same files, flags and whitted.
    let first = frames.as_ref().map(|r| *r.start());
    let first_loaded = match first {
        Some(frame) if scene_args.frame != Some(frame) => {
            load_frame(&scene_args, Some(frame), true)?
        }
        _ => loaded,
    };
    let first_loaded = apply_render_flags(first_loaded, &args.overrides)?;
    let now = fingerprint(&first_loaded.0.scene);
    // The scene compiled above serves its own frame, once.
    let mut first_loaded = Some(first_loaded);
    std::fs::create_dir_all(&args.parts)
        .map_err(|e| Failure::Message(format!("cannot create {}: {e}", args.parts.display())))?;
    let say = |text: String| {
        if !args.quiet {
            eprintln!("{text}");
        }
    };
    let name = |frame: Option<u32>| match frame {
        None => format!("task {}/{}", task.index, task.count),
        Some(f) => format!("task {}/{}, frame {f}", task.index, task.count),
    };
    let pool = crate::render_cmd::thread_pool(args.threads)?;
    let scene_path = scene_args.scene.display().to_string();
    for frame in share.frames {
        if !args.force && is_fresh(&args.parts, task, frame, &now) {
            say(format!(
                "{}: its part in {} is complete and up to date; nothing to do (--force renders \
                 it again)",
                name(frame),
                args.parts.display()
            ));
            continue;
        }
        let compiled = if frame == first {
            first_loaded.take()
        } else {
            None
        };
        let (loaded, options) = match compiled {
            Some(compiled) => compiled,
            None => apply_render_flags(load_frame(&scene_args, frame, true)?, &args.overrides)?,
        };
        let prepared = pool.install(|| PreparedScene::new_releasing_ir(loaded.scene));
        let region = if share.band.count == 1 {
            whitted_tracer::PixelRect::whole(options.width, options.height)
        } else {
            plan_region(&pool, &prepared, &options, share.band)?
        };
        let rendered = pool.install(|| {
            whitted_tracer::render_region(&prepared, &options, region, &whitted_tracer::NoObserver)
        });
        let Some((image, stats)) = rendered else {
            return Err(Failure::Message(
                "the render was cancelled; nothing was written".into(),
            ));
        };
        let manifest = Manifest {
            format: MANIFEST_FORMAT,
            whitted_version: env!("CARGO_PKG_VERSION").to_string(),
            scene: scene_path.clone(),
            scene_hash: now.scene_hash.clone(),
            settings_hash: now.settings_hash.clone(),
            settings: now.settings.clone(),
            task: task.index,
            tasks: task.count,
            frame,
            image_width: options.width,
            image_height: options.height,
            region: Region::from(region),
            pixels_file: String::new(),
            checksum: String::new(),
            rays: stats.total_rays(),
            render_seconds: stats.render_seconds,
        };
        part::write_part(&args.parts, manifest, &image.pixels).map_err(Failure::Message)?;
        say(format!(
            "{}: rows {}..{} written to {}",
            name(frame),
            region.y,
            region.y + region.height,
            args.parts.display()
        ));
    }
    Ok(())
}

/// Task `task`'s pixels under the plan every task works out alike.
pub fn plan_region(
    pool: &rayon::ThreadPool,
    prepared: &PreparedScene,
    options: &RenderOptions,
    task: TaskIndex,
) -> Result<whitted_tracer::PixelRect, Failure> {
    let regions = pool
        .install(|| whitted_tracer::task_plan::plan_regions(prepared, options, task.count))
        .map_err(|e| Failure::Usage(format!("--task {}/{}: {e}", task.index, task.count)))?;
    regions.get(task.index as usize).copied().ok_or_else(|| {
        Failure::Usage(format!(
            "task {} of {} does not exist",
            task.index, task.count
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tasks_are_i_of_n_counted_from_zero() {
        assert_eq!(parse_task("0/4"), Ok(TaskIndex { index: 0, count: 4 }));
        assert_eq!(parse_task(" 3 / 4"), Ok(TaskIndex { index: 3, count: 4 }));
        assert!(parse_task("4/4").unwrap_err().contains("the last is 3"));
        assert!(parse_task("0/0").unwrap_err().contains("at least 1"));
        assert!(parse_task("x").unwrap_err().contains("not a task"));
        assert!(parse_task("-1/3").is_err());
        assert!(parse_task("1/2/3").is_err());
    }

    fn task(index: u32, count: u32) -> TaskIndex {
        TaskIndex { index, count }
    }

    #[test]
    fn an_animation_splits_into_whole_frames_or_bands_of_every_frame() {
        // A still: band I of N.
        let still = share(None, task(2, 5)).unwrap();
        assert_eq!((still.frames, still.band), (vec![None], task(2, 5)));
        // 10 frames from 3 in 4 tasks: runs of 2 or 3 whole frames, every frame once.
        let frames = 3..=12;
        let runs: Vec<Vec<Option<u32>>> = (0..4)
            .map(|i| share(Some(&frames), task(i, 4)).unwrap().frames)
            .collect();
        assert_eq!(
            runs,
            vec![
                vec![Some(3), Some(4)],
                vec![Some(5), Some(6), Some(7)],
                vec![Some(8), Some(9)],
                vec![Some(10), Some(11), Some(12)],
            ]
        );
        assert_eq!(share(Some(&frames), task(3, 4)).unwrap().band, task(0, 1));
        // 10 tasks of 10 frames: one frame each; 30: three bands of each frame.
        assert_eq!(
            share(Some(&frames), task(9, 10)).unwrap().frames,
            vec![Some(12)]
        );
        let banded = share(Some(&frames), task(7, 30)).unwrap();
        assert_eq!((banded.frames, banded.band), (vec![Some(5)], task(1, 3)));
        // 15 tasks of 10 frames is neither.
        let refused = share(Some(&frames), task(0, 15)).unwrap_err();
        assert!(refused.contains("multiple of 10"), "{refused}");
        // One frame and the largest frame numbers do not overflow.
        let last = u32::MAX - 1..=u32::MAX;
        assert_eq!(
            share(Some(&last), task(1, 2)).unwrap().frames,
            vec![Some(u32::MAX)]
        );
    }

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |name| {
            pairs
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn the_environment_names_the_task_of_each_engine() {
        let slurm = [
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "5"),
        ];
        assert_eq!(
            task_from_env(None, env(&slurm)).ok(),
            Some(TaskIndex { index: 2, count: 5 })
        );
        // --tasks wins over the array's own count (a resubmitted subset has fewer).
        assert_eq!(
            task_from_env(Some(8), env(&slurm)).ok(),
            Some(TaskIndex { index: 2, count: 8 })
        );
        let k8s = [("JOB_COMPLETION_INDEX", "6"), ("WHITTED_TASKS", "7")];
        assert_eq!(
            task_from_env(None, env(&k8s)).ok(),
            Some(TaskIndex { index: 6, count: 7 })
        );
        let aws = [
            ("AWS_BATCH_JOB_ARRAY_INDEX", "0"),
            ("AWS_BATCH_JOB_ARRAY_SIZE", "3"),
        ];
        assert_eq!(
            task_from_env(None, env(&aws)).ok(),
            Some(TaskIndex { index: 0, count: 3 })
        );
        assert!(task_from_env(None, env(&[("JOB_COMPLETION_INDEX", "1")])).is_err());
        assert!(task_from_env(None, env(&[])).is_err());
        assert!(task_from_env(Some(3), env(&[("JOB_COMPLETION_INDEX", "3")])).is_err());
        assert!(task_from_env(Some(3), env(&[("JOB_COMPLETION_INDEX", "x")])).is_err());
    }
}
