//! The JSON form of the IR (`whitted ir --json`): the derived serde form of each node, plus
//! its handle and its source location as `path:line:column`.
//!
//! [`document`] is a serde view that serialises straight from the scene, so that the binary
//! can stream it to its output: building a `serde_json::Value` tree first took about 6 GiB
//! per million objects.

use serde::ser::{Serialize, SerializeStruct, Serializer};
use serde_json::Value;

use crate::arena::{Arena, Handle};
use crate::provenance::Step;
use crate::scene::{Camera, Object, Scene, Settings};
use crate::source::SourceMap;

#[derive(serde::Serialize)]
struct Entry<'a, T: Serialize> {
    handle: usize,
    location: String,
    #[serde(flatten)]
    value: &'a T,
}

/// The nodes of one arena, each with its handle and location, serialised one at a time.
struct Entries<'a, T> {
    scene: &'a Scene,
    arena: &'a Arena<T>,
}

impl<T: Serialize> Serialize for Entries<'_, T> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(
            self.arena
                .iter_with_spans()
                .map(|(handle, value, span)| Entry {
                    handle: handle.index(),
                    location: self.scene.sources.location(span),
                    value,
                }),
        )
    }
}

/// The objects, each with its handle, location and, when it was made inside an import, call
/// or loop, its instantiation stack as `made_by` (innermost first).
struct Objects<'a>(&'a Scene);

#[derive(serde::Serialize)]
struct ObjectEntry<'a> {
    handle: usize,
    location: String,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    made_by: Vec<StepJson<'a>>,
    name: Option<&'a str>,
    #[serde(flatten)]
    value: &'a Object,
}

impl Serialize for Objects<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let scene = self.0;
        serializer.collect_seq(
            scene
                .objects
                .iter_with_spans()
                .map(|(handle, value, span)| ObjectEntry {
                    handle: handle.index(),
                    location: scene.sources.location(span),
                    made_by: scene
                        .provenance
                        .stack(handle)
                        .iter()
                        .map(|step| StepJson::new(step, &scene.sources))
                        .collect(),
                    name: scene.name_of(value),
                    value,
                }),
        )
    }
}

/// One step of an instantiation stack in JSON: `{"kind": "loop", "var": "i", "value": 7,
/// "location"}`, `{"kind": "call", "function": "ring", "args": [{"name", "value"}], "text":
/// "ring(12, 2)", "location"}` or `{"kind": "import", "location"}`. Also the ray tree's form.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct StepJson<'a> {
    pub kind: &'static str,
    /// The step as `whitted ir` writes it: `i = 7`, `ring(12, 2)`, `import`.
    pub text: String,
    pub location: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub var: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub function: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub args: Option<Vec<ArgJson<'a>>>,
}

/// A call's argument in JSON: the parameter's name and the value as text.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ArgJson<'a> {
    pub name: &'a str,
    pub value: String,
}

impl<'a> StepJson<'a> {
    pub fn new(step: &Step<'a>, sources: &SourceMap) -> Self {
        let mut json = StepJson {
            kind: step.kind_name(),
            text: step.label(),
            location: sources.location(step.span()),
            var: None,
            value: None,
            function: None,
            args: None,
        };
        match *step {
            Step::Import { .. } => {}
            Step::Loop { var, value, .. } => {
                json.var = Some(var);
                json.value = Some(value);
            }
            Step::Call {
                name, params, args, ..
            } => {
                json.function = Some(name);
                json.args = Some(
                    params
                        .iter()
                        .zip(args)
                        .map(|(name, value)| ArgJson {
                            name,
                            value: value.to_string(),
                        })
                        .collect(),
                );
            }
        }
        json
    }
}

/// The source files, `{ "id", "path" }` each.
struct Files<'a>(&'a Scene);

impl Serialize for Files<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(serde::Serialize)]
        struct File<'a> {
            id: u32,
            path: &'a str,
        }
        serializer.collect_seq(self.0.sources.files().map(|(id, f)| File {
            id: id.0,
            path: &f.path,
        }))
    }
}

#[derive(serde::Serialize)]
struct MeshEntry<'a> {
    handle: usize,
    location: String,
    #[serde(flatten)]
    value: crate::mesh::MeshSummary<'a>,
}

/// The meshes by their counts (not their vertices), each with its handle and location.
struct Meshes<'a>(&'a Scene);

impl Serialize for Meshes<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let scene = self.0;
        serializer.collect_seq(scene.meshes.iter_with_spans().map(|(handle, mesh, span)| {
            MeshEntry {
                handle: handle.index(),
                location: scene.sources.location(span),
                value: mesh.summary(),
            }
        }))
    }
}

/// The whole scene as a serialisable document (format version 1).
pub struct IrDocument<'a> {
    scene: &'a Scene,
}

/// The JSON view of `scene`, to serialise with serde_json (to a writer, to stream it).
pub fn document(scene: &Scene) -> IrDocument<'_> {
    IrDocument { scene }
}

impl Serialize for IrDocument<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let scene = self.scene;
        // Keys in alphabetical order, as the earlier `Value` form printed them.
        let mut map = serializer.serialize_struct("IrDocument", 9)?;
        map.serialize_field("camera", &scene.camera as &Camera)?;
        map.serialize_field("files", &Files(scene))?;
        map.serialize_field(
            "lights",
            &Entries {
                scene,
                arena: &scene.lights,
            },
        )?;
        map.serialize_field(
            "materials",
            &Entries {
                scene,
                arena: &scene.materials,
            },
        )?;
        map.serialize_field("meshes", &Meshes(scene))?;
        map.serialize_field("objects", &Objects(scene))?;
        map.serialize_field("roots", &scene.roots as &Vec<Handle<Object>>)?;
        map.serialize_field("settings", &scene.settings as &Settings)?;
        map.serialize_field("version", &1)?;
        map.end()
    }
}

/// The whole scene as a JSON value (format version 1). Prefer [`document`] for big scenes.
pub fn to_json(scene: &Scene) -> Value {
    serde_json::to_value(document(scene)).unwrap_or(Value::Null)
}
