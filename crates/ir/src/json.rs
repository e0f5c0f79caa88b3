//! The JSON form of the IR (`whitted ir --json`): the derived serde form of each node, plus
//! its handle and its source location as `path:line:column`.

use serde::Serialize;
use serde_json::{json, Value};

use crate::arena::Arena;
use crate::scene::Scene;

#[derive(Serialize)]
struct Entry<'a, T: Serialize> {
    handle: usize,
    location: String,
    #[serde(flatten)]
    value: &'a T,
}

fn entries<T: Serialize>(scene: &Scene, arena: &Arena<T>) -> Value {
    let list: Vec<Value> = arena
        .iter_with_spans()
        .map(|(handle, value, span)| {
            let entry = Entry {
                handle: handle.index(),
                location: scene.sources.location(span),
                value,
            };
            serde_json::to_value(entry).unwrap_or(Value::Null)
        })
        .collect();
    Value::Array(list)
}

/// The whole scene as a JSON value (format version 1).
pub fn to_json(scene: &Scene) -> Value {
    let files: Vec<Value> = scene
        .sources
        .files()
        .map(|(id, f)| json!({ "id": id.0, "path": f.path }))
        .collect();
    json!({
        "version": 1,
        "settings": scene.settings,
        "camera": scene.camera,
        "lights": entries(scene, &scene.lights),
        "materials": entries(scene, &scene.materials),
        "objects": entries(scene, &scene.objects),
        "roots": scene.roots,
        "files": files,
    })
}
