//! The what-if popup's state and work: the listed values, the one being edited, the
//! re-trace of the picked pixel in the changed copy of the scene (on a worker, through the
//! tracer's one trace entry point, like any pick), the old and new trees compared by
//! `whitted_explain::diff`, and writing the change back to the scene file.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::Sender;
use std::sync::Arc;

use ratatui::crossterm::event::{KeyCode, KeyEvent};
use whitted_explain::diff::{diff_trees, ray_changes, RayChange, TreeDiff};
use whitted_ir::{Handle, Material, ValidScene};
use whitted_tracer::ray_tree::RayTree;
use whitted_tracer::RenderOptions;

use crate::app::{Effect, LoadedScene};
use crate::event::Event;
use crate::line_input::{InputOutcome, LineInput};
use crate::terminal::{panic_text, take_worker_panic};
use crate::trace_job::{TraceFailure, TraceJob, Traced};
use crate::what_if::write_back::{write_back, WriteBack};
use crate::what_if::{params, value_text, Owner, Param, Value};

/// The popup, open on one picked pixel.
pub struct WhatIf {
    pub pixel: (u32, u32),
    /// The scene and tree the popup was opened on: the "old" side.
    pub base: LoadedScene,
    pub base_tree: RayTree,
    pub params: Vec<Param>,
    pub selected: usize,
    /// The value being typed, when editing.
    pub editing: Option<LineInput>,
    /// What went wrong with the last value or write (said in the popup), or what was done.
    pub note: Option<Note>,
    /// The re-trace under way.
    pub running: Option<Running>,
    /// The last re-trace's answer.
    pub outcome: Option<Outcome>,
    requests: u64,
    node_budget: usize,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Note {
    pub text: String,
    pub is_error: bool,
}

pub struct Running {
    pub generation: u64,
    pub cancel: Arc<AtomicBool>,
    /// What the job changes; taken by the worker.
    job: Option<WhatIfJob>,
}

/// A changed value and what it does to the pixel.
pub struct Outcome {
    pub param: Param,
    pub value: Value,
    /// The value as the scene language writes it.
    pub text: String,
    pub scene: Arc<ValidScene>,
    pub tree: RayTree,
    /// Where the trees first diverge (the cause).
    pub diff: TreeDiff,
    /// Every ray added, removed or changed (the consequences).
    pub rays: Vec<RayChange>,
}

/// The re-trace for a worker: build the changed scene's acceleration structure and trace the
/// pixel there (both can take a while in a large scene).
pub struct WhatIfJob {
    pub generation: u64,
    pub scene: ValidScene,
    pub pixel: (u32, u32),
    pub cancel: Arc<AtomicBool>,
    pub node_budget: usize,
    param: Param,
    value: Value,
}

/// The worker's answer.
pub struct WhatIfTraced {
    pub generation: u64,
    pub param: Param,
    pub value: Value,
    pub result: Result<(LoadedScene, RayTree), TraceFailure>,
}

impl WhatIf {
    /// The popup for the picked tree's pixel, listing the settings, the material the
    /// selected ray hit (or, for a ray that hit nothing, the camera ray's) and the lights.
    pub fn open(
        base: LoadedScene,
        tree: RayTree,
        material: Option<Handle<Material>>,
        node_budget: usize,
    ) -> WhatIf {
        let [x, y] = tree.pixel;
        let params = params(&base.scene, material);
        // Start on the material's first value when there is one: the likely question.
        let selected = params
            .iter()
            .position(|p| matches!(p.owner, Owner::Material(_)))
            .unwrap_or(0);
        WhatIf {
            pixel: (x, y),
            base,
            base_tree: tree,
            params,
            selected,
            editing: None,
            note: None,
            running: None,
            outcome: None,
            requests: 0,
            node_budget,
        }
    }

    pub fn selected_param(&self) -> Option<Param> {
        self.params.get(self.selected).copied()
    }

