//! Queries in the debugger (`:`): the prompt, running a `whitted query` predicate
//! (`whitted_explain::query`) over every pixel on a worker (cancellable, with progress), the
//! matching pixels kept as a mask for the image overlay, and stepping through them in row
//! order (`n` / `N`).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::Arc;

use whitted_explain::query::{run_with, Query, QueryError, RunControl};
use whitted_ir::Scene;
use whitted_tracer::RenderOptions;

use crate::app::LoadedScene;
use crate::event::Event;
use crate::line_input::LineInput;
use crate::terminal::{panic_text, take_worker_panic};

/// The prompt, the query under way and the last answer.
#[derive(Default)]
pub struct QueryState {
    /// The prompt on the status line, while typing.
    pub prompt: Option<LineInput>,
    /// The queries submitted, oldest first (failed ones too, to be fixed): the prompt opens
    /// empty and ↑↓ bring them back.
    pub history: Vec<String>,
    pub running: Option<QueryRun>,
    /// The matching pixels of the last finished query.
    pub overlay: Option<QueryOverlay>,
    requests: u64,
}

pub struct QueryRun {
    pub generation: u64,
    pub text: String,
    pub cancel: Arc<AtomicBool>,
    pub rows_done: u32,
    pub rows: u32,
    job: Option<QueryJob>,
}

/// A finished query's answer over the image.
#[derive(Clone, Debug, PartialEq)]
pub struct QueryOverlay {
    pub text: String,
    pub width: u32,
    pub height: u32,
    /// Row-major, one per pixel.
    pub mask: Vec<bool>,
    /// The matching pixels in row-major order.
    pub matches: Vec<(u32, u32)>,
}

impl QueryOverlay {
    pub fn matches_pixel(&self, x: u32, y: u32) -> bool {
        x < self.width
            && y < self.height
            && self.mask[(y as usize) * (self.width as usize) + x as usize]
    }

    /// The first match after `pixel` in row order (wrapping), or before it for `backward`.
    pub fn step(&self, (x, y): (u32, u32), backward: bool) -> Option<(u32, u32)> {
        let here = (y, x);
        let key = |&(mx, my): &(u32, u32)| (my, mx);
        if backward {
            self.matches
                .iter()
                .rev()
                .find(|m| key(m) < here)
                .or(self.matches.last())
                .copied()
        } else {
            self.matches
                .iter()
                .find(|m| key(m) > here)
                .or(self.matches.first())
                .copied()
        }
    }
}

/// One query for a worker.
pub struct QueryJob {
    pub generation: u64,
    pub loaded: LoadedScene,
    pub options: RenderOptions,
    pub query: Query,
    pub text: String,
    pub cancel: Arc<AtomicBool>,
}

/// The worker's reports.
pub enum QueryNews {
    /// One more row is done.
    Row { generation: u64 },
    /// The answer, or `None` when cancelled, or the crash's message.
    Done {
        generation: u64,
        result: Result<Option<QueryOverlay>, String>,
    },
}

/// A query's parse or name error in one line, with the column it points at.
pub fn error_text(error: &QueryError, text: &str) -> String {
    let column = text
        .get(..error.span.start.min(text.len()))
        .map_or(1, |before| before.chars().count() + 1);
    format!("query error at column {column}: {}", error.message)
}

impl QueryState {
    /// Compiles `text` against `scene` and asks for a run (the caller returns
    /// [`crate::app::Effect::StartQuery`]); a parse or name error comes back as text.
    pub fn start(
        &mut self,
        text: &str,
        loaded: &LoadedScene,
        options: &RenderOptions,
        scene: &Scene,
    ) -> Result<(), String> {
        let query = Query::compile(text, scene).map_err(|e| error_text(&e, text))?;
        self.cancel();
        self.overlay = None;
        self.requests += 1;
        let cancel = Arc::new(AtomicBool::new(false));
        self.running = Some(QueryRun {
            generation: self.requests,
            text: text.to_string(),
            cancel: Arc::clone(&cancel),
            rows_done: 0,
            rows: options.height,
            job: Some(QueryJob {
                generation: self.requests,
                loaded: loaded.clone(),
                options: options.clone(),
                query,
                text: text.to_string(),
                cancel,
            }),
        });
        Ok(())
    }

    pub fn take_job(&mut self) -> Option<QueryJob> {
        self.running.as_mut()?.job.take()
    }

