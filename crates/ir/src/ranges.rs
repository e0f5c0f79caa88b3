//! The number ranges of [`crate::limits`], checked for validation: every number that the
//! tracer turns into f32 stays finite there, and so do the products it forms from them
//! (intensity times coefficient, squared coordinates in a shape's own space).
//!
//! Each error names the property, its value and the limit in words, at the value where the
//! scene wrote it (the scene's table of written properties) or else at the light, material,
//! object or camera that has it.

use glam::{DMat4, DVec3};

use crate::diagnostic::Diagnostic;
use crate::limits::{
    MAX_COORDINATE, MAX_DEPTH, MAX_FILTERED_SAMPLES, MAX_IMAGE_SIDE, MAX_INTENSITY, MAX_IOR,
    MAX_PIXELS, MAX_SAMPLES_PER_PIXEL, MIN_IOR, MIN_SIZE,
};
use crate::scene::{Color, LightKind, Material, Object, Projection, Scene, Shape};
use crate::source::Span;
use crate::written::{BlockKind, Written};

/// Checks every number of `scene` against its limit, adding an error for each that is out.
pub(crate) fn check(scene: &Scene, errors: &mut Vec<Diagnostic>) {
    let mut ranges = Ranges {
        errors,
        written: &scene.written,
    };
    ranges.settings(scene);
    let camera = &scene.camera;
    let span = scene.camera_span;
    for (what, v) in [
        ("camera's `eye`", camera.eye),
        ("camera's `look_at`", camera.look_at),
        ("camera's `up`", camera.up),
    ] {
        ranges.vector(what, v, span);
    }
    if let Projection::Orthographic { view_height } = camera.projection {
        ranges.size("camera's `height`", view_height, span);
    }
    for (_, light, span) in scene.lights.iter_with_spans() {
        ranges.written_color(
            (BlockKind::Light, span, "color"),
            || "light's `color`".to_string(),
            &light.color,
            MAX_INTENSITY,
            "largest intensity",
        );
        match &light.kind {
            LightKind::Point {
                position,
                attenuation,
            } => {
                ranges.vector("light's `position`", *position, span);
                ranges.attenuation(attenuation, span);
            }
            LightKind::Directional { direction } => {
                ranges.vector("light's `direction`", *direction, span);
            }
            LightKind::Spot {
                position,
                direction,
                attenuation,
                ..
            } => {
                ranges.vector("light's `position`", *position, span);
                ranges.vector("light's `direction`", *direction, span);
                ranges.attenuation(attenuation, span);
            }
        }
    }
    for (_, material, span) in scene.materials.iter_with_spans() {
        ranges.material(material, span);
    }
    // Each mesh's box once, however many objects instance it.
    let mesh_boxes: Vec<Option<(DVec3, DVec3)>> =
        scene.meshes.iter().map(|(_, mesh)| mesh.bounds()).collect();
    for (_, mesh, span) in scene.meshes.iter_with_spans() {
        if let Some((lo, hi)) = mesh.bounds() {
            let what = format!("mesh `{}`'s vertex", mesh.file);
            ranges.vector(&what, lo, span);
            ranges.vector(&what, hi, span);
        }
    }
    for (_, object, span) in scene.objects.iter_with_spans() {
        ranges.object(object, &mesh_boxes, span);
    }
}

struct Ranges<'a> {
    errors: &'a mut Vec<Diagnostic>,
    written: &'a Written,
}

