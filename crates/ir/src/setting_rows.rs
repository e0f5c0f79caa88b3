//! The one table of render settings: for each, its name, the value it takes (with its range),
//! its default, a line of documentation, and how to read and write its field of
//! [`Settings`].
//!
//! Everything that names a setting reads these rows: the language's `settings` block and
//! `--set` (its property rows take their kind, default and doc from here), the command line's
//! `--max-depth`, `--width`, `--height` and `--spp` (applied through [`apply`] before the scene
//! is prepared, so that the IR is the whole truth of what is rendered), `--set` for a MIT
//! 6.837 scene ([`SettingRow::parse`]), the debugger's what-if and the docs test.
//!
//! **To add a setting**, add its field to [`Settings`] (with its default), its row here and
//! its property line in the language's table (`crates/lang/src/properties.rs`, which reads
//! the kind, default and doc from the row); then give it meaning in the tracer.

use crate::limits::{self, MAX_INTENSITY};
use crate::scene::{
    Color, Filter, Fresnel, Highlight, SamplePosition, Sampling, Settings, ShadowMode,
};

/// The value a setting takes, with its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SettingKind {
    /// A whole number from `min` to `max`.
    Whole { min: u32, max: u32 },
    /// A number from `min` to `max` (`min` itself excluded when `open`).
    Number { min: f64, open: bool, max: f64 },
    /// A colour of light: each component from 0 to the largest intensity.
    LightColor,
    /// One of these words.
    Word(&'static [&'static str]),
}

/// A setting's value, of its row's kind.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SettingValue {
    Whole(u32),
    Number(f64),
    Color(Color),
    Word(&'static str),
}

/// One setting.
#[derive(Clone, Copy, Debug)]
pub struct SettingRow {
    /// The setting's name in the language, in `--set` and in messages.
    pub name: &'static str,
    pub kind: SettingKind,
    /// The default as the docs write it.
    pub default: &'static str,
    pub doc: &'static str,
    /// The value in `settings`; `None` when it has none (an automatic epsilon).
    pub get: fn(&Settings) -> Option<SettingValue>,
    /// Writes a value of the row's kind (checked by [`SettingRow::check`]) into `settings`.
    pub set: fn(&mut Settings, SettingValue),
}

const ON_OFF: &[&str] = &["on", "off"];

fn on_off(on: bool) -> SettingValue {
    SettingValue::Word(if on { "on" } else { "off" })
}

fn whole(value: SettingValue) -> u32 {
    match value {
        SettingValue::Whole(n) => n,
        SettingValue::Number(x) => x as u32,
        _ => 0,
    }
}

fn number(value: SettingValue) -> f64 {
    match value {
        SettingValue::Number(x) => x,
        SettingValue::Whole(n) => f64::from(n),
        _ => 0.0,
    }
}

fn color(value: SettingValue) -> Color {
    match value {
        SettingValue::Color(c) => c,
        SettingValue::Number(x) => Color::gray(x),
        _ => Color::BLACK,
    }
}

fn word(value: SettingValue) -> &'static str {
    match value {
        SettingValue::Word(w) => w,
        _ => "",
    }
}

pub const WIDTH: SettingRow = SettingRow {
    name: "width",
    kind: SettingKind::Whole {
        min: 1,
        max: limits::MAX_IMAGE_SIDE,
    },
    default: "640",
    doc: "image width in pixels",
    get: |s| Some(SettingValue::Whole(s.width)),
    set: |s, v| s.width = whole(v),
};

pub const HEIGHT: SettingRow = SettingRow {
    name: "height",
    kind: SettingKind::Whole {
        min: 1,
        max: limits::MAX_IMAGE_SIDE,
    },
    default: "480",
    doc: "image height in pixels",
    get: |s| Some(SettingValue::Whole(s.height)),
    set: |s, v| s.height = whole(v),
};

pub const MAX_DEPTH: SettingRow = SettingRow {
    name: "max_depth",
    kind: SettingKind::Whole {
        min: 0,
        max: limits::MAX_DEPTH,
    },
    default: "5",
    doc: "rays deeper than this are not traced (the camera ray is depth 0)",
    get: |s| Some(SettingValue::Whole(s.max_depth)),
    set: |s, v| s.max_depth = whole(v),
};

pub const MIN_WEIGHT: SettingRow = SettingRow {
    name: "min_weight",
    kind: SettingKind::Number {
        min: 0.0,
        open: false,
        max: 1.0,
    },
    default: "0.001",
    doc: "a reflected or refracted ray contributing less is not traced",
    get: |s| Some(SettingValue::Number(s.min_weight)),
    set: |s, v| s.min_weight = number(v),
};

