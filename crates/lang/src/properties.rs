//! The one table of properties: for every property, each block that accepts it, the value it
//! takes there (with its range), its default and a line of documentation.
//!
//! Resolution (unknown properties with suggestions, arity, words), evaluation (converting a
//! value and checking its range: `eval/convert.rs`), the CLI's `--set NAME=VALUE` and the docs
//! test all read these rows. **To add a property**, add its row here (a new name gets its
//! variant from the same line), then give it meaning: the IR field it sets and what the
//! tracer does with that field. A material colour also gets its row in the IR's half of the
//! table (`whitted_ir::properties`: its field, limit and how `whitted ir` shows it), from
//! which evaluation, validation and the printer set, check and show it; any other property
//! gets its match arm in `eval/properties.rs` (and its check in validation when it needs
//! one). `emission` was added that way: two rows, one IR field, one term in the tracer.
//!
//! Rows are in the order the docs list each block's properties, so that "a sphere takes
//! `center`, `radius`, ..." reads in that order.

use whitted_ir::limits;
use whitted_ir::setting_rows::{self as S, SettingKind, SettingRow};

use crate::schema::{CameraTag, Context, LightTag, ObjectTag};

/// Where a row's property is accepted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Block {
    /// The shape parameters of these object kinds.
    Shape(&'static [ObjectTag]),
    /// Every object, and the block after a call statement.
    AnyObject,
    /// Every object, the block after a call statement and a pattern's block.
    Transforms,
    Settings,
    Camera(&'static [CameraTag]),
    Light(&'static [LightTag]),
    Material,
}

impl Block {
    fn accepts(self, cx: Context) -> bool {
        match (self, cx) {
            (Block::Shape(tags), Context::Object(tag)) => tags.contains(&tag),
            (Block::AnyObject, Context::Object(_) | Context::Modifiers) => true,
            (
                Block::Transforms,
                Context::Object(_) | Context::Modifiers | Context::PatternTransform,
            ) => true,
            (Block::Settings, Context::Settings) => true,
            (Block::Camera(tags), Context::Camera(tag)) => tags.contains(&tag),
            (Block::Light(tags), Context::Light(tag)) => tags.contains(&tag),
            (Block::Material, Context::Material) => true,
            _ => false,
        }
    }
}

/// The value a property takes in a block.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// A number from `min` to `max` (`min` itself excluded when `open`).
    Number { min: f64, open: bool, max: f64 },
    /// A whole number from `min` to `max`.
    Whole { min: f64, max: f64 },
    /// Any vector (a position).
    Vector,
    /// A vector that is not zero (a direction).
    Direction,
    /// A colour (a vector, or one number for a grey).
    Color,
    /// A colour of light: up to the largest intensity.
    LightColor,
    /// A colour, or a pattern with an optional block of transforms.
    ColorOrPattern,
    /// `<constant, linear, quadratic>`, each at least 0 and not all zero.
    Attenuation,
    /// One of these words.
    Word(&'static [&'static str]),
    /// No value: the name alone (`open`).
    Flag,
    /// A material.
    MaterialValue,
    /// Exactly this many vectors, separated by commas.
    Points(usize),
    /// Numbers and vectors adding up to this many numbers.
    Numbers(usize),
    /// A transform (`translate`, `rotate`, `scale`, `matrix`), each with its own forms.
    Transform,
    /// Shape parameters whose ranges the shape's builder and validation check together.
    ShapeParameter,
    /// A string: a file's path.
    Text,
    /// `true` or `false`.
    Bool,
}

/// How many values a property takes after its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arity {
    /// No value at all (`open`).
    Flag,
    /// Exactly one expression.
    One,
    /// Exactly this many expressions, separated by commas (`vertices a, b, c`).
    Exactly(usize),
    /// Numbers and vectors, separated by commas, that add up to this many numbers
    /// (`coefficients <1, 1, 1>, <0, 0, 0>, <0, 0, 0>, -1`).
    Numbers(usize),
}