/// A number as a message shows it: plain unless very large or very small (`90`, `0.001`,
/// `1e12`).
fn shown(value: f64) -> String {
    let magnitude = value.abs();
    if magnitude == 0.0 || (1e-4..1e7).contains(&magnitude) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

impl Ranges<'_> {
    fn out_of_range(&mut self, what: &str, value: f64, rule: String, span: Span) {
        let value = shown(value);
        self.errors.push(
            Diagnostic::error(format!("the {what} is {value}, {rule}"), span)
                .with_hint("see \"Limits\" in docs/language.md"),
        );
    }

    /// Where the block of `kind` made at `header` wrote `name`'s value, if it did.
    fn value_of(&self, kind: BlockKind, header: Span, name: &str) -> Option<Span> {
        self.written
            .properties_in(kind, header, name)
            .last()
            .map(|p| p.value_span)
    }

    /// A colour past its limit: at the value when the scene wrote it, with the range in words.
    /// `what` names it, made only for a message: formatting the name of every material's
    /// every colour up front was a sixth of `whitted check`'s instructions on 1,000 materials.
    fn written_color(
        &mut self,
        (kind, header, name): (BlockKind, Span, &str),
        what: impl Fn() -> String,
        c: &Color,
        max: f64,
        limit: &str,
    ) {
        let Some(value) = c
            .components()
            .into_iter()
            .find(|v| v.is_finite() && *v > max)
        else {
            return;
        };
        let what = what();
        let what = what.as_str();
        let Some(at) = self.value_of(kind, header, name) else {
            self.color(what, c, max, limit, header);
            return;
        };
        let fraction = if max == 1.0 {
            format!(
                " (a fraction of the light: {} for {}%)",
                shown(value / 100.0),
                shown(value)
            )
        } else {
            String::new()
        };
        self.errors.push(
            Diagnostic::error(
                format!(
                    "the {what} is {}, past the {limit} limit ({})",
                    shown(value),
                    shown(max)
                ),
                at,
            )
            .with_label(format!("{} here", shown(value)))
            .with_hint(format!(
                "`{name}` takes a colour whose components are each from 0 to {}{fraction}",
                shown(max)
            )),
        );
    }

    /// A finite number whose magnitude is at most `max` (NaN and infinity are other checks').
    fn at_most(&mut self, what: &str, value: f64, max: f64, limit: &str, span: Span) {
        if value.is_finite() && value.abs() > max {
            let rule = format!("past the {limit} limit ({max:e})");
            self.out_of_range(what, value, rule, span);
        }
    }

    fn coordinate(&mut self, what: &str, value: f64, span: Span) {
        self.at_most(what, value, MAX_COORDINATE, "largest coordinate", span);
    }

    fn vector(&mut self, what: &str, v: DVec3, span: Span) {
        for value in v.to_array() {
            if value.is_finite() && value.abs() > MAX_COORDINATE {
                self.coordinate(what, value, span);
                return;
            }
        }
    }

    /// A size: positive sizes are at least [`MIN_SIZE`] and at most [`MAX_COORDINATE`].
    fn size(&mut self, what: &str, value: f64, span: Span) {
        if value > 0.0 && value < MIN_SIZE {
            let rule = format!("below the smallest size limit ({MIN_SIZE:e})");
            self.out_of_range(what, value, rule, span);
        }
        self.coordinate(what, value, span);
    }

    fn color(&mut self, what: &str, c: &Color, max: f64, limit: &str, span: Span) {
        for value in c.components() {
            if value.is_finite() && value > max {
                self.at_most(what, value, max, limit, span);
                return;
            }
        }
    }

    fn matrix(&mut self, what: &str, m: &DMat4, span: Span) {
        for value in m.to_cols_array() {
            if value.is_finite() && value.abs() > MAX_COORDINATE {
                self.coordinate(what, value, span);
                return;
            }
        }
    }

    fn settings(&mut self, scene: &Scene) {
        // The language checks each setting where it is written; these are for scenes made
        // another way, so they have no place to point at.
        let s = &scene.settings;
        let span = Span::detached();
        let counts = [
            (
                "image width",
                u64::from(s.width),
                u64::from(MAX_IMAGE_SIDE),
                "image side",
            ),
            (
                "image height",
                u64::from(s.height),
                u64::from(MAX_IMAGE_SIDE),
                "image side",
            ),
            (
                "image's pixel count",
                u64::from(s.width) * u64::from(s.height),
                MAX_PIXELS,
                "pixels",
            ),
            (
                "samples per pixel",
                u64::from(s.samples_per_pixel),
                u64::from(MAX_SAMPLES_PER_PIXEL),
                "samples per pixel",
            ),
            (
                "`max_depth`",
                u64::from(s.max_depth),
                u64::from(MAX_DEPTH),
                "max depth",
            ),
        ];
        // Only a filter that reaches past the pixel keeps the samples.
        let filtered_samples = if s.filter_is_own_pixel() {
            0
        } else {
            u64::from(s.width) * u64::from(s.height) * u64::from(s.samples_per_pixel)
        };
        let counts = counts.into_iter().chain([(
            "number of samples to filter (width times height times samples)",
            filtered_samples,
            MAX_FILTERED_SAMPLES,
            "filtered samples",
        )]);
        for (what, value, max, limit) in counts {
            if value > max {
                self.errors.push(Diagnostic::error(
                    format!("the {what} is {value}, past the {limit} limit ({max})"),
                    span,
                ));
            }
        }
        let radius = s.filter_radius;
        if !(radius.is_finite() && radius > 0.0 && radius <= crate::limits::MAX_FILTER_RADIUS) {
            self.errors.push(Diagnostic::error(
                format!(
                    "the `filter_radius` is {radius}: it must be above 0 and at most the filter \
                     radius limit ({})",
                    crate::limits::MAX_FILTER_RADIUS
                ),
                span,
            ));
        }
        // Unset, the tracer bounds the offset by the hit point's rounding error itself.
        // 0 (no offset, the classic acne) is allowed; between 0 and the smallest size, not.
        if let Some(epsilon) = s.epsilon {
            let at = self
                .written
                .setting("epsilon")
                .map_or(span, |p| p.value_span);
            self.size("`epsilon`", epsilon, at);
        }
        self.color(
            "`background`",
            &s.background,
            MAX_INTENSITY,
            "largest intensity",
            span,
        );
        self.color(
            "`ambient` light",
            &s.ambient,
            MAX_INTENSITY,
            "largest intensity",
            span,
        );
    }

    fn attenuation(&mut self, a: &crate::scene::Attenuation, span: Span) {
        for value in [a.constant, a.linear, a.quadratic] {
            self.coordinate("light's `attenuation` term", value, span);
        }
    }

    fn material(&mut self, m: &Material, span: Span) {
        // Intensities first, then reflectances: the order these messages always came in.
        for limit in [crate::properties::INTENSITY, crate::properties::REFLECTANCE] {
            for row in crate::properties::MATERIAL_COLORS {
                if row.limit == limit {
                    let what = || format!("material's `{}`", row.name);
                    let at = (BlockKind::Material, span, row.name);
                    self.written_color(at, what, &(row.get)(m), limit.max, limit.name);
                }
            }
        }
        self.at_most(
            "material's `shininess`",
            m.shininess,
            MAX_INTENSITY,
            "largest intensity",
            span,
        );
        if m.ior.is_finite() && m.ior > 0.0 {
            if m.ior < MIN_IOR {
                let rule = format!("below the smallest ior limit ({MIN_IOR:e})");
                self.out_of_range("material's `ior`", m.ior, rule, span);
            }
            self.at_most("material's `ior`", m.ior, MAX_IOR, "largest ior", span);
        }
        if let Some(pattern) = &m.pattern {
            self.size("pattern's scale", pattern.scale, span);
            self.matrix("pattern transform", &pattern.pattern_from_object, span);
            if let crate::scene::PatternKind::CourseMarble {
                frequency,
                amplitude,
                ..
            }
            | crate::scene::PatternKind::CourseWood {
                frequency,
                amplitude,
                ..
            } = pattern.kind
            {
                self.coordinate("pattern's frequency", frequency, span);
                self.coordinate("pattern's amplitude", amplitude, span);
            }
        }
    }

    fn object(&mut self, object: &Object, mesh_boxes: &[Option<(DVec3, DVec3)>], span: Span) {
        let m = &object.world_from_object;
        self.matrix("object's transform", m, span);
        let Some(shape) = &object.kind.shape() else {
            return;
        };
        // The shape's own numbers, then its box in world space.
        let local_box = match shape {
            Shape::Sphere { center, radius } => {
                self.vector("sphere's `center`", *center, span);
                self.size("sphere's `radius`", *radius, span);
                Some((
                    *center - DVec3::splat(*radius),
                    *center + DVec3::splat(*radius),
                ))
            }
            Shape::Plane { normal, offset } => {
                self.vector("plane's `normal`", *normal, span);
                self.coordinate("plane's `offset`", *offset, span);
                let length = normal.length_squared();
                let point = *normal * (*offset / length);
                (length > 0.0).then_some((point, point))
            }
            Shape::Box { min, max } => {
                self.vector("box's `min`", *min, span);
                self.vector("box's `max`", *max, span);
                let side = (*max - *min).min_element();
                if side > 0.0 {
                    self.size("box's smallest side", side, span);
                }
                Some((*min, *max))
            }
            Shape::Cylinder {
                base, apex, radius, ..
            } => {
                self.vector("cylinder's `base`", *base, span);
                self.vector("cylinder's `apex`", *apex, span);
                self.size("cylinder's `radius`", *radius, span);
                self.size("cylinder's length", (*apex - *base).length(), span);
                let r = DVec3::splat(*radius);
                Some((base.min(*apex) - r, base.max(*apex) + r))
            }
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
                ..
            } => {
                self.vector("cone's `base`", *base, span);
                self.vector("cone's `apex`", *apex, span);
                self.size("cone's larger radius", base_radius.max(*apex_radius), span);
                self.size("cone's length", (*apex - *base).length(), span);
                let r = DVec3::splat(base_radius.max(*apex_radius));
                Some((base.min(*apex) - r, base.max(*apex) + r))
            }
            Shape::Disk {
                center,
                normal,
                radius,
            } => {
                self.vector("disk's `center`", *center, span);
                self.vector("disk's `normal`", *normal, span);
                self.size("disk's `radius`", *radius, span);
                let r = DVec3::splat(*radius);
                Some((*center - r, *center + r))
            }
            Shape::Triangle { a, b, c } => {
                for corner in [a, b, c] {
                    self.vector("triangle's corner", *corner, span);
                }
                Some((a.min(*b).min(*c), a.max(*b).max(*c)))
            }
            Shape::Quadric { quadric, .. } => {
                for value in quadric.coefficients() {
                    self.coordinate("quadric's coefficient", value, span);
                }
                None
            }
            Shape::Mesh { mesh, .. } => mesh_boxes.get(mesh.index()).copied().flatten(),
            Shape::Torus { major, minor } => {
                self.size("torus's `major` radius", *major, span);
                self.size("torus's `minor` radius", *minor, span);
                let outer = major + minor;
                Some((
                    DVec3::new(-outer, -minor, -outer),
                    DVec3::new(outer, *minor, outer),
                ))
            }
        };
        // The tracer intersects most shapes in their own unit space: the inverse of the shape's
        // size under the transform. Its smallest size in world space bounds those coordinates.
        let smallest = match shape {
            Shape::Sphere { radius, .. } | Shape::Disk { radius, .. } => Some(*radius),
            Shape::Box { min, max } => Some((*max - *min).min_element() / 2.0),
            Shape::Cylinder {
                base, apex, radius, ..
            } => Some(radius.min((*apex - *base).length())),
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
                ..
            } => Some(base_radius.max(*apex_radius).min((*apex - *base).length())),
            // Intersected in the space where the major radius is 1.
            Shape::Torus { major, minor } => Some(major.min(*minor)),
            Shape::Plane { .. }
            | Shape::Triangle { .. }
            | Shape::Quadric { .. }
            | Shape::Mesh { .. } => None,
        };
        if let Some(size) = smallest.filter(|s| *s >= MIN_SIZE && m.is_finite()) {
            // Most objects of a large scene are not transformed at all, or only moved: the
            // linear part of their inverse is the identity, exactly what inverting gives,
            // without inverting (4% of compiling a million spheres).
            let largest = if glam::DMat3::from_mat4(**m) == glam::DMat3::IDENTITY {
                1.0
            } else {
                let inverse = m.inverse().to_cols_array();
                [0, 1, 2, 4, 5, 6, 8, 9, 10]
                    .iter()
                    .map(|&i| inverse[i].abs())
                    .fold(0.0, f64::max)
            };
            let world = size / largest;
            if largest.is_finite() && world < MIN_SIZE {
                let what = format!("{}'s smallest size in world space", shape.kind_name());
                let rule = format!("below the smallest size limit ({MIN_SIZE:e})");
                self.out_of_range(&what, world, rule, span);
            }
        }
        if let Some((lo, hi)) = local_box {
            if lo.is_finite() && hi.is_finite() && m.is_finite() {
                for i in 0..8 {
                    let corner = DVec3::new(
                        if i & 1 == 0 { lo.x } else { hi.x },
                        if i & 2 == 0 { lo.y } else { hi.y },
                        if i & 4 == 0 { lo.z } else { hi.z },
                    );
                    let world = m.transform_point3(corner);
                    if world.abs().max_element() > MAX_COORDINATE {
                        let value = world.abs().max_element();
                        self.coordinate(
                            &format!("{}'s extent in world space", shape.kind_name()),
                            value,
                            span,
                        );
                        break;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::DMat4;

    use crate::arena::Handle;
    use crate::scene::*;
    use crate::source::{FileId, Span};
    use crate::validate::validate;

    fn span(n: usize) -> Span {
        Span::new(FileId(0), n, n + 1)
    }

    fn base() -> Scene {
        let mut scene = Scene::default();
        let material = scene.materials.append(Material::default(), span(0));
        let object = scene.objects.append(
            Object {
                name: None,
                kind: ObjectKind::Shape {
                    shape: Shape::Sphere {
                        center: glam::DVec3::ZERO,
                        radius: 1.0,
                    }
                    .into(),
                },
                world_from_object: WorldFromObject::IDENTITY,
                material,
            },
            span(1),
        );
        scene.roots.push(object);
        scene.lights.append(
            Light {
                name: None,
                color: Color::WHITE,
                kind: LightKind::Point {
                    position: glam::DVec3::new(0.0, 5.0, 0.0),
                    attenuation: Attenuation::NONE,
                },
            },
            span(2),
        );
        scene
    }

    /// Each field with a way to set it to a value.
    type Setter = fn(&mut Scene, f64);

    fn fields() -> Vec<(&'static str, Setter)> {
        vec![
            ("light's `color`", |s, v| {
                s.lights[Handle::from_index(0)].color = Color::new(v, 1.0, 1.0)
            }),
            ("light's `position`", |s, v| {
                if let LightKind::Point { position, .. } = &mut s.lights[Handle::from_index(0)].kind
                {
                    position.x = v;
                }
            }),
            ("light's `attenuation` term", |s, v| {
                if let LightKind::Point { attenuation, .. } =
                    &mut s.lights[Handle::from_index(0)].kind
                {
                    attenuation.quadratic = v;
                }
            }),
            ("material's `diffuse`", |s, v| {
                s.materials[Handle::from_index(0)].diffuse = Color::new(v, 0.0, 0.0)
            }),
            ("material's `specular`", |s, v| {
                s.materials[Handle::from_index(0)].specular = Color::gray(v)
            }),
            ("material's `reflective`", |s, v| {
                s.materials[Handle::from_index(0)].reflective = Color::gray(v)
            }),
            ("material's `transmissive`", |s, v| {
                s.materials[Handle::from_index(0)].transmissive = Color::gray(v)
            }),
            ("material's `absorption`", |s, v| {
                s.materials[Handle::from_index(0)].absorption = Color::gray(v)
            }),
            ("material's `shininess`", |s, v| {
                s.materials[Handle::from_index(0)].shininess = v
            }),
            ("material's `ior`", |s, v| {
                s.materials[Handle::from_index(0)].ior = v
            }),
            ("sphere's `radius`", |s, v| {
                if let ObjectKind::Shape { shape } = &mut s.objects[Handle::from_index(0)].kind {
                    shape.update(|s| {
                        if let Shape::Sphere { radius, .. } = s {
                            *radius = v;
                        }
                    });
                }
            }),
            ("sphere's `center`", |s, v| {
                if let ObjectKind::Shape { shape } = &mut s.objects[Handle::from_index(0)].kind {
                    shape.update(|s| {
                        if let Shape::Sphere { center, .. } = s {
                            center.y = v;
                        }
                    });
                }
            }),
            ("object's transform", |s, v| {
                s.objects[Handle::from_index(0)].world_from_object.w_axis.x = v
            }),
            ("camera's `eye`", |s, v| s.camera.eye.x = v),
        ]
    }

    fn messages(scene: Scene) -> Vec<String> {
        match validate(scene) {
            Ok(_) => Vec::new(),
            Err(invalid) => invalid.diagnostics.into_iter().map(|d| d.message).collect(),
        }
    }

    #[test]
    fn numbers_past_f32_are_refused_for_every_field_with_its_name() {
        // Issue 9 item 6: a light colour 1e39 or an ior 1e308 passed validation and made
        // inf/NaN pixels. Edge values: past f32 (both signs), f64's largest, and tiny ones.
        let huge = [f64::from(f32::MAX) * 2.0, 1e39, -1e39, f64::MAX, 1e308];
        for (name, set) in fields() {
            for value in huge {
                let mut scene = base();
                set(&mut scene, value);
                let messages = messages(scene);
                // Negative colours and sizes are already refused as negative.
                let named = messages
                    .iter()
                    .any(|m| m.contains(name) && m.contains("limit"));
                assert!(
                    named || (value < 0.0 && !messages.is_empty()),
                    "{name} = {value:e} gave {messages:?}"
                );
            }
            // A plain value passes.
            let mut scene = base();
            set(&mut scene, 0.5);
            assert_eq!(messages(scene), Vec::<String>::new(), "{name} = 0.5");
        }
        // Tiny sizes round to nothing in f32: refused, with the limit named.
        for value in [5e-324, 1e-310, 1e-40] {
            let mut scene = base();
            if let ObjectKind::Shape { shape } = &mut scene.objects[Handle::from_index(0)].kind {
                shape.update(|s| {
                    if let Shape::Sphere { radius, .. } = s {
                        *radius = value;
                    }
                });
            }
            let messages = messages(scene);
            assert!(
                messages.iter().any(|m| m.contains("smallest size limit")),
                "radius {value:e}: {messages:?}"
            );
        }
    }

    /// Every material colour of the IR's table (emission included, with no line of its own
    /// here) is refused past its row's limit, by name, and negative; at the limit it passes.
    #[test]
    fn every_material_colour_is_checked_by_its_row() {
        for row in crate::properties::MATERIAL_COLORS {
            let with = |v: f64| {
                let mut scene = base();
                (row.set)(
                    &mut scene.materials[Handle::from_index(0)],
                    Color::new(0.0, v, 0.0),
                );
                messages(scene)
            };
            assert_eq!(with(row.limit.max), Vec::<String>::new(), "`{}`", row.name);
            let over = with(row.limit.max * 1.5);
            let what = format!("material's `{}`", row.name);
            assert!(
                over.iter()
                    .any(|m| m.contains(&what) && m.contains(row.limit.name)),
                "`{}` over its limit: {over:?}",
                row.name
            );
            let negative = with(-1.0);
            assert!(
                negative.iter().any(|m| m.contains(&format!(
                    "the material's {} coefficient must be finite and >= 0",
                    row.name
                ))),
                "`{}` negative: {negative:?}",
                row.name
            );
        }
    }

    #[test]
    fn world_space_size_counts_after_the_transform() {
        // Radius 1e-6 under a scale of 1e-4 on one axis: 1e-10 across in world space, where
        // the ray's coordinates in the sphere's own space would square to infinity in f32.
        let mut scene = base();
        scene.objects[Handle::from_index(0)].world_from_object =
            DMat4::from_scale(glam::DVec3::new(1e-4, 1e2, 1e2)).into();
        if let ObjectKind::Shape { shape } = &mut scene.objects[Handle::from_index(0)].kind {
            shape.update(|s| {
                if let Shape::Sphere { radius, .. } = s {
                    *radius = 1e-6;
                }
            });
        }
        let messages = messages(scene);
        assert!(
            messages
                .iter()
                .any(|m| m.contains("smallest size in world space")),
            "{messages:?}"
        );
    }

    #[test]
    fn world_space_extent_counts_after_the_transform() {
        let mut scene = base();
        scene.objects[Handle::from_index(0)].world_from_object =
            DMat4::from_scale(glam::DVec3::splat(1e6)).into();
        if let ObjectKind::Shape { shape } = &mut scene.objects[Handle::from_index(0)].kind {
            shape.update(|s| {
                if let Shape::Sphere { radius, .. } = s {
                    *radius = 1e4;
                }
            });
        }
        let messages = messages(scene);
        assert!(
            messages.iter().any(|m| m.contains("extent in world space")),
            "{messages:?}"
        );
    }
}