pub const SAMPLES: SettingRow = SettingRow {
    name: "samples",
    kind: SettingKind::Whole {
        min: 1,
        max: limits::MAX_SAMPLES_PER_PIXEL,
    },
    default: "1",
    doc: "samples per pixel",
    get: |s| Some(SettingValue::Whole(s.samples_per_pixel)),
    set: |s, v| s.samples_per_pixel = whole(v),
};

pub const SAMPLING: SettingRow = SettingRow {
    name: "sampling",
    kind: SettingKind::Word(&["jittered", "grid", "random"]),
    default: "jittered",
    doc: "where a pixel's samples fall: `jittered` (stratified, no pattern to alias), `grid` (a regular grid, the course's uniform sampler) or `random` (each anywhere, the course's random sampler)",
    get: |s| {
        Some(SettingValue::Word(match s.sampling {
            Sampling::Jittered => "jittered",
            Sampling::Grid => "grid",
            Sampling::Random => "random",
        }))
    },
    set: |s, v| {
        s.sampling = match word(v) {
            "grid" => Sampling::Grid,
            "random" => Sampling::Random,
            _ => Sampling::Jittered,
        }
    },
};

pub const FILTER: SettingRow = SettingRow {
    name: "filter",
    kind: SettingKind::Word(&["box", "tent", "gaussian"]),
    default: "box",
    doc: "how the samples around a pixel make its value (the weighted mean of every sample within the filter's reach, from this pixel and its neighbours): `box` (weight 1 inside a square), `tent` (falling linearly to 0 at the radius) or `gaussian` (σ the radius, cut at 2σ)",
    get: |s| {
        Some(SettingValue::Word(match s.filter {
            Filter::Box => "box",
            Filter::Tent => "tent",
            Filter::Gaussian => "gaussian",
        }))
    },
    set: |s, v| {
        s.filter = match word(v) {
            "tent" => Filter::Tent,
            "gaussian" => Filter::Gaussian,
            _ => Filter::Box,
        }
    },
};

pub const FILTER_RADIUS: SettingRow = SettingRow {
    name: "filter_radius",
    kind: SettingKind::Number {
        min: 0.0,
        open: true,
        max: limits::MAX_FILTER_RADIUS,
    },
    default: "0.5",
    doc: "the filter's radius in pixels (the gaussian's σ); `box` with 0.5 is each pixel's own samples, averaged",
    get: |s| Some(SettingValue::Number(s.filter_radius)),
    set: |s, v| s.filter_radius = number(v),
};

pub const BACKGROUND: SettingRow = SettingRow {
    name: "background",
    kind: SettingKind::LightColor,
    default: "black",
    doc: "the colour of rays that hit nothing",
    get: |s| Some(SettingValue::Color(s.background)),
    set: |s, v| s.background = color(v),
};

pub const AMBIENT: SettingRow = SettingRow {
    name: "ambient",
    kind: SettingKind::LightColor,
    default: "white",
    doc: "the global ambient light",
    get: |s| Some(SettingValue::Color(s.ambient)),
    set: |s, v| s.ambient = color(v),
};

pub const EPSILON: SettingRow = SettingRow {
    name: "epsilon",
    kind: SettingKind::Number {
        min: 0.0,
        open: false,
        max: 1.0,
    },
    default: "automatic",
    doc: "how far off a surface secondary rays start (0: not at all, the classic shadow acne)",
    get: |s| s.epsilon.map(SettingValue::Number),
    set: |s, v| s.epsilon = Some(number(v)),
};

pub const SHADOWS: SettingRow = SettingRow {
    name: "shadows",
    kind: SettingKind::Word(&["opaque", "filtered", "none"]),
    default: "opaque",
    doc: "whether transparent objects let light through to what they shadow (`none`: no shadow rays at all)",
    get: |s| {
        Some(SettingValue::Word(match s.shadows {
            ShadowMode::Opaque => "opaque",
            ShadowMode::Filtered => "filtered",
            ShadowMode::None => "none",
        }))
    },
    set: |s, v| {
        s.shadows = match word(v) {
            "filtered" => ShadowMode::Filtered,
            "none" => ShadowMode::None,
            _ => ShadowMode::Opaque,
        }
    },
};