impl Kind {
    pub fn arity(self) -> Arity {
        match self {
            Kind::Flag => Arity::Flag,
            Kind::Points(n) => Arity::Exactly(n),
            Kind::Numbers(n) => Arity::Numbers(n),
            _ => Arity::One,
        }
    }
}

/// One property in one kind of block.
#[derive(Clone, Copy, Debug)]
pub struct Row {
    pub prop: Prop,
    pub block: Block,
    pub kind: Kind,
    /// The default as the docs write it ("" when there is none: the property is required or
    /// has no default, like a transform).
    pub default: &'static str,
    pub doc: &'static str,
}

/// The table: the `Prop` enum, its names and the rows, all from one list.
macro_rules! properties {
    ($( $prop:ident $name:literal {
        $( $block:expr => $kind:expr, $default:expr, $doc:expr; )+
    } )+) => {
        /// Every property name the language knows. Which blocks accept each, and what it
        /// takes there, is in [`ROWS`]; `height` and `ambient` mean different things in
        /// different blocks.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Prop {
            $( $prop, )+
        }

        impl Prop {
            pub const ALL: &'static [Prop] = &[ $( Prop::$prop, )+ ];

            pub fn name(self) -> &'static str {
                match self {
                    $( Prop::$prop => $name, )+
                }
            }
        }

        pub const ROWS: &[Row] = &[
            $( $( Row {
                prop: Prop::$prop,
                block: $block,
                kind: $kind,
                default: $default,
                doc: $doc,
            }, )+ )+
        ];
    };
}

use Block::*;
use Kind::*;

/// A setting's kind in the language, from its row in the IR's settings table.
const fn setting_kind(row: &SettingRow) -> Kind {
    match row.kind {
        SettingKind::Whole { min, max } => Whole {
            min: min as f64,
            max: max as f64,
        },
        SettingKind::Number { min, open, max } => Number { min, open, max },
        SettingKind::LightColor => LightColor,
        SettingKind::Word(words) => Word(words),
    }
}

const ANY: f64 = f64::INFINITY;
const CAMERAS: &[CameraTag] = &[CameraTag::Perspective, CameraTag::Orthographic];
const POSITIONED: &[LightTag] = &[LightTag::Point, LightTag::Spot];
const AIMED: &[LightTag] = &[LightTag::Directional, LightTag::Spot];
const ALL_LIGHTS: &[LightTag] = &[LightTag::Point, LightTag::Directional, LightTag::Spot];

