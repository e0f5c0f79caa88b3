//! `whitted debug`: compiles the scene, then hands it to the terminal debugger together with
//! a way to compile it again from disk and the files to watch. The debugger itself never
//! parses or reads scene files.

use std::path::{Path, PathBuf};

use whitted_debugger::{Compiled, DebugError, Recompile, Session};
use whitted_ir::SourceMap;
use whitted_mit6837::CourseOptions;

use crate::cli::{DebugArgs, RenderOverrides, SceneArgs};
use crate::scene_input::load_scene;
use crate::Failure;

pub fn debug(args: &DebugArgs) -> Result<(), Failure> {
    // The first compile prints its diagnostics like every other command; a scene with
    // errors stops here, before the terminal is taken over.
    let loaded = load_scene(&args.scene, false)?;
    // At the size and depth of the render it follows (`--width`, `--max-depth`, ...), so
    // that a pixel a lint or `render` names is the same pixel here.
    let (loaded, _) = crate::setting_flags::apply_render_flags(loaded, &args.overrides)?;
    let settings = &loaded.scene.settings;
    if let Some([x, y]) = args.pixel {
        if x >= settings.width || y >= settings.height {
            return Err(crate::request::pixel_outside(
                [x, y],
                settings.width,
                settings.height,
            ));
        }
    }
    let scene_args = args.scene.clone();
    let overrides = args.overrides.clone();
    let course = CourseOptions::default();
    let recompile: Recompile =
        Box::new(move |frame| compile(&scene_args, frame, &overrides, &course));
    run_debugger(
        &args.scene,
        loaded,
        recompile,
        args.pixel.map(|[x, y]| (x, y)),
    )
}

/// `whitted mit6837 ... -gui`: the debugger on a 6.837 scene compiled with the command
/// line's switches (`-shadows`, `-bounces`, the samples and the filter, `-size`), which
/// every reload compiles with again.
pub fn debug_course(
    scene: &SceneArgs,
    course: &CourseOptions,
    loaded: crate::scene_input::Loaded,
) -> Result<(), Failure> {
    let (scene_args, course) = (scene.clone(), course.clone());
    let overrides = RenderOverrides::default();
    let recompile: Recompile =
        Box::new(move |frame| compile(&scene_args, frame, &overrides, &course));
    run_debugger(scene, loaded, recompile, None)
}

/// Whether the debugger can start here: a terminal on stdin and stdout.
pub fn has_terminal() -> bool {
    use std::io::IsTerminal;
    std::io::stdout().is_terminal() && std::io::stdin().is_terminal()
}

fn run_debugger(
    scene: &SceneArgs,
    loaded: crate::scene_input::Loaded,
    recompile: Recompile,
    pixel: Option<(u32, u32)>,
) -> Result<(), Failure> {
    let watch = watch_list(
        &scene.scene,
        &loaded.scene.sources,
        Some(loaded.scene.scene()),
    );
    let session = Session {
        scene_name: scene.scene.display().to_string(),
        scene: loaded.scene,
        watch,
        recompile,
        frame: scene.frame,
        pixel,
        export_dir: export_dir(&scene.scene),
    };
    whitted_debugger::run(session).map_err(|error| match error {
        DebugError::NotATerminal => Failure::Usage(error.to_string()),
        DebugError::Terminal(_) => Failure::Message(error.to_string()),
        DebugError::Signal(signal) => Failure::Signal(signal),
    })
}

/// Where `e` writes the ray tree's JSON: beside the scene file (not wherever the debugger
/// was started), as an absolute path so that the status line says exactly where.
fn export_dir(scene: &Path) -> PathBuf {
    let folder = match scene.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::path::absolute(&folder).unwrap_or(folder)
}

/// Compiles the scene again (with the front end its content calls for, and the same `-D`,
/// `--set` and course switches as the first compile) at `frame` (`None`: the command
/// line's `--frame`), silently: the debugger shows the diagnostics itself.
fn compile(
    args: &SceneArgs,
    frame: Option<u32>,
    overrides: &RenderOverrides,
    course: &CourseOptions,
) -> Compiled {
    let args = SceneArgs {
        frame: frame.or(args.frame),
        ..args.clone()
    };
    let args = &args;
    let mut compilation = crate::front_end::compile(args, course);
    if let Some(scene) = compilation.scene.take() {
        match crate::setting_flags::apply_to_scene(scene, overrides) {
            Ok(scene) => compilation.scene = Some(scene),
            Err(failure) => compilation.diagnostics.push(whitted_ir::Diagnostic::new(
                whitted_ir::Severity::Error,
                failure
                    .message()
                    .unwrap_or("the command line's settings do not fit"),
                None,
            )),
        }
    }
    let watch = watch_list(
        &args.scene,
        &compilation.sources,
        compilation.scene.as_ref().map(|valid| valid.scene()),
    );
    Compiled {
        scene: compilation.scene,
        diagnostics: compilation.diagnostics,
        sources: compilation.sources,
        watch,
    }
}

/// The root file and every source file that exists on disk (imports; not the pseudo-files
/// of `-D` values), and the mesh files of a scene that compiled (saving a model reloads).
fn watch_list(root: &Path, sources: &SourceMap, scene: Option<&whitted_ir::Scene>) -> Vec<PathBuf> {
    let mut files = vec![root.to_path_buf()];
    let meshes = scene
        .into_iter()
        .flat_map(|scene| scene.meshes.iter().map(|(_, mesh)| mesh.file.as_str()));
    let paths = sources.files().map(|(_, file)| file.path.as_str());
    for path in paths.chain(meshes) {
        let path = PathBuf::from(path);
        if path.is_file() && !files.contains(&path) {
            files.push(path);
        }
    }
    files
}
