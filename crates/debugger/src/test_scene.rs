//! For tests: Whitted's scene (a copy of scenes/whitted.scene) built by hand in the IR, with
//! real spans into its source text, since the debugger must not depend on the language.

use std::sync::Arc;

use whitted_ir::{
    validate, Attenuation, BlockKind, Camera, Color, DMat4, DVec3, FileId, Handle, Light,
    LightKind, Material, Object, ObjectKind, Pattern, PatternKind, Projection, Scene, Shape,
    SourceFile, Span, ValidScene, WrittenBlock, WrittenProperty,
};
use whitted_tracer::ray_tree::{trace_pixel, RayTree, SampleChoice};
use whitted_tracer::{PreparedScene, RenderOptions};

pub const SCENE_PATH: &str = "scenes/whitted.scene";

pub const SCENE_TEXT: &str = r#"// Whitted's 1980 picture: a glass sphere and a mirror sphere over a red and yellow
// checkerboard, under a blue sky. The README's default render.
// whitted's world is right-handed: looking along +z, +x is on the left of the image.
settings {
    width 640 height 480
    max_depth 5
    background rgb(0.10, 0.30, 0.75)
}
camera perspective { eye <0, 1.6, -6.5> look_at <0, 1, 0> fov 45 }
light point "sun" { position <-6, 10, -8> color white }

material floor_tiles { diffuse checker(rgb(0.9, 0.1, 0.1), rgb(0.95, 0.9, 0.2), 1) ambient 0.1 }
material glass {
    ambient 0 diffuse 0.05 specular 0.8 shininess 200
    reflective 0.1 transmissive 0.9 ior 1.5
}
material mirror { ambient 0.05 diffuse 0.1 specular 0.8 shininess 120 reflective 0.8 }

plane "floor" { normal <0, 1, 0> offset 0 material floor_tiles }
sphere "glass sphere" { center <-0.75, 1.1, -1.2> radius 1 material glass }
sphere "mirror sphere" { center <1.2, 1, 1.4> radius 1 material mirror }
"#;

/// The span of the item starting with `start`, up to its closing brace.
fn item_span(file: FileId, start: &str) -> Span {
    let begin = SCENE_TEXT.find(start).expect("the item is in the text");
    let mut depth = 0;
    let mut end = begin;
    for (offset, c) in SCENE_TEXT[begin..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    end = begin + offset + 1;
                    break;
                }
            }
            _ => {}
        }
    }
    Span::new(file, begin, end)
}

fn gray(value: f64) -> Color {
    Color::gray(value)
}

