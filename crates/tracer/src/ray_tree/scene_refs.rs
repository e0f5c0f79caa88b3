//! Turning IR handles into the named, located references a ray tree shows: labels and
//! `file:line:col` come from the `whitted_ir::Scene` that the prepared scene was made from.

use whitted_ir::{Handle, Light, LightKind, Material, Object, ObjectKind, Scene, Span};

use super::model::{LightRef, MaterialRef, ObjectRef, StackArg, StackStep};

/// A reference for a handle the scene does not have: only reachable when the caller passes
/// a different scene from the one that was prepared. Labelled, not a panic.
fn unknown(what: &str, handle: u32) -> (u32, Option<String>, String, String, Span) {
    let label = format!("{what} #{handle} (not in this scene)");
    (
        handle,
        None,
        label,
        "<unknown>".to_string(),
        Span::detached(),
    )
}

pub(crate) fn object_ref(scene: &Scene, handle: Handle<Object>) -> ObjectRef {
    let Some(object) = scene.objects.get(handle) else {
        let (handle, name, label, location, span) = unknown("object", handle.index() as u32);
        let kind = "unknown".to_string();
        return ObjectRef {
            handle,
            name,
            label,
            kind,
            location,
            made_by: Vec::new(),
            span,
        };
    };
    let span = scene.objects.span(handle);
    let kind = match &object.kind {
        ObjectKind::Shape { shape } => shape.kind_name(),
        ObjectKind::Csg { op, .. } => op.name(),
        ObjectKind::Group { .. } => "group",
    };
    ObjectRef {
        handle: handle.index() as u32,
        name: scene.name_of(object).map(str::to_string),
        label: scene.object_label(handle),
        kind: kind.to_string(),
        location: scene.sources.location(span),
        made_by: made_by(scene, handle),
        span,
    }
}

/// An object's instantiation stack, as the ray tree shows it.
fn made_by(scene: &Scene, handle: Handle<Object>) -> Vec<StackStep> {
    let steps = scene.provenance.stack(handle);
    steps
        .iter()
        .map(|step| {
            let json = whitted_ir::StepJson::new(step, &scene.sources);
            StackStep {
                kind: json.kind,
                text: json.text,
                location: json.location,
                var: json.var.map(str::to_string),
                value: json.value,
                function: json.function.map(str::to_string),
                args: json.args.map(|args| {
                    args.into_iter()
                        .map(|arg| StackArg {
                            name: arg.name.to_string(),
                            value: arg.value,
                        })
                        .collect()
                }),
                span: step.span(),
            }
        })
        .collect()
}

pub(crate) fn material_ref(scene: &Scene, handle: Handle<Material>) -> MaterialRef {
    if !scene.materials.contains(handle) {
        let (handle, name, label, location, span) = unknown("material", handle.index() as u32);
        return MaterialRef {
            handle,
            name,
            label,
            location,
            span,
        };
    }
    let span = scene.materials.span(handle);
    MaterialRef {
        handle: handle.index() as u32,
        name: scene.materials[handle].name.clone(),
        label: scene.material_label(handle),
        location: scene.sources.location(span),
        span,
    }
}

pub(crate) fn light_ref(scene: &Scene, handle: Handle<Light>) -> LightRef {
    let Some(light) = scene.lights.get(handle) else {
        let (handle, name, label, location, span) = unknown("light", handle.index() as u32);
        let kind = "unknown".to_string();
        return LightRef {
            handle,
            name,
            label,
            kind,
            location,
            span,
        };
    };
    let span = scene.lights.span(handle);
    let kind = match light.kind {
        LightKind::Point { .. } => "point",
        LightKind::Directional { .. } => "directional",
        LightKind::Spot { .. } => "spot",
    };
    LightRef {
        handle: handle.index() as u32,
        name: light.name.clone(),
        label: light
            .name
            .clone()
            .unwrap_or_else(|| format!("light {handle}")),
        kind: kind.to_string(),
        location: scene.sources.location(span),
        span,
    }
}

/// The CSG operations from `object` down to (not including) `leaf`: empty when the object
/// is the leaf. Searched depth first in child order with an explicit stack, so deeply
/// nested CSG cannot overflow the call stack.
pub(crate) fn csg_path(
    scene: &Scene,
    object: Handle<Object>,
    leaf: Handle<Object>,
) -> Vec<ObjectRef> {
    if object == leaf {
        return Vec::new();
    }
    // Each entry: a node and the path of operations that led to it (parents first).
    let mut stack: Vec<(Handle<Object>, Vec<Handle<Object>>)> = vec![(object, Vec::new())];
    while let Some((node, path)) = stack.pop() {
        if node == leaf {
            return path.into_iter().map(|h| object_ref(scene, h)).collect();
        }
        let Some(item) = scene.objects.get(node) else {
            continue;
        };
        let children = match &item.kind {
            ObjectKind::Csg { children, .. } | ObjectKind::Group { children } => children,
            ObjectKind::Shape { .. } => continue,
        };
        // Pushed in reverse so that the first child is searched first.
        for &child in children.iter().rev() {
            let mut child_path = path.clone();
            child_path.push(node);
            stack.push((child, child_path));
        }
    }
    Vec::new()
}
