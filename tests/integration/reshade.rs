//! An f64 re-shading of recorded ray trees, checked against the rendered pixel: an oracle that
//! does not trust the tracer's arithmetic (issue 9, deliver 1b).
//!
//! From each recorded tree it takes only what a ray tracer cannot avoid deciding for itself:
//! which surface each ray hit (`t`, point, shading normal, object, material), what each shadow
//! ray found, and the ray directions. Everything else is recomputed here in f64 with the
//! textbook formulas, written independently of `crates/tracer`:
//!
//! `I = ka·Ia·kd + Σ lights fatt·spot·Ii·S·(kd·(N·L) + ks·(R·V)^n) + kr'·I_r + kt'·I_t`,
//! times the Beer-Lambert factor `exp(−a·t)` of the medium the ray travels in, where `L`,
//! `fatt` and `spot` come from the light's position in the IR, `kr'`/`kt'` from the material's
//! coefficients, Fresnel recomputed from the incidence angle and the ior pair, and the
//! decisions (a shadow ray is due, total internal reflection, the depth and weight limits)
//! are made again here. Where a decision sits on a knife edge (f32 and f64 may honestly
//! disagree), the re-shader follows the recording; everywhere else a different decision is a
//! failure. The child colours are the re-shader's own, bottom-up: no recorded colour is used.
//!
//! The medium each ray travels in, and so the ior pair and the absorption, is the
//! re-shader's own too (see [`Media`]): a nested stack in scenes without priorities, and in
//! scenes with `priority` the solids that hold a point beside each surface, found from the
//! IR's shapes, so that water touching glass is one interface. What it still takes from the
//! recording is a filtered shadow ray's transmittance. Where it simplifies: a solid the
//! ray is inside has the material of its IR node (a CSG's), unless the hit at hand is on
//! it (then the material recorded there, patterns resolved).

use whitted_ir::{
    CsgOp, DMat4, DVec3, Fresnel, Handle, Highlight, LightKind, Material, Object, ObjectKind,
    PatternKind, Scene, ShadowMode, Shape,
};
use whitted_tracer::ray_tree::{trace_pixel, RayNode, SampleChoice, ShadowOutcome};
use whitted_tracer::{render, NoObserver, RayKind, RenderOptions, Termination};

use crate::ray_trees::{feature_scenes, load, Loaded};

/// How close to the rendered pixel the f64 re-shading must come, relative to the larger of 1
/// and the pixel's value (per channel).
///
/// Why this size: the tracer works in f32 (24-bit mantissa, one rounding ≈ 6e-8 relative).
/// A node's colour is a sum of a few dozen products, each with about ten roundings (the hit
/// point, the normal, the normalised light direction, N·L, the attenuation), so one node is
/// good to about 1e-6 relative. The Phong term `(R·V)^n` multiplies the relative error of
/// `R·V` by `n` (up to a few hundred in the scenes: ≈ 1e-5), and a tree chains at most ten
/// levels of such nodes. 1e-4 leaves a margin of about ten over the largest error seen on
/// correct scenes (printed by the test: about 2e-6 … 1e-5) while any modelling mistake (a
/// coefficient, a lost or extra term, a wrong Fresnel split) moves pixels by far more.
const TOLERANCE: f64 = 1e-4;

/// Decisions closer than this to their threshold may come out either way in f32 and f64:
/// there the re-shader follows the recorded decision (N·L against 0, total internal
/// reflection against the critical angle, the path weight against `min_weight`, the checker
/// cell against its edge).
const KNIFE_EDGE: f64 = 1e-4;

fn v(a: [f32; 3]) -> DVec3 {
    DVec3::new(f64::from(a[0]), f64::from(a[1]), f64::from(a[2]))
}

fn c(color: &whitted_ir::Color) -> DVec3 {
    DVec3::new(color.r, color.g, color.b)
}