    /// Cancels the query under way; whether there was one.
    pub fn cancel(&mut self) -> bool {
        match self.running.take() {
            Some(run) => {
                run.cancel.store(true, Ordering::Relaxed);
                true
            }
            None => false,
        }
    }

    /// A worker's report; returns a message for the status line when the query ended.
    pub fn apply(&mut self, news: QueryNews) -> Option<(String, bool)> {
        match news {
            QueryNews::Row { generation } => {
                if let Some(run) = self.running.as_mut().filter(|r| r.generation == generation) {
                    run.rows_done += 1;
                }
                None
            }
            QueryNews::Done { generation, result } => {
                let run = self.running.take_if(|r| r.generation == generation)?;
                match result {
                    Ok(Some(overlay)) => {
                        let count = overlay.matches.len();
                        let message = match count {
                            0 => format!("no pixel matches {}", run.text),
                            1 => format!("1 pixel matches {} (n: go to it)", run.text),
                            n => format!(
                                "{n} pixels match {} (n / N: next / previous; Esc clears)",
                                run.text
                            ),
                        };
                        self.overlay = Some(overlay);
                        Some((message, false))
                    }
                    Ok(None) => Some((format!("cancelled the query {}", run.text), false)),
                    Err(message) => Some((
                        format!("the query crashed (a bug in whitted): {message}"),
                        true,
                    )),
                }
            }
        }
    }
}

