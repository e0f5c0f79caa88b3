//! Watching the scene's files: a change to the root file or any import sends
//! [`Event::FileChanged`]. Directories are watched rather than files, because editors often
//! save by writing a new file and renaming it over the old one, which ends a watch on the
//! file itself.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};

use notify::{EventKind, RecommendedWatcher, RecursiveMode, Watcher};

use crate::event::Event;

pub struct FileWatch {
    watcher: RecommendedWatcher,
    dirs: BTreeSet<PathBuf>,
    /// The watched files, as canonical directory + file name (how events name them).
    files: Arc<Mutex<BTreeSet<PathBuf>>>,
}

impl FileWatch {
    pub fn start(events: Sender<Event>) -> notify::Result<FileWatch> {
        let files: Arc<Mutex<BTreeSet<PathBuf>>> = Arc::default();
        let watched = Arc::clone(&files);
        let watcher = notify::recommended_watcher(move |result: notify::Result<notify::Event>| {
            let Ok(event) = result else {
                return;
            };
            if matches!(event.kind, EventKind::Access(_)) {
                return;
            }
            let relevant = watched
                .lock()
                .is_ok_and(|files| event.paths.iter().any(|p| files.contains(p)));
            if relevant {
                let _ = events.send(Event::FileChanged);
            }
        })?;
        Ok(FileWatch {
            watcher,
            dirs: BTreeSet::new(),
            files,
        })
    }

    /// Watches exactly these files from now on (the scene's sources change on reload).
    /// Files whose directory cannot be watched are skipped: reloading with `r` still works.
    pub fn set_files(&mut self, files: &[PathBuf]) {
        let keys: BTreeSet<PathBuf> = files.iter().filter_map(|f| watch_key(f)).collect();
        let dirs: BTreeSet<PathBuf> = keys
            .iter()
            .filter_map(|k| k.parent().map(Path::to_path_buf))
            .collect();
        for gone in self.dirs.difference(&dirs) {
            let _ = self.watcher.unwatch(gone);
        }
        let mut watching = BTreeSet::new();
        for dir in &dirs {
            let ok = self.dirs.contains(dir)
                || self.watcher.watch(dir, RecursiveMode::NonRecursive).is_ok();
            if ok {
                watching.insert(dir.clone());
            }
        }
        self.dirs = watching;
        if let Ok(mut slot) = self.files.lock() {
            *slot = keys;
        }
    }
}

/// The path a file's events carry: its canonical directory joined with its name (the file
/// itself may be missing for a moment while an editor saves it).
fn watch_key(file: &Path) -> Option<PathBuf> {
    let name = file.file_name()?;
    let dir = match file.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(dir).ok()?.join(name))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;
    use std::time::Duration;

    #[test]
    fn writing_a_watched_file_sends_file_changed_and_others_do_not() {
        let dir = std::env::temp_dir().join(format!("whitted-watch-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let scene = dir.join("a.scene");
        let other = dir.join("notes.txt");
        std::fs::write(&scene, "one").unwrap();
        let (sender, receiver) = mpsc::channel();
        let mut watch = FileWatch::start(sender).unwrap();
        watch.set_files(std::slice::from_ref(&scene));
        std::fs::write(&other, "not watched").unwrap();
        std::fs::write(&scene, "two").unwrap();
        let changed = receiver.recv_timeout(Duration::from_secs(10));
        assert!(matches!(changed, Ok(Event::FileChanged)));
        // Unwatching everything stops the events.
        watch.set_files(&[]);
        while receiver.try_recv().is_ok() {}
        std::fs::write(&scene, "three").unwrap();
        assert!(receiver.recv_timeout(Duration::from_millis(300)).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
