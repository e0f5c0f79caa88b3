//! Metamorphic image tests (issue 9, deliver 1c): relations between two renders that must
//! hold whatever the right pixels are, checked on seeded random scenes and on the hand-made
//! cases that broke them. They trust no output of the tracer, only the relation:
//!
//! (a) objects no ray can reach (below an opaque floor) change no pixel, bit for bit;
//! (b) mirroring the scene (x -> -x everywhere) mirrors the image left to right;
//! (c) a fully clear ior-1 solid (kt = 1, nothing else) renders as if absent, and a tinted
//!     ior-1 box filters shadows as the same box built from twelve triangles does (each
//!     surface a shadow ray crosses filters it, exactly as for camera rays);
//! (d) raising max_depth changes only pixels whose ray tree was cut by max_depth;
//! (e) moving the whole scene and camera far away changes no pixel beyond the error that
//!     the move itself implies (f32 has fewer digits there): no acne, no holes.
// A program, not a library: it prints its results and sets its exit status.
#![allow(clippy::print_stdout, clippy::print_stderr, clippy::exit)]

use whitted_ir::{
    Attenuation, Color, DMat4, DVec3, Fresnel, Light, LightKind, Material, ShadowMode, Shape,
};
use whitted_tracer::testing::SceneBuilder;
use whitted_tracer::{
    render, render_with_pixel_stats, NoObserver, PixelStats, PreparedScene, RenderOptions,
    Termination,
};

const WIDTH: u32 = 48;
const HEIGHT: u32 = 36;

/// splitmix64: a tiny seeded generator, so every scene is reproducible from its seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, low: f64, high: f64) -> f64 {
        low + (high - low) * self.unit()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
}

/// A scene as plain parts, so that it can be transformed before it is built.
#[derive(Clone, Debug)]
struct Spec {
    eye: DVec3,
    look_at: DVec3,
    fov: f64,
    lights: Vec<Light>,
    materials: Vec<Material>,
    /// Shapes with the index of their material.
    objects: Vec<(Shape, usize)>,
    shadows: ShadowMode,
    max_depth: u32,
    /// Every object is placed under this translation (camera and lights are moved by the
    /// caller): the whole scene moved at once.
    shift: DVec3,
}

impl Spec {
    fn build(&self) -> PreparedScene {
        let mut b = SceneBuilder::new();
        b.settings().max_depth = self.max_depth;
        b.settings().shadows = self.shadows;
        b.settings().background = Color::new(0.2, 0.3, 0.5);
        b.settings().ambient = Color::gray(0.5);
        b.camera(self.eye, self.look_at, self.fov);
        for light in &self.lights {
            b.light(light.clone());
        }
        let handles: Vec<_> = self
            .materials
            .iter()
            .map(|m| b.material(m.clone()))
            .collect();
        for (shape, material) in &self.objects {
            b.add(
                shape.clone(),
                DMat4::from_translation(self.shift),
                handles[*material],
            );
        }
        b.prepare()
            .unwrap_or_else(|message| panic!("invalid scene {message}: {self:?}"))
    }

    fn material(&mut self, m: Material) -> usize {
        self.materials.push(m);
        self.materials.len() - 1
    }
}

fn matte(r: f64, g: f64, b: f64) -> Material {
    Material {
        ambient: Color::gray(0.1),
        diffuse: Color::new(r, g, b),
        ..Material::default()
    }
}

fn random_material(rng: &mut Rng, reflective: bool, glass: bool) -> Material {
    let mut m = matte(
        rng.range(0.1, 0.9),
        rng.range(0.1, 0.9),
        rng.range(0.1, 0.9),
    );
    if rng.chance(0.5) {
        m.specular = Color::gray(rng.range(0.2, 0.8));
        m.shininess = [8.0, 40.0, 120.0][rng.below(3)];
    }
    match rng.below(3) {
        1 if reflective => m.reflective = Color::gray(rng.range(0.2, 0.6)),
        2 if glass => {
            m.diffuse = Color::gray(0.05);
            m.ambient = Color::BLACK;
            m.reflective = Color::gray(0.1);
            m.transmissive = Color::new(rng.range(0.5, 0.85), 0.8, rng.range(0.5, 0.85));
            m.ior = rng.range(1.2, 1.8);
            m.fresnel = if rng.chance(0.5) {
                Fresnel::Schlick
            } else {
                Fresnel::Off
            };
        }
        _ => {}
    }
    m
}

