//! The query's recorder: it listens to one pixel's trace through the tracer's one code path
//! and keeps only a bit per predicate, the deepest ray, a small stack of the surfaces the
//! open rays hit (for `self_hit`) and, per predicate, the first ray that showed it. No tree
//! is built, so a whole image costs little more than a render.

use whitted_tracer::{
    trace_pixel_with, LightSample, PixelAccumulator, PreparedScene, RayKind, RayStart, Recorder,
    RenderOptions, ShadowResult, SkippedRay, SurfaceHit, Termination, Vec3A,
};

use super::{Observed, Query, Test};

/// The ray that first showed a predicate in a pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Witness {
    /// Which predicate, by its index in the query (left to right).
    pub atom: usize,
    pub sample: u32,
    /// The ray: for `max_depth`, `weight_cutoff` and a dropped transmission (`tir`), the
    /// ray that was not traced; for the `shadow_blocked` family, the shadow ray.
    pub kind: RayKind,
    pub depth: u32,
    /// The object concerned: the one hit, the blocker, or for rays not traced the surface
    /// they would have left.
    pub object: Option<u32>,
    /// When it was seen, to pick the first of several.
    pub(crate) order: u32,
}

/// An open ray: its depth and the surface it hit (once it has).
#[derive(Clone, Copy, Debug)]
struct Frame {
    kind: RayKind,
    depth: u32,
    object: Option<u32>,
    point: [f32; 3],
}

struct Watch<'q> {
    query: &'q Query,
    observed: Observed,
    witnesses: Vec<Option<Witness>>,
    stack: Vec<Frame>,
    sample: u32,
    events: u32,
}

impl Watch<'_> {
    fn set(&mut self, atom: usize, kind: RayKind, depth: u32, object: Option<u32>) {
        self.observed.bits |= 1 << atom;
        if self.witnesses[atom].is_none() {
            self.events += 1;
            self.witnesses[atom] = Some(Witness {
                atom,
                sample: self.sample,
                kind,
                depth,
                object,
                order: self.events,
            });
        }
    }

    fn each(
        &mut self,
        mut f: impl FnMut(&Test) -> bool,
        kind: RayKind,
        depth: u32,
        object: Option<u32>,
    ) {
        for i in 0..self.query.atoms.len() {
            if f(&self.query.atoms[i]) {
                self.set(i, kind, depth, object);
            }
        }
    }

    fn top(&self) -> Option<Frame> {
        self.stack.last().copied()
    }
}

/// A hit closer than `TINY` of the point it left from (scaled like explain's `self_hit`).
pub(crate) fn tiny(t: f32, from: [f32; 3]) -> bool {
    let scale = from.iter().fold(1.0f32, |m, c| m.max(c.abs()));
    t < crate::findings::surfaces::TINY * scale
}

pub(crate) fn finite(c: [f32; 3]) -> bool {
    c.iter().all(|v| v.is_finite())
}

impl Recorder for Watch<'_> {
    fn ray_started(&mut self, ray: &RayStart) {
        self.observed.deepest = self.observed.deepest.max(ray.depth);
        if ray.interface.is_some_and(|i| i.total_internal_reflection) {
            let object = self.top().and_then(|f| f.object);
            self.each(|t| *t == Test::Tir, ray.kind, ray.depth, object);
        }
        self.stack.push(Frame {
            kind: ray.kind,
            depth: ray.depth,
            object: None,
            point: [0.0; 3],
        });
    }

    fn surface_hit(&mut self, hit: &SurfaceHit) {
        let object = hit.object.index() as u32;
        let leaf = hit.leaf.index() as u32;
        let n = self.stack.len();
        let parent = n.checked_sub(2).map(|i| self.stack[i]);
        let Some(frame) = self.stack.last_mut() else {
            return;
        };
        frame.object = Some(object);
        frame.point = hit.point.to_array();
        let (kind, depth) = (frame.kind, frame.depth);
        self.each(
            |t| matches!(t, Test::Hit(set) if set.contains(&object) || set.contains(&leaf)),
            kind,
            depth,
            Some(object),
        );
        if let Some(parent) = parent {
            if parent.object == Some(object) && tiny(hit.t, parent.point) {
                self.each(|t| *t == Test::SelfHit, kind, depth, Some(object));
            }
        }
    }

    fn light_sampled(&mut self, sample: &LightSample) {
        let Some(shadow) = &sample.shadow_ray else {
            return;
        };
        let ShadowResult::Blocked { object, leaf, t } = shadow.result else {
            return;
        };
        let (object, leaf) = (object.index() as u32, leaf.index() as u32);
        let frame = self.top();
        let depth = frame.map_or(0, |f| f.depth);
        let transparent = self.query.is_transparent(leaf);
        let kind = RayKind::Shadow;
        self.each(
            |test| match test {
                Test::ShadowBlocked => true,
                Test::ShadowBlockedBy(set) => set.contains(&object) || set.contains(&leaf),
                Test::ShadowBlockedByTransparent => transparent,
                _ => false,
            },
            kind,
            depth,
            Some(object),
        );
        if let Some(frame) = frame {
            if frame.object == Some(object) && tiny(t, frame.point) {
                self.each(|test| *test == Test::SelfHit, kind, depth, Some(object));
            }
        }
    }

    fn secondary_skipped(&mut self, skipped: &SkippedRay) {
        let object = self.top().and_then(|f| f.object);
        let wanted = match skipped.reason {
            Termination::MaxDepth => Test::MaxDepth,
            Termination::WeightCutoff => Test::WeightCutoff,
            Termination::TotalInternalReflection => Test::Tir,
            _ => return,
        };
        self.each(|t| *t == wanted, skipped.kind, skipped.depth, object);
    }

    fn ray_finished(&mut self, color: Vec3A, _termination: Termination) {
        if !finite(color.to_array()) {
            let frame = self.top();
            self.each(
                |t| *t == Test::Nan,
                frame.map_or(RayKind::Camera, |f| f.kind),
                frame.map_or(0, |f| f.depth),
                frame.and_then(|f| f.object),
            );
        }
        self.stack.pop();
    }
}

