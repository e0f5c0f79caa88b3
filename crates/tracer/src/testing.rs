//! Scene building in Rust, for tests, benchmarks and small fixed renders (the language
//! server's material thumbnails) that cannot (or should not) go through the scene language:
//! a small builder over `whitted_ir::Scene`, and the benchmark scenes.

use glam::{DMat4, DVec3};
use whitted_ir::{
    validate, Attenuation, Camera, Color, CsgOp, Fresnel, Handle, InvalidScene, Light, LightKind,
    Material, Mesh, Object, ObjectKind, Pattern, PatternKind, Projection, Scene, Settings, Shape,
    Span, ValidScene,
};

use crate::scene::PreparedScene;

/// Builds a `whitted_ir::Scene` by hand. Every node gets a detached span.
#[derive(Clone, Debug, Default)]
pub struct SceneBuilder {
    scene: Scene,
}

impl SceneBuilder {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn settings(&mut self) -> &mut Settings {
        &mut self.scene.settings
    }

    pub fn camera(&mut self, eye: DVec3, look_at: DVec3, vertical_fov_degrees: f64) -> &mut Self {
        self.scene.camera = Camera {
            eye,
            look_at,
            up: DVec3::Y,
            projection: Projection::Perspective {
                vertical_fov_degrees,
            },
        };
        self
    }

    pub fn set_camera(&mut self, camera: Camera) -> &mut Self {
        self.scene.camera = camera;
        self
    }

    pub fn material(&mut self, material: Material) -> Handle<Material> {
        self.scene.materials.append(material, Span::detached())
    }

    pub fn light(&mut self, light: Light) -> Handle<Light> {
        self.scene.lights.append(light, Span::detached())
    }

    /// A point light without attenuation.
    pub fn point_light(&mut self, position: DVec3, intensity: f64) -> Handle<Light> {
        self.light(Light {
            name: None,
            color: Color::gray(intensity),
            kind: LightKind::Point {
                position,
                attenuation: Attenuation::NONE,
            },
        })
    }

    /// A shape that is not (yet) a top-level object: a CSG or group child.
    pub fn part(
        &mut self,
        shape: Shape,
        world_from_object: DMat4,
        material: Handle<Material>,
    ) -> Handle<Object> {
        self.object(
            ObjectKind::Shape {
                shape: shape.into(),
            },
            world_from_object,
            material,
        )
    }

    /// A top-level shape.
    pub fn add(
        &mut self,
        shape: Shape,
        world_from_object: DMat4,
        material: Handle<Material>,
    ) -> Handle<Object> {
        let handle = self.part(shape, world_from_object, material);
        self.scene.roots.push(handle);
        handle
    }

    /// A CSG node over earlier parts; top-level unless it is used as a child later (then
    /// call [`SceneBuilder::demote`]).
    pub fn csg(
        &mut self,
        op: CsgOp,
        children: Vec<Handle<Object>>,
        material: Handle<Material>,
    ) -> Handle<Object> {
        let handle = self.object(ObjectKind::Csg { op, children }, DMat4::IDENTITY, material);
        self.scene.roots.push(handle);
        handle
    }

    /// A group over earlier parts, top-level.
    pub fn group(&mut self, children: Vec<Handle<Object>>) -> Handle<Object> {
        let material = self.default_material();
        let handle = self.object(ObjectKind::Group { children }, DMat4::IDENTITY, material);
        self.scene.roots.push(handle);
        handle
    }

    /// Puts an object (back) at the top level.
    pub fn promote(&mut self, handle: Handle<Object>) {
        if !self.scene.roots.contains(&handle) {
            self.scene.roots.push(handle);
        }
    }

    /// Removes an object from the top level (it became a child).
    pub fn demote(&mut self, handle: Handle<Object>) {
        self.scene.roots.retain(|&root| root != handle);
    }

    /// A mesh's geometry, for [`Shape::Mesh`] objects to instance.
    pub fn mesh(&mut self, mesh: Mesh) -> Handle<Mesh> {
        self.scene.meshes.append(mesh, Span::detached())
    }

