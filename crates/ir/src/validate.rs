//! The validator: checks every invariant the tracer relies on and wraps the scene in
//! [`ValidScene`], the only type the tracer accepts, so the tracer never re-checks.

use glam::{DMat4, DVec3};

use crate::arena::Handle;
use crate::diagnostic::Diagnostic;
use crate::limits::{MAX_MESH_TRIANGLES, MAX_NOISE_OCTAVES, MAX_SCENE_TRIANGLES};
use crate::mesh::{BadEdge, NotSolid};
use crate::scene::{
    Attenuation, Color, LightKind, Material, Object, ObjectKind, PatternKind, Projection, Scene,
    Shape,
};
use crate::source::Span;

/// A scene that passed [`validate`]. Dereferences to the [`Scene`].
#[derive(Clone, Debug)]
pub struct ValidScene(Scene);

impl ValidScene {
    pub fn scene(&self) -> &Scene {
        &self.0
    }

    pub fn into_inner(self) -> Scene {
        self.0
    }
}

impl std::ops::Deref for ValidScene {
    type Target = Scene;
    fn deref(&self) -> &Scene {
        &self.0
    }
}

/// A scene that failed validation, returned whole so the caller can still show sources.
#[derive(Debug)]
pub struct InvalidScene {
    pub scene: Scene,
    pub diagnostics: Vec<Diagnostic>,
}

/// The smallest determinant a transform may have before it counts as singular.
const MIN_DETERMINANT: f64 = 1e-12;

/// Checks handles, transforms, shapes, materials, lights, camera and settings.
pub fn validate(scene: Scene) -> Result<ValidScene, Box<InvalidScene>> {
    let mut checker = Checker { errors: Vec::new() };
    checker.settings(&scene);
    checker.camera(&scene);
    for (_, light, span) in scene.lights.iter_with_spans() {
        checker.light(light, span);
    }
    for (handle, material, span) in scene.materials.iter_with_spans() {
        checker.material(&scene, handle, material, span);
    }
    checker.meshes(&scene);
    for (handle, object, span) in scene.objects.iter_with_spans() {
        checker.object(&scene, handle, object, span);
    }
    crate::ranges::check(&scene, &mut checker.errors);
    for &root in &scene.roots {
        if !scene.objects.contains(root) {
            checker.errors.push(Diagnostic::new(
                crate::Severity::Error,
                format!("the scene lists a top-level object {root} that does not exist"),
                None,
            ));
        }
    }
    if checker.errors.is_empty() {
        Ok(ValidScene(scene))
    } else {
        Err(Box::new(InvalidScene {
            scene,
            diagnostics: checker.errors,
        }))
    }
}

struct Checker {
    errors: Vec<Diagnostic>,
}

fn finite(v: DVec3) -> bool {
    v.is_finite()
}

fn color_ok(c: &Color) -> bool {
    c.components().iter().all(|v| v.is_finite() && *v >= 0.0)
}

impl Checker {
    fn error(&mut self, message: String, span: Span) {
        self.errors.push(Diagnostic::error(message, span));
    }

    fn settings(&mut self, scene: &Scene) {
        let s = &scene.settings;
        let span = Span::detached();
        if s.width == 0 || s.height == 0 {
            self.error(
                format!("the image size {}x{} is empty", s.width, s.height),
                span,
            );
        }
        if s.samples_per_pixel == 0 {
            self.error("samples per pixel must be at least 1".into(), span);
        }
        if !(s.min_weight.is_finite() && s.min_weight >= 0.0) {
            self.error(
                format!("the minimum path weight must be >= 0, not {}", s.min_weight),
                span,
            );
        }
        // 0 is allowed: no offset at all, the classic acne (a student bug `whitted grade`
        // renders).
        if let Some(epsilon) = s.epsilon.filter(|e| !(e.is_finite() && *e >= 0.0)) {
            self.error(
                format!("the surface offset epsilon must be >= 0, not {epsilon}"),
                span,
            );
        }
        if !color_ok(&s.background) {
            self.error("the background colour must be finite and >= 0".into(), span);
        }
        if !color_ok(&s.ambient) {
            self.error(
                "the global ambient light must be finite and >= 0".into(),
                span,
            );
        }
    }

