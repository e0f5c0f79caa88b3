//! What the language knows by name: object, light and camera kinds, and the kinds of block.
//! The grammar is generic (`name value`); the properties each block accepts are rows of
//! [`crate::properties`], which is where a property becomes valid or "not a property of a
//! sphere; did you mean `center`?".

pub use crate::properties::{Arity, Prop};

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
    Torus,
    Mesh,
    Union,
    Intersection,
    Difference,
    Group,
}

impl ObjectTag {
    pub const ALL: [ObjectTag; 18] = [
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
        ObjectTag::Torus,
        ObjectTag::Mesh,
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
            ObjectTag::Torus => "torus",
            ObjectTag::Mesh => "mesh",
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

/// The kind of block an item sits in, which decides what the item may be.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
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
    /// The properties this block accepts, in the order the docs list them (from the table in
    /// [`crate::properties`]).
    pub fn properties(self) -> Vec<Prop> {
        crate::properties::accepted(self)
    }

    /// The property called `name` if this block accepts it, without building the list.
    pub fn property_named(self, name: &str) -> Option<Prop> {
        crate::properties::accepted_named(self, name)
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
