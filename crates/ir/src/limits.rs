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

/// Nested calls of user functions.
pub const MAX_CALL_DEPTH: usize = 256;

/// Nested brackets `(` and `{` in source text.
pub const MAX_NESTING: usize = 256;

/// Nested imports (a file importing a file importing ...).
pub const MAX_IMPORT_DEPTH: usize = 64;

/// Source text over every file of a compilation, in bytes; reads stop at this size.
pub const MAX_SOURCE_BYTES: usize = 64 * 1024 * 1024;

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

/// Recursion depth of the tracer (`max_depth`).
pub const MAX_DEPTH: u32 = 256;

/// Nodes one recorded ray tree may hold; a tree over this is cut, and says where.
pub const MAX_RAY_TREE_NODES: usize = 100_000;

/// Estimated memory of one render (image buffers, statistics, scene), refused up front.
pub const MAX_RENDER_MEMORY_BYTES: u64 = 8 * 1024 * 1024 * 1024;

/// One limit as the docs list it.
#[derive(Clone, Copy, Debug)]
pub struct Limit {
    /// The name used in error messages and in the docs.
    pub name: &'static str,
    /// The value as the docs write it.
    pub value: u64,
    pub what: &'static str,
}

/// Every limit, in the order docs/language.md lists them.
pub const ALL: &[Limit] = &[
    Limit {
        name: "objects",
        value: MAX_OBJECTS as u64,
        what: "objects in a scene",
    },
    Limit {
        name: "evaluation steps",
        value: MAX_EVALUATION_STEPS,
        what: "loop iterations and function calls in one compilation",
    },
    Limit {
        name: "call depth",
        value: MAX_CALL_DEPTH as u64,
        what: "nested function calls",
    },
    Limit {
        name: "nesting",
        value: MAX_NESTING as u64,
        what: "nested brackets",
    },
    Limit {
        name: "import depth",
        value: MAX_IMPORT_DEPTH as u64,
        what: "nested imports",
    },
    Limit {
        name: "source size",
        value: MAX_SOURCE_BYTES as u64,
        what: "bytes of source text over every file",
    },
    Limit {
        name: "lights",
        value: MAX_LIGHTS as u64,
        what: "lights in a scene",
    },
    Limit {
        name: "materials",
        value: MAX_MATERIALS as u64,
        what: "materials in a scene",
    },
    Limit {
        name: "image side",
        value: MAX_IMAGE_SIDE as u64,
        what: "image width or height",
    },
    Limit {
        name: "pixels",
        value: MAX_PIXELS,
        what: "pixels in an image",
    },
    Limit {
        name: "samples per pixel",
        value: MAX_SAMPLES_PER_PIXEL as u64,
        what: "anti-aliasing samples per pixel",
    },
    Limit {
        name: "max depth",
        value: MAX_DEPTH as u64,
        what: "recursion depth of the tracer",
    },
    Limit {
        name: "ray tree nodes",
        value: MAX_RAY_TREE_NODES as u64,
        what: "nodes in one recorded ray tree",
    },
    Limit {
        name: "render memory",
        value: MAX_RENDER_MEMORY_BYTES,
        what: "estimated bytes of memory for one render",
    },
];