impl QueryJob {
    /// Runs the query on this thread, reporting each row through `row_done`.
    pub fn run(&self, row_done: &(dyn Fn() + Sync)) -> Result<Option<QueryOverlay>, String> {
        let control = RunControl {
            cancel: &self.cancel,
            row_done,
        };
        let answered = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            run_with(&self.loaded.prepared, &self.options, &self.query, &control)
        }));
        match answered {
            Ok(result) => Ok(result.map(|r| QueryOverlay {
                text: self.text.clone(),
                width: r.width,
                height: r.height,
                mask: r.mask,
                matches: r.matches.iter().map(|m| (m.pixel[0], m.pixel[1])).collect(),
            })),
            Err(payload) => Err(take_worker_panic().unwrap_or_else(|| panic_text(&*payload))),
        }
    }

    /// Runs on a new thread (the rows on the rayon pool), sending progress and the answer.
    pub fn spawn(self, events: Sender<Event>) -> std::io::Result<()> {
        std::thread::Builder::new()
            .name(format!("query {}", self.generation))
            .spawn(move || {
                let generation = self.generation;
                let progress = events.clone();
                let row_done = move || {
                    let _ = progress.send(Event::Query(QueryNews::Row { generation }));
                };
                let result = self.run(&row_done);
                let _ = events.send(Event::Query(QueryNews::Done { generation, result }));
            })?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::action::Action;
    use crate::app::{App, Effect};
    use crate::test_scene::whitted_scene;
    use crate::update::update;
    use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
    use ratatui::layout::Rect;
    use std::sync::atomic::AtomicUsize;

    fn app() -> App {
        let mut app = App::new(
            "scenes/whitted.scene".into(),
            LoadedScene::new(whitted_scene()),
            Rect::new(0, 0, 120, 40),
            "/tmp".into(),
        );
        // A small image keeps the whole-image query quick.
        app.options.width = 64;
        app.options.height = 48;
        app
    }

    fn type_query(app: &mut App, text: &str) -> Vec<Effect> {
        assert!(update(app, Action::QueryPrompt).is_empty());
        assert!(app.takes_keys());
        for c in text.chars() {
            update(
                app,
                Action::PromptKey(KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE)),
            );
        }
        update(
            app,
            Action::PromptKey(KeyEvent::new(KeyCode::Enter, KeyModifiers::NONE)),
        )
    }

    /// Runs the job the app asked for here, reporting as the worker does.
    fn finish_query(app: &mut App) {
        let job = app.query.take_job().expect("a query to run");
        let rows = AtomicUsize::new(0);
        let result = job.run(&|| {
            rows.fetch_add(1, Ordering::Relaxed);
        });
        assert_eq!(rows.load(Ordering::Relaxed), 48, "one report per row");
        for _ in 0..48 {
            app.query.apply(QueryNews::Row {
                generation: job.generation,
            });
        }
        if let Some(run) = &app.query.running {
            assert_eq!(run.rows_done, run.rows);
        }
        if let Some((message, is_error)) = app.query.apply(QueryNews::Done {
            generation: job.generation,
            result,
        }) {
            app.set_message(message, is_error);
        }
    }

    #[test]
    fn a_query_marks_the_pixels_the_explain_query_finds_and_n_steps_through_them() {
        let mut app = app();
        assert_eq!(
            type_query(&mut app, "hit(\"mirror sphere\")"),
            vec![Effect::StartQuery]
        );
        assert!(!app.takes_keys());
        finish_query(&mut app);
        let overlay = app.query.overlay.clone().expect("an overlay");
        // The oracle: the same query through whitted query's entry point.
        let query = Query::compile("hit(\"mirror sphere\")", &app.loaded.scene).unwrap();
        let expected = whitted_explain::query::run(&app.loaded.prepared, &app.options, &query);
        assert_eq!(overlay.mask, expected.mask);
        assert!(!overlay.matches.is_empty());
        let message = app.message.clone().unwrap();
        assert!(
            message
                .text
                .starts_with(&format!("{} pixels match", overlay.matches.len())),
            "{message:?}"
        );

        app.cursor = (0, 0);
        update(&mut app, Action::NextMatch);
        assert_eq!(app.cursor, overlay.matches[0]);
        assert!(app.tracing.is_some(), "the match is traced");
        assert_eq!(
            app.message.as_ref().unwrap().text,
            format!("match 1 of {}", overlay.matches.len())
        );
        update(&mut app, Action::NextMatch);
        assert_eq!(app.cursor, overlay.matches[1]);
        update(&mut app, Action::PreviousMatch);
        update(&mut app, Action::PreviousMatch);
        assert_eq!(
            app.cursor,
            *overlay.matches.last().unwrap(),
            "N wraps to the last"
        );

        // Esc cancels the trace, then clears the overlay, then quits.
        update(&mut app, Action::Cancel);
        assert!(app.query.overlay.is_some());
        update(&mut app, Action::Cancel);
        assert!(app.query.overlay.is_none() && !app.should_quit);
    }

    #[test]
    fn a_bad_query_is_an_error_with_its_column_and_up_in_the_empty_prompt_brings_it_back() {
        let mut app = app();
        assert!(type_query(&mut app, "tir and hit(\"mirorr sphere\")").is_empty());
        let message = app.message.clone().unwrap();
        assert!(message.is_error);
        assert_eq!(
            message.text,
            "query error at column 13: no object is named \"mirorr sphere\": did you mean \"mirror sphere\"?"
        );
        assert!(app.query.running.is_none());
        update(&mut app, Action::QueryPrompt);
        assert_eq!(app.query.prompt.as_ref().map(LineInput::text), Some(""));
        update(
            &mut app,
            Action::PromptKey(KeyEvent::new(KeyCode::Up, KeyModifiers::NONE)),
        );
        assert_eq!(
            app.query.prompt.as_ref().map(LineInput::text),
            Some("tir and hit(\"mirorr sphere\")")
        );
        update(
            &mut app,
            Action::PromptKey(KeyEvent::new(KeyCode::Esc, KeyModifiers::NONE)),
        );
        assert!(app.query.prompt.is_none());
        update(&mut app, Action::NextMatch);
        assert!(app
            .message
            .as_ref()
            .unwrap()
            .text
            .contains("press : to run one"));
    }

    #[test]
    fn a_cancelled_query_leaves_no_overlay() {
        let mut app = app();
        type_query(&mut app, "depth >= 1");
        let job = app.query.take_job().unwrap();
        update(&mut app, Action::Cancel);
        assert!(job.cancel.load(Ordering::Relaxed));
        assert_eq!(job.run(&|| {}), Ok(None));
        assert!(app.query.running.is_none() && app.query.overlay.is_none());
        assert!(!app.should_quit);
    }

    #[test]
    fn stepping_goes_in_row_order_and_wraps() {
        let overlay = QueryOverlay {
            text: "q".into(),
            width: 4,
            height: 3,
            mask: vec![false; 12],
            matches: vec![(3, 0), (1, 1), (2, 2)],
        };
        assert_eq!(overlay.step((0, 1), false), Some((1, 1)));
        assert_eq!(overlay.step((1, 1), false), Some((2, 2)));
        assert_eq!(overlay.step((2, 2), false), Some((3, 0)));
        assert_eq!(overlay.step((0, 1), true), Some((3, 0)));
        assert_eq!(overlay.step((3, 0), true), Some((2, 2)));
        let none = QueryOverlay {
            matches: Vec::new(),
            ..overlay
        };
        assert_eq!(none.step((0, 0), false), None);
    }
}
