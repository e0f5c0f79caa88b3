//! `whitted fmt`: scene files laid out in the canonical way by `whitted_lang::format_source`,
//! rewritten in place (atomically, and only when they change), or with `--check` a diff of
//! what would change and exit 1.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use whitted_lang::{format_source, render_diagnostics};

use crate::cli::FmtArgs;
use crate::scene_input::{read_source, stderr_wants_color};
use crate::Failure;

pub fn fmt(args: &FmtArgs) -> Result<(), Failure> {
    let stdin_only = args.files.is_empty() || args.files.iter().all(|f| f == Path::new("-"));
    if stdin_only {
        return fmt_stdin(args.check);
    }
    let mut files = Vec::new();
    for path in &args.files {
        if path == Path::new("-") {
            return Err(Failure::Usage(
                "`-` (standard input) cannot be mixed with files".to_string(),
            ));
        }
        collect(path, &mut files)
            .map_err(|e| Failure::Message(format!("cannot read {}: {e}", path.display())))?;
    }
    let (mut broken, mut changed) = (0usize, 0usize);
    for file in &files {
        match fmt_file(file, args.check) {
            Ok(true) => changed += 1,
            Ok(false) => {}
            Err(Some(message)) => {
                let _ = writeln!(std::io::stderr(), "error: {message}");
                broken += 1;
            }
            Err(None) => broken += 1,
        }
    }
    if broken > 0 {
        return Err(Failure::Message(format!(
            "{broken} of {} file(s) could not be formatted",
            files.len()
        )));
    }
    if args.check && changed > 0 {
        return Err(Failure::Message(format!(
            "{changed} of {} file(s) are not formatted; `whitted fmt` would change them as shown",
            files.len()
        )));
    }
    Ok(())
}

/// The files a path names: itself, or every `.scene` file under a folder, in name order.
fn collect(path: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    if !std::fs::metadata(path)?.is_dir() {
        out.push(path.to_path_buf());
        return Ok(());
    }
    let mut entries = std::fs::read_dir(path)?
        .map(|e| e.map(|e| e.path()))
        .collect::<std::io::Result<Vec<_>>>()?;
    entries.sort();
    for entry in entries {
        if entry.is_dir() {
            collect(&entry, out)?;
        } else if entry.extension().is_some_and(|e| e == "scene") {
            out.push(entry);
        }
    }
    Ok(())
}

/// Formats one file. `Ok(changed)`, or an error already printed (`None`) or to print.
fn fmt_file(path: &Path, check: bool) -> Result<bool, Option<String>> {
    let display = path.display().to_string();
    let bytes = read_source(path).map_err(|e| Some(format!("cannot read {display}: {e}")))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| Some(format!("{display} is not UTF-8 text; save it as UTF-8")))?;
    let formatted = format_text(&display, &text).ok_or(None)?;
    if formatted == text {
        return Ok(false);
    }
    if check {
        print_diff(&display, &text, &formatted);
    } else {
        write_atomically(path, &formatted)
            .map_err(|e| Some(format!("cannot write {display}: {e}")))?;
    }
    Ok(true)
}

/// The formatted text, or `None` after printing why the file was refused.
fn format_text(name: &str, text: &str) -> Option<String> {
    match format_source(name, text) {
        Ok(formatted) => Some(formatted),
        Err(failure) => {
            let rendered =
                render_diagnostics(&failure.sources, &failure.diagnostics, stderr_wants_color());
            let _ = write!(std::io::stderr(), "{rendered}");
            None
        }
    }
}

fn fmt_stdin(check: bool) -> Result<(), Failure> {
    let limit = whitted_ir::limits::MAX_SOURCE_BYTES;
    let mut bytes = Vec::new();
    std::io::stdin()
        .take(limit as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Failure::Message(format!("cannot read standard input: {e}")))?;
    if bytes.len() > limit {
        return Err(Failure::Message(format!(
            "standard input has more than {limit} bytes, the source size limit"
        )));
    }
    let text = String::from_utf8(bytes)
        .map_err(|_| Failure::Message("standard input is not UTF-8 text".to_string()))?;
    let formatted = format_text("<stdin>", &text).ok_or(Failure::SceneErrors)?;
    if check {
        if formatted != text {
            print_diff("<stdin>", &text, &formatted);
            return Err(Failure::Message(
                "standard input is not formatted; `whitted fmt` would change it as shown"
                    .to_string(),
            ));
        }
        return Ok(());
    }
    std::io::stdout()
        .write_all(formatted.as_bytes())
        .map_err(|e| Failure::Message(format!("cannot write standard output: {e}")))
}

/// A unified diff, as `diff -u` and `git diff` show one.
fn print_diff(name: &str, old: &str, new: &str) {
    let diff = similar::TextDiff::from_lines(old, new);
    let text = diff
        .unified_diff()
        .context_radius(3)
        .header(name, &format!("{name} (formatted)"))
        .to_string();
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes());
    if !text.ends_with('\n') {
        let _ = writeln!(out);
    }
}

/// Writes `text` to a temporary file beside `path` and renames it over `path`, keeping the
/// file's permissions: a failed write never leaves half a scene.
fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    // Through a symbolic link to the file it names, which stays a link.
    let path = &std::fs::canonicalize(path)?;
    let dir = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let permissions = std::fs::metadata(path)?.permissions();
    let mut temp = tempfile::Builder::new()
        .prefix(".whitted-")
        .suffix(".tmp")
        .tempfile_in(dir)?;
    // Dropped after the rename or the temporary file's own removal, both below.
    let _registered = crate::interrupt::register(temp.path());
    temp.write_all(text.as_bytes())?;
    temp.as_file().set_permissions(permissions)?;
    temp.as_file().sync_all()?;
    temp.persist(path).map_err(|e| e.error)?;
    Ok(())
}