properties! {
    Eye "eye" {
        Camera(CAMERAS) => Vector, "<0, 0, 5>", "where the camera is";
    }
    LookAt "look_at" {
        Camera(CAMERAS) => Vector, "<0, 0, 0>", "the point at the centre of the image";
    }
    Up "up" {
        Camera(CAMERAS) => Direction, "<0, 1, 0>", "which way is up in the image";
    }
    Fov "fov" {
        Camera(&[CameraTag::Perspective]) => Number { min: 0.0, open: true, max: 179.0 }, "45", "vertical field of view in degrees";
    }
    Width "width" {
        Settings => setting_kind(&S::WIDTH), S::WIDTH.default, S::WIDTH.doc;
    }
    Height "height" {
        Camera(&[CameraTag::Orthographic]) => Number { min: 0.0, open: true, max: ANY }, "4", "height of the view in scene units";
        Settings => setting_kind(&S::HEIGHT), S::HEIGHT.default, S::HEIGHT.doc;
    }
    MaxDepth "max_depth" {
        Settings => setting_kind(&S::MAX_DEPTH), S::MAX_DEPTH.default, S::MAX_DEPTH.doc;
    }
    MinWeight "min_weight" {
        Settings => setting_kind(&S::MIN_WEIGHT), S::MIN_WEIGHT.default, S::MIN_WEIGHT.doc;
    }
    Samples "samples" {
        Settings => setting_kind(&S::SAMPLES), S::SAMPLES.default, S::SAMPLES.doc;
    }
    Sampling "sampling" {
        Settings => setting_kind(&S::SAMPLING), S::SAMPLING.default, S::SAMPLING.doc;
    }
    Filter "filter" {
        Settings => setting_kind(&S::FILTER), S::FILTER.default, S::FILTER.doc;
    }
    FilterRadius "filter_radius" {
        Settings => setting_kind(&S::FILTER_RADIUS), S::FILTER_RADIUS.default, S::FILTER_RADIUS.doc;
    }
    Background "background" {
        Settings => setting_kind(&S::BACKGROUND), S::BACKGROUND.default, S::BACKGROUND.doc;
    }
    Ambient "ambient" {
        Settings => setting_kind(&S::AMBIENT), S::AMBIENT.default, S::AMBIENT.doc;
        Material => Color, "0.1", "ka: how much of the global ambient light it reflects";
    }
    Epsilon "epsilon" {
        Settings => setting_kind(&S::EPSILON), S::EPSILON.default, S::EPSILON.doc;
    }
    Shadows "shadows" {
        Settings => setting_kind(&S::SHADOWS), S::SHADOWS.default, S::SHADOWS.doc;
    }
    Highlight "highlight" {
        Settings => setting_kind(&S::HIGHLIGHT), S::HIGHLIGHT.default, S::HIGHLIGHT.doc;
    }
    ShadeBack "shade_back" {
        Settings => setting_kind(&S::SHADE_BACK), S::SHADE_BACK.default, S::SHADE_BACK.doc;
    }
    AttenuationClamp "attenuation_clamp" {
        Settings => setting_kind(&S::ATTENUATION_CLAMP), S::ATTENUATION_CLAMP.default, S::ATTENUATION_CLAMP.doc;
    }
    EnergyClamp "energy_clamp" {
        Settings => setting_kind(&S::ENERGY_CLAMP), S::ENERGY_CLAMP.default, S::ENERGY_CLAMP.doc;
    }
    BackAmbient "back_ambient" {
        Settings => setting_kind(&S::BACK_AMBIENT), S::BACK_AMBIENT.default, S::BACK_AMBIENT.doc;
    }
    HighlightGate "highlight_gate" {
        Settings => setting_kind(&S::HIGHLIGHT_GATE), S::HIGHLIGHT_GATE.default, S::HIGHLIGHT_GATE.doc;
    }
    SamplePosition "sample_position" {
        Settings => setting_kind(&S::SAMPLE_POSITION), S::SAMPLE_POSITION.default, S::SAMPLE_POSITION.doc;
    }
    Frames "frames" {
        Settings => setting_kind(&S::FRAMES), S::FRAMES.default, S::FRAMES.doc;
    }
    FirstFrame "first_frame" {
        Settings => setting_kind(&S::FIRST_FRAME), S::FIRST_FRAME.default, S::FIRST_FRAME.doc;
    }
    Fps "fps" {
        Settings => setting_kind(&S::FPS), S::FPS.default, S::FPS.doc;
    }
    FlipNormals "flip_normals" {
        Settings => setting_kind(&S::FLIP_NORMALS), S::FLIP_NORMALS.default, S::FLIP_NORMALS.doc;
    }
    ExitIor "exit_ior" {
        Settings => setting_kind(&S::EXIT_IOR), S::EXIT_IOR.default, S::EXIT_IOR.doc;
    }
    TotalInternalReflection "total_internal_reflection" {
        Settings => setting_kind(&S::TOTAL_INTERNAL_REFLECTION), S::TOTAL_INTERNAL_REFLECTION.default, S::TOTAL_INTERNAL_REFLECTION.doc;
    }
    LightFalloff "light_falloff" {
        Settings => setting_kind(&S::LIGHT_FALLOFF), S::LIGHT_FALLOFF.default, S::LIGHT_FALLOFF.doc;
    }
    FresnelRule "fresnel_rule" {
        Settings => setting_kind(&S::FRESNEL_RULE), S::FRESNEL_RULE.default, S::FRESNEL_RULE.doc;
    }
    Position "position" {
        Light(POSITIONED) => Vector, "", "where the light is";
    }
    Direction "direction" {
        Light(AIMED) => Direction, "", "the direction the light travels";
    }
    Inner "inner" {
        Light(&[LightTag::Spot]) => Number { min: 0.0, open: false, max: 179.0 }, "20", "full light inside this cone angle, in degrees";
    }
    Outer "outer" {
        Light(&[LightTag::Spot]) => Number { min: 0.0, open: false, max: 179.0 }, "30", "no light outside this cone angle, in degrees";
    }
    Color "color" {
        Light(ALL_LIGHTS) => Color, "white", "the light's colour and intensity";
    }
    Attenuation "attenuation" {
        Light(POSITIONED) => Attenuation, "<1, 0, 0>", "fall-off with distance: <constant, linear, quadratic>";
    }
    Diffuse "diffuse" {
        Material => ColorOrPattern, "0.8", "kd: a colour, or a pattern";
    }
    Specular "specular" {
        Material => Color, "0", "ks: the Phong highlight's colour";
    }
    Shininess "shininess" {
        Material => Number { min: 0.0, open: false, max: ANY }, "32", "the Phong exponent";
    }
    Reflective "reflective" {
        Material => Color, "0", "kr: mirror reflection";
    }
    Transmissive "transmissive" {
        Material => Color, "0", "kt: refraction";
    }
    Ior "ior" {
        Material => Number { min: 0.0, open: true, max: ANY }, "1", "index of refraction";
    }
    Fresnel "fresnel" {
        Material => Word(&["off", "schlick", "exact"]), "off", "how kr and kt vary with the angle";
    }
    Absorption "absorption" {
        Material => Color, "0", "Beer-Lambert absorption per unit of distance inside";
    }
    Emission "emission" {
        Material => Color, "0", "light the surface gives off by itself, whatever the lights and shadows";
    }
    Priority "priority" {
        Material => Whole { min: 0.0, max: limits::MAX_PRIORITY as f64 }, "0", "nested media: which solid fills an overlap";
    }
    Center "center" {
        Shape(&[ObjectTag::Sphere, ObjectTag::Disk]) => ShapeParameter, "<0, 0, 0>", "the centre";
    }
    Base "base" {
        Shape(&[ObjectTag::Cylinder, ObjectTag::Cone]) => ShapeParameter, "<0, 0, 0>", "the centre of the bottom end";
    }
    BaseRadius "base_radius" {
        Shape(&[ObjectTag::Cone]) => ShapeParameter, "1", "the radius at the base";
    }
    Apex "apex" {
        Shape(&[ObjectTag::Cylinder, ObjectTag::Cone]) => ShapeParameter, "<0, 1, 0>", "the centre of the top end";
    }
    ApexRadius "apex_radius" {
        Shape(&[ObjectTag::Cone]) => ShapeParameter, "0", "the radius at the apex";
    }
    Normal "normal" {
        Shape(&[ObjectTag::Plane, ObjectTag::Disk]) => ShapeParameter, "<0, 1, 0>", "the direction the surface faces";
    }
    Offset "offset" {
        Shape(&[ObjectTag::Plane]) => ShapeParameter, "0", "the plane's distance from the origin along its normal";
    }
    Radius "radius" {
        Shape(&[ObjectTag::Sphere, ObjectTag::Cylinder, ObjectTag::Disk]) => ShapeParameter, "1", "the radius";
    }
    Open "open" {
        Shape(&[ObjectTag::Cylinder, ObjectTag::Cone]) => Flag, "", "without end caps (a tube, not a solid)";
    }
    Min "min" {
        Shape(&[ObjectTag::Box]) => ShapeParameter, "<-1, -1, -1>", "the smallest corner";
    }
    Max "max" {
        Shape(&[ObjectTag::Box]) => ShapeParameter, "<1, 1, 1>", "the largest corner";
    }
    Vertices "vertices" {
        Shape(&[ObjectTag::Triangle]) => Points(3), "", "the three corners";
    }
    Coefficients "coefficients" {
        Shape(&[ObjectTag::Quadric]) => Numbers(10), "", "A, B, C, D, E, F, G, H, I, J of the quadric's equation";
    }
    Radii "radii" {
        Shape(&[
            ObjectTag::Ellipsoid,
            ObjectTag::Paraboloid,
            ObjectTag::Hyperboloid,
            ObjectTag::Hyperboloid2,
        ]) => ShapeParameter, "<1, 1, 1>", "the semi-axes";
    }
    Major "major" {
        Shape(&[ObjectTag::Torus]) => Number { min: 0.0, open: true, max: ANY }, "1", "the radius of the ring, from the centre to the middle of the tube";
    }
    Minor "minor" {
        Shape(&[ObjectTag::Torus]) => Number { min: 0.0, open: true, max: ANY }, "0.25", "the radius of the tube";
    }
    File "file" {
        Shape(&[ObjectTag::Mesh]) => Text, "", "the mesh file, `.obj` or `.ply`, relative to the scene file's folder";
    }
    Smooth "smooth" {
        Shape(&[ObjectTag::Mesh]) => Bool, "true", "interpolate the file's vertex normals across each triangle (`false`: each triangle's own normal)";
    }
    Translate "translate" {
        Transforms => Transform, "", "move";
    }
    Rotate "rotate" {
        Transforms => Transform, "", "turn, in degrees";
    }
    Scale "scale" {
        Transforms => Transform, "", "scale uniformly or per axis";
    }
    Matrix "matrix" {
        Transforms => Numbers(16), "", "any invertible 4x4 matrix, row by row";
    }
    Material "material" {
        AnyObject => MaterialValue, "", "the object's material";
    }
}

