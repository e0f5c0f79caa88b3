//! Whole-image queries (`whitted query`): which pixels' rays match a predicate such as
//! `tir and not hit("floor")` (docs/query.md).
//!
//! A query is read by `parse.rs` and resolved against the scene here (object names to
//! handles, so that a misspelt name is an error before any tracing). It is then answered
//! two ways that must agree: `watch.rs` listens to the tracer's one code path with a
//! recorder that keeps a few bits per pixel and builds no tree (what [`run`] uses over the
//! whole image, in parallel), and `tree.rs` evaluates it on a recorded ray tree (the oracle
//! that tests compare [`run`] against, and what the binary shows for a listed pixel).

mod parse;
mod tree;
mod watch;

pub use parse::{parse, Compare, QueryError, PREDICATES};
pub use watch::Witness;

use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use whitted_ir::{Handle, Object, Scene};
use whitted_tracer::ray_tree::RayTree;
use whitted_tracer::{PreparedScene, RenderOptions};

use parse::{Atom, Expr};

/// The most predicates one query may hold (each is one bit per pixel while tracing).
pub const MAX_ATOMS: usize = 64;

/// A predicate resolved against a scene.
#[derive(Clone, Debug)]
pub struct Query {
    expr: Node,
    atoms: Vec<Test>,
    /// Per object handle: whether its own material transmits (for
    /// `shadow_blocked_by_transparent`; a blocker is a leaf shape with its material).
    transparent: Vec<bool>,
}

/// The expression with each predicate replaced by its index in `Query::atoms`.
#[derive(Clone, Debug)]
enum Node {
    Atom(usize),
    Not(Box<Node>),
    And(Box<Node>, Box<Node>),
    Or(Box<Node>, Box<Node>),
}

/// One predicate, resolved.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Test {
    MaxDepth,
    WeightCutoff,
    Tir,
    ShadowBlocked,
    ShadowBlockedBy(Vec<u32>),
    ShadowBlockedByTransparent,
    SelfHit,
    Nan,
    Hit(Vec<u32>),
    Depth(Compare, u32),
}

impl Test {
    pub(crate) fn name(&self) -> String {
        match self {
            Test::MaxDepth => "max_depth".into(),
            Test::WeightCutoff => "weight_cutoff".into(),
            Test::Tir => "tir".into(),
            Test::ShadowBlocked => "shadow_blocked".into(),
            Test::ShadowBlockedBy(_) => "shadow_blocked_by".into(),
            Test::ShadowBlockedByTransparent => "shadow_blocked_by_transparent".into(),
            Test::SelfHit => "self_hit".into(),
            Test::Nan => "nan".into(),
            Test::Hit(_) => "hit".into(),
            Test::Depth(_, _) => "depth".into(),
        }
    }
}

/// What a pixel's rays showed: which predicates held, and the deepest ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Observed {
    /// Bit `i` is set when predicate `i` (other than `depth`) held on some ray.
    pub bits: u64,
    /// The deepest camera, reflected or transmitted ray.
    pub deepest: u32,
}

impl Query {
    /// Reads `text` and resolves its object names in `scene` (a name matches an object or a
    /// CSG leaf with that name).
    pub fn compile(text: &str, scene: &Scene) -> Result<Query, QueryError> {
        let expr = parse(text)?;
        let mut atoms = Vec::new();
        let expr = resolve(&expr, scene, &mut atoms)?;
        if atoms.len() > MAX_ATOMS {
            return Err(QueryError::new(
                format!(
                    "the query has {} predicates; at most {MAX_ATOMS} are allowed",
                    atoms.len()
                ),
                0..text.len(),
            ));
        }
        let transparent = scene
            .objects
            .iter()
            .map(|(_, object)| {
                scene
                    .materials
                    .get(object.material)
                    .is_some_and(|m| !m.transmissive.is_black())
            })
            .collect();
        Ok(Query {
            expr,
            atoms,
            transparent,
        })
    }

    /// Whether what a pixel showed satisfies the query.
    pub fn holds(&self, observed: &Observed) -> bool {
        self.eval(&self.expr, observed)
    }

    fn eval(&self, node: &Node, observed: &Observed) -> bool {
        match node {
            Node::Atom(i) => self.atom_holds(*i, observed),
            Node::Not(inner) => !self.eval(inner, observed),
            Node::And(a, b) => self.eval(a, observed) && self.eval(b, observed),
            Node::Or(a, b) => self.eval(a, observed) || self.eval(b, observed),
        }
    }

