//! Scene building in Rust, for tests and benchmarks that cannot (or should not) go through
//! the scene language: a small builder over `whitted_ir::Scene`, and the benchmark scenes.

use glam::{DMat4, DVec3};
use whitted_ir::{
    validate, Attenuation, Camera, Color, CsgOp, Fresnel, Handle, InvalidScene, Light, LightKind,
    Material, Object, ObjectKind, Pattern, PatternKind, Projection, Scene, Settings, Shape, Span,
    ValidScene,
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
        self.object(ObjectKind::Shape { shape }, world_from_object, material)
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

    /// Removes an object from the top level (it became a child).
    pub fn demote(&mut self, handle: Handle<Object>) {
        self.scene.roots.retain(|&root| root != handle);
    }

    pub fn name(&mut self, handle: Handle<Object>, name: &str) {
        self.scene.objects[handle].name = Some(name.to_string());
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
                world_from_object,
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

/// Whitted's 1980 picture: a glass sphere and a mirror sphere over a red and yellow
/// checkerboard, under a blue sky.
pub fn whitted_classic() -> SceneBuilder {
    let mut b = SceneBuilder::new();
    b.settings().background = Color::new(0.35, 0.55, 0.95);
    b.settings().ambient = Color::gray(1.0);
    b.camera(DVec3::new(0.0, 1.6, 6.0), DVec3::new(0.0, 0.9, 0.0), 45.0);
    b.point_light(DVec3::new(-4.0, 8.0, 6.0), 0.9);
    let red = b.material(matte(0.9, 0.15, 0.1));
    let yellow = b.material(matte(0.95, 0.9, 0.2));
    let checker = b.material(Material {
        pattern: Some(Pattern {
            kind: PatternKind::Checker,
            a: red,
            b: yellow,
            scale: 1.0,
            pattern_from_object: DMat4::IDENTITY,
        }),
        ..Material::default()
    });
    let glass = b.material(glass());
    let mirror = b.material(mirror());
    b.add(plane_y(0.0), DMat4::IDENTITY, checker);
    b.add(sphere(0.6, 1.25, 1.0, 0.8), DMat4::IDENTITY, glass);
    b.add(sphere(-0.9, 0.9, -0.8, 0.9), DMat4::IDENTITY, mirror);
    b
}

/// `count` reflective spheres in a loose cube of side 20, lit by two point lights, over a
/// matte floor. Positions come from a fixed hash, so the scene is the same every time.
pub fn reflective_spheres(count: u32) -> SceneBuilder {
    let mut b = SceneBuilder::new();
    b.settings().background = Color::new(0.1, 0.1, 0.15);
    b.camera(DVec3::new(0.0, 12.0, 34.0), DVec3::new(0.0, 8.0, 0.0), 50.0);
    b.point_light(DVec3::new(-20.0, 40.0, 30.0), 0.7);
    b.point_light(DVec3::new(25.0, 30.0, 10.0), 0.5);
    let floor = b.material(matte(0.6, 0.6, 0.6));
    b.add(plane_y(-1.0), DMat4::IDENTITY, floor);
    let shiny = b.material(Material {
        ambient: Color::gray(0.05),
        diffuse: Color::new(0.5, 0.3, 0.2),
        specular: Color::gray(0.6),
        shininess: 60.0,
        reflective: Color::gray(0.5),
        ..Material::default()
    });
    let unit = |i: u32, salt: u32| {
        let mut h = i.wrapping_mul(0x9E37_79B9) ^ salt.wrapping_mul(0x85EB_CA6B);
        h ^= h >> 16;
        h = h.wrapping_mul(0x7FEB_352D);
        h ^= h >> 15;
        h = h.wrapping_mul(0x846C_A68B);
        h ^= h >> 16;
        f64::from(h) / f64::from(u32::MAX)
    };
    for i in 0..count {
        let x = unit(i, 1) * 20.0 - 10.0;
        let y = unit(i, 2) * 20.0;
        let z = unit(i, 3) * 20.0 - 10.0;
        let r = 0.3 + unit(i, 4) * 0.5;
        b.add(sphere(x, y, z, r), DMat4::IDENTITY, shiny);
    }
    b
}

/// An `n × n` grid of matte spheres on the floor, seen from above at an angle.
pub fn sphere_grid(n: u32) -> SceneBuilder {
    let mut b = SceneBuilder::new();
    let n_f = f64::from(n.max(1));
    b.camera(
        DVec3::new(0.0, n_f * 0.8, n_f * 1.1),
        DVec3::new(0.0, 0.0, 0.0),
        50.0,
    );
    b.point_light(DVec3::new(n_f, n_f * 2.0, n_f), 1.0);
    let floor = b.material(matte(0.5, 0.5, 0.5));
    b.add(plane_y(-0.5), DMat4::IDENTITY, floor);
    let ball = b.material(Material {
        specular: Color::gray(0.3),
        shininess: 20.0,
        ..matte(0.8, 0.3, 0.3)
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
