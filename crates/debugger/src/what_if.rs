//! What-if: the values the what-if popup (`w`) can change (render settings, the selected
//! ray's material, the lights' colours), reading a typed value within the range the scene
//! language accepts, and a copy of the scene with one value changed, validated again.

use whitted_ir::limits::{MAX_DEPTH, MAX_INTENSITY, MAX_IOR, MAX_REFLECTANCE, MIN_IOR, MIN_SIZE};
use whitted_ir::{validate, Color, Handle, Light, Material, Scene, ValidScene};

/// One value the popup can change.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Param {
    MaxDepth,
    MinWeight,
    Epsilon,
    Ior(Handle<Material>),
    Reflective(Handle<Material>),
    Transmissive(Handle<Material>),
    LightColor(Handle<Light>),
}

/// A typed value, checked against its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Whole(u32),
    Number(f64),
    Color(Color),
}

impl Param {
    /// The property's name in the scene language.
    pub fn property(self) -> &'static str {
        match self {
            Param::MaxDepth => "max_depth",
            Param::MinWeight => "min_weight",
            Param::Epsilon => "epsilon",
            Param::Ior(_) => "ior",
            Param::Reflective(_) => "reflective",
            Param::Transmissive(_) => "transmissive",
            Param::LightColor(_) => "color",
        }
    }

    /// Where the value lives, in words: `settings`, `material glass`, `light sun`.
    pub fn owner(self, scene: &Scene) -> String {
        match self {
            Param::MaxDepth | Param::MinWeight | Param::Epsilon => "settings".to_string(),
            Param::Ior(h) | Param::Reflective(h) | Param::Transmissive(h) => {
                let name = scene.materials.get(h).and_then(|m| m.name.clone());
                format!(
                    "material {}",
                    name.unwrap_or_else(|| format!("#{}", h.index()))
                )
            }
            Param::LightColor(h) => {
                let name = scene.lights.get(h).and_then(|l| l.name.clone());
                format!(
                    "light {}",
                    name.unwrap_or_else(|| format!("#{}", h.index()))
                )
            }
        }
    }

    /// The accepted range in words, for the popup and for error messages.
    pub fn range(self) -> String {
        match self {
            Param::MaxDepth => format!("a whole number from 0 to {MAX_DEPTH}"),
            Param::MinWeight => "a number from 0 to 1".to_string(),
            Param::Epsilon => format!("a number from {MIN_SIZE:e} to 1"),
            Param::Ior(_) => format!("a number from {MIN_IOR} to {MAX_IOR}"),
            Param::Reflective(_) | Param::Transmissive(_) => {
                format!("a grey 0 to {MAX_REFLECTANCE}, or rgb(r, g, b) in that range")
            }
            Param::LightColor(_) => {
                format!("a grey 0 to {MAX_INTENSITY:e}, or rgb(r, g, b) in that range")
            }
        }
    }

    /// The value in `scene`; `None` for an automatic epsilon or a handle not in the scene.
    pub fn current(self, scene: &Scene) -> Option<Value> {
        let settings = &scene.settings;
        Some(match self {
            Param::MaxDepth => Value::Whole(settings.max_depth),
            Param::MinWeight => Value::Number(settings.min_weight),
            Param::Epsilon => Value::Number(settings.epsilon?),
            Param::Ior(h) => Value::Number(scene.materials.get(h)?.ior),
            Param::Reflective(h) => Value::Color(scene.materials.get(h)?.reflective),
            Param::Transmissive(h) => Value::Color(scene.materials.get(h)?.transmissive),
            Param::LightColor(h) => Value::Color(scene.lights.get(h)?.color),
        })
    }

    /// The current value as the scene language writes it (`automatic` for epsilon unset).
    pub fn current_text(self, scene: &Scene) -> String {
        match self.current(scene) {
            Some(value) => value_text(value),
            None if self == Param::Epsilon => "automatic".to_string(),
            None => "?".to_string(),
        }
    }

    /// Reads `text` as a value of this parameter, within the range the language accepts.
    pub fn parse(self, text: &str) -> Result<Value, String> {
        let text = text.trim();
        let out_of_range = || format!("{} must be {}", self.property(), self.range());
        match self {
            Param::MaxDepth => {
                let depth: u32 = text.parse().map_err(|_| out_of_range())?;
                (depth <= MAX_DEPTH)
                    .then_some(Value::Whole(depth))
                    .ok_or_else(out_of_range)
            }
            Param::MinWeight | Param::Epsilon | Param::Ior(_) => {
                let number = number(text).ok_or_else(out_of_range)?;
                let fits = match self {
                    Param::MinWeight => (0.0..=1.0).contains(&number),
                    Param::Epsilon => (MIN_SIZE..=1.0).contains(&number),
                    _ => (MIN_IOR..=MAX_IOR).contains(&number),
                };
                fits.then_some(Value::Number(number))
                    .ok_or_else(out_of_range)
            }
            Param::Reflective(_) | Param::Transmissive(_) | Param::LightColor(_) => {
                let max = if matches!(self, Param::LightColor(_)) {
                    MAX_INTENSITY
                } else {
                    MAX_REFLECTANCE
                };
                let color = color(text).ok_or_else(out_of_range)?;
                [color.r, color.g, color.b]
                    .iter()
                    .all(|c| (0.0..=max).contains(c))
                    .then_some(Value::Color(color))
                    .ok_or_else(out_of_range)
            }
        }
    }

    /// A copy of `scene` with this parameter set to `value`, validated again.
    pub fn apply(self, scene: &ValidScene, value: Value) -> Result<ValidScene, String> {
        let mut copy = scene.scene().clone();
        let missing = || format!("{} is no longer in the scene", self.owner(scene));
        match (self, value) {
            (Param::MaxDepth, Value::Whole(depth)) => copy.settings.max_depth = depth,
            (Param::MinWeight, Value::Number(weight)) => copy.settings.min_weight = weight,
            (Param::Epsilon, Value::Number(epsilon)) => copy.settings.epsilon = Some(epsilon),
            (Param::Ior(h) | Param::Reflective(h) | Param::Transmissive(h), value) => {
                let material = copy.materials.get(h).ok_or_else(missing)?.clone();
                // A pattern's colour parts are copies of their host made by the language
                // (same definition, same span): a change to the host's value reaches them.
                let span = copy.materials.span(h);
                let mut targets = vec![h];
                if let Some(pattern) = &material.pattern {
                    for part in [pattern.a, pattern.b] {
                        if copy.materials.span(part) == span {
                            targets.push(part);
                        }
                    }
                }
                for target in targets {
                    let Some(m) = copy.materials.get_mut(target) else {
                        continue;
                    };
                    match (self, value) {
                        (Param::Ior(_), Value::Number(ior)) => m.ior = ior,
                        (Param::Reflective(_), Value::Color(c)) => m.reflective = c,
                        (Param::Transmissive(_), Value::Color(c)) => m.transmissive = c,
                        _ => return Err(format!("{} takes {}", self.property(), self.range())),
                    }
                }
            }
            (Param::LightColor(h), Value::Color(c)) => {
                copy.lights.get_mut(h).ok_or_else(missing)?.color = c;
            }
            _ => return Err(format!("{} takes {}", self.property(), self.range())),
        }
        validate(copy).map_err(|invalid| {
            let first = invalid
                .diagnostics
                .first()
                .map_or_else(|| "it is not valid".to_string(), |d| d.message.clone());
            format!("the changed scene is not valid: {first}")
        })
    }
}