    /// One key while the popup is open: returns whether to close it, and any effect.
    pub fn handle_key(&mut self, key: KeyEvent) -> (bool, Vec<Effect>) {
        if let Some(input) = &mut self.editing {
            return match input.handle(key) {
                InputOutcome::Submitted => {
                    let text = input.text().to_string();
                    (false, self.submit(&text))
                }
                InputOutcome::Cancelled => {
                    self.editing = None;
                    (false, Vec::new())
                }
                InputOutcome::Edited | InputOutcome::Ignored => (false, Vec::new()),
            };
        }
        match key.code {
            KeyCode::Esc => {
                self.cancel();
                return (true, Vec::new());
            }
            KeyCode::Up | KeyCode::Char('k') => self.selected = self.selected.saturating_sub(1),
            KeyCode::Down | KeyCode::Char('j') => {
                self.selected = (self.selected + 1).min(self.params.len().saturating_sub(1));
            }
            KeyCode::Enter => {
                if let Some(param) = self.selected_param() {
                    let shown = match &self.outcome {
                        Some(outcome) if outcome.param == param => outcome.text.clone(),
                        _ => param.current_text(&self.base.scene),
                    };
                    self.editing = Some(LineInput::new(&shown));
                    self.note = None;
                }
            }
            KeyCode::Char('W') => return (false, self.write_back()),
            _ => {}
        }
        (false, Vec::new())
    }

    /// Reads the typed value, makes the changed scene and asks for the re-trace.
    fn submit(&mut self, text: &str) -> Vec<Effect> {
        let Some(param) = self.selected_param() else {
            return Vec::new();
        };
        let changed = param
            .parse(text)
            .and_then(|value| Ok((value, param.apply(&self.base.scene, value)?)));
        match changed {
            Err(message) => {
                self.note = Some(Note {
                    text: message,
                    is_error: true,
                });
                Vec::new()
            }
            Ok((value, scene)) => {
                self.editing = None;
                self.note = None;
                self.cancel();
                self.requests += 1;
                let cancel = Arc::new(AtomicBool::new(false));
                let job = WhatIfJob {
                    generation: self.requests,
                    scene,
                    pixel: self.pixel,
                    cancel: Arc::clone(&cancel),
                    node_budget: self.node_budget,
                    param,
                    value,
                };
                self.running = Some(Running {
                    generation: self.requests,
                    cancel,
                    job: Some(job),
                });
                vec![Effect::WhatIfTrace]
            }
        }
    }

    /// The job to run (once).
    pub fn take_job(&mut self) -> Option<WhatIfJob> {
        self.running.as_mut()?.job.take()
    }

    /// Stops the re-trace under way.
    pub fn cancel(&mut self) {
        if let Some(running) = self.running.take() {
            running.cancel.store(true, Ordering::Relaxed);
        }
    }

    /// The worker's answer; answers to superseded requests are dropped.
    pub fn apply(&mut self, traced: WhatIfTraced) {
        if self
            .running
            .as_ref()
            .is_none_or(|r| r.generation != traced.generation)
        {
            return;
        }
        self.running = None;
        match traced.result {
            Ok((loaded, tree)) => {
                let diff = diff_trees(&self.base.scene, &self.base_tree, &loaded.scene, &tree);
                let rays = ray_changes(&self.base_tree, &tree);
                self.outcome = Some(Outcome {
                    rays,
                    param: traced.param,
                    value: traced.value,
                    text: value_text(traced.value),
                    scene: loaded.scene,
                    tree,
                    diff,
                });
            }
            Err(failure) => {
                let text = match failure {
                    TraceFailure::Cancelled => "cancelled the re-trace".to_string(),
                    TraceFailure::Refused(message) => message,
                    TraceFailure::Crashed(message) => {
                        format!("the tracer crashed (a bug in whitted): {message}")
                    }
                };
                self.note = Some(Note {
                    text,
                    is_error: true,
                });
            }
        }
    }

    /// `W`: the change as a file edit, or why it cannot be written.
    fn write_back(&mut self) -> Vec<Effect> {
        let Some(outcome) = &self.outcome else {
            self.note = Some(Note {
                text: "nothing to write: change a value first (Enter)".into(),
                is_error: true,
            });
            return Vec::new();
        };
        let param = outcome.param;
        match write_back(&self.base.scene, param, &outcome.text) {
            WriteBack::Edit {
                path,
                original,
                contents,
                line,
                new_line,
            } => {
                self.note = Some(Note {
                    text: format!("writing {path}:{line}: {new_line}"),
                    is_error: false,
                });
                vec![Effect::WriteScene {
                    path: PathBuf::from(path),
                    original,
                    contents,
                    line,
                }]
            }
            WriteBack::Refused(why) => {
                self.note = Some(Note {
                    text: why,
                    is_error: true,
                });
                Vec::new()
            }
        }
    }

