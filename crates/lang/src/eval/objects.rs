//! Object, light, camera and settings statements, and the properties that fill them in.
//!
//! Each property is checked where it is written, so an error points at the value that is
//! wrong ("a sphere's radius must be greater than 0"), not at the whole object. Checks that
//! involve several fields (a box's corners, a camera's view) are left to the IR validator,
//! which reports them at the object's header.

use whitted_ir::{
    Attenuation, Color, DMat4, DVec3, Diagnostic, Highlight, Light, LightKind, Object, ObjectKind,
    Quadric, QuadricForm, ShadowMode, Shape, Span,
};

use super::builders::*;
use super::{inherit, Abort, Eval, Evaluator, Sink};
use crate::ast::*;
use crate::properties::{self, Family};
use crate::schema::{Arity, LightTag, ObjectTag, Prop};
use crate::value::Value;

use whitted_ir::limits;

/// A property's evaluated values: one, or a short list (vertices, coefficients, matrix).
enum Values {
    None,
    One(Value, Span),
    List(Vec<(Value, Span)>),
}

impl<'a> Evaluator<'a> {
    // ---- statements that fill a builder ----------------------------------------------------

    pub(super) fn object(
        &mut self,
        tag: ObjectTag,
        kind: Ident,
        name: Option<&'a StrLit>,
        body: &'a Block,
    ) -> Eval<()> {
        let header = match name {
            Some(name) => kind.span.to(name.span),
            None => kind.span,
        };
        self.check_sink(header)?;
        let errors_before = self.error_events;
        self.targets.push(Target::Object(ObjectBuilder {
            tag,
            fields: ShapeFields::defaults(tag),
            placement: Placement::new(),
            set: PropSet::new(),
        }));
        if tag.is_container() {
            self.sinks.push(Sink::Collect(Vec::new()));
        }
        let result = self.items(&body.items);
        let children = if tag.is_container() {
            match self.sinks.pop() {
                Some(Sink::Collect(children)) => children,
                _ => Vec::new(),
            }
        } else {
            Vec::new()
        };
        let builder = match self.targets.pop() {
            Some(Target::Object(builder)) => builder,
            _ => return Err(Abort::Reported),
        };
        result?;
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        let material = match builder.placement.material {
            Some(id) => Some(self.lower_material(id)?),
            None => None,
        };
        let kind = match tag {
            ObjectTag::Union | ObjectTag::Intersection | ObjectTag::Difference => {
                self.place_subtree(&children, builder.placement.transform, material);
                let op = match tag {
                    ObjectTag::Union => whitted_ir::CsgOp::Union,
                    ObjectTag::Intersection => whitted_ir::CsgOp::Intersection,
                    _ => whitted_ir::CsgOp::Difference,
                };
                ObjectKind::Csg { op, children }
            }
            ObjectTag::Group => {
                self.place_subtree(&children, builder.placement.transform, material);
                ObjectKind::Group { children }
            }
            _ => ObjectKind::Shape {
                shape: self.shape(tag, &builder, header)?,
            },
        };
        let object = Object {
            name: self.object_name(name)?,
            kind,
            world_from_object: builder.placement.transform,
            material: material.unwrap_or_else(inherit),
        };
        let handle = self.scene.objects.append(object, header);
        self.emit(handle);
        Ok(())
    }

