//! Command-line syntax: every subcommand and flag, parsed by clap.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use whitted_ir::limits;

#[derive(Parser)]
#[command(
    name = "whitted",
    version,
    about = "A Whitted ray tracer that can explain every pixel"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Render a scene to an image (.png, .exr, .hdr, .ppm or .tga).
    Render(RenderArgs),
    /// Compile, validate and lint a scene; print its diagnostics and warnings.
    Check(CheckArgs),
    /// Print the compiled IR of a scene, as text or JSON.
    Ir(IrArgs),
    /// Record every ray behind one pixel and print its ray tree, as text or JSON.
    Trace(TraceArgs),
    /// Explain one pixel: the light paths that make its colour, and what may be wrong.
    Explain(ExplainArgs),
    /// Compare one pixel's ray trees under two scenes or settings, or an image with
    /// whitted's render (docs/diff.md).
    Diff(DiffArgs),
    /// Say which classic tracer bug explains a student's image (docs/courses.md), or grade
    /// a class: --class DIR --commands FILE.
    Grade(GradeArgs),
    /// Find the pixels whose rays match a predicate, e.g. 'tir and not hit("floor")'
    /// (docs/query.md).
    Query(QueryArgs),
    /// Explore a scene in the terminal: pick a pixel, walk its ray tree, see the source.
    Debug(DebugArgs),
    /// Lay scene files out in the one canonical way, in place (comments kept, meaning
    /// unchanged); with --check, change nothing and show what would change.
    Fmt(FmtArgs),
    /// Run the MIT 6.837 course's command line, flags as it wrote them (see -help).
    ///
    /// whitted mit6837 -input scene.txt -size 200 200 -output out.tga [-shadows] ...
    #[command(disable_help_flag = true)]
    Mit6837(Mit6837Args),
    /// Run the language server on stdin and stdout, for editors (docs/editors.md):
    /// diagnostics, hover, completion, go to definition and the outline.
    Lsp,
    /// Split a render into tasks for a laptop, Slurm or Kubernetes, follow them, and merge
    /// their parts into the image a single render makes, byte for byte (docs/farm.md).
    Farm(FarmArgs),
}

#[derive(Args)]
pub struct FarmArgs {
    #[command(subcommand)]
    pub command: FarmCommand,
}

#[derive(Subcommand)]
pub enum FarmCommand {
    /// Plan a render as N tasks: write DIR/plan.json and the engine's job files (shell:
    /// run.sh; slurm: task.sbatch, merge.sbatch, submit.sh; k8s: job.yaml).
    Plan(Box<FarmPlanArgs>),
    /// Run a shell plan here (DIR/run.sh): the tasks not yet done, then the merge.
    Run(FarmDirArgs),
    /// List each task as done, missing, stale (the scene or settings changed) or corrupt;
    /// exit 1 unless every task is done.
    Status(FarmDirArgs),
    /// Assemble the parts into one image, byte-identical to `whitted render`'s; refuses
    /// parts of another scene, settings or whitted, and missing or overlapping pixels.
    Merge(FarmMergeArgs),
}

/// Where a farm's tasks run.
#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum Engine {
    /// run.sh on this machine, `--jobs` tasks at a time (xargs -P).
    Shell,
    /// A Slurm array job and a merge job that waits for it (sbatch).
    Slurm,
    /// A Kubernetes Indexed Job (batch/v1).
    K8s,
}

impl Engine {
    pub fn name(self) -> &'static str {
        match self {
            Engine::Shell => "shell",
            Engine::Slurm => "slurm",
            Engine::K8s => "k8s",
        }
    }
}