pub const HIGHLIGHT: SettingRow = SettingRow {
    name: "highlight",
    kind: SettingKind::Word(&["phong", "blinn"]),
    default: "phong",
    doc: "the specular model: Phong ks·(R·V)^n or Blinn-Phong ks·(N·H)^n",
    get: |s| {
        Some(SettingValue::Word(match s.highlight {
            Highlight::Phong => "phong",
            Highlight::Blinn => "blinn",
        }))
    },
    set: |s, v| {
        s.highlight = match word(v) {
            "blinn" => Highlight::Blinn,
            _ => Highlight::Phong,
        }
    },
};

pub const SHADE_BACK: SettingRow = SettingRow {
    name: "shade_back",
    kind: SettingKind::Word(ON_OFF),
    default: "on",
    doc: "whether lights shade a surface seen from its back (`off`: only its ambient, emission, reflection and refraction)",
    get: |s| Some(on_off(s.shade_back)),
    set: |s, v| s.shade_back = word(v) != "off",
};

pub const ATTENUATION_CLAMP: SettingRow = SettingRow {
    name: "attenuation_clamp",
    kind: SettingKind::Word(ON_OFF),
    default: "on",
    doc: "whether point and spot lights' distance attenuation is clamped at 1",
    get: |s| Some(on_off(s.attenuation_clamp)),
    set: |s, v| s.attenuation_clamp = word(v) != "off",
};

pub const ENERGY_CLAMP: SettingRow = SettingRow {
    name: "energy_clamp",
    kind: SettingKind::Word(ON_OFF),
    default: "on",
    doc: "whether a surface's reflective and transmissive weights are scaled down to add up to at most 1",
    get: |s| Some(on_off(s.energy_clamp)),
    set: |s, v| s.energy_clamp = word(v) != "off",
};

pub const BACK_AMBIENT: SettingRow = SettingRow {
    name: "back_ambient",
    kind: SettingKind::Word(ON_OFF),
    default: "on",
    doc: "with `shade_back off`, whether a surface seen from its back keeps its ambient and emission (`off`: black but for its reflected and transmitted rays)",
    get: |s| Some(on_off(s.back_ambient)),
    set: |s, v| s.back_ambient = word(v) != "off",
};

pub const HIGHLIGHT_GATE: SettingRow = SettingRow {
    name: "highlight_gate",
    kind: SettingKind::Word(ON_OFF),
    default: "on",
    doc: "whether a light behind the surface (N·L <= 0) adds no highlight (`off`: the highlight whatever N·L is)",
    get: |s| Some(on_off(s.highlight_gate)),
    set: |s, v| s.highlight_gate = word(v) != "off",
};

pub const SAMPLE_POSITION: SettingRow = SettingRow {
    name: "sample_position",
    kind: SettingKind::Word(&["centre", "corner"]),
    default: "centre",
    doc: "where a pixel's one sample falls: its centre, or its corner (every sample half a pixel up and left)",
    get: |s| {
        Some(SettingValue::Word(match s.sample_position {
            SamplePosition::Centre => "centre",
            SamplePosition::Corner => "corner",
        }))
    },
    set: |s, v| {
        s.sample_position = match word(v) {
            "corner" => SamplePosition::Corner,
            _ => SamplePosition::Centre,
        }
    },
};

pub const FLIP_NORMALS: SettingRow = SettingRow {
    name: "flip_normals",
    kind: SettingKind::Word(ON_OFF),
    default: "on",
    doc: "whether a surface hit from its back has its normal turned to face the ray (`off`: the classic bug, for `whitted grade`)",
    get: |s| Some(on_off(s.flip_normals)),
    set: |s, v| s.flip_normals = word(v) != "off",
};

pub const EXIT_IOR: SettingRow = SettingRow {
    name: "exit_ior",
    kind: SettingKind::Word(&["inverted", "uninverted"]),
    default: "inverted",
    doc: "the indices a ray leaving a solid refracts with: `inverted` (ior to 1), or `uninverted` (1 to ior, the classic bug)",
    get: |s| {
        Some(SettingValue::Word(if s.exit_ior_inverted {
            "inverted"
        } else {
            "uninverted"
        }))
    },
    set: |s, v| s.exit_ior_inverted = word(v) != "uninverted",
};

pub const TOTAL_INTERNAL_REFLECTION: SettingRow = SettingRow {
    name: "total_internal_reflection",
    kind: SettingKind::Word(ON_OFF),
    default: "on",
    doc: "whether total internal reflection stops the transmitted ray (`off`: the classic bug, it is traced anyway and returns the background)",
    get: |s| Some(on_off(s.total_internal_reflection)),
    set: |s, v| s.total_internal_reflection = word(v) != "off",
};

