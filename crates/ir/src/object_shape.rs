//! How an object holds its shape and its name compactly: the arena of a million-sphere
//! scene is most of the memory `check`, the debugger and a render's compilation use.
//!
//! A sphere, plane, torus or mesh instance is kept inline (32 bytes at most); a box,
//! cylinder, cone, disk, triangle or quadric (48 to 88 bytes) is boxed, as they are rare in
//! large numbers and an inline [`Shape`] would make every object pay for the largest. A
//! name is an index into the scene's [`Names`], since a `String` in every object would cost
//! 24 bytes that most objects leave empty. Together they bring an [`crate::Object`] from
//! 128 bytes to 56.

use std::num::NonZeroU32;

use glam::DVec3;
use serde::Serialize;

use crate::arena::Handle;
use crate::mesh::Mesh;
use crate::scene::Shape;

/// An object's shape as the arena stores it. Read it with [`ObjectShape::get`]; it
/// compares, prints and serializes as the [`Shape`] it holds.
#[derive(Clone)]
pub struct ObjectShape(Stored);

#[derive(Clone)]
enum Stored {
    Sphere { center: DVec3, radius: f64 },
    Plane { normal: DVec3, offset: f64 },
    Torus { major: f64, minor: f64 },
    Mesh { mesh: Handle<Mesh>, smooth: bool },
    Large(Box<Shape>),
}

impl ObjectShape {
    pub fn new(shape: Shape) -> ObjectShape {
        ObjectShape(match shape {
            Shape::Sphere { center, radius } => Stored::Sphere { center, radius },
            Shape::Plane { normal, offset } => Stored::Plane { normal, offset },
            Shape::Torus { major, minor } => Stored::Torus { major, minor },
            Shape::Mesh { mesh, smooth } => Stored::Mesh { mesh, smooth },
            large => Stored::Large(Box::new(large)),
        })
    }

    /// The shape, by value (no shape owns heap memory, so this is a copy).
    pub fn get(&self) -> Shape {
        match &self.0 {
            Stored::Sphere { center, radius } => Shape::Sphere {
                center: *center,
                radius: *radius,
            },
            Stored::Plane { normal, offset } => Shape::Plane {
                normal: *normal,
                offset: *offset,
            },
            Stored::Torus { major, minor } => Shape::Torus {
                major: *major,
                minor: *minor,
            },
            Stored::Mesh { mesh, smooth } => Shape::Mesh {
                mesh: *mesh,
                smooth: *smooth,
            },
            Stored::Large(shape) => (**shape).clone(),
        }
    }

    /// Changes the shape through `change` (tests and edits that adjust one number).
    pub fn update(&mut self, change: impl FnOnce(&mut Shape)) {
        let mut shape = self.get();
        change(&mut shape);
        *self = ObjectShape::new(shape);
    }

    /// The shape's kind as the language writes it (`sphere`, `cylinder`, ...).
    pub fn kind_name(&self) -> &'static str {
        self.get().kind_name()
    }
}

impl From<Shape> for ObjectShape {
    fn from(shape: Shape) -> ObjectShape {
        ObjectShape::new(shape)
    }
}

impl PartialEq for ObjectShape {
    fn eq(&self, other: &ObjectShape) -> bool {
        self.get() == other.get()
    }
}

impl std::fmt::Debug for ObjectShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.get().fmt(f)
    }
}

impl Serialize for ObjectShape {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.get().serialize(serializer)
    }
}

/// An object's name: an index into the scene's [`Names`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct NameId(NonZeroU32);

/// The objects' names, each stored once per object that was given one.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Names(Vec<Box<str>>);

impl Names {
    /// Keeps `name` and returns its id, or `None` past 2^32 - 1 names (an arena never
    /// holds that many objects: its handles are `u32` too).
    pub fn add(&mut self, name: &str) -> Option<NameId> {
        let id = NonZeroU32::new(u32::try_from(self.0.len() + 1).ok()?)?;
        self.0.push(name.into());
        Some(NameId(id))
    }

    /// The name behind `id` (empty for an id of another scene's table that is past this
    /// one's end).
    pub fn get(&self, id: NameId) -> &str {
        self.0.get(id.0.get() as usize - 1).map_or("", |name| name)
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Object, ObjectKind, Quadric, QuadricForm};

    fn every_kind() -> Vec<Shape> {
        let quadric = Quadric {
            a: 1.0,
            b: 2.0,
            c: 3.0,
            d: 0.5,
            e: -0.5,
            f: 0.25,
            g: 0.0,
            h: -0.0,
            i: 1e-300,
            j: -1.0,
        };
        vec![
            Shape::Sphere {
                center: DVec3::new(1e300, -0.0, 3.0),
                radius: 0.4,
            },
            Shape::Plane {
                normal: DVec3::Y,
                offset: -0.5,
            },
            Shape::Box {
                min: DVec3::splat(-1.0),
                max: DVec3::new(1.0, 2.0, f64::MIN_POSITIVE),
            },
            Shape::Cylinder {
                base: DVec3::ZERO,
                apex: DVec3::Z,
                radius: 2.0,
                capped: false,
            },
            Shape::Cone {
                base: DVec3::ZERO,
                base_radius: 1.0,
                apex: DVec3::X,
                apex_radius: 0.0,
                capped: true,
            },
            Shape::Disk {
                center: DVec3::ONE,
                normal: DVec3::NEG_Z,
                radius: 3.0,
            },
            Shape::Triangle {
                a: DVec3::X,
                b: DVec3::Y,
                c: DVec3::Z,
            },
            Shape::Quadric {
                form: QuadricForm::HyperboloidOneSheet,
                quadric,
            },
            Shape::Torus {
                major: 2.0,
                minor: 0.25,
            },
            Shape::Mesh {
                mesh: Handle::from_index(7),
                smooth: true,
            },
        ]
    }

    /// Every kind of shape comes back as it went in, bit for bit (the oracle is the shape
    /// itself, compared field by field through its JSON, where -0.0 and 0.0 differ).
    #[test]
    fn every_shape_comes_back_as_it_went_in() {
        for shape in every_kind() {
            let stored = ObjectShape::new(shape.clone());
            assert_eq!(stored.get(), shape);
            let stored_json = serde_json::to_string(&stored).expect("a shape serializes");
            let shape_json = serde_json::to_string(&shape).expect("a shape serializes");
            assert_eq!(stored_json, shape_json, "{shape:?}");
            assert_eq!(format!("{stored:?}"), format!("{shape:?}"));
            assert_eq!(stored.kind_name(), shape.kind_name());
        }
    }

    /// The sizes the module's doc promises: what a million-object arena costs per object.
    #[test]
    fn an_object_takes_56_bytes() {
        assert_eq!(std::mem::size_of::<ObjectShape>(), 40);
        assert_eq!(std::mem::size_of::<ObjectKind>(), 40);
        assert_eq!(std::mem::size_of::<Object>(), 56);
    }

    #[test]
    fn names_come_back_by_id() {
        let mut names = Names::default();
        let ids: Vec<NameId> = ["sun", "", "sun", "ünïcode"]
            .iter()
            .map(|n| names.add(n).expect("room"))
            .collect();
        assert_eq!(names.len(), 4);
        assert_ne!(ids[0], ids[2], "each object its own entry");
        let back: Vec<&str> = ids.iter().map(|&id| names.get(id)).collect();
        assert_eq!(back, ["sun", "", "sun", "ünïcode"]);
        assert_eq!(Names::default().get(ids[3]), "");
    }
}
