//! The IR's half of the property table: every colour a material has, as one row each (name,
//! field, largest value, how `whitted ir` shows it), read by validation, `ranges.rs`, the
//! printer and the language's evaluator.
//!
//! The language's table (`crates/lang/src/properties.rs`) says where a property may be
//! written, what it takes and how it is documented; this one says where its value lives in
//! the IR and what bounds it there, because validation and the printer cannot see the
//! language. A test in the language checks that both tables list the same material colours
//! with the same defaults.
//!
//! **To add a material colour**, add its field to [`Material`] (with its default), its row
//! here and its row in the language's table; then give it meaning in the tracer. Evaluation,
//! validation (finite, not negative, at most the row's limit), `whitted ir` and
//! `whitted ir --json` follow from the rows.

use crate::limits::{MAX_INTENSITY, MAX_REFLECTANCE};
use crate::scene::{Color, Material};

/// The largest value a colour's components may take, and the limit's name in messages.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColorLimit {
    pub max: f64,
    pub name: &'static str,
}

/// Intensities: colours of light a surface gives or passes on (ambient, diffuse, ...).
pub const INTENSITY: ColorLimit = ColorLimit {
    max: MAX_INTENSITY,
    name: "largest intensity",
};

/// Reflectances: the weights of secondary rays (reflective, transmissive).
pub const REFLECTANCE: ColorLimit = ColorLimit {
    max: MAX_REFLECTANCE,
    name: "largest reflectance",
};

/// How `whitted ir` shows a colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    /// In the material's fixed line (the colours the printer has always shown).
    InLine,
    /// After the fixed line, only when it is not its default (so that scenes that do not use
    /// it print as they did before it existed).
    WhenSet,
}

/// One colour of a material.
#[derive(Clone, Copy, Debug)]
pub struct MaterialColor {
    /// The property's name in the language (and in messages).
    pub name: &'static str,
    pub get: fn(&Material) -> Color,
    pub set: fn(&mut Material, Color),
    pub limit: ColorLimit,
    pub shown: Shown,
}

/// Every colour of a material, in the order validation reports them.
pub const MATERIAL_COLORS: &[MaterialColor] = &[
    MaterialColor {
        name: "ambient",
        get: |m| m.ambient,
        set: |m, c| m.ambient = c,
        limit: INTENSITY,
        shown: Shown::InLine,
    },
    MaterialColor {
        name: "diffuse",
        get: |m| m.diffuse,
        set: |m, c| m.diffuse = c,
        limit: INTENSITY,
        shown: Shown::InLine,
    },
    MaterialColor {
        name: "specular",
        get: |m| m.specular,
        set: |m, c| m.specular = c,
        limit: INTENSITY,
        shown: Shown::InLine,
    },
    MaterialColor {
        name: "reflective",
        get: |m| m.reflective,
        set: |m, c| m.reflective = c,
        limit: REFLECTANCE,
        shown: Shown::InLine,
    },
    MaterialColor {
        name: "transmissive",
        get: |m| m.transmissive,
        set: |m, c| m.transmissive = c,
        limit: REFLECTANCE,
        shown: Shown::InLine,
    },
    MaterialColor {
        name: "absorption",
        get: |m| m.absorption,
        set: |m, c| m.absorption = c,
        limit: INTENSITY,
        shown: Shown::InLine,
    },
    MaterialColor {
        name: "emission",
        get: |m| m.emission,
        set: |m, c| m.emission = c,
        limit: INTENSITY,
        shown: Shown::WhenSet,
    },
];

/// The row of the material colour called `name`.
pub fn material_color(name: &str) -> Option<&'static MaterialColor> {
    MATERIAL_COLORS.iter().find(|row| row.name == name)
}

/// One number of a material, with the range validation holds it to.
#[derive(Clone, Copy, Debug)]
pub struct MaterialNumber {
    pub name: &'static str,
    pub get: fn(&Material) -> f64,
    pub set: fn(&mut Material, f64),
    pub min: f64,
    pub max: f64,
}

/// The index of refraction.
pub const IOR: MaterialNumber = MaterialNumber {
    name: "ior",
    get: |m| m.ior,
    set: |m, x| m.ior = x,
    min: crate::limits::MIN_IOR,
    max: crate::limits::MAX_IOR,
};

/// The Phong exponent.
pub const SHININESS: MaterialNumber = MaterialNumber {
    name: "shininess",
    get: |m| m.shininess,
    set: |m, x| m.shininess = x,
    min: 0.0,
    max: MAX_INTENSITY,
};

/// The numbers of a material that a tool may change (the debugger's what-if).
pub const MATERIAL_NUMBERS: &[MaterialNumber] = &[IOR, SHININESS];

/// A light's colour: the one value of a light a tool may change.
pub const LIGHT_COLOR: ColorLimit = INTENSITY;

#[cfg(test)]
mod tests {
    use super::*;

    /// Each row reads and writes its own field and no other: a row copied from its
    /// neighbour with one name changed would fail here.
    #[test]
    fn every_row_reads_and_writes_its_own_field() {
        for (i, row) in MATERIAL_COLORS.iter().enumerate() {
            let mut m = Material::default();
            let marker = Color::new(0.25, 0.5, 0.75);
            (row.set)(&mut m, marker);
            assert_eq!((row.get)(&m), marker, "`{}`", row.name);
            for (j, other) in MATERIAL_COLORS.iter().enumerate() {
                if i != j {
                    assert_eq!(
                        (other.get)(&m),
                        (other.get)(&Material::default()),
                        "setting `{}` changed `{}`",
                        row.name,
                        other.name
                    );
                }
            }
        }
    }

    #[test]
    fn names_are_unique() {
        for (i, row) in MATERIAL_COLORS.iter().enumerate() {
            assert!(
                MATERIAL_COLORS[..i].iter().all(|r| r.name != row.name),
                "`{}` twice",
                row.name
            );
        }
    }
}
