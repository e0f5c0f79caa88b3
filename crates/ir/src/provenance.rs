//! The instantiation stack of every object: the imports, function calls (with their argument
//! values) and loop iterations (with their variable's value) that were running when the
//! object was made, kept in a side table beside the object arena, like spans.
//!
//! Frames form a tree shared by every object made under them: one frame per loop iteration,
//! call or import that made at least one object, pointing at its parent (12 bytes each). The
//! objects' table is run-length coded in arena order: a run of objects that share a frame,
//! or that each have the next frame (a loop making one object per iteration), is one entry.
//! An object made at the top level of the root file has no frame and costs nothing. Values
//! are stored as numbers and formatted only when shown.

use std::fmt::{self, Write as _};

use glam::DVec3;
use serde::Serialize;

use crate::arena::Handle;
use crate::scene::Object;
use crate::source::{SourceMap, Span};

/// What a frame's site is: the statement whose running made the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SiteKind {
    /// An `import` line: the objects were made by the imported file's code.
    Import,
    /// A call of a user function: `name` is the function, `params` its parameters.
    Call,
    /// A loop: `name` is its variable.
    Loop,
}

/// A statement that frames point at: shared by every frame it made (every iteration of a
/// loop, every call from one call site).
#[derive(Clone, Debug, PartialEq)]
pub struct Site {
    pub kind: SiteKind,
    /// The import line, the call, or the loop's header.
    pub span: Span,
    /// The function's or the loop variable's name; empty for an import.
    pub name: String,
    /// The called function's parameter names, in order (calls only).
    pub params: Vec<String>,
}

/// Identifies a site in a [`Provenance`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SiteId(u32);

/// Identifies a frame in a [`Provenance`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FrameId(u32);

/// An argument's value as the call received it. Numbers, booleans and vectors are kept as
/// values; anything else (strings, arrays, materials) as the text the front end wrote for it.
#[derive(Clone, Debug, PartialEq)]
pub enum ArgValue {
    Number(f64),
    Bool(bool),
    Vector(DVec3),
    Text(String),
}

/// Marks "no frame" in the compact tables (a frame id is never this large: the object limit
/// keeps the tables far smaller).
const NONE: u32 = u32::MAX;

/// One frame, packed: 12 bytes, since a scene made by loops has one per iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Frame {
    parent: u32,
    site: u32,
    /// A call's first argument in `args`; a loop's value when [`SMALL`] is set (a whole
    /// number from 0 to 2^31 - 1, the usual case), or else its index in `values`.
    payload: u32,
}

/// Marks a loop value stored in the frame itself.
const SMALL: u32 = 1 << 31;

/// Objects `first_object..` (up to the next run, or to `Provenance::recorded` for the
/// last) have frame `frame` each (`NONE`: no stack), or, when `consecutive`, the frames
/// `frame, frame + 1, ...` in turn.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Run {
    first_object: u32,
    frame: u32,
    consecutive: bool,
}

/// The instantiation stacks of a scene's objects (see the module documentation).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Provenance {
    sites: Vec<Site>,
    frames: Vec<Frame>,
    args: Vec<ArgValue>,
    /// Loop values that are not small whole numbers.
    values: Vec<f64>,
    /// The innermost frame of each object, run-length coded in arena order; objects before
    /// the first run and from `recorded` on have none.
    runs: Vec<Run>,
    /// One past the last object recorded.
    recorded: u32,
}

/// One step of an object's stack, as shown: innermost first.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step<'a> {
    /// The object was made by an imported file's code, which this line imported.
    Import { span: Span },
    /// A call: the function's name, the call's span and each parameter with its value.
    Call {
        name: &'a str,
        span: Span,
        params: &'a [String],
        args: &'a [ArgValue],
    },
    /// A loop iteration: the variable, its value and the loop's span.
    Loop {
        var: &'a str,
        value: f64,
        span: Span,
    },
}

impl Provenance {
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether no object has a stack.
    pub fn is_empty(&self) -> bool {
        self.runs.is_empty()
    }

    /// Adds a site and returns its id.
    pub fn add_site(&mut self, site: Site) -> SiteId {
        let id = SiteId(u32::try_from(self.sites.len()).unwrap_or(NONE));
        self.sites.push(site);
        id
    }

    pub fn site(&self, id: SiteId) -> Option<&Site> {
        self.sites.get(id.0 as usize)
    }