#[derive(Args)]
pub struct FarmPlanArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub overrides: RenderOverrides,
    /// How many tasks to split the render into (at most one per row of the image).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub tasks: u32,
    /// Render these frames of an animation, A..=B (default: the scene's own frames when it
    /// is animated). Tasks take whole frames, or, when --tasks is a multiple of the frame
    /// count, bands of each frame.
    #[arg(long, value_name = "A..=B", value_parser = parse_frames, conflicts_with = "frame")]
    pub frames: Option<std::ops::RangeInclusive<u32>>,
    /// Where the tasks run.
    #[arg(long, value_enum, default_value_t = Engine::Shell)]
    pub engine: Engine,
    /// The farm folder: plan.json, the job files, parts/ and logs/ go here.
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    pub dir: PathBuf,
    /// The merged image (shell and slurm; default DIR/SCENE.png).
    #[arg(long, value_name = "OUT", value_parser = parse_output)]
    pub merged: Option<PathBuf>,
    /// shell: tasks run at once (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub jobs: Option<u32>,
    /// slurm, k8s: at most this many tasks at once (Slurm's `--array=0-N%C`, the Job's
    /// parallelism).
    #[arg(long, value_name = "C", value_parser = clap::value_parser!(u32).range(1..))]
    pub max_concurrent: Option<u32>,
    /// Worker threads per task (slurm: its --cpus-per-task; default 1 there, and one per
    /// core elsewhere).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// k8s: the container image with `whitted` on its PATH.
    #[arg(long, value_name = "IMAGE", default_value = "whitted:latest")]
    pub container_image: String,
    /// k8s: the PersistentVolumeClaim mounted at /farm, holding the scene and the parts.
    #[arg(long, value_name = "NAME", default_value = "whitted-farm")]
    pub pvc: String,
    /// k8s: the scene's path inside the container (default /farm/ and its file name).
    #[arg(long, value_name = "PATH")]
    pub container_scene: Option<String>,
}

#[derive(Args)]
pub struct FarmDirArgs {
    /// The farm folder made by `whitted farm plan`.
    pub dir: PathBuf,
}

#[derive(Args)]
pub struct FarmMergeArgs {
    /// The farm folder made by `whitted farm plan`.
    pub dir: PathBuf,
    /// The image to write; the extension picks the format, as for `whitted render`.
    #[arg(short = 'o', long = "output", value_name = "OUT", value_parser = parse_output)]
    pub output: PathBuf,
    /// Render a sample of pixels again and compare them with the parts bit for bit.
    #[arg(long)]
    pub verify: bool,
    /// With --verify: how many pixels (a fixed pseudo-random sample).
    #[arg(long, value_name = "K", default_value_t = 64, requires = "verify")]
    pub samples: u32,
}

#[derive(Args)]
pub struct FmtArgs {
    /// The .scene files to format in place, or folders to format every .scene file in;
    /// `-` or none: read standard input and write the formatted text to standard output.
    pub files: Vec<PathBuf>,
    /// Write nothing: print a diff of every change formatting would make, and exit 1 if
    /// there is one.
    #[arg(long)]
    pub check: bool,
}

/// Everything after `whitted mit6837`, read by the course's own flag rules
/// (`src/mit6837_cmd.rs`), not by clap's.
#[derive(Args)]
pub struct Mit6837Args {
    #[arg(num_args = 0.., allow_hyphen_values = true, trailing_var_arg = true, value_name = "FLAGS")]
    pub args: Vec<std::ffi::OsString>,
}

/// The scene file and the `-D` overrides every scene-reading command takes.
#[derive(Args, Clone, Debug)]
pub struct SceneArgs {
    /// The .scene file, or a MIT 6.837 scene file (.txt; recognised by its first word).
    pub scene: PathBuf,
    /// Override a top-level `const`: -D N=316 (VALUE is an expression).
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
    pub define: Vec<(String, String)>,
    /// Replace a setting of the scene: --set max_depth=8, --set highlight=blinn,
    /// --set background=rgb(0,0,0.2) (any setting of docs/language.md; checked like the
    /// scene's own).
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = parse_setting)]
    pub set: Vec<(String, String)>,
    /// Compile this frame of an animation: the scene's `frame` is N and `clock` its place
    /// in the scene's frame range (docs/language.md, "Animation"). Default: the first frame.
    #[arg(long, value_name = "N")]
    pub frame: Option<u32>,
}

#[derive(Args)]
pub struct CheckArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Skip the lints: report only the compiler's errors and warnings (docs/explain.md,
    /// "Lints").
    #[arg(long, conflicts_with = "lint")]
    pub no_lint: bool,
    /// Lint even a scene of more than 50,000 objects, which is skipped otherwise (the lints
    /// then cost more than the check).
    #[arg(long)]
    pub lint: bool,
}

#[derive(Args)]
pub struct IrArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
pub enum StatsFormat {
    Text,
    Json,
}

