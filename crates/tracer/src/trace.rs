//! Whitted's recursion: the one code path that computes the colour of every ray, generic
//! over a [`Recorder`] so that rendering, ray trees and statistics all run this code.
//!
//! `I = ka·Ia·kd + Σ visible lights fatt·spot·Ii·(kd·(N·L) + ks·(R·V)^n) + kr·I_r + kt·I_t`,
//! with Beer-Lambert absorption on rays travelling inside an absorbing solid.
//!
//! Media (`media.rs`): every ray carries the stack of solids it is inside. The ior pair at a
//! solid's surface is (the medium before, the medium beyond): (1.0, 1.5) from air into
//! glass, (1.5, 1.33) from glass into water. A surface that leaves the current medium
//! unchanged (a lower-priority solid inside a higher-priority one) is a false hit: the ray
//! goes on through it. In scenes with priorities, surfaces within the offset distance of
//! each other (water touching glass) are crossed together, as one interface. A reflected
//! ray stays in its parent's media; Beer-Lambert absorption follows the current medium.

use glam::Vec3A;
use whitted_ir::{Fresnel, Handle, Highlight, Material, Object, ShadowMode};

use crate::material::{Blend, PreparedMaterial};
use crate::media::{same_medium, Medium, MediumStack};
use crate::optics::{beer_lambert, fresnel_exact, max_channel, reflect, refract, schlick};
use crate::query::{Crossed, Hit, Resolved, Scratch, Shadow, Surface};
use crate::recorder::{
    CoincidentSurface, Interface, LightSample, NoShadowRay, RayKind, RayStart, Recorder, ShadowRay,
    ShadowResult, SkippedRay, SurfaceHit, Termination,
};
use crate::scene::PreparedScene;
use whitted_bvh::Ray;
use whitted_bvh::PACKET;

/// Surfaces within this many error bounds of a hit along the ray are reported as
/// coincident with it (the bound is a bound: rounding rarely reaches it, a z-fight's two
/// surfaces are both within it).
const COINCIDENT_BOUNDS: f32 = 4.0;

/// The rounding of a hit's `t` in ulps of the distances it came from: two surfaces in one
/// plane get distances this far apart from their own tests.
const COINCIDENT_T_ULPS: f32 = 64.0;

/// Ray counts kept by the tracer itself (cheap, always on).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounters {
    pub camera: u64,
    pub shadow: u64,
    pub reflected: u64,
    pub transmitted: u64,
    pub deepest: u32,
    /// Camera rays whose first hit was found in a packet.
    pub camera_in_packets: u64,
    /// Samples that reached the ray budget ([`whitted_ir::limits::MAX_RAYS_PER_SAMPLE`]).
    pub samples_cut: u64,
    /// Pixels with at least one such sample (counted by the renderer, per pixel).
    pub pixels_cut: u64,
    /// The first such pixel in row-major order, `[x, y]`.
    pub first_pixel_cut: Option<[u32; 2]>,
}

impl RayCounters {
    pub fn add(&mut self, other: &RayCounters) {
        self.camera += other.camera;
        self.shadow += other.shadow;
        self.reflected += other.reflected;
        self.transmitted += other.transmitted;
        self.deepest = self.deepest.max(other.deepest);
        self.camera_in_packets += other.camera_in_packets;
        self.samples_cut += other.samples_cut;
        self.pixels_cut += other.pixels_cut;
        self.first_pixel_cut = match (self.first_pixel_cut, other.first_pixel_cut) {
            (Some(a), Some(b)) => Some(if (a[1], a[0]) <= (b[1], b[0]) { a } else { b }),
            (a, b) => a.or(b),
        };
    }

    /// Records that pixel `(x, y)` had a sample cut at the ray budget.
    pub fn pixel_cut(&mut self, x: u32, y: u32) {
        self.add(&RayCounters {
            pixels_cut: 1,
            first_pixel_cut: Some([x, y]),
            ..RayCounters::default()
        });
    }
}

/// What a ray carries down the recursion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathState {
    pub kind: RayKind,
    pub depth: u32,
    /// The path weight including this ray's own coefficient.
    pub weight: Vec3A,
    pub coefficient: Vec3A,
    /// Absorption per unit distance of the medium the ray travels in (0 in air).
    pub medium: Vec3A,
    /// The solids the ray is inside (`medium` is the current one's absorption).
    pub media: MediumStack,
    pub interface: Option<Interface>,
}

impl PathState {
    pub fn camera() -> PathState {
        PathState {
            kind: RayKind::Camera,
            depth: 0,
            weight: Vec3A::ONE,
            coefficient: Vec3A::ONE,
            medium: Vec3A::ZERO,
            media: MediumStack::EMPTY,
            interface: None,
        }
    }
}

/// What the recursion carries from ray to ray: all that a ray's colour depends on.
/// The media stack is borrowed, not copied: most rays share their parent's.
#[derive(Clone, Copy, Debug)]
struct Path<'m> {
    kind: RayKind,
    depth: u32,
    weight: Vec3A,
    medium: Vec3A,
    media: &'m MediumStack,
}

/// How crossing a surface changes a ray's media. Stacks are only built for the rays that
/// need them (a transmitted ray, a ray that passes a false hit).
#[derive(Clone, Copy, Debug)]
enum Change {
    /// A thin surface: the same media on both sides.
    Thin,
    Enter(Medium),
    /// Leaving a solid the ray knows it is inside.
    Leave(Medium),
    /// Leaving a solid the ray did not know it was inside (it started inside): it was the
    /// outermost.
    LeaveUnknown(Medium),
    /// Several coincident surfaces (nested media): the stacks are in
    /// [`Tracer::coincident`].
    Coincident,
}