pub const LIGHT_FALLOFF: SettingRow = SettingRow {
    name: "light_falloff",
    kind: SettingKind::Word(ON_OFF),
    default: "on",
    doc: "whether point and spot lights fade with distance as their `attenuation` says (`off`: full colour everywhere)",
    get: |s| Some(on_off(s.light_falloff)),
    set: |s, v| s.light_falloff = word(v) != "off",
};

pub const FRESNEL_RULE: SettingRow = SettingRow {
    name: "fresnel_rule",
    kind: SettingKind::Word(&["material", "off", "schlick", "exact"]),
    default: "material",
    doc: "the Fresnel rule of every material (`material`: each its own `fresnel`)",
    get: |s| {
        Some(SettingValue::Word(match s.fresnel_rule {
            None => "material",
            Some(f) => f.name(),
        }))
    },
    set: |s, v| {
        s.fresnel_rule = match word(v) {
            "off" => Some(Fresnel::Off),
            "schlick" => Some(Fresnel::Schlick),
            "exact" => Some(Fresnel::Exact),
            _ => None,
        }
    },
};

pub const FRAMES: SettingRow = SettingRow {
    name: "frames",
    kind: SettingKind::Whole {
        min: 1,
        max: limits::MAX_FRAMES,
    },
    default: "1",
    doc: "how many frames the animation has (1: a still); `frame` runs from `first_frame` to `first_frame + frames - 1`",
    get: |s| Some(SettingValue::Whole(s.frames)),
    set: |s, v| s.frames = whole(v),
};

pub const FIRST_FRAME: SettingRow = SettingRow {
    name: "first_frame",
    kind: SettingKind::Whole {
        min: 0,
        max: limits::MAX_FIRST_FRAME,
    },
    default: "0",
    doc: "the animation's first frame number",
    get: |s| Some(SettingValue::Whole(s.first_frame)),
    set: |s, v| s.first_frame = whole(v),
};

pub const FPS: SettingRow = SettingRow {
    name: "fps",
    kind: SettingKind::Whole {
        min: 1,
        max: limits::MAX_FPS,
    },
    default: "24",
    doc: "frames per second of the animation (an animated PNG's or GIF's frame delay, a video's rate)",
    get: |s| Some(SettingValue::Whole(s.fps)),
    set: |s, v| s.fps = whole(v),
};

/// Every setting, in the order the docs list them.
pub const SETTINGS: &[SettingRow] = &[
    WIDTH,
    HEIGHT,
    MAX_DEPTH,
    MIN_WEIGHT,
    SAMPLES,
    SAMPLING,
    FILTER,
    FILTER_RADIUS,
    BACKGROUND,
    AMBIENT,
    EPSILON,
    SHADOWS,
    HIGHLIGHT,
    SHADE_BACK,
    ATTENUATION_CLAMP,
    ENERGY_CLAMP,
    BACK_AMBIENT,
    HIGHLIGHT_GATE,
    SAMPLE_POSITION,
    FLIP_NORMALS,
    EXIT_IOR,
    TOTAL_INTERNAL_REFLECTION,
    LIGHT_FALLOFF,
    FRESNEL_RULE,
    FRAMES,
    FIRST_FRAME,
    FPS,
];

/// The rules where the MIT 6.837 course's model and whitted's differ, and the switches
/// that render a classic student bug (`whitted grade`): every setting after the clamps.
pub const SWITCHES: &[SettingRow] = &[
    BACK_AMBIENT,
    HIGHLIGHT_GATE,
    SAMPLE_POSITION,
    FLIP_NORMALS,
    EXIT_IOR,
    TOTAL_INTERNAL_REFLECTION,
    LIGHT_FALLOFF,
    FRESNEL_RULE,
];

/// The row of the setting called `name`.
pub fn setting(name: &str) -> Option<&'static SettingRow> {
    SETTINGS.iter().find(|row| row.name == name)
}

/// Every setting's name, for "did you mean" and "the settings are ...".
pub fn setting_names() -> impl Iterator<Item = &'static str> {
    SETTINGS.iter().map(|row| row.name)
}