#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output image; the extension picks the format: .png (8-bit sRGB), .exr and .hdr
    /// (linear float), .ppm and .tga (8-bit sRGB). Default: the scene's name with .png, here.
    /// An animation writes one image per frame through a pattern (`out/frame-{frame:04}.png`;
    /// an existing folder: NAME-{frame:04}.png in it), or one animated .apng or .gif, or a
    /// video (.mp4, .webm; needs ffmpeg).
    #[arg(short = 'o', long = "output", value_name = "OUT", value_parser = parse_render_output)]
    pub output: Option<PathBuf>,
    /// Render these frames of an animation, A..=B (or A..B, B excluded; or one frame N),
    /// rather than the scene's whole range; `clock` stays that of the scene's range.
    #[arg(long, value_name = "A..=B", value_parser = parse_frames, conflicts_with = "frame")]
    pub frames: Option<std::ops::RangeInclusive<u32>>,
    #[command(flatten)]
    pub overrides: RenderOverrides,
    /// Worker threads (default: one per core). The image is identical for any count.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Print ray counts, timings and rays per second (text, or --stats=json).
    #[arg(long, value_name = "FORMAT", num_args = 0..=1, default_missing_value = "text")]
    pub stats: Option<StatsFormat>,
    /// Also write per-pixel statistics as a heat-map image: rays per pixel, deepest level
    /// and cut-off terminations, side by side (see docs/ray-tree.md).
    #[arg(long, value_name = "OUT", value_parser = parse_output)]
    pub stats_image: Option<PathBuf>,
    /// Print nothing but errors (no progress bar, no warnings).
    #[arg(long, short = 'q')]
    pub quiet: bool,
    /// Skip the lints `whitted check` also prints (docs/explain.md, "Lints").
    #[arg(long)]
    pub no_lint: bool,
    /// Render only task I of N, I counted from 0 (0/4, 1/4, 2/4, 3/4): a band of rows of
    /// about 1/N of the cost, written with its manifest into --parts (docs/farm.md).
    #[arg(long, value_name = "I/N", value_parser = crate::farm::task::parse_task,
          conflicts_with_all = ["task_from_env", "output", "stats_image", "stats"],
          group = "one_task")]
    pub task: Option<crate::farm::task::TaskIndex>,
    /// Take the task from the job array's environment: SLURM_ARRAY_TASK_ID,
    /// AWS_BATCH_JOB_ARRAY_INDEX or JOB_COMPLETION_INDEX, the count from --tasks, the
    /// array's own count variable, or WHITTED_TASKS. Without this flag, a render inside an
    /// array job renders the whole image.
    #[arg(long, conflicts_with_all = ["output", "stats_image", "stats"], group = "one_task")]
    pub task_from_env: bool,
    /// With --task-from-env: the number of tasks.
    #[arg(long, value_name = "N", requires = "task_from_env",
          value_parser = clap::value_parser!(u32).range(1..))]
    pub tasks: Option<u32>,
    /// With --task: the folder the part and its manifest go to.
    #[arg(
        long,
        value_name = "DIR",
        default_value = "parts",
        requires = "one_task"
    )]
    pub parts: PathBuf,
    /// With --task: render even when a complete, fresh part is already there.
    #[arg(long, requires = "one_task")]
    pub force: bool,
}

/// The scene settings that `render` and `trace` may override, so that a trace can follow a
/// render made at another size.
#[derive(Args, Clone, Debug, Default)]
pub struct RenderOverrides {
    /// Image width in pixels (overrides the scene's settings).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(limits::MAX_IMAGE_SIDE)))]
    pub width: Option<u32>,
    /// Image height in pixels (overrides the scene's settings).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(limits::MAX_IMAGE_SIDE)))]
    pub height: Option<u32>,
    /// Samples per pixel, on a stratified pattern (overrides the scene's settings).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(limits::MAX_SAMPLES_PER_PIXEL)))]
    pub spp: Option<u32>,
    /// Maximum recursion depth; the camera ray is depth 0 (overrides the scene's settings).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=i64::from(limits::MAX_DEPTH)))]
    pub max_depth: Option<u32>,
}