    fn shape(&mut self, tag: ObjectTag, builder: &ObjectBuilder, header: Span) -> Eval<Shape> {
        let f = &builder.fields;
        let required = match tag {
            ObjectTag::Triangle => {
                Some((Prop::Vertices, "vertices <0, 0, 0>, <1, 0, 0>, <0, 1, 0>"))
            }
            ObjectTag::Quadric => Some((
                Prop::Coefficients,
                "coefficients <1, 1, 1>, <0, 0, 0>, <0, 0, 0>, -1",
            )),
            _ => None,
        };
        if let Some((prop, example)) = required {
            if !builder.set.has(prop) {
                return self.fail(
                    Diagnostic::error(
                        format!(
                            "{} needs `{}`",
                            crate::schema::article(tag.name()),
                            prop.name()
                        ),
                        header,
                    )
                    .with_label(format!("no `{}` given", prop.name()))
                    .with_hint(format!("for example: `{example}`")),
                );
            }
        }
        let r = f.radii;
        let inverse_square = |x: f64| 1.0 / (x * x);
        let quadric = |form, c: [f64; 10]| Shape::Quadric {
            form,
            quadric: Quadric::from_coefficients(c),
        };
        Ok(match tag {
            ObjectTag::Sphere => Shape::Sphere {
                center: f.center,
                radius: f.radius,
            },
            ObjectTag::Plane => Shape::Plane {
                normal: f.normal,
                offset: f.offset,
            },
            ObjectTag::Box => Shape::Box {
                min: f.min,
                max: f.max,
            },
            ObjectTag::Cylinder => Shape::Cylinder {
                base: f.base,
                apex: f.apex,
                radius: f.radius,
                capped: !f.open,
            },
            ObjectTag::Cone => Shape::Cone {
                base: f.base,
                base_radius: f.base_radius,
                apex: f.apex,
                apex_radius: f.apex_radius,
                capped: !f.open,
            },
            ObjectTag::Disk => Shape::Disk {
                center: f.center,
                normal: f.normal,
                radius: f.radius,
            },
            ObjectTag::Triangle => Shape::Triangle {
                a: f.vertices[0],
                b: f.vertices[1],
                c: f.vertices[2],
            },
            ObjectTag::Quadric => quadric(QuadricForm::General, f.coefficients),
            // x²/a² + y²/b² + z²/c² - 1
            ObjectTag::Ellipsoid => quadric(
                QuadricForm::Ellipsoid,
                [
                    inverse_square(r.x),
                    inverse_square(r.y),
                    inverse_square(r.z),
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    -1.0,
                ],
            ),
            // x²/a² + z²/c² - y/b: opens upwards; at height b its cross-section has radii a, c.
            ObjectTag::Paraboloid => quadric(
                QuadricForm::EllipticParaboloid,
                [
                    inverse_square(r.x),
                    0.0,
                    inverse_square(r.z),
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    -1.0 / r.y,
                    0.0,
                    0.0,
                ],
            ),
            // x²/a² - y²/b² + z²/c² - 1: one sheet around the y axis, waist radii a and c.
            ObjectTag::Hyperboloid => quadric(
                QuadricForm::HyperboloidOneSheet,
                [
                    inverse_square(r.x),
                    -inverse_square(r.y),
                    inverse_square(r.z),
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    -1.0,
                ],
            ),
            // x²/a² - y²/b² + z²/c² + 1: two sheets opening along ±y, tips at y = ±b.
            ObjectTag::Hyperboloid2 => quadric(
                QuadricForm::HyperboloidTwoSheets,
                [
                    inverse_square(r.x),
                    -inverse_square(r.y),
                    inverse_square(r.z),
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    1.0,
                ],
            ),
            ObjectTag::Union
            | ObjectTag::Intersection
            | ObjectTag::Difference
            | ObjectTag::Group => return Err(Abort::Reported),
        })
    }

    /// The block after a call statement: transforms and a material for what the call made.
    pub(super) fn modifiers(&mut self, block: &'a Block) -> Eval<Placement> {
        let errors_before = self.error_events;
        self.targets
            .push(Target::Modifiers(Placement::new(), PropSet::new()));
        let result = self.items(&block.items);
        let placement = match self.targets.pop() {
            Some(Target::Modifiers(placement, _)) => placement,
            _ => Placement::new(),
        };
        result?;
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        Ok(placement)
    }

    pub(super) fn settings(&mut self, body: &'a Block) -> Eval<()> {
        self.targets.push(Target::Settings);
        let result = self.items(&body.items);
        self.targets.pop();
        result.map(|_| ())
    }