    /// A frame for one iteration of the loop at `site`, with its variable's value.
    pub fn push_loop(&mut self, parent: Option<FrameId>, site: SiteId, value: f64) -> FrameId {
        let small = value >= 0.0 && value < f64::from(SMALL) && value.fract() == 0.0;
        let payload = if small && !(value == 0.0 && value.is_sign_negative()) {
            value as u32 | SMALL
        } else {
            let index = u32::try_from(self.values.len()).unwrap_or(NONE) & !SMALL;
            self.values.push(value);
            index
        };
        self.push_frame(parent, site, payload)
    }

    /// A frame for one call from `site`, with its arguments in parameter order.
    pub fn push_call(
        &mut self,
        parent: Option<FrameId>,
        site: SiteId,
        args: impl IntoIterator<Item = ArgValue>,
    ) -> FrameId {
        let first = u32::try_from(self.args.len()).unwrap_or(NONE);
        self.args.extend(args);
        self.push_frame(parent, site, first)
    }

    /// A frame for code run through the import line at `site`.
    pub fn push_import(&mut self, parent: Option<FrameId>, site: SiteId) -> FrameId {
        self.push_frame(parent, site, 0)
    }

    fn push_frame(&mut self, parent: Option<FrameId>, site: SiteId, payload: u32) -> FrameId {
        let id = FrameId(u32::try_from(self.frames.len()).unwrap_or(NONE));
        self.frames.push(Frame {
            parent: parent.map_or(NONE, |p| p.0),
            site: site.0,
            payload,
        });
        id
    }

    /// Records that `object` was made inside `frame` (`None`: at the top level of the root
    /// file). Objects are recorded in arena order, as they are made; objects skipped have no
    /// stack, and an object before the last one recorded is left as it was (returns false).
    pub fn set_object(&mut self, object: Handle<Object>, frame: Option<FrameId>) -> bool {
        let Ok(index) = u32::try_from(object.index()) else {
            return false;
        };
        if index < self.recorded {
            return false;
        }
        let Some(frame) = frame else {
            // Nothing to store: objects from `recorded` on have no stack.
            return true;
        };
        if let Some(last) = self.runs.last_mut() {
            let length = self.recorded - last.first_object;
            let contiguous = index == self.recorded && last.frame != NONE;
            if contiguous && !last.consecutive && frame.0 == last.frame {
                self.recorded = index + 1;
                return true;
            }
            let next = last.frame.wrapping_add(length);
            if contiguous && (last.consecutive || length == 1) && frame.0 == next {
                last.consecutive = true;
                self.recorded = index + 1;
                return true;
            }
            if index > self.recorded {
                // The objects in between were made without a stack.
                self.runs.push(Run {
                    first_object: self.recorded,
                    frame: NONE,
                    consecutive: false,
                });
            }
        }
        self.runs.push(Run {
            first_object: index,
            frame: frame.0,
            consecutive: false,
        });
        self.recorded = index + 1;
        true
    }

    /// The innermost frame of an object, if it has a stack.
    pub fn frame_of(&self, object: Handle<Object>) -> Option<FrameId> {
        let index = u32::try_from(object.index()).ok()?;
        if index >= self.recorded {
            return None;
        }
        let after = self.runs.partition_point(|run| run.first_object <= index);
        let run = self.runs.get(after.checked_sub(1)?)?;
        if run.frame == NONE {
            return None;
        }
        let offset = if run.consecutive {
            index - run.first_object
        } else {
            0
        };
        Some(FrameId(run.frame.wrapping_add(offset)))
    }

