//! Lints found by tracing: a fixed grid of camera rays goes through the tracer's one code
//! path (`trace_pixel_with`) with a recorder of this module's, which keeps the surfaces the
//! rays hit, the surfaces the tracer found in the same place as a hit (within its error
//! bound), every object a ray met (hit or blocked a shadow ray) and the heaviest path
//! through glass that the depth limit cut. From those: coincident surfaces (the tracer's
//! own report, which sees zero-thickness objects such as a disk on a table, and another
//! object's surface passing through a hit point, tested with the IR's insideness) and
//! `max_depth` too low (the depth that gets the light out is found by the explain probe).

use glam::DVec3;
use whitted_ir::{Diagnostic, Handle, Object, Scene};
use whitted_tracer::optics::max_channel;
use whitted_tracer::{
    trace_pixel_with, CoincidentSurface, LightSample, PreparedScene, RayKind, RayStart, Recorder,
    RenderOptions, ShadowResult, SkippedRay, SurfaceHit, Termination,
};

use super::bounds::{world_bounds, Bounds};
use super::geometry::{object_name, renderables, short};
use super::{Lint, LintKind, MAX_PER_KIND};
use crate::inside::contains;
use crate::locate::setting_span;
use crate::probe::{depth_needed, DepthSearch};

/// The camera rays sampled: a grid of this many columns and rows over the image.
pub const GRID_COLUMNS: u32 = 32;
pub const GRID_ROWS: u32 = 24;
/// The most rays one sampled pixel may trace (a hall of mirrors doubles its rays at every
/// level until the weight cut-off).
pub const RAYS_PER_PIXEL: u64 = 4096;
/// The most (hit, object) pairs the coincidence test looks at: with a million objects only
/// the first few hits are tested, so the lint stays linear in the scene's size.
pub const MAX_SURFACE_TESTS: usize = 20_000_000;
/// The most exact shape tests (two insideness tests each, which invert a transform) the
/// coincidence lint makes, once the bounds let an object through: thousands of objects in
/// one place would otherwise cost a test per object per hit.
pub const MAX_SHAPE_TESTS: usize = 200_000;
/// A ray counts when its path weight (largest channel) is at least this: it makes at
/// least a twentieth of its pixel (as explain's findings).
pub const SIGNIFICANT: f32 = 0.05;
/// Two surfaces coincide at a hit when the other one passes within this fraction of the
/// point's largest coordinate (or of 1): far below a "lift it by a hair" of 0.001, far
/// above f32 rounding of the hit point.
pub const COINCIDENT: f64 = 1e-5;

/// A surface a sampled ray of significant weight hit.
pub struct Hit {
    pub object: Handle<Object>,
    pub point: DVec3,
    pub normal: DVec3,
    pub priority: u32,
}

/// A path through glass cut by the depth limit is worth a warning when it carries at least
/// this share of its pixel: the glass then looks visibly darker. Lighter cuts (a grazing
/// ray trapped by total internal reflection in a glass wall) are left to `whitted explain`
/// on the pixel; the scenes in scenes/ set their depth on purpose and stay quiet.
pub const DEPTH_CUT_WEIGHT: f32 = 0.25;

/// The heaviest path through glass that the depth limit cut.
pub struct DepthCut {
    pub pixel: (u32, u32),
    pub weight: f32,
    /// The transparent object the path last went through.
    pub object: Handle<Object>,
}

/// Two objects the tracer could not tell apart at a sampled hit: the one hit, the other,
/// and the point.
pub struct SamePlace {
    pub hit: Handle<Object>,
    pub other: Handle<Object>,
    pub point: DVec3,
}

/// What the grid of camera rays found.
pub struct Samples {
    pub hits: Vec<Hit>,
    /// Coincident surfaces as the tracer reported them (significant rays only).
    pub same_place: Vec<SamePlace>,
    /// Per object (by handle index): whether any sampled ray hit it or a shadow ray met it.
    pub met: Vec<bool>,
    pub depth_cut: Option<DepthCut>,
}