    fn atom_holds(&self, i: usize, observed: &Observed) -> bool {
        match &self.atoms[i] {
            Test::Depth(compare, n) => compare.holds(observed.deepest, *n),
            _ => observed.bits & (1 << i) != 0,
        }
    }

    /// The query evaluated on a recorded ray tree (every sample of it): the oracle.
    pub fn matches_tree(&self, tree: &RayTree) -> bool {
        self.holds(&tree::observe(self, tree))
    }

    /// The predicates that occur outside any `not`: a pixel that matches has a ray that
    /// shows one of them, unless the match rests on `not` alone.
    fn positive(&self) -> u64 {
        fn go(node: &Node, negated: bool, bits: &mut u64) {
            match node {
                Node::Atom(i) if !negated => *bits |= 1 << i,
                Node::Atom(_) => {}
                Node::Not(inner) => go(inner, !negated, bits),
                Node::And(a, b) | Node::Or(a, b) => {
                    go(a, negated, bits);
                    go(b, negated, bits);
                }
            }
        }
        let mut bits = 0;
        go(&self.expr, false, &mut bits);
        bits
    }

    pub(crate) fn is_transparent(&self, object: u32) -> bool {
        self.transparent
            .get(object as usize)
            .copied()
            .unwrap_or(false)
    }

    pub(crate) fn atoms(&self) -> &[Test] {
        &self.atoms
    }
}

fn resolve(expr: &Expr, scene: &Scene, atoms: &mut Vec<Test>) -> Result<Node, QueryError> {
    Ok(match expr {
        Expr::Not(inner) => Node::Not(Box::new(resolve(inner, scene, atoms)?)),
        Expr::And(a, b) => Node::And(
            Box::new(resolve(a, scene, atoms)?),
            Box::new(resolve(b, scene, atoms)?),
        ),
        Expr::Or(a, b) => Node::Or(
            Box::new(resolve(a, scene, atoms)?),
            Box::new(resolve(b, scene, atoms)?),
        ),
        Expr::Atom(atom) => {
            let test = match atom {
                Atom::MaxDepth => Test::MaxDepth,
                Atom::WeightCutoff => Test::WeightCutoff,
                Atom::Tir => Test::Tir,
                Atom::ShadowBlocked => Test::ShadowBlocked,
                Atom::ShadowBlockedByTransparent => Test::ShadowBlockedByTransparent,
                Atom::SelfHit => Test::SelfHit,
                Atom::Nan => Test::Nan,
                Atom::Depth(c, n) => Test::Depth(*c, *n),
                Atom::ShadowBlockedBy(name, at) => Test::ShadowBlockedBy(named(scene, name, at)?),
                Atom::Hit(name, at) => Test::Hit(named(scene, name, at)?),
            };
            atoms.push(test);
            Node::Atom(atoms.len() - 1)
        }
    })
}

/// The handles of the objects called `name`; an error naming the closest names when none is.
fn named(scene: &Scene, name: &str, at: &std::ops::Range<usize>) -> Result<Vec<u32>, QueryError> {
    let handles: Vec<u32> = scene
        .objects
        .iter()
        .filter(|(_, o)| scene.name_of(o) == Some(name))
        .map(|(h, _): (Handle<Object>, _)| h.index() as u32)
        .collect();
    if !handles.is_empty() {
        return Ok(handles);
    }
    let mut names: Vec<&str> = scene
        .objects
        .iter()
        .filter_map(|(_, o)| scene.name_of(o))
        .collect();
    names.sort_unstable();
    names.dedup();
    let hint = match names
        .iter()
        .map(|n| (parse::edit_distance(name, n), *n))
        .filter(|(d, _)| *d <= 2)
        .min_by_key(|(d, _)| *d)
    {
        Some((_, near)) => format!(": did you mean \"{near}\"?"),
        None if names.is_empty() => {
            ": the scene names no objects (give one a name: `sphere \"ball\" { ... }`)".into()
        }
        None => {
            let shown: Vec<String> = names.iter().take(8).map(|n| format!("\"{n}\"")).collect();
            format!(
                " (named objects: {}{})",
                shown.join(", "),
                if names.len() > 8 { ", ..." } else { "" }
            )
        }
    };
    Err(QueryError::new(
        format!("no object is named \"{name}\"{hint}"),
        at.clone(),
    ))
}