    /// The steps of an object's stack, innermost first (empty for an object made at the top
    /// level of the root file). A malformed table ends the walk rather than panicking.
    pub fn stack(&self, object: Handle<Object>) -> Vec<Step<'_>> {
        let mut steps = Vec::new();
        let mut current = self.frame_of(object).map_or(NONE, |f| f.0);
        // Parents are pushed before their children, so a well-formed chain strictly
        // decreases; the bound also stops a hand-made cycle.
        let mut remaining = self.frames.len();
        while current != NONE && remaining > 0 {
            remaining -= 1;
            let Some(frame) = self.frames.get(current as usize) else {
                break;
            };
            let Some(site) = self.sites.get(frame.site as usize) else {
                break;
            };
            steps.push(match site.kind {
                SiteKind::Import => Step::Import { span: site.span },
                SiteKind::Loop => Step::Loop {
                    var: &site.name,
                    value: if frame.payload & SMALL != 0 {
                        f64::from(frame.payload & !SMALL)
                    } else {
                        // A malformed index shows as NaN rather than panicking.
                        self.values
                            .get(frame.payload as usize)
                            .copied()
                            .unwrap_or(f64::NAN)
                    },
                    span: site.span,
                },
                SiteKind::Call => {
                    let first = (frame.payload as usize).min(self.args.len());
                    let end = first.saturating_add(site.params.len()).min(self.args.len());
                    Step::Call {
                        name: &site.name,
                        span: site.span,
                        params: &site.params,
                        args: &self.args[first..end],
                    }
                }
            });
            current = frame.parent;
        }
        steps
    }

    /// An object's stack as one line, innermost first, each step with its `file:line:col`:
    /// `i = 7 at lib.scene:3:1, import at main.scene:1:1, ring(12, 2) at main.scene:5:3`.
    /// Empty for an object without a stack.
    pub fn describe(&self, object: Handle<Object>, sources: &SourceMap) -> String {
        let mut line = String::new();
        for (i, step) in self.stack(object).iter().enumerate() {
            if i > 0 {
                line.push_str(", ");
            }
            let _ = write!(
                line,
                "{} at {}",
                step.label(),
                sources.location(step.span())
            );
        }
        line
    }
}

impl Step<'_> {
    /// Where the step's statement is.
    pub fn span(&self) -> Span {
        match *self {
            Step::Import { span } | Step::Call { span, .. } | Step::Loop { span, .. } => span,
        }
    }

    /// The step's kind as JSON and the ray tree name it: `import`, `call` or `loop`.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Step::Import { .. } => "import",
            Step::Call { .. } => "call",
            Step::Loop { .. } => "loop",
        }
    }

    /// The step without its place: `import`, `ring(12, 2)` or `i = 7`.
    pub fn label(&self) -> String {
        match *self {
            Step::Import { .. } => "import".to_string(),
            Step::Loop { var, value, .. } => format!("{var} = {}", Number(value)),
            Step::Call { name, args, .. } => {
                let mut text = format!("{name}(");
                for (i, arg) in args.iter().enumerate() {
                    if i > 0 {
                        text.push_str(", ");
                    }
                    let _ = write!(text, "{arg}");
                }
                text.push(')');
                text
            }
        }
    }
}

/// A number as the scene language writes it: whole numbers without a fraction, very large or
/// small ones with an exponent.
struct Number(f64);

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let magnitude = x.abs();
        if x == 0.0 {
            write!(f, "0")
        } else if !(1e-6..1e15).contains(&magnitude) {
            write!(f, "{x:e}")
        } else {
            write!(f, "{x}")
        }
    }
}