struct Frame {
    weight: f32,
    object: Option<Handle<Object>>,
    /// Where this ray hit `object`.
    point: DVec3,
    /// The transparent object this path last entered, if any.
    through: Option<Handle<Object>>,
}

struct GridRecorder<'s> {
    scene: &'s Scene,
    samples: Samples,
    stack: Vec<Frame>,
    pixel: (u32, u32),
    rays: u64,
}

impl Recorder for GridRecorder<'_> {
    fn should_stop(&self) -> bool {
        self.rays > RAYS_PER_PIXEL
    }

    fn ray_started(&mut self, ray: &RayStart) {
        self.rays += 1;
        let through = match ray.kind {
            RayKind::Transmitted => self.stack.last().and_then(|f| f.object),
            _ => self.stack.last().and_then(|f| f.through),
        };
        self.stack.push(Frame {
            weight: max_channel(ray.weight),
            object: None,
            point: DVec3::ZERO,
            through,
        });
    }

    fn surface_hit(&mut self, hit: &SurfaceHit) {
        self.mark(hit.object);
        let Some(frame) = self.stack.last_mut() else {
            return;
        };
        frame.object = Some(hit.object);
        frame.point = hit.point.as_dvec3();
        if frame.weight < SIGNIFICANT {
            return;
        }
        let priority = self
            .scene
            .materials
            .get(hit.material)
            .map_or(0, |m| m.priority);
        self.samples.hits.push(Hit {
            object: hit.object,
            point: hit.point.as_dvec3(),
            normal: hit.geometric_normal.as_dvec3(),
            priority,
        });
    }

    fn coincident_surface(&mut self, other: &CoincidentSurface) {
        let Some(frame) = self.stack.last() else {
            return;
        };
        let Some(hit) = frame.object.filter(|&hit| hit != other.object) else {
            return;
        };
        if frame.weight >= SIGNIFICANT {
            self.samples.same_place.push(SamePlace {
                hit,
                other: other.object,
                point: frame.point,
            });
        }
    }

    fn light_sampled(&mut self, sample: &LightSample) {
        if let Some(shadow) = &sample.shadow_ray {
            if let ShadowResult::Blocked { object, .. } = shadow.result {
                self.mark(object);
            }
        }
    }

    fn secondary_skipped(&mut self, skipped: &SkippedRay) {
        if skipped.reason != Termination::MaxDepth {
            return;
        }
        let Some(frame) = self.stack.last() else {
            return;
        };
        let through = match skipped.kind {
            RayKind::Transmitted => frame.object,
            _ => frame.through,
        };
        let weight = max_channel(skipped.weight);
        let (Some(object), true) = (through, weight >= DEPTH_CUT_WEIGHT) else {
            return;
        };
        let heavier = self
            .samples
            .depth_cut
            .as_ref()
            .is_none_or(|cut| weight > cut.weight);
        if heavier {
            self.samples.depth_cut = Some(DepthCut {
                pixel: self.pixel,
                weight,
                object,
            });
        }
    }

    fn ray_finished(&mut self, _color: whitted_tracer::Vec3A, _termination: Termination) {
        self.stack.pop();
    }
}

impl GridRecorder<'_> {
    fn mark(&mut self, object: Handle<Object>) {
        if let Some(met) = self.samples.met.get_mut(object.index()) {
            *met = true;
        }
    }
}

/// The image options the grid is traced with: the image's, one sample per pixel.
pub fn grid_options(image: &RenderOptions) -> RenderOptions {
    RenderOptions {
        samples_per_pixel: 1,
        ..image.clone()
    }
}

