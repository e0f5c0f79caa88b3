//! One snapshot per family of errors, each case with its rendered diagnostic, so that every
//! class of error a user can meet is shown here exactly as they would see it.

use whitted_lang::{compile_file, CompileOptions, Limits};

use crate::support::*;

#[test]
fn syntax_errors() {
    check_errors(
        "syntax_errors",
        &[
            (
                "a missing closing brace",
                "sphere {\n    radius 1\n\nbox { }\n",
            ),
            ("a mismatched bracket", "let x = (1 + 2};\n"),
            ("an extra closing brace", "sphere { radius 1 } }\n"),
            ("an unterminated string", "sphere \"ball { }\n"),
            ("an unterminated comment", "/* never closed\nsphere { }\n"),
            (
                "a missing comma in a vector",
                "sphere { center <0, 1 0> }\n",
            ),
            (
                "a vector that is not closed",
                "sphere { center <0, 1, 0 radius 1 }\n",
            ),
            ("a missing semicolon", "let r = 1\nsphere { radius r }\n"),
            ("a property without its value", "sphere { radius }\n"),
            ("two values without a comma", "sphere { radius 1 2 }\n"),
            ("a keyword as a name", "let in = 1;\n"),
            ("a stray character", "sphere { radius 1 } @\n"),
            ("a number too large", "let x = 1e999;\n"),
            ("an unknown escape", "sphere \"a\\qb\" { }\n"),
            ("`=` where `==` was meant", "let x = 1;\nif x = 1 { }\n"),
            ("a range outside a loop", "let x = 1..2;\n"),
            ("a loop without `in`", "for i 0..3 { }\n"),
            ("a camera without its kind", "camera { eye <0, 0, -5> }\n"),
            ("an import without quotes", "import materials.scene\n"),
            ("a missing field name", "let v = <1, 2, 3>;\nlet x = v.;\n"),
        ],
    );
}

/// Issue 27: the mistakes people bring from other languages, each said for what it is at
/// the place it is, with the fix (before: "expected `;`, found `}`" with a help about
/// `let`; "separate values with commas"; "expected something else, found `px`").
#[test]
fn common_mistakes() {
    check_errors(
        "common_mistakes",
        &[
            ("`=` after a property", "sphere { radius = 1 }\n"),
            (
                "`=` after a property on its own line",
                "material glass {\n    ior = 1.5\n    transmissive 0.9\n}\n",
            ),
            ("`;` after a property", "sphere { radius 1; }\n"),
            ("pixels after a number", "settings { width 640px }\n"),
            // A wide character just before the number (a byte-order mark the grammar
            // takes for white space) once made the number's start a byte inside it.
            (
                "a unit after a number after a wide character",
                "settings { width\u{feff}640px }\n",
            ),
            (
                "degrees after a number",
                "camera perspective { fov 45deg }\n",
            ),
            (
                "radians after a number",
                "camera perspective { fov 0.8rad }\n",
            ),
            (
                "an assignment in a loop is not a property",
                "let radius = 1;\nfor i in 0..2 {\n    radius = radius + 1\n}\n",
            ),
        ],
    );
}

/// Issue 27: values that are valid but almost certainly meant otherwise, warned at the
/// value with what to write (before: no word), and a camera looking along `up` gets the
/// `up` to use.
#[test]
fn mistaken_values() {
    check_errors(
        "mistaken_values",
        &[
            (
                "a colour written 0-255",
                "material m { diffuse rgb(255, 128, 0) specular 0.5 }\nsphere { material m }\n",
            ),
            (
                "a field of view in radians",
                "camera perspective { eye <0, 0, -5> look_at <0, 0, 0> fov 0.785 }\nsphere { }\n",
            ),
            (
                "a camera looking along `up`",
                "camera perspective { eye <0, 5, 0> look_at <0, 0, 0> }\nsphere { }\n",
            ),
            (
                "a reflectance written as a percentage",
                "material m {\n    diffuse 0.5\n    transmissive 90\n}\nsphere { material m }\n",
            ),
            (
                "a light brighter than the largest intensity",
                "light point { position <0, 5, 0> color rgb(1, 2e7, 1) }\nsphere { }\n",
            ),
        ],
    );
}

