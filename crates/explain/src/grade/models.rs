//! The student bug models: each classic Whitted-tracer mistake as the settings that make
//! whitted's tracer commit it (or, for gamma, the other 8-bit encoding), with the words a
//! teacher reads and the handout's section it breaks.

use whitted_ir::{Color, Fresnel, Highlight, SamplePosition, Settings, ShadowMode};

/// How a model changes the reference render.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Change {
    /// These settings (`name`, value as `--set` writes it) on top of the reference's.
    Set(Vec<(&'static str, String)>),
    /// The reference image written in the other 8-bit encoding (sRGB for linear, or back).
    OtherEncoding,
    /// The reference image with its rows in the opposite order (a file origin mistaken).
    UpsideDown,
    /// The reference image with red and blue exchanged (TGA's BGR order written as RGB).
    RedBlueSwapped,
}

/// One classic bug.
#[derive(Debug)]
pub struct StudentBug {
    /// A short name for reports, CSV and `--model`.
    pub id: &'static str,
    /// What the student's tracer does, in plain words.
    pub words: &'static str,
    /// Where the handouts (MIT 6.837, Fall 2004) ask for the right behaviour.
    pub handout: &'static str,
    /// What the student's tracer must do instead.
    pub fix: &'static str,
    /// The change that renders the bug, given the reference's settings; `None` when the
    /// bug cannot show under them (no shadows to get wrong without shadow rays).
    pub change: fn(&Settings) -> Option<Change>,
}

fn set(name: &'static str, value: impl Into<String>) -> Option<Change> {
    Some(Change::Set(vec![(name, value.into())]))
}

/// Every model, in the order reports list ties.
pub const BUGS: &[StudentBug] = &[
    StudentBug {
        id: "no-shadow-offset",
        words: "rays leaving a surface start exactly on it and hit it again (shadow acne, speckled reflections)",
        handout: "assignment 4, shadows and traceRay: start shadow, reflected and refracted rays a small epsilon off the surface",
        fix: "start shadow and secondary rays a small epsilon off the surface (or ignore hits closer than epsilon)",
        change: |s| (s.epsilon != Some(0.0)).then(|| Change::Set(vec![("epsilon", "0".into())])),
    },
    StudentBug {
        id: "no-shadows",
        words: "casts no shadow rays: nothing is in shadow",
        handout: "assignment 4, -shadows: cast a ray to each light; a blocked light adds nothing",
        fix: "cast a shadow ray to each light and drop the light when an object blocks it",
        change: |s| (s.shadows != ShadowMode::None).then_some(()).and_then(|_| set("shadows", "none")),
    },
    StudentBug {
        id: "opaque-shadows",
        words: "transparent objects cast full shadows",
        handout: "assignment 4, -transparent_shadows: a shadow ray passes through a transparent object, tinted by its transparentColor",
        fix: "let shadow rays through transparent objects, multiplying by transparentColor at each surface",
        change: |s| (s.shadows == ShadowMode::Filtered).then_some(()).and_then(|_| set("shadows", "opaque")),
    },
    StudentBug {
        id: "shadows-not-asked",
        words: "casts shadows though the command line did not ask for them",
        handout: "assignment 4: shadow rays only with -shadows",
        fix: "cast shadow rays only with -shadows (or -transparent_shadows)",
        change: |s| (s.shadows == ShadowMode::None).then_some(()).and_then(|_| set("shadows", "opaque")),
    },
    StudentBug {
        id: "back-faces-lit",
        words: "lights surfaces seen from behind as if from the front",
        handout: "assignment 2, -shade_back: only with it is a back face shaded, with its normal flipped",
        fix: "without -shade_back, colour a surface seen from behind black",
        change: |s| (!s.shade_back).then_some(()).and_then(|_| set("shade_back", "on")),
    },
    StudentBug {
        id: "back-faces-not-shaded",
        words: "does not shade surfaces seen from behind (ignores -shade_back)",
        handout: "assignment 2, -shade_back: flip the normal of a back face and shade it",
        fix: "with -shade_back, flip the normal towards the viewer and shade the back face",
        change: |s| s.shade_back.then_some(()).and_then(|_| set("shade_back", "off")),
    },
    StudentBug {
        id: "back-face-ambient",
        words: "handles back faces differently: the ambient term kept or dropped",
        handout: "assignment 2, -shade_back: without it, a back face is black",
        fix: "without -shade_back, give a back face no colour of its own (ambient included)",
        change: |s| {
            (!s.shade_back).then_some(()).and_then(|_| {
                set("back_ambient", if s.back_ambient { "off" } else { "on" })
            })
        },
    },
    StudentBug {
        id: "normals-not-flipped",
        words: "keeps the outward normal when a ray hits a surface from inside a solid",
        handout: "assignment 4, refraction: inside an object, flip the normal before reflecting and refracting",
        fix: "flip the normal when the ray is inside (ray direction · normal > 0)",
        change: |s| s.flip_normals.then_some(()).and_then(|_| set("flip_normals", "off")),
    },
    StudentBug {
        id: "ior-not-inverted",
        words: "refracts out of an object as if going into it (the index ratio not inverted)",
        handout: "assignment 4, refraction: leaving an object the ratio is index/1, not 1/index",
        fix: "when leaving an object swap the indices: from its index into 1",
        change: |s| s.exit_ior_inverted.then_some(()).and_then(|_| set("exit_ior", "uninverted")),
    },
    StudentBug {
        id: "no-total-internal-reflection",
        words: "traces the refracted ray past the critical angle (no total internal reflection)",
        handout: "assignment 4, refraction: transmittedDirection returns false on total internal reflection",
        fix: "test for total internal reflection (the square root's argument < 0) and trace no transmitted ray then",
        change: |s| {
            s.total_internal_reflection
                .then_some(())
                .and_then(|_| set("total_internal_reflection", "off"))
        },
    },
    StudentBug {
        id: "one-bounce-fewer",
        words: "stops one bounce early (-bounces counted from 1)",
        handout: "assignment 4, -bounces N: reflected and refracted rays up to depth N, the camera ray depth 0",
        fix: "trace secondary rays while their depth is at most the -bounces value",
        change: |s| (s.max_depth >= 1).then(|| Change::Set(vec![("max_depth", (s.max_depth - 1).to_string())])),
    },
    StudentBug {
        id: "one-bounce-more",
        words: "goes one bounce too far",
        handout: "assignment 4, -bounces N: reflected and refracted rays up to depth N, the camera ray depth 0",
        fix: "stop when the depth passes the -bounces value",
        change: |s| {
            (s.max_depth < whitted_ir::limits::MAX_DEPTH)
                .then(|| Change::Set(vec![("max_depth", (s.max_depth + 1).to_string())]))
        },
    },
    StudentBug {
        id: "no-weight-cutoff",
        words: "ignores the -weight cut-off",
        handout: "assignment 4, -weight W: a ray whose contribution is below W is not traced",
        fix: "carry each ray's weight (the product of coefficients) and stop below -weight",
        change: |s| (s.min_weight > 0.0).then(|| Change::Set(vec![("min_weight", "0".into())])),
    },
    StudentBug {
        id: "no-ambient",
        words: "leaves out the ambient term",
        handout: "assignment 2, Phong: colour = ambient light · diffuse colour + the lights' terms",
        fix: "add the scene's ambient light times the diffuse colour",
        change: |s| (s.ambient != Color::BLACK).then(|| Change::Set(vec![("ambient", "0".into())])),
    },
    StudentBug {
        id: "highlight-gate",
        words: "gates the highlight by N·L differently (specular from lights behind the surface kept or dropped)",
        handout: "assignment 3, PhongMaterial::Shade: the specular term is computed whatever N·L is",
        fix: "compute the specular term as the handout writes it, clamping only the diffuse term",
        change: |s| set("highlight_gate", if s.highlight_gate { "off" } else { "on" }),
    },
    StudentBug {
        id: "highlight-model",
        words: "uses the other highlight formula (Phong's R·V for Blinn's N·H, or back)",
        handout: "assignment 3, PhongMaterial: the specular term is ks·(N·H)^exponent, H halfway between the light and the viewer",
        fix: "use the half vector H = normalize(L + V) and (N·H)^exponent",
        change: |s| {
            set(
                "highlight",
                match s.highlight {
                    Highlight::Phong => "blinn",
                    Highlight::Blinn => "phong",
                },
            )
        },
    },
    StudentBug {
        id: "gamma",
        words: "writes the other encoding: sRGB gamma where linear values are expected (or linear where sRGB is)",
        handout: "assignment 1, Image: a colour channel times 255 is written as it is",
        fix: "write each channel clamped to [0, 1] times 255, without a gamma curve",
        change: |_| Some(Change::OtherEncoding),
    },
    StudentBug {
        id: "upside-down",
        words: "writes the image upside down (rows from the top where the file's origin is the bottom, or back)",
        handout: "assignment 1, Image::SaveTGA: rows are written bottom first, as the format's origin is the lower left",
        fix: "write rows in the order the file format expects (TGA: the bottom row first), or map j to height - 1 - j",
        change: |_| Some(Change::UpsideDown),
    },
    StudentBug {
        id: "red-blue-swapped",
        words: "writes red and blue exchanged (TGA stores blue, green, red)",
        handout: "assignment 1, Image::SaveTGA: each pixel is written as blue, green, red",
        fix: "write each pixel's bytes in the file format's order (TGA: B, G, R)",
        change: |_| Some(Change::RedBlueSwapped),
    },
    StudentBug {
        id: "pixel-corner",
        words: "samples each pixel at its corner instead of its centre",
        handout: "assignment 2, generateRay: the point (i + 0.5)/width, (j + 0.5)/height is the pixel's centre",
        fix: "shoot the ray through the pixel's centre, (i + 0.5, j + 0.5)",
        change: |s| {
            (s.sample_position == SamplePosition::Centre)
                .then_some(())
                .and_then(|_| set("sample_position", "corner"))
        },
    },
    StudentBug {
        id: "no-attenuation",
        words: "ignores the lights' distance attenuation",
        handout: "assignment 4, PointLight: the light's colour over (a + b·d + c·d²)",
        fix: "divide a point light's colour by its attenuation at the distance",
        change: |s| s.light_falloff.then_some(()).and_then(|_| set("light_falloff", "off")),
    },
    StudentBug {
        id: "fresnel",
        words: "splits reflection and refraction by Fresnel (Schlick) where the colours are to be used as given, or not where Fresnel is asked",
        handout: "assignment 4, traceRay: add reflectiveColor·trace + transparentColor·trace",
        fix: "weight the reflected and transmitted rays by the material's colours only",
        change: |s| match s.fresnel_rule {
            None => set("fresnel_rule", "schlick"),
            Some(Fresnel::Off) => set("fresnel_rule", "schlick"),
            Some(_) => set("fresnel_rule", "off"),
        },
    },
    StudentBug {
        id: "energy-scaled",
        words: "scales reflective + transparent down to add up to 1",
        handout: "assignment 4, traceRay: reflectiveColor and transparentColor are used as given",
        fix: "use the reflective and transparent colours as given, even when they add up to more than 1",
        change: |s| set("energy_clamp", if s.energy_clamp { "off" } else { "on" }),
    },
];

/// The model called `id`.
pub fn bug(id: &str) -> Option<&'static StudentBug> {
    BUGS.iter().find(|b| b.id == id)
}