/// The pixels of the grid: the centres of `GRID_COLUMNS × GRID_ROWS` equal cells (every
/// pixel when the image is smaller).
fn grid(options: &RenderOptions) -> impl Iterator<Item = (u32, u32)> {
    let (width, height) = (options.width.max(1), options.height.max(1));
    let columns = GRID_COLUMNS.min(width);
    let rows = GRID_ROWS.min(height);
    (0..rows).flat_map(move |row| {
        (0..columns).map(move |column| {
            let x = (u64::from(column) * 2 + 1) * u64::from(width) / (u64::from(columns) * 2);
            let y = (u64::from(row) * 2 + 1) * u64::from(height) / (u64::from(rows) * 2);
            (x as u32, y as u32)
        })
    })
}

/// Traces the grid, over the image of `options`.
pub fn sample(prepared: &PreparedScene, scene: &Scene, options: &RenderOptions) -> Samples {
    let mut recorder = GridRecorder {
        scene,
        samples: Samples {
            hits: Vec::new(),
            same_place: Vec::new(),
            met: vec![false; scene.objects.len()],
            depth_cut: None,
        },
        stack: Vec::new(),
        pixel: (0, 0),
        rays: 0,
    };
    for (x, y) in grid(options) {
        recorder.pixel = (x, y);
        recorder.rays = 0;
        recorder.stack.clear();
        trace_pixel_with(prepared, options, x, y, 0, &mut recorder);
    }
    recorder.samples
}

/// Another object's surface passes through a sampled hit point: the two surfaces coincide
/// there, and which one a ray sees is decided by rounding (speckles, stripes). CSG
/// children are parts of one object, so their shared faces are not reported; neither are
/// surfaces of nested media (a material with a `priority`), which the tracer crosses
/// together as one interface (ARCHITECTURE.md, "Coincident surfaces").
pub(super) fn coincident_surfaces(scene: &Scene, samples: &Samples, lints: &mut Vec<Lint>) {
    // Pairs already found; a set, because thousands of spheres in one place make millions.
    let mut reported: std::collections::HashSet<(Handle<Object>, Handle<Object>)> =
        std::collections::HashSet::new();
    let prioritised = |o: Handle<Object>| scene.materials[scene.objects[o].material].priority > 0;
    // What the tracer itself saw: it finds zero-thickness surfaces (a disk on a table, a
    // poster on a wall) that have no inside to test.
    for same in &samples.same_place {
        if !(prioritised(same.hit) && prioritised(same.other)) {
            report_pair(
                scene,
                same.hit,
                same.other,
                same.point,
                &mut reported,
                lints,
            );
        }
    }
    let objects = renderables(scene);
    let bounds: Vec<Option<Bounds>> = objects.iter().map(|&o| world_bounds(scene, o)).collect();
    let hits_to_test = (MAX_SURFACE_TESTS / objects.len().max(1)).min(samples.hits.len());
    let mut shape_tests = 0usize;
    'hits: for hit in &samples.hits[..hits_to_test] {
        if hit.priority > 0 {
            continue;
        }
        let scale = hit.point.abs().max_element().max(1.0);
        let step = COINCIDENT * scale;
        let Some(normal) = hit.normal.try_normalize() else {
            continue;
        };
        let (below, above) = (hit.point - normal * step, hit.point + normal * step);
        for (&other, other_bounds) in objects.iter().zip(&bounds) {
            if other == hit.object
                || other_bounds.is_some_and(|b| !b.contains(hit.point, step))
                || prioritised(other)
            {
                continue;
            }
            shape_tests += 1;
            if shape_tests > MAX_SHAPE_TESTS {
                break 'hits;
            }
            let (Some(inside_below), Some(inside_above)) =
                (contains(scene, other, below), contains(scene, other, above))
            else {
                continue;
            };
            if inside_below != inside_above {
                report_pair(scene, hit.object, other, hit.point, &mut reported, lints);
            }
        }
    }
    // Only the first pairs became warnings; the last one says how many more there were.
    if reported.len() > MAX_PER_KIND {
        if let Some(last) = lints
            .iter_mut()
            .rev()
            .find(|l| l.kind == LintKind::CoincidentSurfaces)
        {
            last.diagnostic.hints.push(format!(
                "{} more coincident_surfaces warnings are not shown",
                reported.len() - MAX_PER_KIND
            ));
        }
    }
}

