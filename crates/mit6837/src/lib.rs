//! whitted-mit6837: the MIT 6.837 (Fall 2004) scene format as a second front end, read into
//! the same validated IR as the scene language, with spans into the `.txt` file.
//!
//! The format is whitespace-separated words with no comments (see docs/courses.md for the
//! grammar and how each construct maps onto whitted's model). The course's command-line
//! switches arrive as [`CourseOptions`] and become the scene's settings: shadows off unless
//! asked for, back faces unlit unless asked for, Blinn-Phong highlights, attenuation not
//! clamped. Mesh files (`TriangleMesh { obj_file x.obj }`) are read through a
//! [`MeshLoader`] that the caller provides: the library reads no files itself.

mod convert;
mod mesh;
mod objects;
mod procedural;
mod reader;
mod tokens;

#[cfg(test)]
mod procedural_tests;
#[cfg(test)]
mod tests;

use std::path::Path;

use whitted_ir::{Diagnostic, SourceMap, ValidScene};

pub use convert::convert;

/// Reads the `.obj` files a scene names. Paths are already joined onto the scene file's
/// folder.
pub trait MeshLoader {
    fn load(&mut self, path: &Path) -> std::io::Result<Vec<u8>>;
}

/// The course's command-line switches (`-shadows`, `-bounces N`, ...), as settings of the
/// scene. The defaults are the course's defaults without the switch.
#[derive(Clone, Debug, PartialEq)]
pub struct CourseOptions {
    /// `-size W H`.
    pub width: u32,
    pub height: u32,
    /// `-shadows`: cast shadow rays (opaque blockers).
    pub shadows: bool,
    /// `-transparent_shadows`: shadow rays pass through transparent objects, tinted by
    /// their `transparentColor` (implies shadows).
    pub transparent_shadows: bool,
    /// `-shade_back`: light a surface seen from its back with its normal turned.
    pub shade_back: bool,
    /// `-bounces N`: reflected and refracted rays up to this depth (0: none).
    pub bounces: u32,
    /// `-weight W`: rays contributing less than this are not traced.
    pub weight: f64,
    /// `-uniform_samples N`, `-jittered_samples N` or `-random_samples N` (assignment 7):
    /// samples per pixel and where they fall.
    pub samples: u32,
    pub sampling: whitted_ir::Sampling,
    /// Where a pixel's sample falls (the handouts do not say; whitted's flag
    /// `-sample_position corner` picks the corner).
    pub sample_position: whitted_ir::SamplePosition,
    /// `-box_filter R`, `-tent_filter R` or `-gaussian_filter SIGMA` (assignment 7): the
    /// filter and its radius (σ for the gaussian).
    pub filter: whitted_ir::Filter,
    pub filter_radius: f64,
}

impl Default for CourseOptions {
    fn default() -> Self {
        CourseOptions {
            width: 512,
            height: 512,
            shadows: false,
            transparent_shadows: false,
            shade_back: false,
            bounces: 0,
            weight: 0.0,
            samples: 1,
            sampling: whitted_ir::Sampling::Jittered,
            sample_position: whitted_ir::SamplePosition::Centre,
            filter: whitted_ir::Filter::Box,
            filter_radius: 0.5,
        }
    }
}

/// What a conversion produced: every file read, the scene when there were no errors, and
/// the diagnostics (located in `sources`).
#[derive(Debug)]
pub struct Conversion {
    pub sources: SourceMap,
    pub scene: Option<ValidScene>,
    pub diagnostics: Vec<Diagnostic>,
}

impl Conversion {
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}

/// The words a 6.837 scene file can start with.
pub const TOP_LEVEL_KEYWORDS: &[&str] = &[
    "OrthographicCamera",
    "PerspectiveCamera",
    "Background",
    "Lights",
    "Materials",
    "Group",
];

/// Whether `bytes` look like a 6.837 scene: the first word is one of
/// [`TOP_LEVEL_KEYWORDS`]. (No word of the scene language starts a file that way: its
/// keywords are lower case.)
pub fn is_mit6837(bytes: &[u8]) -> bool {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    let rest = &bytes[start..];
    let end = rest
        .iter()
        .position(|b| b.is_ascii_whitespace() || *b == b'{')
        .unwrap_or(rest.len());
    TOP_LEVEL_KEYWORDS
        .iter()
        .any(|k| k.as_bytes() == &rest[..end])
}