    fn camera(&mut self, scene: &Scene) {
        let camera = &scene.camera;
        let span = scene.camera_span;
        if !(finite(camera.eye) && finite(camera.look_at) && finite(camera.up)) {
            self.error(
                "the camera has a coordinate that is not a finite number".into(),
                span,
            );
            return;
        }
        let view = camera.look_at - camera.eye;
        if view.length() < 1e-12 {
            self.error(
                "the camera looks at its own eye point: `eye` and `look_at` are equal".into(),
                span,
            );
        } else if view.normalize().cross(camera.up).length() < 1e-9 {
            // The world axis most across the view is an `up` that works.
            let d = view.normalize().abs();
            let across = if d.y <= d.x && d.y <= d.z {
                "<0, 1, 0>"
            } else if d.z <= d.x {
                "<0, 0, 1>"
            } else {
                "<1, 0, 0>"
            };
            self.errors.push(
                Diagnostic::error("the camera's `up` is parallel to its view direction", span)
                    .with_label("looks straight along `up`")
                    .with_hint(format!(
                        "the image's vertical is undefined when the camera looks along `up`: \
                         give the camera `up {across}`, or move `eye` off the line to `look_at`"
                    )),
            );
        }
        match camera.projection {
            Projection::Perspective {
                vertical_fov_degrees: fov,
            } => {
                if !(fov > 0.0 && fov < 180.0) {
                    self.error(
                        format!("the field of view must be between 0 and 180 degrees, not {fov}"),
                        span,
                    );
                }
            }
            Projection::Orthographic { view_height } => {
                if !(view_height.is_finite() && view_height > 0.0) {
                    self.error(
                        format!("the orthographic view height must be > 0, not {view_height}"),
                        span,
                    );
                }
            }
        }
    }

    fn attenuation(&mut self, a: &Attenuation, span: Span) {
        let terms = [a.constant, a.linear, a.quadratic];
        if terms.iter().any(|t| !t.is_finite() || *t < 0.0) {
            self.error("attenuation terms must be finite and >= 0".into(), span);
        } else if terms.iter().all(|t| *t == 0.0) {
            self.error(
                "attenuation terms cannot all be zero (the light would be infinitely bright)"
                    .into(),
                span,
            );
        }
    }

    fn light(&mut self, light: &crate::Light, span: Span) {
        if !color_ok(&light.color) {
            self.error("a light's colour must be finite and >= 0".into(), span);
        }
        match &light.kind {
            LightKind::Point {
                position,
                attenuation,
            } => {
                if !finite(*position) {
                    self.error("the light's position is not finite".into(), span);
                }
                self.attenuation(attenuation, span);
            }
            LightKind::Directional { direction } => {
                if !finite(*direction) || direction.length() < 1e-12 {
                    self.error(
                        "a directional light needs a non-zero direction".into(),
                        span,
                    );
                }
            }
            LightKind::Spot {
                position,
                direction,
                inner_angle_degrees,
                outer_angle_degrees,
                attenuation,
            } => {
                if !finite(*position) {
                    self.error("the light's position is not finite".into(), span);
                }
                if !finite(*direction) || direction.length() < 1e-12 {
                    self.error("a spot light needs a non-zero direction".into(), span);
                }
                let (inner, outer) = (*inner_angle_degrees, *outer_angle_degrees);
                if !(inner >= 0.0 && inner <= outer && outer < 180.0) {
                    self.error(format!(
                        "a spot light needs 0 <= inner <= outer < 180 degrees, not inner {inner} and outer {outer}"
                    ), span);
                }
                self.attenuation(attenuation, span);
            }
        }
    }

