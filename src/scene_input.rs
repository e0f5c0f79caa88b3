//! Reading and compiling scenes from disk, printing their diagnostics, and the two commands
//! that do nothing else: `check` and `ir`.

use std::io::{IsTerminal, Write};
use std::path::Path;

use whitted_ir::{Severity, ValidScene};
use whitted_lang::render_diagnostics;
use whitted_mit6837::CourseOptions;

use crate::cli::{CheckArgs, IrArgs, SceneArgs};
use crate::Failure;

/// Reads one scene file's bytes (the language decodes them and locates bad UTF-8), refusing
/// what is not a regular file (a device such as `/dev/zero` never ends, a FIFO blocks) and
/// stopping at the source size limit rather than reading until memory runs out.
pub fn read_source(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::{Error, ErrorKind, Read};
    let limit = whitted_ir::limits::MAX_SOURCE_BYTES;
    let not_regular = |kind: &str| {
        Error::new(
            ErrorKind::InvalidInput,
            format!("it is {kind}, not a regular file"),
        )
    };
    // Look before opening: opening a FIFO for reading blocks until a writer appears.
    let kind = std::fs::metadata(path)?.file_type();
    if !kind.is_file() {
        return Err(not_regular(file_kind(kind)));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    // The file may have been swapped for a FIFO since; never block on the open.
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let kind = file.metadata()?.file_type();
    if !kind.is_file() {
        return Err(not_regular(file_kind(kind)));
    }
    // Room for the whole file up front (one byte more, so that reaching its end needs no
    // growth): growing by doubling would copy and touch a large generated scene twice over.
    let expected = usize::try_from(file.metadata()?.len()).unwrap_or(usize::MAX);
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(expected.min(limit) + 1)
        .map_err(|_| Error::new(ErrorKind::OutOfMemory, "not enough memory to read it"))?;
    file.take(limit as u64 + 1).read_to_end(&mut bytes)?;
    if bytes.len() > limit {
        return Err(Error::new(
            ErrorKind::InvalidData,
            format!("it has more than {limit} bytes, the source size limit"),
        ));
    }
    Ok(bytes)
}

/// Names the kind of a file that is not a regular one, for error messages.
fn file_kind(kind: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a directory"
    } else {
        "a special file"
    }
}

/// Whether to colour what goes to stderr: only on a terminal, and never under NO_COLOR.
pub fn stderr_wants_color() -> bool {
    std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none()
}

/// A compiled scene plus what the user should hear about it.
pub struct Loaded {
    pub scene: ValidScene,
    pub warnings: usize,
    /// Where the compiler's own warnings point, so that a lint does not say the same
    /// thing twice (the language warns about `reflective + transmissive > 1` itself).
    pub warned_at: Vec<whitted_ir::Span>,
}

/// Compiles `args.scene` (with either front end, a 6.837 scene with the course's defaults),
/// prints diagnostics (all of them, or only errors when `quiet`), and returns the scene or
/// `Failure::SceneErrors`.
pub fn load_scene(args: &SceneArgs, quiet: bool) -> Result<Loaded, Failure> {
    load_scene_with(args, quiet, &CourseOptions::default())
}

/// [`load_scene`] with the course's switches for a 6.837 scene.
pub fn load_scene_with(
    args: &SceneArgs,
    quiet: bool,
    course: &CourseOptions,
) -> Result<Loaded, Failure> {
    // Report a missing or unreadable root file as one line, before the compiler sees it.
    if let Err(error) = std::fs::metadata(&args.scene) {
        return Err(Failure::Message(format!(
            "cannot read {}: {error}",
            args.scene.display()
        )));
    }
    let compilation = crate::front_end::compile(args, course);
    let shown: Vec<_> = compilation
        .diagnostics
        .iter()
        .filter(|d| !quiet || d.severity == Severity::Error)
        .cloned()
        .collect();
    if !shown.is_empty() {
        let text = render_diagnostics(&compilation.sources, &shown, stderr_wants_color());
        let _ = std::io::stderr().write_all(text.as_bytes());
    }
    let warnings = compilation
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Warning)
        .count();
    match compilation.scene {
        Some(scene) => Ok(Loaded {
            scene,
            warnings,
            warned_at: compilation
                .diagnostics
                .iter()
                .filter(|d| d.severity == Severity::Warning)
                .filter_map(|d| d.span)
                .collect(),
        }),
        None => {
            let errors = compilation
                .diagnostics
                .iter()
                .filter(|d| d.is_error())
                .count();
            // Errors only in what the command line said (`--set foo=1`, `-D N=oops`): the
            // usage is wrong, not the scene (exit 2, the flag quoted).
            let flag_of = |d: &whitted_ir::Diagnostic| {
                let file = d.span.filter(|s| !s.is_detached())?.file;
                let path = &compilation.sources.get(file)?.path;
                path.strip_prefix('<')
                    .and_then(|p| p.strip_suffix('>'))
                    .filter(|p| p.starts_with("--set ") || p.starts_with("-D "))
                    .map(str::to_string)
            };
            let flags: Option<Vec<String>> = compilation
                .diagnostics
                .iter()
                .filter(|d| d.is_error())
                .map(flag_of)
                .collect();
            if let Some(mut flags) = flags.filter(|f| !f.is_empty()) {
                flags.dedup();
                let quoted: Vec<String> = flags.iter().map(|f| format!("`{f}`")).collect();
                return Err(Failure::Usage(format!(
                    "the command line has {errors} error{} (in {}); the scene has no errors of its own",
                    if errors == 1 { "" } else { "s" },
                    quoted.join(", ")
                )));
            }
            let _ = writeln!(
                std::io::stderr(),
                "error: {} has {errors} error{}",
                args.scene.display(),
                if errors == 1 { "" } else { "s" }
            );
            Err(Failure::SceneErrors)
        }
    }
}

