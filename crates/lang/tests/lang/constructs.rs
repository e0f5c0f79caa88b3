//! Every construct of the language, compiled and checked against the IR it must produce:
//! exact values where arithmetic is involved, IR-dump snapshots for the shape of the output.

use whitted_ir::{
    Color, CsgOp, DMat4, DVec3, Fresnel, LightKind, ObjectKind, PatternKind, Projection,
    QuadricForm, Severity, ShadowMode, Shape,
};
use whitted_lang::CompileOptions;

use crate::support::*;

fn close(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-12
}

// ---- comments, literals and values ---------------------------------------------------------

#[test]
fn comments_numbers_booleans_and_vectors() {
    let scene = scene(
        "// line comment\n/* block\n comment */ sphere { center <1.5, -2, .5> radius 1e-1 } // end",
    );
    assert_eq!(first_center(&scene), DVec3::new(1.5, -2.0, 0.5));
    assert_eq!(number("2.5e2"), 250.0);
    assert!(boolean("true") && !boolean("false"));
}

#[test]
fn colours_rgb_hex_srgb_and_names() {
    assert_eq!(vector("rgb(1, 0.5, 0)"), DVec3::new(1.0, 0.5, 0.0));
    assert_eq!(vector("#ffffff"), DVec3::ONE);
    assert_eq!(vector("#000000"), DVec3::ZERO);
    // sRGB 0x80 is about 0.2158 in linear light.
    assert!((vector("#808080").x - 0.21586).abs() < 1e-4);
    assert!((vector("srgb(0.5, 0.5, 0.5)").y - 0.21404).abs() < 1e-4);
    assert_eq!(vector("red"), DVec3::X);
    assert_eq!(vector("gray"), DVec3::splat(0.5));
    assert_eq!(vector("0.5 * white + blue"), DVec3::new(0.5, 0.5, 1.5));
    assert_eq!(vector("<1, 2, 3>").z, number("<1, 2, 3>.b"));
}

// ---- expressions ---------------------------------------------------------------------------

#[test]
fn arithmetic_follows_precedence() {
    assert_eq!(number("2 + 3 * 4"), 14.0);
    assert_eq!(number("(2 + 3) * 4"), 20.0);
    assert_eq!(number("10 - 4 - 3"), 3.0);
    assert_eq!(number("12 / 3 / 2"), 2.0);
    assert_eq!(number("-2 * -3"), 6.0);
    assert_eq!(number("7 % 3"), 1.0);
    assert_eq!(number("-1 % 3"), 2.0);
    assert_eq!(number("-(1 + 2)"), -3.0);
}