/// What pixel `(x, y)`'s rays show, every sample traced through the one code path, and the
/// first witness of each predicate. The pixel's colour (the mean, as `render` makes it)
/// counts for `nan` too.
pub(crate) fn observe_pixel(
    prepared: &PreparedScene,
    options: &RenderOptions,
    query: &Query,
    x: u32,
    y: u32,
) -> (Observed, Vec<Option<Witness>>) {
    let mut watch = Watch {
        query,
        observed: Observed::default(),
        witnesses: vec![None; query.atoms.len()],
        stack: Vec::new(),
        sample: 0,
        events: 0,
    };
    let mut accumulator = PixelAccumulator::new();
    for sample in 0..options.samples_per_pixel.max(1) {
        watch.sample = sample;
        watch.stack.clear();
        accumulator.add(trace_pixel_with(
            prepared, options, x, y, sample, &mut watch,
        ));
    }
    if !finite(accumulator.mean()) {
        watch.each(|t| *t == Test::Nan, RayKind::Camera, 0, None);
    }
    (watch.observed, watch.witnesses)
}

/// The earliest witness among the predicates in `bits`.
pub(crate) fn first_witness(witnesses: &[Option<Witness>], bits: u64) -> Option<Witness> {
    witnesses
        .iter()
        .enumerate()
        .filter(|(i, _)| bits & (1 << i) != 0)
        .filter_map(|(_, w)| *w)
        .min_by_key(|w| w.order)
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::Scene;

    fn start(kind: RayKind, depth: u32) -> RayStart {
        RayStart {
            kind,
            depth,
            origin: Vec3A::ZERO,
            direction: Vec3A::Z,
            weight: Vec3A::ONE,
            coefficient: Vec3A::ONE,
            interface: None,
        }
    }

    // No scene makes a NaN colour (tests/integration/extremes.rs sees to that), so the
    // hooks are fed one by hand.
    #[test]
    fn a_ray_returning_nan_is_seen_with_its_depth() {
        let query = Query::compile("nan and depth >= 1", &Scene::default()).unwrap();
        let mut watch = Watch {
            query: &query,
            observed: Observed::default(),
            witnesses: vec![None; query.atoms.len()],
            stack: Vec::new(),
            sample: 3,
            events: 0,
        };
        watch.ray_started(&start(RayKind::Camera, 0));
        watch.ray_started(&start(RayKind::Reflected, 1));
        watch.ray_finished(Vec3A::new(0.0, f32::NAN, 0.0), Termination::Miss);
        watch.ray_finished(Vec3A::ONE, Termination::NotEnded);
        assert!(query.holds(&watch.observed));
        let witness = first_witness(&watch.witnesses, watch.observed.bits).unwrap();
        assert_eq!(
            (witness.sample, witness.kind, witness.depth),
            (3, RayKind::Reflected, 1)
        );
        assert!(watch.stack.is_empty());
        let clean = Observed {
            bits: 0,
            deepest: 1,
        };
        assert!(!query.holds(&clean));
    }
}