/// One pixel that matches, with the ray that shows why (when a predicate outside any `not`
/// holds; `None` when the pixel matches through `depth` or `not` alone).
#[derive(Clone, Debug, PartialEq)]
pub struct Match {
    pub pixel: [u32; 2],
    pub witness: Option<Witness>,
    /// The deepest camera, reflected or transmitted ray (what `depth` compares).
    pub deepest: u32,
}

/// The answer over a whole image.
#[derive(Clone, Debug, PartialEq)]
pub struct QueryResult {
    pub width: u32,
    pub height: u32,
    /// Row-major, one per pixel: whether it matches.
    pub mask: Vec<bool>,
    /// The matching pixels in row-major order.
    pub matches: Vec<Match>,
}

/// Every pixel of the image checked against `query`, rows in parallel on the current rayon
/// pool, each sample traced through the one code path with a recorder that keeps only what
/// the predicates need. The result does not depend on the thread count.
pub fn run(prepared: &PreparedScene, options: &RenderOptions, query: &Query) -> QueryResult {
    let never = AtomicBool::new(false);
    let control = RunControl {
        cancel: &never,
        row_done: &|| {},
    };
    // Nothing cancels it, so it always finishes.
    run_with(prepared, options, query, &control).unwrap_or_else(|| QueryResult {
        width: options.width,
        height: options.height,
        mask: Vec::new(),
        matches: Vec::new(),
    })
}

/// One pixel's answer while running: whether it matches, its witness, its deepest ray.
type PixelAnswer = (bool, Option<Witness>, u32);

/// How a caller that waits on [`run_with`] (the debugger) steers it: a flag that stops it
/// between rows, and a call after each finished row (for progress).
pub struct RunControl<'a> {
    pub cancel: &'a AtomicBool,
    pub row_done: &'a (dyn Fn() + Sync),
}

/// [`run`], stopping between rows when `control.cancel` is set (then `None`).
pub fn run_with(
    prepared: &PreparedScene,
    options: &RenderOptions,
    query: &Query,
    control: &RunControl<'_>,
) -> Option<QueryResult> {
    let (width, height) = (options.width, options.height);
    let positive = query.positive();
    let rows: Option<Vec<Vec<PixelAnswer>>> = (0..height)
        .into_par_iter()
        .map(|y| {
            if control.cancel.load(Ordering::Relaxed) {
                return None;
            }
            let row = (0..width)
                .map(|x| {
                    let (observed, witnesses) =
                        watch::observe_pixel(prepared, options, query, x, y);
                    let matched = query.holds(&observed);
                    let witness = matched
                        .then(|| watch::first_witness(&witnesses, observed.bits & positive))
                        .flatten();
                    (matched, witness, observed.deepest)
                })
                .collect();
            (control.row_done)();
            Some(row)
        })
        .collect();
    let rows = rows?;
    let mut mask = Vec::with_capacity((width * height) as usize);
    let mut matches = Vec::new();
    for (y, row) in rows.into_iter().enumerate() {
        for (x, (matched, witness, deepest)) in row.into_iter().enumerate() {
            mask.push(matched);
            if matched {
                matches.push(Match {
                    pixel: [x as u32, y as u32],
                    witness,
                    deepest,
                });
            }
        }
    }
    Some(QueryResult {
        width,
        height,
        mask,
        matches,
    })
}

/// What a witness shows, in words: `tir: sample 0, transmitted ray at depth 3 in glass`.
pub fn describe_witness(query: &Query, scene: &Scene, witness: &Witness) -> String {
    let what = query
        .atoms()
        .get(witness.atom)
        .map_or("?".to_string(), Test::name);
    let place = match witness.object {
        Some(handle) => {
            let handle = Handle::<Object>::from_index(handle as usize);
            let location = scene.sources.location(scene.objects.span(handle));
            let relation = match query.atoms().get(witness.atom) {
                Some(
                    Test::ShadowBlocked
                    | Test::ShadowBlockedBy(_)
                    | Test::ShadowBlockedByTransparent,
                ) => "blocked by",
                Some(Test::MaxDepth | Test::WeightCutoff) => "not traced from",
                Some(Test::Tir) => "inside",
                _ => "hitting",
            };
            format!(" {relation} {} ({location})", scene.object_label(handle))
        }
        None => String::new(),
    };
    format!(
        "{what}: sample {}, {} ray at depth {}{place}",
        witness.sample,
        witness.kind.name(),
        witness.depth
    )
}
