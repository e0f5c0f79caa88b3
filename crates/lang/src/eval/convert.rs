//! Conversion of property values to what their row in [`crate::properties`] says they take,
//! with the row's range: the one place evaluation checks a property's value.

use whitted_ir::{limits, Color, DVec3, Diagnostic, Span};

use super::{Eval, Evaluator};
use crate::properties::{Kind, Row};
use crate::schema::Prop;
use crate::value::Value;

/// A property's value after conversion.
#[derive(Clone, Copy, Debug)]
pub(super) enum Converted {
    Number(f64),
    Vector(DVec3),
    Color(Color),
    /// Kinds with forms of their own (words, patterns, transforms, ...) are read by the code
    /// that gives them meaning.
    Unconverted,
}

impl Converted {
    pub(super) fn number(self) -> f64 {
        match self {
            Converted::Number(x) => x,
            _ => 0.0,
        }
    }

    pub(super) fn vector(self) -> DVec3 {
        match self {
            Converted::Vector(v) => v,
            Converted::Color(c) => DVec3::new(c.r, c.g, c.b),
            _ => DVec3::ZERO,
        }
    }

    pub(super) fn color(self) -> Color {
        match self {
            Converted::Color(c) => c,
            _ => Color::BLACK,
        }
    }
}

/// A `fov` under this many degrees is probably radians: the narrowest lenses people use
/// on purpose are a few degrees wide, and 3.14 radians is 180°.
const FOV_LOOKS_LIKE_RADIANS: f64 = 3.2;