/// The surface a ray really meets (after false hits), with the media on either side.
struct Meeting<'s> {
    hit: Hit,
    surface: Surface<'s>,
    front_face: bool,
    /// Whether the surface is a solid's (thin surfaces have no media of their own).
    solid: bool,
    material: Handle<Material>,
    /// The course's blend of two materials at the point, when its patterns make one
    /// (`material` is then the dominant one, which the media use).
    blend: Option<Blend>,
    change: Change,
    /// The current medium before the surface (where a reflected ray travels) and beyond it.
    outer: Option<Medium>,
    inner: Option<Medium>,
    /// Where to look on when the meeting is a false hit.
    resume: f32,
}

/// One surface crossing near a hit, for coincident-surface handling.
#[derive(Clone, Copy)]
struct NearCrossing {
    hit: Hit,
    entering: bool,
    medium: Medium,
}

/// One worker's tracing context: the scene, the limits, CSG scratch space and counters.
pub struct Tracer<'a> {
    scene: &'a PreparedScene,
    max_depth: u32,
    min_weight: f32,
    scratch: Scratch,
    pub counters: RayCounters,
    /// 1, except in tests that prove the acne checks can fail by removing the offset.
    offset_scale: f32,
    /// Whether lights skip their shadow ray at surfaces with no diffuse and no specular
    /// colour (nothing the ray could find would change the colour); false only in tests
    /// that prove the skip changes no pixel.
    skip_unshaded_shadows: bool,
    /// The media before and beyond the last coincident meeting (nested media only), read
    /// right after [`Tracer::meet`] returns.
    coincident: (MediumStack, MediumStack),
    /// The most reflected, transmitted and shadow rays one sample may cast
    /// ([`whitted_ir::limits::MAX_RAYS_PER_SAMPLE`]), the count cast so far in the current
    /// sample, and whether it has reached the budget.
    ray_budget: u32,
    sample_rays: u32,
    sample_cut: bool,
}