/// The medium a ray travels in, in one of two models.
///
/// Without priorities (most scenes): one entry per solid the ray is inside, innermost last.
/// Entering a solid's front face pushes its material, leaving through a back face pops; the
/// ior pair at a surface is (the medium's ior, the next one's). Solids overlap only by
/// nesting.
///
/// With priorities (docs/language.md, "Nested media"): the medium at a point is found by
/// geometry, not by the path: of the solids whose inside holds the point (tested in f64
/// from the IR's shapes, [`solid_contains`]), the one of highest rank (the priority; 0, a
/// plain solid, above every other), and of equal ranks the one entered last along the path
/// (`entered`). The two sides of a recorded hit are points just off the surface along its
/// normal, so surfaces in the same place (water touching glass) are crossed as one
/// interface, and a surface whose sides have the same medium is no interface at all (the
/// tracer must have passed through it, not recorded it).
#[derive(Clone, Debug, Default)]
struct Media {
    /// Without priorities: the solids entered, innermost last.
    stack: Vec<Medium>,
    /// With priorities: the medium the ray travels in (`None`: air).
    current: Option<Medium>,
    /// With priorities: the solids entered along the path, in order (the last entered wins
    /// among equal ranks).
    entered: Vec<u32>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Medium {
    /// The top-level object (a shape or a CSG root) that is the solid.
    object: u32,
    ior: f64,
    absorption: DVec3,
    /// The priority, with 0 (plain) above every other.
    rank: u32,
}

impl Media {
    fn innermost(&self) -> Option<&Medium> {
        self.current.as_ref().or(self.stack.last())
    }
    fn ior(&self) -> f64 {
        self.innermost().map_or(1.0, |m| m.ior)
    }
    fn absorption(&self) -> DVec3 {
        self.innermost().map_or(DVec3::ZERO, |m| m.absorption)
    }
    /// The ior on the other side of the innermost solid's surface (air outside every solid).
    fn ior_outside_innermost(&self) -> f64 {
        let n = self.stack.len();
        if n >= 2 {
            self.stack[n - 2].ior
        } else {
            1.0
        }
    }
}

/// The rank of a priority: 0 (plain) ranks above every other.
fn rank(priority: u32) -> u32 {
    if priority == 0 {
        u32::MAX
    } else {
        priority
    }
}

/// The solids of a scene with priorities: every top-level object (not a CSG child; groups
/// are flattened) that has an inside.
fn top_level_solids(scene: &Scene) -> Vec<Handle<Object>> {
    let mut in_csg = vec![false; scene.objects.len()];
    let objects: Vec<(Handle<Object>, &Object)> = scene.objects.iter().collect();
    for &(handle, object) in objects.iter().rev() {
        if let ObjectKind::Csg { children, .. } = &object.kind {
            for child in children {
                in_csg[child.index()] = true;
            }
        } else if in_csg[handle.index()] {
            if let ObjectKind::Group { children } = &object.kind {
                for child in children {
                    in_csg[child.index()] = true;
                }
            }
        }
    }
    scene
        .objects
        .iter()
        .filter(|(h, o)| !in_csg[h.index()] && !matches!(o.kind, ObjectKind::Group { .. }))
        .filter(|(h, _)| solid_contains(scene, *h, DVec3::ZERO).is_some())
        .map(|(h, _)| h)
        .collect()
}

/// `Some(true)` when `p` is strictly inside the solid `handle`, `Some(false)` outside,
/// `None` when it has no inside (disks, triangles, open tubes, open meshes, groups): the
/// shapes' definitions in docs/language.md, in object space, and CSG by its operation.
fn solid_contains(scene: &Scene, handle: Handle<Object>, p: DVec3) -> Option<bool> {
    let object = &scene.objects[handle];
    match &object.kind {
        ObjectKind::Shape { shape } => {
            let q = object.world_from_object.inverse().transform_point3(p);
            shape_contains(scene, &shape.get(), q)
        }
        ObjectKind::Csg { op, children } => {
            let mut inside = children
                .iter()
                .map(|&c| solid_contains(scene, c, p).unwrap_or(false));
            Some(match op {
                CsgOp::Union => inside.any(|b| b),
                CsgOp::Intersection => inside.all(|b| b),
                CsgOp::Difference => inside.next().unwrap_or(false) && !inside.any(|b| b),
            })
        }
        ObjectKind::Group { .. } => None,
    }
}

fn shape_contains(scene: &Scene, shape: &Shape, q: DVec3) -> Option<bool> {
    // Inside a capped tube from `a` (radius `r0`) to `b` (radius `r1`).
    let tube = |a: DVec3, b: DVec3, r0: f64, r1: f64| {
        let axis = b - a;
        let s = (q - a).dot(axis) / axis.length_squared();
        let r = r0 + (r1 - r0) * s;
        s > 0.0 && s < 1.0 && (q - a - axis * s).length_squared() < r * r
    };
    match *shape {
        Shape::Sphere { center, radius } => Some(q.distance_squared(center) < radius * radius),
        Shape::Plane { normal, offset } => Some(normal.dot(q) < offset),
        Shape::Box { min, max } => Some(q.cmpgt(min).all() && q.cmplt(max).all()),
        Shape::Cylinder {
            base,
            apex,
            radius,
            capped: true,
        } => Some(tube(base, apex, radius, radius)),
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            capped: true,
        } => Some(tube(base, apex, base_radius, apex_radius)),
        Shape::Quadric { quadric, .. } => Some(quadric.eval(q) < 0.0),
        Shape::Torus { major, minor } => {
            let ring = (q.x * q.x + q.z * q.z).sqrt() - major;
            Some(ring * ring + q.y * q.y < minor * minor)
        }
        Shape::Mesh { mesh, .. } => {
            let mesh = &scene.meshes[mesh];
            mesh.solid.then(|| mesh_contains(mesh, q))
        }
        Shape::Cylinder { .. }
        | Shape::Cone { .. }
        | Shape::Disk { .. }
        | Shape::Triangle { .. } => None,
    }
}

/// Inside a closed mesh: a ray from `q` in a direction off every axis crosses its surface
/// an odd number of times.
fn mesh_contains(mesh: &whitted_ir::Mesh, q: DVec3) -> bool {
    let direction = DVec3::new(0.5773, 0.6131, 0.5394).normalize();
    let corner = |i: u32| v(mesh.positions[i as usize]);
    let crossings = mesh
        .triangles
        .iter()
        .filter(|&&[a, b, c]| {
            let (a, b, c) = (corner(a), corner(b), corner(c));
            let (e1, e2) = (b - a, c - a);
            let pvec = direction.cross(e2);
            let det = e1.dot(pvec);
            let tvec = q - a;
            let u = tvec.dot(pvec) / det;
            let qvec = tvec.cross(e1);
            let w = direction.dot(qvec) / det;
            det != 0.0 && u >= 0.0 && w >= 0.0 && u + w <= 1.0 && e2.dot(qvec) / det > 0.0
        })
        .count();
    crossings % 2 == 1
}

/// Beer-Lambert: `exp(−a·t)` per channel; a channel without absorption transmits fully even
/// over an infinite distance.
fn beer_lambert(a: DVec3, t: f64) -> DVec3 {
    let channel = |a: f64| if a == 0.0 { 1.0 } else { (-a * t).exp() };
    DVec3::new(channel(a.x), channel(a.y), channel(a.z))
}

/// Schlick's approximation, taking the cosine on the denser side (the transmitted angle when
/// light goes into a less dense medium), so that R reaches 1 at the critical angle.
fn schlick(cos_i: f64, n1: f64, n2: f64) -> f64 {
    let r0 = ((n1 - n2) / (n1 + n2)).powi(2);
    let cos = if n1 > n2 {
        let sin2_t = (n1 / n2).powi(2) * (1.0 - cos_i * cos_i);
        if sin2_t >= 1.0 {
            return 1.0;
        }
        (1.0 - sin2_t).sqrt()
    } else {
        cos_i
    };
    r0 + (1.0 - r0) * (1.0 - cos).powi(5)
}