impl Prop {
    /// Every row of this property (one per kind of block that accepts it).
    pub fn rows(self) -> impl Iterator<Item = &'static Row> {
        ROWS.iter().filter(move |row| row.prop == self)
    }

    /// How many values it takes: the same in every block that accepts it.
    pub fn arity(self) -> Arity {
        self.facts().arity
    }

    /// The words it takes, when its value is one of a few words rather than an expression.
    pub fn words(self) -> Option<&'static [&'static str]> {
        self.facts().words
    }

    /// Transforms may be given any number of times; every other property once per block.
    pub fn is_transform(self) -> bool {
        self.facts().transform
    }

    /// What the rows say of this property, read from [`FACTS`]: the evaluator asks it for
    /// every property of every statement, and searching the rows each time was a tenth of
    /// compiling a million spheres written by loops (issue 14).
    fn facts(self) -> Facts {
        FACTS
            .get(self as usize)
            .copied()
            .unwrap_or_else(|| Facts::from_rows(self))
    }
}

/// The facts about a property that hold in every block accepting it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Facts {
    arity: Arity,
    words: Option<&'static [&'static str]>,
    transform: bool,
}

impl Facts {
    fn from_rows(prop: Prop) -> Facts {
        Facts {
            arity: prop
                .rows()
                .next()
                .map_or(Arity::One, |row| row.kind.arity()),
            words: prop.rows().find_map(|row| match row.kind {
                Kind::Word(words) => Some(words),
                _ => None,
            }),
            transform: prop.rows().any(|row| row.block == Block::Transforms),
        }
    }
}

