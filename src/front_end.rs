//! Picking the front end by the file's content: a file whose first word is a 6.837 keyword
//! (`OrthographicCamera`, `Group`, ...) is read by whitted-mit6837, anything else by the
//! scene language. Both give the same IR; the commands after this never know which made it.

use std::io::Read;
use std::path::Path;

use whitted_ir::{Diagnostic, Severity, SourceFile, SourceMap, Span, ValidScene};
use whitted_lang::{compile_file, CompileOptions, SourceLoader};
use whitted_mit6837::{CourseOptions, MeshLoader};

use crate::cli::SceneArgs;
use crate::scene_input::read_source;

/// Reads scene files, imports and mesh files from the file system for both front ends.
pub struct DiskLoader;

impl SourceLoader for DiskLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        read_source(path)
    }

    /// Through symbolic links, so that a linked folder that loops is an import cycle.
    fn identify(&mut self, path: &Path) -> std::path::PathBuf {
        std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
    }
}

impl MeshLoader for DiskLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        read_source(path)
    }
}

/// What either front end made of a file: its sources, the scene when it had no errors, and
/// the diagnostics (located in `sources`).
pub struct Compiled {
    pub sources: SourceMap,
    pub scene: Option<ValidScene>,
    pub diagnostics: Vec<Diagnostic>,
}

/// How much of a file is read to find its first word: a 6.837 file starts with a keyword
/// after at most this much white space.
const SNIFF_BYTES: u64 = 64 * 1024;

/// Whether the file at `path` is a 6.837 scene (see [`whitted_mit6837::is_mit6837`]).
/// Unreadable files are not: the language's reader reports them.
pub fn is_course_scene(path: &Path) -> bool {
    let Ok(metadata) = std::fs::metadata(path) else {
        return false;
    };
    if !metadata.is_file() {
        return false;
    }
    let mut start = Vec::new();
    match std::fs::File::open(path) {
        Ok(file) => match file.take(SNIFF_BYTES).read_to_end(&mut start) {
            Ok(_) => whitted_mit6837::is_mit6837(&start),
            Err(_) => false,
        },
        Err(_) => false,
    }
}

/// Compiles `args.scene` with the front end its content calls for. A 6.837 scene takes the
/// course's switches from `course` (the course's defaults for `render`, `check` and the
/// others) and then `--set` like any scene; `-D` has no meaning for it.
pub fn compile(args: &SceneArgs, course: &CourseOptions) -> Compiled {
    if !is_course_scene(&args.scene) {
        let options = CompileOptions {
            defines: args.define.clone(),
            settings: args.set.clone(),
            frame: args.frame,
            ..CompileOptions::default()
        };
        let compilation = compile_file(&args.scene, &mut DiskLoader, &options);
        return Compiled {
            sources: compilation.sources,
            scene: compilation.scene,
            diagnostics: compilation.diagnostics,
        };
    }
    let bytes = match read_source(&args.scene) {
        Ok(bytes) => bytes,
        Err(error) => {
            return Compiled {
                sources: SourceMap::new(),
                scene: None,
                diagnostics: vec![Diagnostic::new(
                    Severity::Error,
                    format!("cannot read {}: {error}", args.scene.display()),
                    None,
                )],
            }
        }
    };
    let conversion = whitted_mit6837::convert(&args.scene, bytes, &mut DiskLoader, course);
    let mut compiled = Compiled {
        sources: conversion.sources,
        scene: conversion.scene,
        diagnostics: conversion.diagnostics,
    };
    if let Some((name, value)) = args.define.first() {
        compiled.scene = None;
        // In the flag's pseudo-file, as the language puts its `-D` errors: the command line
        // is at fault (exit 2), and the message quotes it.
        let file = compiled.sources.add(SourceFile::new(
            format!("<-D {name}>"),
            format!("{name}={value}"),
        ));
        compiled.diagnostics.push(Diagnostic::new(
            Severity::Error,
            format!(
                "-D {name}: a 6.837 scene has no constants to override (use --set for settings)"
            ),
            Some(Span::new(file, 0, name.len())),
        ));
        return compiled;
    }
    if args.set.is_empty() {
        return compiled;
    }
    let Some(scene) = compiled.scene.take() else {
        return compiled;
    };
    // `--set` through the IR's settings table, from the 6.837 scene's own settings.
    match crate::setting_flags::apply_course_sets(scene, &args.set) {
        Ok(scene) => {
            compiled.sources = scene.sources.clone();
            compiled.scene = Some(scene);
        }
        Err((sources, diagnostics)) => {
            compiled.sources = sources;
            compiled.diagnostics.extend(diagnostics);
        }
    }
    compiled
}