/// A zero of either sign: -0.0 and +0.0 take different paths in ray-box slab tests.
fn signed_zero(rng: &mut Rng) -> f64 {
    if rng.chance(0.5) {
        0.0
    } else {
        -0.0
    }
}

/// Straight down (with zeros of either sign) half of the time: the edge cases of ray-box
/// tests.
fn random_light(rng: &mut Rng) -> Light {
    let color = Color::gray(rng.range(0.4, 0.9));
    let position = DVec3::new(
        rng.range(-5.0, 5.0),
        rng.range(4.0, 9.0),
        rng.range(-6.0, 3.0),
    );
    let down = if rng.chance(0.5) {
        DVec3::new(signed_zero(rng), -1.0, signed_zero(rng))
    } else {
        DVec3::new(rng.range(-0.6, 0.6), -1.0, rng.range(-0.6, 0.6))
    };
    let kind = match rng.below(3) {
        0 => LightKind::Point {
            position,
            attenuation: if rng.chance(0.5) {
                Attenuation::NONE
            } else {
                Attenuation {
                    constant: 1.0,
                    linear: 0.05,
                    quadratic: 0.01,
                }
            },
        },
        1 => LightKind::Directional { direction: down },
        _ => LightKind::Spot {
            position,
            direction: down,
            inner_angle_degrees: 20.0,
            outer_angle_degrees: 35.0,
            attenuation: Attenuation::NONE,
        },
    };
    Light {
        name: None,
        color,
        kind,
    }
}

/// A shape resting above the floor (y = 0), inside x ∈ [-3, 3], z ∈ [-1, 4].
fn random_shape(rng: &mut Rng, solid_only: bool) -> Shape {
    let x = rng.range(-3.0, 3.0);
    let z = rng.range(-1.0, 4.0);
    let size = rng.range(0.3, 1.0);
    let kinds = if solid_only { 3 } else { 5 };
    match rng.below(kinds) {
        0 => Shape::Sphere {
            center: DVec3::new(x, size + rng.range(0.01, 1.0), z),
            radius: size,
        },
        1 => {
            let min = DVec3::new(x, rng.range(0.01, 0.5), z);
            Shape::Box {
                min,
                max: min + DVec3::new(size, rng.range(0.3, 1.5), rng.range(0.3, 1.0)),
            }
        }
        2 => {
            let base = DVec3::new(x, rng.range(0.01, 0.3), z);
            Shape::Cylinder {
                base,
                apex: base + DVec3::new(0.0, rng.range(0.5, 1.5), 0.0),
                radius: size * 0.6,
                capped: true,
            }
        }
        3 => {
            let a = DVec3::new(x, rng.range(0.2, 1.5), z);
            Shape::Triangle {
                a,
                b: a + DVec3::new(size, rng.range(-0.2, 0.2), rng.range(-0.5, 0.5)),
                c: a + DVec3::new(rng.range(-0.3, 0.3), size, rng.range(-0.5, 0.5)),
            }
        }
        _ => Shape::Disk {
            center: DVec3::new(x, rng.range(0.5, 1.5), z),
            normal: DVec3::new(rng.range(-1.0, 1.0), 1.0, rng.range(-1.0, 1.0)),
            radius: size,
        },
    }
}

fn floor() -> Shape {
    Shape::Plane {
        normal: DVec3::Y,
        offset: 0.0,
    }
}

