//! The terminal, set up and restored in one place: raw mode, the alternate screen and mouse
//! capture on the way in; all three undone on the way out, on error (a drop guard) and on a
//! panic of the UI thread (the panic hook).
//!
//! A panic on a worker thread must not restore the terminal under a UI that keeps running,
//! nor print into the alternate screen where nobody would read it: the hook keeps its
//! message for the worker to report instead (see [`take_worker_panic`]).
//!
//! SIGTERM, SIGHUP, SIGQUIT and SIGINT (from outside: in raw mode Ctrl-C is a key) would end
//! the process with the terminal raw, on the alternate screen, with mouse capture on:
//! [`forward_signals`] turns them into events so that the UI thread restores the terminal
//! and stops.

use std::io::{self, IsTerminal, Stdout};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Mutex, Once, OnceLock};
use std::thread::{self, ThreadId};
use std::time::Duration;

use ratatui::backend::CrosstermBackend;
use ratatui::crossterm::event::{DisableMouseCapture, EnableMouseCapture};
use ratatui::crossterm::execute;
use ratatui::crossterm::terminal::{
    disable_raw_mode, enable_raw_mode, EnterAlternateScreen, LeaveAlternateScreen,
};
use ratatui::Terminal;
use signal_hook::consts::{SIGHUP, SIGINT, SIGQUIT, SIGTERM};
use signal_hook::iterator::Signals;

use crate::event::Event;

/// How long the UI thread has to give the terminal back after a signal before the signal
/// thread does it itself (the UI thread may be busy) and lets the signal take its course.
const SIGNAL_GRACE: Duration = Duration::from_secs(2);

pub type Tui = Terminal<CrosstermBackend<Stdout>>;

static UI_THREAD: OnceLock<ThreadId> = OnceLock::new();
static HOOK: Once = Once::new();
static WORKER_PANIC: Mutex<Option<String>> = Mutex::new(None);
/// Whether the terminal is ours right now. Restoring twice would leave the alternate screen
/// twice, and terminals then move the cursor back up over whatever was printed between
/// (the panic message).
static TAKEN_OVER: AtomicBool = AtomicBool::new(false);

/// Restores the terminal when dropped.
pub struct TerminalGuard {
    pub terminal: Tui,
}

impl Drop for TerminalGuard {
    fn drop(&mut self) {
        let _ = restore();
    }
}

/// Whether both ends of the session are a terminal.
pub fn is_interactive() -> bool {
    io::stdout().is_terminal() && io::stdin().is_terminal()
}

/// Takes over the terminal. On failure whatever was set up is undone.
pub fn init() -> io::Result<TerminalGuard> {
    let _ = UI_THREAD.set(thread::current().id());
    install_panic_hook();
    let set_up = || -> io::Result<Tui> {
        TAKEN_OVER.store(true, Ordering::SeqCst);
        enable_raw_mode()?;
        execute!(io::stdout(), EnterAlternateScreen, EnableMouseCapture)?;
        let mut terminal = Terminal::new(CrosstermBackend::new(io::stdout()))?;
        terminal.hide_cursor()?;
        terminal.clear()?;
        Ok(terminal)
    };
    match set_up() {
        Ok(terminal) => Ok(TerminalGuard { terminal }),
        Err(error) => {
            let _ = restore();
            Err(error)
        }
    }
}

/// Gives the terminal back: mouse capture off, main screen, cooked mode, cursor shown. Only
/// the first call after [`init`] does anything.
pub fn restore() -> io::Result<()> {
    if !TAKEN_OVER.swap(false, Ordering::SeqCst) {
        return Ok(());
    }
    let mouse = execute!(
        io::stdout(),
        DisableMouseCapture,
        LeaveAlternateScreen,
        ratatui::crossterm::cursor::Show
    );
    let raw = disable_raw_mode();
    mouse.and(raw)
}

fn install_panic_hook() {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if Some(&thread::current().id()) == UI_THREAD.get() {
                let _ = restore();
                previous(info);
            } else {
                let payload = panic_text(info.payload());
                let location = info
                    .location()
                    .map(|l| format!(" at {}:{}", l.file(), l.line()))
                    .unwrap_or_default();
                if let Ok(mut slot) = WORKER_PANIC.lock() {
                    *slot = Some(format!("{payload}{location}"));
                }
            }
        }));
    });
}

/// A panic's message, from its payload.
pub fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_string())
}

/// The message of the latest panic on a worker thread, if any (taken: asked once).
pub fn take_worker_panic() -> Option<String> {
    WORKER_PANIC.lock().ok().and_then(|mut slot| slot.take())
}

/// Sends SIGTERM, SIGHUP, SIGQUIT and SIGINT to the event loop as [`Event::Signal`]. Should
/// the loop not stop within [`SIGNAL_GRACE`], this thread restores the terminal and ends the
/// process as the signal would have.
pub fn forward_signals(events: Sender<Event>) -> io::Result<()> {
    let mut signals = Signals::new([SIGTERM, SIGHUP, SIGQUIT, SIGINT])?;
    thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let _ = events.send(Event::Signal(signal));
                thread::sleep(SIGNAL_GRACE);
                let _ = restore();
                signals.handle().close();
                let _ = signal_hook::low_level::emulate_default_handler(signal);
            }
        })?;
    Ok(())
}
