//! Properties: each checked once per block, its values evaluated and converted, and set on
//! what the block builds (a shape's parameters, a transform, a setting, the camera, a light,
//! a material).

use whitted_ir::setting_rows::{self, SettingKind, SettingValue};
use whitted_ir::{Attenuation, Color, DMat4, DVec3, Diagnostic, Span};

use super::builders::*;
use super::{Abort, Eval, Evaluator};
use crate::ast::*;
use crate::properties::{self, Family};
use crate::schema::{Arity, Prop};
use crate::value::Value;

use whitted_ir::limits;

/// A property's evaluated values: one, or a short list (vertices, coefficients, matrix).
pub(super) enum Values {
    None,
    One(Value, Span),
    List(Vec<(Value, Span)>),
}

impl<'a> Evaluator<'a> {
    // ---- properties ------------------------------------------------------------------------

    pub(super) fn property(&mut self, property: &Property) -> Eval<()> {
        let Some(prop) = property.prop else {
            // Already reported by the resolver, or in a block of unknown kind.
            return Ok(());
        };
        if !prop.is_transform() {
            self.record(prop, property.name.span)?;
        }
        let values = self.values(property, prop)?;
        let span = property.name.span;
        if matches!(
            self.targets.last(),
            Some(Target::Settings | Target::Camera(_) | Target::Light(_) | Target::Material(_))
        ) {
            self.record_written(property, prop);
        }
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
    pub(super) fn record(&mut self, prop: Prop, span: Span) -> Eval<()> {
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

    pub(super) fn values(&mut self, property: &Property, prop: Prop) -> Eval<Values> {
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
    pub(super) fn numbers(
        &mut self,
        values: &Values,
        span: Span,
        prop: Prop,
        n: usize,
    ) -> Eval<Vec<f64>> {
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

    pub(super) fn transform(
        &mut self,
        property: &Property,
        prop: Prop,
        values: &Values,
    ) -> Eval<DMat4> {
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

    pub(super) fn shape_property(&mut self, prop: Prop, values: &Values, span: Span) -> Eval<()> {
        /// A converted value, held while `self` reports errors, then stored in place (the
        /// builder is large; copying it per property showed in profiles).
        enum Set {
            Vector(DVec3),
            Number(f64),
            Vertices([DVec3; 3]),
            Coefficients([f64; 10]),
            Open,
            Mesh(whitted_ir::Handle<whitted_ir::Mesh>),
            Smooth(bool),
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
            Prop::Major | Prop::Minor => match properties::row(prop, Family::Shape) {
                Some(row) => Set::Number(self.convert(row, value, value_span)?.number()),
                None => return Ok(()),
            },
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
            Prop::File => {
                let Value::Str(id) = value else {
                    return self.fail(
                        Diagnostic::error(
                            format!("`file` must be a string, not {}", value.type_name()),
                            value_span,
                        )
                        .with_label(format!("{} here", value.type_name()))
                        .with_hint("write the path in quotes: `file \"models/gem.obj\"`"),
                    );
                };
                let path = self
                    .store
                    .strings
                    .get(id as usize)
                    .cloned()
                    .unwrap_or_default();
                Set::Mesh(self.mesh_file(&path, value_span)?)
            }
            Prop::Smooth => match value {
                Value::Bool(b) => Set::Smooth(b),
                other => {
                    return self.fail(
                        Diagnostic::error(
                            format!(
                                "`smooth` must be `true` or `false`, not {}",
                                other.type_name()
                            ),
                            value_span,
                        )
                        .with_label(format!("{} here", other.type_name())),
                    )
                }
            },
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
            (Prop::Major, Set::Number(x)) => f.major = x,
            (Prop::Minor, Set::Number(x)) => f.minor = x,
            (Prop::Radius, Set::Number(x)) => f.radius = x,
            (Prop::BaseRadius, Set::Number(x)) => f.base_radius = x,
            (Prop::ApexRadius, Set::Number(x)) => f.apex_radius = x,
            (_, Set::Vertices(v)) => f.vertices = v,
            (_, Set::Coefficients(c)) => f.coefficients = c,
            (_, Set::Open) => f.open = true,
            (_, Set::Mesh(handle)) => f.mesh = Some(handle),
            (_, Set::Smooth(b)) => f.smooth = b,
            _ => {}
        }
        Ok(())
    }

    pub(super) fn settings_property(
        &mut self,
        property: &Property,
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
        let Some(ir_row) = setting_rows::setting(prop.name()) else {
            return Ok(());
        };
        // What each setting means is its row in the IR's table: the field it sets.
        let value = match ir_row.kind {
            SettingKind::Whole { .. } => SettingValue::Whole(value.number() as u32),
            SettingKind::Number { .. } => SettingValue::Number(value.number()),
            SettingKind::LightColor => SettingValue::Color(value.color()),
            SettingKind::Word(words) => match word.and_then(|w| words.iter().find(|x| **x == w)) {
                Some(word) => SettingValue::Word(word),
                None => return Ok(()),
            },
        };
        let mut settings = self.scene.settings.clone();
        (ir_row.set)(&mut settings, value);
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

    pub(super) fn camera_property(&mut self, prop: Prop, values: &Values, span: Span) -> Eval<()> {
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

    pub(super) fn light_property(&mut self, prop: Prop, values: &Values, span: Span) -> Eval<()> {
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

    pub(super) fn material_property(
        &mut self,
        property: &Property,
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
            // Every other colour is stored by its row in the IR's table.
            _ => {
                if let Some(row) = whitted_ir::properties::material_color(prop.name()) {
                    (row.set)(m, color);
                }
            }
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
pub(super) fn rotation_about(axis: DVec3, degrees: f64) -> DMat4 {
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
pub(super) fn one(values: &Values, span: Span) -> (Value, Span) {
    match values {
        Values::One(value, span) => (*value, *span),
        Values::List(list) => list.first().copied().unwrap_or((Value::Poisoned, span)),
        Values::None => (Value::Poisoned, span),
    }
}

pub(super) fn values_span(values: &Values, span: Span) -> Span {
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
pub(super) fn word(property: &Property) -> Option<&'static str> {
    let ExprKind::Name(name) = &property.values.first()?.kind else {
        return None;
    };
    let Res::Word(index) = name.res else {
        return None;
    };
    property.prop?.words()?.get(index as usize).copied()
}