/// The values the popup lists: the render settings, then `material`'s (the selected ray's),
/// then each light's colour.
pub fn params(scene: &Scene, material: Option<Handle<Material>>) -> Vec<Param> {
    let mut params = vec![Param::MaxDepth, Param::MinWeight, Param::Epsilon];
    if let Some(h) = material.filter(|&h| scene.materials.contains(h)) {
        params.extend([Param::Ior(h), Param::Reflective(h), Param::Transmissive(h)]);
    }
    params.extend(scene.lights.iter().map(|(h, _)| Param::LightColor(h)));
    params
}

/// A value as the scene language writes it: `5`, `1.5`, `0.9`, `rgb(1, 0.5, 0)`.
pub fn value_text(value: Value) -> String {
    match value {
        Value::Whole(n) => n.to_string(),
        Value::Number(x) => number_text(x),
        Value::Color(c) if c.r == c.g && c.g == c.b => number_text(c.r),
        Value::Color(c) => format!(
            "rgb({}, {}, {})",
            number_text(c.r),
            number_text(c.g),
            number_text(c.b)
        ),
    }
}

/// The shortest text that reads back as `x` (`1.5`, `1`, `0.001`).
fn number_text(x: f64) -> String {
    format!("{x}")
}

/// A finite decimal number (no `inf`, no `nan`, which Rust's parser would take).
fn number(text: &str) -> Option<f64> {
    let plain = text
        .chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | 'E'));
    text.parse::<f64>().ok().filter(|x| plain && x.is_finite())
}

