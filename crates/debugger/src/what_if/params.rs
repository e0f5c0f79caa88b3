//! What-if: the values the what-if popup (`w`) can change (render settings, the selected
//! ray's material, the lights' colours), each an (owner, row) pair whose row is the IR's
//! table row for the value (its name, range, and how to read and write it), reading a typed
//! value within that range, and a copy of the scene with one value changed, validated again.

use whitted_ir::properties::{self, ColorLimit, MaterialColor, MaterialNumber};
use whitted_ir::setting_rows::{self, plain_color, plain_number, SettingKind, SettingRow};
use whitted_ir::{validate, Handle, Light, Material, Scene, ValidScene};

pub use whitted_ir::setting_rows::{value_text, SettingValue as Value};

/// What holds a value: the settings, a material or a light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Owner {
    Settings,
    Material(Handle<Material>),
    Light(Handle<Light>),
}

/// The table row of a value: a setting, a material's colour or number, a light's colour.
#[derive(Clone, Copy, Debug)]
pub enum Row {
    Setting(&'static SettingRow),
    MaterialColor(&'static MaterialColor),
    MaterialNumber(&'static MaterialNumber),
    LightColor,
}

impl Row {
    /// The property's name in the scene language.
    pub fn name(self) -> &'static str {
        match self {
            Row::Setting(row) => row.name,
            Row::MaterialColor(row) => row.name,
            Row::MaterialNumber(row) => row.name,
            Row::LightColor => "color",
        }
    }
}

impl PartialEq for Row {
    /// Rows are the same row when they name the same value of the same table.
    fn eq(&self, other: &Row) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other) && self.name() == other.name()
    }
}

/// One value the popup can change: which row, of which owner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Param {
    pub owner: Owner,
    pub row: Row,
}

impl Param {
    pub fn setting(row: &'static SettingRow) -> Param {
        Param {
            owner: Owner::Settings,
            row: Row::Setting(row),
        }
    }

    pub fn material_color(h: Handle<Material>, row: &'static MaterialColor) -> Param {
        Param {
            owner: Owner::Material(h),
            row: Row::MaterialColor(row),
        }
    }

    pub fn material_number(h: Handle<Material>, row: &'static MaterialNumber) -> Param {
        Param {
            owner: Owner::Material(h),
            row: Row::MaterialNumber(row),
        }
    }

    pub fn light_color(h: Handle<Light>) -> Param {
        Param {
            owner: Owner::Light(h),
            row: Row::LightColor,
        }
    }

