//! One task's output on disk: its pixels (linear f32, lossless) and its manifest (JSON),
//! written atomically with the manifest last, and read back with every check the status and
//! the merge need.
//!
//! A part of task I of N is two files in the parts folder: `part-IIII-of-NNNN.f32` (the
//! magic `WHTPIX01`, the width and height as little-endian u32, then the pixels as
//! little-endian f32 RGB, row-major) and `part-IIII-of-NNNN.json` (a [`Manifest`]). The
//! pixels go first: a task killed at any point leaves no manifest, or the old one whose
//! checksum no longer matches, so nothing half-written looks complete.

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use whitted_tracer::PixelRect;

/// The first bytes of a pixels file.
const MAGIC: &[u8; 8] = b"WHTPIX01";

/// The manifest's format version; a part of another format is stale.
pub const MANIFEST_FORMAT: u32 = 1;

/// What a task rendered, from what, and how to check its pixels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub format: u32,
    /// `CARGO_PKG_VERSION` of the whitted that rendered the part.
    pub whitted_version: String,
    /// The scene file, as the task was given it (absolute).
    pub scene: String,
    /// SHA-256 of the scene's sources (the file and its imports) and of the compiled IR,
    /// settings and overrides included (see `fingerprint`).
    pub scene_hash: String,
    /// SHA-256 of the effective settings alone, to say which of the two changed.
    pub settings_hash: String,
    /// The effective settings (size, samples, filter, ...), for people reading the file.
    pub settings: serde_json::Value,
    /// This task's index, from 0.
    pub task: u32,
    /// How many tasks the render was split into.
    pub tasks: u32,
    /// The frame of an animation this part belongs to; none for a still.
    #[serde(default)]
    pub frame: Option<u32>,
    /// The whole image's size.
    pub image_width: u32,
    pub image_height: u32,
    /// The pixels this part holds, in the whole image's coordinates.
    pub region: Region,
    /// The pixels file's name, beside the manifest.
    pub pixels_file: String,
    /// `sha256:` and the hex digest of the whole pixels file.
    pub checksum: String,
    /// Rays traced and seconds spent on the part, for the record.
    pub rays: u64,
    pub render_seconds: f64,
}

/// A rectangle of pixels in the manifest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Region {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

impl From<PixelRect> for Region {
    fn from(r: PixelRect) -> Self {
        Region {
            x: r.x,
            y: r.y,
            width: r.width,
            height: r.height,
        }
    }
}

impl From<Region> for PixelRect {
    fn from(r: Region) -> Self {
        PixelRect {
            x: r.x,
            y: r.y,
            width: r.width,
            height: r.height,
        }
    }
}

/// The base name of task `task` of `tasks`' files (for one frame of an animation).
pub fn part_stem(task: u32, tasks: u32, frame: Option<u32>) -> String {
    match frame {
        None => format!("part-{task:04}-of-{tasks:04}"),
        Some(frame) => format!("part-{task:04}-of-{tasks:04}-frame-{frame:06}"),
    }
}

pub fn manifest_path(parts: &Path, task: u32, tasks: u32, frame: Option<u32>) -> PathBuf {
    parts.join(format!("{}.json", part_stem(task, tasks, frame)))
}

/// The hex SHA-256 of `bytes`, prefixed `sha256:`.
pub fn checksum(bytes: &[u8]) -> String {
    format!("sha256:{}", hex(&Sha256::digest(bytes)))
}

pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The pixels file's bytes for a `width` x `height` block of linear RGB.
pub fn encode_pixels(width: u32, height: u32, pixels: &[[f32; 3]]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(16 + pixels.len() * 12);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&width.to_le_bytes());
    bytes.extend_from_slice(&height.to_le_bytes());
    for channel in pixels.iter().flatten() {
        bytes.extend_from_slice(&channel.to_le_bytes());
    }
    bytes
}

/// The pixels of a pixels file, or why it is not one.
pub fn decode_pixels(bytes: &[u8]) -> Result<(u32, u32, Vec<[f32; 3]>), String> {
    let header = bytes
        .get(..16)
        .ok_or("the file is shorter than its header")?;
    if &header[..8] != MAGIC {
        return Err("the file does not start with WHTPIX01".into());
    }
    let word = |at: usize| {
        u32::from_le_bytes([header[at], header[at + 1], header[at + 2], header[at + 3]])
    };
    let (width, height) = (word(8), word(12));
    let expected = u64::from(width) * u64::from(height) * 12;
    let body = &bytes[16..];
    if body.len() as u64 != expected {
        return Err(format!(
            "a {width}x{height} block needs {expected} bytes of pixels, the file has {}",
            body.len()
        ));
    }
    let pixels = body
        .chunks_exact(12)
        .map(|p| {
            let f = |at: usize| f32::from_le_bytes([p[at], p[at + 1], p[at + 2], p[at + 3]]);
            [f(0), f(4), f(8)]
        })
        .collect();
    Ok((width, height, pixels))
}