    fn material(&mut self, scene: &Scene, handle: Handle<Material>, m: &Material, span: Span) {
        for row in crate::properties::MATERIAL_COLORS {
            let field = row.name;
            if !color_ok(&(row.get)(m)) {
                self.error(
                    format!("the material's {field} coefficient must be finite and >= 0"),
                    span,
                );
            }
        }
        if !(m.shininess.is_finite() && m.shininess >= 0.0) {
            self.error(format!("shininess must be >= 0, not {}", m.shininess), span);
        }
        if !(m.ior.is_finite() && m.ior > 0.0) {
            self.error(
                format!("the index of refraction must be > 0, not {}", m.ior),
                span,
            );
        }
        if let Some(pattern) = &m.pattern {
            for part in [pattern.a, pattern.b] {
                if part >= handle {
                    self.error(
                        format!(
                            "a pattern refers to material {part}, which is not defined before it"
                        ),
                        span,
                    );
                } else if !scene.materials.contains(part) {
                    self.error(
                        format!("a pattern refers to a missing material {part}"),
                        span,
                    );
                }
            }
            if !(pattern.scale.is_finite() && pattern.scale > 0.0) {
                self.error(
                    format!("a pattern's scale must be > 0, not {}", pattern.scale),
                    span,
                );
            }
            self.transform(&pattern.pattern_from_object, "pattern transform", span);
            if let Some(octaves) = pattern.kind.octaves() {
                if !(1..=MAX_NOISE_OCTAVES).contains(&octaves) {
                    self.error(
                        format!(
                            "a noise pattern's octaves must be 1 to {MAX_NOISE_OCTAVES} (the \
                             `noise octaves` limit), not {octaves}"
                        ),
                        span,
                    );
                }
            }
            if let PatternKind::CourseMarble {
                frequency,
                amplitude,
                ..
            }
            | PatternKind::CourseWood {
                frequency,
                amplitude,
                ..
            } = pattern.kind
            {
                if !(frequency.is_finite() && amplitude.is_finite()) {
                    self.error(
                        format!(
                            "a pattern's frequency and amplitude must be finite, not \
                             {frequency} and {amplitude}"
                        ),
                        span,
                    );
                }
            }
            if pattern.kind.blends() && pattern.a < handle && pattern.b < handle {
                for part in [pattern.a, pattern.b] {
                    if let Some(inner) = blend_within(scene, part) {
                        let through = if inner == part {
                            String::new()
                        } else {
                            format!(" (through material {inner})")
                        };
                        self.error(
                            format!(
                                "a blending pattern's material {part} blends materials \
                                 itself{through}: a blend of blends is not supported"
                            ),
                            span,
                        );
                    }
                }
            }
        }
    }

    fn transform(&mut self, m: &DMat4, what: &str, span: Span) {
        if !m.is_finite() {
            self.error(format!("the {what} has a number that is not finite"), span);
        } else if m.row(3) != glam::DVec4::W {
            // The tracer maps rays with the affine part only; a projective matrix would be
            // silently misread, so it is refused here.
            self.error(
                format!(
                    "the {what} is projective: its last row must be 0, 0, 0, 1 (whitted supports affine transforms only)"
                ),
                span,
            );
        } else if m.determinant().abs() < MIN_DETERMINANT {
            self.error(
                format!("the {what} is not invertible (a scale by zero flattens the object)"),
                span,
            );
        }
    }