impl<'a> Tracer<'a> {
    pub fn new(scene: &'a PreparedScene, max_depth: u32, min_weight: f32) -> Tracer<'a> {
        Tracer {
            scene,
            max_depth,
            min_weight,
            scratch: Scratch::default(),
            counters: RayCounters::default(),
            offset_scale: 1.0,
            skip_unshaded_shadows: true,
            coincident: (MediumStack::EMPTY, MediumStack::EMPTY),
            ray_budget: whitted_ir::limits::MAX_RAYS_PER_SAMPLE,
            sample_rays: 0,
            sample_cut: false,
        }
    }

    /// A smaller ray budget per sample than the limit: only for tests of the cut.
    #[cfg(test)]
    pub fn with_ray_budget(mut self, budget: u32) -> Self {
        self.ray_budget = budget;
        self
    }

    /// Casts shadow rays even where the material cannot use them: only for tests showing
    /// that skipping them changes no pixel.
    #[cfg(test)]
    pub fn casting_every_shadow_ray(mut self) -> Self {
        self.skip_unshaded_shadows = false;
        self
    }

    /// Starts secondary rays `scale` times the usual offset off the surface (negative:
    /// below it): only for tests showing that their checks catch a wrong offset where
    /// shapes put the hit point exactly on their surface and no offset at all still works.
    #[cfg(test)]
    pub fn with_surface_offset_scale(mut self, scale: f32) -> Self {
        self.offset_scale = scale;
        self
    }

    /// Traces one ray and returns the colour it brings back to its origin.
    pub fn trace<R: Recorder>(&mut self, ray: &Ray, path: &PathState, rec: &mut R) -> Vec3A {
        self.trace_first(ray, path, rec, FirstHit::Find)
    }

    /// The closest hits of camera rays walked together through the BVH, each what
    /// [`Tracer::trace`] would find first for its ray (see `intersect_packet`); false, with
    /// `hits` untouched, when these rays cannot walk together.
    pub(crate) fn camera_hits(&mut self, rays: &[Ray], hits: &mut [Option<Hit>; PACKET]) -> bool {
        self.scene
            .intersect_packet(rays, 0.0, &mut self.scratch, hits)
    }

    /// [`Tracer::trace`] of a camera ray that meets `object`'s surface first where the
    /// tracer cannot tell it from the surface it does meet first (z-fighting: the other
    /// side of the fight). `None` when the ray misses, or no surface of `object` is within
    /// the first hit's error bound along it.
    pub(crate) fn trace_preferring<R: Recorder>(
        &mut self,
        ray: &Ray,
        object: Handle<Object>,
        rec: &mut R,
    ) -> Option<Vec3A> {
        let scene = self.scene;
        let first = scene.intersect(ray, 0.0, f32::INFINITY, &mut self.scratch)?;
        let surface = scene.surface(ray, &first);
        let window = coincident_window(ray, first.t, &surface);
        let mut preferred = None;
        let range = ((first.t - window).max(0.0), first.t + window);
        let normal = surface.geometric_normal;
        scene.crossings_between(ray, range, Crossed::Any, &mut self.scratch, |other| {
            if scene.item(other.item).object() == object
                && parallel(scene.surface(ray, &other).geometric_normal, normal)
            {
                preferred = Some(other);
                return false;
            }
            true
        });
        let preferred = preferred?;
        Some(self.trace_first(
            ray,
            &PathState::camera(),
            rec,
            FirstHit::Known(Some(preferred)),
        ))
    }

    /// [`Tracer::trace`] of a ray whose first hit is already known (from
    /// [`Tracer::camera_hits`]): the same trace, bit for bit, without finding it again.
    pub(crate) fn trace_from_hit<R: Recorder>(
        &mut self,
        ray: &Ray,
        path: &PathState,
        rec: &mut R,
        hit: Option<Hit>,
    ) -> Vec3A {
        self.counters.camera_in_packets += 1;
        self.trace_first(ray, path, rec, FirstHit::Known(hit))
    }

    #[inline(always)]
    fn trace_first<R: Recorder>(
        &mut self,
        ray: &Ray,
        path: &PathState,
        rec: &mut R,
        first: FirstHit,
    ) -> Vec3A {
        rec.ray_started(&RayStart {
            kind: path.kind,
            depth: path.depth,
            origin: ray.origin,
            direction: ray.direction,
            weight: path.weight,
            coefficient: path.coefficient,
            interface: path.interface,
        });
        let path = Path {
            kind: path.kind,
            depth: path.depth,
            weight: path.weight,
            medium: path.medium,
            media: &path.media,
        };
        // A new sample: its ray budget starts afresh.
        self.sample_rays = 0;
        self.sample_cut = false;
        self.count(&path);
        self.trace_started(ray, &path, rec, first)
    }

    /// Counts a ray about to be traced (its caller has reported it to the recorder).
    #[inline(always)]
    fn count(&mut self, path: &Path<'_>) {
        match path.kind {
            RayKind::Camera => self.counters.camera += 1,
            RayKind::Reflected => {
                self.counters.reflected += 1;
                self.sample_rays += 1;
            }
            RayKind::Transmitted => {
                self.counters.transmitted += 1;
                self.sample_rays += 1;
            }
            // Shadow rays are queries, not traced paths; they are counted where they are cast.
            RayKind::Shadow => {}
        }
        self.counters.deepest = self.counters.deepest.max(path.depth);
    }

    /// The body of [`Tracer::trace`], once the recorder has heard of the ray: the recursion
    /// passes only what the colour depends on, and each caller reports the rest.
    fn trace_started<R: Recorder>(
        &mut self,
        ray: &Ray,
        path: &Path<'_>,
        rec: &mut R,
        first: FirstHit,
    ) -> Vec3A {
        let scene = self.scene;
        // Most rays travel in air; then nothing is absorbed and multiplying by the
        // transmittance (exactly 1) can be skipped without changing a bit.
        let in_air = path.medium == Vec3A::ZERO;

        // False hits (surfaces that do not change the medium) are passed through: the same
        // ray looks on beyond them, so `t` stays measured from its origin and the medium,
        // unchanged by a false hit, absorbs along the whole distance.
        let found = match first {
            FirstHit::Find => scene.intersect(ray, 0.0, f32::INFINITY, &mut self.scratch),
            FirstHit::Known(hit) => hit,
        };
        let Some(hit) = found else {
            return self.missed(path, rec);
        };
        let mut meeting = self.meet(ray, 0.0, hit, path.media);
        let mut passed: Option<MediumStack> = None;
        if is_false_hit(meeting.solid, meeting.outer, meeting.inner) {
            match self.beyond_false_hits(ray, path.media, &mut meeting) {
                Some(media) => passed = Some(media),
                None => return self.missed(path, rec),
            }
        }
        let media = passed.as_ref().unwrap_or(path.media);
        let Meeting {
            hit,
            surface,
            front_face,
            solid,
            material: material_handle,
            blend,
            change,
            outer,
            inner,
            ..
        } = meeting;
        // The media a reflected ray travels in: the incoming ray's, unless it turned out to
        // be inside the solid it leaves (or the surfaces were coincident).
        let before_store;
        let before: &MediumStack = match change {
            Change::LeaveUnknown(medium) => {
                let mut stack = *media;
                stack.insert_outermost(medium);
                before_store = stack;
                &before_store
            }
            Change::Coincident => {
                before_store = self.coincident.0;
                &before_store
            }
            _ => media,
        };
        // Saved now: the reflected ray's own meetings overwrite `self.coincident`.
        let coincident_after = matches!(change, Change::Coincident).then(|| self.coincident.1);
        let absorption = if in_air {
            Vec3A::ONE
        } else {
            beer_lambert(path.medium, hit.t)
        };

        let d = ray.direction;
        // Shading (and the secondary rays) use the shading normal; which side the ray is on
        // was decided by the geometric one.
        // `flip_normals off` keeps the outward normal on a back face: the student bug.
        let n = if front_face || !scene.settings.flip_normals {
            surface.shading_normal
        } else {
            -surface.shading_normal
        };
        let point = surface.point;
        let blended;
        let m = match &blend {
            None => &scene.materials[material_handle.index()],
            Some(b) => {
                blended = PreparedMaterial::blend(
                    &scene.materials[b.first.index()],
                    &scene.materials[b.second.index()],
                    b,
                );
                &blended
            }
        };
        let offset = scene.offset_at(&surface) * self.offset_scale;
        rec.surface_hit(&SurfaceHit {
            t: hit.t,
            point,
            geometric_normal: surface.geometric_normal,
            shading_normal: n,
            front_face,
            object: surface.item.object(),
            leaf: surface.leaf.object,
            material: surface.leaf.material,
            resolved_material: material_handle,
            blend,
            absorption,
            error_bound: crate::hit_error::error_along(surface.geometric_normal, surface.error),
            offset,
        });
        if R::RECORDS {
            self.report_coincident(ray, &hit, &surface, rec);
        }

        let outside = point + offset * n;
        let mut color = self.local_illumination(m, outside, n, -d, front_face, rec);

        // Secondary rays.
        let ior = (self.ior(outer), self.ior(inner));
        // `exit_ior uninverted`: a ray leaving a solid refracts as if entering it.
        let ior = if front_face || scene.settings.exit_ior_inverted {
            ior
        } else {
            (ior.1, ior.0)
        };
        let split = split_at(
            m,
            d,
            n,
            ior,
            solid && front_face,
            self.scene.settings.energy_clamp,
        );
        let mut outcome = Outcome::default();
        let carried = if in_air {
            path.weight
        } else {
            path.weight * absorption
        };
        let depth = path.depth + 1;
        if split.reflect != Vec3A::ZERO {
            let child = Path {
                kind: RayKind::Reflected,
                depth,
                weight: carried * split.reflect,
                medium: self.absorption(outer),
                media: before,
            };
            // Unit already: a reflection preserves length (to a few ulps).
            let reflected = Ray::new(outside, reflect(d, n));
            if let Some(c) = self.spawn(&reflected, &child, &split, &mut outcome, rec) {
                color += split.reflect * c;
            }
        }
        if split.interface.total_internal_reflection {
            let reason = Termination::TotalInternalReflection;
            // What the impossible transmission loses: all of `kt` without Fresnel (dropped),
            // nothing with Fresnel (R = 1 gave it to the reflected ray).
            let lost = match m.fresnel {
                Fresnel::Off => m.transmissive,
                Fresnel::Schlick | Fresnel::Exact => Vec3A::ZERO,
            };
            rec.secondary_skipped(&SkippedRay {
                kind: RayKind::Transmitted,
                depth,
                weight: carried * lost,
                coefficient: lost,
                reason,
            });
            outcome.skipped(reason);
            // `total_internal_reflection off`: the student traced the impossible ray anyway;
            // its direction is the square root of a negative number, so it meets nothing
            // and brings back the background, weighted by `kt`.
            if !scene.settings.total_internal_reflection {
                color += m.transmissive * scene.background;
            }
        }
        if let Some(direction) = split.refracted.filter(|_| split.transmit != Vec3A::ZERO) {
            let beyond = match coincident_after {
                Some(after) => after,
                None => self.media_beyond(media, change),
            };
            let child = Path {
                kind: RayKind::Transmitted,
                depth,
                weight: carried * split.transmit,
                medium: self.absorption(inner),
                media: &beyond,
            };
            let transmitted = Ray::new(point - offset * n, direction);
            if let Some(c) = self.spawn(&transmitted, &child, &split, &mut outcome, rec) {
                color += split.transmit * c;
            }
        }

        if !in_air {
            color *= absorption;
        }
        let termination = if outcome.traced_any {
            Termination::NotEnded
        } else {
            outcome.first_skip.unwrap_or(Termination::Absorbed)
        };
        rec.ray_finished(color, termination);
        color
    }

    /// The refractive index of a medium (air is 1).
    #[inline(always)]
    fn ior(&self, medium: Option<Medium>) -> f32 {
        medium.map_or(1.0, |m| self.scene.materials[m.material as usize].ior)
    }

    /// The absorption per unit distance of a medium (air absorbs nothing).
    #[inline(always)]
    fn absorption(&self, medium: Option<Medium>) -> Vec3A {
        medium.map_or(Vec3A::ZERO, |m| {
            self.scene.materials[m.material as usize].absorption
        })
    }

    /// Passes false hits (surfaces that do not change the medium): the same ray looks on
    /// beyond them, so `t` stays measured from its origin and the medium, unchanged by a
    /// false hit, absorbs along the whole distance. Leaves the surface really met in
    /// `meeting` and returns the ray's media there, or `None` when the ray leaves the scene.
    #[cold]
    #[inline(never)]
    fn beyond_false_hits(
        &mut self,
        ray: &Ray,
        media: &MediumStack,
        meeting: &mut Meeting<'a>,
    ) -> Option<MediumStack> {
        let scene = self.scene;
        let mut media = self.media_beyond(media, meeting.change);
        loop {
            let tmin = meeting.resume;
            let hit = scene.intersect(ray, tmin, f32::INFINITY, &mut self.scratch)?;
            *meeting = self.meet(ray, tmin, hit, &media);
            if !is_false_hit(meeting.solid, meeting.outer, meeting.inner) {
                return Some(media);
            }
            media = self.media_beyond(&media, meeting.change);
        }
    }

    /// A ray that left the scene: the background, through the medium it travels in.
    #[inline(always)]
    fn missed<R: Recorder>(&self, path: &Path<'_>, rec: &mut R) -> Vec3A {
        let scene = self.scene;
        let color = if path.medium == Vec3A::ZERO {
            scene.background
        } else {
            scene.background * beer_lambert(path.medium, f32::INFINITY)
        };
        rec.ray_missed(scene.background);
        rec.ray_finished(color, Termination::Miss);
        color
    }

    /// The media beyond a surface, for a ray in `media` crossing it.
    #[inline(always)]
    fn media_beyond(&self, media: &MediumStack, change: Change) -> MediumStack {
        let mut stack = *media;
        match change {
            Change::Thin | Change::LeaveUnknown(_) => {}
            Change::Enter(medium) => stack.enter(medium),
            Change::Leave(medium) => {
                stack.leave(medium.object);
            }
            Change::Coincident => stack = self.coincident.1,
        }
        stack
    }

    /// The surface `hit` and the current media on either side of it, for a ray in `media`,
    /// worked out without copying the stack. Thin surfaces have the same medium on both
    /// sides. In scenes with priorities every solid surface within the offset distance of
    /// the hit is crossed with it (coincident surfaces are one interface); otherwise the
    /// hit is crossed alone.
    #[inline(always)]
    fn meet(&mut self, ray: &Ray, tmin: f32, hit: Hit, media: &MediumStack) -> Meeting<'a> {
        let scene = self.scene;
        let surface = scene.surface(ray, &hit);
        let front_face = surface.geometric_normal.dot(ray.direction) < 0.0;
        let Resolved { material, blend } =
            scene.resolve_material(surface.leaf, surface.point, hit.part);
        let current = media.current();
        let solid = surface.leaf.geometry.is_solid();
        let mut meeting = Meeting {
            hit,
            surface,
            front_face,
            solid,
            material,
            blend,
            change: Change::Thin,
            outer: current,
            inner: current,
            resume: hit.t,
        };
        if !solid {
            return meeting;
        }
        if scene.nested_media {
            return self.meet_coincident(ray, tmin, meeting, media);
        }
        let medium = Medium {
            object: surface.item.object().index() as u32,
            material: material.index() as u32,
            rank: scene.materials[material.index()].rank,
        };
        // As `MediumStack::current` would find after `enter`, `leave` or
        // `insert_outermost`: the highest rank wins, the latest among equals.
        if front_face {
            meeting.change = Change::Enter(medium);
            if current.is_none_or(|c| medium.rank >= c.rank) {
                meeting.inner = Some(medium);
            }
        } else if media.contains(medium.object) {
            meeting.change = Change::Leave(medium);
            meeting.inner = media.current_without(medium.object);
        } else {
            meeting.change = Change::LeaveUnknown(medium);
            if current.is_none_or(|c| medium.rank > c.rank) {
                meeting.outer = Some(medium);
            }
        }
        meeting
    }