/// A random scene: an opaque floor, `objects` shapes over it, one to three lights. Half of
/// the cameras sit on the x = 0 plane (their rays then have ±0 components).
fn random_scene(seed: u64, objects: usize, reflective: bool, glass: bool) -> Spec {
    let mut rng = Rng(seed);
    let centred = rng.chance(0.5);
    let eye_x = if centred { 0.0 } else { rng.range(-3.0, 3.0) };
    let mut spec = Spec {
        eye: DVec3::new(eye_x, rng.range(2.0, 5.0), rng.range(-9.0, -6.0)),
        look_at: DVec3::new(eye_x * 0.3, rng.range(0.3, 1.0), rng.range(0.0, 1.5)),
        fov: rng.range(40.0, 55.0),
        lights: (0..1 + rng.below(3))
            .map(|_| random_light(&mut rng))
            .collect(),
        materials: Vec::new(),
        objects: Vec::new(),
        shadows: ShadowMode::Opaque,
        max_depth: 6,
        shift: DVec3::ZERO,
    };
    let floor_material = matte(0.8, 0.8, 0.7);
    let floor_material = spec.material(floor_material);
    spec.objects.push((floor(), floor_material));
    for _ in 0..objects {
        let shape = random_shape(&mut rng, false);
        let m = random_material(&mut rng, reflective, glass);
        let m = spec.material(m);
        spec.objects.push((shape, m));
    }
    spec
}

/// The case of issue 9: a directional light straight down (`direction`), a ball over a
/// floor, and enough other objects (`others`) for the BVH to be used.
fn straight_down_light(others: usize, direction: DVec3) -> Spec {
    let mut spec = Spec {
        eye: DVec3::new(0.0, 3.0, -6.0),
        look_at: DVec3::new(0.0, 0.5, 0.0),
        fov: 45.0,
        lights: vec![Light {
            name: None,
            color: Color::WHITE,
            kind: LightKind::Directional { direction },
        }],
        materials: Vec::new(),
        objects: Vec::new(),
        shadows: ShadowMode::Opaque,
        max_depth: 5,
        shift: DVec3::ZERO,
    };
    let floor_material = spec.material(matte(0.8, 0.8, 0.8));
    let ball = spec.material(matte(0.8, 0.2, 0.2));
    spec.objects.push((floor(), floor_material));
    spec.objects.push((
        Shape::Sphere {
            center: DVec3::new(0.3, 1.0, 0.0),
            radius: 0.7,
        },
        ball,
    ));
    for i in 0..others {
        spec.objects.push((
            Shape::Sphere {
                center: DVec3::new(-3.0 + i as f64 * 0.4, 0.2, 3.0),
                radius: 0.15,
            },
            ball,
        ));
    }
    spec
}

fn options(max_depth: u32) -> RenderOptions {
    RenderOptions {
        width: WIDTH,
        height: HEIGHT,
        samples_per_pixel: 1,
        max_depth,
        min_weight: 0.001,
    }
}

fn image(spec: &Spec) -> Vec<[f32; 3]> {
    let scene = spec.build();
    render(&scene, &options(spec.max_depth), &NoObserver)
        .unwrap_or_else(|| panic!("cancelled"))
        .0
        .pixels
}

fn bits(pixels: &[[f32; 3]]) -> Vec<u32> {
    pixels.iter().flatten().map(|v| v.to_bits()).collect()
}

/// Pixels that differ by more than `tolerance` (relative to the larger of 1 and the value),
/// after mapping pixel `i` of `a` to pixel `map(i)` of `b`.
fn differing(
    a: &[[f32; 3]],
    b: &[[f32; 3]],
    tolerance: f32,
    map: impl Fn(usize) -> usize,
) -> Vec<usize> {
    (0..a.len())
        .filter(|&i| {
            let (p, q) = (a[i], b[map(i)]);
            (0..3).any(|c| {
                let scale = p[c].abs().max(q[c].abs()).max(1.0);
                // NaN differs from everything.
                let close = (p[c] - q[c]).abs() <= tolerance * scale;
                !close
            })
        })
        .collect()
}

