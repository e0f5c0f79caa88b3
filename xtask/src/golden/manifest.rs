//! The golden manifest (tests/golden/manifest.toml): which scenes are golden, at what size,
//! with which thresholds, and which pixels have their ray trees stored.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use serde::Deserialize;

/// Pass/fail bounds for one scene, in the manner of Blender's render tests.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Thresholds {
    /// A pixel counts as different when a channel differs by more than this (0..1, sRGB).
    pub pixel_tolerance: f64,
    /// The scene fails when more than this share of pixels is different.
    pub max_failing_share: f64,
    /// The scene fails when the mean FLIP error is above this.
    pub max_mean_flip: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds {
            pixel_tolerance: 0.02,
            max_failing_share: 0.002,
            max_mean_flip: 0.02,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDefaults {
    width: Option<u32>,
    height: Option<u32>,
    pixel_tolerance: Option<f64>,
    max_failing_share: Option<f64>,
    max_mean_flip: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    name: String,
    path: PathBuf,
    width: Option<u32>,
    height: Option<u32>,
    #[serde(default)]
    defines: Vec<String>,
    pixel_tolerance: Option<f64>,
    max_failing_share: Option<f64>,
    max_mean_flip: Option<f64>,
    #[serde(default)]
    pixels: Vec<[u32; 2]>,
    course: Option<Vec<String>>,
    frame: Option<u32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawManifest {
    defaults: Option<RawDefaults>,
    #[serde(default)]
    scene: Vec<RawScene>,
    /// Scenes under the scene folder that are deliberately not golden, with the reason.
    #[serde(default)]
    exclude: Vec<Exclusion>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Exclusion {
    pub path: PathBuf,
    pub reason: String,
}

/// One golden scene, with every default filled in.
#[derive(Clone, Debug, PartialEq)]
pub struct GoldenScene {
    pub name: String,
    /// The scene file, relative to the workspace root (or absolute).
    pub path: PathBuf,
    pub width: u32,
    pub height: u32,
    pub defines: Vec<String>,
    pub thresholds: Thresholds,
    /// Pixels (at the golden size) whose ray trees are stored beside the image.
    pub pixels: Vec<[u32; 2]>,
    /// For a MIT 6.837 scene, the course's flags (`["-shadows", "-bounces", "4"]`): the
    /// reference is what `whitted mit6837 -input PATH -size W H -output OUT FLAGS` writes
    /// (8-bit linear, as the course's images). `None`: `whitted render`.
    pub course: Option<Vec<String>>,
    /// For an animated scene, the frame rendered (`whitted render --frame N`).
    pub frame: Option<u32>,
}

#[derive(Debug)]
pub struct Manifest {
    pub scenes: Vec<GoldenScene>,
    pub exclusions: Vec<Exclusion>,
}

pub const DEFAULT_WIDTH: u32 = 160;
pub const DEFAULT_HEIGHT: u32 = 120;

pub fn parse(text: &str, origin: &Path) -> anyhow::Result<Manifest> {
    let raw: RawManifest =
        toml::from_str(text).with_context(|| format!("cannot read {}", origin.display()))?;
    let defaults = raw.defaults.unwrap_or(RawDefaults {
        width: None,
        height: None,
        pixel_tolerance: None,
        max_failing_share: None,
        max_mean_flip: None,
    });
    let base = Thresholds::default();
    let mut scenes = Vec::new();
    for s in raw.scene {
        if s.name.is_empty()
            || !s
                .name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        {
            bail!(
                "{}: golden name `{}` must be letters, digits, - or _",
                origin.display(),
                s.name
            );
        }
        if scenes.iter().any(|g: &GoldenScene| g.name == s.name) {
            bail!(
                "{}: the golden name `{}` is used twice",
                origin.display(),
                s.name
            );
        }
        let width = s.width.or(defaults.width).unwrap_or(DEFAULT_WIDTH);
        let height = s.height.or(defaults.height).unwrap_or(DEFAULT_HEIGHT);
        if s.course.is_some() && s.frame.is_some() {
            bail!(
                "{}: `{}` is rendered by the course's command line, which has no frames: \
                 leave out `frame`",
                origin.display(),
                s.name
            );
        }
        if s.course.is_some() && !s.pixels.is_empty() {
            bail!(
                "{}: `{}` is rendered by the course's command line, which has no ray trees: \
                 leave out `pixels`",
                origin.display(),
                s.name
            );
        }
        for [x, y] in &s.pixels {
            if *x >= width || *y >= height {
                bail!(
                    "{}: pixel {x},{y} of `{}` is outside its {width}x{height} image",
                    origin.display(),
                    s.name
                );
            }
        }
        scenes.push(GoldenScene {
            name: s.name,
            path: s.path,
            width,
            height,
            defines: s.defines,
            thresholds: Thresholds {
                pixel_tolerance: s
                    .pixel_tolerance
                    .or(defaults.pixel_tolerance)
                    .unwrap_or(base.pixel_tolerance),
                max_failing_share: s
                    .max_failing_share
                    .or(defaults.max_failing_share)
                    .unwrap_or(base.max_failing_share),
                max_mean_flip: s
                    .max_mean_flip
                    .or(defaults.max_mean_flip)
                    .unwrap_or(base.max_mean_flip),
            },
            pixels: s.pixels,
            course: s.course,
            frame: s.frame,
        });
    }
    Ok(Manifest {
        scenes,
        exclusions: raw.exclude,
    })
}

/// A manifest for a user's folder without one: every scene in it, with the defaults.
pub fn from_folder(scenes_dir: &Path) -> anyhow::Result<Manifest> {
    let mut scenes = Vec::new();
    for path in scene_files(scenes_dir)? {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        scenes.push(GoldenScene {
            name,
            path,
            width: DEFAULT_WIDTH,
            height: DEFAULT_HEIGHT,
            defines: Vec::new(),
            thresholds: Thresholds::default(),
            pixels: Vec::new(),
            course: None,
            frame: None,
        });
    }
    Ok(Manifest {
        scenes,
        exclusions: Vec::new(),
    })
}

/// The `.scene` files and MIT 6.837 scenes (`.txt` files whose first word is a 6.837
/// keyword) directly inside `dir`, sorted (no recursion: subfolders such as scenes/bench/
/// are not golden).
pub fn scene_files(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("cannot list {}", dir.display()))? {
        let path = entry?.path();
        if path.is_file()
            && (path.extension().is_some_and(|e| e == "scene") || is_course_scene(&path))
        {
            files.push(path);
        }
    }
    files.sort();
    Ok(files)
}

/// A `.txt` file that is a MIT 6.837 scene.
fn is_course_scene(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "txt")
        && std::fs::read(path).is_ok_and(|bytes| whitted_mit6837::is_mit6837(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_fill_in_and_scene_values_win() {
        let text = r#"
            [defaults]
            width = 100
            max_mean_flip = 0.05
            [[scene]]
            name = "a"
            path = "scenes/a.scene"
            pixels = [[1, 2]]
            [[scene]]
            name = "b"
            path = "scenes/b.scene"
            height = 50
            # b has fine noise, so it may differ a little more.
            max_failing_share = 0.01
        "#;
        let manifest = parse(text, Path::new("m.toml")).unwrap();
        let a = &manifest.scenes[0];
        assert_eq!((a.width, a.height), (100, DEFAULT_HEIGHT));
        assert_eq!(a.thresholds.max_mean_flip, 0.05);
        assert_eq!(a.pixels, vec![[1, 2]]);
        let b = &manifest.scenes[1];
        assert_eq!(b.height, 50);
        assert_eq!(b.thresholds.max_failing_share, 0.01);
        assert_eq!(
            b.thresholds.pixel_tolerance,
            Thresholds::default().pixel_tolerance
        );
    }

    #[test]
    fn bad_manifests_are_refused() {
        let dup = "[[scene]]\nname='a'\npath='x'\n[[scene]]\nname='a'\npath='y'\n";
        assert!(parse(dup, Path::new("m")).is_err());
        let outside = "[[scene]]\nname='a'\npath='x'\nwidth=10\nheight=10\npixels=[[10,0]]\n";
        assert!(parse(outside, Path::new("m")).is_err());
        let typo = "[[scene]]\nname='a'\npath='x'\nwidht=10\n";
        assert!(parse(typo, Path::new("m")).is_err());
    }
}
