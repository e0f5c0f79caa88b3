//! The 3D ray view's state: the orbit camera, the backdrop (a small render of the scene from
//! that camera, one pixel per half-cell of the pane) and the render of the next backdrop,
//! which runs on a worker thread, is cancelled when the camera moves again, and reports back
//! as an [`Event::Backdrop`].

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::Arc;

use whitted_ir::{Camera, DVec3};
use whitted_tracer::ray_tree::RayTree;
use whitted_tracer::{render_from, PreparedScene, RenderObserver, RenderOptions, TileResult};

use crate::app::LoadedScene;
use crate::event::Event;
use crate::ray_view::orbit::OrbitCamera;

/// What a backdrop shows: the scene, the camera and the size in pixels. A backdrop is
/// current when its key matches the view's.
#[derive(Clone)]
pub struct BackdropKey {
    /// Held, not just its address: a reloaded scene must never pass for the old one.
    scene: Arc<PreparedScene>,
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
}

impl PartialEq for BackdropKey {
    fn eq(&self, other: &BackdropKey) -> bool {
        Arc::ptr_eq(&self.scene, &other.scene)
            && self.camera == other.camera
            && (self.width, self.height) == (other.width, other.height)
    }
}

impl std::fmt::Debug for BackdropKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BackdropKey")
            .field("camera", &self.camera)
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

/// A finished backdrop: linear pixels, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Backdrop {
    pub key: BackdropKey,
    pub pixels: Vec<[f32; 3]>,
}

impl Backdrop {
    pub fn linear(&self, x: u32, y: u32) -> Option<[f32; 3]> {
        if x >= self.key.width || y >= self.key.height {
            return None;
        }
        self.pixels
            .get(y as usize * self.key.width as usize + x as usize)
            .copied()
    }
}

/// The 3D view, while it is shown.
#[derive(Clone, Debug)]
pub struct RayViewState {
    pub orbit: OrbitCamera,
    pub backdrop: Option<Backdrop>,
    /// The backdrop being rendered, its number and cancel flag.
    rendering: Option<(u64, BackdropKey, Arc<AtomicBool>)>,
    renders: u64,
    /// Where the left button went down or last dragged to, in the pane: drags orbit.
    pub drag_from: Option<(u16, u16)>,
}

/// The point the view orbits first: where the picked pixel's camera ray hit, or else the
/// point the scene's camera looks at.
pub fn orbit_target(camera: &Camera, tree: Option<&RayTree>) -> DVec3 {
    tree.and_then(|t| t.samples.first())
        .and_then(|s| s.root.hit.as_ref())
        .map(|hit| {
            let [x, y, z] = hit.point;
            DVec3::new(f64::from(x), f64::from(y), f64::from(z))
        })
        .filter(|p| p.is_finite())
        .unwrap_or(camera.look_at)
}

impl RayViewState {
    pub fn new(camera: &Camera, tree: Option<&RayTree>) -> RayViewState {
        RayViewState {
            orbit: OrbitCamera::new(camera.clone(), orbit_target(camera, tree)),
            backdrop: None,
            rendering: None,
            renders: 0,
            drag_from: None,
        }
    }

    /// The backdrop render the view needs for a pane of `columns × rows` cells, unless the
    /// current backdrop or the one under way already shows it. A render under way for an
    /// older camera is cancelled.
    pub fn backdrop_job(
        &mut self,
        loaded: &LoadedScene,
        options: &RenderOptions,
        columns: u16,
        rows: u16,
    ) -> Option<BackdropJob> {
        let key = BackdropKey {
            scene: Arc::clone(&loaded.prepared),
            camera: self.orbit.camera().clone(),
            width: u32::from(columns),
            height: u32::from(rows) * 2,
        };
        if key.width == 0 || key.height == 0 {
            return None;
        }
        if self.backdrop.as_ref().is_some_and(|b| b.key == key)
            || self.rendering.as_ref().is_some_and(|(_, k, _)| *k == key)
        {
            return None;
        }
        self.cancel();
        self.renders += 1;
        let cancel = Arc::new(AtomicBool::new(false));
        self.rendering = Some((self.renders, key.clone(), Arc::clone(&cancel)));
        let options = RenderOptions {
            width: key.width,
            height: key.height,
            // One sample is enough for a backdrop a few dozen pixels wide.
            samples_per_pixel: 1,
            ..options.clone()
        };
        Some(BackdropJob {
            generation: self.renders,
            loaded: loaded.clone(),
            options,
            key,
            cancel,
        })
    }

