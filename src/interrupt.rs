//! Removing temporary files when the process is interrupted: a SIGINT, SIGTERM or SIGHUP
//! during a write would otherwise leave the half-written `.whitted-*.tmp` file behind (the
//! temporary file deletes itself when dropped, but a signal ends the process without drops).

use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once};

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// The temporary files being written right now.
static TEMPORARY: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static INSTALL: Once = Once::new();

/// Starts the thread that waits for the signals; on one it removes every registered file and
/// exits as the signal would have (128 + its number: 130 for SIGINT, 143 for SIGTERM). If the
/// thread cannot start, signals keep their default behaviour.
pub fn install() {
    INSTALL.call_once(|| {
        let Ok(mut signals) = Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return;
        };
        let _ = std::thread::Builder::new()
            .name("signals".into())
            .spawn(move || {
                if let Some(signal) = signals.forever().next() {
                    // The lock is held until exit, so that no new file appears meanwhile.
                    let files = TEMPORARY.lock().unwrap_or_else(|e| e.into_inner());
                    for path in files.iter() {
                        let _ = std::fs::remove_file(path);
                    }
                    std::process::exit(128 + signal);
                }
            });
    });
}

/// A temporary file registered for removal on a signal; unregistered when dropped.
pub struct Registered {
    path: PathBuf,
}

/// Registers `path` (a temporary file just created) for removal on a signal.
pub fn register(path: &Path) -> Registered {
    let mut files = TEMPORARY.lock().unwrap_or_else(|e| e.into_inner());
    files.push(path.to_path_buf());
    Registered {
        path: path.to_path_buf(),
    }
}

impl Drop for Registered {
    fn drop(&mut self) {
        let mut files = TEMPORARY.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(index) = files.iter().position(|p| *p == self.path) {
            files.swap_remove(index);
        }
    }
}