    fn object(&mut self, scene: &Scene, handle: Handle<Object>, object: &Object, span: Span) {
        self.transform(&object.world_from_object, "object's transform", span);
        if !scene.materials.contains(object.material) {
            self.error(
                format!(
                    "the object refers to a missing material {}",
                    object.material
                ),
                span,
            );
        }
        match &object.kind {
            ObjectKind::Shape { shape } => match shape.get() {
                Shape::Mesh { mesh, .. } => {
                    if !scene.meshes.contains(mesh) {
                        self.error(format!("the object refers to a missing mesh {mesh}"), span);
                    }
                }
                shape => self.shape(&shape, span),
            },
            ObjectKind::Csg { op, children } => {
                if children.is_empty() {
                    self.error(format!("this {} has no children", op.name()), span);
                }
                for &child in children {
                    if !self.child_ok(scene, handle, child, span) {
                        continue;
                    }
                    if !is_solid(scene, child) {
                        let child_span = scene.objects.span(child);
                        // A mesh says why it is not a solid, with an edge and its face.
                        let why = match scene.objects[child].kind.shape() {
                            Some(Shape::Mesh { mesh, .. }) => {
                                scene.meshes.get(mesh).and_then(|m| m.not_solid.as_ref())
                            }
                            _ => None,
                        };
                        // `an intersection`, but `a union` (its first sound is a consonant).
                        let article = if op.name().starts_with(['a', 'e', 'i', 'o']) {
                            "an"
                        } else {
                            "a"
                        };
                        let message = match why {
                            Some(why) => format!(
                                "{article} {} needs solid children, and this mesh {}",
                                op.name(),
                                why.describe()
                            ),
                            None => format!(
                                "{article} {} needs solid children, and this is not a solid",
                                op.name()
                            ),
                        };
                        let mut diagnostic = Diagnostic::error(message, child_span)
                            .with_secondary(span, "in this CSG operation");
                        if let Some(NotSolid::Edge(BadEdge {
                            face, other_face, ..
                        })) = why
                        {
                            for face in face.iter().chain(other_face) {
                                diagnostic =
                                    diagnostic.with_secondary(*face, "a face with that edge");
                            }
                        }
                        self.errors.push(diagnostic.with_hint("disks, triangles, open cylinders and cones, open meshes, and groups have no inside; use a capped shape, a closed mesh or a union"));
                    }
                }
            }
            ObjectKind::Group { children } => {
                for &child in children {
                    self.child_ok(scene, handle, child, span);
                }
            }
        }
    }

    fn child_ok(
        &mut self,
        scene: &Scene,
        parent: Handle<Object>,
        child: Handle<Object>,
        span: Span,
    ) -> bool {
        if child >= parent || !scene.objects.contains(child) {
            self.error(
                format!("object {parent} has a child {child} that is not defined before it"),
                span,
            );
            return false;
        }
        true
    }