#[derive(Args)]
pub struct TraceArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// The pixel to trace: X,Y counted from the top-left corner (0,0).
    // Hyphen values reach the parser so that `-1,3` gets its message, not "unexpected argument".
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel, allow_hyphen_values = true)]
    pub pixel: [u32; 2],
    /// Record only this sample of the pixel (default: every sample).
    #[arg(long, value_name = "K")]
    pub sample: Option<u32>,
    /// Print the versioned JSON document (docs/ray-tree.md) instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub overrides: RenderOverrides,
    /// Compare the pixel's ray tree with its tree in this scene (as `whitted diff`).
    #[arg(long, value_name = "SCENE_B")]
    pub against: Option<PathBuf>,
    /// Compare the pixel's ray tree with its tree under this setting (repeatable; as
    /// `whitted diff --against-set`).
    #[arg(long = "against-set", value_name = "NAME=VALUE", value_parser = parse_setting)]
    pub against_set: Vec<(String, String)>,
}

#[derive(Args)]
pub struct DiffArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// The scene to compare with (compiled with the same -D and --set).
    #[arg(value_name = "SCENE_B")]
    pub other: Option<PathBuf>,
    /// The pixel whose ray trees to compare: X,Y counted from the top-left corner (0,0).
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel, allow_hyphen_values = true)]
    pub pixel: Option<[u32; 2]>,
    /// Compare with the same scene (or SCENE_B) under this setting too: --against-set
    /// max_depth=8 (repeatable).
    #[arg(long = "against-set", value_name = "NAME=VALUE", value_parser = parse_setting)]
    pub against_set: Vec<(String, String)>,
    /// Compare a student's image (PNG, TGA, PPM or EXR, the scene's size) with whitted's
    /// render, the reference: list the regions that differ and read a pixel of each from
    /// the student's side.
    #[arg(long = "against-image", value_name = "STUDENT.tga")]
    pub against_image: Option<PathBuf>,
    /// With --against-image: compare in 8-bit linear values (colour times 255), as the MIT
    /// 6.837 course wrote images (the default for a 6.837 scene).
    #[arg(long, conflicts_with = "srgb")]
    pub linear: bool,
    /// With --against-image: compare in 8-bit sRGB, as `whitted render` writes PNG, TGA and
    /// PPM (the default for a scene in whitted's language).
    #[arg(long)]
    pub srgb: bool,
    /// With --against-image: the largest difference (in 8-bit steps, any channel) that
    /// still counts as equal.
    #[arg(long, default_value_t = 8)]
    pub tolerance: u8,
    /// With --against-image: explain at most this many regions (the largest).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub regions: u32,
    /// Print a versioned JSON document instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub overrides: RenderOverrides,
}

#[derive(Args)]
pub struct GradeArgs {
    /// The scene (.scene, or the course's .txt) the student rendered; with --command, the
    /// student's image.
    #[arg(value_name = "SCENE", required_unless_present = "class")]
    pub scene: Option<PathBuf>,
    /// The student's image (PNG, TGA, PPM or EXR, the scene's size).
    #[arg(value_name = "IMAGE")]
    pub image: Option<PathBuf>,
    /// The course's command line that made the reference, instead of SCENE and --set:
    /// --command "raytracer -input scene4_03.txt -size 200 200 -shadows -bounces 4".
    #[arg(long, value_name = "LINE", allow_hyphen_values = true, conflicts_with_all = ["define", "set", "class"])]
    pub command: Option<String>,
    /// Override a top-level `const`: -D N=316.
    #[arg(short = 'D', value_name = "NAME=VALUE", value_parser = parse_define)]
    pub define: Vec<(String, String)>,
    /// Replace a setting of the scene: --set shadows=opaque (the course's -shadows).
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = parse_setting)]
    pub set: Vec<(String, String)>,
    /// Compare in 8-bit linear values (colour times 255), as the MIT 6.837 course wrote
    /// images (the default for a 6.837 scene).
    #[arg(long, conflicts_with = "srgb")]
    pub linear: bool,
    /// Compare in 8-bit sRGB, as `whitted render` writes (the default for whitted's scenes).
    #[arg(long)]
    pub srgb: bool,
    /// The largest difference (8-bit steps, any channel) that still counts as equal.
    #[arg(long, default_value_t = 8)]
    pub tolerance: u8,
    /// Write the picture student | reference | best model | residual (x4) here (.png).
    #[arg(long, value_name = "OUT.png", value_parser = parse_output)]
    pub picture: Option<PathBuf>,
    /// List at most this many explanations.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub top: u32,
    /// Print a versioned JSON document instead of text.
    #[arg(long)]
    pub json: bool,
    /// Grade a class: a folder with one folder of images per student, named as the
    /// command lines of --commands write them.
    #[arg(long, value_name = "DIR", requires = "commands", conflicts_with_all = ["scene", "image", "picture", "json"])]
    pub class: Option<PathBuf>,
    /// With --class: the assignment's command lines, one per line, as the course wrote
    /// them (`raytracer -input scene4_03.txt -size 200 200 -output output4_03.tga
    /// -shadows`); scene paths are relative to this file.
    #[arg(long, value_name = "FILE")]
    pub commands: Option<PathBuf>,
    /// With --class: where the report goes (default: DIR/grade-report). Students already
    /// graded there, with the same images, are not graded again.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    #[command(flatten)]
    pub overrides: RenderOverrides,
}