/// `whitted check`: compile, validate, lint (unless `--no-lint`), summarise.
pub fn check(check_args: &CheckArgs) -> Result<(), Failure> {
    let args = &check_args.scene;
    let mut loaded = load_scene(args, false)?;
    let big = !whitted_explain::lint::lints_by_default(&loaded.scene);
    if big && !check_args.lint && !check_args.no_lint {
        let _ = writeln!(
            std::io::stderr(),
            "note: not linted: {} objects is more than {} (`--lint` lints it anyway)",
            loaded.scene.objects.len(),
            whitted_explain::lint::MAX_OBJECTS
        );
    } else if !check_args.no_lint {
        let prepared = whitted_tracer::PreparedScene::new(&loaded.scene);
        let options = whitted_tracer::RenderOptions::from_settings(&loaded.scene.settings);
        loaded.warnings += print_lints(&loaded, &prepared, &options);
    }
    let scene = &loaded.scene;
    let summary = format!(
        "{}: ok ({} object{}, {} light{}, {} material{}{})\n",
        args.scene.display(),
        scene.objects.len(),
        if scene.objects.len() == 1 { "" } else { "s" },
        scene.lights.len(),
        if scene.lights.len() == 1 { "" } else { "s" },
        scene.materials.len(),
        if scene.materials.len() == 1 { "" } else { "s" },
        match loaded.warnings {
            0 => String::new(),
            1 => ", 1 warning".to_string(),
            n => format!(", {n} warnings"),
        }
    );
    write_stdout(&summary)
}

/// Lints a compiled scene (docs/explain.md, "Lints"), prints its warnings like the
/// compiler's and returns how many there were. A lint at a place the compiler already
/// warned about is left out. `prepared` must be made from `loaded.scene`.
pub fn print_lints(
    loaded: &Loaded,
    prepared: &whitted_tracer::PreparedScene,
    options: &whitted_tracer::RenderOptions,
) -> usize {
    let scene = &loaded.scene;
    let lints = whitted_explain::lint::lint_at(prepared, scene, options);
    let diagnostics: Vec<_> = lints
        .into_iter()
        .map(|l| l.diagnostic)
        .filter(|d| d.span.is_none_or(|span| !loaded.warned_at.contains(&span)))
        .collect();
    if diagnostics.is_empty() {
        return 0;
    }
    let text = render_diagnostics(&scene.sources, &diagnostics, stderr_wants_color());
    let _ = std::io::stderr().write_all(text.as_bytes());
    diagnostics.len()
}

/// `whitted ir`: the compiled IR as text or JSON on stdout.
pub fn ir(args: &IrArgs) -> Result<(), Failure> {
    let loaded = load_scene(&args.scene, false)?;
    if args.json {
        write_json_stdout(&whitted_ir::json_document(&loaded.scene))
    } else {
        write_stdout(&whitted_ir::print(&loaded.scene))
    }
}

/// Writes `value` as pretty JSON and a newline to stdout as it is serialised, never holding
/// the whole text (a million objects would take gigabytes); a closed pipe is success.
pub fn write_json_stdout<T: serde::Serialize>(value: &T) -> Result<(), Failure> {
    let mut writer = std::io::BufWriter::new(std::io::stdout().lock());
    let written = serde_json::to_writer_pretty(&mut writer, value)
        .map_err(std::io::Error::from)
        .and_then(|()| writer.write_all(b"\n"))
        .and_then(|()| writer.flush());
    match written {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Failure::Message(format!("cannot write to stdout: {e}"))),
    }
}

/// Writes to stdout, treating a closed pipe (`| head`) as success rather than a crash.
pub fn write_stdout(text: &str) -> Result<(), Failure> {
    let mut stdout = std::io::stdout().lock();
    match stdout
        .write_all(text.as_bytes())
        .and_then(|_| stdout.flush())
    {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Failure::Message(format!("cannot write to stdout: {e}"))),
    }
}