    /// [`Tracer::meet`] for scenes with priorities: every solid surface within the offset
    /// distance of the hit is crossed at once (a glass wall and the water touching it), and
    /// the interface is the surface of the medium that wins: the higher rank of the medium
    /// left and the medium entered.
    #[cold]
    #[inline(never)]
    fn meet_coincident(
        &mut self,
        ray: &Ray,
        tmin: f32,
        first: Meeting<'a>,
        media: &MediumStack,
    ) -> Meeting<'a> {
        const MOST: usize = MediumStack::CAPACITY;
        let scene = self.scene;
        // Surfaces closer together than the hit point's error bound cannot be told apart: two
        // shapes in one plane (water touching glass) get distances that far apart from their
        // own tests, along the ray the bound over the cosine or the rounding of `t` itself.
        let window = coincident_window(ray, first.hit.t, &first.surface)
            .max(scene.offset_at(&first.surface));
        let resume = first.hit.t + window;
        let empty = NearCrossing {
            hit: first.hit,
            entering: false,
            medium: Medium {
                object: u32::MAX,
                material: 0,
                rank: 0,
            },
        };
        let mut near = [empty; MOST];
        let mut count = 0usize;
        let crossing = |hit: Hit| {
            let surface = scene.surface(ray, &hit);
            let material = scene
                .resolve_material(surface.leaf, surface.point, hit.part)
                .material;
            NearCrossing {
                hit,
                entering: surface.geometric_normal.dot(ray.direction) < 0.0,
                medium: Medium {
                    object: surface.item.object().index() as u32,
                    material: material.index() as u32,
                    rank: scene.materials[material.index()].rank,
                },
            }
        };
        let range = ((first.hit.t - window).max(tmin), first.hit.t + window);
        scene.crossings_between(ray, range, Crossed::Solids, &mut self.scratch, |hit| {
            near[count] = crossing(hit);
            count += 1;
            count < MOST
        });
        let first_found = near[..count]
            .iter()
            .any(|c| c.hit.item == first.hit.item && c.hit.leaf == first.hit.leaf);
        if !first_found && count < MOST {
            near[count] = crossing(first.hit);
            count += 1;
        }
        let near = &mut near[..count];
        // Along the ray; at equal distances leave before entering.
        near.sort_unstable_by(|a, b| {
            a.hit
                .t
                .total_cmp(&b.hit.t)
                .then(a.entering.cmp(&b.entering))
        });
        let mut before = *media;
        for c in near.iter().filter(|c| !c.entering) {
            if !before.contains(c.medium.object) {
                before.insert_outermost(c.medium);
            }
        }
        let mut after = before;
        for c in near.iter() {
            if c.entering {
                after.enter(c.medium);
            } else {
                after.leave(c.medium.object);
            }
        }
        let (outer, inner) = (before.current(), after.current());
        let left = outer.and_then(|o| {
            near.iter()
                .find(|c| !c.entering && c.medium.object == o.object)
        });
        let entered = inner.and_then(|i| {
            near.iter()
                .find(|c| c.entering && c.medium.object == i.object)
        });
        let chosen = match (left, entered) {
            (Some(l), Some(e)) if l.medium.rank > e.medium.rank => Some(l),
            (_, Some(e)) => Some(e),
            (l, None) => l,
        };
        let mut meeting = match chosen {
            Some(c) => {
                let surface = scene.surface(ray, &c.hit);
                let blend = scene
                    .resolve_material(surface.leaf, surface.point, c.hit.part)
                    .blend;
                Meeting {
                    hit: c.hit,
                    surface,
                    front_face: c.entering,
                    material: Handle::from_index(c.medium.material as usize),
                    blend,
                    ..first
                }
            }
            None => first,
        };
        self.coincident = (before, after);
        meeting.change = Change::Coincident;
        meeting.outer = outer;
        meeting.inner = inner;
        meeting.resume = resume;
        meeting
    }

    /// `ka·Ia·kd`, plus the surface's own emission, plus, for every light on the visible
    /// side, `fatt·spot·Ii·(kd·(N·L) + ks·(R·V)^n)` (or `ks·(N·H)^n` with `highlight blinn`)
    /// times what the shadow ray lets through. `outside` is the hit point already moved off
    /// the surface along `n`, which faces the viewer. With `shade_back off`, a surface seen
    /// from its back (`front_face` false) gets no light at all; with `shadows none`, no
    /// shadow ray is cast and every light facing the surface counts as unblocked. The order
    /// of the additions is part of the recorder contract (see `recorder.rs`): keep it.
    fn local_illumination<R: Recorder>(
        &mut self,
        m: &PreparedMaterial,
        outside: Vec3A,
        n: Vec3A,
        view: Vec3A,
        front_face: bool,
        rec: &mut R,
    ) -> Vec3A {
        let scene = self.scene;
        let back_face = !front_face && !scene.settings.shade_back;
        // `back_ambient off` (MIT 6.837's handout): a back face's own colour is black. A
        // self-lit surface's emission counts whatever the lights and shadows.
        let (ambient, emission) = if back_face && !scene.settings.back_ambient {
            (Vec3A::ZERO, Vec3A::ZERO)
        } else {
            (m.ambient * scene.ambient * m.diffuse, m.emission)
        };
        rec.ambient(ambient);
        rec.emission(emission);
        let mut color = ambient + emission;
        // With no diffuse and no specular colour a light adds nothing whatever its shadow
        // ray finds, so the ray is not cast (14% of a mirror scene's shadow rays).
        let unshaded = m.diffuse == Vec3A::ZERO && m.specular == Vec3A::ZERO;
        // `highlight_gate off` (the course's Phong): a light behind the surface still adds
        // its highlight, so it is not skipped when the material has one.
        let gated = scene.settings.highlight_gate || m.specular == Vec3A::ZERO;
        for (light_index, light) in scene.lights.iter().enumerate() {
            let incidence = light.incidence(outside);
            let n_dot_l = n.dot(incidence.to_light);
            let strength = incidence.attenuation * incidence.spot;
            let mut sample = LightSample {
                light: light.handle,
                to_light: incidence.to_light,
                distance: incidence.distance,
                n_dot_l,
                attenuation: incidence.attenuation,
                spot: incidence.spot,
                cos_axis: incidence.cos_axis,
                shadow_ray: None,
                no_shadow_ray: None,
                diffuse: Vec3A::ZERO,
                specular: Vec3A::ZERO,
            };
            if back_face {
                sample.no_shadow_ray = Some(NoShadowRay::BackFace);
                rec.light_sampled(&sample);
                continue;
            }
            if (n_dot_l <= 0.0 && gated) || strength <= 0.0 || light.intensity == Vec3A::ZERO {
                sample.no_shadow_ray = Some(unlit(n_dot_l, incidence.spot, light.intensity));
                rec.light_sampled(&sample);
                continue;
            }
            if unshaded && self.skip_unshaded_shadows {
                sample.no_shadow_ray = Some(NoShadowRay::Unshaded);
                rec.light_sampled(&sample);
                continue;
            }
            let (passed, shadow_ray) = if scene.shadows == ShadowMode::None {
                sample.no_shadow_ray = Some(NoShadowRay::ShadowsOff);
                (Vec3A::ONE, None)
            } else {
                self.cast_shadow::<R>(light_index, outside, incidence.to_light, incidence.distance)
            };
            sample.shadow_ray = shadow_ray;
            if passed != Vec3A::ZERO {
                let light_in = light.intensity * strength * passed;
                sample.diffuse = light_in * m.diffuse * n_dot_l.max(0.0);
                if m.specular != Vec3A::ZERO {
                    let cosine = match scene.settings.highlight {
                        Highlight::Phong => reflect(-incidence.to_light, n).dot(view),
                        Highlight::Blinn => n.dot((incidence.to_light + view).normalize_or_zero()),
                    };
                    sample.specular = light_in * m.specular * m.phong(cosine);
                }
                color += sample.diffuse + sample.specular;
            }
            rec.light_sampled(&sample);
        }
        color
    }

    /// Casts a shadow ray; returns what fraction of the light passes, and the record when
    /// the recorder wants one (finding the blocker's object is work for the recorder only).
    fn cast_shadow<R: Recorder>(
        &mut self,
        light: usize,
        origin: Vec3A,
        to_light: Vec3A,
        distance: f32,
    ) -> (Vec3A, Option<ShadowRay>) {
        let scene = self.scene;
        let ray = Ray::new(origin, to_light);
        self.counters.shadow += 1;
        self.sample_rays += 1;
        let shadow = match scene.shadows {
            ShadowMode::Opaque => {
                match scene.occluded_towards(
                    light,
                    R::RECORDS,
                    &ray,
                    0.0,
                    distance,
                    &mut self.scratch,
                ) {
                    Some(blocker) => Shadow::Blocked(blocker),
                    None => Shadow::Clear,
                }
            }
            ShadowMode::Filtered => scene.filter_shadow(&ray, 0.0, distance, &mut self.scratch),
            // `local_illumination` casts no shadow ray with `shadows none`.
            ShadowMode::None => Shadow::Clear,
        };
        let passed = match shadow {
            Shadow::Clear => Vec3A::ONE,
            Shadow::Blocked(_) => Vec3A::ZERO,
            Shadow::Filtered { transmittance, .. } => transmittance,
        };
        let record = R::RECORDS.then(|| ShadowRay {
            origin,
            direction: to_light,
            max_t: distance,
            result: shadow_result(scene, shadow),
        });
        (passed, record)
    }

    /// Tells the recorder of every other surface the ray crosses within the hit's error
    /// bound (z-fighting: which of them a ray meets is rounding). The window along the ray
    /// is the error bound over the cosine of incidence, or the rounding of `t` itself if
    /// larger. Only recorders pay for it; rendering never calls it.
    #[cold]
    #[inline(never)]
    fn report_coincident<R: Recorder>(
        &mut self,
        ray: &Ray,
        hit: &Hit,
        surface: &Surface<'_>,
        rec: &mut R,
    ) {
        let scene = self.scene;
        let window = coincident_window(ray, hit.t, surface);
        let mut near = [None; 4];
        let mut count = 0;
        let range = ((hit.t - window).max(0.0), hit.t + window);
        scene.crossings_between(ray, range, Crossed::Any, &mut self.scratch, |other| {
            if other.item == hit.item && other.leaf == hit.leaf {
                return true;
            }
            near[count] = Some(other);
            count += 1;
            count < near.len()
        });
        for other in near.iter().flatten() {
            let found = scene.surface(ray, other);
            // Two surfaces that meet at an edge (a wall on a floor) are both crossed there
            // at the same distance, but they are not in the same place: only a surface
            // parallel to the hit's is.
            if !parallel(found.geometric_normal, surface.geometric_normal) {
                continue;
            }
            rec.coincident_surface(&CoincidentSurface {
                t: other.t,
                object: found.item.object(),
                leaf: found.leaf.object,
                material: scene
                    .resolve_material(found.leaf, found.point, other.part)
                    .material,
            });
        }
    }

    /// Traces a secondary ray unless a stopping criterion forbids it (then records why).
    /// `split` gives the ray's coefficient and the interface it leaves, for the recorder.
    #[inline(always)]
    fn spawn<R: Recorder>(
        &mut self,
        ray: &Ray,
        child: &Path<'_>,
        split: &Split,
        outcome: &mut Outcome,
        rec: &mut R,
    ) -> Option<Vec3A> {
        if rec.should_stop() {
            return None;
        }
        let coefficient = match child.kind {
            RayKind::Transmitted => split.transmit,
            _ => split.reflect,
        };
        match self.secondary_verdict(child) {
            None => {
                outcome.traced_any = true;
                rec.ray_started(&RayStart {
                    kind: child.kind,
                    depth: child.depth,
                    origin: ray.origin,
                    direction: ray.direction,
                    weight: child.weight,
                    coefficient,
                    interface: Some(split.interface),
                });
                self.count(child);
                Some(self.trace_started(ray, child, rec, FirstHit::Find))
            }
            Some(reason) => {
                if reason == Termination::RayBudget && !self.sample_cut {
                    self.sample_cut = true;
                    self.counters.samples_cut += 1;
                }
                rec.secondary_skipped(&SkippedRay {
                    kind: child.kind,
                    depth: child.depth,
                    weight: child.weight,
                    coefficient,
                    reason,
                });
                outcome.skipped(reason);
                None
            }
        }
    }

    /// `None` when the secondary ray may be traced; otherwise why not.
    #[inline]
    fn secondary_verdict(&self, child: &Path<'_>) -> Option<Termination> {
        if child.depth > self.max_depth {
            Some(Termination::MaxDepth)
        } else if max_channel(child.weight) < self.min_weight {
            Some(Termination::WeightCutoff)
        } else if self.sample_rays >= self.ray_budget {
            Some(Termination::RayBudget)
        } else {
            None
        }
    }
}