    /// The result of writing the file (the watcher then reloads it).
    pub fn apply_write(&mut self, result: Result<(PathBuf, u32), String>) {
        self.note = Some(match result {
            Ok((path, line)) => Note {
                text: format!("wrote {}:{line}; reloading", path.display()),
                is_error: false,
            },
            Err(error) => Note {
                text: format!("not written: {error}"),
                is_error: true,
            },
        });
    }
}

impl WhatIfJob {
    /// Prepares the changed scene and traces the pixel in it (the worker's body; tests call
    /// it directly).
    pub fn run(self) -> WhatIfTraced {
        let options = RenderOptions::from_settings(&self.scene.settings);
        let (param, value, generation) = (self.param, self.value, self.generation);
        let prepared = catch_unwind(AssertUnwindSafe(|| LoadedScene::new(self.scene)));
        let result = match prepared {
            Err(payload) => Err(TraceFailure::Crashed(
                take_worker_panic().unwrap_or_else(|| panic_text(&*payload)),
            )),
            Ok(loaded) => {
                let job = TraceJob {
                    generation,
                    loaded: loaded.clone(),
                    options,
                    pixel: self.pixel,
                    cancel: self.cancel,
                    node_budget: self.node_budget,
                };
                let Traced { result, .. } = job.run();
                result.map(|(tree, _)| (loaded, tree))
            }
        };
        WhatIfTraced {
            generation,
            param,
            value,
            result,
        }
    }

