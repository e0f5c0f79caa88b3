//! Lints read off the IR alone, no ray traced: lights inside solids, materials whose
//! reflected and transmitted rays together carry more than the light that arrives, and
//! planes or triangles whose lit side is not the side the camera sees.

use glam::DVec3;
use whitted_ir::{
    Color, Diagnostic, Handle, Light, LightKind, Object, ObjectKind, Scene, ShadowMode, Shape,
};

use super::bounds::world_bounds;
use super::{Lint, LintKind};
use crate::inside::contains;

/// The most light-in-object tests [`lights_inside_solids`] makes (lights × objects): past
/// it, the objects after the first `MAX_CONTAINMENT_TESTS / lights` are not tested (a
/// million objects and 50 lights still fit).
pub const MAX_CONTAINMENT_TESTS: usize = 50_000_000;

/// A light's display name.
pub(super) fn light_label(scene: &Scene, handle: Handle<Light>) -> String {
    match &scene.lights[handle].name {
        Some(name) => format!("light \"{name}\""),
        None => format!("light {handle}"),
    }
}

/// An object as the warnings name it: `sphere "ball"`, or `sphere #3` when unnamed.
pub(super) fn object_name(scene: &Scene, handle: Handle<Object>) -> String {
    let Some(object) = scene.objects.get(handle) else {
        return format!("object {handle}");
    };
    match scene.name_of(object) {
        Some(name) => {
            let kind = match &object.kind {
                ObjectKind::Shape { shape } => shape.kind_name(),
                ObjectKind::Csg { op, .. } => op.name(),
                ObjectKind::Group { .. } => "group",
            };
            format!("{kind} \"{name}\"")
        }
        None => scene.object_label(handle),
    }
}

/// A material as the warnings name it.
fn material_name(scene: &Scene, handle: Handle<whitted_ir::Material>) -> String {
    match &scene.materials[handle].name {
        Some(name) => format!("material `{name}`"),
        None => format!("the material {handle}"),
    }
}

/// The objects that render as objects: the roots, with groups opened (CSG solids stay
/// whole: their children's surfaces are internal).
pub(super) fn renderables(scene: &Scene) -> Vec<Handle<Object>> {
    let mut out = Vec::with_capacity(scene.roots.len());
    let mut stack: Vec<Handle<Object>> = scene.roots.iter().rev().copied().collect();
    while let Some(handle) = stack.pop() {
        match scene.objects.get(handle).map(|o| &o.kind) {
            Some(ObjectKind::Group { children }) => stack.extend(children.iter().rev()),
            Some(_) => out.push(handle),
            None => {}
        }
    }
    out
}

/// A point or spot light inside a closed object that keeps its light in: every shadow ray
/// towards it is blocked, so it lights nothing outside. Not reported when shadows are off
/// (`shadows none` lights every surface anyway) or when shadows are filtered and the solid
/// lets light through (the light then shines out through it, tinted).
pub(super) fn lights_inside_solids(scene: &Scene, lints: &mut Vec<Lint>) {
    if scene.settings.shadows == ShadowMode::None {
        return;
    }
    let lights: Vec<(Handle<Light>, DVec3)> = scene
        .lights
        .iter()
        .filter_map(|(handle, light)| match light.kind {
            LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
                Some((handle, position))
            }
            LightKind::Directional { .. } => None,
        })
        .collect();
    if lights.is_empty() {
        return;
    }
    let objects = renderables(scene);
    let budget = MAX_CONTAINMENT_TESTS / lights.len();
    // Objects outer, lights inner: each object's bounds are made once and rule out most
    // lights without inverting its transform.
    let mut inside: Vec<(Handle<Light>, Handle<Object>)> = Vec::new();
    for &object_handle in objects.iter().take(budget) {
        let bounds = world_bounds(scene, object_handle);
        for &(light_handle, position) in &lights {
            if bounds.is_some_and(|b| !b.contains(position, 0.0)) {
                continue;
            }
            if contains(scene, object_handle, position) == Some(true) {
                inside.push((light_handle, object_handle));
            }
        }
    }
    inside.sort();
    for (light_handle, object_handle) in inside {
        let light_span = scene.lights.span(light_handle);
        let position = match scene.lights[light_handle].kind {
            LightKind::Point { position, .. } | LightKind::Spot { position, .. } => position,
            LightKind::Directional { .. } => continue,
        };
        {
            let object = &scene.objects[object_handle];
            let lets_light_through = !scene.materials[object.material].transmissive.is_black();
            if lets_light_through && scene.settings.shadows == ShadowMode::Filtered {
                continue;
            }
            let name = object_name(scene, object_handle);
            let light_name = light_label(scene, light_handle);
            let plane = matches!(object.kind.shape(), Some(Shape::Plane { .. }));
            let (inside, fix) = if plane {
                (
                    format!("below {name} (on the side its normal points away from)"),
                    format!(
                        "move {light_name} to the side of {name} its normal points to, or turn \
                         the plane around (negate its normal)"
                    ),
                )
            } else {
                (
                    format!("inside {name}"),
                    format!(
                        "move {light_name} out of {name}{}",
                        if lets_light_through {
                            ", or add `shadows filtered` to the settings so that its light \
                             shines out through the transparent solid"
                        } else {
                            ""
                        }
                    ),
                )
            };
            let diagnostic = Diagnostic::warning(
                format!("{light_name} is {inside}: every shadow ray towards it is blocked, so it lights nothing outside"),
                light_span,
            )
            .with_label(format!("{light_name} at {}", point(position)))
            .with_secondary(scene.objects.span(object_handle), format!("{name} encloses it"))
            .with_hint(fix);
            lints.push(Lint::new(LintKind::LightInsideSolid, diagnostic));
        }
    }
}