#[derive(Args)]
pub struct QueryArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// The predicate (docs/query.md), e.g. 'shadow_blocked_by("glass") or depth >= 5'.
    #[arg(value_name = "EXPR")]
    pub expr: String,
    /// Write the matching pixels as a white-on-black mask image (.png).
    #[arg(long, value_name = "OUT", value_parser = parse_output)]
    pub mask: Option<PathBuf>,
    /// List at most this many matching pixels (the count covers all of them).
    #[arg(long, default_value_t = 20)]
    pub limit: usize,
    /// Print a versioned JSON document instead of text.
    #[arg(long)]
    pub json: bool,
    /// Worker threads (default: one per core). The answer is identical for any count.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    #[command(flatten)]
    pub overrides: RenderOverrides,
}

#[derive(Args)]
pub struct ExplainArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// The pixel to explain: X,Y counted from the top-left corner (0,0).
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel, allow_hyphen_values = true)]
    pub pixel: [u32; 2],
    /// Print the versioned JSON document (docs/explain.md) instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub overrides: RenderOverrides,
}

#[derive(Args)]
pub struct DebugArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// A pixel to trace at start: X,Y counted from the top-left corner (0,0).
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel, allow_hyphen_values = true)]
    pub pixel: Option<[u32; 2]>,
    #[command(flatten)]
    pub overrides: RenderOverrides,
}

fn parse_pixel(text: &str) -> Result<[u32; 2], String> {
    let usage = || format!("`{text}` is not a pixel: write X,Y (for example --pixel 400,270)");
    let (x, y) = text.split_once(',').ok_or_else(usage)?;
    let x = x.trim().parse::<u32>().map_err(|_| usage())?;
    let y = y.trim().parse::<u32>().map_err(|_| usage())?;
    Ok([x, y])
}

fn parse_define(text: &str) -> Result<(String, String), String> {
    let Some((name, value)) = text.split_once('=') else {
        return Err(format!("`{text}` is not NAME=VALUE (for example -D N=316)"));
    };
    let name = name.trim();
    let valid_name = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !valid_name {
        return Err(format!("`{name}` is not a valid constant name"));
    }
    if value.trim().is_empty() {
        return Err(format!("-D {name}= needs a value after `=`"));
    }
    Ok((name.to_string(), value.to_string()))
}

/// `NAME=VALUE` of a `--set`; the name and value are checked by the compiler, which knows
/// the settings and points into the text in its diagnostics.
fn parse_setting(text: &str) -> Result<(String, String), String> {
    let Some((name, value)) = text.split_once('=') else {
        return Err(format!(
            "`{text}` is not NAME=VALUE (for example --set max_depth=8)"
        ));
    };
    if value.trim().is_empty() {
        return Err(format!("--set {name}= needs a value after `=`"));
    }
    Ok((name.trim().to_string(), value.to_string()))
}

/// The image formats `render` can write, chosen by the output's extension.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Exr,
    Hdr,
    Ppm,
    /// Uncompressed 24-bit Targa, the MIT 6.837 course's format.
    Tga,
}

impl ImageFormat {
    pub fn from_path(path: &std::path::Path) -> Option<ImageFormat> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        match extension.as_str() {
            "png" => Some(ImageFormat::Png),
            "exr" => Some(ImageFormat::Exr),
            "hdr" => Some(ImageFormat::Hdr),
            "ppm" => Some(ImageFormat::Ppm),
            "tga" => Some(ImageFormat::Tga),
            _ => None,
        }
    }
}