/// How far along `ray` another surface may be from the hit at `t` and still be in the same
/// place as far as f32 can tell: the hit point's error bound over the cosine of incidence,
/// or the rounding of `t` itself (two surfaces in one plane get distances this far apart
/// from their own tests), whichever is larger.
#[inline]
fn coincident_window(ray: &Ray, t: f32, surface: &Surface<'_>) -> f32 {
    let bound = crate::hit_error::error_along(surface.geometric_normal, surface.error);
    let cos = surface.geometric_normal.dot(ray.direction).abs().max(0.01);
    let rounding_of_t = (t + ray.origin.abs().max_element()) * f32::EPSILON * COINCIDENT_T_ULPS;
    (COINCIDENT_BOUNDS * bound / cos).max(rounding_of_t)
}

/// Whether two unit normals are parallel (either way round): surfaces that cross a ray at
/// one distance with parallel normals lie in one place there (z-fighting); with others
/// they only meet at an edge.
#[inline]
fn parallel(a: Vec3A, b: Vec3A) -> bool {
    a.dot(b).abs() > PARALLEL_COS
}

/// The cosine above which two normals count as parallel: within about 2.6°.
const PARALLEL_COS: f32 = 0.999;

/// Where a trace's first hit comes from.
#[derive(Clone, Copy)]
enum FirstHit {
    /// Found by the trace itself.
    Find,
    /// Already found by a packet query over `(0, ∞)`.
    Known(Option<Hit>),
}

