//! What the language knows by name: object, light and camera kinds, and which properties each
//! block accepts. The grammar is generic (`name value`), so these tables are where a property
//! becomes valid or "not a property of a sphere; did you mean `center`?".

/// The kinds of object statement (`sphere { ... }`, `union { ... }`, ...).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ObjectTag {
    Sphere,
    Plane,
    Box,
    Cylinder,
    Cone,
    Disk,
    Triangle,
    Quadric,
    Ellipsoid,
    Paraboloid,
    Hyperboloid,
    Hyperboloid2,
    Union,
    Intersection,
    Difference,
    Group,
}

impl ObjectTag {
    pub const ALL: [ObjectTag; 16] = [
        ObjectTag::Sphere,
        ObjectTag::Plane,
        ObjectTag::Box,
        ObjectTag::Cylinder,
        ObjectTag::Cone,
        ObjectTag::Disk,
        ObjectTag::Triangle,
        ObjectTag::Quadric,
        ObjectTag::Ellipsoid,
        ObjectTag::Paraboloid,
        ObjectTag::Hyperboloid,
        ObjectTag::Hyperboloid2,
        ObjectTag::Union,
        ObjectTag::Intersection,
        ObjectTag::Difference,
        ObjectTag::Group,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ObjectTag::Sphere => "sphere",
            ObjectTag::Plane => "plane",
            ObjectTag::Box => "box",
            ObjectTag::Cylinder => "cylinder",
            ObjectTag::Cone => "cone",
            ObjectTag::Disk => "disk",
            ObjectTag::Triangle => "triangle",
            ObjectTag::Quadric => "quadric",
            ObjectTag::Ellipsoid => "ellipsoid",
            ObjectTag::Paraboloid => "paraboloid",
            ObjectTag::Hyperboloid => "hyperboloid",
            ObjectTag::Hyperboloid2 => "hyperboloid2",
            ObjectTag::Union => "union",
            ObjectTag::Intersection => "intersection",
            ObjectTag::Difference => "difference",
            ObjectTag::Group => "group",
        }
    }

    pub fn from_name(name: &str) -> Option<ObjectTag> {
        ObjectTag::ALL.into_iter().find(|tag| tag.name() == name)
    }

    /// Union, intersection, difference and group hold other objects; shapes do not.
    pub fn is_container(self) -> bool {
        matches!(
            self,
            ObjectTag::Union | ObjectTag::Intersection | ObjectTag::Difference | ObjectTag::Group
        )
    }

    /// The properties that describe the shape itself (transforms and `material` come on top).
    fn own_properties(self) -> &'static [Prop] {
        use Prop::*;
        match self {
            ObjectTag::Sphere => &[Center, Radius],
            ObjectTag::Plane => &[Normal, Offset],
            ObjectTag::Box => &[Min, Max],
            ObjectTag::Cylinder => &[Base, Apex, Radius, Open],
            ObjectTag::Cone => &[Base, BaseRadius, Apex, ApexRadius, Open],
            ObjectTag::Disk => &[Center, Normal, Radius],
            ObjectTag::Triangle => &[Vertices],
            ObjectTag::Quadric => &[Coefficients],
            ObjectTag::Ellipsoid
            | ObjectTag::Paraboloid
            | ObjectTag::Hyperboloid
            | ObjectTag::Hyperboloid2 => &[Radii],
            ObjectTag::Union
            | ObjectTag::Intersection
            | ObjectTag::Difference
            | ObjectTag::Group => &[],
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightTag {
    Point,
    Directional,
    Spot,
}

impl LightTag {
    pub const ALL: [LightTag; 3] = [LightTag::Point, LightTag::Directional, LightTag::Spot];

    pub fn name(self) -> &'static str {
        match self {
            LightTag::Point => "point",
            LightTag::Directional => "directional",
            LightTag::Spot => "spot",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CameraTag {
    Perspective,
    Orthographic,
}

impl CameraTag {
    pub const ALL: [CameraTag; 2] = [CameraTag::Perspective, CameraTag::Orthographic];

    pub fn name(self) -> &'static str {
        match self {
            CameraTag::Perspective => "perspective",
            CameraTag::Orthographic => "orthographic",
        }
    }
}

/// Every property name the language knows. Which ones a block accepts depends on the block
/// ([`Context::properties`]); `height` and `ambient` mean different things in different blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Prop {
    // Shapes.
    Center,
    Radius,
    Normal,
    Offset,
    Min,
    Max,
    Base,
    Apex,
    BaseRadius,
    ApexRadius,
    Vertices,
    Coefficients,
    Radii,
    Open,
    // Any object, and the block after a call.
    Translate,
    Rotate,
    Scale,
    Matrix,
    Material,
    // Settings.
    Width,
    Height,
    MaxDepth,
    MinWeight,
    Samples,
    Background,
    Ambient,
    Epsilon,
    Shadows,
    // Cameras.
    Eye,
    LookAt,
    Up,
    Fov,
    // Lights.
    Position,
    Color,
    Attenuation,
    Direction,
    Inner,
    Outer,
    // Materials (`Ambient` too).
    Diffuse,
    Specular,
    Shininess,
    Reflective,
    Transmissive,
    Ior,
    Fresnel,
    Absorption,
    Priority,
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

impl Prop {
    pub const ALL: [Prop; 47] = {
        use Prop::*;
        [
            Center,
            Radius,
            Normal,
            Offset,
            Min,
            Max,
            Base,
            Apex,
            BaseRadius,
            ApexRadius,
            Vertices,
            Coefficients,
            Radii,
            Open,
            Translate,
            Rotate,
            Scale,
            Matrix,
            Material,
            Width,
            Height,
            MaxDepth,
            MinWeight,
            Samples,
            Background,
            Ambient,
            Epsilon,
            Shadows,
            Eye,
            LookAt,
            Up,
            Fov,
            Position,
            Color,
            Attenuation,
            Direction,
            Inner,
            Outer,
            Diffuse,
            Specular,
            Shininess,
            Reflective,
            Transmissive,
            Ior,
            Fresnel,
            Absorption,
            Priority,
        ]
    };

    pub fn name(self) -> &'static str {
        use Prop::*;
        match self {
            Center => "center",
            Radius => "radius",
            Normal => "normal",
            Offset => "offset",
            Min => "min",
            Max => "max",
            Base => "base",
            Apex => "apex",
            BaseRadius => "base_radius",
            ApexRadius => "apex_radius",
            Vertices => "vertices",
            Coefficients => "coefficients",
            Radii => "radii",
            Open => "open",
            Translate => "translate",
            Rotate => "rotate",
            Scale => "scale",
            Matrix => "matrix",
            Material => "material",
            Width => "width",
            Height => "height",
            MaxDepth => "max_depth",
            MinWeight => "min_weight",
            Samples => "samples",
            Background => "background",
            Ambient => "ambient",
            Epsilon => "epsilon",
            Shadows => "shadows",
            Eye => "eye",
            LookAt => "look_at",
            Up => "up",
            Fov => "fov",
            Position => "position",
            Color => "color",
            Attenuation => "attenuation",
            Direction => "direction",
            Inner => "inner",
            Outer => "outer",
            Diffuse => "diffuse",
            Specular => "specular",
            Shininess => "shininess",
            Reflective => "reflective",
            Transmissive => "transmissive",
            Ior => "ior",
            Fresnel => "fresnel",
            Absorption => "absorption",
            Priority => "priority",
        }
    }

    pub fn arity(self) -> Arity {
        match self {
            Prop::Open => Arity::Flag,
            Prop::Vertices => Arity::Exactly(3),
            Prop::Coefficients => Arity::Numbers(10),
            Prop::Matrix => Arity::Numbers(16),
            _ => Arity::One,
        }
    }

    /// Properties whose value is one of a few words rather than an expression.
    pub fn words(self) -> Option<&'static [&'static str]> {
        match self {
            Prop::Shadows => Some(&["opaque", "filtered"]),
            Prop::Fresnel => Some(&["off", "schlick", "exact"]),
            _ => None,
        }
    }

    /// Transforms may be given any number of times; every other property once per block.
    pub fn is_transform(self) -> bool {
        matches!(
            self,
            Prop::Translate | Prop::Rotate | Prop::Scale | Prop::Matrix
        )
    }
}