/// Warns, once per pair and up to [`MAX_PER_KIND`] pairs, that `other`'s surface lies on
/// `hit`'s at `at`.
fn report_pair(
    scene: &Scene,
    hit: Handle<Object>,
    other: Handle<Object>,
    at: DVec3,
    reported: &mut std::collections::HashSet<(Handle<Object>, Handle<Object>)>,
    lints: &mut Vec<Lint>,
) {
    let pair = (hit.min(other), hit.max(other));
    if !reported.insert(pair) || reported.len() > MAX_PER_KIND {
        return;
    }
    let (this_name, other_name) = (object_name(scene, hit), object_name(scene, other));
    let diagnostic = Diagnostic::warning(
        format!(
            "{other_name} and {this_name} share a surface at <{}, {}, {}>: which one a ray \
             sees there is decided by rounding, so it renders as speckles or stripes",
            short(at.x),
            short(at.y),
            short(at.z)
        ),
        scene.objects.span(other),
    )
    .with_label(format!(
        "{other_name}'s surface passes through {this_name}'s"
    ))
    .with_secondary(scene.objects.span(hit), format!("{this_name} is here"))
    .with_hint(format!(
        "move {other_name} off {this_name} by more than a hair (for example 0.001), so that \
         no surface of one lies on the other; or, for water in glass, give both materials a \
         `priority`"
    ));
    lints.push(Lint::new(LintKind::CoincidentSurfaces, diagnostic));
}

/// A sampled camera ray through glass is still carrying a significant weight when the
/// depth limit cuts it: the glass renders dark. The depth needed is found by tracing that
/// pixel again with larger limits (the explain probe, bounded by its ray budget).
pub(super) fn max_depth_too_low(
    prepared: &PreparedScene,
    scene: &Scene,
    samples: &Samples,
    options: &RenderOptions,
    lints: &mut Vec<Lint>,
) {
    let Some(cut) = &samples.depth_cut else {
        return;
    };
    // `max_depth 0` asks for no reflected or transmitted rays at all: local shading only,
    // on purpose (the MIT 6.837 course's default without `-bounces`).
    if options.max_depth == 0 {
        return;
    }
    let (x, y) = cut.pixel;
    let name = object_name(scene, cut.object);
    let current = options.max_depth;
    let needed = match depth_needed(prepared, options, x, y, SIGNIFICANT) {
        DepthSearch::Found { max_depth, .. } => format!(
            "raise max_depth to {max_depth} (`max_depth {max_depth}` in the settings, or \
             --set max_depth={max_depth}): the light then gets out of {name}"
        ),
        DepthSearch::NotFound { tried } => format!(
            "even max_depth {tried} does not get the light out of {name}: raise max_depth \
             and look at the pixel with `whitted explain --pixel {x},{y}`"
        ),
        DepthSearch::TooManyRays { max_depth } => format!(
            "raise max_depth (to at least {max_depth}); the search stopped there at its ray \
             budget"
        ),
    };
    let mut diagnostic = Diagnostic::warning(
        format!(
            "max_depth {current} is too low for {name}: at pixel ({x}, {y}) the depth \
             limit cuts a ray through it that carries {:.0}% of the pixel, so it renders too \
             dark",
            f64::from(cut.weight) * 100.0
        ),
        scene.objects.span(cut.object),
    )
    .with_label(format!(
        "light is still inside {name} when max_depth {current} stops it"
    ))
    .with_hint(needed);
    if let Some(span) = setting_span(scene, "max_depth") {
        diagnostic = diagnostic.with_secondary(span, format!("max_depth is {current} here"));
    }
    lints.push(Lint::new(LintKind::MaxDepthTooLow, diagnostic));
}