/// A material whose reflected and transmitted rays together weigh more than 1 on a
/// channel. Without Fresnel the rays weigh `kr` and `kt`; with Fresnel `kr + kt·R` and
/// `kt·(1 − R)`, which still sum to `kr + kt`. So the rule is `kr + kt > 1` in every
/// mode: such a surface would return more light than reaches it, so the tracer scales
/// both down to sum to 1 (`conserve_energy` in the tracer) and the material is not what
/// its numbers say. The diffuse and specular terms are not counted: Whitted's model adds
/// them on top of `kr` and `kt` by design (a diffuse 0.8 mirror of `kr` 0.5 is the
/// textbook's own kind of material). The scene language warns about the same rule when it
/// evaluates the material; the binary shows one of the two, so this lint is what a 6.837
/// scene (or any other front end) gets.
pub(super) fn material_gain(scene: &Scene, lints: &mut Vec<Lint>) {
    for (handle, material, span) in scene.materials.iter_with_spans() {
        let sum = [
            material.reflective.r + material.transmissive.r,
            material.reflective.g + material.transmissive.g,
            material.reflective.b + material.transmissive.b,
        ];
        let worst = sum.into_iter().fold(0.0f64, f64::max);
        if worst <= 1.0 + 1e-9 {
            continue;
        }
        let name = material_name(scene, handle);
        let consequence = if scene.settings.energy_clamp {
            "so the tracer scales both down to sum to 1"
        } else {
            "and with `energy_clamp off` both are used as given: every bounce returns more \
             light than arrives"
        };
        let diagnostic = Diagnostic::warning(
            format!(
                "{name} reflects and transmits more light than it receives: reflective + \
                 transmissive is {} (more than 1), {consequence}",
                color_sum(material.reflective, material.transmissive)
            ),
            span,
        )
        .with_label(format!(
            "reflective {} + transmissive {}",
            color(material.reflective),
            color(material.transmissive)
        ))
        .with_hint(format!(
            "lower reflective or transmissive so that they sum to 1 at most on each channel \
             (for glass with `fresnel schlick` or `exact`, reflective 0 and transmissive 1: \
             Fresnel splits it); here the largest sum is {worst:.3}"
        ));
        lints.push(Lint::new(LintKind::MaterialGain, diagnostic));
    }
}

/// Which sides of a flat surface lights are on, and the camera.
struct Sides {
    front_lit: bool,
    back_lit: bool,
    /// Whether the camera is on the front side.
    camera_in_front: bool,
}