/// A grey (`0.5`), three numbers (`1 0.5 0`) or `rgb(1, 0.5, 0)`.
fn color(text: &str) -> Option<Color> {
    let inner = text
        .strip_prefix("rgb(")
        .and_then(|rest| rest.strip_suffix(')'))
        .unwrap_or(text);
    let parts: Vec<f64> = inner
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|p| !p.is_empty())
        .map(number)
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
    use crate::test_scene::whitted_scene;

    fn glass(scene: &Scene) -> Handle<Material> {
        scene
            .materials
            .iter()
            .find(|(_, m)| m.name.as_deref() == Some("glass"))
            .map(|(h, _)| h)
            .expect("the glass material")
    }

    #[test]
    fn the_popup_lists_settings_the_material_and_every_light_with_their_values() {
        let scene = whitted_scene();
        let glass = glass(&scene);
        let listed = params(&scene, Some(glass));
        let shown: Vec<String> = listed
            .iter()
            .map(|p| {
                format!(
                    "{} {} = {}",
                    p.owner(&scene),
                    p.property(),
                    p.current_text(&scene)
                )
            })
            .collect();
        assert_eq!(
            shown,
            [
                "settings max_depth = 5",
                "settings min_weight = 0.001",
                "settings epsilon = automatic",
                "material glass ior = 1.5",
                "material glass reflective = 0.1",
                "material glass transmissive = 0.9",
                "light sun color = 1",
            ]
        );
        assert_eq!(
            params(&scene, None).len(),
            4,
            "no material rows without a hit"
        );
    }

    #[test]
    fn values_are_read_within_the_languages_ranges_and_anything_else_is_said_plainly() {
        let h = Handle::from_index(0);
        assert_eq!(Param::Ior(h).parse(" 1.0 "), Ok(Value::Number(1.0)));
        assert_eq!(Param::MaxDepth.parse("7"), Ok(Value::Whole(7)));
        assert_eq!(
            Param::Transmissive(h).parse("rgb(1, 0.5, 0)"),
            Ok(Value::Color(Color::new(1.0, 0.5, 0.0)))
        );
        assert_eq!(
            Param::LightColor(Handle::from_index(0)).parse("2 2 2"),
            Ok(Value::Color(Color::gray(2.0)))
        );
        for (param, text) in [
            (Param::Ior(h), "0"),
            (Param::Ior(h), "-1"),
            (Param::Ior(h), "abc"),
            (Param::Ior(h), "inf"),
            (Param::Ior(h), "NaN"),
            (Param::Ior(h), ""),
            (Param::MaxDepth, "2.5"),
            (Param::MaxDepth, "257"),
            (Param::MinWeight, "1.5"),
            (Param::Epsilon, "0"),
            (Param::Reflective(h), "1.2"),
            (Param::Reflective(h), "rgb(1, 2)"),
            (Param::LightColor(Handle::from_index(0)), "-1"),
        ] {
            let error = param.parse(text).expect_err(text);
            assert!(
                error.starts_with(&format!("{} must be ", param.property())),
                "{text}: {error}"
            );
        }
        assert_eq!(
            Param::Ior(h).parse("0").unwrap_err(),
            "ior must be a number from 0.001 to 1000"
        );
    }

    #[test]
    fn applying_changes_one_value_of_a_copy_and_leaves_the_scene_alone() {
        let scene = whitted_scene();
        let glass = glass(&scene);
        let changed = Param::Ior(glass).apply(&scene, Value::Number(1.0)).unwrap();
        assert_eq!(changed.materials[glass].ior, 1.0);
        assert_eq!(scene.materials[glass].ior, 1.5);
        let mut expected = scene.scene().clone();
        expected.materials.get_mut(glass).unwrap().ior = 1.0;
        assert_eq!(format!("{:?}", changed.scene()), format!("{expected:?}"));
        let deeper = Param::MaxDepth.apply(&scene, Value::Whole(9)).unwrap();
        assert_eq!(deeper.settings.max_depth, 9);
        let light = Handle::from_index(0);
        let red = Param::LightColor(light)
            .apply(&scene, Value::Color(Color::new(1.0, 0.0, 0.0)))
            .unwrap();
        assert_eq!(red.lights[light].color, Color::new(1.0, 0.0, 0.0));
        assert!(Param::MaxDepth.apply(&scene, Value::Number(1.0)).is_err());
    }

    #[test]
    fn a_change_to_a_patterned_material_reaches_its_colour_parts() {
        let scene = whitted_scene();
        let (tiles, material) = scene
            .materials
            .iter()
            .find(|(_, m)| m.name.as_deref() == Some("floor_tiles"))
            .expect("the floor's material");
        let pattern = material.pattern.clone().expect("a checker");
        let changed = Param::Reflective(tiles)
            .apply(&scene, Value::Color(Color::gray(0.5)))
            .unwrap();
        assert_eq!(changed.materials[pattern.a].reflective, Color::gray(0.5));
        assert_eq!(changed.materials[pattern.b].reflective, Color::gray(0.5));
    }

    #[test]
    fn values_are_written_as_the_language_reads_them() {
        assert_eq!(value_text(Value::Number(1.0)), "1");
        assert_eq!(value_text(Value::Number(1.25)), "1.25");
        assert_eq!(value_text(Value::Whole(6)), "6");
        assert_eq!(value_text(Value::Color(Color::gray(0.9))), "0.9");
        assert_eq!(
            value_text(Value::Color(Color::new(1.0, 0.5, 0.0))),
            "rgb(1, 0.5, 0)"
        );
    }
}