impl fmt::Display for ArgValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ArgValue::Number(x) => write!(f, "{}", Number(*x)),
            ArgValue::Bool(b) => write!(f, "{b}"),
            ArgValue::Vector(v) => {
                write!(f, "<{}, {}, {}>", Number(v.x), Number(v.y), Number(v.z))
            }
            ArgValue::Text(text) => f.write_str(text),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::{FileId, SourceFile};

    fn sources() -> SourceMap {
        let mut sources = SourceMap::new();
        sources.add(SourceFile::new(
            "main.scene",
            "import \"lib.scene\"\nfor k in 0..3 {\n  ring(12, 2)\n}\n",
        ));
        sources.add(SourceFile::new(
            "lib.scene",
            "fn ring(n, r) {\n  for i in 0..n { sphere { } }\n}\n",
        ));
        sources
    }

    #[test]
    fn stacks_are_shared_and_listed_innermost_first() {
        let mut p = Provenance::new();
        let main = FileId(0);
        let lib = FileId(1);
        let k = p.add_site(Site {
            kind: SiteKind::Loop,
            span: Span::new(main, 19, 32),
            name: "k".into(),
            params: vec![],
        });
        let ring = p.add_site(Site {
            kind: SiteKind::Call,
            span: Span::new(main, 37, 48),
            name: "ring".into(),
            params: vec!["n".into(), "r".into()],
        });
        let import = p.add_site(Site {
            kind: SiteKind::Import,
            span: Span::new(main, 0, 18),
            name: String::new(),
            params: vec![],
        });
        let i = p.add_site(Site {
            kind: SiteKind::Loop,
            span: Span::new(lib, 18, 31),
            name: "i".into(),
            params: vec![],
        });
        let k1 = p.push_loop(None, k, 1.0);
        let call = p.push_call(
            Some(k1),
            ring,
            [ArgValue::Number(12.0), ArgValue::Number(2.0)],
        );
        let imported = p.push_import(Some(call), import);
        let i7 = p.push_loop(Some(imported), i, 7.0);
        let i8 = p.push_loop(Some(imported), i, 8.0);
        p.set_object(Handle::from_index(3), Some(i7));
        p.set_object(Handle::from_index(4), Some(i8));

        let sources = sources();
        assert_eq!(
            p.describe(Handle::from_index(3), &sources),
            "i = 7 at lib.scene:2:3, import at main.scene:1:1, ring(12, 2) at main.scene:3:3, \
             k = 1 at main.scene:2:1"
        );
        assert!(p
            .describe(Handle::from_index(4), &sources)
            .starts_with("i = 8 at lib.scene:2:3, import"));
        // Before the first object with a stack, and past the last, objects have none.
        assert_eq!(p.describe(Handle::from_index(0), &sources), "");
        assert!(p.stack(Handle::from_index(5)).is_empty());
        assert_eq!(p.frame_of(Handle::from_index(3)), Some(i7));
    }

    #[test]
    fn objects_at_the_top_level_cost_nothing() {
        let mut p = Provenance::new();
        for index in 0..1000 {
            assert!(p.set_object(Handle::from_index(index), None));
        }
        assert!(p.is_empty());
        assert_eq!(p.runs.capacity(), 0);
    }

    #[test]
    fn runs_cover_shared_and_consecutive_frames_and_gaps() {
        let mut p = Provenance::new();
        let site = p.add_site(Site {
            kind: SiteKind::Loop,
            span: Span::detached(),
            name: "i".into(),
            params: vec![],
        });
        let outer = p.push_loop(None, site, 0.0);
        let frames: Vec<FrameId> = (0..4)
            .map(|i| p.push_loop(Some(outer), site, f64::from(i)))
            .collect();
        let object = Handle::from_index;
        // Objects 2..6 one frame each in turn, 6 and 7 sharing the last, 8 none, 9 the first.
        for (i, frame) in frames.iter().enumerate() {
            assert!(p.set_object(object(2 + i), Some(*frame)));
        }
        assert!(p.set_object(object(6), Some(frames[3])));
        assert!(p.set_object(object(7), Some(frames[3])));
        assert!(p.set_object(object(8), None));
        assert!(p.set_object(object(10), Some(frames[0])));
        // Out of order: refused, and nothing changes.
        assert!(!p.set_object(object(3), Some(outer)));
        let expected = [
            None,
            None,
            Some(frames[0]),
            Some(frames[1]),
            Some(frames[2]),
            Some(frames[3]),
            Some(frames[3]),
            Some(frames[3]),
            None,
            None,
            Some(frames[0]),
            None,
        ];
        for (i, frame) in expected.iter().enumerate() {
            assert_eq!(p.frame_of(object(i)), *frame, "object {i}");
        }
        // Four runs, not one entry per object: 2..6 in turn, 6..8 shared, the gap, 10.
        assert_eq!(p.runs.len(), 4);
    }

    #[test]
    fn loop_values_of_every_size_and_sign_read_back() {
        let mut p = Provenance::new();
        let site = p.add_site(Site {
            kind: SiteKind::Loop,
            span: Span::detached(),
            name: "i".into(),
            params: vec![],
        });
        let values = [0.0, -0.0, 7.0, -3.0, 2147483647.0, 2147483648.0, 1e300, 0.5];
        for (i, &value) in values.iter().enumerate() {
            let frame = p.push_loop(None, site, value);
            p.set_object(Handle::from_index(i), Some(frame));
        }
        for (i, &value) in values.iter().enumerate() {
            let stack = p.stack(Handle::from_index(i));
            let Step::Loop { value: read, .. } = stack[0] else {
                panic!("a loop step");
            };
            assert_eq!(read.to_bits(), value.to_bits(), "{value}");
        }
    }

    #[test]
    fn values_are_written_as_the_language_writes_them() {
        assert_eq!(ArgValue::Number(7.0).to_string(), "7");
        assert_eq!(ArgValue::Number(-0.25).to_string(), "-0.25");
        assert_eq!(ArgValue::Number(1e300).to_string(), "1e300");
        assert_eq!(
            ArgValue::Vector(DVec3::new(1.0, 0.5, -2.0)).to_string(),
            "<1, 0.5, -2>"
        );
        assert_eq!(ArgValue::Bool(true).to_string(), "true");
    }
}
