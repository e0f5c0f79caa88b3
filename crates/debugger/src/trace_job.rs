//! Recording a pixel's ray tree off the UI thread: a hall of mirrors can take seconds (the
//! tree itself is bounded by the ray-tree node budget, but the rays are all traced), and the
//! UI must stay responsive and able to cancel it (Esc). A panic while tracing is reported,
//! not fatal.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::Arc;
use std::time::{Duration, Instant};

use whitted_explain::{explain_tree, Explanation};
use whitted_tracer::ray_tree::{trace_pixel_request, RayTree, SampleChoice, TraceRequest};
use whitted_tracer::RenderOptions;

use crate::app::LoadedScene;
use crate::event::Event;
use crate::terminal::{panic_text, take_worker_panic};

/// One trace to run: the scene and options it was asked in, the pixel, and its cancel flag.
pub struct TraceJob {
    pub generation: u64,
    pub loaded: LoadedScene,
    pub options: RenderOptions,
    pub pixel: (u32, u32),
    pub cancel: Arc<AtomicBool>,
    /// The node budget of the tree (the `ray tree nodes` limit, lowered in tests).
    pub node_budget: usize,
}

/// A trace's answer to the event loop.
#[derive(Debug)]
pub struct Traced {
    pub generation: u64,
    pub pixel: (u32, u32),
    pub result: Result<(RayTree, Duration), TraceFailure>,
}

/// The explanation of a recorded tree (`x`), sent after the tree itself: its findings may
/// trace the pixel again with other settings, and the tree must not wait for that.
#[derive(Debug)]
pub struct Explained {
    /// The trace's generation: the explanation belongs to that trace's tree only.
    pub generation: u64,
    /// The explanation, or the panic's message (a bug).
    pub result: Result<Explanation, String>,
}

/// Why a trace gave no tree.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TraceFailure {
    /// The user cancelled it.
    Cancelled,
    /// The request was wrong (a pixel outside the image): the tracer's message.
    Refused(String),
    /// The tracer panicked (a bug): the panic's message.
    Crashed(String),
}

impl TraceJob {
    /// Traces on this thread (the worker's body; tests call it directly).
    pub fn run(&self) -> Traced {
        let started = Instant::now();
        let (x, y) = self.pixel;
        let request = TraceRequest {
            x,
            y,
            which: SampleChoice::All,
            node_budget: self.node_budget,
            cancel: Some(&self.cancel),
        };
        let traced = catch_unwind(AssertUnwindSafe(|| {
            trace_pixel_request(
                &self.loaded.prepared,
                &self.loaded.scene,
                &self.options,
                &request,
            )
        }));
        let result = match traced {
            Ok(Ok(tree)) => Ok((tree, started.elapsed())),
            Ok(Err(_)) if self.cancel.load(Ordering::Relaxed) => Err(TraceFailure::Cancelled),
            Ok(Err(error)) => Err(TraceFailure::Refused(error.to_string())),
            Err(payload) => Err(TraceFailure::Crashed(
                take_worker_panic().unwrap_or_else(|| panic_text(&*payload)),
            )),
        };
        Traced {
            generation: self.generation,
            pixel: self.pixel,
            result,
        }
    }

    /// Explains the recorded tree itself (no second trace of it), so that the explanation
    /// is of exactly the rays shown beside it.
    pub fn explain(&self, tree: &RayTree) -> Explained {
        let explained = catch_unwind(AssertUnwindSafe(|| {
            explain_tree(
                &self.loaded.prepared,
                &self.loaded.scene,
                &self.options,
                tree,
            )
        }));
        Explained {
            generation: self.generation,
            result: explained
                .map_err(|payload| take_worker_panic().unwrap_or_else(|| panic_text(&*payload))),
        }
    }

    /// Runs the trace on a new thread and sends its answer as [`Event::Traced`], then,
    /// unless it was cancelled meanwhile, the tree's explanation as [`Event::Explained`].
    pub fn spawn(self, events: Sender<Event>) -> std::io::Result<()> {
        std::thread::Builder::new()
            .name(format!("trace {}", self.generation))
            .spawn(move || {
                let traced = self.run();
                let tree = traced.result.as_ref().ok().map(|(tree, _)| tree.clone());
                if events.send(Event::Traced(traced)).is_err() {
                    return;
                }
                if let Some(tree) = tree.filter(|_| !self.cancel.load(Ordering::Relaxed)) {
                    let _ = events.send(Event::Explained(self.explain(&tree)));
                }
            })?;
        Ok(())
    }
}