const TRANSFORMS: &[Prop] = &[Prop::Translate, Prop::Rotate, Prop::Scale, Prop::Matrix];
const SETTINGS: &[Prop] = &[
    Prop::Width,
    Prop::Height,
    Prop::MaxDepth,
    Prop::MinWeight,
    Prop::Samples,
    Prop::Background,
    Prop::Ambient,
    Prop::Epsilon,
    Prop::Shadows,
];
const MATERIAL: &[Prop] = &[
    Prop::Ambient,
    Prop::Diffuse,
    Prop::Specular,
    Prop::Shininess,
    Prop::Reflective,
    Prop::Transmissive,
    Prop::Ior,
    Prop::Fresnel,
    Prop::Absorption,
    Prop::Priority,
];

/// The kind of block an item sits in, which decides what the item may be.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Context {
    /// A file's top level, a function body, or a `for`/`if` block inside either.
    Statements {
        top_level: bool,
        in_function: bool,
    },
    Object(ObjectTag),
    /// The block after a call statement: `ring(3) { translate <0, 1, 0> }`.
    Modifiers,
    Settings,
    Camera(CameraTag),
    Light(LightTag),
    Material,
    /// The block after a pattern: `diffuse checker(a, b, 1) { rotate <0, 45, 0> }`.
    PatternTransform,
    /// The body of an object, light or camera of an unknown kind (already reported):
    /// its properties are not checked, so one typo gives one error.
    Unknown,
}