impl Evaluator<'_> {
    /// Converts `value` as `row` says: its kind and its range.
    pub(super) fn convert(&mut self, row: &Row, value: Value, span: Span) -> Eval<Converted> {
        let prop = row.prop;
        Ok(match row.kind {
            Kind::Number { min, open, max } => {
                Converted::Number(self.in_range(value, span, prop, min, open, max)?)
            }
            Kind::Whole { min, max } => {
                Converted::Number(f64::from(self.whole_in_range(value, span, prop, min, max)?))
            }
            Kind::Vector => Converted::Vector(self.as_vector(value, span, prop)?),
            Kind::Direction => Converted::Vector(self.nonzero_vector(value, span, prop)?),
            Kind::Color => Converted::Color(self.as_color(value, span, prop)?),
            Kind::LightColor => Converted::Color(self.light_color(value, span, prop)?),
            _ => Converted::Unconverted,
        })
    }

    pub(super) fn in_range(
        &mut self,
        value: Value,
        span: Span,
        prop: Prop,
        low: f64,
        low_open: bool,
        high: f64,
    ) -> Eval<f64> {
        let x = self.as_number(value, span, prop)?;
        let ok = if low_open { x > low } else { x >= low } && x <= high;
        if ok {
            if prop.name() == "fov" && x < FOV_LOOKS_LIKE_RADIANS {
                self.warn_fov_in_radians(x, span);
            }
            return Ok(x);
        }
        let wanted = match (low_open, high.is_finite()) {
            (true, false) => format!("greater than {low}"),
            (false, false) => format!("at least {low}"),
            (true, true) => format!("greater than {low} and at most {high}"),
            (false, true) => format!("from {low} to {high}"),
        };
        self.fail(
            Diagnostic::error(format!("`{}` must be {wanted}, not {x}", prop.name()), span)
                .with_label("out of range"),
        )
    }

    pub(super) fn whole_in_range(
        &mut self,
        value: Value,
        span: Span,
        prop: Prop,
        low: f64,
        high: f64,
    ) -> Eval<u32> {
        let x = self.in_range(value, span, prop, low, false, high)?;
        if x.fract() != 0.0 {
            return self.fail(
                Diagnostic::error(
                    format!("`{}` must be a whole number, not {x}", prop.name()),
                    span,
                )
                .with_label("not a whole number"),
            );
        }
        Ok(x as u32)
    }

    pub(super) fn nonzero_vector(&mut self, value: Value, span: Span, prop: Prop) -> Eval<DVec3> {
        let v = self.as_vector(value, span, prop)?;
        if v.length() < 1e-12 {
            return self.fail(
                Diagnostic::error(
                    format!("`{}` must not be the zero vector", prop.name()),
                    span,
                )
                .with_label("a direction needs a length"),
            );
        }
        Ok(v)
    }

    pub(super) fn as_number(&mut self, value: Value, span: Span, prop: Prop) -> Eval<f64> {
        match value {
            Value::Number(x) => Ok(x),
            other => self.fail(
                Diagnostic::error(
                    format!(
                        "`{}` must be a number, not {}",
                        prop.name(),
                        other.type_name()
                    ),
                    span,
                )
                .with_label(format!("{} here", other.type_name())),
            ),
        }
    }

    pub(super) fn as_vector(&mut self, value: Value, span: Span, prop: Prop) -> Eval<DVec3> {
        match value {
            Value::Vector(v) => Ok(v),
            other => self.fail(
                Diagnostic::error(
                    format!(
                        "`{}` must be a vector `<x, y, z>`, not {}",
                        prop.name(),
                        other.type_name()
                    ),
                    span,
                )
                .with_label(format!("{} here", other.type_name())),
            ),
        }
    }

    /// A colour: a vector of red, green, blue, or one number for a grey. Never negative.
    pub(super) fn as_color(&mut self, value: Value, span: Span, prop: Prop) -> Eval<Color> {
        let v = match value {
            Value::Number(x) => DVec3::splat(x),
            Value::Vector(v) => v,
            other => {
                return self.fail(
                    Diagnostic::error(
                        format!(
                            "`{}` must be a colour (`rgb(r, g, b)` or a number), not {}",
                            prop.name(),
                            other.type_name()
                        ),
                        span,
                    )
                    .with_label(format!("{} here", other.type_name())),
                )
            }
        };
        if v.cmplt(DVec3::ZERO).any() {
            return self.fail(
                Diagnostic::error(format!("`{}` cannot be negative", prop.name()), span)
                    .with_label(format!("this is <{}, {}, {}>", v.x, v.y, v.z)),
            );
        }
        if matches!(prop.name(), "diffuse" | "specular") && v.max_element() > 1.0 {
            self.warn_color_out_of_255(prop, v, span);
        }
        Ok(Color::new(v.x, v.y, v.z))
    }

    /// A surface colour over 1 is almost always written 0-255 (`rgb(255, 128, 0)`): it
    /// reflects 255 times the light that arrives. Said with the colour to write instead.
    fn warn_color_out_of_255(&mut self, prop: Prop, v: DVec3, span: Span) {
        let scaled = |x: f64| {
            let text = format!("{:.3}", x / 255.0);
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        };
        self.diagnostics.push(
            Diagnostic::warning(
                format!(
                    "`{}` is over 1 ({}, {}, {}): a surface colour goes from 0 to 1, so this \
                     reflects more light than arrives",
                    prop.name(),
                    v.x,
                    v.y,
                    v.z
                ),
                span,
            )
            .with_label("written 0-255?")
            .with_hint(format!(
                "if it was written from 0 to 255, divide by 255: `rgb({}, {}, {})`",
                scaled(v.x),
                scaled(v.y),
                scaled(v.z)
            )),
        );
    }

    /// A field of view under a few degrees is almost always radians (`0.785` for 45°).
    fn warn_fov_in_radians(&mut self, fov: f64, span: Span) {
        self.diagnostics.push(
            Diagnostic::warning(
                format!("a field of view of {fov} degrees is a very narrow telephoto"),
                span,
            )
            .with_label("radians?")
            .with_hint(format!(
                "`fov` is in degrees: {fov} radians is {}°, so write `fov {}`",
                (fov.to_degrees() * 10.0).round() / 10.0,
                fov.to_degrees().round()
            )),
        );
    }

    /// A colour of light (background, ambient): at most the largest intensity limit.
    pub(super) fn light_color(&mut self, value: Value, span: Span, prop: Prop) -> Eval<Color> {
        let color = self.as_color(value, span, prop)?;
        let largest = color.components().into_iter().fold(0.0, f64::max);
        if largest > limits::MAX_INTENSITY {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "`{}` must be at most the largest intensity limit ({:e}), not {largest:e}",
                        prop.name(),
                        limits::MAX_INTENSITY
                    ),
                    span,
                )
                .with_label("too bright"),
            );
        }
        Ok(color)
    }
}
