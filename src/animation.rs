//! `whitted render` of an animation: each frame compiled with its own `frame` and `clock`,
//! rendered, and written through a file-name pattern (`frame-{frame:04}.png`), into one
//! animated PNG or GIF, or through ffmpeg into a video.
//!
//! The pieces other code may call to split an animation (a render farm): [`frame_range`]
//! (the scene's frames), [`render_frame`] (one frame, compiled and rendered) and
//! [`write_frames`] (a list of frames through a pattern).

use std::io::{IsTerminal, Write};
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use whitted_ir::limits;
use whitted_tracer::{PreparedScene, RenderObserver, TileResult};

use crate::cli::{ImageFormat, RenderArgs, RenderOverrides, SceneArgs};
use crate::image_output::{to_srgb8, write_atomically, write_image, Pixels};
use crate::scene_input::{load_scene, Loaded};
use crate::setting_flags::apply_render_flags;
use crate::Failure;

/// The frames of the scene's animation, first to last: one frame for a still.
pub fn frame_range(loaded: &Loaded) -> RangeInclusive<u32> {
    loaded.scene.settings.frame_range()
}

/// Containers that hold a whole animation, by the output's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnimationFormat {
    /// An animated PNG (`.apng`).
    Apng,
    Gif,
    /// A video made by ffmpeg; the extension (`mp4`, `webm`) picks its container.
    Video(&'static str),
}

impl AnimationFormat {
    pub fn from_path(path: &Path) -> Option<AnimationFormat> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        match extension.as_str() {
            "apng" => Some(AnimationFormat::Apng),
            "gif" => Some(AnimationFormat::Gif),
            "mp4" => Some(AnimationFormat::Video("mp4")),
            "webm" => Some(AnimationFormat::Video("webm")),
            _ => None,
        }
    }
}

/// A file name with the frame number in it: `out/frame-{frame:04}.png` is
/// `out/frame-0007.png` for frame 7. `{frame}` writes the number as it is; `{frame:0W}`
/// pads it with zeros to W digits.
#[derive(Clone, Debug, PartialEq)]
pub struct FramePattern {
    /// Text and holes, in order.
    parts: Vec<PatternPart>,
}

#[derive(Clone, Debug, PartialEq)]
enum PatternPart {
    Text(String),
    /// A `{frame}` hole, padded to this many digits.
    Frame(usize),
}

impl FramePattern {
    /// The pattern in `text`, `None` when it has no `{frame` hole.
    pub fn parse(text: &str) -> Result<Option<FramePattern>, String> {
        const HOLE: &str = "{frame";
        if !text.contains(HOLE) {
            return Ok(None);
        }
        let mut parts = Vec::new();
        let mut rest = text;
        while let Some(at) = rest.find(HOLE) {
            parts.push(PatternPart::Text(rest[..at].to_string()));
            let after = &rest[at + HOLE.len()..];
            let Some(close) = after.find('}') else {
                return Err(format!(
                    "the output pattern `{text}` has `{{frame` without its closing `}}`: write \
                     {{frame}} or {{frame:04}}"
                ));
            };
            let spec = &after[..close];
            let width = match spec {
                "" => 0,
                _ => spec
                    .strip_prefix(":0")
                    .or_else(|| spec.strip_prefix(':'))
                    .and_then(|w| w.parse::<usize>().ok())
                    .filter(|w| *w <= 10)
                    .ok_or_else(|| {
                        format!(
                            "the output pattern `{text}` has `{{frame{spec}}}`: write {{frame}} \
                             or {{frame:0W}} with W a width of at most 10 digits, like \
                             {{frame:04}}"
                        )
                    })?,
            };
            parts.push(PatternPart::Frame(width));
            rest = &after[close + 1..];
        }
        parts.push(PatternPart::Text(rest.to_string()));
        Ok(Some(FramePattern { parts }))
    }

    /// The file of `frame`.
    pub fn path(&self, frame: u32) -> PathBuf {
        let mut text = String::new();
        for part in &self.parts {
            match part {
                PatternPart::Text(t) => text.push_str(t),
                PatternPart::Frame(width) => text.push_str(&format!("{frame:0width$}")),
            }
        }
        PathBuf::from(text)
    }
}

/// Where an animation goes.
enum Target {
    Pattern(FramePattern),
    Container(PathBuf, AnimationFormat),
}