/// [`Facts`] of every property, by its place in [`Prop::ALL`] (its discriminant: the enum
/// and the list come from the same macro line).
static FACTS: std::sync::LazyLock<Vec<Facts>> = std::sync::LazyLock::new(|| {
    Prop::ALL
        .iter()
        .map(|&prop| Facts::from_rows(prop))
        .collect()
});

/// The families of blocks whose properties the evaluator converts by their rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// Shape parameters (most keep dedicated checks; see [`Kind::ShapeParameter`]).
    Shape,
    Settings,
    Camera,
    Light,
    Material,
}

/// The row of `prop` in a family of blocks (a property has at most one row per family).
pub fn row(prop: Prop, family: Family) -> Option<&'static Row> {
    ROWS.iter().find(|row| {
        row.prop == prop
            && matches!(
                (row.block, family),
                (Block::Shape(_), Family::Shape)
                    | (Block::Settings, Family::Settings)
                    | (Block::Camera(_), Family::Camera)
                    | (Block::Light(_), Family::Light)
                    | (Block::Material, Family::Material)
            )
    })
}

/// The properties the block `cx` accepts, in the docs' order: an object's shape parameters
/// first, then the transforms, then `material`.
pub fn accepted(cx: Context) -> Vec<Prop> {
    let mut list: Vec<Prop> = Vec::new();
    for pass in [Pass::Own, Pass::Transforms, Pass::Material] {
        for row in ROWS.iter().filter(|row| row.block.accepts(cx)) {
            let in_pass = match row.block {
                Block::Transforms => pass == Pass::Transforms,
                Block::AnyObject => pass == Pass::Material,
                _ => pass == Pass::Own,
            };
            if in_pass && !list.contains(&row.prop) {
                list.push(row.prop);
            }
        }
    }
    list
}