/// scenes/whitted.scene, as the language compiles it (`whitted ir scenes/whitted.scene`).
pub fn whitted_scene() -> ValidScene {
    let mut scene = Scene::default();
    let file = scene.sources.add(SourceFile::new(SCENE_PATH, SCENE_TEXT));
    scene.settings.width = 640;
    scene.settings.height = 480;
    scene.settings.max_depth = 5;
    scene.settings.background = Color::new(0.1, 0.3, 0.75);
    scene.camera = Camera {
        eye: DVec3::new(0.0, 1.6, -6.5),
        look_at: DVec3::new(0.0, 1.0, 0.0),
        up: DVec3::Y,
        projection: Projection::Perspective {
            vertical_fov_degrees: 45.0,
        },
    };
    scene.camera_span = item_span(file, "camera perspective");
    scene.lights.append(
        Light {
            name: Some("sun".into()),
            color: Color::WHITE,
            kind: LightKind::Point {
                position: DVec3::new(-6.0, 10.0, -8.0),
                attenuation: Attenuation::NONE,
            },
        },
        item_span(file, "light point"),
    );
    let floor_span = item_span(file, "material floor_tiles");
    let tile = |name: &str, diffuse: Color| Material {
        name: Some(name.into()),
        ambient: gray(0.1),
        diffuse,
        ..Material::default()
    };
    let a = scene
        .materials
        .append(tile("floor_tiles/a", Color::new(0.9, 0.1, 0.1)), floor_span);
    let b = scene.materials.append(
        tile("floor_tiles/b", Color::new(0.95, 0.9, 0.2)),
        floor_span,
    );
    let floor_tiles = scene.materials.append(
        Material {
            pattern: Some(Pattern {
                kind: PatternKind::Checker,
                a,
                b,
                scale: 1.0,
                pattern_from_object: DMat4::IDENTITY,
            }),
            ..tile("floor_tiles", gray(0.8))
        },
        floor_span,
    );
    let glass = scene.materials.append(
        Material {
            name: Some("glass".into()),
            ambient: gray(0.0),
            diffuse: gray(0.05),
            specular: gray(0.8),
            shininess: 200.0,
            reflective: gray(0.1),
            transmissive: gray(0.9),
            ior: 1.5,
            ..Material::default()
        },
        item_span(file, "material glass"),
    );
    let mirror = scene.materials.append(
        Material {
            name: Some("mirror".into()),
            ambient: gray(0.05),
            diffuse: gray(0.1),
            specular: gray(0.8),
            shininess: 120.0,
            reflective: gray(0.8),
            ..Material::default()
        },
        item_span(file, "material mirror"),
    );
    let mut object = |name: &str, shape: Shape, material, start: &str| {
        let handle = scene.objects.append(
            Object {
                name: scene.object_names.add(name),
                kind: ObjectKind::Shape {
                    shape: shape.into(),
                },
                world_from_object: DMat4::IDENTITY.into(),
                material,
            },
            item_span(file, start),
        );
        scene.roots.push(handle);
    };
    object(
        "floor",
        Shape::Plane {
            normal: DVec3::Y,
            offset: 0.0,
        },
        floor_tiles,
        "plane \"floor\"",
    );
    object(
        "glass sphere",
        Shape::Sphere {
            center: DVec3::new(-0.75, 1.1, -1.2),
            radius: 1.0,
        },
        glass,
        "sphere \"glass sphere\"",
    );
    object(
        "mirror sphere",
        Shape::Sphere {
            center: DVec3::new(1.2, 1.0, 1.4),
            radius: 1.0,
        },
        mirror,
        "sphere \"mirror sphere\"",
    );
    record_written(&mut scene, file);
    validate(scene).expect("the hand-built scene is valid")
}

/// The table of written properties, as the language fills it: each block (with the span
/// the arena keeps for what it made) and where each of its properties' names and values are.
fn record_written(scene: &mut Scene, file: FileId) {
    let settings_at = SCENE_TEXT.find("settings {").expect("settings");
    let settings = Span::new(file, settings_at, settings_at + "settings".len());
    let light = scene.lights.iter_with_spans().next().map(|(_, _, s)| s);
    let material = |name: &str| {
        scene
            .materials
            .iter_with_spans()
            .find(|(_, m, _)| m.name.as_deref() == Some(name))
            .map(|(_, _, span)| span)
    };
    let blocks = [
        (
            BlockKind::Settings,
            Some(settings),
            &[
                ("width", "640"),
                ("height", "480"),
                ("max_depth", "5"),
                ("background", "rgb(0.10, 0.30, 0.75)"),
            ][..],
        ),
        (
            BlockKind::Camera,
            Some(scene.camera_span),
            &[
                ("eye", "<0, 1.6, -6.5>"),
                ("look_at", "<0, 1, 0>"),
                ("fov", "45"),
            ][..],
        ),
        (
            BlockKind::Light,
            light,
            &[("position", "<-6, 10, -8>"), ("color", "white")][..],
        ),
        (
            BlockKind::Material,
            material("glass"),
            &[
                ("ambient", "0"),
                ("diffuse", "0.05"),
                ("specular", "0.8"),
                ("shininess", "200"),
                ("reflective", "0.1"),
                ("transmissive", "0.9"),
                ("ior", "1.5"),
            ][..],
        ),
        (
            BlockKind::Material,
            material("mirror"),
            &[
                ("ambient", "0.05"),
                ("diffuse", "0.1"),
                ("specular", "0.8"),
                ("shininess", "120"),
                ("reflective", "0.8"),
            ][..],
        ),
    ];
    for (kind, header, properties) in blocks {
        let header = header.expect("the block's span");
        let open =
            header.start as usize + SCENE_TEXT[header.start as usize..].find('{').expect("{");
        let close = open + SCENE_TEXT[open..].find('}').expect("}");
        let block = scene.written.add_block(WrittenBlock {
            kind,
            header,
            body: Span::new(file, open, close + 1),
        });
        for (name, value) in properties {
            let written = format!("{name} {value}");
            let at = open
                + SCENE_TEXT[open..close]
                    .find(&written)
                    .expect("written in the block");
            let value_at = at + name.len() + 1;
            scene.written.add_property(WrittenProperty {
                block,
                name,
                name_span: Span::new(file, at, at + name.len()),
                value_span: Span::new(file, value_at, value_at + value.len()),
            });
        }
    }
}

