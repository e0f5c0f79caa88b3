//! Every bound on what a user can ask for, in one place: the language, validation, the CLI's
//! flag ranges, the tracer and the debugger all read these constants, and docs/language.md
//! lists each of them once (a test checks the docs against [`ALL`]).
//!
//! A limit exists so that no input, however careless or hostile, panics, hangs or eats the
//! machine. Each is reported by name when reached, with the place that reached it.

/// Objects in a scene (shapes, CSG nodes, groups). A million spheres take about 300 MB.
pub const MAX_OBJECTS: usize = 5_000_000;

/// Evaluation steps in one compilation: every loop iteration and every function call counts
/// one, so that neither loops nor recursion (`f(n-1) f(n-1)`) can run for days.
pub const MAX_EVALUATION_STEPS: u64 = 100_000_000;

/// Elements of one array (`[a, b, c]`).
pub const MAX_ARRAY_LENGTH: usize = 100_000;

/// Bytes of one string value or formatted name (`"ball {i}"`).
pub const MAX_STRING_BYTES: usize = 4_096;

/// Bytes of every array and string made in one compilation: they live until it ends, so a
/// loop that makes one per iteration is bounded here.
pub const MAX_VALUE_BYTES: u64 = 256 * 1024 * 1024;

/// Nested calls of user functions.
pub const MAX_CALL_DEPTH: usize = 256;

/// Nested brackets `(` and `{` in source text.
pub const MAX_NESTING: usize = 256;

/// Nested imports (a file importing a file importing ...).
pub const MAX_IMPORT_DEPTH: usize = 64;

/// Files one compilation reads (the root and every distinct import), so that imports
/// through a symbolic-link loop cannot fan out without end.
pub const MAX_IMPORTS: usize = 10_000;

/// Source text over every file of a compilation, in bytes; reads stop at this size. Scenes
/// written by programs are big: a million literal spheres is about 70 MB.
pub const MAX_SOURCE_BYTES: usize = 256 * 1024 * 1024;

/// Lights in a scene: every shading point visits every light.
pub const MAX_LIGHTS: usize = 10_000;

/// Materials in a scene, named and inline together.
pub const MAX_MATERIALS: usize = 1_000_000;

/// Width or height of an image, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 32_768;

/// Pixels in an image (width times height).
pub const MAX_PIXELS: u64 = 1 << 27;

/// Anti-aliasing samples per pixel.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 4_096;

/// Frames of one animation (`frames`, and `--frames` on the command line).
pub const MAX_FRAMES: u32 = 100_000;

/// The first frame number of an animation (`first_frame`).
pub const MAX_FIRST_FRAME: u32 = 1_000_000_000;

/// Frames per second of an animation (`fps`).
pub const MAX_FPS: u32 = 1_000;

/// Pixels an animated image (APNG or GIF) holds at once: every frame's pixels, frames times
/// width times height, at 4 bytes each for the GIF encoder (1 GiB): 873 frames of 640x480.
pub const MAX_ANIMATION_PIXELS: u64 = 1 << 28;

/// Recursion depth of the tracer (`max_depth`).
pub const MAX_DEPTH: u32 = 256;

/// Samples a filtered render keeps (width times height times samples per pixel): a filter
/// that reaches past the pixel (any but `box` of radius 0.5) needs every sample's colour
/// until the image is filtered, 12 bytes each, so this is 384 MiB.
pub const MAX_FILTERED_SAMPLES: u64 = 1 << 25;

/// A filter's radius in pixels (the gaussian's σ, which reaches 2σ). A pixel's value weighs
/// every sample of the (2·reach + 1)² pixels around it: at radius 4 a gaussian weighs 289
/// pixels' samples.
pub const MAX_FILTER_RADIUS: f64 = 4.0;

/// Nodes one recorded ray tree may hold; a tree over this is cut, and says where.
pub const MAX_RAY_TREE_NODES: usize = 100_000;

/// Rays one sample may cast besides its camera ray (reflected, transmitted and shadow
/// rays), in `render`, `trace` and everything else that traces. Past it no further
/// reflected or transmitted ray is started in that sample (the colour gathered so far is
/// kept, and the ray records the termination `ray_budget`); the rays already under way
/// finish their own lights. Without it `min_weight 0` and glass that both reflects and
/// transmits cost 2^max_depth rays per sample: at `max_depth 64`, never finishing.
///
/// The figure: the busiest sample of any scene in `scenes/` (and `scenes/bench/`) casts 701
/// rays (scenes/glass-of-water.scene: glass and water with Fresnel, to depth 10); the next
/// are 236 (scenes/mesh.scene) and 155 (scenes/lang-csg-lens.scene), so ordinary scenes stay
/// 14 times below it. A sample at the budget costs about 0.5 ms of one core (20 million rays
/// per CPU-second), so the explosion scene (scenes/ray-explosion.scene, 2,842 of its 3,072
/// pixels at the budget) renders at 64x48 in about 2 s on 2 threads.
pub const MAX_RAYS_PER_SAMPLE: u32 = 10_000;

