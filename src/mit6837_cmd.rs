//! `whitted mit6837`: the MIT 6.837 (Fall 2004) course's command line, its single-dash flags
//! taken verbatim (`-input scene.txt -size 200 200 -output out.tga -shadows -bounces 4`),
//! writing what the course's reference ray tracer wrote: the image, and the depth and
//! normals images, as 8-bit linear values (colour times 255, no sRGB curve).
//!
//! The flags are read by hand rather than by clap: clap's long flags take two dashes, and
//! the course's command lines must work as the assignments wrote them.

use std::ffi::OsString;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use whitted_ir::limits;
use whitted_mit6837::CourseOptions;
use whitted_tracer::{PreparedScene, RayKind, RayStart, Recorder, RenderOptions, SurfaceHit};

use crate::cli::{ImageFormat, SceneArgs};
use crate::image_output::{to_linear8, write_image, Pixels};
use crate::scene_input::load_scene_with;
use crate::Failure;

/// What `whitted mit6837 -help` prints.
pub const USAGE: &str = "\
usage: whitted mit6837 -input SCENE.txt -size W H [-output OUT.tga|.png|.ppm]
                       [-shadows] [-transparent_shadows] [-shade_back]
                       [-bounces N] [-weight W]
                       [-depth T0 T1 DEPTH.tga] [-normals NORMALS.tga]
                       [-uniform_samples|-jittered_samples|-random_samples N]
                       [-box_filter R|-tent_filter R|-gaussian_filter SIGMA]
                       [-render_samples FILE ZOOM] [-render_filter FILE ZOOM]
                       [-stats] [-gui]