#[test]
fn vector_arithmetic_and_components() {
    assert_eq!(vector("<1, 2, 3> + <1, 1, 1>"), DVec3::new(2.0, 3.0, 4.0));
    assert_eq!(vector("<1, 2, 3> - <1, 1, 1>"), DVec3::new(0.0, 1.0, 2.0));
    assert_eq!(vector("2 * <1, 2, 3>"), DVec3::new(2.0, 4.0, 6.0));
    assert_eq!(vector("<1, 2, 3> * <2, 2, 0>"), DVec3::new(2.0, 4.0, 0.0));
    assert_eq!(vector("<2, 4, 6> / 2"), DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(vector("-<1, 0, 0>"), DVec3::NEG_X);
    assert_eq!(number("<4, 5, 6>.y"), 5.0);
    assert_eq!(number("<4, 5, 6>.x + <4, 5, 6>.z"), 10.0);
    assert_eq!(number("rgb(0.1, 0.2, 0.3).g"), 0.2);
}

#[test]
fn comparisons_and_boolean_logic() {
    assert!(boolean("1 < 2") && boolean("2 <= 2") && boolean("3 > 2") && boolean("3 >= 3"));
    assert!(boolean("1 == 1") && boolean("1 != 2") && !boolean("<1, 2, 3> == <1, 2, 4>"));
    assert!(boolean("true && !false") && boolean("false || true"));
    // Short-circuit: the right side would divide by zero.
    assert!(!boolean("false && 1 / 0 > 1"));
    assert!(boolean("true || 1 / 0 > 1"));
    assert!(boolean("1 + 1 == 2 && 2 * 2 > 3"));
}

#[test]
fn every_builtin_function() {
    let cases: &[(&str, f64)] = &[
        ("sqrt(16)", 4.0),
        ("pow(2, 10)", 1024.0),
        ("exp(0)", 1.0),
        ("log(1)", 0.0),
        ("sin(30)", 0.5),
        ("cos(60)", 0.5),
        ("tan(45)", 1.0),
        ("asin(1)", 90.0),
        ("acos(0)", 90.0),
        ("atan(1)", 45.0),
        ("atan2(1, 0)", 90.0),
        ("abs(-3)", 3.0),
        ("min(2, 3)", 2.0),
        ("max(2, 3)", 3.0),
        ("floor(2.7)", 2.0),
        ("ceil(2.1)", 3.0),
        ("round(2.5)", 3.0),
        ("clamp(5, 0, 1)", 1.0),
        ("radians(180)", std::f64::consts::PI),
        ("degrees(pi)", 180.0),
        ("dot(<1, 2, 3>, <4, 5, 6>)", 32.0),
        ("length(<3, 4, 0>)", 5.0),
        ("mix(10, 20, 0.25)", 12.5),
    ];
    for (expr, expected) in cases {
        let got = number(expr);
        assert!(
            (got - expected).abs() < 1e-12,
            "{expr} = {got}, expected {expected}"
        );
    }
    assert_eq!(vector("cross(<1, 0, 0>, <0, 1, 0>)"), DVec3::Z);
    assert!(close(
        vector("normalize(<0, 3, 4>)"),
        DVec3::new(0.0, 0.6, 0.8)
    ));
    assert_eq!(
        vector("mix(<0, 0, 0>, <2, 4, 6>, 0.5)"),
        DVec3::new(1.0, 2.0, 3.0)
    );
    assert_eq!(number("cos(90)"), 0.0);
}

// ---- names, control flow, functions ------------------------------------------------------

#[test]
fn let_bindings_and_block_scope() {
    let scene = scene(
        "let r = 0.5; let c = <1, 2, 3>;\n\
         for i in 0..1 { let r = 2; sphere { center c radius r } }\n\
         sphere { radius r }",
    );
    let radii: Vec<f64> = scene
        .objects
        .iter()
        .filter_map(|(_, o)| match o.kind.shape() {
            Some(Shape::Sphere { radius, .. }) => Some(radius),
            _ => None,
        })
        .collect();
    assert_eq!(radii, [2.0, 0.5]);
}

#[test]
fn for_loops_nest_and_ranges_include_or_exclude_the_end() {
    let scene = scene("for i in 0..3 { for j in 1..=2 { sphere { center <i, j, 0> } } } for k in 5..2 { box { } }");
    let centers: Vec<DVec3> = scene
        .objects
        .iter()
        .filter_map(|(_, o)| match o.kind.shape() {
            Some(Shape::Sphere { center, .. }) => Some(center),
            _ => None,
        })
        .collect();
    assert_eq!(centers.len(), 6);
    assert_eq!(centers[0], DVec3::new(0.0, 1.0, 0.0));
    assert_eq!(centers[5], DVec3::new(2.0, 2.0, 0.0));
    assert_eq!(scene.objects.len(), 6, "an empty range runs nothing");
}

#[test]
fn if_else_if_else_chooses_one_branch() {
    for (x, expected) in [(1, "sphere"), (2, "box"), (3, "cone")] {
        let scene = scene(&format!(
            "let x = {x}; if x == 1 {{ sphere {{ }} }} else if x == 2 {{ box {{ }} }} else {{ cone {{ }} }}"
        ));
        assert_eq!(scene.object_label(scene.roots[0]), format!("{expected} #0"));
    }
}

#[test]
fn functions_return_values_and_recurse() {
    let scene = scene(
        "fn lerp(a, b, t) { return a + (b - a) * t; }\n\
         fn fact(n) { if n <= 1 { return 1; } return n * fact(n - 1); }\n\
         sphere { center <lerp(2, 4, 0.25), fact(5), 0> }",
    );
    assert_eq!(first_center(&scene), DVec3::new(2.5, 120.0, 0.0));
}

#[test]
fn functions_make_objects_and_call_blocks_move_them() {
    check(
        "function_objects",
        "fn ring(n, radius) {\n\
         \x20   for i in 0..n { sphere { center <radius * cos(i * 360 / n), 0, radius * sin(i * 360 / n)> radius 0.1 } }\n\
         }\n\
         material gold { diffuse rgb(1, 0.75, 0.3) }\n\
         ring(4, 2) { material gold translate <0, 1, 0> }\n\
         ring(2, 1)\n",
    );
}

#[test]
fn functions_take_and_return_materials() {
    let scene = scene(
        "fn tint(c) { return material { diffuse c }; }\n\
         fn post(m) { cylinder { material m } }\n\
         post(tint(red))",
    );
    let object = &scene.objects[scene.roots[0]];
    assert_eq!(
        scene.materials[object.material].diffuse,
        Color::new(1.0, 0.0, 0.0)
    );
}

#[test]
fn imports_bring_names_and_objects_and_run_once() {
    let mut loader = MapLoader::with(&[
        ("lib/materials.scene", "material chrome { reflective 0.8 }\nlet size = 2;\n"),
        ("lib/shapes.scene", "import \"materials.scene\"\nfn ball() { sphere { radius size material chrome } }\nbox { }\n"),
    ]);
    let compilation = compile_with(
        "import \"lib/shapes.scene\"\nimport \"lib/materials.scene\"\nball()\n",
        &mut loader,
        &CompileOptions::default(),
    );
    let out = output(&compilation);
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!("imports", out);
    });
    let scene = compilation.scene.expect("compiles");
    assert_eq!(scene.roots.len(), 2, "the box runs once, then the ball");
    assert_eq!(scene.sources.files().len(), 3);
}