/// Estimated memory of one render (image buffers, statistics, scene), refused up front.
pub const MAX_RENDER_MEMORY_BYTES: u64 = 8 * 1024 * 1024 * 1024;

/// Triangles in one mesh file. A triangle costs the tracer about 60 bytes (corners, its
/// share of the vertices and of the mesh's BVH), so this is about a gigabyte.
pub const MAX_MESH_TRIANGLES: usize = 16_000_000;

/// Triangles over every distinct mesh of a scene (instances of a mesh do not count again:
/// they share its geometry).
pub const MAX_SCENE_TRIANGLES: usize = 64_000_000;

/// The largest magnitude of a coordinate, size, distance, direction, transform entry or
/// quadric coefficient, in the scene file and in world space after transforms. The tracer
/// works in f32, where at 1e9 neighbouring numbers are already 64 units apart.
pub const MAX_COORDINATE: f64 = 1e9;

/// The smallest size (radius, box side, pattern scale, view height, epsilon). With
/// [`MAX_COORDINATE`], a ray's coordinates in a shape's own space stay below 1e18, whose
/// square is still finite in f32.
pub const MIN_SIZE: f64 = 1e-9;

/// The largest colour component: light colours, ambient and background light, and the
/// ambient, diffuse and specular coefficients, shininess and absorption. Intensity times
/// coefficient over every light and every level of recursion then stays finite in f32.
pub const MAX_INTENSITY: f64 = 1e6;

/// The largest reflective or transmissive coefficient: a surface that returned more than
/// arrives would multiply the light at every bounce (and every filtered shadow) until it
/// overflowed.
pub const MAX_REFLECTANCE: f64 = 1.0;

/// The largest nested-media priority of a material (any order of a few solids fits).
pub const MAX_PRIORITY: u32 = 1_000;

/// Octaves of noise in one of the MIT 6.837 course's `Noise`, `Marble` or `Wood` materials:
/// each octave is one more noise evaluation per shading point, and past 16 an octave's
/// weight (`2^-16`) is below what an 8-bit image shows.
pub const MAX_NOISE_OCTAVES: u32 = 16;

/// The smallest index of refraction.
pub const MIN_IOR: f64 = 1e-3;

/// The largest index of refraction.
pub const MAX_IOR: f64 = 1e3;

/// The largest distance attenuation of a point or spot light when `attenuation_clamp` is
/// off: `1 / (c + l·d + q·d²)` grows without bound as a surface nears a light with no
/// constant term, and this keeps it (times the largest intensity and coefficient, over
/// every light) finite in f32.
pub const MAX_UNCLAMPED_ATTENUATION: f64 = 1e6;

/// A limit's value: a count of things, or a bound on a number in the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Count(u64),
    Number(f64),
}

impl std::fmt::Display for Value {
    /// Counts with thousands separators (`5,000,000`), numbers in scientific notation
    /// (`1e9`, `1e-9`), or plainly when they are small whole numbers (`1`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Value::Count(n) => {
                let digits = n.to_string();
                let mut out = String::new();
                for (i, c) in digits.chars().enumerate() {
                    if i > 0 && (digits.len() - i) % 3 == 0 {
                        out.push(',');
                    }
                    out.push(c);
                }
                f.write_str(&out)
            }
            Value::Number(x) if x.fract() == 0.0 && x.abs() < 1e4 => write!(f, "{x}"),
            Value::Number(x) => write!(f, "{x:e}"),
        }
    }
}

/// One limit as the docs list it.
#[derive(Clone, Copy, Debug)]
pub struct Limit {
    /// The name used in error messages and in the docs.
    pub name: &'static str,
    /// The value as the docs write it.
    pub value: Value,
    /// What is limited, as a phrase for the docs' table.
    pub what: &'static str,
}

const fn count(name: &'static str, value: u64, what: &'static str) -> Limit {
    Limit {
        name,
        value: Value::Count(value),
        what,
    }
}

const fn number(name: &'static str, value: f64, what: &'static str) -> Limit {
    Limit {
        name,
        value: Value::Number(value),
        what,
    }
}