/// Whether a meeting is no interface at all: a solid's surface that leaves the current
/// medium unchanged.
#[inline(always)]
fn is_false_hit(solid: bool, outer: Option<Medium>, inner: Option<Medium>) -> bool {
    solid && same_medium(outer, inner)
}

/// Why a light facing the surface adds nothing (the `N·L`, cone and colour test of
/// `local_illumination` failed), in the order of that test.
#[cold]
fn unlit(n_dot_l: f32, spot: f32, intensity: Vec3A) -> NoShadowRay {
    if n_dot_l <= 0.0 {
        NoShadowRay::FacingAway
    } else if spot <= 0.0 {
        NoShadowRay::OutsideCone
    } else if intensity == Vec3A::ZERO {
        NoShadowRay::BlackLight
    } else {
        NoShadowRay::TooFaint
    }
}

/// A shadow query's outcome as the recorder reports it.
fn shadow_result(scene: &PreparedScene, shadow: Shadow) -> ShadowResult {
    match shadow {
        Shadow::Clear => ShadowResult::Unblocked,
        Shadow::Blocked(blocker) => {
            let item = scene.item(blocker.item);
            ShadowResult::Blocked {
                object: item.object(),
                leaf: item.leaf(blocker.leaf).object,
                t: blocker.t,
            }
        }
        Shadow::Filtered {
            transmittance,
            blockers,
        } => ShadowResult::Filtered {
            transmittance,
            blockers,
        },
    }
}