impl SettingKind {
    /// The accepted values in words: "a whole number from 0 to 256", "`opaque`, `filtered`
    /// or `none`".
    pub fn range_in_words(self) -> String {
        match self {
            SettingKind::Whole { min, max } => format!("a whole number from {min} to {max}"),
            SettingKind::Number { min, open, max } => match (open, max.is_finite()) {
                (false, true) => {
                    format!("a number from {} to {}", number_text(min), number_text(max))
                }
                (true, true) => format!(
                    "a number above {} and at most {}",
                    number_text(min),
                    number_text(max)
                ),
                (false, false) => format!("a number of at least {}", number_text(min)),
                (true, false) => format!("a number above {}", number_text(min)),
            },
            SettingKind::LightColor => format!(
                "a colour with components from 0 to {}: a grey (`0.5`) or rgb(r, g, b)",
                number_text(MAX_INTENSITY)
            ),
            SettingKind::Word(words) => match words {
                [] => String::new(),
                [only] => format!("`{only}`"),
                [init @ .., last] => {
                    let init: Vec<String> = init.iter().map(|w| format!("`{w}`")).collect();
                    format!("{} or `{last}`", init.join(", "))
                }
            },
        }
    }
}

impl SettingRow {
    /// Whether `value` is of this row's kind and in its range; the error says the range in
    /// words.
    pub fn check(&self, value: SettingValue) -> Result<SettingValue, String> {
        let fits = match (self.kind, value) {
            (SettingKind::Whole { min, max }, SettingValue::Whole(n)) => (min..=max).contains(&n),
            (SettingKind::Number { min, open, max }, SettingValue::Number(x)) => {
                x.is_finite() && (if open { x > min } else { x >= min }) && x <= max
            }
            (SettingKind::LightColor, SettingValue::Color(c)) => [c.r, c.g, c.b]
                .iter()
                .all(|x| x.is_finite() && (0.0..=MAX_INTENSITY).contains(x)),
            (SettingKind::Word(words), SettingValue::Word(w)) => words.contains(&w),
            _ => false,
        };
        if fits {
            Ok(value)
        } else {
            Err(format!(
                "`{}` must be {}",
                self.name,
                self.kind.range_in_words()
            ))
        }
    }

    /// Reads a plain value typed on a command line or into the debugger: a number, a word,
    /// a grey, three numbers or `rgb(r, g, b)` (no expressions: a scene in the language
    /// evaluates `--set` values as expressions itself).
    pub fn parse(&self, text: &str) -> Result<SettingValue, String> {
        let text = text.trim();
        let wrong = || format!("`{}` must be {}", self.name, self.kind.range_in_words());
        let value = match self.kind {
            SettingKind::Whole { .. } => {
                SettingValue::Whole(text.parse::<u32>().map_err(|_| wrong())?)
            }
            SettingKind::Number { .. } => {
                SettingValue::Number(plain_number(text).ok_or_else(wrong)?)
            }
            SettingKind::LightColor => SettingValue::Color(plain_color(text).ok_or_else(wrong)?),
            SettingKind::Word(words) => SettingValue::Word(
                words
                    .iter()
                    .copied()
                    .find(|w| *w == text)
                    .ok_or_else(wrong)?,
            ),
        };
        self.check(value)
    }

    /// The value in `settings` as the language writes it (`automatic` for a value it has
    /// not got).
    pub fn text(&self, settings: &Settings) -> String {
        match (self.get)(settings) {
            Some(value) => value_text(value),
            None => self.default.to_string(),
        }
    }
}

/// A value as the language writes it: `5`, `0.001`, `rgb(1, 0.5, 0)`, a grey as one number.
pub fn value_text(value: SettingValue) -> String {
    match value {
        SettingValue::Whole(n) => n.to_string(),
        SettingValue::Number(x) => number_text(x),
        SettingValue::Color(c) if c.r == c.g && c.g == c.b => number_text(c.r),
        SettingValue::Color(c) => format!(
            "rgb({}, {}, {})",
            number_text(c.r),
            number_text(c.g),
            number_text(c.b)
        ),
        SettingValue::Word(w) => w.to_string(),
    }
}

/// Sets the setting called `name` to `value`, checked against its row.
pub fn apply(settings: &mut Settings, name: &str, value: SettingValue) -> Result<(), String> {
    let row = setting(name).ok_or_else(|| format!("there is no setting `{name}`"))?;
    let value = row.check(value)?;
    (row.set)(settings, value);
    Ok(())
}