/// The unpolarised Fresnel reflectance (the mean of the s and p reflectances), for the
/// `fresnel exact` mode being added on another branch.
fn fresnel_exact(cos_i: f64, n1: f64, n2: f64) -> f64 {
    let sin2_t = (n1 / n2).powi(2) * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
    let rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Distance attenuation `min(1, 1/(c + l·d + q·d²))`, or without the `min` when `clamp` is
/// off (then bounded by the largest attenuation limit, as docs/language.md says).
fn fatt(a: &whitted_ir::Attenuation, d: f64, clamp: bool) -> f64 {
    let largest = if clamp {
        1.0
    } else {
        whitted_ir::limits::MAX_UNCLAMPED_ATTENUATION
    };
    (1.0 / (a.constant + a.linear * d + a.quadratic * d * d)).min(largest)
}

/// The smoothstep of the spot cone between the outer and the inner angle.
fn spot_factor(cos_angle: f64, inner_degrees: f64, outer_degrees: f64) -> f64 {
    let cos_inner = inner_degrees.to_radians().cos();
    let cos_outer = outer_degrees.to_radians().cos();
    if cos_angle >= cos_inner {
        1.0
    } else if cos_angle <= cos_outer {
        0.0
    } else {
        let x = (cos_angle - cos_outer) / (cos_inner - cos_outer);
        x * x * (3.0 - 2.0 * x)
    }
}

/// Where the light is seen from `p`: unit direction, distance, fatt and the spot factor.
fn incidence(kind: &LightKind, p: DVec3, clamp: bool) -> (DVec3, f64, f64, f64) {
    match kind {
        LightKind::Point {
            position,
            attenuation,
        } => {
            let d = (*position - p).length();
            ((*position - p) / d, d, fatt(attenuation, d, clamp), 1.0)
        }
        LightKind::Directional { direction } => (-direction.normalize(), f64::INFINITY, 1.0, 1.0),
        LightKind::Spot {
            position,
            direction,
            inner_angle_degrees,
            outer_angle_degrees,
            attenuation,
        } => {
            let d = (*position - p).length();
            let l = (*position - p) / d;
            let cos_angle = (-l).dot(direction.normalize());
            let spot = spot_factor(cos_angle, *inner_angle_degrees, *outer_angle_degrees);
            (l, d, fatt(attenuation, d, clamp), spot)
        }
    }
}

/// Snell's law for a unit `d` meeting a unit normal `n` that faces it; `None` beyond the
/// critical angle.
fn refract(d: DVec3, n: DVec3, n1: f64, n2: f64) -> Option<DVec3> {
    let eta = n1 / n2;
    let cos_i = (-d.dot(n)).clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    (sin2_t <= 1.0).then(|| (eta * d + (eta * cos_i - (1.0 - sin2_t).sqrt()) * n).normalize())
}

/// One sample re-shaded, and everything found wrong on the way.
struct Reshader<'a> {
    scene: &'a Scene,
    max_depth: u32,
    min_weight: f64,
    /// The scene's solids when it uses priorities (the media are then found by geometry).
    solids: Option<Vec<Handle<Object>>>,
    /// Disagreements in decisions or directions, each with the path of the node.
    problems: Vec<String>,
    /// The deepest node whose recorded colour differs from its re-shaded colour.
    worst_node: Option<(usize, String)>,
    /// Reflected, transmitted and shadow rays of the current sample so far, in the tracer's
    /// order, against the ray budget per sample.
    rays: u32,
}