The MIT 6.837 (Fall 2004) ray tracer's command line, flags as the course wrote them.
Images are 8-bit linear (colour times 255, clamped), as the course's were.

  -input F            the 6.837 scene file
  -size W H           image width and height in pixels
  -output F           the rendered image (.tga, .png or .ppm)
  -shadows            cast shadow rays (any object blocks the light)
  -transparent_shadows  shadow rays pass through transparent objects, tinted
  -shade_back         light surfaces seen from behind (otherwise lights skip them)
  -bounces N          reflected and refracted rays up to depth N (default 0)
  -weight W           do not trace rays that contribute less than W (default 0)
  -depth T0 T1 F      the distance to the first hit, T0 white to T1 black
  -normals F          the first hit's normal, |x| |y| |z| as red, green, blue
  -uniform_samples N  N samples per pixel on a regular grid (assignment 7)
  -jittered_samples N N samples per pixel, stratified and jittered
  -random_samples N   N samples per pixel, each anywhere in the pixel
  -box_filter R       each pixel the mean of the samples within R of its centre
                      (a square; 0.5, the default, is the pixel's own samples)
  -tent_filter R      the samples weighted 1 - d/R by their distance d
  -gaussian_filter S  the samples weighted exp(-d^2/(2 S^2)), out to 2 S
  -render_samples F Z every sample as a dot in its colour, the image zoomed Z times
  -render_filter F Z  the filter's weights around the centre pixel, zoomed Z times
  -stats              print the ray counts after the render
  -gui                open the scene in whitted's terminal debugger (whitted debug),
                      with these settings, after writing any images
  -tessellation T P, -gouraud, -grid X Y Z
                      accepted and ignored (the course's OpenGL preview and grid)

See docs/courses.md.";

/// The course's flags that whitted does not have yet, each with why, so that a teacher's
/// script gets a reason rather than "unknown flag".
const NOT_YET: &[(&str, &str)] = &[
    ("-visualize_grid", "assignment 6 draws the cells of the course's uniform grid that rays visit, and whitted accelerates with a BVH, which has no grid cells to draw (-grid is accepted and ignored for the same reason); to see which objects a ray meets, open the scene with -gui (or `whitted debug SCENE.txt`) and trace a pixel, or run `whitted trace SCENE.txt --pixel X,Y`"),
    ("-filter_samples", "whitted draws the filter's weights with -render_filter FILE ZOOM and the samples with -render_samples FILE ZOOM"),
    ("-zoom_factor", "the zoom is the second argument of -render_samples FILE ZOOM and -render_filter FILE ZOOM, as assignment 7 wrote them"),
];

/// A parsed command line.
#[derive(Debug, PartialEq)]
pub enum Request {
    Help,
    Run(Box<CourseRun>),
}

#[derive(Debug, PartialEq)]
pub struct CourseRun {
    pub input: PathBuf,
    pub options: CourseOptions,
    pub output: Option<PathBuf>,
    /// `-depth t0 t1 file`.
    pub depth: Option<(f64, f64, PathBuf)>,
    pub normals: Option<PathBuf>,
    /// `-stats`: print the ray counts after the render.
    pub stats: bool,
    /// `-render_samples file zoom`.
    pub render_samples: Option<(PathBuf, u32)>,
    /// `-render_filter file zoom`.
    pub render_filter: Option<(PathBuf, u32)>,
    /// `-gui`: open the debugger after writing the images.
    pub gui: bool,
    /// What the command line asked that whitted accepts and ignores, said once each.
    pub notes: Vec<String>,
    /// `--set NAME=VALUE` (whitted's own, repeatable): any setting on top of the course's,
    /// such as a student bug model for `whitted grade`'s examples.
    pub sets: Vec<(String, String)>,
}

/// Reads the course's flags. Every mistake is one message naming the flag.
pub fn parse(args: &[OsString]) -> Result<Request, String> {
    let mut words = args.iter();
    let mut input = None;
    let mut size = None;
    let mut output = None;
    let mut depth = None;
    let mut normals = None;
    let mut stats = false;
    let mut render_samples = None;
    let mut render_filter = None;
    let mut gui = false;
    let mut notes: Vec<String> = Vec::new();
    let mut options = CourseOptions::default();
    let mut seen: Vec<String> = Vec::new();
    let mut sets = Vec::new();
    while let Some(word) = words.next() {
        let flag = word.to_string_lossy().into_owned();
        if flag == "--set" {
            let text = words
                .next()
                .ok_or("--set needs NAME=VALUE")?
                .to_string_lossy()
                .into_owned();
            let (name, value) = text
                .split_once('=')
                .ok_or_else(|| format!("--set {text}: write NAME=VALUE, e.g. --set epsilon=0"))?;
            sets.push((name.trim().to_string(), value.trim().to_string()));
            continue;
        }
        if seen.contains(&flag) {
            return Err(format!("{flag} is given twice"));
        }
        let mut value = |what: &str| -> Result<OsString, String> {
            words
                .next()
                .cloned()
                .ok_or_else(|| format!("{flag} needs {what}"))
        };
        match flag.as_str() {
            "-help" | "--help" | "-h" => return Ok(Request::Help),
            "-input" => input = Some(PathBuf::from(value("a scene file")?)),
            "-size" => {
                let side = |text: OsString, what: &str| {
                    number::<u32>(&text, "-size", what).and_then(|n| {
                        if (1..=limits::MAX_IMAGE_SIDE).contains(&n) {
                            Ok(n)
                        } else {
                            Err(format!(
                                "-size: the {what} must be from 1 to {} (the image side limit), not {n}",
                                limits::MAX_IMAGE_SIDE
                            ))
                        }
                    })
                };
                let width = side(value("a width and a height")?, "width")?;
                let height = side(value("a width and a height")?, "height")?;
                // Past the pixels limit the compiler would blame the scene for the flag's size.
                let pixels = u64::from(width) * u64::from(height);
                if pixels > limits::MAX_PIXELS {
                    return Err(format!(
                        "`-size {width} {height}` asks for {pixels} pixels, more than the pixels \
                         limit ({}, about 11585x11585)",
                        limits::MAX_PIXELS
                    ));
                }
                size = Some((width, height));
            }
            "-output" => output = Some(image_path(value("an image file")?, "-output")?),
            "-shadows" => options.shadows = true,
            "-transparent_shadows" => options.transparent_shadows = true,
            "-shade_back" => options.shade_back = true,
            "-bounces" => {
                let n = number::<u32>(&value("a number of bounces")?, "-bounces", "count")?;
                if n > limits::MAX_DEPTH {
                    return Err(format!(
                        "-bounces {n} is past {}",
                        limits::describe("max depth")
                    ));
                }
                options.bounces = n;
            }
            "-weight" => {
                let w = number::<f64>(&value("a weight")?, "-weight", "weight")?;
                if !(0.0..=1.0).contains(&w) {
                    return Err(format!("-weight must be from 0 to 1, not {w}"));
                }
                options.weight = w;
            }
            "-depth" => {
                let what = "a near and a far distance and an image file";
                let near = number::<f64>(&value(what)?, "-depth", "near distance")?;
                let far = number::<f64>(&value(what)?, "-depth", "far distance")?;
                if !(near.is_finite() && far.is_finite() && near < far) {
                    return Err(format!(
                        "-depth {near} {far}: the near distance must be less than the far one"
                    ));
                }
                depth = Some((near, far, image_path(value(what)?, "-depth")?));
            }
            "-normals" => normals = Some(image_path(value("an image file")?, "-normals")?),
            "-uniform_samples" | "-jittered_samples" | "-random_samples" => {
                let what = "a number of samples per pixel";
                let n = number::<u32>(&value(what)?, &flag, "count")?;
                if !(1..=limits::MAX_SAMPLES_PER_PIXEL).contains(&n) {
                    return Err(format!(
                        "{flag} {n}: the samples per pixel must be from 1 to {}",
                        limits::MAX_SAMPLES_PER_PIXEL
                    ));
                }
                if seen
                    .iter()
                    .any(|s| s.ends_with("_samples") && s != "-render_samples")
                {
                    return Err(format!("{flag}: give one of -uniform_samples, -jittered_samples and -random_samples"));
                }
                options.samples = n;
                options.sampling = match flag.as_str() {
                    "-uniform_samples" => whitted_ir::Sampling::Grid,
                    "-random_samples" => whitted_ir::Sampling::Random,
                    _ => whitted_ir::Sampling::Jittered,
                };
            }
            "-box_filter" | "-tent_filter" | "-gaussian_filter" => {
                let what = if flag == "-gaussian_filter" {
                    "sigma"
                } else {
                    "radius"
                };
                let radius = number::<f64>(&value(&format!("a {what}"))?, &flag, what)?;
                if !(radius > 0.0 && radius <= limits::MAX_FILTER_RADIUS) {
                    return Err(format!(
                        "{flag} {radius}: the {what} must be above 0 and at most {} pixels \
                         (the filter radius limit)",
                        limits::MAX_FILTER_RADIUS
                    ));
                }
                if seen
                    .iter()
                    .any(|s| s.ends_with("_filter") && s != "-render_filter")
                {
                    return Err(format!(
                        "{flag}: give one of -box_filter, -tent_filter and -gaussian_filter"
                    ));
                }
                options.filter = match flag.as_str() {
                    "-tent_filter" => whitted_ir::Filter::Tent,
                    "-gaussian_filter" => whitted_ir::Filter::Gaussian,
                    _ => whitted_ir::Filter::Box,
                };
                options.filter_radius = radius;
            }
            "-render_samples" | "-render_filter" => {
                let what = "an image file and a zoom";
                let path = image_path(value(what)?, &flag)?;
                let zoom = number::<u32>(&value(what)?, &flag, "zoom")?;
                crate::mit6837_pictures::picture_size(&flag, (1, 1), zoom)?;
                if flag == "-render_samples" {
                    render_samples = Some((path, zoom));
                } else {
                    render_filter = Some((path, zoom));
                }
            }
            "-gui" => gui = true,
            "-stats" => stats = true,
            // The handouts do not say where in the pixel the ray goes; students differ.
            "-sample_position" => {
                options.sample_position = match value("centre or corner")?.to_str() {
                    Some("centre" | "center") => whitted_ir::SamplePosition::Centre,
                    Some("corner") => whitted_ir::SamplePosition::Corner,
                    _ => return Err("-sample_position takes centre or corner".into()),
                }
            }
            // They shape only the course's OpenGL preview, which whitted does not draw.
            "-tessellation" => {
                let what = "two numbers of steps (theta and phi)";
                number::<u32>(&value(what)?, "-tessellation", "count")?;
                number::<u32>(&value(what)?, "-tessellation", "count")?;
                notes.push("-tessellation shapes the course's OpenGL preview only: whitted's spheres are exact".into());
            }
            "-gouraud" => notes.push(
                "-gouraud shapes the course's OpenGL preview only: whitted ignores it".into(),
            ),
            "-grid" => {
                let what = "three numbers of cells";
                for _ in 0..3 {
                    number::<u32>(&value(what)?, "-grid", "count")?;
                }
                notes.push("-grid: whitted accelerates with a BVH, not the course's grid; the image is the same".into());
            }
            later if NOT_YET.iter().any(|(name, _)| *name == later) => {
                let why = NOT_YET
                    .iter()
                    .find(|(name, _)| *name == later)
                    .map_or("", |(_, why)| why);
                return Err(format!("{later} is not available in whitted: {why}"));
            }
            other => {
                return Err(format!(
                    "unknown flag `{other}` (see whitted mit6837 -help for the flags)"
                ))
            }
        }
        seen.push(flag);
    }
    let Some(input) = input else {
        return Err("-input SCENE.txt is required (see whitted mit6837 -help)".into());
    };
    let Some((width, height)) = size else {
        return Err("-size W H is required (see whitted mit6837 -help)".into());
    };
    let pictures = [
        ("-render_samples", &render_samples),
        ("-render_filter", &render_filter),
    ];
    for (flag, picture) in pictures {
        if let Some((_, zoom)) = picture {
            crate::mit6837_pictures::picture_size(flag, (width, height), *zoom)?;
        }
    }
    options.width = width;
    options.height = height;
    Ok(Request::Run(Box::new(CourseRun {
        input,
        options,
        output,
        depth,
        normals,
        stats,
        render_samples,
        render_filter,
        gui,
        notes,
        sets,
    })))
}

fn number<T: std::str::FromStr>(text: &OsString, flag: &str, what: &str) -> Result<T, String> {
    let text = text.to_string_lossy();
    text.trim()
        .parse::<T>()
        .map_err(|_| format!("{flag}: `{text}` is not a {what}"))
}

/// An output path whose extension is one the course's images can have.
fn image_path(text: OsString, flag: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(text);
    match ImageFormat::from_path(&path) {
        Some(ImageFormat::Tga | ImageFormat::Png | ImageFormat::Ppm) => Ok(path),
        _ => Err(format!(
            "{flag} {}: the course's images are .tga, .png or .ppm",
            path.display()
        )),
    }
}

/// Runs a parsed command line: `whitted mit6837 ...`.
pub fn mit6837(args: &[OsString]) -> Result<(), Failure> {
    let run = match parse(args).map_err(Failure::Usage)? {
        Request::Help => return crate::scene_input::write_stdout(&format!("{USAGE}\n")),
        Request::Run(run) => run,
    };
    let nothing = [
        run.output.is_none(),
        run.depth.is_none(),
        run.normals.is_none(),
    ];
    if nothing.iter().all(|&n| n)
        && run.render_samples.is_none()
        && run.render_filter.is_none()
        && !run.gui
    {
        return Err(Failure::Usage(
            "nothing to write: give -output, -depth, -normals, -render_samples or \
             -render_filter (or -gui to look at the scene)"
                .into(),
        ));
    }
    let outputs: Vec<&Path> = [
        run.output.as_deref(),
        run.depth.as_ref().map(|(_, _, path)| path.as_path()),
        run.normals.as_deref(),
        run.render_samples.as_ref().map(|(path, _)| path.as_path()),
        run.render_filter.as_ref().map(|(path, _)| path.as_path()),
    ]
    .into_iter()
    .flatten()
    .collect();
    for (i, path) in outputs.iter().enumerate() {
        if outputs[..i].contains(path) {
            return Err(Failure::Usage(format!(
                "{} is named for two images: each needs its own file",
                path.display()
            )));
        }
        if crate::render_cmd::same_file(path, &run.input) {
            return Err(Failure::Usage(format!(
                "the output {} is the scene file: choose another",
                path.display()
            )));
        }
        crate::render_cmd::check_output_folder(path)?;
    }
    // Before any render: the debugger cannot start without a terminal.
    if run.gui && !crate::debug_cmd::has_terminal() {
        return Err(Failure::Usage(
            "-gui opens whitted's terminal debugger, which needs a terminal on stdin and \
             stdout; run it in one, or leave out -gui to only write the images"
                .into(),
        ));
    }
    if std::fs::metadata(&run.input).is_ok() && !crate::front_end::is_course_scene(&run.input) {
        return Err(Failure::Message(format!(
            "{} is not a 6.837 scene: its first word is not one of {}",
            run.input.display(),
            whitted_mit6837::TOP_LEVEL_KEYWORDS.join(", ")
        )));
    }
    for note in &run.notes {
        eprintln!("note: {note}");
    }
    crate::interrupt::install();
    let scene_args = SceneArgs {
        scene: run.input.clone(),
        define: Vec::new(),
        set: run.sets.clone(),
        frame: None,
    };
    let loaded = load_scene_with(&scene_args, false, &run.options)?;
    let options = RenderOptions::from_settings(&loaded.scene.settings);
    crate::render_cmd::check_image_size(options.width, options.height)?;
    let (width, height) = (options.width, options.height);
    if run.render_samples.is_some() {
        // The picture needs every sample, which a filtered render keeps anyway (and
        // validation bounded); the default box keeps them only for this picture.
        let samples =
            u64::from(width) * u64::from(height) * u64::from(options.samples_per_pixel.max(1));
        if samples > limits::MAX_FILTERED_SAMPLES {
            return Err(Failure::Usage(format!(
                "-render_samples keeps every sample, and {width}x{height} with {} per pixel \
                 is {samples}, past {}: use a smaller -size",
                options.samples_per_pixel.max(1),
                limits::describe("filtered samples")
            )));
        }
    }
    let prepared = PreparedScene::new(&loaded.scene);
    if run.output.is_some() || run.render_samples.is_some() {
        let observer = &whitted_tracer::NoObserver;
        let rendered = if run.render_samples.is_some() {
            whitted_tracer::render_film(&prepared, &options, observer)
                .map(|(film, image, stats)| (image, stats, Some(film)))
        } else {
            whitted_tracer::render(&prepared, &options, observer)
                .map(|(image, stats)| (image, stats, None))
        };
        let Some((image, stats, film)) = rendered else {
            return Err(Failure::Message("the render was cancelled".into()));
        };
        if let Some(path) = &run.output {
            write(path, width, height, to_linear8(&image.pixels))?;
        }
        if let (Some((path, zoom)), Some(film)) = (&run.render_samples, &film) {
            let picture = crate::mit6837_pictures::samples_picture(film, *zoom);
            write_picture(path, &picture)?;
        }
        if run.stats {
            crate::scene_input::write_stdout(&course_stats(
                &stats,
                width,
                height,
                options.samples_per_pixel,
            ))?;
        }
    }
    if let Some((path, zoom)) = &run.render_filter {
        let filter = whitted_tracer::PixelFilter::from_settings(&loaded.scene.settings);
        let picture = crate::mit6837_pictures::filter_picture(&filter, (width, height), *zoom);
        write_picture(path, &picture)?;
    }
    if run.depth.is_some() || run.normals.is_some() {
        let hits = first_hits(&prepared, &options);
        if let Some((near, far, path)) = &run.depth {
            write(path, width, height, depth_image(&hits, *near, *far))?;
        }
        if let Some(path) = &run.normals {
            write(path, width, height, normals_image(&hits))?;
        }
    }
    if run.gui {
        drop(prepared);
        return crate::debug_cmd::debug_course(&scene_args, &run.options, loaded);
    }
    Ok(())
}

fn write_picture(path: &Path, picture: &crate::mit6837_pictures::Picture) -> Result<(), Failure> {
    let bytes = to_linear8(&picture.pixels);
    write(path, picture.width, picture.height, bytes)
}

/// `-stats`: the ray counts of the render, per kind and per pixel, as the course's
/// statistics listed them.
fn course_stats(
    stats: &whitted_tracer::RenderStats,
    width: u32,
    height: u32,
    samples: u32,
) -> String {
    let pixels = u64::from(width) * u64::from(height);
    let per_pixel = |n: u64| n as f64 / pixels.max(1) as f64;
    format!(
        "image            {width}x{height}, {samples} sample{} per pixel\n\
         camera rays      {} ({:.2} per pixel)\n\
         shadow rays      {} ({:.2} per pixel)\n\
         reflected rays   {} ({:.2} per pixel)\n\
         transmitted rays {} ({:.2} per pixel)\n\
         total rays       {} ({:.2} per pixel)\n\
         render           {:.3} s\n",
        if samples == 1 { "" } else { "s" },
        stats.camera_rays,
        per_pixel(stats.camera_rays),
        stats.shadow_rays,
        per_pixel(stats.shadow_rays),
        stats.reflected_rays,
        per_pixel(stats.reflected_rays),
        stats.transmitted_rays,
        per_pixel(stats.transmitted_rays),
        stats.total_rays(),
        per_pixel(stats.total_rays()),
        stats.render_seconds,
    )
}

fn write(path: &Path, width: u32, height: u32, bytes: Vec<u8>) -> Result<(), Failure> {
    let format = ImageFormat::from_path(path).unwrap_or(ImageFormat::Tga);
    write_image(path, format, width, height, Pixels::Linear8(bytes)).map_err(Failure::Message)
}

/// The camera ray's hit: distance and world-space outward normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstHit {
    pub t: f32,
    pub normal: [f32; 3],
}

/// Records the camera ray's hit, through the renderer's own tracing code.
#[derive(Default)]
struct FirstHitRecorder {
    in_camera_ray: bool,
    hit: Option<FirstHit>,
}

impl Recorder for FirstHitRecorder {
    fn ray_started(&mut self, ray: &RayStart) {
        self.in_camera_ray = ray.kind == RayKind::Camera;
    }

    fn surface_hit(&mut self, hit: &SurfaceHit) {
        if self.in_camera_ray && self.hit.is_none() {
            self.hit = Some(FirstHit {
                t: hit.t,
                normal: hit.geometric_normal.to_array(),
            });
        }
    }
}

/// Every pixel's first hit (row-major, top first), traced as the render traces its rays.
fn first_hits(scene: &PreparedScene, options: &RenderOptions) -> Vec<Option<FirstHit>> {
    (0..options.height)
        .into_par_iter()
        .flat_map_iter(|y| {
            (0..options.width).map(move |x| {
                let mut recorder = FirstHitRecorder::default();
                whitted_tracer::trace_pixel_with(scene, options, x, y, 0, &mut recorder);
                recorder.hit
            })
        })
        .collect()
}

/// The course's depth image: `t` from `near` (white) to `far` (black), clamped; black where
/// nothing is hit.
pub fn depth_image(hits: &[Option<FirstHit>], near: f64, far: f64) -> Vec<u8> {
    hits.iter()
        .flat_map(|hit| {
            let v = hit.map_or(0.0, |h| {
                ((far - f64::from(h.t)) / (far - near)).clamp(0.0, 1.0)
            });
            [(v * 255.0).round() as u8; 3]
        })
        .collect()
}

/// The course's normals image: the absolute value of each component of the hit's unit
/// normal as red, green and blue; black where nothing is hit.
pub fn normals_image(hits: &[Option<FirstHit>]) -> Vec<u8> {
    hits.iter()
        .flat_map(|hit| {
            let n = hit.map_or([0.0; 3], |h| h.normal);
            n.map(|c| (c.abs().min(1.0) * 255.0).round() as u8)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_words(text: &str) -> Result<Request, String> {
        let words: Vec<OsString> = text.split_whitespace().map(OsString::from).collect();
        parse(&words)
    }

    #[test]
    fn the_assignment_command_lines_read_verbatim() {
        let request = parse_words(
            "-input scene4_03.txt -size 200 150 -output out.tga -shadows -bounces 4 \
             -weight 0.01 -shade_back -depth 9 11 depth.tga -normals normals.png",
        );
        let Ok(Request::Run(run)) = request else {
            panic!("{request:?}");
        };
        assert_eq!(run.input, PathBuf::from("scene4_03.txt"));
        assert_eq!((run.options.width, run.options.height), (200, 150));
        assert!(run.options.shadows && run.options.shade_back);
        assert!(!run.options.transparent_shadows);
        assert_eq!((run.options.bounces, run.options.weight), (4, 0.01));
        assert_eq!(run.output, Some(PathBuf::from("out.tga")));
        assert_eq!(run.depth, Some((9.0, 11.0, PathBuf::from("depth.tga"))));
        assert_eq!(run.normals, Some(PathBuf::from("normals.png")));
        assert_eq!(parse_words("-input a.txt -help"), Ok(Request::Help));
    }

    #[test]
    fn whitted_s_own_set_and_the_sample_position_are_read() {
        let line = "-input a.txt -size 8 8 -output a.tga --set epsilon=0 -sample_position corner \
                    --set ambient=0";
        let Ok(Request::Run(run)) = parse_words(line) else {
            panic!("{line} was refused");
        };
        assert_eq!(
            run.sets,
            vec![
                ("epsilon".to_string(), "0".to_string()),
                ("ambient".to_string(), "0".to_string())
            ]
        );
        assert_eq!(
            run.options.sample_position,
            whitted_ir::SamplePosition::Corner
        );
        for (line, message) in [
            ("-input a.txt -size 8 8 --set", "--set needs NAME=VALUE"),
            ("-input a.txt -size 8 8 --set epsilon", "write NAME=VALUE"),
            (
                "-input a.txt -size 8 8 -sample_position middle",
                "-sample_position takes centre or corner",
            ),
        ] {
            let error = parse_words(line).err().unwrap_or_default();
            assert!(error.contains(message), "{line}: {error}");
        }
    }

    #[test]
    fn mistakes_name_their_flag() {
        let cases = [
            ("-size 10 10 -output a.tga", "-input SCENE.txt is required"),
            ("-input a.txt -output a.tga", "-size W H is required"),
            ("-input a.txt -size 10", "-size needs a width and a height"),
            (
                "-input a.txt -size 10 0 -output a.tga",
                "the height must be from 1",
            ),
            ("-input a.txt -size ten 10", "-size: `ten` is not a width"),
            (
                "-input a.txt -size 10 10 -output a.jpg",
                "the course's images are .tga, .png or .ppm",
            ),
            (
                "-input a.txt -size 10 10 -output a.tga -bounces 999",
                "-bounces 999 is past the max depth limit (256)",
            ),
            (
                "-input a.txt -size 10 10 -output a.tga -weight 2",
                "-weight must be from 0 to 1",
            ),
            (
                "-input a.txt -size 10 10 -depth 5 2 d.tga",
                "the near distance must be less",
            ),
            (
                "-input a.txt -size 10 10 -output a.tga -visualize_grid",
                "-visualize_grid is not available in whitted: assignment 6 draws the cells",
            ),
            (
                "-input a.txt -size 10 10 -output a.tga -zoom_factor 4",
                "the zoom is the second argument of -render_samples FILE ZOOM",
            ),
            (
                "-input a.txt -size 10 10 -output a.tga -box_filter 5",
                "-box_filter 5: the radius must be above 0 and at most 4 pixels",
            ),
            (
                "-input a.txt -size 10 10 -output a.tga -gaussian_filter -1",
                "-gaussian_filter -1: the sigma must be above 0",
            ),
            (
                "-input a.txt -size 10 10 -output a.tga -tent_filter 1 -box_filter 1",
                "give one of -box_filter, -tent_filter and -gaussian_filter",
            ),
            (
                "-input a.txt -size 10 10 -render_samples s.tga",
                "-render_samples needs an image file and a zoom",
            ),
            (
                "-input a.txt -size 10 10 -render_filter f.jpg 4",
                "the course's images are .tga, .png or .ppm",
            ),
            (
                "-input a.txt -size 10 10 -render_filter f.tga 65",
                "-render_filter: the zoom must be from 1 to 64, not 65",
            ),
            (
                "-input a.txt -size 1000 1000 -render_samples s.tga 20",
                "a 1000x1000 image zoomed 20 times is a 20000x20000 picture",
            ),
            (
                "-input a.txt -size 10 10 -output a.tga -uniform_samples 4 -random_samples 4",
                "give one of -uniform_samples, -jittered_samples and -random_samples",
            ),
            (
                "-input a.txt -size 10 10 -output a.tga --shadows",
                "unknown flag `--shadows`",
            ),
            ("-input a.txt -input b.txt", "-input is given twice"),
        ];
        for (line, expected) in cases {
            match parse_words(line) {
                Err(message) => assert!(message.contains(expected), "{line}: {message}"),
                Ok(request) => panic!("{line} was accepted: {request:?}"),
            }
        }
    }

    /// Assignment 7's samplers become the sampling setting; the preview's flags are taken
    /// and ignored with a note.
    #[test]
    fn the_course_s_samplers_and_preview_flags_are_read() {
        let line = "-input a.txt -size 8 8 -output a.tga -uniform_samples 9 -box_filter 0.5 \
                    -stats -tessellation 10 5 -gouraud -grid 10 10 10";
        let Ok(Request::Run(run)) = parse_words(line) else {
            panic!("{line} was refused");
        };
        assert_eq!(run.options.samples, 9);
        assert_eq!(run.options.sampling, whitted_ir::Sampling::Grid);
        assert!(run.stats);
        assert_eq!(run.notes.len(), 3, "{:?}", run.notes);
        for (flag, sampling) in [
            ("-jittered_samples", whitted_ir::Sampling::Jittered),
            ("-random_samples", whitted_ir::Sampling::Random),
        ] {
            let line = format!("-input a.txt -size 8 8 -output a.tga {flag} 4");
            let Ok(Request::Run(run)) = parse_words(&line) else {
                panic!("{line} was refused");
            };
            assert_eq!((run.options.samples, run.options.sampling), (4, sampling));
        }
    }

    /// Assignment 7's filters become the filter setting; its pictures and -gui are read
    /// with their arguments in the course's order (file, then zoom).
    #[test]
    fn the_course_s_filters_pictures_and_gui_are_read() {
        let line = "-input a.txt -size 9 9 -render_samples s.tga 20 -render_filter f.tga 10 \
                    -jittered_samples 4 -tent_filter 1.5 -gui";
        let Ok(Request::Run(run)) = parse_words(line) else {
            panic!("{line} was refused");
        };
        assert_eq!(run.render_samples, Some((PathBuf::from("s.tga"), 20)));
        assert_eq!(run.render_filter, Some((PathBuf::from("f.tga"), 10)));
        assert_eq!(
            (run.options.filter, run.options.filter_radius),
            (whitted_ir::Filter::Tent, 1.5)
        );
        assert!(run.gui && run.output.is_none());
        for (flag, filter) in [
            ("-box_filter 0.5", whitted_ir::Filter::Box),
            ("-gaussian_filter 0.4", whitted_ir::Filter::Gaussian),
        ] {
            let line = format!("-input a.txt -size 8 8 -output a.tga {flag}");
            let Ok(Request::Run(run)) = parse_words(&line) else {
                panic!("{line} was refused");
            };
            assert_eq!(run.options.filter, filter);
        }
        let Ok(Request::Run(run)) = parse_words("-input a.txt -size 8 8 -gui") else {
            panic!("-gui alone was refused");
        };
        assert!(run.gui);
    }

    #[test]
    fn depth_and_normals_follow_the_course_by_hand() {
        let hits = [
            None,
            Some(FirstHit {
                t: 9.0,
                normal: [0.0, -0.6, 0.8],
            }),
            Some(FirstHit {
                t: 10.0,
                normal: [1.0, 0.0, 0.0],
            }),
            Some(FirstHit {
                t: 12.0,
                normal: [0.0, 0.0, -1.0],
            }),
        ];
        // 9 is the near distance (white), 11 the far one (black), 10 half way, 12 past it.
        assert_eq!(
            depth_image(&hits, 9.0, 11.0),
            vec![0, 0, 0, 255, 255, 255, 128, 128, 128, 0, 0, 0]
        );
        assert_eq!(
            normals_image(&hits),
            vec![0, 0, 0, 0, 153, 204, 255, 0, 0, 0, 0, 255]
        );
    }
}