#[test]
fn name_errors() {
    check_errors(
        "name_errors",
        &[
            (
                "an unknown name, with a close one",
                "material glass { }\nsphere { material glas }\n",
            ),
            (
                "an unknown name, with nothing close",
                "sphere { radius size }\n",
            ),
            (
                "a name used before its definition",
                "sphere { radius r }\nlet r = 1;\n",
            ),
            ("an unknown function", "let x = sqr(4);\n"),
            (
                "a built-in with the wrong number of arguments",
                "let x = pow(2);\n",
            ),
            (
                "a function with the wrong number of arguments",
                "fn f(a, b) { return a; }\nlet x = f(1);\n",
            ),
            (
                "a function used as a value",
                "fn f() { return 1; }\nlet x = f;\n",
            ),
            ("a built-in function used as a value", "let x = sqrt;\n"),
            (
                "a value called as a function",
                "let r = 1;\nlet x = r(2);\n",
            ),
            ("a function used as an object", "fn ring(n) { }\nring { }\n"),
            ("an unknown object kind", "sphre { radius 1 }\n"),
            ("an unknown light kind", "light spto { }\n"),
            ("an unknown camera kind", "camera perspectiv { }\n"),
            ("a name defined twice", "let a = 1;\nlet a = 2;\n"),
            (
                "an unknown vector field",
                "let v = <1, 2, 3>;\nlet x = v.w;\n",
            ),
            ("a property written like a call", "sphere { scale(2) }\n"),
            (
                "unused material and function",
                "material unused { }\nfn helper() { }\nmaterial _kept { }\nsphere { }\n",
            ),
            (
                "a material that returns more light than it receives",
                "material glass { reflective 1 transmissive 1 fresnel schlick }\nfor i in 0..3 { material shiny { reflective 0.6 transmissive <0.2, 0.5, 0.2> } sphere { material shiny } }\nsphere { material glass }\n",
            ),
        ],
    );
}

#[test]
fn placement_errors() {
    check_errors(
        "placement_errors",
        &[
            (
                "an unknown property, with a close one",
                "sphere { centre <0, 0, 0> }\n",
            ),
            (
                "an unknown property, with nothing close",
                "sphere { colour red }\n",
            ),
            ("a property at the top level", "radius 1\n"),
            (
                "a light inside an object",
                "union { light point { position <0, 1, 0> } }\n",
            ),
            (
                "a material definition inside an object",
                "material glass { }\nsphere { material glass { ior 1.3 } }\n",
            ),
            ("an object inside a shape", "sphere { box { } }\n"),
            ("an object inside a material", "material m { sphere { } }\n"),
            ("`const` inside a block", "for i in 0..2 { const N = 1; }\n"),
            ("a function inside a block", "if true { fn f() { } }\n"),
            ("`return` outside a function", "return 1;\n"),
            (
                "settings inside a function",
                "fn f() { settings { width 10 } }\nf()\n",
            ),
            (
                "an import inside a block",
                "if true { import \"x.scene\" }\n",
            ),
            ("a call inside a shape", "fn f() { }\nsphere { f() }\n"),
            (
                "three numbers where a vector is wanted",
                "sphere { center 0, 1, 0 }\n",
            ),
            (
                "two vertices for a triangle",
                "triangle { vertices <0, 0, 0>, <1, 0, 0> }\n",
            ),
            (
                "`about` with a translation",
                "sphere { translate <1, 0, 0> about <0, 1, 0> }\n",
            ),
            (
                "a block after a colour property",
                "material m { specular 0.5 { scale 2 } }\n",
            ),
            ("a misspelt word", "settings { shadows filterd }\n"),
            (
                "a number where a word is wanted",
                "material m { fresnel 1 }\n",
            ),
            ("`open` on a sphere", "sphere { open }\n"),
        ],
    );
}