impl Reshader<'_> {
    fn material(&self, index: u32) -> &Material {
        &self.scene.materials[Handle::from_index(index as usize)]
    }

    fn problem(&mut self, path: &str, message: String) {
        self.problems.push(format!("{path}: {message}"));
    }

    /// The colour `node` returns, in f64. `weight` is its path weight before its own
    /// absorption, `media` the solids it travels inside.
    fn shade(&mut self, node: &RayNode, weight: DVec3, media: &Media, path: &str) -> DVec3 {
        let color = self.shade_inner(node, weight, media, path);
        let recorded = v(node.color);
        let error = (color - recorded).abs().max_element() / recorded.max_element().max(1.0);
        if error > TOLERANCE {
            let depth = path.matches('/').count();
            if self.worst_node.as_ref().is_none_or(|(d, _)| depth >= *d) {
                self.worst_node = Some((
                    depth,
                    format!(
                        "{path} ({} hitting {}): recorded {recorded:?}, f64 {color:?}",
                        node.kind.name(),
                        node.hit
                            .as_ref()
                            .map_or("nothing", |h| h.object.label.as_str())
                    ),
                ));
            }
        }
        color
    }

    /// One light's diffuse and specular terms: `strength` is fatt·spot, `passed` what the
    /// shadow ray let through, `(n, l, d)` the shading normal, the unit direction to the
    /// light and the incoming ray's direction.
    fn light_terms(
        &self,
        light: &whitted_ir::Light,
        strength: f64,
        passed: DVec3,
        (n, l, d): (DVec3, DVec3, DVec3),
        m: &Material,
    ) -> DVec3 {
        let n_dot_l = n.dot(l);
        let light_in = c(&light.color) * strength * passed;
        let diffuse = light_in * c(&m.diffuse) * n_dot_l.max(0.0);
        let cosine = match self.scene.settings.highlight {
            Highlight::Phong => {
                let r = -l + 2.0 * n_dot_l * n; // L mirrored about N
                r.dot(-d)
            }
            // H halfway between the light and the viewer.
            Highlight::Blinn => n.dot((l - d).normalize_or_zero()),
        };
        diffuse + light_in * c(&m.specular) * cosine.max(0.0).powf(m.shininess)
    }

    fn shade_inner(&mut self, node: &RayNode, weight: DVec3, media: &Media, path: &str) -> DVec3 {
        let a = media.absorption();
        let d = v(node.direction).normalize();
        let background = c(&self.scene.settings.background);
        let Some(hit) = &node.hit else {
            if node.termination != Termination::Miss {
                self.problem(path, format!("a miss ends with {:?}", node.termination));
            }
            return background * beer_lambert(a, f64::INFINITY);
        };
        let absorption = beer_lambert(a, f64::from(hit.t));
        let m = match &hit.blend {
            None => self.material(hit.resolved_material.handle).clone(),
            Some(blend) => self.blended(hit, blend),
        };
        self.check_pattern(hit, path);
        let p = v(hit.point);
        let n = v(hit.shading_normal).normalize();
        if n.dot(d) > KNIFE_EDGE {
            self.problem(path, "the shading normal faces away from the ray".into());
        }

        // Local illumination.
        let mut local =
            c(&m.ambient) * c(&self.scene.settings.ambient) * c(&m.diffuse) + c(&m.emission);
        let settings = &self.scene.settings;
        if !settings.shade_back && !settings.back_ambient && !hit.front_face {
            // The handout's back face: its own colour is black.
            local = DVec3::ZERO;
        }
        // Without the N·L gate (the course's Phong), a light behind the surface still
        // counts when the material has a highlight.
        let gated = settings.highlight_gate || c(&m.specular) == DVec3::ZERO;
        let lights = node.local.as_ref().map_or(&[][..], |l| &l.lights[..]);
        if lights.len() != self.scene.lights.len() {
            self.problem(path, format!("{} light entries", lights.len()));
        }
        let kd = c(&m.diffuse);
        let ks = c(&m.specular);
        for entry in lights {
            let light = &self.scene.lights[Handle::from_index(entry.light.handle as usize)];
            let shadow = entry.shadow_child.and_then(|i| node.children.get(i));
            if shadow.is_some() {
                self.rays += 1;
            }
            // The light is seen from where the shadow ray starts (the point moved off the
            // surface); without a shadow ray, from the hit point itself.
            let from = shadow.map_or(p, |s| v(s.origin));
            let settings = &self.scene.settings;
            let (l, distance, fatt, spot) =
                incidence(&light.kind, from, settings.attenuation_clamp);
            let n_dot_l = n.dot(l);
            let strength = fatt * spot * c(&light.color).max_element();
            if !settings.shade_back && !hit.front_face {
                // A back face with `shade_back off`: no light, no shadow ray.
                if shadow.is_some() {
                    self.problem(path, "a shadow ray from an unlit back face".into());
                }
                continue;
            }
            if settings.shadows == ShadowMode::None {
                if shadow.is_some() {
                    self.problem(path, "a shadow ray with shadows none".into());
                }
                if (n_dot_l > 0.0 || !gated) && strength > 0.0 {
                    local += self.light_terms(light, fatt * spot, DVec3::ONE, (n, l, d), &m);
                }
                continue;
            }
            let Some(shadow) = shadow else {
                // No shadow ray: right when the light cannot count here (or, as a shortcut
                // some tracers take, when the material has no diffuse or specular term).
                let counts = (n_dot_l > KNIFE_EDGE || !gated) && strength > KNIFE_EDGE;
                if counts && (kd != DVec3::ZERO || ks != DVec3::ZERO) {
                    self.problem(
                        path,
                        format!(
                            "no shadow ray to light #{} though N·L = {n_dot_l}",
                            entry.light.handle
                        ),
                    );
                }
                continue;
            };
            if (n_dot_l < -KNIFE_EDGE && gated) || strength == 0.0 {
                self.problem(
                    path,
                    format!(
                        "a shadow ray to light #{} with N·L = {n_dot_l}",
                        entry.light.handle
                    ),
                );
                continue;
            }
            if (v(shadow.direction) - l).length() > 1e-5 {
                self.problem(
                    path,
                    format!(
                        "shadow ray direction {:?}, expected {l:?}",
                        shadow.direction
                    ),
                );
            }
            if let (Some(max_t), true) = (
                shadow.shadow.as_ref().and_then(|s| s.max_t),
                distance.is_finite(),
            ) {
                if (f64::from(max_t) - distance).abs() > 1e-5 * distance.max(1.0) {
                    self.problem(
                        path,
                        format!("shadow ray stops at {max_t}, light at {distance}"),
                    );
                }
            }
            let passed = match shadow.shadow.as_ref() {
                Some(info) => match info.result {
                    ShadowOutcome::Unblocked => DVec3::ONE,
                    ShadowOutcome::Blocked => DVec3::ZERO,
                    ShadowOutcome::Filtered => {
                        if self.scene.settings.shadows != ShadowMode::Filtered {
                            self.problem(
                                path,
                                "a filtered shadow in an opaque-shadow scene".into(),
                            );
                        }
                        info.transmittance.map_or(DVec3::ZERO, v)
                    }
                },
                None => {
                    self.problem(path, "a shadow child without shadow data".into());
                    DVec3::ZERO
                }
            };
            local += self.light_terms(light, fatt * spot, passed, (n, l, d), &m);
        }

        // Secondary rays: what the material asks for, split by Fresnel.
        let leaf = &self.scene.objects[Handle::from_index(hit.leaf.handle as usize)];
        let solid = match &leaf.kind {
            // A mesh is a solid when its data says so (closed and consistently oriented).
            ObjectKind::Shape { shape } => self.scene.is_solid_shape(&shape.get()),
            _ => true,
        };
        let kr = c(&m.reflective);
        let kt = c(&m.transmissive);
        let cos_i = (-d).dot(n).clamp(0.0, 1.0);
        // The media on each side, and the media the reflected and transmitted rays travel in.
        let (n1, n2, outside, inside) = if self.solids.is_some() {
            self.priority_sides(d, hit, &m, solid, media, path)
        } else if !solid {
            (media.ior(), media.ior(), media.clone(), media.clone())
        } else if hit.front_face {
            // Entering a solid adds it, leaving removes it.
            let mut inside = media.clone();
            inside.stack.push(Medium {
                object: hit.object.handle,
                ior: m.ior,
                absorption: c(&m.absorption),
                rank: rank(m.priority),
            });
            (media.ior(), m.ior, media.clone(), inside)
        } else {
            let mut outside = media.clone();
            outside.stack.pop();
            (m.ior, media.ior_outside_innermost(), media.clone(), outside)
        };
        let mut reflect = kr;
        let mut transmit = DVec3::ZERO;
        let mut refracted = None;
        let mut tir = false;
        if kt != DVec3::ZERO {
            let sin2_t = (n1 / n2).powi(2) * (1.0 - cos_i * cos_i);
            let recorded_tir = node
                .skipped
                .iter()
                .any(|s| s.reason == Termination::TotalInternalReflection)
                || node
                    .child(RayKind::Reflected)
                    .and_then(|r| r.interface.as_ref())
                    .is_some_and(|i| i.total_internal_reflection);
            tir = if (sin2_t - 1.0).abs() < KNIFE_EDGE {
                recorded_tir
            } else {
                sin2_t > 1.0
            };
            if tir != recorded_tir {
                self.problem(
                    path,
                    format!(
                        "total internal reflection: recorded {recorded_tir}, sin²θt = {sin2_t}"
                    ),
                );
            }
            let r = match m.fresnel {
                Fresnel::Off => None,
                Fresnel::Schlick => Some(schlick(cos_i, n1, n2)),
                Fresnel::Exact => Some(fresnel_exact(cos_i, n1, n2)),
            };
            if tir {
                // Textbook: with Fresnel everything reflects (R = 1); without it the
                // transmitted term is dropped.
                if r.is_some() {
                    reflect = kr + kt;
                }
            } else {
                refracted = refract(d, n, n1, n2);
                match r {
                    Some(r) => {
                        reflect = kr + kt * r;
                        transmit = kt * (1.0 - r);
                    }
                    None => transmit = kt,
                }
            }
        }

        let carried = weight * absorption;
        let mut color = local;
        let mut traced_any = false;
        let mut first_skip = None;
        let secondaries = [
            (
                RayKind::Reflected,
                reflect,
                Some(d - 2.0 * d.dot(n) * n),
                outside,
            ),
            (RayKind::Transmitted, transmit, refracted, inside),
        ];
        for (kind, coefficient, direction, child_media) in secondaries {
            if kind == RayKind::Transmitted && tir {
                first_skip = first_skip.or(Some(Termination::TotalInternalReflection));
            }
            let recorded = node.child(kind);
            let skipped = node.skipped.iter().find(|s| s.kind == kind);
            if coefficient == DVec3::ZERO {
                if let Some(recorded) = recorded {
                    self.problem(
                        path,
                        format!(
                            "a {} ray with coefficient {:?}, expected none",
                            kind.name(),
                            recorded.coefficient
                        ),
                    );
                }
                continue;
            }
            let child_weight = carried * coefficient;
            let verdict = if node.depth + 1 > self.max_depth {
                Some(Termination::MaxDepth)
            } else if (child_weight.max_element() - self.min_weight).abs()
                < KNIFE_EDGE * self.min_weight
            {
                // On the edge: follow the recording.
                skipped.map(|s| s.reason)
            } else if child_weight.max_element() < self.min_weight {
                Some(Termination::WeightCutoff)
            } else if self.rays >= whitted_ir::limits::MAX_RAYS_PER_SAMPLE {
                Some(Termination::RayBudget)
            } else {
                None
            };
            match (verdict, recorded) {
                (None, Some(child)) => {
                    traced_any = true;
                    self.rays += 1;
                    if let Some(expected) = direction {
                        // A direction's f32 error grows along a path of curved reflections
                        // (a glass ball in a mirror box, 60 bounces deep, drifts by 1e-4):
                        // the tolerance doubles every 8 levels past 16; colours are still
                        // held to TOLERANCE.
                        let levels = f64::from(child.depth.saturating_sub(16)) / 8.0;
                        let tolerance = 1e-4 * 2f64.powf(levels);
                        if (v(child.direction) - expected).length() > tolerance {
                            self.problem(
                                path,
                                format!(
                                    "{} direction {:?}, expected {expected:?}",
                                    kind.name(),
                                    child.direction
                                ),
                            );
                        }
                    }
                    let child_path = format!("{path}/{}", kind.name());
                    let returned = self.shade(child, child_weight, &child_media, &child_path);
                    color += coefficient * returned;
                }
                (Some(reason), None) => {
                    first_skip = first_skip.or(Some(reason));
                    if skipped.map(|s| s.reason) != Some(reason) {
                        self.problem(
                            path,
                            format!("{} ray should be skipped for {reason:?}", kind.name()),
                        );
                    }
                }
                (None, None) => self.problem(
                    path,
                    format!(
                        "no {} ray, expected one with coefficient {coefficient:?}",
                        kind.name()
                    ),
                ),
                (Some(reason), Some(_)) => self.problem(
                    path,
                    format!(
                        "a {} ray was traced though it should be skipped for {reason:?}",
                        kind.name()
                    ),
                ),
            }
        }
        let expected_termination = if traced_any {
            Termination::NotEnded
        } else {
            first_skip.unwrap_or(Termination::Absorbed)
        };
        if node.termination != expected_termination {
            self.problem(
                path,
                format!(
                    "ends with {:?}, expected {expected_termination:?}",
                    node.termination
                ),
            );
        }
        color * absorption
    }

    /// The ior on either side of a solid's surface in a scene with priorities, and the
    /// media of the reflected and the transmitted ray (see [`Media`]). Checks that the
    /// surface is an interface at all, that the ray arrives in the medium found on its side,
    /// and that the surface recorded is the winning medium's: the higher rank of the medium
    /// left and the medium entered (air ranks lowest).
    fn priority_sides(
        &mut self,
        d: DVec3,
        hit: &whitted_tracer::ray_tree::HitInfo,
        m: &Material,
        solid: bool,
        media: &Media,
        path: &str,
    ) -> (f64, f64, Media, Media) {
        if !solid {
            // A thin surface: the same medium on both sides.
            return (media.ior(), media.ior(), media.clone(), media.clone());
        }
        let scene = self.scene;
        let solids = self.solids.as_deref().unwrap_or_default();
        let medium_of = |h: Handle<Object>| {
            // The material the solid is entered through: the one recorded at this hit, or
            // the object's own (a CSG's leaves carry the material of the node).
            let material = if h.index() == hit.object.handle as usize {
                m
            } else {
                &scene.materials[scene.objects[h].material]
            };
            Medium {
                object: h.index() as u32,
                ior: material.ior,
                absorption: c(&material.absorption),
                rank: rank(material.priority),
            }
        };
        let inside = |q: DVec3| -> Vec<Medium> {
            solids
                .iter()
                .filter(|&&h| solid_contains(scene, h, q) == Some(true))
                .map(|&h| medium_of(h))
                .collect()
        };
        let winner = |set: &[Medium], entered: &[u32]| -> Option<Medium> {
            let order = |m: &Medium| entered.iter().rposition(|&o| o == m.object);
            set.iter()
                .copied()
                .max_by_key(|m| (m.rank, order(m).map_or(-1, |i| i as i64)))
        };
        let object = |m: Option<Medium>| m.map(|m| m.object);
        // Points just off the surface on either side, along the geometric normal: past the
        // hit point's error (the tracer starts its rays at `offset`, twice it), and far
        // inside every feature of a scene. The same test four times further off must agree,
        // or another surface is within rounding of this one.
        let p = v(hit.point);
        let mut g = v(hit.geometric_normal).normalize();
        if g.dot(d) > 0.0 {
            g = -g;
        }
        let step = 2.0 * f64::from(hit.offset.max(hit.error_bound));
        let near = (inside(p + step * g), inside(p - step * g));
        let far = (inside(p + 4.0 * step * g), inside(p - 4.0 * step * g));
        let before = winner(&near.0, &media.entered);
        let after = winner(&near.1, &media.entered);
        if object(winner(&far.0, &media.entered)) != object(before)
            || object(winner(&far.1, &media.entered)) != object(after)
        {
            self.problem(
                path,
                "another solid's surface within rounding of the hit".into(),
            );
        }
        if object(media.current) != object(before) {
            self.problem(
                path,
                format!(
                    "the ray travels in {:?} but arrives from {:?}",
                    object(media.current),
                    object(before)
                ),
            );
        }
        let expected = match (before, after) {
            (Some(b), Some(a)) if b.rank > a.rank => Some((b.object, false)),
            (_, Some(a)) => Some((a.object, true)),
            (b, None) => b.map(|b| (b.object, false)),
        };
        if object(before) == object(after) {
            self.problem(
                path,
                format!(
                    "a hit on a surface that changes no medium (in {:?} on both sides)",
                    object(before)
                ),
            );
        } else if expected != Some((hit.object.handle, hit.front_face)) {
            self.problem(
                path,
                format!(
                    "the interface from {:?} to {:?} is {expected:?} (object, entering), \
                     recorded ({}, {})",
                    object(before),
                    object(after),
                    hit.object.handle,
                    hit.front_face
                ),
            );
        }
        let mut entered = media.entered.clone();
        for m in &near.0 {
            if !near.1.iter().any(|a| a.object == m.object) {
                entered.retain(|&o| o != m.object);
            }
        }
        for m in &near.1 {
            if !near.0.iter().any(|b| b.object == m.object) {
                entered.retain(|&o| o != m.object);
                entered.push(m.object);
            }
        }
        let ior = |m: Option<Medium>| m.map_or(1.0, |m| m.ior);
        (
            ior(before),
            ior(after),
            Media {
                current: before,
                entered: media.entered.clone(),
                ..Media::default()
            },
            Media {
                current: after,
                entered,
                ..Media::default()
            },
        )
    }

    /// The course's blend of two materials (docs/courses.md, "Procedural materials"): the
    /// colours and the exponent interpolated, the medium's numbers (ior, Fresnel, priority,
    /// absorption) the recorded material's, which is the one with the larger weight.
    fn blended(
        &self,
        hit: &whitted_tracer::ray_tree::HitInfo,
        blend: &whitted_tracer::ray_tree::BlendInfo,
    ) -> Material {
        let (first, second) = (
            self.material(blend.first.handle),
            self.material(blend.second.handle),
        );
        let w = f64::from(blend.weight);
        let mix = |a: &whitted_ir::Color, b: &whitted_ir::Color| {
            whitted_ir::Color::new(
                a.r + (b.r - a.r) * w,
                a.g + (b.g - a.g) * w,
                a.b + (b.b - a.b) * w,
            )
        };
        Material {
            ambient: mix(&first.ambient, &second.ambient),
            diffuse: mix(&first.diffuse, &second.diffuse),
            specular: mix(&first.specular, &second.specular),
            shininess: first.shininess + (second.shininess - first.shininess) * w,
            reflective: mix(&first.reflective, &second.reflective),
            transmissive: mix(&first.transmissive, &second.transmissive),
            emission: mix(&first.emission, &second.emission),
            ..self.material(hit.resolved_material.handle).clone()
        }
    }

    /// The course's patterns read the world-space point: the blend's weight (or the
    /// checker's cell) recomputed in f64 from the formulas, with the reference noise.
    fn check_course_pattern(
        &mut self,
        hit: &whitted_tracer::ray_tree::HitInfo,
        pattern: &whitted_ir::Pattern,
        path: &str,
    ) {
        let q = pattern.pattern_from_object.transform_point3(v(hit.point));
        let n = |octaves| whitted_tracer::testing::reference_octave_sum(q.to_array(), octaves);
        let weight = match pattern.kind {
            PatternKind::CourseNoise { octaves } => n(octaves).clamp(0.0, 1.0),
            PatternKind::CourseMarble {
                octaves,
                frequency,
                amplitude,
            } => (1.0 + (frequency * q.x + amplitude * n(octaves)).sin()) / 2.0,
            PatternKind::CourseWood {
                octaves,
                frequency,
                amplitude,
            } => {
                let radius = (q.x * q.x + q.z * q.z).sqrt();
                (1.0 + (frequency * radius + amplitude * n(octaves)).sin()) / 2.0
            }
            _ => return,
        };
        let Some(blend) = &hit.blend else {
            self.problem(
                path,
                format!("a {} pattern without a blend", pattern.kind.name()),
            );
            return;
        };
        let plain = |h: Handle<Material>| self.material(h.index() as u32).pattern.is_none();
        if plain(pattern.a)
            && plain(pattern.b)
            && (blend.first.handle as usize, blend.second.handle as usize)
                != (pattern.a.index(), pattern.b.index())
        {
            self.problem(
                path,
                "the blend is not of the pattern's two materials".into(),
            );
        }
        // The point is f32 and the weight's slope is about frequency plus amplitude times
        // the noise's: 1e-3 is far above the rounding and far below any formula mistake.
        if (f64::from(blend.weight) - weight).abs() > 1e-3 {
            self.problem(
                path,
                format!(
                    "the {} weight at {q:?} is {weight}, recorded {}",
                    pattern.kind.name(),
                    blend.weight
                ),
            );
        }
    }

    /// Recomputes which of a pattern's two materials covers the hit point (away from cell
    /// edges) from the leaf's transform and the pattern's own, in f64.
    fn check_pattern(&mut self, hit: &whitted_tracer::ray_tree::HitInfo, path: &str) {
        let given = self.material(hit.material.handle);
        let Some(pattern) = &given.pattern else {
            if hit.resolved_material.handle != hit.material.handle {
                self.problem(path, "a resolved material without a pattern".into());
            }
            return;
        };
        if pattern.kind.blends() {
            let pattern = pattern.clone();
            return self.check_course_pattern(hit, &pattern, path);
        }
        let leaf = &self.scene.objects[Handle::from_index(hit.leaf.handle as usize)];
        let object_from_world: DMat4 = if pattern.kind.world_space() {
            DMat4::IDENTITY
        } else {
            leaf.world_from_object.inverse()
        };
        let q = (pattern.pattern_from_object * object_from_world).transform_point3(v(hit.point))
            / pattern.scale;
        let coordinates: &[f64] = match pattern.kind {
            PatternKind::Checker | PatternKind::CourseCheckerboard => &[q.x, q.y, q.z],
            PatternKind::Stripes => &[q.x],
            // Noise patterns are checked by their own tests (crates/tracer/src/noise.rs):
            // recomputing them here would repeat the code under test.
            PatternKind::Marble | PatternKind::Wood | PatternKind::Turbulence => return,
            PatternKind::CourseNoise { .. }
            | PatternKind::CourseMarble { .. }
            | PatternKind::CourseWood { .. } => return,
        };
        // The hit point is f32: near a cell edge the cell is not decidable from it.
        if coordinates
            .iter()
            .any(|x| (x - x.round()).abs() < 1e-3 * x.abs().max(1.0))
        {
            return;
        }
        let parity: i64 = coordinates.iter().map(|x| x.floor() as i64).sum();
        let expected = if parity.rem_euclid(2) == 0 {
            pattern.a
        } else {
            pattern.b
        };
        if self.material(expected.index() as u32).pattern.is_some() {
            // A pattern of patterns: the recorded material is the inner one's choice.
            return;
        }
        if expected.index() != hit.resolved_material.handle as usize {
            self.problem(
                path,
                format!(
                    "pattern cell at {q:?} gives material #{}, recorded #{}",
                    expected.index(),
                    hit.resolved_material.handle
                ),
            );
        }
    }
}