/// The property called `name` that the block `cx` accepts: the same answer as searching
/// [`accepted`] by name, without building that list. The resolver asks this once per property
/// of every statement, so a million literal spheres asked it millions of times and the list
/// it built each time was a fifth of `whitted check` (issue 17). Property names are unique
/// (see the test), so the first matching row is the property `accepted` would list.
pub fn accepted_named(cx: Context, name: &str) -> Option<Prop> {
    ROWS.iter()
        .find(|row| row.prop.name() == name && row.block.accepts(cx))
        .map(|row| row.prop)
}

/// Whether `row` is the property's row for the block `cx`.
pub fn row_accepts(row: &Row, cx: Context) -> bool {
    row.block.accepts(cx)
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Pass {
    Own,
    Transforms,
    Material,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every block a property can be in, for checking lookups against the full list.
    fn every_context() -> Vec<Context> {
        use crate::schema::{CameraTag, LightTag, ObjectTag};
        let mut all = vec![Context::Modifiers, Context::Settings, Context::Material];
        all.extend([Context::PatternTransform, Context::Unknown]);
        for top_level in [false, true] {
            for in_function in [false, true] {
                all.push(Context::Statements {
                    top_level,
                    in_function,
                });
            }
        }
        all.extend(ObjectTag::ALL.into_iter().map(Context::Object));
        all.extend(CameraTag::ALL.into_iter().map(Context::Camera));
        all.extend(LightTag::ALL.into_iter().map(Context::Light));
        all
    }

    /// The facts table is indexed by discriminant and must say what the rows say.
    #[test]
    fn the_facts_of_each_property_are_its_rows() {
        for (index, &prop) in Prop::ALL.iter().enumerate() {
            assert_eq!(prop as usize, index, "{prop:?}");
            assert_eq!(prop.facts(), Facts::from_rows(prop), "{prop:?}");
        }
        assert!(Prop::Translate.is_transform() && !Prop::Radius.is_transform());
        assert_eq!(Prop::Matrix.arity(), Arity::Numbers(16));
    }

    #[test]
    fn property_names_are_unique() {
        for (i, a) in Prop::ALL.iter().enumerate() {
            for b in &Prop::ALL[i + 1..] {
                assert_ne!(a.name(), b.name(), "two properties share a name");
            }
        }
    }

    /// The oracle for `accepted_named` is the list it stands in for, searched by name: every
    /// property name (and some that are none) in every block.
    #[test]
    fn accepted_named_is_the_accepted_list_searched_by_name() {
        let mut names: Vec<&str> = Prop::ALL.iter().map(|p| p.name()).collect();
        names.extend(["", "foo", "Radius", "radiu", "sphere"]);
        for cx in every_context() {
            let list = accepted(cx);
            for name in &names {
                let expected = list.iter().copied().find(|p| p.name() == *name);
                assert_eq!(accepted_named(cx, name), expected, "`{name}` in {cx:?}");
            }
        }
    }

    #[test]
    fn every_property_has_a_row_and_every_row_a_doc_line() {
        for prop in Prop::ALL {
            assert!(prop.rows().next().is_some(), "`{}` has no row", prop.name());
        }
        for row in ROWS {
            assert!(!row.doc.is_empty(), "`{}` has no doc line", row.prop.name());
        }
    }

    /// The reference must document every property (the docs test compiles its examples; this
    /// checks none is missing).
    #[test]
    fn docs_language_md_names_every_property() {
        let docs = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/language.md"),
        )
        .unwrap_or_default();
        assert!(docs.len() > 10_000, "docs/language.md not found");
        for prop in Prop::ALL {
            assert!(
                docs.contains(&format!("`{}", prop.name())),
                "docs/language.md never mentions `{}`",
                prop.name()
            );
        }
    }

    /// The IR's material colours (where validation and the printer find them) are exactly
    /// this table's material colours, with the defaults the docs give.
    #[test]
    fn material_colours_agree_with_the_ir_table() {
        use whitted_ir::properties::{material_color, MATERIAL_COLORS};
        let colours: Vec<&Row> = ROWS
            .iter()
            .filter(|row| {
                row.block == Block::Material
                    && matches!(row.kind, Kind::Color | Kind::ColorOrPattern)
            })
            .collect();
        for row in &colours {
            let name = row.prop.name();
            let ir = material_color(name)
                .unwrap_or_else(|| panic!("`{name}` has no row in whitted_ir::properties"));
            let grey: f64 = row
                .default
                .parse()
                .unwrap_or_else(|_| panic!("`{name}`'s default {:?}", row.default));
            let default = (ir.get)(&whitted_ir::Material::default());
            assert_eq!(
                default,
                whitted_ir::Color::gray(grey),
                "`{name}`: the docs say {grey}, the IR starts at {default:?}"
            );
        }
        for ir in MATERIAL_COLORS {
            assert!(
                colours.iter().any(|row| row.prop.name() == ir.name),
                "the IR's `{}` has no material row here",
                ir.name
            );
        }
    }

    /// The language's settings are exactly the IR's settings table, each with its row's
    /// kind, default and doc (a setting added to one table and not the other fails here).
    #[test]
    fn settings_are_the_ir_settings_table() {
        use whitted_ir::setting_rows::SETTINGS;
        let ours: Vec<&Row> = ROWS
            .iter()
            .filter(|row| row.block == Block::Settings)
            .collect();
        assert_eq!(ours.len(), SETTINGS.len());
        for ir in SETTINGS {
            let row = ours
                .iter()
                .find(|row| row.prop.name() == ir.name)
                .unwrap_or_else(|| panic!("the IR's setting `{}` has no row here", ir.name));
            assert_eq!(row.kind, setting_kind(ir), "`{}`", ir.name);
            assert_eq!(
                (row.default, row.doc),
                (ir.default, ir.doc),
                "`{}`",
                ir.name
            );
        }
    }

    #[test]
    fn a_property_takes_the_same_number_of_values_wherever_it_goes() {
        for prop in Prop::ALL {
            let arities: Vec<Arity> = prop.rows().map(|row| row.kind.arity()).collect();
            assert!(
                arities.windows(2).all(|w| w[0] == w[1]),
                "`{}` has arities {arities:?}",
                prop.name()
            );
        }
    }

    #[test]
    fn no_block_accepts_a_property_twice() {
        let mut contexts = vec![Context::Settings, Context::Material, Context::Modifiers];
        contexts.extend(ObjectTag::ALL.map(Context::Object));
        contexts.extend(LightTag::ALL.map(Context::Light));
        contexts.extend(CameraTag::ALL.map(Context::Camera));
        for cx in contexts {
            for prop in Prop::ALL {
                let rows = ROWS
                    .iter()
                    .filter(|row| row.prop == *prop && row.block.accepts(cx))
                    .count();
                assert!(
                    rows <= 1,
                    "{} has {rows} rows for `{}`",
                    cx.describe(),
                    prop.name()
                );
            }
        }
    }
}
