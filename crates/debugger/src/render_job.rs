//! The background render: a thread that renders the scene on the rayon pool and streams each
//! finished tile to the event loop, so the UI never waits. Each render has a generation
//! number; a newer render (after a reload) cancels the older one, and the app drops tiles
//! that arrive late from it.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::Arc;

use whitted_tracer::{render_with_pixel_stats, RenderObserver, RenderOptions, TileResult};

use crate::app::LoadedScene;
use crate::event::Event;
use crate::terminal::take_worker_panic;

/// A render under way; cancelled when dropped.
pub struct RenderJob {
    cancel: Arc<AtomicBool>,
}

/// Sends tiles to the event loop and answers the renderer's "should I stop?".
struct StreamTiles {
    generation: u64,
    events: Sender<Event>,
    cancel: Arc<AtomicBool>,
}

impl RenderObserver for StreamTiles {
    fn tile_done(&self, tile: &TileResult) {
        let _ = self.events.send(Event::RenderTile {
            generation: self.generation,
            tile: tile.clone(),
        });
    }

    /// With a filter that reaches past the pixel, the tiles were previews (each pixel's own
    /// samples): the filtered image replaces them as one tile.
    fn image_filtered(&self, image: &TileResult) {
        self.tile_done(image);
    }

    fn should_stop(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

impl RenderJob {
    /// Starts rendering `loaded` on a new thread. If the thread cannot start, the render
    /// ends at once (as cancelled) and the error is returned.
    pub fn start(
        generation: u64,
        loaded: &LoadedScene,
        options: RenderOptions,
        events: Sender<Event>,
    ) -> std::io::Result<RenderJob> {
        let cancel = Arc::new(AtomicBool::new(false));
        let observer = StreamTiles {
            generation,
            events,
            cancel: Arc::clone(&cancel),
        };
        let prepared = Arc::clone(&loaded.prepared);
        std::thread::Builder::new()
            .name(format!("render {generation}"))
            .spawn(move || {
                let rendered = catch_unwind(AssertUnwindSafe(|| {
                    render_with_pixel_stats(&prepared, &options, &observer)
                }));
                let event = match rendered {
                    Ok(result) => Event::RenderDone {
                        generation,
                        result: result.map(|(_, stats, pixel_stats)| (stats, pixel_stats)),
                    },
                    Err(_) => Event::RenderFailed {
                        generation,
                        message: take_worker_panic().unwrap_or_else(|| "no message".into()),
                    },
                };
                let _ = observer.events.send(event);
            })?;
        Ok(RenderJob { cancel })
    }

    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
}

impl Drop for RenderJob {
    fn drop(&mut self) {
        self.cancel();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::whitted_scene;
    use std::sync::mpsc;
    use std::time::Duration;

    fn small_options(loaded: &LoadedScene) -> RenderOptions {
        let mut options = RenderOptions::from_settings(&loaded.scene.settings);
        options.width = 64;
        options.height = 48;
        options
    }

    #[test]
    fn tiles_stream_in_then_the_render_reports_its_end() {
        let loaded = LoadedScene::new(whitted_scene());
        let (sender, receiver) = mpsc::channel();
        let _job = RenderJob::start(7, &loaded, small_options(&loaded), sender).unwrap();
        let mut pixels = 0;
        loop {
            match receiver.recv_timeout(Duration::from_secs(60)).unwrap() {
                Event::RenderTile { generation, tile } => {
                    assert_eq!(generation, 7);
                    pixels += tile.width * tile.height;
                }
                Event::RenderDone { generation, result } => {
                    assert_eq!(generation, 7);
                    let (stats, pixel_stats) = result.expect("not cancelled");
                    assert_eq!(stats.camera_rays, 64 * 48);
                    assert_eq!(pixel_stats.len(), 64 * 48);
                    break;
                }
                _ => panic!("unexpected event"),
            }
        }
        assert_eq!(pixels, 64 * 48);
    }

    #[test]
    fn a_cancelled_render_stops_and_reports_no_result() {
        let loaded = LoadedScene::new(whitted_scene());
        let (sender, receiver) = mpsc::channel();
        let observer = StreamTiles {
            generation: 3,
            events: sender,
            cancel: Arc::new(AtomicBool::new(true)),
        };
        let result = render_with_pixel_stats(&loaded.prepared, &small_options(&loaded), &observer);
        assert!(result.is_none());
        assert!(receiver.try_recv().is_err(), "no tile was rendered");
    }
}