#[test]
fn value_errors() {
    check_errors(
        "value_errors",
        &[
            ("adding a vector and a number", "let x = <1, 2, 3> + 1;\n"),
            ("a condition that is a number", "if 1 { }\n"),
            ("a vector where a number is wanted", "sphere { radius <1, 1, 1> }\n"),
            ("a number where a vector is wanted", "sphere { center 1 }\n"),
            ("negating a boolean", "let x = -true;\n"),
            ("a component of a number", "let x = (1).x;\n"),
            ("ordering vectors", "let x = <1, 2, 3> < <1, 2, 4>;\n"),
            ("a division by zero", "let x = 1 / (2 - 2);\n"),
            ("a remainder by zero", "let x = 5 % 0;\n"),
            ("an infinite result", "let x = pow(10, 200) * pow(10, 200);\n"),
            ("the square root of a negative number", "let x = sqrt(-4);\n"),
            ("asin out of range", "let x = asin(2);\n"),
            ("normalizing zero", "let v = normalize(<0, 0, 0>);\n"),
            ("a built-in given the wrong type", "let x = sqrt(<1, 2, 3>);\n"),
            ("a radius of zero", "sphere { radius 0 }\n"),
            ("a negative colour", "material m { diffuse rgb(-1, 0, 0) }\n"),
            ("settings out of range", "settings { width 0 samples 2.5 }\n"),
            ("a property set twice", "sphere { radius 1 radius 2 }\n"),
            ("a property set twice by a loop", "sphere { for i in 0..2 { radius 1 } }\n"),
            ("two cameras", "camera perspective { }\ncamera orthographic { }\n"),
            ("a point light without a position", "light point { color white }\n"),
            ("a spot light with inner > outer", "light spot { position <0, 1, 0> direction <0, -1, 0> inner 40 outer 20 }\n"),
            ("a triangle without vertices", "triangle { }\n"),
            ("too few coefficients", "quadric { coefficients 1, 2, 3 }\n"),
            ("a matrix that cannot be inverted", "sphere { matrix 0, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1 }\n"),
            ("a scale by zero", "box { scale <1, 0, 1> }\n"),
            ("a rotation without an axis", "box { rotate 30 }\n"),
            ("a loop bound that is not whole", "for i in 0..2.5 { }\n"),
            ("an object made in a function called for its value", "fn f() { sphere { } return 1; }\nlet x = f();\n"),
            ("a function that returns nothing", "fn f() { }\nlet x = f();\n"),
            ("a number given as a material", "sphere { material 1 }\n"),
            ("a parent that is not a material", "let m = 1;\nmaterial x : m { }\n"),
            ("a pattern where a colour is wanted", "material m { specular checker(white, black) }\n"),
            ("a block after a plain colour", "material m { diffuse red { scale 2 } }\n"),
            ("a pattern of size zero", "material m { diffuse checker(white, black, 0) }\n"),
            ("attenuation that is all zero", "light point { position <0, 1, 0> attenuation <0, 0, 0> }\n"),
            (
                "several errors, all reported",
                "let a = 1 / 0;\nsphere { radius -1 }\nbox { center <0, 0, 0> }\nlet b = sqrt(-1);\n",
            ),
            ("an error in a loop, reported once", "for i in 0..1000 { sphere { radius i - 2000 } }\n"),
        ],
    );
}

#[test]
fn validation_errors() {
    check_errors(
        "validation_errors",
        &[
            (
                "a box turned inside out",
                "box { min <1, 1, 1> max <0, 0, 0> }\n",
            ),
            (
                "a flat triangle",
                "triangle { vertices <0, 0, 0>, <1, 0, 0>, <2, 0, 0> }\n",
            ),
            (
                "a camera whose up is its view",
                "camera perspective { eye <0, 5, 0> look_at <0, 0, 0> up <0, 1, 0> }\n",
            ),
            (
                "a camera looking at itself",
                "camera perspective { eye <1, 2, 3> look_at <1, 2, 3> }\n",
            ),
            (
                "a quadric that is a plane",
                "quadric { coefficients 0, 0, 0, 0, 0, 0, 1, 0, 0, 1 }\n",
            ),
            (
                "a cone with equal radii",
                "cone { base_radius 1 apex_radius 1 }\n",
            ),
            (
                "a cylinder of zero length",
                "cylinder { base <0, 0, 0> apex <0, 0, 0> }\n",
            ),
            (
                "a CSG child that is not solid",
                "union { disk { } sphere { } }\n",
            ),
            ("an empty CSG", "union { }\n"),
            (
                "a group inside a difference",
                "difference { sphere { } group { box { } } }\n",
            ),
        ],
    );
}

