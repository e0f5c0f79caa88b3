//! What an editor's hover shows of a definition, recorded while the scene runs: a binding's
//! value, a loop's range, a material's properties, by the span of the name. Recorded only
//! when an editor index was asked for (`CompileOptions::index`); a render pays one check.

use std::collections::HashMap;

use whitted_ir::{Color, Fresnel, Material, Span};

use super::Evaluator;
use crate::editor::Shown;
use crate::strings::format_number;
use crate::value::Value;

impl Evaluator<'_> {
    /// Notes that the definition named at `span` took `value`.
    pub(super) fn show_value(&mut self, span: Span, value: Value) {
        if self.shown.is_none() {
            return;
        }
        let text = match value {
            Value::Material(id) => match self.materials.get(id as usize) {
                Some(def) => material_text(&def.material),
                None => self.value_text(value, 0),
            },
            other => self.value_text(other, 0),
        };
        self.show_text(span, text);
    }

    /// Notes a loop's range: its variable's first and last value and how many it takes.
    pub(super) fn show_range(&mut self, span: Span, first: i128, last: i128, step: i128) {
        if self.shown.is_none() {
            return;
        }
        let text = if step == 0 || (step > 0 && last < first) || (step < 0 && last > first) {
            "no values (the loop does not run)".to_string()
        } else {
            let count = (last - first) / step + 1;
            let last = first + (count - 1) * step;
            let by = if step == 1 {
                String::new()
            } else {
                format!(" by {step}")
            };
            let values = if count == 1 { "value" } else { "values" };
            format!("{first} to {last}{by} ({count} {values})")
        };
        self.show_text(span, text);
    }

    fn show_text(&mut self, span: Span, text: String) {
        let Some(shown) = self.shown.as_mut() else {
            return;
        };
        match shown.get_mut(&span) {
            Some(known) if known.text != text => known.others = known.others.saturating_add(1),
            Some(_) => {}
            None => {
                shown.insert(span, Shown { text, others: 0 });
            }
        }
    }

    pub(crate) fn take_shown(&mut self) -> Option<HashMap<Span, Shown>> {
        self.shown.take()
    }
}

/// `rgb(r, g, b)`: a colour as editors recognise it (CSS's form, components 0 to 255).
fn rgb(color: Color) -> String {
    let byte = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
    format!(
        "rgb({}, {}, {})",
        byte(color.r),
        byte(color.g),
        byte(color.b)
    )
}

/// A colour with its exact components when they are not whole bytes' worth.
fn color_text(color: Color) -> String {
    format!(
        "{} <{}, {}, {}>",
        rgb(color),
        format_number(color.r),
        format_number(color.g),
        format_number(color.b)
    )
}

/// A material's properties, one a line: the colours as `rgb(...)`, then the numbers.
fn material_text(material: &Material) -> String {
    let mut lines = vec![
        format!("diffuse {}", color_text(material.diffuse)),
        format!("ambient {}", color_text(material.ambient)),
        format!("specular {}", color_text(material.specular)),
        format!("shininess {}", format_number(material.shininess)),
        format!("reflective {}", color_text(material.reflective)),
        format!("transmissive {}", color_text(material.transmissive)),
        format!("ior {}", format_number(material.ior)),
    ];
    if material.fresnel != Fresnel::Off {
        lines.push(format!("fresnel {:?}", material.fresnel).to_lowercase());
    }
    if material.absorption != Color::BLACK {
        lines.push(format!("absorption {}", color_text(material.absorption)));
    }
    if material.emission != Color::BLACK {
        lines.push(format!("emission {}", color_text(material.emission)));
    }
    if material.pattern.is_some() {
        lines.push("a pattern of two materials".to_string());
    }
    lines.join("\n")
}