/// Every limit, in the order docs/language.md lists them.
pub const ALL: &[Limit] = &[
    count("objects", MAX_OBJECTS as u64, "objects in a scene (shapes, CSG nodes, groups)"),
    count(
        "evaluation steps",
        MAX_EVALUATION_STEPS,
        "loop iterations and function calls in one compilation",
    ),
    count("call depth", MAX_CALL_DEPTH as u64, "nested function calls"),
    count("array length", MAX_ARRAY_LENGTH as u64, "elements of one array"),
    count("string length", MAX_STRING_BYTES as u64, "bytes of one string or formatted name"),
    count(
        "value memory",
        MAX_VALUE_BYTES,
        "bytes of all arrays and strings made in one compilation",
    ),
    count("nesting", MAX_NESTING as u64, "nested brackets `(` and `{`"),
    count("import depth", MAX_IMPORT_DEPTH as u64, "nested imports"),
    count("imports", MAX_IMPORTS as u64, "files read in one compilation"),
    count(
        "source size",
        MAX_SOURCE_BYTES as u64,
        "bytes of source text over every file",
    ),
    count("lights", MAX_LIGHTS as u64, "lights in a scene"),
    count(
        "mesh triangles",
        MAX_MESH_TRIANGLES as u64,
        "triangles in one mesh file",
    ),
    count(
        "scene triangles",
        MAX_SCENE_TRIANGLES as u64,
        "triangles over every distinct mesh of a scene (instances share theirs)",
    ),
    count("materials", MAX_MATERIALS as u64, "materials in a scene"),
    count("image side", MAX_IMAGE_SIDE as u64, "image width or height, in pixels"),
    count("pixels", MAX_PIXELS, "pixels in an image (width times height)"),
    count(
        "samples per pixel",
        MAX_SAMPLES_PER_PIXEL as u64,
        "anti-aliasing samples per pixel",
    ),
    count("frames", MAX_FRAMES as u64, "frames of one animation (`frames`, `--frames`)"),
    count(
        "first frame",
        MAX_FIRST_FRAME as u64,
        "the first frame number of an animation (`first_frame`)",
    ),
    count("fps", MAX_FPS as u64, "frames per second of an animation (`fps`)"),
    count(
        "animation pixels",
        MAX_ANIMATION_PIXELS,
        "frames times pixels of an animated PNG or GIF, which holds every frame at once",
    ),
    count("max depth", MAX_DEPTH as u64, "recursion depth of the tracer (`max_depth`)"),
    count(
        "filtered samples",
        MAX_FILTERED_SAMPLES,
        "samples a render keeps to filter (width times height times samples, with any `filter` but `box` of radius 0.5)",
    ),
    number(
        "filter radius",
        MAX_FILTER_RADIUS,
        "a filter's radius in pixels (`filter_radius`; the gaussian's σ)",
    ),
    count(
        "ray tree nodes",
        MAX_RAY_TREE_NODES as u64,
        "nodes in one recorded ray tree",
    ),
    count(
        "rays per sample",
        MAX_RAYS_PER_SAMPLE as u64,
        "reflected, transmitted and shadow rays of one sample (past it recursion stops)",
    ),
    count(
        "render memory",
        MAX_RENDER_MEMORY_BYTES,
        "estimated bytes of memory for one render",
    ),
    count("priority", MAX_PRIORITY as u64, "a material's nested-media priority"),
    count(
        "noise octaves",
        MAX_NOISE_OCTAVES as u64,
        "octaves of a 6.837 `Noise`, `Marble` or `Wood` material",
    ),
    number(
        "largest coordinate",
        MAX_COORDINATE,
        "magnitude of a coordinate, size, direction, transform entry or coefficient, also in world space",
    ),
    number(
        "smallest size",
        MIN_SIZE,
        "radius, box side, pattern scale, view height or epsilon",
    ),
    number(
        "largest intensity",
        MAX_INTENSITY,
        "light colour, ambient, background, and a material's ambient, diffuse, specular, shininess, absorption, emission",
    ),
    number(
        "largest reflectance",
        MAX_REFLECTANCE,
        "a material's reflective or transmissive coefficient",
    ),
    number("smallest ior", MIN_IOR, "index of refraction"),
    number("largest ior", MAX_IOR, "index of refraction"),
    number(
        "largest attenuation",
        MAX_UNCLAMPED_ATTENUATION,
        "a point or spot light's distance attenuation with `attenuation_clamp off`",
    ),
];

/// The limit called `name` (for messages): `the evaluation steps limit (100,000,000)`.
pub fn describe(name: &str) -> String {
    match ALL.iter().find(|l| l.name == name) {
        Some(limit) => format!("the {} limit ({})", limit.name, limit.value),
        None => format!("the {name} limit"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_print_as_the_docs_write_them() {
        assert_eq!(Value::Count(5_000_000).to_string(), "5,000,000");
        assert_eq!(Value::Count(256).to_string(), "256");
        assert_eq!(Value::Count(1000).to_string(), "1,000");
        assert_eq!(Value::Number(1e9).to_string(), "1e9");
        assert_eq!(Value::Number(1e-9).to_string(), "1e-9");
        assert_eq!(Value::Number(1.0).to_string(), "1");
    }

    #[test]
    fn names_are_unique() {
        for (i, a) in ALL.iter().enumerate() {
            assert!(ALL[i + 1..].iter().all(|b| b.name != a.name), "{}", a.name);
        }
    }
}