#[test]
fn import_errors() {
    let files = [
        ("a.scene", "import \"b.scene\"\nsphere { }\n"),
        ("b.scene", "import \"a.scene\"\n"),
        ("lib.scene", "material glass { }\n"),
        ("other.scene", "material glass { ior 2 }\n"),
        ("broken.scene", "sphere { radius }\n"),
    ];
    check_errors_with(
        "import_errors",
        &[
            ("a missing file", "import \"nowhere.scene\"\nsphere { }\n"),
            ("an import cycle", "import \"a.scene\"\n"),
            ("a file that imports itself", "import \"test.scene\"\n"),
            (
                "two imports defining one name",
                "import \"lib.scene\"\nimport \"other.scene\"\nsphere { material glass }\n",
            ),
            (
                "a name defined again after its import",
                "import \"lib.scene\"\nmaterial glass { }\nsphere { material glass }\n",
            ),
            (
                "a syntax error in an imported file",
                "import \"broken.scene\"\n",
            ),
        ],
        &files,
        &CompileOptions::default(),
    );
}

#[test]
fn define_errors() {
    let defines = |pairs: &[(&str, &str)]| CompileOptions {
        defines: pairs
            .iter()
            .map(|(n, v)| (n.to_string(), v.to_string()))
            .collect(),
        ..CompileOptions::default()
    };
    let scene = "const SIZE = 3;\nconst COLOR = red;\nlet count = 2;\nsphere { radius SIZE material { diffuse COLOR } }\n";
    let mut out = String::new();
    /// (title, scene, -D pairs)
    type Case<'a> = (&'a str, &'a str, &'a [(&'a str, &'a str)]);
    let cases: &[Case<'_>] = &[
        (
            "an undefined constant, with a close one",
            scene,
            &[("SIZ", "4")],
        ),
        ("an undefined constant, with a list", scene, &[("N", "4")]),
        ("a `let`, which cannot be set", scene, &[("count", "4")]),
        ("no constants at all", "sphere { }\n", &[("N", "4")]),
        ("a value of the wrong type", scene, &[("SIZE", "<1, 2, 3>")]),
        ("a name that is not a name", scene, &[("2x", "4")]),
        ("a value that does not parse", scene, &[("SIZE", "1 +")]),
        ("a value with an unknown name", scene, &[("SIZE", "twelve")]),
        (
            "a value that is a material",
            scene,
            &[("COLOR", "material { }")],
        ),
        ("a value that divides by zero", scene, &[("SIZE", "1 / 0")]),
    ];
    for (title, input, pairs) in cases {
        let compilation = compile_with(input, &mut MapLoader::default(), &defines(pairs));
        assert!(compilation.has_errors(), "case `{title}` compiled");
        let list: Vec<String> = pairs.iter().map(|(n, v)| format!("-D {n}={v}")).collect();
        out.push_str(&format!(
            "=== {title}: {}\n{}\n",
            list.join(" "),
            output(&compilation)
        ));
    }
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!("define_errors", out);
    });
}

#[test]
fn a_root_file_that_cannot_be_read_is_a_diagnostic_without_a_span() {
    let compilation = compile_file(
        std::path::Path::new("missing.scene"),
        &mut MapLoader::default(),
        &CompileOptions::default(),
    );
    assert!(compilation.scene.is_none());
    assert_eq!(compilation.diagnostics.len(), 1);
    assert_eq!(compilation.diagnostics[0].span, None);
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!("unreadable_root", output(&compilation));
    });
}

#[test]
fn limits_are_errors_that_name_the_limit() {
    let limits = Limits {
        max_objects: 5,
        max_evaluation_steps: 50,
        max_call_depth: 8,
        max_nesting: 6,
        max_import_depth: 2,
        max_imports: 10,
        max_source_bytes: 200,
        max_lights: 3,
        max_materials: 4,
        max_mesh_triangles: 100,
        max_scene_triangles: 1_000,
    };
    let options = CompileOptions {
        limits,
        ..CompileOptions::default()
    };
    let files = [
        ("one.scene", "import \"two.scene\"\n"),
        ("two.scene", "import \"three.scene\"\n"),
        ("three.scene", "sphere { }\n"),
        ("big.scene", "// padding\n".repeat(30).leak()),
    ];
    check_errors_with(
        "limit_errors",
        &[
            ("too many objects", "for i in 0..10 { sphere { center <i, 0, 0> } }\n"),
            ("too many loop iterations", "for i in 0..10 { for j in 0..10 { } }\n"),
            ("a loop of a billion", "for i in 0..1000000000 { }\n"),
            ("runaway recursion", "fn f(n) { return f(n + 1); }\nlet x = f(0);\n"),
            ("brackets nested too deeply", "let x = ((((((((1))))))));\n"),
            ("blocks nested too deeply", "if true { if true { if true { if true { if true { if true { if true { } } } } } } }\n"),
            ("an expression too deep", "let x = ----------------------------------------------------------------------------------------------------1;\n"),
            ("vectors nested too deeply", "let x = <<<<<<<1, 0, 0>.x, 0, 0>.x, 0, 0>.x, 0, 0>.x, 0, 0>.x, 0, 0>.x, 0, 0>;\n"),
            ("imports nested too deeply", "import \"one.scene\"\n"),
            ("too much source", "import \"big.scene\"\n"),
        ],
        &files,
        &options,
    );
}