#[test]
fn constants_are_overridden_by_defines() {
    let options = CompileOptions {
        defines: vec![
            ("N".into(), "4".into()),
            ("C".into(), "rgb(0, 1, 0)".into()),
        ],
        ..CompileOptions::default()
    };
    let compilation = compile_with(
        "const N = 2;\nconst C = red;\nfor i in 0..N { sphere { center <i, 0, 0> material { diffuse C } } }",
        &mut MapLoader::default(),
        &options,
    );
    let scene = compilation.scene.expect("compiles");
    assert_eq!(scene.objects.len(), 4);
    assert_eq!(
        scene.materials[scene.objects[scene.roots[0]].material].diffuse,
        Color::new(0.0, 1.0, 0.0)
    );
    assert_eq!(
        compilation.sources.files().len(),
        3,
        "one pseudo-file per -D"
    );
}

// ---- settings, camera, lights --------------------------------------------------------------

#[test]
fn settings_set_every_field() {
    let scene = scene(
        "settings { width 320 height 200 max_depth 7 min_weight 0.01 samples 4\n\
         background rgb(0.1, 0.2, 0.6) ambient 0.5 epsilon 1e-3 shadows filtered }",
    );
    let s = &scene.settings;
    assert_eq!(
        (s.width, s.height, s.max_depth, s.samples_per_pixel),
        (320, 200, 7, 4)
    );
    assert_eq!((s.min_weight, s.epsilon), (0.01, Some(1e-3)));
    assert_eq!(s.background, Color::new(0.1, 0.2, 0.6));
    assert_eq!(s.ambient, Color::gray(0.5));
    assert_eq!(s.shadows, ShadowMode::Filtered);
    assert_eq!(
        super::support::scene("settings { shadows opaque }")
            .settings
            .shadows,
        ShadowMode::Opaque
    );
}