/// What happened to a ray's secondary rays, for its termination.
#[derive(Default)]
struct Outcome {
    traced_any: bool,
    first_skip: Option<Termination>,
}

impl Outcome {
    fn skipped(&mut self, reason: Termination) {
        self.first_skip = self.first_skip.or(Some(reason));
    }
}

/// How a surface divides a ray's weight between reflection and transmission.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Split {
    pub interface: Interface,
    /// `kr`, plus `kt·R` with Fresnel (R = 1 on total internal reflection).
    pub reflect: Vec3A,
    /// `kt`, times `1 − R` with Fresnel; zero on total internal reflection.
    pub transmit: Vec3A,
    /// The refracted direction, when the material transmits and refraction is possible.
    pub refracted: Option<Vec3A>,
}

/// The reflection/transmission split at a surface hit along `d`, with `n` the unit normal
/// facing the incoming ray, for a solid in air: it refracts between air (1.0) and the
/// material's ior, the direction decided by `front_face`; thin surfaces (no inside) have
/// 1.0 on both sides. (The tracer calls [`split_at`] with the media it knows; tests use this.)
#[cfg(test)]
pub fn split_weights(
    m: &PreparedMaterial,
    d: Vec3A,
    n: Vec3A,
    solid: bool,
    front_face: bool,
) -> Split {
    let ior = match (solid, front_face) {
        (false, _) => (1.0, 1.0),
        (true, true) => (1.0, m.ior),
        (true, false) => (m.ior, 1.0),
    };
    split_at(m, d, n, ior, solid && front_face, true)
}