/// Writes `bytes` to `path` through a temporary file in the same folder, renamed over it
/// only once complete and synced (with the permissions any written image gets).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), String> {
    crate::image_output::write_atomically(path, |file| {
        file.write_all(bytes).map_err(|e| e.to_string())
    })
}

/// Writes a part: the pixels, then the manifest (with the pixels' checksum filled in).
pub fn write_part(
    parts: &Path,
    mut manifest: Manifest,
    pixels: &[[f32; 3]],
) -> Result<Manifest, String> {
    let stem = part_stem(manifest.task, manifest.tasks, manifest.frame);
    let bytes = encode_pixels(manifest.region.width, manifest.region.height, pixels);
    manifest.pixels_file = format!("{stem}.f32");
    manifest.checksum = checksum(&bytes);
    // An old manifest goes first: a task killed from here on leaves its part missing,
    // rather than an old manifest over new pixels (which would read as corrupt).
    let manifest_file = manifest_path(parts, manifest.task, manifest.tasks, manifest.frame);
    match std::fs::remove_file(&manifest_file) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(format!("cannot replace {}: {e}", manifest_file.display())),
    }
    write_atomically(&parts.join(&manifest.pixels_file), &bytes)?;
    drop(bytes);
    let mut json = serde_json::to_vec_pretty(&manifest).map_err(|e| e.to_string())?;
    json.push(b'\n');
    write_atomically(&manifest_file, &json)?;
    Ok(manifest)
}

/// What the parts folder holds for one task.
#[derive(Debug)]
pub enum PartState {
    /// No manifest (or no pixels file beside it).
    Missing,
    /// A manifest that cannot be read, or pixels that do not match their checksum.
    Corrupt(String),
    /// A readable part whose pixels match their checksum; the pixels, when asked for.
    Intact(Box<Manifest>, Option<Vec<[f32; 3]>>),
}

/// Reads task `task` of `tasks`' part (of `frame`, for an animation) and checks its
/// checksum and shape; keeps the pixels when `keep_pixels`.
pub fn read_part(
    parts: &Path,
    task: u32,
    tasks: u32,
    frame: Option<u32>,
    keep_pixels: bool,
) -> PartState {
    let path = manifest_path(parts, task, tasks, frame);
    let text = match std::fs::read(&path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return PartState::Missing,
        Err(e) => return PartState::Corrupt(format!("cannot read {}: {e}", path.display())),
    };
    let manifest: Manifest = match serde_json::from_slice(&text) {
        Ok(manifest) => manifest,
        Err(e) => {
            return PartState::Corrupt(format!("{} is not a part manifest: {e}", path.display()))
        }
    };
    if manifest.task != task || manifest.tasks != tasks || manifest.frame != frame {
        return PartState::Corrupt(format!(
            "{} says it is task {}/{}{}",
            path.display(),
            manifest.task,
            manifest.tasks,
            manifest
                .frame
                .map_or_else(String::new, |f| format!(" of frame {f}"))
        ));
    }
    // The manifest names a file beside it, never a path elsewhere.
    if Path::new(&manifest.pixels_file).file_name() != Some(manifest.pixels_file.as_ref()) {
        return PartState::Corrupt(format!(
            "{} names a pixels file outside the folder: {}",
            path.display(),
            manifest.pixels_file
        ));
    }
    let pixels_path = parts.join(&manifest.pixels_file);
    let bytes = match std::fs::read(&pixels_path) {
        Ok(bytes) => bytes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return PartState::Missing,
        Err(e) => return PartState::Corrupt(format!("cannot read {}: {e}", pixels_path.display())),
    };
    if checksum(&bytes) != manifest.checksum {
        return PartState::Corrupt(format!(
            "{} does not match the checksum in its manifest",
            pixels_path.display()
        ));
    }
    match decode_pixels(&bytes) {
        Ok((width, height, pixels)) => {
            if (width, height) != (manifest.region.width, manifest.region.height) {
                return PartState::Corrupt(format!(
                    "{} holds {width}x{height} pixels, its manifest says {}x{}",
                    pixels_path.display(),
                    manifest.region.width,
                    manifest.region.height
                ));
            }
            PartState::Intact(Box::new(manifest), keep_pixels.then_some(pixels))
        }
        Err(e) => PartState::Corrupt(format!("{}: {e}", pixels_path.display())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_survive_the_round_trip_bit_for_bit() {
        let pixels = vec![[0.1f32, -0.0, f32::MAX], [1.5, f32::MIN_POSITIVE, 3.25e-8]];
        let bytes = encode_pixels(2, 1, &pixels);
        let (w, h, back) = decode_pixels(&bytes).unwrap();
        assert_eq!((w, h), (2, 1));
        let bits = |p: &[[f32; 3]]| p.iter().flatten().map(|c| c.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back), bits(&pixels));
        assert!(decode_pixels(&bytes[..bytes.len() - 1]).is_err());
        assert!(decode_pixels(b"WHTPIX0").is_err());
        assert!(decode_pixels(b"NOTPIXELS0000000").is_err());
    }
}