    pub(super) fn camera(
        &mut self,
        tag: crate::schema::CameraTag,
        header: Span,
        body: &'a Block,
    ) -> Eval<()> {
        if let Some(first) = self.camera_span {
            return self.fail(
                Diagnostic::error("the scene already has a camera", header)
                    .with_label("a second camera")
                    .with_secondary(first, "the first camera")
                    .with_hint("a scene has one camera; remove one of them"),
            );
        }
        let errors_before = self.error_events;
        self.targets.push(Target::Camera(CameraBuilder::new(tag)));
        let result = self.items(&body.items);
        let builder = match self.targets.pop() {
            Some(Target::Camera(builder)) => builder,
            _ => return Err(Abort::Reported),
        };
        result?;
        // Claim the camera even if its body failed, so a second one is still reported.
        self.camera_span = Some(header);
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        self.scene.camera = builder.build();
        Ok(())
    }

    pub(super) fn light(
        &mut self,
        tag: LightTag,
        header: Span,
        name: Option<&'a StrLit>,
        body: &'a Block,
    ) -> Eval<()> {
        if self.scene.lights.len() >= self.limits.max_lights {
            let limit = self.limits.max_lights;
            return self.fatal(
                Diagnostic::error(format!("the lights limit ({limit}) was reached"), header)
                    .with_label("one light too many")
                    .with_hint("every shading point visits every light; see \"Limits\" in docs/language.md"),
            );
        }
        let errors_before = self.error_events;
        self.targets.push(Target::Light(LightBuilder::new()));
        let result = self.items(&body.items);
        let builder = match self.targets.pop() {
            Some(Target::Light(builder)) => builder,
            _ => return Err(Abort::Reported),
        };
        result?;
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        let needs_position = tag != LightTag::Directional;
        let needs_direction = tag != LightTag::Point;
        for (needed, prop) in [
            (needs_position, Prop::Position),
            (needs_direction, Prop::Direction),
        ] {
            if needed && !builder.set.has(prop) {
                return self.fail(
                    Diagnostic::error(
                        format!("a {} light needs a `{}`", tag.name(), prop.name()),
                        header,
                    )
                    .with_label(format!("no `{}` given", prop.name())),
                );
            }
        }
        if tag == LightTag::Spot && builder.inner > builder.outer {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "a spot light's `inner` angle ({}) must not be larger than its `outer` angle ({})",
                        builder.inner, builder.outer
                    ),
                    header,
                )
                .with_label("inner > outer"),
            );
        }
        let kind = match tag {
            LightTag::Point => LightKind::Point {
                position: builder.position,
                attenuation: builder.attenuation,
            },
            LightTag::Directional => LightKind::Directional {
                direction: builder.direction,
            },
            LightTag::Spot => LightKind::Spot {
                position: builder.position,
                direction: builder.direction,
                inner_angle_degrees: builder.inner,
                outer_angle_degrees: builder.outer,
                attenuation: builder.attenuation,
            },
        };
        let name = self.object_name(name)?;
        self.scene.lights.append(
            Light {
                name,
                color: builder.color,
                kind,
            },
            header,
        );
        Ok(())
    }

    // ---- properties ------------------------------------------------------------------------

    pub(super) fn property(&mut self, property: &'a Property) -> Eval<()> {
        let Some(prop) = property.prop else {
            // Already reported by the resolver, or in a block of unknown kind.
            return Ok(());
        };
        if !prop.is_transform() {
            self.record(prop, property.name.span)?;
        }
        let values = self.values(property, prop)?;
        let span = property.name.span;
        match self.targets.last() {
            Some(Target::Object(_))
            | Some(Target::Modifiers(..))
            | Some(Target::PatternTransform(_))
                if prop.is_transform() =>
            {
                let transform = self.transform(property, prop, &values)?;
                match self.targets.last_mut() {
                    Some(Target::Object(b)) => {
                        b.placement.transform = transform * b.placement.transform
                    }
                    Some(Target::Modifiers(p, _)) => p.transform = transform * p.transform,
                    Some(Target::PatternTransform(m)) => *m = transform * *m,
                    _ => {}
                }
                Ok(())
            }
            Some(Target::Object(_)) | Some(Target::Modifiers(..)) if prop == Prop::Material => {
                let (value, value_span) = one(&values, span);
                let Value::Material(id) = value else {
                    return self.fail(
                        Diagnostic::error(
                            format!("`material` must be a material, not {}", value.type_name()),
                            value_span,
                        )
                        .with_label(format!("{} here", value.type_name()))
                        .with_hint("name a material defined with `material NAME { ... }`, or write one inline: `material { diffuse red }`"),
                    );
                };
                match self.targets.last_mut() {
                    Some(Target::Object(b)) => b.placement.material = Some(id),
                    Some(Target::Modifiers(p, _)) => p.material = Some(id),
                    _ => {}
                }
                Ok(())
            }
            Some(Target::Object(_)) => self.shape_property(prop, &values, span),
            Some(Target::Settings) => self.settings_property(property, prop, &values),
            Some(Target::Camera(_)) => self.camera_property(prop, &values, span),
            Some(Target::Light(_)) => self.light_property(prop, &values, span),
            Some(Target::Material(_)) => self.material_property(property, prop, &values),
            _ => Ok(()),
        }
    }

    /// Remembers that `prop` was set in the current block; setting it twice is an error.
    fn record(&mut self, prop: Prop, span: Span) -> Eval<()> {
        let result = match self.targets.last_mut() {
            Some(Target::Object(b)) => b.set.insert(prop, span),
            Some(Target::Modifiers(_, set)) => set.insert(prop, span),
            Some(Target::Camera(b)) => b.set.insert(prop, span),
            Some(Target::Light(b)) => b.set.insert(prop, span),
            Some(Target::Material(b)) => b.set.insert(prop, span),
            Some(Target::Settings) => match self.settings_set.iter().find(|(p, _)| *p == prop) {
                Some(&(_, first)) => Err(first),
                None => {
                    self.settings_set.push((prop, span));
                    Ok(())
                }
            },
            Some(Target::PatternTransform(_)) | None => Ok(()),
        };
        let Err(first) = result else {
            return Ok(());
        };
        let name = prop.name();
        let mut diagnostic =
            Diagnostic::error(format!("`{name}` is set twice"), span).with_label("set again here");
        if first != span {
            diagnostic = diagnostic.with_secondary(first, "first set here");
        } else {
            diagnostic = diagnostic.with_hint("this line runs more than once (it is in a loop)");
        }
        self.fail(diagnostic)
    }

    fn values(&mut self, property: &'a Property, prop: Prop) -> Eval<Values> {
        if prop.words().is_some() {
            return Ok(Values::None);
        }
        let count = property.values.len();
        let wrong_count = match prop.arity() {
            Arity::Flag => count != 0,
            Arity::One => count != 1,
            Arity::Exactly(n) => count != n,
            Arity::Numbers(_) => count == 0,
        };
        if wrong_count {
            // Reported by the resolver; evaluation only goes on to find other errors.
            return Err(Abort::Reported);
        }
        match (prop.arity(), property.values.as_slice()) {
            (Arity::Flag, _) | (_, []) => Ok(Values::None),
            (Arity::One, [value, ..]) => Ok(Values::One(self.eval(value)?, value.span)),
            (_, list) => {
                let mut values = Vec::with_capacity(list.len());
                for value in list {
                    values.push((self.eval(value)?, value.span));
                }
                Ok(Values::List(values))
            }
        }
    }

    // ---- value conversions, each with its own message --------------------------------------

    /// A number within `low..=high` (or `low < x` when `low_open`), with a message naming
    /// the property and the range.
    /// Numbers and vectors flattened into exactly `n` numbers.
    fn numbers(&mut self, values: &Values, span: Span, prop: Prop, n: usize) -> Eval<Vec<f64>> {
        let mut out = Vec::with_capacity(n);
        let list: Vec<(Value, Span)> = match values {
            Values::None => Vec::new(),
            Values::One(v, s) => vec![(*v, *s)],
            Values::List(list) => list.clone(),
        };
        for (value, value_span) in &list {
            match value {
                Value::Number(x) => out.push(*x),
                Value::Vector(v) => out.extend_from_slice(&v.to_array()),
                other => {
                    return self.fail(
                        Diagnostic::error(
                            format!(
                                "`{}` takes numbers and vectors, not {}",
                                prop.name(),
                                other.type_name()
                            ),
                            *value_span,
                        )
                        .with_label(format!("{} here", other.type_name())),
                    )
                }
            }
        }
        if out.len() != n {
            let whole = match (list.first(), list.last()) {
                (Some(first), Some(last)) => first.1.to(last.1),
                _ => span,
            };
            return self.fail(
                Diagnostic::error(
                    format!(
                        "`{}` needs {n} numbers, but these make {}",
                        prop.name(),
                        out.len()
                    ),
                    whole,
                )
                .with_label(format!("{} numbers", out.len()))
                .with_hint("a vector counts as three numbers"),
            );
        }
        Ok(out)
    }

    // ---- transforms ------------------------------------------------------------------------

    fn transform(&mut self, property: &'a Property, prop: Prop, values: &Values) -> Eval<DMat4> {
        let span = property.name.span;
        if prop == Prop::Matrix {
            let m = self.numbers(values, span, prop, 16)?;
            let mut array = [0.0; 16];
            array.copy_from_slice(&m);
            // Written row by row, as on paper; glam stores columns.
            let matrix = DMat4::from_cols_array(&array).transpose();
            if matrix.determinant().abs() < 1e-12 {
                let whole = values_span(values, span);
                return self.fail(
                    Diagnostic::error("this matrix cannot be undone (its determinant is 0)", whole)
                        .with_label("not invertible")
                        .with_hint("a transform must be invertible; a zero row or column flattens the object"),
                );
            }
            return Ok(matrix);
        }
        let (value, value_span) = one(values, span);
        match prop {
            Prop::Translate => Ok(DMat4::from_translation(
                self.as_vector(value, value_span, prop)?,
            )),
            Prop::Scale => {
                let v = match value {
                    Value::Number(x) => DVec3::splat(x),
                    other => self.as_vector(other, value_span, prop)?,
                };
                if v.cmpeq(DVec3::ZERO).any() {
                    return self.fail(
                        Diagnostic::error("a scale by zero flattens the object", value_span)
                            .with_label("zero here")
                            .with_hint("every scale factor must be non-zero (negative mirrors)"),
                    );
                }
                Ok(DMat4::from_scale(v))
            }
            _ => {
                // Rotate.
                match (&property.about, value) {
                    (None, Value::Vector(angles)) => {
                        // x first, then y, then z, like POV-Ray.
                        Ok(rotation_about(DVec3::Z, angles.z)
                            * rotation_about(DVec3::Y, angles.y)
                            * rotation_about(DVec3::X, angles.x))
                    }
                    (Some(axis_expr), Value::Number(angle)) => {
                        let axis_value = self.eval(axis_expr)?;
                        let axis = self.nonzero_vector(axis_value, axis_expr.span, prop)?;
                        Ok(rotation_about(axis.normalize(), angle))
                    }
                    (None, Value::Number(_)) => self.fail(
                        Diagnostic::error("`rotate` with one angle needs an axis", value_span)
                            .with_label("which axis?")
                            .with_hint("write `rotate <0, 30, 0>` (degrees about x, y, z) or `rotate 30 about <0, 1, 0>`"),
                    ),
                    (Some(_), other) => self.fail(
                        Diagnostic::error(
                            format!("`rotate ... about` takes one angle, not {}", other.type_name()),
                            value_span,
                        )
                        .with_label("the angle in degrees")
                        .with_hint("write `rotate 30 about <0, 1, 0>`"),
                    ),
                    (None, other) => self.fail(
                        Diagnostic::error(
                            format!("`rotate` takes a vector of angles, not {}", other.type_name()),
                            value_span,
                        )
                        .with_label(format!("{} here", other.type_name())),
                    ),
                }
            }
        }
    }

    // ---- per-block properties --------------------------------------------------------------

    fn shape_property(&mut self, prop: Prop, values: &Values, span: Span) -> Eval<()> {
        /// A converted value, held while `self` reports errors, then stored in place (the
        /// builder is large; copying it per property showed in profiles).
        enum Set {
            Vector(DVec3),
            Number(f64),
            Vertices([DVec3; 3]),
            Coefficients([f64; 10]),
            Open,
        }
        let tag = match self.targets.last() {
            Some(Target::Object(b)) => b.tag,
            _ => return Ok(()),
        };
        let (value, value_span) = one(values, span);
        let shape = || crate::schema::article(tag.name());
        let set = match prop {
            Prop::Center | Prop::Min | Prop::Max | Prop::Base | Prop::Apex => {
                Set::Vector(self.as_vector(value, value_span, prop)?)
            }
            Prop::Normal => Set::Vector(self.nonzero_vector(value, value_span, prop)?),
            Prop::Offset => Set::Number(self.as_number(value, value_span, prop)?),
            Prop::Radius => {
                let x = self.as_number(value, value_span, prop)?;
                if x <= 0.0 {
                    return self.fail(
                        Diagnostic::error(
                            format!("{}'s radius must be greater than 0, not {x}", shape()),
                            value_span,
                        )
                        .with_label("too small"),
                    );
                }
                Set::Number(x)
            }
            Prop::BaseRadius | Prop::ApexRadius => {
                Set::Number(self.in_range(value, value_span, prop, 0.0, false, f64::INFINITY)?)
            }
            Prop::Radii => {
                let v = self.as_vector(value, value_span, prop)?;
                if v.cmple(DVec3::ZERO).any() {
                    return self.fail(
                        Diagnostic::error(
                            format!("{}'s radii must all be greater than 0", shape()),
                            value_span,
                        )
                        .with_label(format!("this is <{}, {}, {}>", v.x, v.y, v.z)),
                    );
                }
                Set::Vector(v)
            }
            Prop::Vertices => {
                let mut vertices = [DVec3::ZERO; 3];
                if let Values::List(list) = values {
                    for (slot, (value, value_span)) in vertices.iter_mut().zip(list) {
                        *slot = self.as_vector(*value, *value_span, prop)?;
                    }
                }
                Set::Vertices(vertices)
            }
            Prop::Coefficients => {
                let numbers = self.numbers(values, span, prop, 10)?;
                let mut coefficients = [0.0; 10];
                coefficients.copy_from_slice(&numbers);
                Set::Coefficients(coefficients)
            }
            Prop::Open => Set::Open,
            _ => return Ok(()),
        };
        let Some(Target::Object(b)) = self.targets.last_mut() else {
            return Ok(());
        };
        let f = &mut b.fields;
        match (prop, set) {
            (Prop::Center, Set::Vector(v)) => f.center = v,
            (Prop::Min, Set::Vector(v)) => f.min = v,
            (Prop::Max, Set::Vector(v)) => f.max = v,
            (Prop::Base, Set::Vector(v)) => f.base = v,
            (Prop::Apex, Set::Vector(v)) => f.apex = v,
            (Prop::Normal, Set::Vector(v)) => f.normal = v,
            (Prop::Radii, Set::Vector(v)) => f.radii = v,
            (Prop::Offset, Set::Number(x)) => f.offset = x,
            (Prop::Radius, Set::Number(x)) => f.radius = x,
            (Prop::BaseRadius, Set::Number(x)) => f.base_radius = x,
            (Prop::ApexRadius, Set::Number(x)) => f.apex_radius = x,
            (_, Set::Vertices(v)) => f.vertices = v,
            (_, Set::Coefficients(c)) => f.coefficients = c,
            (_, Set::Open) => f.open = true,
            _ => {}
        }
        Ok(())
    }

    fn settings_property(
        &mut self,
        property: &'a Property,
        prop: Prop,
        values: &Values,
    ) -> Eval<()> {
        let span = property.name.span;
        let (value, value_span) = one(values, span);
        self.apply_setting(prop, value, value_span, word(property))
    }

    /// Sets one setting from its value (or its word, for settings that take one): from a
    /// `settings` block, or from the command line's `--set NAME=VALUE`.
    pub(super) fn apply_setting(
        &mut self,
        prop: Prop,
        value: Value,
        value_span: Span,
        word: Option<&str>,
    ) -> Eval<()> {
        let Some(row) = properties::row(prop, Family::Settings) else {
            return Ok(());
        };
        let value = self.convert(row, value, value_span)?;
        let mut settings = self.scene.settings.clone();
        // What each setting means: the field it sets (its kind and range are its row's).
        match prop {
            Prop::Width => settings.width = value.number() as u32,
            Prop::Height => settings.height = value.number() as u32,
            Prop::MaxDepth => settings.max_depth = value.number() as u32,
            Prop::Samples => settings.samples_per_pixel = value.number() as u32,
            Prop::MinWeight => settings.min_weight = value.number(),
            Prop::Epsilon => settings.epsilon = Some(value.number()),
            Prop::Background => settings.background = value.color(),
            Prop::Ambient => settings.ambient = value.color(),
            Prop::Shadows => {
                settings.shadows = if word == Some("filtered") {
                    ShadowMode::Filtered
                } else {
                    ShadowMode::Opaque
                }
            }
            Prop::Highlight => {
                settings.highlight = if word == Some("blinn") {
                    Highlight::Blinn
                } else {
                    Highlight::Phong
                }
            }
            _ => {}
        }
        let pixels = u64::from(settings.width) * u64::from(settings.height);
        if pixels > limits::MAX_PIXELS {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "a {}x{} image has {pixels} pixels, past the pixels limit ({})",
                        settings.width,
                        settings.height,
                        limits::MAX_PIXELS
                    ),
                    value_span,
                )
                .with_label("too many pixels with this")
                .with_hint("about 11585x11585 at most; see \"Limits\" in docs/language.md"),
            );
        }
        self.scene.settings = settings;
        Ok(())
    }

    fn camera_property(&mut self, prop: Prop, values: &Values, span: Span) -> Eval<()> {
        let (value, value_span) = one(values, span);
        let Some(row) = properties::row(prop, Family::Camera) else {
            return Ok(());
        };
        let value = self.convert(row, value, value_span)?;
        if let Some(Target::Camera(b)) = self.targets.last_mut() {
            match prop {
                Prop::Eye => b.eye = value.vector(),
                Prop::LookAt => b.look_at = value.vector(),
                Prop::Up => b.up = value.vector(),
                Prop::Fov => b.fov = value.number(),
                Prop::Height => b.height = value.number(),
                _ => {}
            }
        }
        Ok(())
    }

    fn light_property(&mut self, prop: Prop, values: &Values, span: Span) -> Eval<()> {
        let (value, value_span) = one(values, span);
        let mut light = match self.targets.last() {
            Some(Target::Light(b)) => LightFields {
                position: b.position,
                direction: b.direction,
                color: b.color,
                attenuation: b.attenuation,
                inner: b.inner,
                outer: b.outer,
            },
            _ => return Ok(()),
        };
        let Some(row) = properties::row(prop, Family::Light) else {
            return Ok(());
        };
        let converted = self.convert(row, value, value_span)?;
        match prop {
            Prop::Position => light.position = converted.vector(),
            Prop::Direction => light.direction = converted.vector(),
            Prop::Color => light.color = converted.color(),
            Prop::Attenuation => {
                let v = self.as_vector(value, value_span, prop)?;
                if v.cmplt(DVec3::ZERO).any() || v == DVec3::ZERO {
                    return self.fail(
                        Diagnostic::error(
                            "`attenuation <constant, linear, quadratic>` needs terms >= 0, not all zero",
                            value_span,
                        )
                        .with_label(format!("this is <{}, {}, {}>", v.x, v.y, v.z))
                        .with_hint("`<1, 0, 0>` means no fall-off with distance"),
                    );
                }
                light.attenuation = Attenuation {
                    constant: v.x,
                    linear: v.y,
                    quadratic: v.z,
                };
            }
            Prop::Inner => light.inner = converted.number(),
            Prop::Outer => light.outer = converted.number(),
            _ => {}
        }
        if let Some(Target::Light(b)) = self.targets.last_mut() {
            b.position = light.position;
            b.direction = light.direction;
            b.color = light.color;
            b.attenuation = light.attenuation;
            b.inner = light.inner;
            b.outer = light.outer;
        }
        Ok(())
    }

    fn material_property(
        &mut self,
        property: &'a Property,
        prop: Prop,
        values: &Values,
    ) -> Eval<()> {
        let span = property.name.span;
        let (value, value_span) = one(values, span);
        let mut pattern = None;
        let mut color = Color::BLACK;
        let mut number = 0.0;
        match prop {
            Prop::Diffuse => match value {
                Value::Pattern(id) => {
                    pattern = Some(match &property.block {
                        Some(block) => self.transformed_pattern(id, block)?,
                        None => id,
                    });
                }
                other => {
                    if let Some(block) = &property.block {
                        return self.fail(
                            Diagnostic::error(
                                "only a pattern takes a block of transforms",
                                block.span,
                            )
                            .with_label("unexpected block")
                            .with_secondary(value_span, format!("{} here", other.type_name())),
                        );
                    }
                    color = self.as_color(other, value_span, prop)?;
                }
            },
            _ => {
                if let Some(row) = properties::row(prop, Family::Material) {
                    let converted = self.convert(row, value, value_span)?;
                    color = converted.color();
                    number = converted.number();
                }
            }
        }
        let Some(Target::Material(b)) = self.targets.last_mut() else {
            return Ok(());
        };
        let m = &mut b.material;
        match prop {
            Prop::Diffuse => {
                b.pattern = pattern;
                if pattern.is_none() {
                    m.diffuse = color;
                }
            }
            Prop::Ambient => m.ambient = color,
            Prop::Specular => m.specular = color,
            Prop::Reflective => m.reflective = color,
            Prop::Transmissive => m.transmissive = color,
            Prop::Absorption => m.absorption = color,
            Prop::Shininess => m.shininess = number,
            Prop::Ior => m.ior = number,
            Prop::Fresnel => {
                m.fresnel = match word(property) {
                    Some("schlick") => whitted_ir::Fresnel::Schlick,
                    Some("exact") => whitted_ir::Fresnel::Exact,
                    _ => whitted_ir::Fresnel::Off,
                }
            }
            Prop::Priority => m.priority = number as u32,
            _ => {}
        }
        Ok(())
    }
}