/// The scene with everything a test of the app needs.
pub struct Fixture {
    pub scene: Arc<ValidScene>,
    pub prepared: Arc<PreparedScene>,
    pub options: RenderOptions,
}

pub fn fixture() -> Fixture {
    let scene = whitted_scene();
    let prepared = PreparedScene::new(&scene);
    let options = RenderOptions::from_settings(&scene.settings);
    Fixture {
        scene: Arc::new(scene),
        prepared: Arc::new(prepared),
        options,
    }
}

/// A pixel on the glass sphere (right of centre: +x is on the image's left).
pub const GLASS_PIXEL: (u32, u32) = (400, 270);

/// The ray tree of [`GLASS_PIXEL`].
pub fn glass_pixel_tree() -> RayTree {
    let f = fixture();
    trace_pixel(
        &f.prepared,
        &f.scene,
        &f.options,
        GLASS_PIXEL.0,
        GLASS_PIXEL.1,
        SampleChoice::All,
    )
    .expect("the pixel is inside the image")
}

/// Runs the trace the app asked for on this thread and hands it the answer, then the
/// tree's explanation, as the event loop does with a worker thread.
pub fn finish_trace(app: &mut crate::app::App) {
    if let Some(job) = app.trace_job() {
        let traced = job.run();
        let tree = traced.result.as_ref().ok().map(|(tree, _)| tree.clone());
        app.apply_trace(traced);
        if let Some(tree) = tree {
            app.apply_explained(job.explain(&tree));
        }
    }
}

/// Whitted's scene inside a box of mirrors with the deepest recursion and no minimum weight:
/// every path bounces for ever and splits at the glass, so one pixel's trace runs away (the
/// tree is cut at its budget, but the rays go on being traced until cancelled).
pub fn hall_of_mirrors() -> ValidScene {
    let mut scene = whitted_scene().into_inner();
    scene.settings.max_depth = whitted_ir::limits::MAX_DEPTH;
    scene.settings.min_weight = 0.0;
    let span = scene.camera_span;
    let mirror = scene.materials.append(
        Material {
            name: Some("wall mirror".into()),
            reflective: gray(0.95),
            diffuse: gray(0.05),
            ..Material::default()
        },
        span,
    );
    let walls = [
        (DVec3::NEG_Y, -4.0),
        (DVec3::X, -4.0),
        (DVec3::NEG_X, -4.0),
        (DVec3::Z, -8.0),
        (DVec3::NEG_Z, -8.0),
    ];
    for (normal, offset) in walls {
        let handle = scene.objects.append(
            Object {
                name: None,
                kind: ObjectKind::Shape {
                    shape: Shape::Plane { normal, offset }.into(),
                },
                world_from_object: DMat4::IDENTITY.into(),
                material: mirror,
            },
            span,
        );
        scene.roots.push(handle);
    }
    validate(scene).expect("the hall of mirrors is valid")
}

/// The material called `name` in `scene`; panics (a test's failure) when there is none.
pub fn material_named(scene: &Scene, name: &str) -> Handle<Material> {
    match scene
        .materials
        .iter()
        .find(|(_, m)| m.name.as_deref() == Some(name))
    {
        Some((handle, _)) => handle,
        None => panic!("no material `{name}` in the test scene"),
    }
}

/// An app on Whitted's scene whose glass-sphere pixel has been picked and traced, as after
/// pressing Enter on it.
pub fn picked_app() -> crate::app::App {
    let mut app = crate::app::App::new(
        "scenes/whitted.scene".into(),
        crate::app::LoadedScene::new(whitted_scene()),
        ratatui::layout::Rect::new(0, 0, 120, 40),
        "/tmp/out".into(),
    );
    app.cursor = GLASS_PIXEL;
    crate::update::update(&mut app, crate::action::Action::TraceCursor);
    finish_trace(&mut app);
    app
}