#[test]
fn cameras_perspective_and_orthographic() {
    let scene =
        scene("camera perspective { eye <0, 2, -6> look_at <0, 1, 0> up <0, 1, 0> fov 30 }");
    assert_eq!(scene.camera.eye, DVec3::new(0.0, 2.0, -6.0));
    assert_eq!(scene.camera.look_at, DVec3::Y);
    assert_eq!(
        scene.camera.projection,
        Projection::Perspective {
            vertical_fov_degrees: 30.0
        }
    );
    assert!(!scene.camera_span.is_detached());
    let ortho =
        super::support::scene("camera orthographic { eye <0, 0, -5> look_at <0, 0, 0> height 3 }");
    assert_eq!(
        ortho.camera.projection,
        Projection::Orthographic { view_height: 3.0 }
    );
    let none = super::support::scene("sphere { }");
    assert!(
        none.camera_span.is_detached(),
        "no camera: the default, with no span"
    );
}

#[test]
fn lights_point_directional_and_spot() {
    check(
        "lights",
        "light point \"key\" { position <5, 8, -5> color white attenuation <1, 0, 0.01> }\n\
         light directional { direction <-1, -1, 1> color 0.5 }\n\
         light spot \"torch\" { position <0, 5, 0> direction <0, -1, 0> inner 15 outer 25 color #ff8000 }\n\
         for i in 0..2 { light point { position <i, 1, 0> } }\n",
    );
    let scene = scene("light spot { position <0, 5, 0> direction <0, -1, 0> }");
    let (_, light) = scene.lights.iter().next().expect("a light");
    assert!(matches!(
        light.kind,
        LightKind::Spot {
            inner_angle_degrees: 20.0,
            outer_angle_degrees: 30.0,
            ..
        }
    ));
}

// ---- materials and patterns ----------------------------------------------------------------

#[test]
fn materials_set_every_field_and_inherit() {
    let scene = scene(
        "material glass { ambient 0.2 diffuse black specular 0.8 shininess 200 reflective 0.1\n\
         transmissive 0.9 ior 1.5 fresnel schlick absorption <0.3, 0.1, 0.1> }\n\
         material tinted : glass { absorption 0 ior 1.33 }\n\
         sphere { material tinted } sphere { material glass }",
    );
    let tinted = &scene.materials[scene.objects[scene.roots[0]].material];
    assert_eq!(tinted.name.as_deref(), Some("tinted"));
    assert_eq!(tinted.ambient, Color::gray(0.2));
    assert_eq!(tinted.diffuse, Color::BLACK);
    assert_eq!(tinted.specular, Color::gray(0.8));
    assert_eq!((tinted.shininess, tinted.ior), (200.0, 1.33));
    assert_eq!(tinted.reflective, Color::gray(0.1));
    assert_eq!(tinted.transmissive, Color::gray(0.9));
    assert_eq!(tinted.fresnel, Fresnel::Schlick);
    assert_eq!(tinted.absorption, Color::BLACK);
    let glass = &scene.materials[scene.objects[scene.roots[1]].material];
    assert_eq!(glass.absorption, Color::new(0.3, 0.1, 0.1));
}

#[test]
fn exact_fresnel_and_priority_are_material_properties() {
    let scene = scene(
        "material glass { transmissive 1 ior 1.5 fresnel exact priority 2 }\n\
         material water : glass { ior 1.33 priority 1 }\n\
         sphere { material water } sphere { material glass } sphere { }",
    );
    let material = |i: usize| &scene.materials[scene.objects[scene.roots[i]].material];
    assert_eq!(
        (material(0).fresnel, material(0).priority),
        (Fresnel::Exact, 1)
    );
    assert_eq!(
        (material(1).fresnel, material(1).priority),
        (Fresnel::Exact, 2)
    );
    // The default: a plain solid.
    assert_eq!(
        (material(2).fresnel, material(2).priority),
        (Fresnel::Off, 0)
    );
}