    /// The property's name in the scene language.
    pub fn property(self) -> &'static str {
        self.row.name()
    }

    /// Where the value lives, in words: `settings`, `material glass`, `light sun`.
    pub fn owner(self, scene: &Scene) -> String {
        match self.owner {
            Owner::Settings => "settings".to_string(),
            Owner::Material(h) => {
                let name = scene.materials.get(h).and_then(|m| m.name.clone());
                format!(
                    "material {}",
                    name.unwrap_or_else(|| format!("#{}", h.index()))
                )
            }
            Owner::Light(h) => {
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
        let color = |limit: ColorLimit| {
            format!(
                "a grey 0 to {}, or rgb(r, g, b) in that range",
                short(limit.max)
            )
        };
        match self.row {
            Row::Setting(row) => row.kind.range_in_words(),
            Row::MaterialColor(row) => color(row.limit),
            Row::MaterialNumber(row) => {
                format!("a number from {} to {}", short(row.min), short(row.max))
            }
            Row::LightColor => color(properties::LIGHT_COLOR),
        }
    }

    /// The value in `scene`; `None` for an automatic epsilon or an owner not in the scene.
    pub fn current(self, scene: &Scene) -> Option<Value> {
        match (self.owner, self.row) {
            (Owner::Settings, Row::Setting(row)) => (row.get)(&scene.settings),
            (Owner::Material(h), Row::MaterialColor(row)) => {
                Some(Value::Color((row.get)(scene.materials.get(h)?)))
            }
            (Owner::Material(h), Row::MaterialNumber(row)) => {
                Some(Value::Number((row.get)(scene.materials.get(h)?)))
            }
            (Owner::Light(h), Row::LightColor) => Some(Value::Color(scene.lights.get(h)?.color)),
            _ => None,
        }
    }

    /// The current value as the scene language writes it (`automatic` for epsilon unset).
    pub fn current_text(self, scene: &Scene) -> String {
        match (self.current(scene), self.row) {
            (Some(value), _) => value_text(value),
            (None, Row::Setting(row)) => row.default.to_string(),
            (None, _) => "?".to_string(),
        }
    }

    /// Reads `text` as a value of this parameter, within the range the language accepts.
    pub fn parse(self, text: &str) -> Result<Value, String> {
        let text = text.trim();
        let out_of_range = || format!("{} must be {}", self.property(), self.range());
        let color_within = |max: f64| {
            let color = plain_color(text).ok_or_else(out_of_range)?;
            [color.r, color.g, color.b]
                .iter()
                .all(|c| (0.0..=max).contains(c))
                .then_some(Value::Color(color))
                .ok_or_else(out_of_range)
        };
        match self.row {
            Row::Setting(row) => {
                if let SettingKind::Number { .. } = row.kind {
                    // Only plain decimals: no `inf` or `nan`, which Rust's parser takes.
                    plain_number(text).ok_or_else(out_of_range)?;
                }
                row.parse(text).map_err(|_| out_of_range())
            }
            Row::MaterialNumber(row) => {
                let number = plain_number(text).ok_or_else(out_of_range)?;
                (row.min..=row.max)
                    .contains(&number)
                    .then_some(Value::Number(number))
                    .ok_or_else(out_of_range)
            }
            Row::MaterialColor(row) => color_within(row.limit.max),
            Row::LightColor => color_within(properties::LIGHT_COLOR.max),
        }
    }

    /// A copy of `scene` with this parameter set to `value`, validated again.
    pub fn apply(self, scene: &ValidScene, value: Value) -> Result<ValidScene, String> {
        let mut copy = scene.scene().clone();
        let missing = || format!("{} is no longer in the scene", self.owner(scene));
        let wrong = || format!("{} takes {}", self.property(), self.range());
        match (self.owner, self.row, value) {
            (Owner::Settings, Row::Setting(row), value) => {
                let value = row.check(value).map_err(|_| wrong())?;
                (row.set)(&mut copy.settings, value);
            }
            (Owner::Material(h), Row::MaterialColor(_) | Row::MaterialNumber(_), value) => {
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
                    match (self.row, value) {
                        (Row::MaterialColor(row), Value::Color(c)) => (row.set)(m, c),
                        (Row::MaterialNumber(row), Value::Number(x)) => (row.set)(m, x),
                        _ => return Err(wrong()),
                    }
                }
            }
            (Owner::Light(h), Row::LightColor, Value::Color(c)) => {
                copy.lights.get_mut(h).ok_or_else(missing)?.color = c;
            }
            _ => return Err(wrong()),
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
    let mut params: Vec<Param> = [
        &setting_rows::MAX_DEPTH,
        &setting_rows::MIN_WEIGHT,
        &setting_rows::EPSILON,
    ]
    .into_iter()
    .map(Param::setting)
    .collect();
    if let Some(h) = material.filter(|&h| scene.materials.contains(h)) {
        params.push(Param::material_number(h, &properties::IOR));
        for name in ["reflective", "transmissive"] {
            if let Some(row) = properties::material_color(name) {
                params.push(Param::material_color(h, row));
            }
        }
    }
    params.extend(scene.lights.iter().map(|(h, _)| Param::light_color(h)));
    params
}

/// A limit as the popup shows it: `1`, `1000`, `1e6`.
fn short(x: f64) -> String {
    if x >= 1e5 {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_scene::whitted_scene;
    use whitted_ir::Color;

    fn ior(h: Handle<Material>) -> Param {
        Param::material_number(h, &properties::IOR)
    }

    fn reflective(h: Handle<Material>) -> Param {
        Param::material_color(h, properties::material_color("reflective").expect("a row"))
    }

    fn transmissive(h: Handle<Material>) -> Param {
        Param::material_color(
            h,
            properties::material_color("transmissive").expect("a row"),
        )
    }

    fn depth() -> Param {
        Param::setting(&setting_rows::MAX_DEPTH)
    }

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
        assert_eq!(ior(h).parse(" 1.0 "), Ok(Value::Number(1.0)));
        assert_eq!(depth().parse("7"), Ok(Value::Whole(7)));
        assert_eq!(
            transmissive(h).parse("rgb(1, 0.5, 0)"),
            Ok(Value::Color(Color::new(1.0, 0.5, 0.0)))
        );
        assert_eq!(
            Param::light_color(Handle::from_index(0)).parse("2 2 2"),
            Ok(Value::Color(Color::gray(2.0)))
        );
        for (param, text) in [
            (ior(h), "0"),
            (ior(h), "-1"),
            (ior(h), "abc"),
            (ior(h), "inf"),
            (ior(h), "NaN"),
            (ior(h), ""),
            (depth(), "2.5"),
            (depth(), "257"),
            (Param::setting(&setting_rows::MIN_WEIGHT), "1.5"),
            (Param::setting(&setting_rows::EPSILON), "-0.5"),
            (reflective(h), "1.2"),
            (reflective(h), "rgb(1, 2)"),
            (Param::light_color(Handle::from_index(0)), "-1"),
        ] {
            let error = param.parse(text).expect_err(text);
            assert!(
                error.starts_with(&format!("{} must be ", param.property())),
                "{text}: {error}"
            );
        }
        assert_eq!(
            ior(h).parse("0").unwrap_err(),
            "ior must be a number from 0.001 to 1000"
        );
    }

    #[test]
    fn applying_changes_one_value_of_a_copy_and_leaves_the_scene_alone() {
        let scene = whitted_scene();
        let glass = glass(&scene);
        let changed = ior(glass).apply(&scene, Value::Number(1.0)).unwrap();
        assert_eq!(changed.materials[glass].ior, 1.0);
        assert_eq!(scene.materials[glass].ior, 1.5);
        let mut expected = scene.scene().clone();
        expected.materials.get_mut(glass).unwrap().ior = 1.0;
        assert_eq!(format!("{:?}", changed.scene()), format!("{expected:?}"));
        let deeper = depth().apply(&scene, Value::Whole(9)).unwrap();
        assert_eq!(deeper.settings.max_depth, 9);
        let light = Handle::from_index(0);
        let red = Param::light_color(light)
            .apply(&scene, Value::Color(Color::new(1.0, 0.0, 0.0)))
            .unwrap();
        assert_eq!(red.lights[light].color, Color::new(1.0, 0.0, 0.0));
        assert!(depth().apply(&scene, Value::Number(1.0)).is_err());
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
        let changed = reflective(tiles)
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