/// `render -o`: an image, an animation's container (.apng, .gif, .mp4, .webm), a pattern
/// with `{frame}` (its extension an image's), or an existing folder.
fn parse_render_output(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    if path.is_dir() || crate::animation::AnimationFormat::from_path(&path).is_some() {
        return Ok(path);
    }
    match ImageFormat::from_path(&path) {
        Some(_) => Ok(path),
        None => Err(format!(
            "cannot tell the image format of `{text}`: use a .png, .exr, .hdr, .ppm or .tga \
             extension, .apng, .gif, .mp4 or .webm for an animation, or an existing folder"
        )),
    }
}

/// `--frames A..=B`, `A..B` or `N`: a range of frame numbers, not empty.
pub fn parse_frames(text: &str) -> Result<std::ops::RangeInclusive<u32>, String> {
    let usage = || {
        format!(
            "`{text}` is not a frame range: write A..=B (both included), A..B (B excluded) or \
             one frame N, with whole numbers from 0 to {}",
            u32::MAX
        )
    };
    let number = |t: &str| t.trim().parse::<u32>().map_err(|_| usage());
    let (first, last) = if let Some((a, b)) = text.split_once("..=") {
        (number(a)?, number(b)?)
    } else if let Some((a, b)) = text.split_once("..") {
        let (a, b) = (number(a)?, number(b)?);
        if b <= a {
            return Err(format!(
                "--frames {text} is empty: the last frame {b} is excluded and not after the first {a}"
            ));
        }
        (a, b - 1)
    } else {
        let n = number(text)?;
        (n, n)
    };
    if last < first {
        return Err(format!(
            "--frames {text} runs backwards: the first frame ({first}) must not be after the last ({last})"
        ));
    }
    let count = u64::from(last - first) + 1;
    if count > u64::from(limits::MAX_FRAMES) {
        return Err(format!(
            "--frames {text} has {count} frames, more than the frames limit ({})",
            limits::MAX_FRAMES
        ));
    }
    Ok(first..=last)
}

fn parse_output(text: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    match ImageFormat::from_path(&path) {
        Some(_) => Ok(path),
        None => Err(format!(
            "cannot tell the image format of `{text}`: use a .png, .exr, .hdr, .ppm or .tga extension"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defines_need_a_name_and_a_value() {
        assert_eq!(parse_define("N=316"), Ok(("N".into(), "316".into())));
        assert_eq!(
            parse_define("color=<1, 0, 0>"),
            Ok(("color".into(), "<1, 0, 0>".into()))
        );
        assert!(parse_define("N").is_err());
        assert!(parse_define("1N=3").is_err());
        assert!(parse_define("N=").is_err());
    }

    #[test]
    fn frame_ranges_are_read_by_hand() {
        assert_eq!(parse_frames("2..=4"), Ok(2..=4));
        assert_eq!(parse_frames("2..5"), Ok(2..=4));
        assert_eq!(parse_frames("7"), Ok(7..=7));
        assert_eq!(parse_frames(" 0 ..= 0 "), Ok(0..=0));
        let backwards = parse_frames("5..=2").unwrap_err();
        assert!(backwards.contains("runs backwards"), "{backwards}");
        assert!(parse_frames("3..3").unwrap_err().contains("is empty"));
        assert!(parse_frames("0..=4294967296").is_err());
        assert!(parse_frames("-1..=3").is_err());
        assert!(parse_frames("a..=b").is_err());
        let too_many = parse_frames("0..=100000").unwrap_err();
        assert!(too_many.contains("frames limit (100000)"), "{too_many}");
    }

    #[test]
    fn pixels_are_two_unsigned_numbers() {
        assert_eq!(parse_pixel("400,270"), Ok([400, 270]));
        assert_eq!(parse_pixel(" 3 , 4 "), Ok([3, 4]));
        assert!(parse_pixel("400").is_err());
        assert!(parse_pixel("-1,2").is_err());
        assert!(parse_pixel("1,2,3").is_err());
        assert!(parse_pixel("x,y").is_err());
    }

    #[test]
    fn output_format_follows_the_extension() {
        assert_eq!(
            ImageFormat::from_path("a/b.PNG".as_ref()),
            Some(ImageFormat::Png)
        );
        assert_eq!(
            ImageFormat::from_path("x.exr".as_ref()),
            Some(ImageFormat::Exr)
        );
        assert!(parse_output("out.jpg").is_err());
        assert!(parse_output("out").is_err());
    }

    #[test]
    fn the_command_line_definition_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }
}