#[test]
fn inline_materials_new_and_derived() {
    check(
        "inline_materials",
        "material glass { transmissive 0.9 ior 1.5 }\n\
         sphere \"red\" { material { diffuse red specular 0.5 } }\n\
         sphere \"water\" { material : glass { ior 1.33 } }\n\
         let m = material { diffuse blue };\n\
         box { material m }\n",
    );
}

#[test]
fn patterns_of_colours_and_of_materials() {
    check(
        "patterns",
        "material floor { diffuse checker(white, #202020, 2) { rotate <0, 45, 0> } ambient 0.1 }\n\
         material mirror { reflective 0.8 }\n\
         material matte { diffuse red }\n\
         material zebra { diffuse stripes(mirror, matte) }\n\
         plane { material floor }\n\
         sphere { material zebra }\n",
    );
    let scene = scene(
        "material floor { diffuse checker(white, black, 2) { scale 2 translate <1, 0, 0> } }\n\
         material child : floor { ambient 0.3 }\n\
         plane { material child }",
    );
    let m = &scene.materials[scene.objects[scene.roots[0]].material];
    let pattern = m.pattern.as_ref().expect("a pattern, inherited");
    assert_eq!(pattern.kind, PatternKind::Checker);
    assert_eq!(pattern.scale, 2.0);
    // The block places the pattern: scale 2 then move 1, so pattern space is the inverse.
    let p = pattern
        .pattern_from_object
        .transform_point3(DVec3::new(3.0, 2.0, 0.0));
    assert!(close(p, DVec3::new(1.0, 1.0, 0.0)), "{p}");
    // Each colour became a derived material with the child's ambient.
    assert_eq!(scene.materials[pattern.a].diffuse, Color::WHITE);
    assert_eq!(scene.materials[pattern.b].ambient, Color::gray(0.3));
}

// ---- shapes --------------------------------------------------------------------------------

#[test]
fn every_shape() {
    check(
        "shapes",
        "sphere \"ball\" { center <0, 1, 0> radius 1 }\n\
         plane { normal <0, 1, 0> offset -1 }\n\
         box { min <-1, -1, -1> max <1, 2, 3> }\n\
         cylinder { base <0, 0, 0> apex <0, 2, 0> radius 0.5 }\n\
         cylinder { open }\n\
         cone { base <0, 0, 0> base_radius 1 apex <0, 2, 0> apex_radius 0.25 }\n\
         cone { open }\n\
         disk { center <0, 0, 0> normal <0, 0, 1> radius 2 }\n\
         triangle { vertices <0, 0, 0>, <1, 0, 0>, <0, 1, 0> }\n",
    );
    let scene = scene("cylinder { open } cylinder { }");
    let capped: Vec<bool> = scene
        .objects
        .iter()
        .map(|(_, o)| matches!(o.kind.shape(), Some(Shape::Cylinder { capped: true, .. })))
        .collect();
    assert_eq!(capped, [false, true]);
}