/// [`split_weights`] between the media on either side: `ior` is (before, beyond) the
/// surface, and `entering` whether the ray enters a solid there (for the record);
/// `energy_clamp` is the scene's setting (off: `kr` and `kt` as given, as MIT 6.837 adds them).
#[inline(always)]
pub fn split_at(
    m: &PreparedMaterial,
    d: Vec3A,
    n: Vec3A,
    ior: (f32, f32),
    entering: bool,
    energy_clamp: bool,
) -> Split {
    let cos_incidence = (-d).dot(n).clamp(0.0, 1.0);
    let mut split = Split {
        interface: Interface {
            cos_incidence,
            ior: None,
            entering,
            fresnel: m.fresnel,
            fresnel_reflectance: None,
            total_internal_reflection: false,
        },
        reflect: m.reflective,
        transmit: Vec3A::ZERO,
        refracted: None,
    };
    if m.transmissive == Vec3A::ZERO {
        return split;
    }
    let (from, to) = ior;
    split.interface.ior = Some((from, to));
    match refract(d, n, from, to) {
        None => {
            split.interface.total_internal_reflection = true;
            match m.fresnel {
                // The textbook model (MIT 6.837): refraction is impossible, so the
                // transmitted term is dropped and only `kr` reflects. Handing `kt` to the
                // reflected ray instead made glass with kr + kt > 1 gain light per bounce.
                Fresnel::Off => {}
                // Fresnel reflects R = 1 of the transmitted share: `kt·R` joins `kr`.
                Fresnel::Schlick | Fresnel::Exact => {
                    split.interface.fresnel_reflectance = Some(1.0);
                    split.reflect = m.reflective + m.transmissive;
                }
            }
        }
        Some(direction) => {
            let reflectance = match m.fresnel {
                Fresnel::Off => None,
                Fresnel::Schlick => Some(schlick(cos_incidence, from, to)),
                Fresnel::Exact => Some(fresnel_exact(cos_incidence, from, to)),
            };
            match reflectance {
                Some(r) => {
                    split.interface.fresnel_reflectance = Some(r);
                    split.reflect = m.reflective + m.transmissive * r;
                    split.transmit = m.transmissive * (1.0 - r);
                }
                None => split.transmit = m.transmissive,
            }
            split.refracted = Some(direction);
        }
    }
    if energy_clamp {
        conserve_energy(&mut split);
    }
    split
}

/// Scales a surface's reflected and transmitted coefficients down, channel by channel, so
/// that they add up to at most 1: a material with `reflective + transmissive` over 1 (the
/// language warns) would otherwise return more light than arrives at every bounce, and a
/// trapped ray (total internal reflection with Fresnel, where `kr + kt·R = kr + kt`) would
/// grow brighter without bound as `max_depth` rises. The ray tree records the scaled
/// coefficients, so it shows the weights that were used.
#[inline(always)]
fn conserve_energy(split: &mut Split) {
    let total = split.reflect + split.transmit;
    if total.cmpgt(Vec3A::ONE).any() {
        let scale = Vec3A::ONE / total.max(Vec3A::ONE);
        split.reflect *= scale;
        split.transmit *= scale;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use whitted_ir::{Color, Fresnel, Material};

    fn glass(reflective: f64, fresnel: Fresnel) -> PreparedMaterial {
        PreparedMaterial::new(&Material {
            reflective: Color::gray(reflective),
            transmissive: Color::gray(0.9),
            ior: 1.5,
            fresnel,
            ..Material::default()
        })
    }

    fn incoming(degrees: f32) -> Vec3A {
        let theta = degrees.to_radians();
        Vec3A::new(theta.sin(), -theta.cos(), 0.0)
    }

    #[test]
    fn without_fresnel_the_coefficients_are_the_material_s() {
        let split = split_weights(
            &glass(0.1, Fresnel::Off),
            incoming(30.0),
            Vec3A::Y,
            true,
            true,
        );
        assert_eq!(split.reflect, Vec3A::splat(0.1));
        assert_eq!(split.transmit, Vec3A::splat(0.9));
        assert_eq!(split.interface.ior, Some((1.0, 1.5)));
        assert!(split.interface.entering);
        assert!(split.refracted.is_some());
    }

    #[test]
    fn schlick_moves_part_of_the_transmission_into_reflection() {
        let split = split_weights(
            &glass(0.1, Fresnel::Schlick),
            incoming(60.0),
            Vec3A::Y,
            true,
            true,
        );
        let r = split.interface.fresnel_reflectance.unwrap_or(-1.0);
        assert!(r > 0.04 && r < 1.0, "{r}");
        assert!(split.reflect.abs_diff_eq(Vec3A::splat(0.1 + 0.9 * r), 1e-6));
        assert!(split
            .transmit
            .abs_diff_eq(Vec3A::splat(0.9 * (1.0 - r)), 1e-6));
    }

    #[test]
    fn total_internal_reflection_reflects_everything() {
        // Leaving glass (a back face) at 60°, beyond the critical angle of 41.8°.
        let split = split_weights(
            &glass(0.1, Fresnel::Schlick),
            incoming(60.0),
            Vec3A::Y,
            true,
            false,
        );
        assert!(split.interface.total_internal_reflection);
        assert_eq!(split.interface.ior, Some((1.5, 1.0)));
        assert_eq!(split.interface.fresnel_reflectance, Some(1.0));
        assert_eq!(split.reflect, Vec3A::splat(0.1 + 0.9));
        assert_eq!(split.transmit, Vec3A::ZERO);
        assert!(split.refracted.is_none());
    }

    #[test]
    fn thin_surfaces_pass_light_straight_through() {
        let d = incoming(50.0);
        let split = split_weights(&glass(0.0, Fresnel::Off), d, Vec3A::Y, false, true);
        assert_eq!(split.interface.ior, Some((1.0, 1.0)));
        assert!(!split.interface.entering);
        assert!(split.refracted.unwrap_or(Vec3A::ZERO).abs_diff_eq(d, 1e-6));
    }
}