/// Whether a scene uses `priority` (nested media with priorities: [`Media`]).
fn uses_priorities(scene: &Scene) -> bool {
    scene.materials.iter().any(|(_, m)| m.priority > 0)
}

/// What re-shading one pixel found.
struct PixelVerdict {
    error: f64,
    problems: Vec<String>,
    worst_node: Option<String>,
}

fn reshade_pixel(
    loaded: &Loaded,
    options: &RenderOptions,
    x: u32,
    y: u32,
    rendered: [f32; 3],
) -> PixelVerdict {
    let priorities = uses_priorities(&loaded.scene);
    reshade_pixel_modelled(loaded, options, (x, y), rendered, priorities)
}

/// [`reshade_pixel`] with the media model chosen: `priorities` finds media by geometry.
fn reshade_pixel_modelled(
    loaded: &Loaded,
    options: &RenderOptions,
    (x, y): (u32, u32),
    rendered: [f32; 3],
    priorities: bool,
) -> PixelVerdict {
    let tree = trace_pixel(
        &loaded.prepared,
        &loaded.scene,
        options,
        x,
        y,
        SampleChoice::All,
    )
    .unwrap_or_else(|error| panic!("{error}"));
    let mut reshader = Reshader {
        scene: &loaded.scene,
        max_depth: tree.max_depth,
        min_weight: f64::from(tree.min_weight),
        solids: priorities.then(|| top_level_solids(&loaded.scene)),
        problems: Vec::new(),
        worst_node: None,
        rays: 0,
    };
    let mut sum = DVec3::ZERO;
    for sample in &tree.samples {
        reshader.rays = 0;
        let path = format!("sample {}", sample.index);
        sum += reshader.shade(&sample.root, DVec3::ONE, &Media::default(), &path);
    }
    let mean = sum / tree.samples.len().max(1) as f64;
    let rendered = v(rendered);
    PixelVerdict {
        error: (mean - rendered).abs().max_element() / rendered.max_element().max(1.0),
        problems: reshader.problems,
        worst_node: reshader.worst_node.map(|(_, s)| s),
    }
}