    /// Every mesh: indices in range, numbers finite, not empty, within the triangle limits.
    /// Each problem is reported once per mesh, at the first object that uses it (the
    /// `file` property's place), naming the file.
    fn meshes(&mut self, scene: &Scene) {
        let mut total = 0usize;
        for (_, mesh, span) in scene.meshes.iter_with_spans() {
            let file = &mesh.file;
            let count = mesh.triangles.len();
            total = total.saturating_add(count);
            if count == 0 {
                self.error(format!("the mesh `{file}` has no triangles"), span);
            }
            if count > MAX_MESH_TRIANGLES {
                self.error(
                    format!("the mesh `{file}` has {count} triangles, over the mesh triangles limit of {MAX_MESH_TRIANGLES}"),
                    span,
                );
            }
            let vertices = mesh.positions.len();
            if let Some((i, t)) = mesh
                .triangles
                .iter()
                .enumerate()
                .find(|(_, t)| t.iter().any(|&k| k as usize >= vertices))
            {
                self.error(
                    format!(
                        "the mesh `{file}`'s triangle {i} uses vertex {} of {vertices}",
                        t.iter().copied().max().unwrap_or(0)
                    ),
                    span,
                );
            }
            if !mesh.normals.is_empty() && mesh.normals.len() != vertices {
                self.error(
                    format!(
                        "the mesh `{file}` has {} normals for {vertices} vertices",
                        mesh.normals.len()
                    ),
                    span,
                );
            }
            for (what, list) in [("vertex", &mesh.positions), ("normal", &mesh.normals)] {
                if let Some(i) = list.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
                    self.error(
                        format!("the mesh `{file}`'s {what} {i} is not finite"),
                        span,
                    );
                }
            }
        }
        if total > MAX_SCENE_TRIANGLES {
            self.error(
                format!("the scene's meshes have {total} triangles, over the scene triangles limit of {MAX_SCENE_TRIANGLES}"),
                Span::detached(),
            );
        }
    }

    fn shape(&mut self, shape: &Shape, span: Span) {
        let bad = |ok: bool, message: &str, this: &mut Self| {
            if !ok {
                this.error(message.to_string(), span);
            }
        };
        match shape {
            Shape::Sphere { center, radius } => {
                bad(finite(*center), "the sphere's centre is not finite", self);
                bad(
                    radius.is_finite() && *radius > 0.0,
                    "a sphere's radius must be > 0",
                    self,
                );
            }
            Shape::Plane { normal, offset } => {
                bad(
                    finite(*normal) && normal.length() > 1e-12,
                    "a plane needs a non-zero normal",
                    self,
                );
                bad(offset.is_finite(), "the plane's offset is not finite", self);
            }
            Shape::Box { min, max } => {
                bad(
                    finite(*min) && finite(*max),
                    "the box's corners are not finite",
                    self,
                );
                bad(
                    min.cmplt(*max).all(),
                    "a box needs min < max on every axis (it has no volume)",
                    self,
                );
            }
            Shape::Cylinder {
                base, apex, radius, ..
            } => {
                bad(
                    finite(*base) && finite(*apex),
                    "the cylinder's end points are not finite",
                    self,
                );
                bad(
                    (*apex - *base).length() > 1e-12,
                    "a cylinder's two end points must differ",
                    self,
                );
                bad(
                    radius.is_finite() && *radius > 0.0,
                    "a cylinder's radius must be > 0",
                    self,
                );
            }
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
                ..
            } => {
                bad(
                    finite(*base) && finite(*apex),
                    "the cone's end points are not finite",
                    self,
                );
                bad(
                    (*apex - *base).length() > 1e-12,
                    "a cone's two end points must differ",
                    self,
                );
                bad(
                    base_radius.is_finite()
                        && apex_radius.is_finite()
                        && *base_radius >= 0.0
                        && *apex_radius >= 0.0,
                    "a cone's radii must be >= 0",
                    self,
                );
                bad(
                    *base_radius != *apex_radius,
                    "a cone with equal radii is a cylinder: use `cylinder`",
                    self,
                );
            }
            Shape::Disk {
                center,
                normal,
                radius,
            } => {
                bad(finite(*center), "the disk's centre is not finite", self);
                bad(
                    finite(*normal) && normal.length() > 1e-12,
                    "a disk needs a non-zero normal",
                    self,
                );
                bad(
                    radius.is_finite() && *radius > 0.0,
                    "a disk's radius must be > 0",
                    self,
                );
            }
            Shape::Triangle { a, b, c } => {
                bad(
                    finite(*a) && finite(*b) && finite(*c),
                    "the triangle's corners are not finite",
                    self,
                );
                bad(
                    (*b - *a).cross(*c - *a).length() > 1e-14,
                    "the triangle is degenerate (its corners are in a line)",
                    self,
                );
            }
            // Checked with its mesh in `meshes`.
            Shape::Mesh { .. } => {}
            Shape::Torus { major, minor } => {
                bad(
                    major.is_finite() && *major > 0.0,
                    "a torus's `major` radius must be > 0",
                    self,
                );
                bad(
                    minor.is_finite() && *minor > 0.0,
                    "a torus's `minor` radius must be > 0",
                    self,
                );
            }
            Shape::Quadric { quadric, .. } => {
                let c = quadric.coefficients();
                bad(
                    c.iter().all(|v| v.is_finite()),
                    "the quadric has a coefficient that is not finite",
                    self,
                );
                bad(
                    c[..6].iter().any(|v| *v != 0.0),
                    "the quadric is degenerate: A to F are all zero, so it is a plane or nothing (use `plane`)",
                    self,
                );
            }
        }
    }
}