#[test]
fn quadrics_general_and_named() {
    let coefficients = |input: &str| -> (QuadricForm, [f64; 10]) {
        let scene = scene(input);
        match scene.objects[scene.roots[0]].kind.shape() {
            Some(Shape::Quadric { form, quadric }) => (form, quadric.coefficients()),
            other => panic!("not a quadric: {other:?}"),
        }
    };
    let unit = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
    assert_eq!(
        coefficients("quadric { coefficients 1, 1, 1, 0, 0, 0, 0, 0, 0, -1 }"),
        (QuadricForm::General, unit)
    );
    assert_eq!(
        coefficients("quadric { coefficients <1, 1, 1>, <0, 0, 0>, <0, 0, 0>, -1 }"),
        (QuadricForm::General, unit)
    );
    assert_eq!(
        coefficients("ellipsoid { radii <2, 1, 0.5> }"),
        (
            QuadricForm::Ellipsoid,
            [0.25, 1.0, 4.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0]
        )
    );
    assert_eq!(
        coefficients("paraboloid { radii <1, 2, 1> }"),
        (
            QuadricForm::EllipticParaboloid,
            [1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -0.5, 0.0, 0.0]
        )
    );
    assert_eq!(
        coefficients("hyperboloid { radii <1, 2, 1> }"),
        (
            QuadricForm::HyperboloidOneSheet,
            [1.0, -0.25, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0]
        )
    );
    assert_eq!(
        coefficients("hyperboloid2 { }"),
        (
            QuadricForm::HyperboloidTwoSheets,
            [1.0, -1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
        )
    );
    // The documented insides: negative at the centre of an ellipsoid and inside a
    // paraboloid's bowl; positive at the waist's centre of the two-sheet hyperboloid.
    let eval = |input: &str, p: DVec3| {
        let (_, c) = coefficients(input);
        whitted_ir::Quadric::from_coefficients(c).eval(p)
    };
    assert!(eval("ellipsoid { }", DVec3::ZERO) < 0.0);
    assert!(eval("paraboloid { }", DVec3::new(0.0, 1.0, 0.0)) < 0.0);
    assert!(eval("hyperboloid { }", DVec3::ZERO) < 0.0);
    assert!(eval("hyperboloid2 { }", DVec3::ZERO) > 0.0);
    assert!(eval("hyperboloid2 { }", DVec3::new(0.0, 2.0, 0.0)) < 0.0);
}

// ---- CSG, groups, transforms, material inheritance -----------------------------------------

#[test]
fn csg_nests_over_any_solid() {
    check(
        "csg",
        "difference \"die\" {\n\
         \x20   intersection { box { } sphere { radius 1.4 } }\n\
         \x20   union { cylinder { } quadric { coefficients 1, 1, 1, 0, 0, 0, 0, 0, 0, -1 } ellipsoid { } }\n\
         \x20   material { diffuse red }\n\
         }\n\
         group { disk { } triangle { vertices <0, 0, 0>, <1, 0, 0>, <0, 1, 0> } union { sphere { } } }\n",
    );
    let scene =
        scene("difference { sphere { } union { box { } intersection { sphere { } cone { } } } }");
    let root = &scene.objects[scene.roots[0]];
    assert!(
        matches!(&root.kind, ObjectKind::Csg { op: CsgOp::Difference, children } if children.len() == 2)
    );
    // Children come before parents in the arena.
    assert_eq!(scene.roots[0].index(), scene.objects.len() - 1);
}

#[test]
fn transforms_compose_in_the_order_written() {
    let center = |input: &str| {
        let scene = scene(input);
        let object = &scene.objects[scene.roots[0]];
        object.world_from_object.transform_point3(DVec3::ZERO)
    };
    assert!(close(
        center("sphere { scale 2 translate <1, 0, 0> }"),
        DVec3::X
    ));
    assert!(close(
        center("sphere { translate <1, 0, 0> scale 2 }"),
        DVec3::new(2.0, 0.0, 0.0)
    ));
    // Rotation about x first, then y: <0, 0, 1> → (x 90) → <0, -1, 0> → (y 90) → same.
    let scene = scene("sphere { rotate <90, 90, 0> }");
    let m = scene.objects[scene.roots[0]].world_from_object.matrix();
    assert!(close(m.transform_vector3(DVec3::Z), DVec3::NEG_Y));
    assert!(close(m.transform_vector3(DVec3::X), DVec3::NEG_Z));
    assert!(close(
        center("sphere { translate <1, 0, 0> rotate 90 about <0, 0, 1> }"),
        DVec3::Y
    ));
    assert!(close(
        center("sphere { matrix 1, 0, 0, 2,  0, 1, 0, 3,  0, 0, 1, 4,  0, 0, 0, 1 }"),
        DVec3::new(2.0, 3.0, 4.0)
    ));
    let scaled = scene_of("box { scale <1, 2, 3> }");
    assert_eq!(scaled, DMat4::from_scale(DVec3::new(1.0, 2.0, 3.0)));
}

fn scene_of(input: &str) -> DMat4 {
    let scene = scene(input);
    scene.objects[scene.roots[0]].world_from_object.matrix()
}

#[test]
fn a_childs_transforms_apply_before_its_parents() {
    let scene = scene(
        "group { union { sphere { translate <1, 0, 0> } rotate <0, 0, 90> } translate <0, 0, 5> }",
    );
    let sphere = scene
        .objects
        .iter()
        .find(|(_, o)| matches!(o.kind, ObjectKind::Shape { .. }))
        .map(|(_, o)| o.world_from_object.matrix())
        .expect("a sphere");
    assert!(close(
        sphere.transform_point3(DVec3::ZERO),
        DVec3::new(0.0, 1.0, 5.0)
    ));
    // A call block is a parent too.
    let scene = super::support::scene("fn f() { sphere { translate <1, 0, 0> } } f() { scale 3 }");
    let m = scene.objects[scene.roots[0]].world_from_object.matrix();
    assert!(close(
        m.transform_point3(DVec3::ZERO),
        DVec3::new(3.0, 0.0, 0.0)
    ));
}

#[test]
fn children_inherit_the_nearest_material_and_the_rest_get_the_default() {
    let compilation = compile(
        "material a { diffuse red }\nmaterial b { diffuse blue }\n\
         group { sphere { } sphere { material b } group { box { } } material a }\n\
         sphere { }\nfor i in 0..3 { box { } }",
    );
    let scene = compilation.scene.as_ref().expect("compiles");
    let label =
        |i: usize| scene.material_label(scene.objects[whitted_ir::Handle::from_index(i)].material);
    // sphere, sphere b, box (in the inner group), inner group, outer group, sphere, 3 boxes
    assert_eq!(label(0), "a");
    assert_eq!(label(1), "b");
    assert_eq!(label(2), "a");
    assert_eq!(label(5), "default");
    let notes: Vec<_> = compilation
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Note)
        .collect();
    assert_eq!(
        notes.len(),
        2,
        "one note per statement, not per object: {notes:?}"
    );
    let text = output(&compilation);
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!("default_material", text);
    });
}

#[test]
fn names_reach_objects_lights_and_materials() {
    let scene = scene(
        "material m { } light point \"key\" { position <0, 1, 0> } sphere \"ball\" { material m }",
    );
    assert_eq!(scene.object_label(scene.roots[0]), "ball");
    assert_eq!(
        scene.material_label(scene.objects[scene.roots[0]].material),
        "m"
    );
    assert_eq!(
        scene
            .lights
            .iter()
            .next()
            .and_then(|(_, l)| l.name.clone())
            .as_deref(),
        Some("key")
    );
}

#[test]
fn spans_point_at_the_statement_that_made_each_node() {
    let compilation = compile("material m { }\n\nfn f() {\n  sphere \"s\" { material m }\n}\nf()\nlight point { position <0, 1, 0> }\n");
    let scene = compilation.scene.expect("compiles");
    let location = |span| scene.sources.location(span);
    assert_eq!(
        location(scene.objects.span(scene.roots[0])),
        "test.scene:4:3"
    );
    assert_eq!(
        location(scene.materials.span(scene.objects[scene.roots[0]].material)),
        "test.scene:1:1"
    );
    assert_eq!(
        location(scene.lights.span(whitted_ir::Handle::from_index(0))),
        "test.scene:7:1"
    );
}
