//! The bench's generated mesh cases (issue 11, issue 31): a sphere of 1,000,000 triangles
//! written as an `.obj` (500 bands of 1,000 quads, every vertex shared, so it is a closed
//! solid) with two scenes over a floor: matte (opaque, diffuse and specular: the primary and
//! shadow rays' cost) and glass (rays enter, cross and leave the mesh).

use std::fmt::Write as _;
use std::path::Path;

/// Bands from pole to pole, and quads around each: 2·SLICES·(STACKS − 1) triangles.
const STACKS: u32 = 501;
const SLICES: u32 = 1_000;

pub(super) const MATTE_SCENE: &str = "mesh1m-matte.scene";
pub(super) const GLASS_SCENE: &str = "mesh1m-glass.scene";

const SETTING: &str = "camera perspective { eye <0, 1.2, -4.5> look_at <0, 0.2, 0> fov 40 }\n\
                       light point { position <3, 6, -4> }\n\
                       plane { normal <0, 1, 0> offset -1 material { diffuse checker(rgb(0.9, 0.9, 0.9), rgb(0.2, 0.3, 0.2), 0.5) } }\n";

/// Writes `mesh1m.obj` (once: it is kept between runs) and the matte and glass scenes that
/// render it into `dir`.
pub(super) fn write(dir: &Path) -> anyhow::Result<()> {
    let obj = dir.join("mesh1m.obj");
    if !obj.exists() {
        // Under another name first, so that an interrupted run leaves no half sphere.
        let partial = dir.join("mesh1m.obj.partial");
        std::fs::write(&partial, sphere_obj(STACKS, SLICES))?;
        std::fs::rename(&partial, &obj)?;
    }
    std::fs::write(
        dir.join(MATTE_SCENE),
        format!(
            "// Written by `cargo xtask bench`: an opaque sphere of 1,000,000 triangles.\n{SETTING}\
             mesh \"ball\" {{ file \"mesh1m.obj\" material {{ diffuse <0.8, 0.3, 0.2> specular 0.5 shininess 60 }} }}\n"
        ),
    )?;
    std::fs::write(
        dir.join(GLASS_SCENE),
        format!(
            "// Written by `cargo xtask bench`: a glass sphere of 1,000,000 triangles.\n{SETTING}\
             mesh \"ball\" {{ file \"mesh1m.obj\" material {{ diffuse 0 specular 0.8 shininess 200 transmissive 0.9 reflective 0.1 ior 1.5 }} }}\n"
        ),
    )?;
    Ok(())
}

/// A unit sphere as OBJ text: poles, then rings of `slices` vertices, faces wound outward.
fn sphere_obj(stacks: u32, slices: u32) -> String {
    let mut out = String::with_capacity(64 * (stacks * slices) as usize);
    out.push_str("v 0 1 0\nv 0 -1 0\n");
    for i in 1..stacks {
        let theta = std::f64::consts::PI * f64::from(i) / f64::from(stacks);
        for j in 0..slices {
            let phi = std::f64::consts::TAU * f64::from(j) / f64::from(slices);
            let _ = writeln!(
                out,
                "v {:.7} {:.7} {:.7}",
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin()
            );
        }
    }
    // 1-based OBJ indices.
    let v = |i: u32, j: u32| 3 + (i - 1) * slices + j % slices;
    for j in 0..slices {
        let _ = writeln!(out, "f 1 {} {}", v(1, j + 1), v(1, j));
        let _ = writeln!(out, "f 2 {} {}", v(stacks - 1, j), v(stacks - 1, j + 1));
        for i in 1..stacks - 1 {
            let _ = writeln!(
                out,
                "f {} {} {} {}",
                v(i, j),
                v(i, j + 1),
                v(i + 1, j + 1),
                v(i + 1, j)
            );
        }
    }
    out
}
