//! Ray trees recorded in-process from the real scenes: the tree's colour is the rendered
//! pixel bit for bit on every feature scene, the glass sphere's refraction shows in the
//! tree, and the text form is pinned by snapshots.

use std::path::{Path, PathBuf};

use whitted_ir::ValidScene;
use whitted_lang::{compile_file, CompileOptions, SourceLoader};
use whitted_tracer::ray_tree::{
    format_text, trace_pixel, RayNode, RayTree, SampleChoice, ShadowOutcome, TextOptions,
    Visibility,
};
use whitted_tracer::{render, NoObserver, PreparedScene, RayKind, RenderOptions, Termination};

struct FileLoader;

impl SourceLoader for FileLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        std::fs::read(path)
    }
}

impl whitted_mit6837::MeshLoader for FileLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>> {
        std::fs::read(path)
    }
}

/// A compiled and prepared scene; paths are relative to the workspace, as users type them.
pub struct Loaded {
    pub scene: ValidScene,
    pub prepared: PreparedScene,
}

/// Compiles a scene with the front end its content calls for. A 6.837 scene gets the
/// course's defaults (no shadow rays, back faces unlit, attenuation unclamped) with five
/// bounces, so that its reflections and refractions are traced too.
pub fn load(path: &str) -> Loaded {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let (scene, diagnostics) = if whitted_mit6837::is_mit6837(&bytes) {
        let options = whitted_mit6837::CourseOptions {
            bounces: 5,
            weight: 0.01,
            ..whitted_mit6837::CourseOptions::default()
        };
        let conversion =
            whitted_mit6837::convert(Path::new(path), bytes, &mut FileLoader, &options);
        (conversion.scene, conversion.diagnostics)
    } else {
        let compilation =
            compile_file(Path::new(path), &mut FileLoader, &CompileOptions::default());
        (compilation.scene, compilation.diagnostics)
    };
    let Some(scene) = scene else {
        panic!("{path} does not compile: {diagnostics:?}");
    };
    let prepared = PreparedScene::new(&scene);
    Loaded { scene, prepared }
}

/// The feature scenes (scenes/*.scene, not the benchmarks, and the 6.837 scenes in
/// scenes/mit6837/), sorted.
pub fn feature_scenes() -> Vec<PathBuf> {
    let listed = |dir: &str, extension: &str| -> Vec<PathBuf> {
        std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{dir}: {e}"))
            .filter_map(|entry| entry.ok().map(|e| e.path()))
            .filter(|path| path.extension().is_some_and(|e| e == extension))
            .collect()
    };
    let mut scenes = listed("scenes", "scene");
    scenes.extend(listed("scenes/mit6837", "txt"));
    scenes.sort();
    scenes
}

fn options_at(loaded: &Loaded, width: u32, height: u32) -> RenderOptions {
    RenderOptions {
        width,
        height,
        ..RenderOptions::from_settings(&loaded.scene.settings)
    }
}

fn tree(loaded: &Loaded, options: &RenderOptions, x: u32, y: u32, which: SampleChoice) -> RayTree {
    trace_pixel(&loaded.prepared, &loaded.scene, options, x, y, which)
        .unwrap_or_else(|error| panic!("{error}"))
}

fn bits(color: [f32; 3]) -> [u32; 3] {
    color.map(f32::to_bits)
}

fn walk(node: &RayNode) -> Vec<&RayNode> {
    let mut nodes = vec![node];
    let mut i = 0;
    while i < nodes.len() {
        let next = nodes[i];
        nodes.extend(next.children.iter());
        i += 1;
    }
    nodes
}

#[test]
fn on_every_scene_the_tree_colour_is_the_rendered_pixel_bit_for_bit() {
    let scenes = feature_scenes();
    assert!(
        scenes.len() >= 15,
        "expected the feature scenes, found {}",
        scenes.len()
    );
    let (width, height) = (64, 48);
    for path in scenes {
        let name = path.display().to_string();
        let loaded = load(&name);
        let options = options_at(&loaded, width, height);
        let Some((image, _)) = render(&loaded.prepared, &options, &NoObserver) else {
            panic!("{name}: the render was cancelled");
        };
        let xs = (0..width).step_by(5).chain([width - 1]);
        let mut checked = 0;
        for x in xs {
            for y in (0..height).step_by(5).chain([height - 1]) {
                let tree = tree(&loaded, &options, x, y, SampleChoice::All);
                let rendered = image.pixel(x, y).unwrap_or([f32::NAN; 3]);
                assert_eq!(bits(tree.color), bits(rendered), "{name} pixel ({x}, {y})");
                assert_eq!(
                    tree.samples.len(),
                    options.samples_per_pixel.max(1) as usize
                );
                for sample in &tree.samples {
                    assert_eq!(bits(sample.color), bits(sample.root.color), "{name}");
                }
                checked += 1;
            }
        }
        assert_eq!(checked, 14 * 11, "{name}");
    }
}

