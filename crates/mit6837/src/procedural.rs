//! The course's procedural materials (assignments 6 and 7): `Checkerboard`, `Noise`, `Marble`
//! and `Wood`, each a pattern over two earlier materials of the `Materials` block.
//!
//! The course's reader takes their fields in one order, and so does this one:
//!
//! ```text
//! Marble {
//!     Transform { <transforms> }     optional: texture space from world space
//!     materialIndex 0                the first material (weight 1 - v)
//!     materialIndex 1                the second material (weight v)
//!     octaves 4                      Noise, Marble, Wood
//!     frequency 2                    Marble, Wood
//!     amplitude 3                    Marble, Wood
//! }
//! ```
//!
//! What each computes (docs/courses.md, "Procedural materials"), with `p` the world-space
//! hit point mapped by the block's `Transform`: `Checkerboard` takes the first material
//! where `floor(x) + floor(y) + floor(z)` is even and the second where it is odd; the other
//! three blend the two by a weight `v` of Perlin's improved noise (`whitted_tracer`'s
//! `perlin.rs`).

use whitted_ir::{limits, DMat4, Diagnostic, Material, Pattern, PatternKind, Span};

use crate::convert::{list, Converter};
use crate::reader::Read;
use crate::tokens::Token;

/// The fields after the two `materialIndex`es, by material.
fn numbers(keyword: &str) -> &'static [&'static str] {
    match keyword {
        "Noise" => &["octaves"],
        "Marble" | "Wood" => &["octaves", "frequency", "amplitude"],
        _ => &[],
    }
}

impl<'a> Converter<'a, '_> {
    /// One procedural material, the `index`th of the `Materials` block: it may use the
    /// materials before it.
    pub(crate) fn procedural(&mut self, keyword: Token<'a>, index: usize) -> Read<()> {
        self.reader.expect("{")?;
        let mut texture_from_world = DMat4::IDENTITY;
        if self
            .reader
            .tokens
            .peek()
            .is_some_and(|t| t.text == "Transform")
        {
            let token = self.reader.next("`Transform`")?;
            texture_from_world = self.transform_only(token)?;
        }
        let first = self.material_index(keyword, index)?;
        let second = self.material_index(keyword, index)?;
        let mut values = [0.0f64; 3];
        let mut octaves = 0u32;
        for (i, name) in numbers(keyword.text).iter().enumerate() {
            let token = self.procedural_field(keyword, name)?;
            if *name == "octaves" {
                octaves = self.octaves(token)?;
            } else {
                values[i] = self
                    .reader
                    .number(&format!("the {}'s {name}", keyword.text))?;
            }
        }
        let close = self.procedural_field(keyword, "}")?;
        let [_, frequency, amplitude] = values;
        let kind = match keyword.text {
            "Checkerboard" => PatternKind::CourseCheckerboard,
            "Noise" => PatternKind::CourseNoise { octaves },
            "Marble" => PatternKind::CourseMarble {
                octaves,
                frequency,
                amplitude,
            },
            _ => PatternKind::CourseWood {
                octaves,
                frequency,
                amplitude,
            },
        };
        let span = Span::new(self.reader.file, keyword.start, close.end);
        // The host's own colours are never shaded (the pattern's parts are); it repeats the
        // first material's so that `whitted ir` and the linter see a plausible material.
        let host = Material {
            name: None,
            pattern: Some(Pattern {
                kind,
                a: self.materials[first],
                b: self.materials[second],
                scale: 1.0,
                pattern_from_object: texture_from_world,
            }),
            ..self.scene.materials[self.materials[first]].clone()
        };
        let handle = self.scene.materials.append(host, span);
        self.materials.push(handle);
        Ok(())
    }

    /// The next word, which must be `name` (a field, or the closing brace).
    fn procedural_field(&mut self, keyword: Token<'a>, name: &str) -> Read<Token<'a>> {
        let shown = if name == "}" {
            "`}`".to_string()
        } else {
            format!("`{name}`")
        };
        let token = self.reader.next(&shown)?;
        if token.text == name {
            return Ok(token);
        }
        let mut order = vec!["materialIndex", "materialIndex"];
        order.extend(numbers(keyword.text));
        let message = if token.text == "}" {
            format!("`{}` needs {shown} here", keyword.text)
        } else if name == "}" {
            format!(
                "`{}` has no more fields, found `{}`",
                keyword.text, token.text
            )
        } else {
            format!(
                "expected {shown} in `{}`, found `{}`",
                keyword.text, token.text
            )
        };
        Err(Box::new(
            Diagnostic::error(message, self.reader.span(token))
                .with_label(format!("expected {shown}"))
                .with_hint(format!(
                    "`{}` takes, in this order, an optional `Transform {{ ... }}`, then {}",
                    keyword.text,
                    list(&order)
                )),
        ))
    }

    /// `materialIndex i`, which must name a material defined before the `index`th.
    fn material_index(&mut self, keyword: Token<'a>, index: usize) -> Read<usize> {
        self.procedural_field(keyword, "materialIndex")?;
        let token = self.reader.next("a material index")?;
        let Ok(i) = token.text.parse::<u64>() else {
            return self.reader.error_at(
                token,
                format!(
                    "expected a material index (a whole number), found `{}`",
                    token.text
                ),
            );
        };
        if i < index as u64 {
            return Ok(i as usize);
        }
        let defined = match index {
            0 => "no material is defined before it".to_string(),
            1 => "only material 0 is defined before it".to_string(),
            n => format!("only materials 0 to {} are defined before it", n - 1),
        };
        Err(Box::new(
            Diagnostic::error(
                format!(
                    "`{}` (material {index}) refers to material {i}: {defined}",
                    keyword.text
                ),
                self.reader.span(token),
            )
            .with_label("not defined yet")
            .with_hint(
                "a procedural material blends materials listed before it in `Materials`; \
                 move it after the materials it uses",
            ),
        ))
    }

    /// The number of noise octaves: 1 to the limit.
    fn octaves(&mut self, keyword: Token<'a>) -> Read<u32> {
        let what = "the number of octaves";
        let value = self.reader.tokens.peek();
        let octaves =
            self.reader
                .count(what, limits::MAX_NOISE_OCTAVES as usize, "noise octaves")?;
        if octaves == 0 {
            let at = value.map_or(self.reader.span(keyword), |t| self.reader.span(t));
            return Err(Box::new(
                Diagnostic::error("`octaves` must be at least 1", at)
                    .with_label("no octave")
                    .with_hint(format!(
                        "the noise sums octaves 0 to octaves - 1; from 1 to {} are allowed",
                        limits::MAX_NOISE_OCTAVES
                    )),
            ));
        }
        Ok(octaves as u32)
    }
}