/// One rendered frame.
pub struct RenderedFrame {
    pub frame: u32,
    pub width: u32,
    pub height: u32,
    /// Linear RGB, row-major, top first.
    pub pixels: Vec<[f32; 3]>,
}

/// A render observer that does nothing: the progress of an animation is counted in frames.
struct Quiet;

impl RenderObserver for Quiet {
    fn tile_done(&self, _tile: &TileResult) {}
}

/// Compiles `scene` at `frame` (its `-D` and `--set` kept), applies the render flags and
/// renders it on `pool`. Warnings are printed unless `quiet`.
pub fn render_frame(
    scene: &SceneArgs,
    overrides: &RenderOverrides,
    frame: u32,
    pool: &rayon::ThreadPool,
    quiet: bool,
) -> Result<RenderedFrame, Failure> {
    let args = SceneArgs {
        frame: Some(frame),
        ..scene.clone()
    };
    let loaded = load_scene(&args, quiet)?;
    let (loaded, options) = apply_render_flags(loaded, overrides)?;
    crate::render_cmd::check_image_size(options.width, options.height)?;
    let ir = loaded.scene;
    let prepared = pool.install(|| PreparedScene::new_releasing_ir(ir));
    let rendered = pool.install(|| whitted_tracer::render(&prepared, &options, &Quiet));
    let Some((image, _stats)) = rendered else {
        return Err(Failure::Message(format!(
            "the render was cancelled at frame {frame}"
        )));
    };
    Ok(RenderedFrame {
        frame,
        width: image.width,
        height: image.height,
        pixels: image.pixels,
    })
}

/// Renders each of `frames` and writes it to its file of `pattern` (atomically, in the
/// pattern's image format), with a progress bar over the frames when `progress`. Returns
/// the files written, in the order of `frames`.
pub fn write_frames(
    scene: &SceneArgs,
    overrides: &RenderOverrides,
    frames: &[u32],
    pattern: &FramePattern,
    pool: &rayon::ThreadPool,
    progress: bool,
) -> Result<Vec<PathBuf>, Failure> {
    let mut written = Vec::with_capacity(frames.len());
    each_frame(scene, overrides, frames, pool, progress, |rendered| {
        let path = pattern.path(rendered.frame);
        let format = ImageFormat::from_path(&path).unwrap_or(ImageFormat::Png);
        write_image(
            &path,
            format,
            rendered.width,
            rendered.height,
            Pixels::Linear(&rendered.pixels),
        )
        .map_err(Failure::Message)?;
        written.push(path);
        Ok(())
    })?;
    Ok(written)
}

/// Renders `frames` one after the other and hands each to `sink`, the progress bar (when
/// `progress`) counting frames with an ETA. The first frame's warnings are printed once.
fn each_frame(
    scene: &SceneArgs,
    overrides: &RenderOverrides,
    frames: &[u32],
    pool: &rayon::ThreadPool,
    progress: bool,
    mut sink: impl FnMut(RenderedFrame) -> Result<(), Failure>,
) -> Result<(), Failure> {
    let bar = progress.then(|| {
        let bar = ProgressBar::new(frames.len() as u64);
        let style = ProgressStyle::with_template(
            "{spinner} frame {pos}/{len} [{bar:40}] {elapsed_precise} elapsed, ETA {eta}",
        )
        .map(|s| s.progress_chars("=> "))
        .unwrap_or_else(|_| ProgressStyle::default_bar());
        bar.set_style(style);
        bar
    });
    for (index, &frame) in frames.iter().enumerate() {
        let rendered = render_frame(scene, overrides, frame, pool, index > 0 || !progress);
        let rendered = match rendered {
            Ok(rendered) => rendered,
            Err(failure) => {
                if let Some(bar) = &bar {
                    bar.finish_and_clear();
                }
                return Err(failure);
            }
        };
        sink(rendered)?;
        if let Some(bar) = &bar {
            bar.inc(1);
        }
    }
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    Ok(())
}

/// Whether `render` should take the animation path: more than one frame, an output that
/// holds an animation, or a `{frame}` pattern.
pub fn is_animation_job(args: &RenderArgs, loaded: &Loaded) -> bool {
    let many = match &args.frames {
        Some(_) => true,
        None => args.scene.frame.is_none() && loaded.scene.settings.is_animated(),
    };
    let output_animates = args.output.as_deref().is_some_and(|o| {
        o.is_dir()
            || AnimationFormat::from_path(o).is_some()
            || o.to_string_lossy().contains("{frame")
    });
    many || output_animates
}

