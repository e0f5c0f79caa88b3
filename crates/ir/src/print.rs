//! A readable text dump of the IR (`whitted ir`): one line per node, children indented,
//! each with the source location that made it. Names are printed quoted and escaped
//! (`{:?}`), so that a control character in a name cannot reach the user's terminal raw.

use std::fmt::Write;

use glam::{DMat4, DVec3};

use crate::arena::Handle;
use crate::scene::{
    Color, LightKind, Material, Object, ObjectKind, PatternKind, Projection, Scene, Shape,
};

/// Prints the scene as indented text. Numbers use Rust's shortest round-trip form.
pub fn print(scene: &Scene) -> String {
    let mut out = String::new();
    let s = &scene.settings;
    let _ = writeln!(out, "settings");
    let _ = writeln!(
        out,
        "  size {}x{}, samples {}, max depth {}, min weight {}",
        s.width, s.height, s.samples_per_pixel, s.max_depth, s.min_weight
    );
    let _ = writeln!(
        out,
        "  background {}, ambient {}, epsilon {}, shadows {}{}{}{}{}{}{}",
        color(&s.background),
        color(&s.ambient),
        s.epsilon.map_or("auto".to_string(), |e| e.to_string()),
        word(&s.shadows),
        // Shown when it is not the classic Phong, so that older dumps read the same.
        match s.highlight {
            crate::scene::Highlight::Phong => "",
            crate::scene::Highlight::Blinn => ", highlight blinn",
        },
        // Likewise shown only when they leave the default.
        if s.shade_back {
            ""
        } else {
            ", back faces unlit"
        },
        if s.attenuation_clamp {
            ""
        } else {
            ", attenuation unclamped"
        },
        if s.energy_clamp {
            ""
        } else {
            ", reflective + transmissive unclamped"
        },
        match s.sampling {
            crate::scene::Sampling::Jittered => "",
            crate::scene::Sampling::Grid => ", sampling grid",
            crate::scene::Sampling::Random => ", sampling random",
        },
        // Shown when it is not the default box of each pixel's own samples.
        if s.filter_is_own_pixel() {
            String::new()
        } else {
            format!(", filter {} {}", word(&s.filter), s.filter_radius)
        }
    );
    // The course's rules and the student-bug switches: a line only when one leaves its
    // default, so that dumps of ordinary scenes read as before.
    let defaults = crate::scene::Settings::default();
    let changed: Vec<String> = crate::setting_rows::SWITCHES
        .iter()
        .filter(|row| (row.get)(s) != (row.get)(&defaults))
        .map(|row| format!("{} {}", row.name, row.text(s)))
        .collect();
    if !changed.is_empty() {
        let _ = writeln!(out, "  {}", changed.join(", "));
    }
    // An animation's frames: a line only for an animated scene.
    if s.is_animated() || s.first_frame != 0 || s.fps != crate::scene::DEFAULT_FPS {
        let range = s.frame_range();
        let _ = writeln!(
            out,
            "  frames {}..={} at {} fps",
            range.start(),
            range.end(),
            s.fps
        );
    }
    let c = &scene.camera;
    let projection = match c.projection {
        Projection::Perspective {
            vertical_fov_degrees,
        } => format!("perspective fov {vertical_fov_degrees}"),
        Projection::Orthographic { view_height } => format!("orthographic height {view_height}"),
    };
    let _ = writeln!(
        out,
        "camera {projection} eye {} look_at {} up {}  @ {}",
        v(c.eye),
        v(c.look_at),
        v(c.up),
        scene.sources.location(scene.camera_span)
    );
    for (handle, light, span) in scene.lights.iter_with_spans() {
        let name = light
            .name
            .as_deref()
            .map(|n| format!(" {n:?}"))
            .unwrap_or_default();
        let kind = match &light.kind {
            LightKind::Point {
                position,
                attenuation: a,
            } => format!(
                "point at {} attenuation ({}, {}, {})",
                v(*position),
                a.constant,
                a.linear,
                a.quadratic
            ),
            LightKind::Directional { direction } => {
                format!("directional towards {}", v(*direction))
            }
            LightKind::Spot {
                position,
                direction,
                inner_angle_degrees,
                outer_angle_degrees,
                attenuation: a,
            } => format!(
                "spot at {} towards {} cone {}..{} deg attenuation ({}, {}, {})",
                v(*position),
                v(*direction),
                inner_angle_degrees,
                outer_angle_degrees,
                a.constant,
                a.linear,
                a.quadratic
            ),
        };
        let _ = writeln!(
            out,
            "light {handle}{name} {kind} colour {}  @ {}",
            color(&light.color),
            scene.sources.location(span)
        );
    }
    for (handle, material, span) in scene.materials.iter_with_spans() {
        let _ = writeln!(
            out,
            "material {handle}{}  @ {}",
            material_name(material),
            scene.sources.location(span)
        );
        let _ = writeln!(out, "  {}", material_fields(material));
        if let Some(p) = &material.pattern {
            let parameters = match p.kind {
                PatternKind::CourseNoise { octaves } => format!(" octaves {octaves}"),
                PatternKind::CourseMarble {
                    octaves,
                    frequency,
                    amplitude,
                }
                | PatternKind::CourseWood {
                    octaves,
                    frequency,
                    amplitude,
                } => format!(" octaves {octaves} frequency {frequency} amplitude {amplitude}"),
                _ => String::new(),
            };
            let (between, space) = if p.kind.blends() {
                ("blend", " (world space)")
            } else if p.kind.world_space() {
                ("of", " (world space)")
            } else {
                ("of", "")
            };
            let _ = writeln!(
                out,
                "  pattern {} {between} {} and {}{parameters} scale {}{}{space}",
                p.kind.name(),
                p.a,
                p.b,
                p.scale,
                matrix_suffix(&p.pattern_from_object)
            );
        }
    }
    // Meshes by their counts: a million vertices would bury the scene.
    for (handle, mesh, span) in scene.meshes.iter_with_spans() {
        let _ = writeln!(
            out,
            "mesh {handle} {:?} {} vertices, {} triangles, {}, {}  @ {}",
            mesh.file,
            mesh.positions.len(),
            mesh.triangles.len(),
            if mesh.normals.is_empty() {
                "no normals"
            } else {
                "vertex normals"
            },
            if mesh.solid { "solid" } else { "open" },
            scene.sources.location(span)
        );
    }
    for &root in &scene.roots {
        print_object(scene, root, 0, &mut out);
    }
    out
}