fn xy(i: usize) -> (usize, usize) {
    (i % WIDTH as usize, i / WIDTH as usize)
}

// ---------------------------------------------------------------------------------------
// (a) Unreachable objects change no pixel.

/// Adds `count` objects of every kind below the floor, far from anything a ray can reach: the
/// floor is an opaque infinite plane and everything else (camera, lights, objects) is above
/// it, so every ray that goes down stops on the floor first.
fn with_unreachable_objects(spec: &Spec, seed: u64, count: usize) -> Spec {
    let mut rng = Rng(seed ^ 0xa5a5);
    let mut more = spec.clone();
    let hidden = more.material(matte(1.0, 0.0, 1.0));
    for _ in 0..count {
        let shape = random_shape(&mut rng, false);
        let depth = rng.range(50.0, 1000.0);
        let scale = rng.range(1.0, 40.0);
        // Scaled and pushed down: every point of the shape stays far below y = 0.
        let moved = match shape {
            Shape::Sphere { center, radius } => Shape::Sphere {
                center: center * scale - DVec3::Y * (depth + radius * scale + center.y * scale),
                radius: radius * scale,
            },
            Shape::Box { min, max } => Shape::Box {
                min: min * scale - DVec3::Y * (depth + max.y * scale),
                max: max * scale - DVec3::Y * (depth + max.y * scale),
            },
            other => {
                // Other kinds: a sphere far below, behind the camera.
                let _ = other;
                Shape::Sphere {
                    center: DVec3::new(0.0, -depth, -depth),
                    radius: scale,
                }
            }
        };
        more.objects.push((moved, hidden));
    }
    more
}

fn check_unreachable(spec: &Spec, seed: u64, count: usize) -> Result<(), String> {
    let before = image(spec);
    let after = image(&with_unreachable_objects(spec, seed, count));
    if bits(&before) == bits(&after) {
        return Ok(());
    }
    let changed = differing(&before, &after, 0.0, |i| i);
    Err(format!(
        "adding {count} unreachable objects changed {} pixels, first at {:?}: {:?} -> {:?}",
        changed.len(),
        xy(changed[0]),
        before[changed[0]],
        after[changed[0]]
    ))
}