#[test]
fn the_glass_sphere_refracts_in_and_out_and_shadow_rays_name_their_blocker() {
    let loaded = load("scenes/whitted.scene");
    let options = RenderOptions::from_settings(&loaded.scene.settings);
    assert_eq!((options.width, options.height), (640, 480));
    let tree = tree(&loaded, &options, 400, 270, SampleChoice::All);
    let root = &tree.samples[0].root;
    let hit = root.hit.as_ref().expect("the camera ray hits");
    assert_eq!(hit.object.label, "glass sphere");
    assert_eq!(hit.object.location, "scenes/whitted.scene:20:1");
    assert_eq!(hit.material.label, "glass");

    let into = root
        .child(RayKind::Transmitted)
        .expect("refraction into the glass");
    let interface = into.interface.as_ref().expect("an interface");
    assert!(interface.entering);
    assert_eq!(interface.ior, Some([1.0, 1.5]));
    let inside = into.hit.as_ref().expect("the ray meets the far side");
    assert_eq!(inside.object.label, "glass sphere");
    assert!(!inside.front_face);

    // Leaving the glass again (or totally reflected inside it).
    let out = into.child(RayKind::Transmitted);
    let tir = into.interface.as_ref().is_some_and(|_| {
        into.skipped
            .iter()
            .any(|s| s.reason == Termination::TotalInternalReflection)
    });
    match out {
        Some(out) => {
            let interface = out.interface.as_ref().expect("an interface");
            assert!(!interface.entering);
            assert_eq!(interface.ior, Some([1.5, 1.0]));
            assert_eq!(out.depth, 2);
        }
        None => assert!(
            tir,
            "neither an exit nor total internal reflection: {into:#?}"
        ),
    }

    // Every shadow ray says what it found, and a blocked one names the blocker.
    let shadows: Vec<&RayNode> = walk(root)
        .into_iter()
        .filter(|n| n.kind == RayKind::Shadow)
        .collect();
    assert!(!shadows.is_empty());
    let mut blocked = 0;
    for shadow in shadows {
        let info = shadow.shadow.as_ref().expect("shadow info");
        assert_eq!(info.light.label, "sun");
        if info.result == ShadowOutcome::Blocked {
            let blocker = info.blocker.as_ref().expect("a blocker");
            assert!(blocker.t > 0.0);
            assert!(!blocker.object.label.is_empty());
            blocked += 1;
        }
    }
    assert!(
        blocked > 0,
        "the light inside the glass is blocked by the sphere itself"
    );
    let lights = &into.local.as_ref().expect("local illumination").lights;
    assert_eq!(lights[0].visibility, Visibility::Blocked);
}

#[test]
fn total_internal_reflection_inside_the_glass_cube_is_recorded() {
    let loaded = load("scenes/tir.scene");
    let options = options_at(&loaded, 48, 36);
    let tree = tree(&loaded, &options, 21, 24, SampleChoice::All);
    let nodes = walk(&tree.samples[0].root);
    let trapped = nodes
        .iter()
        .find(|n| {
            n.skipped.iter().any(|s| {
                s.kind == RayKind::Transmitted && s.reason == Termination::TotalInternalReflection
            })
        })
        .expect("a ray that could not leave the glass");
    // Its reflected child carries the whole transmitted weight, marked as TIR.
    let reflected = trapped
        .child(RayKind::Reflected)
        .expect("the reflected ray");
    let interface = reflected.interface.as_ref().expect("an interface");
    assert!(interface.total_internal_reflection);
    assert!(!interface.entering);
    assert_eq!(interface.ior, Some([1.5, 1.0]));
}

fn snapshot(name: &str, text: String) {
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!(name, text);
    });
}

fn text_of(path: &str, size: Option<(u32, u32)>, x: u32, y: u32, which: SampleChoice) -> String {
    let loaded = load(path);
    let options = match size {
        Some((width, height)) => options_at(&loaded, width, height),
        None => RenderOptions::from_settings(&loaded.scene.settings),
    };
    format_text(
        &tree(&loaded, &options, x, y, which),
        TextOptions::default(),
    )
}