    pub fn name(&mut self, handle: Handle<Object>, name: &str) {
        self.scene.objects[handle].name = self.scene.object_names.add(name);
    }

    fn default_material(&mut self) -> Handle<Material> {
        if self.scene.materials.is_empty() {
            self.material(Material::default())
        } else {
            Handle::from_index(0)
        }
    }

    fn object(
        &mut self,
        kind: ObjectKind,
        world_from_object: DMat4,
        material: Handle<Material>,
    ) -> Handle<Object> {
        self.scene.objects.append(
            Object {
                name: None,
                kind,
                world_from_object: world_from_object.into(),
                material,
            },
            Span::detached(),
        )
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn build(self) -> Result<ValidScene, Box<InvalidScene>> {
        validate(self.scene)
    }

    /// Validates and prepares; the error lists the validator's messages.
    pub fn prepare(self) -> Result<PreparedScene, String> {
        match self.build() {
            Ok(valid) => Ok(PreparedScene::new(&valid)),
            Err(invalid) => Err(invalid
                .diagnostics
                .iter()
                .map(|d| d.message.clone())
                .collect::<Vec<_>>()
                .join("; ")),
        }
    }
}

/// A closed sphere of triangles around the origin: `stacks` bands from pole to pole, each
/// of `slices` quads (two triangles; one at the poles), every vertex shared, wound outward.
/// With `normals`, each vertex carries the sphere's exact normal there.
pub fn tessellated_sphere(radius: f32, stacks: u32, slices: u32, normals: bool) -> Mesh {
    let (stacks, slices) = (stacks.max(2), slices.max(3));
    let mut positions = vec![[0.0, radius, 0.0], [0.0, -radius, 0.0]];
    for i in 1..stacks {
        let theta = std::f64::consts::PI * f64::from(i) / f64::from(stacks);
        for j in 0..slices {
            let phi = std::f64::consts::TAU * f64::from(j) / f64::from(slices);
            let r = f64::from(radius);
            positions.push([
                (r * theta.sin() * phi.cos()) as f32,
                (r * theta.cos()) as f32,
                (r * theta.sin() * phi.sin()) as f32,
            ]);
        }
    }
    let v = |i: u32, j: u32| 2 + (i - 1) * slices + j % slices;
    let mut triangles = Vec::new();
    for j in 0..slices {
        triangles.push([0, v(1, j + 1), v(1, j)]);
        triangles.push([1, v(stacks - 1, j), v(stacks - 1, j + 1)]);
        for i in 1..stacks - 1 {
            triangles.push([v(i, j), v(i, j + 1), v(i + 1, j + 1)]);
            triangles.push([v(i, j), v(i + 1, j + 1), v(i + 1, j)]);
        }
    }
    let normals = if normals {
        positions.iter().map(|p| p.map(|x| x / radius)).collect()
    } else {
        Vec::new()
    };
    Mesh::new("sphere.obj".to_string(), positions, normals, triangles)
}

pub fn sphere(x: f64, y: f64, z: f64, radius: f64) -> Shape {
    Shape::Sphere {
        center: DVec3::new(x, y, z),
        radius,
    }
}

pub fn plane_y(height: f64) -> Shape {
    Shape::Plane {
        normal: DVec3::Y,
        offset: height,
    }
}

pub fn matte(r: f64, g: f64, b: f64) -> Material {
    Material {
        ambient: Color::gray(0.1),
        diffuse: Color::new(r, g, b),
        ..Material::default()
    }
}

pub fn mirror() -> Material {
    Material {
        ambient: Color::BLACK,
        diffuse: Color::gray(0.05),
        specular: Color::gray(1.0),
        shininess: 200.0,
        reflective: Color::gray(0.9),
        ..Material::default()
    }
}

pub fn glass() -> Material {
    Material {
        ambient: Color::BLACK,
        diffuse: Color::BLACK,
        specular: Color::gray(1.0),
        shininess: 200.0,
        reflective: Color::BLACK,
        transmissive: Color::gray(1.0),
        ior: 1.5,
        fresnel: Fresnel::Schlick,
        ..Material::default()
    }
}

/// A checker of materials `a` and `other` with cells of size `scale`.
pub fn checker(b: &mut SceneBuilder, a: Material, other: Material, scale: f64) -> Handle<Material> {
    let a = b.material(a);
    let other = b.material(other);
    b.material(Material {
        pattern: Some(Pattern {
            kind: PatternKind::Checker,
            a,
            b: other,
            scale,
            pattern_from_object: DMat4::IDENTITY,
        }),
        ..Material::default()
    })
}

/// Whitted's 1980 picture, as `scenes/whitted.scene` (and `scenes/bench/classic.scene`)
/// writes it: a glass sphere and a mirror sphere over a red and yellow checkerboard, under
/// a blue sky.
pub fn whitted_classic() -> SceneBuilder {
    let mut b = SceneBuilder::new();
    b.settings().max_depth = 5;
    b.settings().background = Color::new(0.10, 0.30, 0.75);
    b.camera(DVec3::new(0.0, 1.6, -6.5), DVec3::new(0.0, 1.0, 0.0), 45.0);
    b.point_light(DVec3::new(-6.0, 10.0, -8.0), 1.0);
    let tiles = checker(&mut b, matte(0.9, 0.1, 0.1), matte(0.95, 0.9, 0.2), 1.0);
    let glass = b.material(Material {
        ambient: Color::BLACK,
        diffuse: Color::gray(0.05),
        specular: Color::gray(0.8),
        shininess: 200.0,
        reflective: Color::gray(0.1),
        transmissive: Color::gray(0.9),
        ior: 1.5,
        ..Material::default()
    });
    let mirror = b.material(Material {
        ambient: Color::gray(0.05),
        diffuse: Color::gray(0.1),
        specular: Color::gray(0.8),
        shininess: 120.0,
        reflective: Color::gray(0.8),
        ..Material::default()
    });
    b.add(plane_y(0.0), DMat4::IDENTITY, tiles);
    b.add(sphere(-0.75, 1.1, -1.2, 1.0), DMat4::IDENTITY, glass);
    b.add(sphere(1.2, 1.0, 1.4, 1.0), DMat4::IDENTITY, mirror);
    b
}

/// A 10 × 10 × 10 lattice of reflective spheres over a plane, one light, shadows: as
/// `scenes/bench/spheres1000.scene` writes it.
pub fn reflective_spheres() -> SceneBuilder {
    let mut b = SceneBuilder::new();
    b.settings().max_depth = 5;
    b.settings().background = Color::new(0.05, 0.05, 0.1);
    b.camera(
        DVec3::new(14.0, 12.0, -16.0),
        DVec3::new(4.5, 3.5, 4.5),
        45.0,
    );
    b.point_light(DVec3::new(20.0, 30.0, -10.0), 1.0);
    let floor = b.material(Material {
        ambient: Color::gray(0.1),
        diffuse: Color::gray(0.6),
        ..Material::default()
    });
    b.add(plane_y(-0.5), DMat4::IDENTITY, floor);
    for i in 0..10 {
        for j in 0..10 {
            for k in 0..10 {
                let tint = |n: i32| (0.2 + f64::from(n) / 12.0) * 0.7;
                let material = b.material(Material {
                    ambient: Color::gray(0.1),
                    diffuse: Color::new(tint(i), tint(j), tint(k)),
                    specular: Color::gray(0.5),
                    shininess: 60.0,
                    reflective: Color::gray(0.3),
                    ..Material::default()
                });
                b.add(
                    sphere(f64::from(i), f64::from(j), f64::from(k), 0.35),
                    DMat4::IDENTITY,
                    material,
                );
            }
        }
    }
    b
}

/// An `n × n` grid of spheres on a checkered floor, as `scenes/bench/grid.scene` writes it
/// (each sphere at its place through its transform, as the language lowers it).
pub fn sphere_grid(n: u32) -> SceneBuilder {
    let mut b = SceneBuilder::new();
    let n_f = f64::from(n.max(1));
    b.camera(DVec3::new(0.0, n_f * 0.8, -n_f * 0.9), DVec3::ZERO, 50.0);
    b.point_light(DVec3::new(n_f, 2.0 * n_f, -n_f), 1.0);
    b.light(Light {
        name: None,
        color: Color::gray(0.3),
        kind: LightKind::Directional {
            direction: DVec3::new(1.0, -1.0, 1.0),
        },
    });
    let tiles = checker(&mut b, matte(1.0, 1.0, 1.0), matte(0.25, 0.25, 0.25), 2.0);
    b.add(plane_y(-0.5), DMat4::IDENTITY, tiles);
    let ball = b.material(Material {
        specular: Color::gray(0.3),
        shininess: 40.0,
        ..matte(0.8, 0.3, 0.2)
    });
    let half = (n_f - 1.0) / 2.0;
    for i in 0..n {
        for j in 0..n {
            let center = DVec3::new(f64::from(i) - half, 0.0, f64::from(j) - half);
            b.add(
                sphere(0.0, 0.0, 0.0, 0.4),
                DMat4::from_translation(center),
                ball,
            );
        }
    }
    b
}

/// Perlin's improved noise as an independent f64 oracle, written from the algorithm's
/// description rather than from `perlin.rs`'s code (with the same published permutation):
/// each of the eight corners' gradient from the table of directions, dotted with the offset
/// from that corner and weighted by the product of the fade curves.
pub fn reference_improved_noise(p: [f64; 3]) -> f64 {
    // The sixteen gradient directions of the reference code, in hash order.
    const DIRECTIONS: [[f64; 3]; 16] = [
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
        [1.0, -1.0, 0.0],
        [-1.0, -1.0, 0.0],
        [1.0, 0.0, 1.0],
        [-1.0, 0.0, 1.0],
        [1.0, 0.0, -1.0],
        [-1.0, 0.0, -1.0],
        [0.0, 1.0, 1.0],
        [0.0, -1.0, 1.0],
        [0.0, 1.0, -1.0],
        [0.0, -1.0, -1.0],
        [1.0, 1.0, 0.0],
        [0.0, -1.0, 1.0],
        [-1.0, 1.0, 0.0],
        [0.0, -1.0, -1.0],
    ];
    let table = |i: i64| i64::from(crate::perlin::PERMUTATION[i.rem_euclid(256) as usize]);
    let cell = p.map(f64::floor);
    let frac = [p[0] - cell[0], p[1] - cell[1], p[2] - cell[2]];
    let smooth = |t: f64| 6.0 * t.powi(5) - 15.0 * t.powi(4) + 10.0 * t.powi(3);
    let mut total = 0.0;
    for corner in 0..8 {
        let d = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1].map(i64::from);
        let c = [
            cell[0] as i64 + d[0],
            cell[1] as i64 + d[1],
            cell[2] as i64 + d[2],
        ];
        let hash = table(table(table(c[0]) + c[1].rem_euclid(256)) + c[2].rem_euclid(256));
        let g = DIRECTIONS[(hash & 15) as usize];
        let offset = [
            frac[0] - d[0] as f64,
            frac[1] - d[1] as f64,
            frac[2] - d[2] as f64,
        ];
        let dot = g[0] * offset[0] + g[1] * offset[1] + g[2] * offset[2];
        let mut weight = 1.0;
        for axis in 0..3 {
            let s = smooth(frac[axis]);
            weight *= if d[axis] == 1 { s } else { 1.0 - s };
        }
        total += weight * dot;
    }
    total
}

/// The course's `N(p)` over [`reference_improved_noise`]: `Σ_{i<octaves} noise(2^i·p) / 2^i`.
pub fn reference_octave_sum(p: [f64; 3], octaves: u32) -> f64 {
    (0..octaves)
        .map(|i| {
            let s = f64::from(2u32.pow(i));
            reference_improved_noise([s * p[0], s * p[1], s * p[2]]) / s
        })
        .sum()
}