struct LightFields {
    position: DVec3,
    direction: DVec3,
    color: Color,
    attenuation: Attenuation,
    inner: f64,
    outer: f64,
}

/// A right-handed rotation by `degrees` about a unit `axis` (Rodrigues' formula), exact for
/// quarter turns.
fn rotation_about(axis: DVec3, degrees: f64) -> DMat4 {
    let (sin, cos) = crate::builtins::sin_cos_degrees(degrees);
    let (x, y, z) = (axis.x, axis.y, axis.z);
    let t = 1.0 - cos;
    // Column by column.
    DMat4::from_cols_array(&[
        t * x * x + cos,
        t * x * y + sin * z,
        t * x * z - sin * y,
        0.0,
        t * x * y - sin * z,
        t * y * y + cos,
        t * y * z + sin * x,
        0.0,
        t * x * z + sin * y,
        t * y * z - sin * x,
        t * z * z + cos,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
    ])
}

/// The single value of a one-value property (the resolver checked the count).
fn one(values: &Values, span: Span) -> (Value, Span) {
    match values {
        Values::One(value, span) => (*value, *span),
        Values::List(list) => list.first().copied().unwrap_or((Value::Poisoned, span)),
        Values::None => (Value::Poisoned, span),
    }
}

fn values_span(values: &Values, span: Span) -> Span {
    match values {
        Values::List(list) => match (list.first(), list.last()) {
            (Some(first), Some(last)) => first.1.to(last.1),
            _ => span,
        },
        Values::One(_, s) => *s,
        Values::None => span,
    }
}

/// The word of a word-valued property (`shadows filtered`), as the resolver checked it.
fn word(property: &Property) -> Option<&'static str> {
    let ExprKind::Name(name) = &property.values.first()?.kind else {
        return None;
    };
    let Res::Word(index) = name.res else {
        return None;
    };
    property.prop?.words()?.get(index as usize).copied()
}