/// `whitted render` of an animation (see [`is_animation_job`]); `loaded` is the scene as
/// compiled at its first frame (or `--frame`), for its range, rate and size.
pub fn render_animation(args: &RenderArgs, loaded: Loaded) -> Result<(), Failure> {
    let started = Instant::now();
    let range = frame_range(&loaded);
    let frames: Vec<u32> = match (&args.frames, args.scene.frame) {
        (Some(asked), _) => asked.clone().collect(),
        (None, Some(frame)) => vec![frame],
        (None, None) => range.clone().collect(),
    };
    if frames.len() > limits::MAX_FRAMES as usize {
        return Err(Failure::Usage(format!(
            "{} frames is more than the frames limit ({})",
            frames.len(),
            limits::MAX_FRAMES
        )));
    }
    let fps = loaded.scene.settings.fps;
    if args.stats.is_some() || args.stats_image.is_some() {
        return Err(Failure::Usage(format!(
            "--stats and --stats-image report one render, and this renders {} frames: add \
             --frame N for one of them",
            frames.len()
        )));
    }
    let name = args.scene.scene.file_stem().map_or_else(
        || "render".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let default_pattern = format!("{name}-{{frame:04}}.png");
    let target = match &args.output {
        None => Target::Pattern(pattern_or_usage(&default_pattern)?),
        Some(dir) if dir.is_dir() => Target::Pattern(pattern_or_usage(
            &dir.join(&default_pattern).to_string_lossy(),
        )?),
        Some(path) => match AnimationFormat::from_path(path) {
            Some(format) => Target::Container(path.clone(), format),
            None => match FramePattern::parse(&path.to_string_lossy()).map_err(Failure::Usage)? {
                Some(pattern) => Target::Pattern(pattern),
                None if frames.len() == 1 => Target::Pattern(FramePattern {
                    parts: vec![PatternPart::Text(path.to_string_lossy().into_owned())],
                }),
                None => {
                    return Err(Failure::Usage(format!(
                        "-o {} names one file, but {} frames are to be rendered and would \
                         overwrite each other: put {{frame}} in the name (for example -o \
                         '{}'), name a folder, or write .apng, .gif, .mp4 or .webm",
                        path.display(),
                        frames.len(),
                        with_frame_hole(path).display()
                    )))
                }
            },
        },
    };
    // Fail before a long render, not after it, when the output cannot be written there.
    let first_output = match &target {
        Target::Pattern(pattern) => pattern.path(frames[0]),
        Target::Container(path, _) => path.clone(),
    };
    crate::render_cmd::check_output_folder(&first_output)?;
    if let Target::Pattern(pattern) = &target {
        if ImageFormat::from_path(&pattern.path(frames[0])).is_none() {
            return Err(Failure::Usage(format!(
                "cannot tell the image format of the frames `{}`: end the pattern in .png, .exr, .hdr, .ppm or .tga",
                pattern.path(frames[0]).display()
            )));
        }
    }
    let (loaded, options) = apply_render_flags(loaded, &args.overrides)?;
    drop(loaded);
    if let Target::Container(path, format) = &target {
        if matches!(format, AnimationFormat::Apng | AnimationFormat::Gif) {
            let pixels = (frames.len() as u64)
                .saturating_mul(u64::from(options.width) * u64::from(options.height));
            if pixels > limits::MAX_ANIMATION_PIXELS {
                return Err(Failure::Usage(format!(
                    "{} holds every frame at once: {} frames of {}x{} are {pixels} pixels, \
                     more than the animation pixels limit ({}); render fewer frames \
                     (--frames), a smaller image (--width), or frames to files (-o \
                     'frames/{name}-{{frame:04}}.png')",
                    path.display(),
                    frames.len(),
                    options.width,
                    options.height,
                    limits::MAX_ANIMATION_PIXELS
                )));
            }
        }
        if let AnimationFormat::Video(extension) = format {
            if find_on_path("ffmpeg").is_none() {
                return Err(Failure::Message(format!(
                    "writing a .{extension} video needs ffmpeg, and there is none on the PATH: \
                     install ffmpeg, or write the frames as images (-o \
                     'frames/{name}-{{frame:04}}.png') or as an animated .apng or .gif"
                )));
            }
        }
    }
    crate::interrupt::install();
    let pool = crate::render_cmd::thread_pool(args.threads)?;
    let progress = !args.quiet && std::io::stderr().is_terminal();
    let described = match &target {
        Target::Pattern(pattern) => {
            let written = write_frames(
                &args.scene,
                &args.overrides,
                &frames,
                pattern,
                &pool,
                progress,
            )?;
            match (written.first(), written.last()) {
                (Some(first), Some(last)) if written.len() > 1 => format!(
                    "{} frames, {} to {}",
                    written.len(),
                    first.display(),
                    last.display()
                ),
                (Some(only), _) => only.display().to_string(),
                _ => "nothing".to_string(),
            }
        }
        Target::Container(path, AnimationFormat::Video(_)) => {
            write_video(args, &frames, fps, path, &pool, progress)?;
            format!("{} ({} frames)", path.display(), frames.len())
        }
        Target::Container(path, format) => {
            let mut images: Vec<RenderedFrame> = Vec::with_capacity(frames.len());
            each_frame(
                &args.scene,
                &args.overrides,
                &frames,
                &pool,
                progress,
                |rendered| {
                    if let Some(first) = images.first() {
                        if (first.width, first.height) != (rendered.width, rendered.height) {
                            return Err(Failure::Message(format!(
                                "frame {} is {}x{} but frame {} is {}x{}: the frames of an \
                                 animated image must all have one size",
                                rendered.frame,
                                rendered.width,
                                rendered.height,
                                first.frame,
                                first.width,
                                first.height
                            )));
                        }
                    }
                    images.push(rendered);
                    Ok(())
                },
            )?;
            let encode = |file: &mut std::fs::File| match format {
                AnimationFormat::Gif => encode_gif(file, &images, fps),
                _ => encode_apng(file, &images, fps),
            };
            write_atomically(path, encode).map_err(Failure::Message)?;
            format!("{} ({} frames)", path.display(), frames.len())
        }
    };
    if !args.quiet && std::io::stderr().is_terminal() {
        eprintln!(
            "wrote {described} in {:.2} s",
            started.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

fn pattern_or_usage(text: &str) -> Result<FramePattern, Failure> {
    match FramePattern::parse(text) {
        Ok(Some(pattern)) => Ok(pattern),
        Ok(None) => Err(Failure::Usage(format!("`{text}` has no {{frame}}"))),
        Err(message) => Err(Failure::Usage(message)),
    }
}

/// `out/x.png` as `out/x-{frame:04}.png`, for the message that suggests it.
fn with_frame_hole(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    let extension = path
        .extension()
        .map_or_else(|| "png".to_string(), |e| e.to_string_lossy().into_owned());
    path.with_file_name(format!("{stem}-{{frame:04}}.{extension}"))
}

/// An animated PNG of `frames` (8-bit sRGB, as a still PNG), each shown 1/fps seconds,
/// looping.
fn encode_apng(file: &mut std::fs::File, frames: &[RenderedFrame], fps: u32) -> Result<(), String> {
    let Some(first) = frames.first() else {
        return Err("no frames to write".into());
    };
    let writer = std::io::BufWriter::new(file);
    let mut encoder = png::Encoder::new(writer, first.width, first.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let count = u32::try_from(frames.len()).map_err(|_| "too many frames".to_string())?;
    encoder.set_animated(count, 0).map_err(|e| e.to_string())?;
    let fps = u16::try_from(fps).unwrap_or(u16::MAX).max(1);
    encoder.set_frame_delay(1, fps).map_err(|e| e.to_string())?;
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    for frame in frames {
        writer
            .write_image_data(&to_srgb8(&frame.pixels))
            .map_err(|e| e.to_string())?;
    }
    writer.finish().map_err(|e| e.to_string())
}

/// An animated GIF of `frames`, each shown 1/fps seconds (GIF counts in hundredths), looping;
/// the colours are quantised by the `image` crate's encoder.
fn encode_gif(file: &mut std::fs::File, frames: &[RenderedFrame], fps: u32) -> Result<(), String> {
    use image::codecs::gif::{GifEncoder, Repeat};
    let mut writer = std::io::BufWriter::new(file);
    {
        let mut encoder = GifEncoder::new(&mut writer);
        encoder
            .set_repeat(Repeat::Infinite)
            .map_err(|e| e.to_string())?;
        for frame in frames {
            let rgba: Vec<u8> = to_srgb8(&frame.pixels)
                .chunks_exact(3)
                .flat_map(|p| [p[0], p[1], p[2], 255])
                .collect();
            let buffer = image::RgbaImage::from_raw(frame.width, frame.height, rgba)
                .ok_or("the frame has the wrong number of pixels")?;
            let delay = image::Delay::from_numer_denom_ms(1000, fps.max(1));
            encoder
                .encode_frame(image::Frame::from_parts(buffer, 0, 0, delay))
                .map_err(|e| e.to_string())?;
        }
    }
    writer.flush().map_err(|e| e.to_string())
}

/// The file `program` runs from, searched along PATH.
fn find_on_path(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(program))
        .find(|candidate| candidate.is_file())
}

/// A video through ffmpeg: the frames as PNGs in a temporary folder, then one ffmpeg run
/// into a temporary file beside `output`, renamed over it when ffmpeg succeeds.
fn write_video(
    args: &RenderArgs,
    frames: &[u32],
    fps: u32,
    output: &Path,
    pool: &rayon::ThreadPool,
    progress: bool,
) -> Result<(), Failure> {
    let folder = tempfile::tempdir()
        .map_err(|e| Failure::Message(format!("cannot make a temporary folder: {e}")))?;
    // ffmpeg numbers its input from 0: the n-th frame rendered is file n.
    let mut index = 0usize;
    each_frame(
        &args.scene,
        &args.overrides,
        frames,
        pool,
        progress,
        |rendered| {
            let path = folder.path().join(format!("{index:06}.png"));
            index += 1;
            write_image(
                &path,
                ImageFormat::Png,
                rendered.width,
                rendered.height,
                Pixels::Linear(&rendered.pixels),
            )
            .map_err(Failure::Message)
        },
    )?;
    let ffmpeg = find_on_path("ffmpeg")
        .ok_or_else(|| Failure::Message("ffmpeg is no longer on the PATH".into()))?;
    let extension = output
        .extension()
        .map_or_else(|| "mp4".to_string(), |e| e.to_string_lossy().into_owned());
    let dir = match output.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    let suffix = format!(".{extension}");
    builder.prefix(".whitted-").suffix(&suffix);
    // A video is an ordinary file, not a private one (tempfile's 0600): 0666 and the umask.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let temp = builder
        .tempfile_in(dir)
        .map_err(|e| Failure::Message(format!("cannot write {}: {e}", output.display())))?;
    let _registered = crate::interrupt::register(temp.path());
    let status = std::process::Command::new(ffmpeg)
        .args(["-y", "-loglevel", "error", "-framerate"])
        .arg(fps.to_string())
        .arg("-i")
        .arg(folder.path().join("%06d.png"))
        .args(["-pix_fmt", "yuv420p"])
        .arg(temp.path())
        .status()
        .map_err(|e| Failure::Message(format!("cannot run ffmpeg: {e}")))?;
    if !status.success() {
        return Err(Failure::Message(format!(
            "ffmpeg could not write {} ({status})",
            output.display()
        )));
    }
    temp.persist(output)
        .map_err(|e| Failure::Message(format!("cannot write {}: {}", output.display(), e.error)))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_put_the_frame_number_in_the_name() {
        let pattern = FramePattern::parse("out/frame-{frame:04}.png")
            .unwrap()
            .unwrap();
        assert_eq!(pattern.path(7), PathBuf::from("out/frame-0007.png"));
        assert_eq!(pattern.path(12345), PathBuf::from("out/frame-12345.png"));
        let plain = FramePattern::parse("f{frame}.png").unwrap().unwrap();
        assert_eq!(plain.path(3), PathBuf::from("f3.png"));
        let two = FramePattern::parse("{frame}-{frame:3}.png")
            .unwrap()
            .unwrap();
        assert_eq!(two.path(5), PathBuf::from("5-005.png"));
        assert_eq!(FramePattern::parse("still.png"), Ok(None));
    }

    #[test]
    fn broken_patterns_say_what_to_write() {
        let open = FramePattern::parse("out/f-{frame.png").unwrap_err();
        assert!(open.contains("without its closing `}`"), "{open}");
        let spec = FramePattern::parse("f-{frame:x}.png").unwrap_err();
        assert!(spec.contains("{frame:0W}"), "{spec}");
    }

    #[test]
    fn the_suggested_pattern_keeps_the_folder_and_extension() {
        assert_eq!(
            with_frame_hole(Path::new("out/x.tga")),
            PathBuf::from("out/x-{frame:04}.tga")
        );
    }
}