impl Context {
    /// The properties this block accepts, in the order the docs list them.
    pub fn properties(self) -> Vec<Prop> {
        match self {
            Context::Statements { .. } => Vec::new(),
            Context::Object(tag) => {
                let mut list = tag.own_properties().to_vec();
                list.extend_from_slice(TRANSFORMS);
                list.push(Prop::Material);
                list
            }
            Context::Modifiers => {
                let mut list = TRANSFORMS.to_vec();
                list.push(Prop::Material);
                list
            }
            Context::Settings => SETTINGS.to_vec(),
            Context::Camera(CameraTag::Perspective) => {
                vec![Prop::Eye, Prop::LookAt, Prop::Up, Prop::Fov]
            }
            Context::Camera(CameraTag::Orthographic) => {
                vec![Prop::Eye, Prop::LookAt, Prop::Up, Prop::Height]
            }
            Context::Light(LightTag::Point) => vec![Prop::Position, Prop::Color, Prop::Attenuation],
            Context::Light(LightTag::Directional) => vec![Prop::Direction, Prop::Color],
            Context::Light(LightTag::Spot) => vec![
                Prop::Position,
                Prop::Direction,
                Prop::Inner,
                Prop::Outer,
                Prop::Color,
                Prop::Attenuation,
            ],
            Context::Material => MATERIAL.to_vec(),
            Context::PatternTransform => TRANSFORMS.to_vec(),
            Context::Unknown => Vec::new(),
        }
    }

    /// "a sphere", "the settings", ...: how messages name the block.
    pub fn describe(self) -> String {
        match self {
            Context::Statements {
                in_function: true, ..
            } => "a function body".to_string(),
            Context::Statements {
                top_level: true, ..
            } => "the top level".to_string(),
            Context::Statements { .. } => "a block".to_string(),
            Context::Object(tag) => article(tag.name()),
            Context::Modifiers => "the block after a call".to_string(),
            Context::Settings => "the settings".to_string(),
            Context::Camera(tag) => article(&format!("{} camera", tag.name())),
            Context::Light(tag) => article(&format!("{} light", tag.name())),
            Context::Material => "a material".to_string(),
            Context::PatternTransform => "a pattern's transform block".to_string(),
            Context::Unknown => "this block".to_string(),
        }
    }

    pub fn is_statements(self) -> bool {
        matches!(self, Context::Statements { .. })
    }
}

/// "a sphere", "an ellipsoid".
pub fn article(noun: &str) -> String {
    // "a union": a `u` that sounds like "you" takes "a".
    let vowel = noun
        .chars()
        .next()
        .is_some_and(|c| "aeiou".contains(c.to_ascii_lowercase()))
        && !noun.starts_with("uni");
    if vowel {
        format!("an {noun}")
    } else {
        format!("a {noun}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_object_name_round_trips() {
        for tag in ObjectTag::ALL {
            assert_eq!(ObjectTag::from_name(tag.name()), Some(tag));
        }
        assert_eq!(ObjectTag::from_name("sphre"), None);
    }

    #[test]
    fn blocks_accept_their_own_properties_and_transforms() {
        let sphere = Context::Object(ObjectTag::Sphere).properties();
        assert!(sphere.contains(&Prop::Radius) && sphere.contains(&Prop::Rotate));
        assert!(!sphere.contains(&Prop::Open));
        assert!(Context::Object(ObjectTag::Cone)
            .properties()
            .contains(&Prop::Open));
        assert!(!Context::Material.properties().contains(&Prop::Translate));
        assert_eq!(article("ellipsoid"), "an ellipsoid");
        assert_eq!(article("point light"), "a point light");
        assert_eq!(article("union"), "a union");
    }
}