#[test]
fn unreachable_objects_change_no_pixel_on_random_scenes() {
    let mut failures = Vec::new();
    for seed in 0..24u64 {
        let spec = random_scene(seed, 1 + (seed % 4) as usize, true, true);
        // 4 objects go to the BVH when the few-object list is full; 30 make a real tree.
        for count in [2, 30] {
            if let Err(e) = check_unreachable(&spec, seed, count) {
                failures.push(format!("seed {seed}: {e}"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The issue-9 scene: four objects are tested one by one; with unreachable objects added
/// the BVH is used, and (before the -0.0 fix) the ball's shadow under the straight-down
/// light vanished.
#[test]
fn unreachable_objects_keep_the_shadow_of_a_straight_down_light() {
    let spec = straight_down_light(3, DVec3::new(0.0, -1.0, 0.0));
    if let Err(e) = check_unreachable(&spec, 7, 4) {
        panic!("{e}");
    }
}

// ---------------------------------------------------------------------------------------
// (b) Mirroring the scene mirrors the image.

fn mirror(v: DVec3) -> DVec3 {
    DVec3::new(-v.x, v.y, v.z)
}

fn mirror_shape(shape: &Shape) -> Shape {
    match shape {
        // Symmetric about x = 0 already.
        Shape::Torus { major, minor } => Shape::Torus {
            major: *major,
            minor: *minor,
        },
        Shape::Sphere { center, radius } => Shape::Sphere {
            center: mirror(*center),
            radius: *radius,
        },
        Shape::Plane { normal, offset } => Shape::Plane {
            normal: mirror(*normal),
            offset: *offset,
        },
        Shape::Box { min, max } => Shape::Box {
            min: DVec3::new(-max.x, min.y, min.z),
            max: DVec3::new(-min.x, max.y, max.z),
        },
        Shape::Cylinder {
            base,
            apex,
            radius,
            capped,
        } => Shape::Cylinder {
            base: mirror(*base),
            apex: mirror(*apex),
            radius: *radius,
            capped: *capped,
        },
        Shape::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
            capped,
        } => Shape::Cone {
            base: mirror(*base),
            base_radius: *base_radius,
            apex: mirror(*apex),
            apex_radius: *apex_radius,
            capped: *capped,
        },
        Shape::Disk {
            center,
            normal,
            radius,
        } => Shape::Disk {
            center: mirror(*center),
            normal: mirror(*normal),
            radius: *radius,
        },
        // Mirroring reverses the winding; a triangle has no preferred side, so keep the
        // vertices in order.
        Shape::Triangle { a, b, c } => Shape::Triangle {
            a: mirror(*a),
            b: mirror(*b),
            c: mirror(*c),
        },
        Shape::Quadric { .. } => panic!("the generator makes no quadrics"),
        Shape::Mesh { .. } => panic!("the generator makes no meshes"),
    }
}

/// `light` with its position mapped by `position` and its direction by `direction`.
fn map_light(
    light: &Light,
    position: impl Fn(DVec3) -> DVec3,
    direction: impl Fn(DVec3) -> DVec3,
) -> Light {
    let kind = match &light.kind {
        LightKind::Point {
            position: p,
            attenuation,
        } => LightKind::Point {
            position: position(*p),
            attenuation: *attenuation,
        },
        LightKind::Directional { direction: d } => LightKind::Directional {
            direction: direction(*d),
        },
        LightKind::Spot {
            position: p,
            direction: d,
            inner_angle_degrees,
            outer_angle_degrees,
            attenuation,
        } => LightKind::Spot {
            position: position(*p),
            direction: direction(*d),
            inner_angle_degrees: *inner_angle_degrees,
            outer_angle_degrees: *outer_angle_degrees,
            attenuation: *attenuation,
        },
    };
    Light {
        kind,
        ..light.clone()
    }
}

fn mirror_light(light: &Light) -> Light {
    map_light(light, mirror, mirror)
}

/// x -> -x on every object, light and the camera. The camera's basis is derived from eye,
/// look_at and up, so its right vector turns round as well: the image is flipped.
fn mirrored(spec: &Spec) -> Spec {
    Spec {
        eye: mirror(spec.eye),
        look_at: mirror(spec.look_at),
        lights: spec.lights.iter().map(mirror_light).collect(),
        objects: spec
            .objects
            .iter()
            .map(|(shape, m)| (mirror_shape(shape), *m))
            .collect(),
        ..spec.clone()
    }
}

/// How far a mirrored pixel may be from its original. The two renders differ only by
/// rounding (a mirrored pixel centre is `-u` up to an ulp, and the hit points follow), so a
/// pixel inside a surface changes by ~1e-6; a pixel whose ray grazes a silhouette or a
/// shadow edge may land on the other side and change completely. Up to `EDGE_PIXELS` such
/// pixels are allowed; a lost shadow or a missing object changes far more.
const MIRROR_TOLERANCE: f32 = 1e-3;
const EDGE_PIXELS: usize = 4;

fn check_mirror(spec: &Spec) -> Result<usize, String> {
    let original = image(spec);
    let flipped = image(&mirrored(spec));
    let w = WIDTH as usize;
    let changed = differing(&original, &flipped, MIRROR_TOLERANCE, |i| {
        let (x, y) = xy(i);
        y * w + (w - 1 - x)
    });
    if changed.len() > EDGE_PIXELS {
        let i = changed[0];
        let (x, y) = xy(i);
        return Err(format!(
            "{} pixels differ from their mirror image, first ({x}, {y}): {:?} vs {:?}",
            changed.len(),
            original[i],
            flipped[y * w + (w - 1 - x)]
        ));
    }
    Ok(changed.len())
}

#[test]
fn mirroring_a_random_scene_mirrors_its_image() {
    let mut failures = Vec::new();
    let mut edge_pixels = 0;
    for seed in 100..130u64 {
        let spec = random_scene(seed, 2 + (seed % 7) as usize, true, true);
        match check_mirror(&spec) {
            Ok(n) => edge_pixels += n,
            Err(e) => failures.push(format!("seed {seed}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    eprintln!("mirror: {edge_pixels} edge pixels over 30 scenes");
}

#[test]
fn mirroring_keeps_the_shadow_of_a_straight_down_light() {
    // Mirrored, <0, -1, -0> becomes <-0, -1, -0>: one of the two sends shadow rays with a
    // -0.0 component and one does not. With three small balls the objects are tested one by
    // one; with four or more the BVH is walked.
    let mut failures = Vec::new();
    for others in [2, 4, 8] {
        for z in [0.0, -0.0] {
            let spec = straight_down_light(others, DVec3::new(0.0, -1.0, z));
            if let Err(e) = check_mirror(&spec) {
                failures.push(format!(
                    "{others} small balls, direction <0, -1, {z:?}>: {e}"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// ---------------------------------------------------------------------------------------
// (c) Clear solids are invisible; solids filter shadows per surface.

fn clear() -> Material {
    Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        specular: Color::BLACK,
        reflective: Color::BLACK,
        transmissive: Color::WHITE,
        ior: 1.0,
        fresnel: Fresnel::Off,
        absorption: Color::BLACK,
        ..Material::default()
    }
}

/// Clear solids add two depth levels per crossing; the scene's depth is raised so that
/// only the weight cut-off ends paths (kr ≤ 0.6 reaches 0.001 within 14 bounces).
const CLEAR_DEPTH: u32 = 40;

/// A crossing moves the ray by the surface offset (1e-4) along the normal, so pixels
/// behind a clear solid may change by about that much relative; edges may flip.
const CLEAR_TOLERANCE: f32 = 2e-3;

fn check_clear(spec: &Spec, seed: u64, count: usize, shadows: ShadowMode) -> Result<usize, String> {
    let mut rng = Rng(seed ^ 0x5eed);
    let mut base = spec.clone();
    base.shadows = shadows;
    base.max_depth = CLEAR_DEPTH;
    let mut with = base.clone();
    let clear = with.material(clear());
    for _ in 0..count {
        with.objects.push((random_shape(&mut rng, true), clear));
    }
    let absent = image(&base);
    let present = image(&with);
    let changed = differing(&absent, &present, CLEAR_TOLERANCE, |i| i);
    if changed.len() > EDGE_PIXELS {
        let i = changed[0];
        return Err(format!(
            "{} clear solids changed {} pixels, first {:?}: {:?} -> {:?}",
            count,
            changed.len(),
            xy(i),
            absent[i],
            present[i]
        ));
    }
    Ok(changed.len())
}

#[test]
fn a_clear_ior_one_solid_renders_as_if_absent() {
    let mut failures = Vec::new();
    for seed in 200..224u64 {
        let spec = random_scene(seed, 1 + (seed % 6) as usize, true, false);
        if let Err(e) = check_clear(&spec, seed, 1 + (seed % 3) as usize, ShadowMode::Filtered) {
            failures.push(format!("seed {seed}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The relation has teeth: with opaque shadows the same clear solids cast black shadows,
    // and the check must see them.
    let caught = (200..224u64)
        .filter(|&seed| {
            let spec = random_scene(seed, 1 + (seed % 6) as usize, true, false);
            check_clear(&spec, seed, 1 + (seed % 3) as usize, ShadowMode::Opaque).is_err()
        })
        .count();
    assert!(
        caught >= 12,
        "opaque shadows of clear solids caught in only {caught} of 24 scenes"
    );
}

/// The twelve triangles of the box `min`..`max`.
fn box_triangles(min: DVec3, max: DVec3) -> Vec<Shape> {
    let corner = |i: usize| {
        DVec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        )
    };
    // Each face as four corner indices around it.
    let faces = [
        [0, 1, 3, 2],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 3, 7, 5],
    ];
    faces
        .iter()
        .flat_map(|f| {
            [
                Shape::Triangle {
                    a: corner(f[0]),
                    b: corner(f[1]),
                    c: corner(f[2]),
                },
                Shape::Triangle {
                    a: corner(f[0]),
                    b: corner(f[2]),
                    c: corner(f[3]),
                },
            ]
        })
        .collect()
}

/// A tinted, ior-1 box as a solid and as twelve thin triangles: camera rays are filtered at
/// each of the two surfaces they cross in both, so shadow rays must be too.
fn check_box_against_triangles(spec: &Spec, seed: u64) -> Result<usize, String> {
    let mut rng = Rng(seed ^ 0xb0c5);
    let mut solid = spec.clone();
    solid.shadows = ShadowMode::Filtered;
    solid.max_depth = CLEAR_DEPTH;
    let tint = solid.material(Material {
        transmissive: Color::new(
            rng.range(0.3, 0.9),
            rng.range(0.3, 0.9),
            rng.range(0.3, 0.9),
        ),
        ..clear()
    });
    let mut thin = solid.clone();
    let min = DVec3::new(
        rng.range(-2.0, 1.0),
        rng.range(0.05, 0.5),
        rng.range(-1.0, 2.0),
    );
    let max = min
        + DVec3::new(
            rng.range(0.5, 1.5),
            rng.range(0.5, 1.5),
            rng.range(0.5, 1.5),
        );
    solid.objects.push((Shape::Box { min, max }, tint));
    for triangle in box_triangles(min, max) {
        thin.objects.push((triangle, tint));
    }
    let a = image(&solid);
    let b = image(&thin);
    let changed = differing(&a, &b, CLEAR_TOLERANCE, |i| i);
    // Rays along a triangle's diagonal may hit both halves or neither: a few pixels.
    if changed.len() > EDGE_PIXELS {
        let i = changed[0];
        return Err(format!(
            "box and triangles differ at {} pixels, first {:?}: box {:?}, triangles {:?}",
            changed.len(),
            xy(i),
            a[i],
            b[i]
        ));
    }
    Ok(changed.len())
}

#[test]
fn a_tinted_box_filters_shadows_as_its_twelve_triangles_do() {
    let mut failures = Vec::new();
    for seed in 300..316u64 {
        let spec = random_scene(seed, (seed % 4) as usize, false, false);
        if let Err(e) = check_box_against_triangles(&spec, seed) {
            failures.push(format!("seed {seed}: {e}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// ---------------------------------------------------------------------------------------
// (d) Raising max_depth changes only pixels that max_depth cut.

fn render_stats(spec: &Spec, max_depth: u32) -> (Vec<[f32; 3]>, Vec<PixelStats>) {
    let scene = spec.build();
    let (image, _, stats) = render_with_pixel_stats(&scene, &options(max_depth), &NoObserver)
        .unwrap_or_else(|| panic!("cancelled"));
    (image.pixels, stats)
}

/// Pixels that changed between depth `low` and `high` although their tree at `low` was not
/// cut by the depth limit; and how many changed at all.
fn depth_changes(spec: &Spec, low: u32, high: u32, trust_cut: bool) -> (Vec<usize>, usize) {
    let (shallow, stats) = render_stats(spec, low);
    let (deep, _) = render_stats(spec, high);
    let changed = differing(&shallow, &deep, 0.0, |i| i);
    let uncut = changed
        .iter()
        .copied()
        .filter(|&i| !(trust_cut && stats[i].terminations.contains(Termination::MaxDepth)))
        .collect();
    (uncut, changed.len())
}

#[test]
fn raising_max_depth_changes_only_pixels_cut_by_it() {
    let mut failures = Vec::new();
    let mut changed_total = 0;
    for seed in 400..420u64 {
        let spec = random_scene(seed, 2 + (seed % 6) as usize, true, true);
        for (low, high) in [(0, 1), (1, 3), (2, 6)] {
            let (uncut, changed) = depth_changes(&spec, low, high, true);
            changed_total += changed;
            if let Some(&i) = uncut.first() {
                failures.push(format!(
                    "seed {seed}, depth {low} -> {high}: {} uncut pixels changed, first {:?}",
                    uncut.len(),
                    xy(i)
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // The relation has teeth: without the per-pixel statistics many pixels would count as
    // wrongly changed, so the test can fail.
    assert!(
        changed_total > 1000,
        "only {changed_total} pixels changed with depth"
    );
    let (uncut_without_stats, _) = depth_changes(&random_scene(401, 5, true, true), 1, 3, false);
    assert!(!uncut_without_stats.is_empty());
}

// ---------------------------------------------------------------------------------------
// (e) Moving the whole scene far away.

fn moved_light(light: &Light, by: DVec3) -> Light {
    map_light(light, |p| p + by, |d| d)
}

/// The scene, camera and lights moved by `by`.
fn moved(spec: &Spec, by: DVec3) -> Spec {
    Spec {
        eye: spec.eye + by,
        look_at: spec.look_at + by,
        lights: spec.lights.iter().map(|l| moved_light(l, by)).collect(),
        shift: spec.shift + by,
        ..spec.clone()
    }
}

/// How many pixels of the moved render may differ, in tenths of a percent per unit of
/// the move's ulp: at a distance `d` every coordinate is known to about `d·2⁻²⁴`, so edges
/// (silhouettes, shadow and checker borders, glass paths through them) move by that much
/// and the pixels they cross change; acne or holes change whole surfaces.
fn allowed_pixels(distance: f64) -> usize {
    let ulp = distance * f64::from(f32::EPSILON);
    let pixels = (WIDTH * HEIGHT) as f64;
    // One pixel in 200 at a thousand, growing with the move's ulp; never under 4.
    (pixels * (ulp / 1.2e-4 * 0.005))
        .max(4.0)
        .min(pixels * 0.05) as usize
}

fn check_moved(spec: &Spec, by: DVec3) -> Result<usize, String> {
    let original = image(spec);
    let far = image(&moved(spec, by));
    let changed = differing(&original, &far, 0.02, |i| i);
    let allowed = allowed_pixels(by.abs().max_element());
    if changed.len() > allowed {
        let i = changed[0];
        let (x, y) = xy(i);
        return Err(format!(
            "{} pixels differ (at most {allowed} allowed), first ({x}, {y}): {:?} vs {:?}",
            changed.len(),
            original[i],
            far[i]
        ));
    }
    Ok(changed.len())
}

/// Issue 26: bounds that ignore where a shape is put acne on far scenes, and a gate that
/// ignores how far a ray came opens holes; moving every random scene 1e3 and 3e4 away
/// (along every axis, and along one) keeps its image.
#[test]
fn moving_the_whole_scene_far_away_keeps_its_image() {
    let mut failures = Vec::new();
    let mut changed = 0;
    for seed in 200..215u64 {
        let spec = random_scene(seed, 3 + (seed % 6) as usize, true, true);
        for by in [
            DVec3::new(1e3, -1e3, 1e3),
            DVec3::new(3e4, 0.0, 0.0),
            DVec3::new(-2e4, 2e4, -3e4),
        ] {
            match check_moved(&spec, by) {
                Ok(n) => changed += n,
                Err(e) => failures.push(format!("seed {seed}, moved by {by}: {e}")),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    eprintln!("moved: {changed} edge pixels over 45 renders");
}