/// Re-shades every pixel of a small render of `path`; returns the failures (one line each,
/// at most a few per scene) and the largest relative error seen.
fn check_scene(path: &str, width: u32, height: u32) -> (Vec<String>, f64, usize) {
    let loaded = load(path);
    let options = RenderOptions {
        width,
        height,
        ..RenderOptions::from_settings(&loaded.scene.settings)
    };
    let Some((image, _)) = render(&loaded.prepared, &options, &NoObserver) else {
        panic!("{path}: the render was cancelled");
    };
    let mut failures = Vec::new();
    let mut failing_pixels = 0;
    let mut largest = 0.0f64;
    for y in 0..height {
        for x in 0..width {
            let rendered = image.pixel(x, y).unwrap_or([f32::NAN; 3]);
            let verdict = reshade_pixel(&loaded, &options, x, y, rendered);
            largest = largest.max(verdict.error);
            if verdict.error > TOLERANCE || !verdict.problems.is_empty() || verdict.error.is_nan() {
                failing_pixels += 1;
                if failures.len() < 3 {
                    failures.push(format!(
                        "{path} pixel ({x}, {y}): relative error {:.3e}; {}; deepest wrong node: {}",
                        verdict.error,
                        if verdict.problems.is_empty() {
                            "no wrong decision".to_string()
                        } else {
                            verdict.problems[..verdict.problems.len().min(3)].join("; ")
                        },
                        verdict.worst_node.unwrap_or_else(|| "none".into())
                    ));
                }
            }
        }
    }
    (failures, largest, failing_pixels)
}