    /// Runs on a new thread and sends the answer as [`Event::WhatIfTraced`].
    pub fn spawn(self, events: Sender<Event>) -> std::io::Result<()> {
        std::thread::Builder::new()
            .name(format!("what-if {}", self.generation))
            .spawn(move || {
                let _ = events.send(Event::WhatIfTraced(self.run()));
            })?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::{
        glass_pixel_tree, material_named, whitted_scene, GLASS_PIXEL, SCENE_TEXT,
    };
    use ratatui::crossterm::event::KeyModifiers;
    use whitted_explain::diff::Change;
    use whitted_tracer::ray_tree::{trace_pixel, SampleChoice};
    use whitted_tracer::PreparedScene;

    fn key(code: KeyCode) -> KeyEvent {
        KeyEvent::new(code, KeyModifiers::NONE)
    }

    /// The popup on the glass pixel with the glass material listed (and selected).
    fn popup() -> WhatIf {
        let loaded = LoadedScene::new(whitted_scene());
        let glass = material_named(&loaded.scene, "glass");
        WhatIf::open(loaded, glass_pixel_tree(), Some(glass), 100_000)
    }

    /// Types `text` over the selected value and presses Enter; runs the re-trace here.
    fn change_to(what_if: &mut WhatIf, text: &str) -> Vec<Effect> {
        what_if.handle_key(key(KeyCode::Enter));
        for _ in 0..20 {
            what_if.handle_key(key(KeyCode::Backspace));
        }
        for c in text.chars() {
            what_if.handle_key(key(KeyCode::Char(c)));
        }
        let (closed, effects) = what_if.handle_key(key(KeyCode::Enter));
        assert!(!closed);
        if let Some(job) = what_if.take_job() {
            what_if.apply(job.run());
        }
        effects
    }

    #[test]
    fn a_changed_ior_retraces_the_pixel_as_the_tracer_does_on_a_scene_edited_apart() {
        let mut what_if = popup();
        assert_eq!(what_if.selected_param().map(Param::property), Some("ior"));
        assert_eq!(change_to(&mut what_if, "1.0"), vec![Effect::WhatIfTrace]);
        let outcome = what_if.outcome.as_ref().expect("a re-trace");

        // The oracle: the IR edited by hand, traced through trace_pixel.
        let mut edited = whitted_scene().into_inner();
        let glass = material_named(&edited, "glass");
        edited.materials.get_mut(glass).unwrap().ior = 1.0;
        let edited = whitted_ir::validate(edited).unwrap();
        let prepared = PreparedScene::new(&edited);
        let options = RenderOptions::from_settings(&edited.settings);
        let (x, y) = GLASS_PIXEL;
        let expected = trace_pixel(&prepared, &edited, &options, x, y, SampleChoice::All).unwrap();
        assert_eq!(outcome.tree.color, expected.color, "bit for bit");
        assert_eq!(
            outcome.diff.color,
            [glass_pixel_tree().color, expected.color]
        );
        assert_ne!(
            expected.color,
            glass_pixel_tree().color,
            "the ior matters here"
        );
        let first = outcome.diff.divergences.first().expect("a divergence");
        assert_eq!(first.what, "ior of material glass (at glass sphere)");
        assert_eq!(first.values, ["1.5".to_string(), "1".to_string()]);
        assert!(!outcome.rays.is_empty());
        // The popup's own scene is untouched: Esc discards the change.
        assert_eq!(what_if.base.scene.materials[glass].ior, 1.5);
        let (closed, _) = what_if.handle_key(key(KeyCode::Esc));
        assert!(closed);
    }

    #[test]
    fn a_value_out_of_range_is_said_plainly_and_traces_nothing() {
        let mut what_if = popup();
        assert!(change_to(&mut what_if, "-2").is_empty());
        assert!(what_if.outcome.is_none() && what_if.running.is_none());
        let note = what_if.note.clone().expect("a note");
        assert!(note.is_error);
        assert_eq!(note.text, "ior must be a number from 0.001 to 1000");
        assert!(what_if.editing.is_some(), "the value stays open to fix");
        // Esc leaves the edit, a second Esc the popup.
        assert!(!what_if.handle_key(key(KeyCode::Esc)).0);
        assert!(what_if.editing.is_none());
        assert!(what_if.handle_key(key(KeyCode::Esc)).0);
    }

    #[test]
    fn a_lower_max_depth_removes_rays_and_the_list_accounts_for_every_one() {
        let mut what_if = popup();
        what_if.selected = 0;
        assert_eq!(
            what_if.selected_param(),
            Some(Param::setting(&whitted_ir::setting_rows::MAX_DEPTH))
        );
        change_to(&mut what_if, "1");
        let outcome = what_if.outcome.as_ref().expect("a re-trace");
        let removed: usize = outcome
            .rays
            .iter()
            .filter(|c| c.change == Change::Removed)
            .map(|c| 1 + c.rays_below)
            .sum();
        assert!(removed > 0);
        assert_eq!(outcome.diff.rays[0] - removed, outcome.diff.rays[1]);
        assert!(outcome.rays.iter().all(|c| c.change != Change::Added));
    }

    #[test]
    fn w_writes_the_change_on_its_line_or_adds_it_to_its_block() {
        let mut what_if = popup();
        assert!(what_if.handle_key(key(KeyCode::Char('W'))).1.is_empty());
        assert!(what_if
            .note
            .as_ref()
            .unwrap()
            .text
            .contains("change a value first"));
        change_to(&mut what_if, "1.0");
        let (_, effects) = what_if.handle_key(key(KeyCode::Char('W')));
        let [Effect::WriteScene {
            path,
            original,
            contents,
            line,
        }] = effects.as_slice()
        else {
            panic!("{effects:?}");
        };
        assert_eq!(path, &PathBuf::from("scenes/whitted.scene"));
        assert_eq!(original.as_str(), SCENE_TEXT);
        assert_eq!(*line, 15);
        assert_eq!(contents.as_str(), SCENE_TEXT.replace("ior 1.5", "ior 1"));
        what_if.apply_write(Ok((path.clone(), 15)));
        assert_eq!(
            what_if.note.as_ref().unwrap().text,
            "wrote scenes/whitted.scene:15; reloading"
        );

        // The mirror writes no ior: it is added to the mirror's block, on its line.
        let loaded = LoadedScene::new(whitted_scene());
        let mirror = material_named(&loaded.scene, "mirror");
        let mut what_if = WhatIf::open(loaded, glass_pixel_tree(), Some(mirror), 100_000);
        change_to(&mut what_if, "1.3");
        let (_, effects) = what_if.handle_key(key(KeyCode::Char('W')));
        let [Effect::WriteScene { contents, line, .. }] = effects.as_slice() else {
            panic!("{effects:?}");
        };
        assert_eq!(*line, 17);
        assert_eq!(
            contents.as_str(),
            SCENE_TEXT.replace("reflective 0.8 }", "reflective 0.8 ior 1.3 }")
        );
        assert!(what_if
            .note
            .as_ref()
            .unwrap()
            .text
            .starts_with("writing scenes/whitted.scene:17: material mirror {"));
    }

    #[test]
    fn an_answer_to_a_superseded_change_is_dropped() {
        let mut what_if = popup();
        what_if.handle_key(key(KeyCode::Enter));
        what_if.handle_key(key(KeyCode::Backspace));
        what_if.handle_key(key(KeyCode::Char('2')));
        what_if.handle_key(key(KeyCode::Enter));
        let old = what_if.take_job().unwrap();
        change_to(&mut what_if, "1.0");
        let kept = what_if.outcome.as_ref().map(|o| o.text.clone());
        what_if.apply(old.run());
        assert_eq!(what_if.outcome.as_ref().map(|o| o.text.clone()), kept);
        assert_eq!(kept.as_deref(), Some("1"));
    }
}