fn material_name(m: &Material) -> String {
    m.name
        .as_deref()
        .map(|n| format!(" {n:?}"))
        .unwrap_or_default()
}

fn material_fields(m: &Material) -> String {
    let mut fields = format!(
        "ambient {} diffuse {} specular {} shininess {} reflective {} transmissive {} ior {} fresnel {} absorption {}",
        color(&m.ambient), color(&m.diffuse), color(&m.specular), m.shininess, color(&m.reflective),
        color(&m.transmissive), m.ior, m.fresnel.name(), color(&m.absorption)
    );
    // Only nested media use a priority: plain materials print as they always did.
    if m.priority != 0 {
        fields.push_str(&format!(" priority {}", m.priority));
    }
    // Colours added after the fixed line existed show only where a scene uses them.
    let default = Material::default();
    for row in crate::properties::MATERIAL_COLORS {
        let value = (row.get)(m);
        if row.shown == crate::properties::Shown::WhenSet && value != (row.get)(&default) {
            fields.push_str(&format!(" {} {}", row.name, color(&value)));
        }
    }
    fields
}

fn print_object(scene: &Scene, handle: Handle<Object>, depth: usize, out: &mut String) {
    let object = &scene.objects[handle];
    let indent = "  ".repeat(depth);
    let name = scene
        .name_of(object)
        .map(|n| format!(" {n:?}"))
        .unwrap_or_default();
    let what = match &object.kind {
        ObjectKind::Shape { shape } => shape_text(scene, &shape.get()),
        ObjectKind::Csg { op, .. } => op.name().to_string(),
        ObjectKind::Group { .. } => "group".to_string(),
    };
    let location = scene.sources.location(scene.objects.span(handle));
    // The instantiation stack, when the object was made inside an import, call or loop.
    let stack = scene.provenance.describe(handle, &scene.sources);
    let made_by = if stack.is_empty() {
        String::new()
    } else {
        format!("  made by {stack}")
    };
    let _ = writeln!(
        out,
        "{indent}object {handle}{name} {what} material {}{}  @ {location}{made_by}",
        object.material,
        matrix_suffix(&object.world_from_object)
    );
    if let ObjectKind::Csg { children, .. } | ObjectKind::Group { children } = &object.kind {
        for &child in children {
            print_object(scene, child, depth + 1, out);
        }
    }
}