#[test]
fn every_scene_re_shaded_in_f64_from_its_ray_trees_matches_the_render() {
    let scenes = feature_scenes();
    assert!(scenes.len() >= 15, "found {} scenes", scenes.len());
    let mut report = Vec::new();
    let mut failures = Vec::new();
    let mut with_priorities = 0;
    for scene in &scenes {
        let name = scene.display().to_string();
        // Every scene is re-shaded: those with priorities through the geometric media model
        // (`Media`), the others through the nested stack.
        with_priorities += usize::from(uses_priorities(&load(&name).scene));
        let (width, height) = (40, 30);
        let (mut found, largest, failing) = check_scene(&name, width, height);
        report.push(format!(
            "{name}: largest error {largest:.2e}, {failing} of {} pixels fail",
            width * height
        ));
        failures.append(&mut found);
    }
    eprintln!("{}", report.join("\n"));
    assert!(
        with_priorities >= 1,
        "no scene with priorities: the glass of water is the oracle's nested-media case"
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The oracle must be able to fail: re-shading a tree against a pixel of another colour, or
/// with the textbook's coefficient changed, is caught.
#[test]
fn the_re_shader_catches_a_wrong_pixel_and_a_wrong_coefficient() {
    let loaded = load("scenes/whitted.scene");
    let options = RenderOptions {
        width: 40,
        height: 30,
        ..RenderOptions::from_settings(&loaded.scene.settings)
    };
    let Some((image, _)) = render(&loaded.prepared, &options, &NoObserver) else {
        panic!("cancelled");
    };
    let mut caught_pixel = 0;
    let mut caught_material = 0;
    let mut lit = 0;
    // A scene whose glass is a little less transparent than the one rendered.
    let mut altered = loaded.scene.scene().clone();
    for i in 0..altered.materials.len() {
        let material = &mut altered.materials[Handle::from_index(i)];
        material.transmissive.g *= 0.99;
        material.diffuse.r *= 0.99;
    }
    let altered = Loaded {
        scene: whitted_ir::validate(altered).unwrap_or_else(|_| panic!("invalid")),
        prepared: whitted_tracer::PreparedScene::new(&loaded.scene),
    };
    for y in (0..30).step_by(3) {
        for x in (0..40).step_by(3) {
            let rendered = image.pixel(x, y).unwrap_or([f32::NAN; 3]);
            if v(rendered).max_element() < 0.05 {
                continue;
            }
            lit += 1;
            let nudged = rendered.map(|c| c + 1e-3);
            if reshade_pixel(&loaded, &options, x, y, nudged).error > TOLERANCE {
                caught_pixel += 1;
            }
            let verdict = reshade_pixel(&altered, &options, x, y, rendered);
            if verdict.error > TOLERANCE {
                caught_material += 1;
            }
        }
    }
    assert!(lit > 50, "{lit}");
    assert_eq!(caught_pixel, lit, "a pixel 1e-3 off must be caught");
    assert!(caught_material > lit / 2, "{caught_material} of {lit}");
}

/// The priority model is needed and is checked: on the glass of water, the plain nested
/// stack (solids that only nest) gets the pixels that look through the glass into the water
/// wrong, and so does the priority model given the scene with the two priorities swapped
/// (the interface where glass touches water is then the water's surface, not the glass's).
#[test]
fn the_re_shader_catches_media_without_priorities_or_with_them_swapped() {
    let loaded = load("scenes/glass-of-water.scene");
    let (width, height) = (40, 30);
    let options = RenderOptions {
        width,
        height,
        ..RenderOptions::from_settings(&loaded.scene.settings)
    };
    let Some((image, _)) = render(&loaded.prepared, &options, &NoObserver) else {
        panic!("cancelled");
    };
    let mut swapped = loaded.scene.scene().clone();
    for i in 0..swapped.materials.len() {
        let material = &mut swapped.materials[Handle::from_index(i)];
        material.priority = match material.priority {
            1 => 2,
            2 => 1,
            other => other,
        };
    }
    let swapped = Loaded {
        scene: whitted_ir::validate(swapped).unwrap_or_else(|_| panic!("invalid")),
        prepared: whitted_tracer::PreparedScene::new(&loaded.scene),
    };
    let (mut right, mut nested_wrong, mut swapped_wrong) = (0, 0, 0);
    let wrong = |v: &PixelVerdict| v.error > TOLERANCE || !v.problems.is_empty();
    for y in 0..height {
        for x in 0..width {
            let rendered = image.pixel(x, y).unwrap_or([f32::NAN; 3]);
            right += usize::from(!wrong(&reshade_pixel(&loaded, &options, x, y, rendered)));
            let nested = reshade_pixel_modelled(&loaded, &options, (x, y), rendered, false);
            nested_wrong += usize::from(wrong(&nested));
            let verdict = reshade_pixel(&swapped, &options, x, y, rendered);
            swapped_wrong += usize::from(wrong(&verdict));
        }
    }
    eprintln!(
        "glass of water: {right} pixels right; without priorities {nested_wrong} wrong, \
         with them swapped {swapped_wrong} wrong"
    );
    assert_eq!(right, (width * height) as usize);
    assert!(nested_wrong > 20, "{nested_wrong}");
    assert!(swapped_wrong > 20, "{swapped_wrong}");
}

#[test]
fn fresnel_formulas_agree_at_normal_incidence_and_reach_one_at_the_critical_angle() {
    let r0 = ((1.5f64 - 1.0) / 2.5).powi(2);
    assert!((schlick(1.0, 1.0, 1.5) - r0).abs() < 1e-12);
    assert!((fresnel_exact(1.0, 1.0, 1.5) - r0).abs() < 1e-12);
    let critical = (1.0f64 / 1.5).asin();
    let just_beyond = (critical + 1e-6).cos();
    assert_eq!(schlick(just_beyond, 1.5, 1.0), 1.0);
    assert_eq!(fresnel_exact(just_beyond, 1.5, 1.0), 1.0);
    // At 60° into glass the exact value is about 0.0898; Schlick's is close to it.
    let cos60 = 60f64.to_radians().cos();
    assert!((fresnel_exact(cos60, 1.0, 1.5) - 0.0898).abs() < 1e-3);
    assert!((schlick(cos60, 1.0, 1.5) - 0.0898).abs() < 2e-2);
}
