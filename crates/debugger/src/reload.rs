//! The reload worker: a thread that owns the binary's recompile callback, compiles and
//! prepares the scene when asked, and sends the result to the event loop. Requests that
//! pile up while it works are merged into one compilation.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc::{self, Sender};

use whitted_ir::{Diagnostic, Severity};

use crate::app::{LoadedScene, SceneErrors};
use crate::event::{Event, Reloaded};
use crate::session::{Compiled, Recompile};

pub struct Reloader {
    requests: Sender<()>,
}

impl Reloader {
    pub fn start(mut recompile: Recompile, events: Sender<Event>) -> std::io::Result<Reloader> {
        let (requests, pending) = mpsc::channel::<()>();
        std::thread::Builder::new()
            .name("reload".into())
            .spawn(move || {
                while pending.recv().is_ok() {
                    while pending.try_recv().is_ok() {}
                    // A compiler panic is a bug, but it must not take the debugger down
                    // with it: report it as an error of the scene.
                    let reloaded = match catch_unwind(AssertUnwindSafe(&mut recompile)) {
                        Ok(compiled) => load(compiled),
                        Err(_) => Reloaded {
                            result: Err(SceneErrors {
                                diagnostics: vec![Diagnostic::new(
                                    Severity::Error,
                                    format!(
                                        "the compiler crashed on this scene (a bug in whitted): {}",
                                        crate::terminal::take_worker_panic()
                                            .unwrap_or_else(|| "no message".into())
                                    ),
                                    None,
                                )],
                                sources: Default::default(),
                            }),
                            watch: Vec::new(),
                        },
                    };
                    if events.send(Event::Reloaded(reloaded)).is_err() {
                        break;
                    }
                }
            })?;
        Ok(Reloader { requests })
    }

    pub fn request(&self) {
        let _ = self.requests.send(());
    }
}

/// Prepares a compiled scene for rendering (the BVH build happens here, off the UI thread).
pub fn load(compiled: Compiled) -> Reloaded {
    let warnings = compiled
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Warning)
        .count();
    let result = match compiled.scene {
        Some(scene) => Ok((LoadedScene::new(scene), warnings)),
        None => Err(SceneErrors {
            diagnostics: compiled.diagnostics,
            sources: compiled.sources,
        }),
    };
    Reloaded {
        result,
        watch: compiled.watch,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::whitted_scene;
    use std::time::Duration;
    use whitted_ir::SourceMap;

    #[test]
    fn each_request_compiles_once_and_failures_carry_their_diagnostics() {
        let mut calls = 0;
        let recompile: Recompile = Box::new(move || {
            calls += 1;
            if calls == 1 {
                Compiled {
                    scene: Some(whitted_scene()),
                    diagnostics: Vec::new(),
                    sources: SourceMap::new(),
                    watch: vec!["a.scene".into()],
                }
            } else {
                Compiled {
                    scene: None,
                    diagnostics: vec![Diagnostic::new(Severity::Error, "broken", None)],
                    sources: SourceMap::new(),
                    watch: vec!["a.scene".into(), "b.scene".into()],
                }
            }
        });
        let (sender, receiver) = mpsc::channel();
        let reloader = Reloader::start(recompile, sender).unwrap();
        let next = || match receiver.recv_timeout(Duration::from_secs(60)) {
            Ok(Event::Reloaded(reloaded)) => reloaded,
            _ => panic!("expected a reload result"),
        };
        reloader.request();
        let first = next();
        assert!(first.result.is_ok());
        assert_eq!(first.watch, vec![std::path::PathBuf::from("a.scene")]);
        reloader.request();
        let second = next();
        let errors = second.result.err().expect("the second compile fails");
        assert_eq!(errors.diagnostics[0].message, "broken");
        assert_eq!(second.watch.len(), 2);
    }
}