    /// Cancels the backdrop render under way, if any.
    pub fn cancel(&mut self) {
        if let Some((_, _, cancel)) = self.rendering.take() {
            cancel.store(true, Ordering::Relaxed);
        }
    }

    pub fn is_rendering(&self) -> bool {
        self.rendering.is_some()
    }

    /// A backdrop render's answer; answers from cancelled or superseded renders are dropped.
    pub fn apply_backdrop(&mut self, rendered: BackdropRendered) {
        if self
            .rendering
            .as_ref()
            .is_some_and(|(generation, _, _)| *generation == rendered.generation)
        {
            self.rendering = None;
            if let Some(backdrop) = rendered.backdrop {
                self.backdrop = Some(backdrop);
            }
        }
    }
}

impl Drop for RayViewState {
    fn drop(&mut self) {
        self.cancel();
    }
}

/// One backdrop to render.
pub struct BackdropJob {
    pub generation: u64,
    loaded: LoadedScene,
    options: RenderOptions,
    key: BackdropKey,
    cancel: Arc<AtomicBool>,
}

/// A backdrop render's answer: the picture, or `None` when it was cancelled or crashed.
#[derive(Debug)]
pub struct BackdropRendered {
    pub generation: u64,
    pub backdrop: Option<Backdrop>,
}

/// Answers the renderer's "should I stop?" from the job's cancel flag.
struct Cancellable<'a>(&'a AtomicBool);

impl RenderObserver for Cancellable<'_> {
    fn tile_done(&self, _tile: &TileResult) {}

    fn should_stop(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

impl BackdropJob {
    /// Renders on this thread (the worker's body; tests call it directly). A panic in the
    /// renderer gives no backdrop; the main render reports renderer crashes.
    pub fn run(&self) -> BackdropRendered {
        let rendered = catch_unwind(AssertUnwindSafe(|| {
            render_from(
                &self.loaded.prepared,
                &self.key.camera,
                &self.options,
                &Cancellable(&self.cancel),
            )
        }));
        let backdrop = match rendered {
            Ok(Some((image, _))) => Some(Backdrop {
                key: self.key.clone(),
                pixels: image.pixels,
            }),
            Ok(None) => None,
            Err(_) => {
                let _ = crate::terminal::take_worker_panic();
                None
            }
        };
        BackdropRendered {
            generation: self.generation,
            backdrop,
        }
    }

    /// Renders on a new thread and sends the answer as [`Event::Backdrop`].
    pub fn spawn(self, events: Sender<Event>) -> std::io::Result<()> {
        std::thread::Builder::new()
            .name(format!("backdrop {}", self.generation))
            .spawn(move || {
                let _ = events.send(Event::Backdrop(self.run()));
            })?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::whitted_scene;

    #[test]
    fn a_backdrop_is_rendered_once_per_camera_and_size_and_a_moved_camera_cancels_the_old() {
        let loaded = LoadedScene::new(whitted_scene());
        let options = RenderOptions::from_settings(&loaded.scene.settings);
        let mut view = RayViewState::new(&loaded.scene.camera, None);
        assert_eq!(view.orbit.target(), loaded.scene.camera.look_at);
        let job = view
            .backdrop_job(&loaded, &options, 20, 8)
            .expect("a first render");
        assert!(view.backdrop_job(&loaded, &options, 20, 8).is_none());
        view.apply_backdrop(job.run());
        let backdrop = view.backdrop.as_ref().expect("a backdrop");
        assert_eq!((backdrop.key.width, backdrop.key.height), (20, 16));
        assert_eq!(backdrop.pixels.len(), 20 * 16);
        assert!(view.backdrop_job(&loaded, &options, 20, 8).is_none());
        view.orbit.orbit(0.5, 0.0);
        let old = view.backdrop_job(&loaded, &options, 20, 8).expect("moved");
        let new = view
            .backdrop_job(&loaded, &options, 21, 8)
            .expect("resized");
        assert!(old.cancel.load(Ordering::Relaxed));
        let stale = old.run();
        assert!(stale.backdrop.is_none(), "a cancelled render stops");
        view.apply_backdrop(stale);
        assert!(view.is_rendering());
        view.apply_backdrop(new.run());
        assert_eq!(view.backdrop.as_ref().unwrap().key.width, 21);
        assert!(!view.is_rendering());
    }
}