/// The word the scene language uses for a setting's value (`opaque`, `checker`): its
/// serde name, which is that word.
fn word<T: serde::Serialize>(value: &T) -> String {
    serde_json::to_value(value)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

fn shape_text(scene: &Scene, shape: &Shape) -> String {
    match shape {
        Shape::Sphere { center, radius } => format!("sphere center {} radius {radius}", v(*center)),
        Shape::Plane { normal, offset } => format!("plane normal {} offset {offset}", v(*normal)),
        Shape::Box { min, max } => format!("box min {} max {}", v(*min), v(*max)),
        Shape::Cylinder {
            base,
            apex,
            radius,
            capped,
        } => {
            format!(
                "cylinder {} to {} radius {radius}{}",
                v(*base),
                v(*apex),
                if *capped { "" } else { " open" }
            )
        }
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            capped,
        } => format!(
            "cone {} radius {base_radius} to {} radius {apex_radius}{}",
            v(*base),
            v(*apex),
            if *capped { "" } else { " open" }
        ),
        Shape::Disk {
            center,
            normal,
            radius,
        } => format!(
            "disk center {} normal {} radius {radius}",
            v(*center),
            v(*normal)
        ),
        Shape::Triangle { a, b, c } => format!("triangle {} {} {}", v(*a), v(*b), v(*c)),
        Shape::Torus { major, minor } => format!("torus major {major} minor {minor}"),
        Shape::Mesh { mesh, smooth } => {
            // Smooth shading interpolates the file's vertex normals, or normals worked out
            // from the faces when the file has none: say which.
            let computed = scene
                .meshes
                .get(*mesh)
                .is_some_and(|m| m.normals.is_empty());
            let shading = match (smooth, computed) {
                (true, false) => " smooth",
                (true, true) => " smooth (normals computed from the faces)",
                (false, _) => "",
            };
            format!("mesh {mesh}{shading}")
        }
        Shape::Quadric { quadric, .. } => {
            let c = quadric.coefficients();
            let list: Vec<String> = c.iter().map(|x| x.to_string()).collect();
            format!("{} [{}]", shape.kind_name(), list.join(", "))
        }
    }
}

fn v(p: DVec3) -> String {
    format!("<{}, {}, {}>", p.x, p.y, p.z)
}

fn color(c: &Color) -> String {
    format!("rgb({}, {}, {})", c.r, c.g, c.b)
}

/// Nothing for the identity; otherwise the matrix rows, so the dump stays short.
fn matrix_suffix(m: &DMat4) -> String {
    if *m == DMat4::IDENTITY {
        return String::new();
    }
    let rows: Vec<String> = (0..4)
        .map(|r| {
            let row = m.row(r);
            format!("[{} {} {} {}]", row.x, row.y, row.z, row.w)
        })
        .collect();
    format!(" transform {}", rows.join(" "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Light, LightKind};

    #[test]
    fn names_with_control_characters_are_printed_escaped() {
        // Issue 10: `whitted ir` printed an ESC from a light's name raw to the terminal.
        let mut scene = Scene::default();
        scene.lights.append(
            Light {
                name: Some("red\u{1b}[31m\u{7}ça".to_string()),
                color: crate::Color::WHITE,
                kind: LightKind::Directional {
                    direction: glam::DVec3::NEG_Y,
                },
            },
            crate::Span::detached(),
        );
        let text = print(&scene);
        assert!(
            !text.contains('\u{1b}') && !text.contains('\u{7}'),
            "{text:?}"
        );
        assert!(text.contains("\"red\\u{1b}[31m\\u{7}ça\""), "{text}");
    }

    /// A colour shown only when set (`emission`) leaves the default material's line as it
    /// always was, and appears after it once a scene sets it.
    #[test]
    fn colours_shown_when_set_appear_only_when_set() {
        let plain = material_fields(&Material::default());
        assert!(!plain.contains("emission"), "{plain}");
        assert!(plain.ends_with("absorption rgb(0, 0, 0)"), "{plain}");
        let glowing = Material {
            emission: crate::Color::new(1.0, 0.5, 0.25),
            ..Material::default()
        };
        let text = material_fields(&glowing);
        assert_eq!(text, format!("{plain} emission rgb(1, 0.5, 0.25)"));
    }
}
