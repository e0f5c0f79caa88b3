//! Issue 9 item 6: no NaN or infinity reaches a pixel. Scenes with every number at the edge
//! of its limit (the largest intensity, coordinate and ior, the smallest size, reflectance 1)
//! compile, and render to finite pixels; one past the limit is refused (see
//! `whitted_ir`'s range tests for each field).

use std::path::Path;

use whitted_lang::{compile_source, CompileOptions, SourceLoader};
use whitted_tracer::{render, NoObserver, PreparedScene, RenderOptions};

struct NoFiles;

impl SourceLoader for NoFiles {
    fn load(&mut self, _: &Path) -> std::io::Result<Vec<u8>> {
        Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "no imports here",
        ))
    }
}

/// Renders `text` at 24x16 and returns its pixels; panics if it does not compile.
fn pixels(name: &str, text: &str) -> Vec<f32> {
    let compilation = compile_source(name, text, &mut NoFiles, &CompileOptions::default());
    let Some(scene) = compilation.scene else {
        panic!("{name} does not compile: {:?}", compilation.diagnostics);
    };
    let prepared = PreparedScene::new(&scene);
    let options = RenderOptions {
        width: 24,
        height: 16,
        ..RenderOptions::from_settings(&scene.settings)
    };
    let Some((image, _)) = render(&prepared, &options, &NoObserver) else {
        panic!("{name} was cancelled");
    };
    image.pixels.iter().flatten().copied().collect()
}

const CASES: &[(&str, &str)] = &[
    (
        "brightest lights and coefficients",
        "settings { ambient 1e6 background 1e6 max_depth 20 }
         camera perspective { eye <0, 0, 5> look_at <0, 0, 0> }
         for i in 0..50 { light point { position <i - 25, 5, 5> color 1e6 } }
         material hot { ambient 1e6 diffuse 1e6 specular 1e6 shininess 1e6 reflective 1 }
         sphere { radius 1 material hot }
         plane { normal <0, 1, 0> offset -1 material hot }
         plane { normal <0, 0, 1> offset -3 material hot }",
    ),
    (
        "facing mirrors at the largest depth",
        "settings { max_depth 256 min_weight 0 }
         camera perspective { eye <0, 0, 0.5> look_at <0, 0, -1> }
         light point { position <0, 0, 0> color 1e6 }
         material mirror { diffuse 1e6 reflective 1 }
         plane { normal <0, 0, 1> offset -1 material mirror }
         plane { normal <0, 0, -1> offset -1 material mirror }",
    ),
    (
        "glass at both ior limits",
        "settings { max_depth 30 min_weight 0 shadows filtered }
         light point { position <0, 5, 5> color 1e6 }
         sphere { center <-1, 0, 0> radius 0.9 material { transmissive 1 reflective 1 ior 1e3 absorption 1e6 } }
         sphere { center <1, 0, 0> radius 0.9 material { transmissive 1 ior 0.001 fresnel schlick } }
         plane { normal <0, 1, 0> offset -1 }",
    ),
    (
        "the largest coordinates",
        "camera perspective { eye <0, 0, 1e9> look_at <0, 0, 0> }
         light point { position <0, 1e9, 1e9> color 1e6 attenuation <1e9, 1e9, 1e9> }
         light directional { direction <1e9, -1e9, 0> }
         sphere { center <0, 0, -5e8> radius 4e8 }
         box { min <-1e9, -1e9, -1e9> max <-5e8, 1e9, 1e9> }
         plane { normal <0, 1e9, 0> offset -1e9 }
         sphere { radius 1e-9 }",
    ),
    (
        "the smallest sizes",
        "settings { epsilon 1e-9 }
         camera perspective { eye <0, 0, 1e-7> look_at <0, 0, 0> }
         light point { position <0, 1e-7, 1e-7> attenuation <0, 0, 1e9> }
         sphere { radius 1e-9 }
         box { min <1e-9, 0, 0> max <2e-9, 1e-9, 1e-9> }
         cylinder { base <-3e-9, 0, 0> apex <-3e-9, 1e-9, 0> radius 1e-9 }
         sphere { center <0, 0, -1> radius 0.5 material { diffuse checker(white, black, 1e-9) } }",
    ),
];

#[test]
fn numbers_at_their_limits_render_finite_pixels() {
    for (name, text) in CASES {
        let pixels = pixels(name, text);
        let bad = pixels.iter().filter(|v| !v.is_finite()).count();
        assert_eq!(bad, 0, "{name}: {bad} components are NaN or infinite");
        assert!(
            pixels.iter().any(|v| *v > 0.0),
            "{name}: an all-black image"
        );
    }
}

#[test]
fn numbers_past_their_limits_are_refused_with_the_limit_named() {
    for (text, limit) in [
        (
            "light point { position <0, 5, 0> color 1e39 }",
            "largest intensity limit",
        ),
        ("sphere { material { ior 1e308 } }", "largest ior limit"),
        ("sphere { radius 1e39 }", "largest coordinate limit"),
        (
            "sphere { center <-1e39, 0, 0> }",
            "largest coordinate limit",
        ),
        (
            "sphere { material { reflective 1.5 } }",
            "largest reflectance limit",
        ),
        ("sphere { radius 1e-310 }", "smallest size limit"),
        (
            "sphere { radius 1 scale 1e6 translate <1e9, 0, 0> }",
            "largest coordinate limit",
        ),
    ] {
        let compilation = compile_source("t.scene", text, &mut NoFiles, &CompileOptions::default());
        let error = compilation.diagnostics.iter().find(|d| d.is_error());
        let Some(error) = error else {
            panic!("{text} compiled");
        };
        assert!(error.message.contains(limit), "{text}: {}", error.message);
        assert!(error.span.is_some(), "{text}: no place");
    }
}
