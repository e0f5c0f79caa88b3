//! For tests: scenes/provenance (three rings of beads made by `ring` from
//! scenes/provenance/lib.scene, called in a loop) built by hand in the IR with its
//! instantiation stacks, as the language would compile it, since the debugger must not
//! depend on the language.

use whitted_ir::{
    validate, ArgValue, Attenuation, Camera, Color, DMat4, DVec3, Light, LightKind, Material,
    Object, ObjectKind, Projection, Scene, Shape, Site, SiteKind, SourceFile, Span, ValidScene,
};

pub const MAIN_PATH: &str = "scenes/provenance/main.scene";
pub const LIB_PATH: &str = "scenes/provenance/lib.scene";
pub const MAIN_TEXT: &str = include_str!("../../../scenes/provenance/main.scene");
pub const LIB_TEXT: &str = include_str!("../../../scenes/provenance/lib.scene");

/// The pixel (at the scene's 64x48) that sees bead 7 of the middle ring (k = 1).
pub const BEAD_PIXEL: (u32, u32) = (38, 27);

/// The span of the first occurrence of `what` in `text`.
fn find(file: whitted_ir::FileId, text: &str, what: &str) -> Span {
    let start = text.find(what).expect("the text is in the file");
    Span::new(file, start, start + what.len())
}

/// The span from `start` to the end of its block (its matching closing brace).
fn item(file: whitted_ir::FileId, text: &str, start: &str) -> Span {
    let begin = text.find(start).expect("the item is in the file");
    let mut depth = 0;
    for (offset, c) in text[begin..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return Span::new(file, begin, begin + offset + 1);
                }
            }
            _ => {}
        }
    }
    Span::new(file, begin, text.len())
}

pub fn provenance_scene() -> ValidScene {
    let mut scene = Scene::default();
    let main = scene.sources.add(SourceFile::new(MAIN_PATH, MAIN_TEXT));
    let lib = scene.sources.add(SourceFile::new(LIB_PATH, LIB_TEXT));
    scene.settings.width = 64;
    scene.settings.height = 48;
    scene.settings.background = Color::new(16.0 / 255.0, 16.0 / 255.0, 24.0 / 255.0);
    scene.camera = Camera {
        eye: DVec3::new(0.0, 0.0, -14.0),
        look_at: DVec3::ZERO,
        up: DVec3::Y,
        projection: Projection::Perspective {
            vertical_fov_degrees: 50.0,
        },
    };
    scene.camera_span = item(main, MAIN_TEXT, "camera perspective");
    scene.lights.append(
        Light {
            name: Some("key".into()),
            color: Color::WHITE,
            kind: LightKind::Point {
                position: DVec3::new(-5.0, 8.0, -12.0),
                attenuation: Attenuation::NONE,
            },
        },
        find(main, MAIN_TEXT, "light point \"key\""),
    );
    let red = scene.materials.append(
        Material {
            name: Some("ring_red".into()),
            diffuse: Color::new(0.8, 0.2, 0.2),
            specular: Color::gray(0.4),
            shininess: 30.0,
            ..Material::default()
        },
        item(lib, LIB_TEXT, "material ring_red"),
    );
    let site = |kind, span, name: &str, params: &[&str]| Site {
        kind,
        span,
        name: name.into(),
        params: params.iter().map(|p| p.to_string()).collect(),
    };
    let provenance = &mut scene.provenance;
    let k_site = provenance.add_site(site(
        SiteKind::Loop,
        item(main, MAIN_TEXT, "for k in"),
        "k",
        &[],
    ));
    let call_site = provenance.add_site(site(
        SiteKind::Call,
        find(main, MAIN_TEXT, "ring(12, 2)"),
        "ring",
        &["n", "r"],
    ));
    let import_site = provenance.add_site(site(
        SiteKind::Import,
        find(main, MAIN_TEXT, "import \"lib.scene\""),
        "",
        &[],
    ));
    let i_site = provenance.add_site(site(
        SiteKind::Loop,
        item(lib, LIB_TEXT, "for i in"),
        "i",
        &[],
    ));
    let bead_span = find(lib, LIB_TEXT, "sphere \"bead {i}\"");
    for k in 0..3 {
        let provenance = &mut scene.provenance;
        let k_frame = provenance.push_loop(None, k_site, f64::from(k));
        let call = provenance.push_call(
            Some(k_frame),
            call_site,
            [ArgValue::Number(12.0), ArgValue::Number(2.0)],
        );
        let imported = provenance.push_import(Some(call), import_site);
        let world_from_object =
            DMat4::from_translation(DVec3::new(f64::from(k - 1) * 5.0, 0.0, 0.0));
        for i in 0..12 {
            let angle = (f64::from(i) * 360.0 / 12.0).to_radians();
            let handle = scene.objects.append(
                Object {
                    name: scene.object_names.add(&format!("bead {i}")),
                    kind: ObjectKind::Shape {
                        shape: Shape::Sphere {
                            center: DVec3::new(2.0 * angle.cos(), 2.0 * angle.sin(), 0.0),
                            radius: 0.35,
                        }
                        .into(),
                    },
                    world_from_object: world_from_object.into(),
                    material: red,
                },
                bead_span,
            );
            let frame = scene
                .provenance
                .push_loop(Some(imported), i_site, f64::from(i));
            scene.provenance.set_object(handle, Some(frame));
            scene.roots.push(handle);
        }
    }
    validate(scene).expect("the hand-built scene is valid")
}
