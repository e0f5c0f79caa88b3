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
    requests: Sender<Option<u32>>,
}

impl Reloader {
    pub fn start(mut recompile: Recompile, events: Sender<Event>) -> std::io::Result<Reloader> {
        let (requests, pending) = mpsc::channel::<Option<u32>>();
        std::thread::Builder::new()
            .name("reload".into())
            .spawn(move || {
                while let Ok(mut frame) = pending.recv() {
                    // Requests merge into one, at the frame asked for last.
                    while let Ok(later) = pending.try_recv() {
                        frame = later;
                    }
                    // A panic in the compiler or the BVH build is a bug, but it must not
                    // take the debugger down with it (nor leave it "reloading" forever):
                    // report it as an error of the scene.
                    let reloaded = match catch_unwind(AssertUnwindSafe(|| load(recompile(frame)))) {
                        Ok(reloaded) => reloaded,
                        Err(payload) => Reloaded {
                            result: Err(SceneErrors {
                                diagnostics: vec![Diagnostic::new(
                                    Severity::Error,
                                    format!(
                                        "whitted crashed loading this scene (a bug): {}",
                                        crate::terminal::take_worker_panic().unwrap_or_else(|| {
                                            crate::terminal::panic_text(&*payload)
                                        })
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

    /// Compiles the scene again at `frame` (see [`crate::Recompile`]).
    pub fn request(&self, frame: Option<u32>) {
        let _ = self.requests.send(frame);
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
        // The debugger checks the size at start; a save may change it, so check again
        // before the BVH build and the framebuffer (32768x32768 would want 12 GiB).
        Some(scene) => match image_size_error(scene.settings.width, scene.settings.height) {
            Some(message) => Err(SceneErrors {
                diagnostics: vec![Diagnostic::new(Severity::Error, message, None)],
                sources: compiled.sources,
            }),
            None => Ok((LoadedScene::new(scene), warnings)),
        },
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

/// Why an image of this size cannot be shown, if it cannot: the same limits as `render`.
pub fn image_size_error(width: u32, height: u32) -> Option<String> {
    let pixels = u64::from(width) * u64::from(height);
    let limit = whitted_ir::limits::MAX_PIXELS;
    (pixels > limit).then(|| {
        format!(
            "a {width}x{height} image has {pixels} pixels, more than the pixels limit of \
             {limit}; showing the last good image"
        )
    })
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
        let recompile: Recompile = Box::new(move |_frame| {
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
        reloader.request(None);
        let first = next();
        assert!(first.result.is_ok());
        assert_eq!(first.watch, vec![std::path::PathBuf::from("a.scene")]);
        reloader.request(None);
        let second = next();
        let errors = second.result.err().expect("the second compile fails");
        assert_eq!(errors.diagnostics[0].message, "broken");
        assert_eq!(second.watch.len(), 2);
    }

    fn answer(reloader: &Reloader, receiver: &mpsc::Receiver<Event>) -> Reloaded {
        reloader.request(None);
        match receiver.recv_timeout(Duration::from_secs(60)) {
            Ok(Event::Reloaded(reloaded)) => reloaded,
            _ => panic!("the reload worker did not answer"),
        }
    }

    fn compiled(scene: whitted_ir::Scene) -> Compiled {
        Compiled {
            scene: Some(whitted_ir::validate(scene).expect("a valid scene")),
            diagnostics: Vec::new(),
            sources: SourceMap::new(),
            watch: Vec::new(),
        }
    }

    #[test]
    fn an_image_too_big_on_reload_is_an_error_and_the_worker_goes_on() {
        let mut calls = 0;
        let recompile: Recompile = Box::new(move |_frame| {
            calls += 1;
            let mut scene = whitted_scene().into_inner();
            if calls == 1 {
                scene.settings.width = 32768;
                scene.settings.height = 32768;
                // Validation refuses the size too (the pixels limit), as the binary's
                // recompile would report it.
                return match whitted_ir::validate(scene) {
                    Ok(valid) => Compiled {
                        scene: Some(valid),
                        diagnostics: Vec::new(),
                        sources: SourceMap::new(),
                        watch: Vec::new(),
                    },
                    Err(invalid) => Compiled {
                        scene: None,
                        diagnostics: invalid.diagnostics,
                        sources: SourceMap::new(),
                        watch: Vec::new(),
                    },
                };
            }
            compiled(scene)
        });
        let (sender, receiver) = mpsc::channel();
        let reloader = Reloader::start(recompile, sender).unwrap();
        let errors = answer(&reloader, &receiver)
            .result
            .err()
            .expect("a 32768x32768 image is refused");
        assert!(
            errors.diagnostics[0].message.contains("pixels limit"),
            "{}",
            errors.diagnostics[0].message
        );
        assert!(answer(&reloader, &receiver).result.is_ok());
    }

    #[test]
    fn a_panic_while_preparing_the_scene_is_reported_and_the_worker_goes_on() {
        // A sphere of radius 1e19 next to a unit sphere made the BVH build panic (issue 10);
        // whether or not it still does, the worker must answer every request.
        let mut calls = 0;
        let recompile: Recompile = Box::new(move |_frame| {
            calls += 1;
            if calls == 2 {
                panic!("a compiler bug");
            }
            let mut scene = whitted_scene().into_inner();
            if calls == 1 {
                let material = scene.objects[scene.roots[1]].material;
                let span = whitted_ir::Span::new(whitted_ir::FileId(0), 0, 0);
                let huge = scene.objects.append(
                    whitted_ir::Object {
                        name: None,
                        kind: whitted_ir::ObjectKind::Shape {
                            shape: whitted_ir::Shape::Sphere {
                                center: whitted_ir::DVec3::ZERO,
                                radius: 1e19,
                            }
                            .into(),
                        },
                        world_from_object: whitted_ir::WorldFromObject::IDENTITY,
                        material,
                    },
                    span,
                );
                scene.roots.push(huge);
            }
            compiled(scene)
        });
        let (sender, receiver) = mpsc::channel();
        let reloader = Reloader::start(recompile, sender).unwrap();
        match answer(&reloader, &receiver).result {
            Ok(_) => {}
            Err(errors) => assert!(
                errors.diagnostics[0].message.contains("crashed"),
                "{}",
                errors.diagnostics[0].message
            ),
        }
        let errors = answer(&reloader, &receiver)
            .result
            .err()
            .expect("the compiler panicked");
        assert!(errors.diagnostics[0].message.contains("a compiler bug"));
        assert!(answer(&reloader, &receiver).result.is_ok());
    }
}