/// Words and habits brought from POV-Ray and elsewhere, each answered with the whitted way
/// (crates/lang/src/hints.rs), and a comma put between two properties.
#[test]
fn foreign_words_and_habits() {
    check_errors(
        "foreign_words",
        &[
            (
                "a POV-Ray colour in a material",
                "material m { color rgb 0.9 }\n",
            ),
            (
                "a POV-Ray colour in a light",
                "light point { position <0, 1, 0> color rgb 0.9 }\n",
            ),
            (
                "a comma between properties",
                "sphere { center <0, 0, 0>, radius 1 }\n",
            ),
            ("an axis name as a vector", "plane { normal y }\n"),
            (
                "an axis times a vector",
                "sphere { center <1, 0, 0> * x }\n",
            ),
            ("a per-object no_shadow", "sphere { radius 1 no_shadow }\n"),
            ("a mesh", "mesh { }\n"),
            ("#declare", "#declare R = 1;\n"),
            ("#include", "#include \"colors.inc\"\n"),
            (
                "a filter channel",
                "material m { diffuse rgbf <1, 1, 1, 0.5> }\n",
            ),
            (
                "phong and phong_size",
                "material m { phong 0.5 phong_size 40 }\n",
            ),
            ("a pigment block", "sphere { pigment { color red } }\n"),
            (
                "a camera location",
                "camera perspective { location <0, 0, -5> }\n",
            ),
            (
                "a light_source",
                "light_source { <0, 10, 0> color white }\n",
            ),
            ("a positional sphere", "sphere { <0, 0, 0>, 1 }\n"),
            ("a positional box", "box { <0, 0, 0>, <1, 1, 1> }\n"),
            (
                "a comma between properties on two lines",
                "sphere {\n    center <0, 0, 0>,\n    radius 1\n}\n",
            ),
            ("an x axis", "plane { normal x }\n"),
            ("a z axis", "disk { normal z }\n"),
            ("#local", "fn f() {\n    #local R = 1;\n}\n"),
            (
                "a transmit channel",
                "material m { diffuse rgbt <1, 1, 1, 0.5> }\n",
            ),
            ("filter", "material m { filter 0.5 }\n"),
            ("transmit", "material m { transmit 0.5 }\n"),
            ("a finish block", "sphere { finish { phong 1 } }\n"),
            ("a texture block", "sphere { texture { } }\n"),
            ("a mesh2", "mesh2 { }\n"),
        ],
    );
}

/// More of POV-Ray's words: shapes, modifiers, finish and light words and global
/// illumination, each answered with the nearest whitted construction (crates/lang/src/hints.rs).
#[test]
fn more_foreign_words() {
    check_errors(
        "more_foreign_words",
        &[
            ("a smooth triangle", "smooth_triangle { }\n"),
            ("a blob", "blob { }\n"),
            ("a lathe", "lathe { }\n"),
            ("an isosurface", "isosurface { }\n"),
            ("clipped_by", "sphere { radius 1 clipped_by { box { } } }\n"),
            ("hollow", "sphere { radius 1 hollow }\n"),
            ("roughness", "material m { roughness 0.05 }\n"),
            ("metallic", "material m { specular 0.5 metallic }\n"),
            (
                "an area light",
                "light point { position <0, 5, 0> area_light }\n",
            ),
            ("a spotlight", "light spotlight { position <0, 5, 0> }\n"),
            (
                "point_at",
                "light spot { position <0, 5, 0> point_at <0, 0, 0> }\n",
            ),
            (
                "falloff",
                "light spot { position <0, 5, 0> direction <0, -1, 0> falloff 30 }\n",
            ),
            (
                "fade_distance",
                "light point { position <0, 5, 0> fade_distance 10 }\n",
            ),
            ("radiosity", "settings { radiosity { } }\n"),
            ("photons", "settings { photons { } }\n"),
        ],
    );
}