/// Text that reads back as the same number: plain when short (`0.001`), with an exponent
/// when that is much shorter (`1e-9`, not `0.000000001`).
fn number_text(x: f64) -> String {
    let plain = format!("{x}");
    let exponent = format!("{x:e}");
    if plain.len() > 6 && exponent.len() < plain.len() {
        exponent
    } else {
        plain
    }
}

/// A finite decimal number (no `inf`, no `nan`, which Rust's parser would take).
pub fn plain_number(text: &str) -> Option<f64> {
    let plain = text
        .chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'));
    text.parse::<f64>().ok().filter(|x| plain && x.is_finite())
}

/// A grey (`0.5`), three numbers (`1 0.5 0`, `1, 0.5, 0`), `<1, 0.5, 0>` or `rgb(1, 0.5, 0)`.
pub fn plain_color(text: &str) -> Option<Color> {
    let text = text.trim();
    let inner = text
        .strip_prefix("rgb(")
        .and_then(|rest| rest.strip_suffix(')'))
        .or_else(|| {
            text.strip_prefix('<')
                .and_then(|rest| rest.strip_suffix('>'))
        })
        .unwrap_or(text);
    let parts: Vec<f64> = inner
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|p| !p.is_empty())
        .map(plain_number)
        .collect::<Option<_>>()?;
    match parts.as_slice() {
        [grey] => Some(Color::gray(*grey)),
        [r, g, b] => Some(Color::new(*r, *g, *b)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each row writes its own field and no other, and reads back what it wrote: a row
    /// copied from its neighbour with one name changed fails here.
    #[test]
    fn every_row_reads_and_writes_its_own_field() {
        for (i, row) in SETTINGS.iter().enumerate() {
            let value = match row.kind {
                SettingKind::Whole { min, max } => SettingValue::Whole((min + 1).min(max)),
                SettingKind::Number { max, .. } => SettingValue::Number(max),
                SettingKind::LightColor => SettingValue::Color(Color::new(0.25, 0.5, 0.75)),
                SettingKind::Word(words) => SettingValue::Word(words[words.len() - 1]),
            };
            let mut settings = Settings::default();
            apply(&mut settings, row.name, value).expect("in range");
            assert_eq!((row.get)(&settings), Some(value), "`{}`", row.name);
            for (j, other) in SETTINGS.iter().enumerate() {
                if i != j {
                    assert_eq!(
                        (other.get)(&settings),
                        (other.get)(&Settings::default()),
                        "setting `{}` changed `{}`",
                        row.name,
                        other.name
                    );
                }
            }
        }
    }

    /// The defaults the docs write are the defaults [`Settings::default`] has.
    #[test]
    fn written_defaults_are_the_defaults() {
        let defaults = Settings::default();
        for row in SETTINGS {
            let written = match row.default {
                "black" => "0".to_string(),
                "white" => "1".to_string(),
                other => other.to_string(),
            };
            assert_eq!(row.text(&defaults), written, "`{}`", row.name);
        }
    }

    #[test]
    fn values_out_of_range_say_the_range_in_words() {
        let depth = setting("max_depth").expect("a row");
        assert_eq!(depth.parse(" 8 "), Ok(SettingValue::Whole(8)));
        assert_eq!(
            depth.parse("300").unwrap_err(),
            "`max_depth` must be a whole number from 0 to 256"
        );
        assert!(depth.parse("-1").is_err());
        let weight = setting("min_weight").expect("a row");
        assert_eq!(
            weight.parse("inf").unwrap_err(),
            "`min_weight` must be a number from 0 to 1"
        );
        let shadows = setting("shadows").expect("a row");
        assert_eq!(
            shadows.parse("soft").unwrap_err(),
            "`shadows` must be `opaque`, `filtered` or `none`"
        );
        let background = setting("background").expect("a row");
        assert_eq!(
            background.parse("<1, 0.5, 0>"),
            Ok(SettingValue::Color(Color::new(1.0, 0.5, 0.0)))
        );
        assert_eq!(
            background.parse("rgb(1,2)").unwrap_err(),
            "`background` must be a colour with components from 0 to 1e6: a grey (`0.5`) or rgb(r, g, b)"
        );
        assert_eq!(
            setting("epsilon").map(|r| r.kind.range_in_words()),
            Some("a number from 0 to 1".to_string())
        );
    }

    #[test]
    fn names_are_unique() {
        for (i, row) in SETTINGS.iter().enumerate() {
            assert!(
                SETTINGS[..i].iter().all(|r| r.name != row.name),
                "`{}` twice",
                row.name
            );
        }
    }
}