/// A plane or a lone triangle (not one of a mesh's or group's) whose side the camera sees
/// gets no light: it renders with ambient (and emission) only. With `shade_back on`
/// either side is lit by the lights on its side; with `shade_back off` only the front is,
/// so a plane seen from its back is dark whatever the lights. Triangles of groups are left
/// out: a closed mesh always has faces turned from every light and from the camera.
/// Surfaces with no diffuse and no specular colour (mirrors, glass) are left out too: the
/// lights add nothing to them on either side.
pub(super) fn facing_away_from_lights(scene: &Scene, lints: &mut Vec<Lint>) {
    if scene.lights.is_empty() {
        return;
    }
    for &handle in &scene.roots {
        let object = &scene.objects[handle];
        let Some(shape) = object.kind.shape() else {
            continue;
        };
        let (normal, on_surface, what) = match shape {
            Shape::Plane { normal, offset } => {
                let p = normal * (offset / normal.length_squared());
                (normal, p, "plane")
            }
            Shape::Triangle { a, b, c } => ((b - a).cross(c - a), a, "triangle"),
            _ => continue,
        };
        let material = &scene.materials[object.material];
        if material.diffuse.is_black() && material.specular.is_black() {
            continue;
        }
        let world_from_object = object.world_from_object.matrix();
        let normal = world_from_object
            .inverse()
            .transpose()
            .transform_vector3(normal);
        let origin = world_from_object.transform_point3(on_surface);
        let Some(normal) = normal.try_normalize() else {
            continue;
        };
        let Some(sides) = sides(scene, normal, origin) else {
            continue;
        };
        let name = object_name(scene, handle);
        let (message, fix) = if !scene.settings.shade_back && !sides.camera_in_front {
            (
                format!(
                    "the camera sees the back of {name}, and `shade_back off` leaves \
                     back faces unlit: it renders with ambient light only"
                ),
                match what {
                    "plane" => "turn the plane around (negate its normal), or set `shade_back on`"
                        .to_string(),
                    _ => {
                        "turn the triangle around (swap two of its corners), or set `shade_back on`"
                            .to_string()
                    }
                },
            )
        } else {
            let seen_lit = if sides.camera_in_front {
                sides.front_lit
            } else {
                sides.back_lit
            };
            if seen_lit {
                continue;
            }
            let side = if sides.camera_in_front {
                "front"
            } else {
                "back"
            };
            (
                format!(
                    "every light is behind {name}: the camera sees its {side}, which \
                     no light faces, so it renders with ambient light only"
                ),
                format!("move a light to the camera's side of {name}"),
            )
        };
        let diagnostic = Diagnostic::warning(message, scene.objects.span(handle))
            .with_label(format!("its normal points along {}", point(normal)))
            .with_hint(fix);
        lints.push(Lint::new(LintKind::FacingAwayFromLights, diagnostic));
    }
}

/// The sides of the plane through `origin` with unit `normal` that the lights and the
/// camera are on; `None` when the camera lies in the plane (it sees neither side).
fn sides(scene: &Scene, normal: DVec3, origin: DVec3) -> Option<Sides> {
    let camera_side = normal.dot(scene.camera.eye - origin);
    if camera_side == 0.0 {
        return None;
    }
    let (mut front_lit, mut back_lit) = (false, false);
    for (_, light) in scene.lights.iter() {
        let side = match light.kind {
            LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
                normal.dot(position - origin)
            }
            LightKind::Directional { direction } => -normal.dot(direction),
        };
        front_lit |= side > 0.0;
        back_lit |= side < 0.0;
    }
    Some(Sides {
        front_lit,
        back_lit,
        camera_in_front: camera_side > 0.0,
    })
}

fn point(p: DVec3) -> String {
    format!("<{}, {}, {}>", short(p.x), short(p.y), short(p.z))
}

fn color(c: Color) -> String {
    if c.r == c.g && c.g == c.b {
        short(c.r)
    } else {
        format!("rgb({}, {}, {})", short(c.r), short(c.g), short(c.b))
    }
}

fn color_sum(a: Color, b: Color) -> String {
    color(Color::new(a.r + b.r, a.g + b.g, a.b + b.b))
}

/// A number in at most four decimals, without trailing zeros.
pub(super) fn short(x: f64) -> String {
    let text = format!("{x:.4}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".to_string()
    } else {
        text.to_string()
    }
}