fn is_solid(scene: &Scene, handle: Handle<Object>) -> bool {
    match &scene.objects[handle].kind {
        ObjectKind::Shape { shape } => scene.is_solid_shape(&shape.get()),
        ObjectKind::Csg { .. } => true,
        ObjectKind::Group { .. } => false,
    }
}

/// The first material with a blending pattern that `start` reaches through choosing
/// patterns (itself included): the tracer blends two materials that are each resolved by
/// choices alone. Parts come earlier in the arena, so the walk ends; each material is
/// visited once.
fn blend_within(scene: &Scene, start: Handle<Material>) -> Option<Handle<Material>> {
    let mut seen = vec![false; scene.materials.len()];
    let mut stack = vec![start];
    while let Some(h) = stack.pop() {
        if seen.get(h.index()).copied().unwrap_or(true) {
            continue;
        }
        seen[h.index()] = true;
        let Some(pattern) = scene.materials.get(h).and_then(|m| m.pattern.as_ref()) else {
            continue;
        };
        if pattern.kind.blends() {
            return Some(h);
        }
        stack.extend([pattern.a, pattern.b].into_iter().filter(|p| *p < h));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Fresnel, WorldFromObject};
    use crate::source::FileId;

    fn span(n: usize) -> Span {
        Span::new(FileId(0), n, n + 1)
    }

    fn scene_with(shape: Shape) -> Scene {
        let mut scene = Scene::default();
        let material = scene.materials.append(Material::default(), span(0));
        let object = scene.objects.append(
            Object {
                name: None,
                kind: ObjectKind::Shape {
                    shape: shape.into(),
                },
                world_from_object: WorldFromObject::IDENTITY,
                material,
            },
            span(1),
        );
        scene.roots.push(object);
        scene
    }

    fn errors(scene: Scene) -> Vec<String> {
        match validate(scene) {
            Ok(_) => Vec::new(),
            Err(invalid) => invalid.diagnostics.into_iter().map(|d| d.message).collect(),
        }
    }

    /// A scene with a chain of patterns: each of `kinds` over the one before it (the first
    /// over a plain material) and a second plain material.
    fn patterned(kinds: &[PatternKind]) -> Scene {
        let mut scene = scene_with(Shape::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
        });
        let mut last = scene.materials.append(Material::default(), span(2));
        let plain = scene.materials.append(Material::default(), span(3));
        for (i, kind) in kinds.iter().enumerate() {
            last = scene.materials.append(
                Material {
                    pattern: Some(crate::scene::Pattern {
                        kind: *kind,
                        a: last,
                        b: plain,
                        scale: 1.0,
                        pattern_from_object: DMat4::IDENTITY,
                    }),
                    ..Material::default()
                },
                span(4 + i),
            );
        }
        scene
    }

    #[test]
    fn course_patterns_are_checked() {
        let noise = |octaves| PatternKind::CourseNoise { octaves };
        assert!(errors(patterned(&[noise(1), PatternKind::CourseCheckerboard])).is_empty());
        assert!(errors(patterned(&[PatternKind::CourseCheckerboard, noise(16)])).is_empty());
        for octaves in [0, 17, u32::MAX] {
            assert_eq!(
                errors(patterned(&[noise(octaves)])),
                [format!(
                    "a noise pattern's octaves must be 1 to 16 (the `noise octaves` limit), \
                     not {octaves}"
                )]
            );
        }
        assert_eq!(
            errors(patterned(&[noise(2), noise(3)])),
            [
                "a blending pattern's material #3 blends materials itself: a blend of blends is \
              not supported"
            ]
        );
        assert_eq!(
            errors(patterned(&[
                noise(2),
                PatternKind::CourseCheckerboard,
                noise(3)
            ])),
            [
                "a blending pattern's material #4 blends materials itself (through material #3): \
              a blend of blends is not supported"
            ]
        );
        let marble = PatternKind::CourseMarble {
            octaves: 2,
            frequency: f64::NAN,
            amplitude: 1.0,
        };
        assert_eq!(
            errors(patterned(&[marble])),
            ["a pattern's frequency and amplitude must be finite, not NaN and 1"]
        );
    }

    #[test]
    fn a_simple_scene_is_valid() {
        assert!(errors(scene_with(Shape::Sphere {
            center: DVec3::ZERO,
            radius: 1.0
        }))
        .is_empty());
    }

    #[test]
    fn degenerate_shapes_are_rejected() {
        let cases = [
            Shape::Sphere {
                center: DVec3::ZERO,
                radius: 0.0,
            },
            Shape::Box {
                min: DVec3::ONE,
                max: DVec3::ONE,
            },
            Shape::Quadric {
                form: crate::QuadricForm::General,
                quadric: Quadric::from_coefficients([
                    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0,
                ]),
            },
            Shape::Triangle {
                a: DVec3::ZERO,
                b: DVec3::X,
                c: DVec3::X * 2.0,
            },
            Shape::Plane {
                normal: DVec3::ZERO,
                offset: 0.0,
            },
        ];
        for shape in cases {
            let name = shape.kind_name();
            assert_eq!(
                errors(scene_with(shape)).len(),
                1,
                "{name} should give one error"
            );
        }
    }

    use crate::scene::Quadric;

    #[test]
    fn singular_transform_and_bad_material_are_reported_together() {
        let mut scene = scene_with(Shape::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
        });
        scene.objects[Handle::from_index(0)].world_from_object =
            DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0)).into();
        let m = &mut scene.materials[Handle::from_index(0)];
        m.ior = 0.0;
        m.diffuse = Color::new(-1.0, 0.0, 0.0);
        m.fresnel = Fresnel::Schlick;
        let messages = errors(scene);
        assert_eq!(messages.len(), 3, "{messages:?}");
        assert!(messages.iter().any(|m| m.contains("not invertible")));
        assert!(messages.iter().any(|m| m.contains("index of refraction")));
        assert!(messages.iter().any(|m| m.contains("diffuse")));
    }

    #[test]
    fn csg_children_must_be_solid_and_defined_first() {
        let mut scene = scene_with(Shape::Disk {
            center: DVec3::ZERO,
            normal: DVec3::Y,
            radius: 1.0,
        });
        let disk = Handle::from_index(0);
        let material = Handle::from_index(0);
        let csg = scene.objects.append(
            Object {
                name: None,
                kind: ObjectKind::Csg {
                    op: crate::CsgOp::Union,
                    children: vec![disk],
                },
                world_from_object: WorldFromObject::IDENTITY,
                material,
            },
            span(2),
        );
        scene.roots = vec![csg];
        let messages = errors(scene.clone());
        assert_eq!(messages.len(), 1);
        assert!(messages[0].contains("solid"));
        // A forward reference (a cycle in the making) is refused.
        scene.objects[disk].kind = ObjectKind::Group {
            children: vec![csg],
        };
        assert!(errors(scene)
            .iter()
            .any(|m| m.contains("not defined before")));
    }

    #[test]
    fn projective_transforms_are_rejected() {
        let mut scene = scene_with(Shape::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
        });
        let mut m = DMat4::IDENTITY;
        m.x_axis.w = 0.5; // row 3, column 0
        scene.objects[Handle::from_index(0)].world_from_object = m.into();
        let messages = errors(scene);
        assert_eq!(messages.len(), 1);
        assert!(messages[0].contains("projective"), "{messages:?}");
    }

    #[test]
    fn degenerate_camera_is_rejected() {
        let mut scene = scene_with(Shape::Sphere {
            center: DVec3::ZERO,
            radius: 1.0,
        });
        scene.camera.look_at = scene.camera.eye;
        assert_eq!(errors(scene.clone()).len(), 1);
        scene.camera.look_at = DVec3::ZERO;
        scene.camera.up = DVec3::Z;
        assert!(errors(scene)[0].contains("parallel"));
    }
}