#[test]
fn text_of_the_glass_sphere_pixel() {
    snapshot(
        "trace_whitted_glass",
        text_of("scenes/whitted.scene", None, 400, 270, SampleChoice::All),
    );
}

#[test]
fn text_of_a_csg_cut_with_its_leaf_and_operations() {
    snapshot(
        "trace_csg_difference",
        text_of(
            "scenes/csg-difference.scene",
            Some((48, 36)),
            22,
            16,
            SampleChoice::All,
        ),
    );
}

#[test]
fn text_of_total_internal_reflection() {
    snapshot(
        "trace_tir",
        text_of(
            "scenes/tir.scene",
            Some((48, 36)),
            21,
            24,
            SampleChoice::All,
        ),
    );
}

#[test]
fn text_of_a_filtered_shadow() {
    snapshot(
        "trace_filtered_shadow",
        text_of(
            "scenes/transparent-shadows.scene",
            Some((48, 32)),
            27,
            18,
            SampleChoice::All,
        ),
    );
}

#[test]
fn text_of_one_sample_of_many() {
    snapshot(
        "trace_one_sample",
        text_of(
            "scenes/antialiasing.scene",
            Some((48, 32)),
            24,
            12,
            SampleChoice::One(5),
        ),
    );
}

/// A spot light whose cone misses the point, and lights behind the surface, each say so in
/// their own words (issue 26): a floor pixel outside the blue spot's cone (the others lit),
/// and a pixel low on the ball that faces away from all three.
#[test]
fn text_of_a_spot_cone_that_misses_and_lights_that_face_away() {
    snapshot(
        "trace_spot_outside_cone",
        text_of(
            "scenes/spotlight.scene",
            Some((64, 48)),
            32,
            30,
            SampleChoice::All,
        ),
    );
    snapshot(
        "trace_spot_facing_away",
        text_of(
            "scenes/spotlight.scene",
            Some((64, 48)),
            32,
            23,
            SampleChoice::All,
        ),
    );
}

/// The same two pixels' light entries in the JSON form: the visibility words and the cone.
#[test]
fn json_of_a_spot_cone_that_misses_and_lights_that_face_away() {
    let loaded = load("scenes/spotlight.scene");
    let options = options_at(&loaded, 64, 48);
    let mut lights = Vec::new();
    for (x, y) in [(32, 30), (32, 23)] {
        let tree = tree(&loaded, &options, x, y, SampleChoice::All);
        let local = tree.samples[0].root.local.clone().expect("a hit");
        for light in local.lights {
            lights.push(serde_json::json!({
                "pixel": [x, y],
                "light": light.light.label,
                "n_dot_l": light.n_dot_l,
                "spot": light.spot,
                "cone": light.cone,
                "visibility": light.visibility,
                "shadow_child": light.shadow_child,
            }));
        }
    }
    let text = serde_json::to_string_pretty(&lights).expect("JSON");
    snapshot("trace_spot_lights_json", text);
}

/// The text between the first fence that starts with `opening` and the next fence.
fn fenced_block<'a>(doc: &'a str, opening: &str, after: &str) -> &'a str {
    let from = doc.find(after).expect("the anchor text") + after.len();
    let start = from + doc[from..].find(opening).expect("an opening fence") + opening.len();
    let end = start + doc[start..].find("```").expect("a closing fence");
    &doc[start..end]
}

#[test]
fn the_examples_in_the_documentation_are_real_output() {
    let doc = std::fs::read_to_string("docs/ray-tree.md").expect("docs/ray-tree.md");
    let stale =
        "docs/ray-tree.md is out of date: paste the output of the command above the example";

    let text = fenced_block(
        &doc,
        "```\n",
        "`whitted trace scenes/tir.scene --width 48 --height 36 --pixel 21,24`:",
    );
    let expected = text_of(
        "scenes/tir.scene",
        Some((48, 36)),
        21,
        24,
        SampleChoice::All,
    );
    assert_eq!(text, expected, "{stale}");

    let json = fenced_block(&doc, "```json\n", "--pixel 27,18 --json`");
    let documented: serde_json::Value = serde_json::from_str(json).expect("the example is JSON");
    let loaded = load("scenes/transparent-shadows.scene");
    let tree = tree(
        &loaded,
        &options_at(&loaded, 48, 32),
        27,
        18,
        SampleChoice::All,
    );
    // Through text, as the CLI does: f32 values print in their shortest form.
    let printed = serde_json::to_string(&tree.document()).expect("the document serialises");
    let actual: serde_json::Value = serde_json::from_str(&printed).expect("it reads back");
    assert_eq!(documented, actual, "{stale}");
}
