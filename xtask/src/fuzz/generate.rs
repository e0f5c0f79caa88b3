//! Random scenes. Most are valid ([`case`]): every setting, camera, light, material,
//! pattern, shape, CSG operation and transform of the language with numbers inside the
//! ranges of `whitted_ir::limits` and the property table, and meshes written as `.obj` and
//! `.ply` files beside the scene (closed and open, ASCII and binary, and flat axis-aligned
//! slabs far from the origin seen from afar), so that they reach the tracer, the lints and
//! explain. A minority are wild ([`scene`]): numbers drawn from the edges (±0, 1e-30, 1e19,
//! 1e39, 1e308, ...), loops, functions and deep nesting that end in errors, broken mesh
//! files.

use whitted_ir::DVec3;

use super::rng::Rng;
use super::Case;

/// Numbers at the edges of f32 and f64, and the zeros of both signs.
const EXTREMES: &[&str] = &[
    "0", "-0", "1", "-1", "0.5", "1e-4", "1e-30", "1e-45", "1e-300", "1e19", "-1e19", "3.4e38",
    "1e39", "-1e39", "1e308", "65536", "16777217", "0.1", "2", "90", "180", "360", "1000",
];

/// Writes one random value of a setting.
type ValueFn = for<'a, 'b> fn(&'a mut Generator<'b>) -> String;

pub struct Generator<'a> {
    rng: &'a mut Rng,
    out: String,
    /// How wild the numbers are: the chance of an edge value instead of an ordinary one.
    wild: f64,
    materials: Vec<String>,
    depth: usize,
    /// Only values the language and validation accept (the valid scenes of [`case`]).
    valid: bool,
    /// The mesh files the scene reads, by name.
    files: Vec<(String, Vec<u8>)>,
}

/// A random case: 85% valid scenes (an eighth of them a flat slab far from the origin),
/// the rest wild.
pub fn case(rng: &mut Rng) -> Case {
    if rng.chance(0.15) {
        let mut g = Generator::new(rng, false);
        let text = g.scene_body();
        return Case {
            text,
            files: g.files,
            origin: "wild",
        };
    }
    let mut g = Generator::new(rng, true);
    let text = if g.rng.chance(0.12) {
        g.far_slab()
    } else {
        g.scene_body()
    };
    Case {
        text,
        files: g.files,
        origin: "valid",
    }
}

/// A whole random wild scene (numbers from the edges, constructs that end in errors).
pub fn scene(rng: &mut Rng) -> String {
    Generator::new(rng, false).scene_body()
}

impl<'a> Generator<'a> {
    fn new(rng: &'a mut Rng, valid: bool) -> Generator<'a> {
        let wild = if valid {
            0.0
        } else {
            *rng.pick(&[0.0, 0.02, 0.1, 0.3])
        };
        Generator {
            rng,
            out: String::new(),
            wild,
            materials: Vec::new(),
            depth: 0,
            valid,
            files: Vec::new(),
        }
    }

    fn scene_body(&mut self) -> String {
        let g = self;
        g.settings();
        if g.valid || g.rng.chance(0.8) {
            g.camera();
        }
        let lights = match g.rng.below(10) {
            0 if !g.valid => 0,
            // Many lights; valid scenes stay under the fuzzer's limit (64).
            1 if g.valid => 20 + g.rng.below(40),
            1 => 20 + g.rng.below(60),
            _ => 1 + g.rng.below(3),
        };
        for _ in 0..lights {
            g.light();
        }
        for i in 0..g.rng.below(5) {
            g.material_definition(&format!("m{i}"));
        }
        let statements = 1 + g.rng.below(8);
        for _ in 0..statements {
            g.statement();
        }
        std::mem::take(&mut g.out)
    }
}

impl Generator<'_> {
    fn number(&mut self) -> String {
        if self.rng.chance(self.wild) {
            self.rng.pick(EXTREMES).to_string()
        } else {
            format!("{:.3}", self.rng.range(-4.0, 4.0))
        }
    }

    /// Greater than zero, except rarely (a degenerate shape is an error worth reaching).
    fn positive(&mut self) -> String {
        if self.rng.chance(self.wild) {
            self.rng
                .pick(&[
                    "1e-30", "1e-45", "1e-300", "1e19", "3.4e38", "1e39", "1e308", "65536", "0.5",
                    "1e-7", "0",
                ])
                .to_string()
        } else {
            format!("{:.3}", self.rng.range(0.05, 2.0))
        }
    }

    fn unit_interval(&mut self) -> String {
        if self.rng.chance(self.wild) {
            self.rng
                .pick(&["0", "1", "-0", "1e-30", "0.999999", "1e39"])
                .to_string()
        } else {
            format!("{:.3}", self.rng.unit())
        }
    }

    /// A vector, sometimes axis-aligned with zeros of either sign.
    fn vector(&mut self) -> String {
        if self.rng.chance(0.2) {
            let axis = self.rng.below(3);
            let sign = if self.rng.chance(0.5) { "-" } else { "" };
            let zero = |rng: &mut Rng| if rng.chance(0.5) { "-0" } else { "0" };
            let mut c = [zero(self.rng), zero(self.rng), zero(self.rng)].map(str::to_string);
            c[axis] = format!("{sign}1");
            return format!("<{}, {}, {}>", c[0], c[1], c[2]);
        }
        format!("<{}, {}, {}>", self.number(), self.number(), self.number())
    }

    fn color(&mut self) -> String {
        match self.rng.below(6) {
            0 => self
                .rng
                .pick(&[
                    "white",
                    "black",
                    "red",
                    "gray",
                    "#ff8000",
                    "srgb(0.2, 0.4, 0.9)",
                ])
                .to_string(),
            1 => format!(
                "rgb({}, {}, {})",
                self.unit_interval(),
                self.unit_interval(),
                self.unit_interval()
            ),
            2 if self.rng.chance(self.wild) => self
                .rng
                .pick(&["1e39", "3.4e38", "1e308", "1e-45"])
                .to_string(),
            _ => self.unit_interval(),
        }
    }

    fn line(&mut self, text: &str) {
        for _ in 0..self.depth {
            self.out.push_str("  ");
        }
        self.out.push_str(text);
        self.out.push('\n');
    }

    fn settings(&mut self) {
        if self.valid {
            return self.valid_settings();
        }
        let mut props = Vec::new();
        let options: [(&str, ValueFn); 9] = [
            ("samples", |g| g.rng.pick(&["1", "2", "4", "3"]).to_string()),
            ("max_depth", |g| {
                g.rng
                    .pick(&["0", "1", "5", "10", "64", "256", "1000"])
                    .to_string()
            }),
            ("min_weight", |g| g.unit_interval()),
            ("background", |g| g.color()),
            ("ambient", |g| g.color()),
            ("epsilon", |g| {
                g.rng
                    .pick(&["1e-4", "1e-30", "1", "1e-7", "0.5"])
                    .to_string()
            }),
            ("shadows", |g| {
                g.rng.pick(&["opaque", "filtered"]).to_string()
            }),
            ("width", |g| {
                g.rng.pick(&["8", "1", "640", "32768"]).to_string()
            }),
            ("height", |g| {
                g.rng.pick(&["6", "1", "480", "32768"]).to_string()
            }),
        ];
        for (name, value) in options {
            if self.rng.chance(0.4) {
                let v = value(self);
                props.push(format!("{name} {v}"));
            }
        }
        if !props.is_empty() {
            let text = format!("settings {{ {} }}", props.join(" "));
            self.line(&text);
        }
    }

    /// Every setting, each inside its range (crates/lang/src/properties.rs).
    fn valid_settings(&mut self) {
        let mut props = Vec::new();
        let options: [(&str, ValueFn); 12] = [
            ("samples", |g| g.rng.pick(&["1", "2", "4"]).to_string()),
            ("max_depth", |g| {
                g.rng.pick(&["0", "1", "3", "5", "10"]).to_string()
            }),
            ("min_weight", |g| {
                g.rng.pick(&["0.001", "0.01", "0.1", "0.5"]).to_string()
            }),
            ("background", |g| g.color()),
            ("ambient", |g| g.color()),
            ("epsilon", |g| {
                g.rng.pick(&["1e-4", "1e-6", "1e-9", "0.01"]).to_string()
            }),
            ("shadows", |g| {
                g.rng.pick(&["opaque", "filtered", "none"]).to_string()
            }),
            ("highlight", |g| g.rng.pick(&["phong", "blinn"]).to_string()),
            ("shade_back", |g| g.rng.pick(&["on", "off"]).to_string()),
            ("attenuation_clamp", |g| {
                g.rng.pick(&["on", "off"]).to_string()
            }),
            ("width", |g| g.rng.pick(&["8", "1", "640"]).to_string()),
            ("height", |g| g.rng.pick(&["6", "1", "480"]).to_string()),
        ];
        for (name, value) in options {
            // The surface offset is automatic in most scenes (the hit's own error bound).
            let chance = if name == "epsilon" { 0.1 } else { 0.35 };
            if self.rng.chance(chance) {
                let v = value(self);
                props.push(format!("{name} {v}"));
            }
        }
        if !props.is_empty() {
            let text = format!("settings {{ {} }}", props.join(" "));
            self.line(&text);
        }
    }

    fn camera(&mut self) {
        if self.valid {
            let eye = self.eye(DVec3::ZERO);
            let text = self.valid_camera(&eye, "<0, 0, 0>");
            self.line(&text);
            return;
        }
        let text = if self.rng.chance(0.7) {
            format!(
                "camera perspective {{ eye {} look_at {} fov {} }}",
                self.vector(),
                self.vector(),
                self.rng.pick(&["45", "1", "179", "90", "0.001", "30"])
            )
        } else {
            format!(
                "camera orthographic {{ eye {} look_at {} up {} height {} }}",
                self.vector(),
                self.vector(),
                self.vector(),
                self.positive()
            )
        };
        self.line(&text);
    }

    /// An eye 4 to 40 units from `at`, not straight above or below it (so that the
    /// default `up` is never along the view).
    fn eye(&mut self, at: DVec3) -> String {
        let distance = *self.rng.pick(&[4.0, 8.0, 15.0, 40.0]);
        let angle = self.rng.range(0.0, std::f64::consts::TAU);
        let height = self.rng.range(-0.7, 0.7);
        let across = (1.0 - height * height).sqrt();
        format!(
            "<{}, {}, {}>",
            at.x + distance * across * angle.cos(),
            at.y + distance * height,
            at.z + distance * across * angle.sin()
        )
    }

    fn valid_camera(&mut self, eye: &str, look_at: &str) -> String {
        if self.rng.chance(0.75) {
            format!(
                "camera perspective {{ eye {eye} look_at {look_at} fov {} }}",
                self.rng.pick(&["45", "10", "90", "150", "30"])
            )
        } else {
            format!(
                "camera orthographic {{ eye {eye} look_at {look_at} up <0, 1, 0> height {} }}",
                self.rng.pick(&["2", "5", "10", "0.5"])
            )
        }
    }

    fn light(&mut self) {
        let text = match self.rng.below(3) {
            0 => format!(
                "light point {{ position {} color {} attenuation <{}, {}, {}> }}",
                self.vector(),
                self.color(),
                self.positive(),
                self.unit_interval(),
                self.unit_interval()
            ),
            1 => format!(
                "light directional {{ direction {} color {} }}",
                self.vector(),
                self.color()
            ),
            _ => format!(
                "light spot {{ position {} direction {} inner {} color {} }}",
                self.vector(),
                self.vector(),
                self.rng.pick(&[
                    "10 outer 30",
                    "20 outer 20",
                    "0 outer 90",
                    "89 outer 90",
                    "1e-30 outer 1e-30"
                ]),
                self.color()
            ),
        };
        self.line(&text);
    }

    fn material_body(&mut self) -> String {
        let mut props = Vec::new();
        let names = [
            "ambient",
            "diffuse",
            "specular",
            "shininess",
            "reflective",
            "transmissive",
            "ior",
            "fresnel",
            "absorption",
        ];
        for name in names {
            if !self.rng.chance(0.45) {
                continue;
            }
            let value = match name {
                "shininess" => self.positive(),
                "ior" if self.valid => self
                    .rng
                    .pick(&["1", "1.5", "2.4", "1.33", "1.0001", "0.7"])
                    .to_string(),
                "ior" => self
                    .rng
                    .pick(&[
                        "1", "1.5", "2.4", "1.33", "1e308", "1e-30", "1e39", "1.0001",
                    ])
                    .to_string(),
                "fresnel" => self.rng.pick(&["off", "schlick", "exact"]).to_string(),
                "diffuse" if self.rng.chance(0.2) => format!(
                    "{}({}, {}, {}){}",
                    self.rng.pick(&["checker", "stripes"]),
                    self.color(),
                    self.color(),
                    self.positive(),
                    if self.rng.chance(0.3) {
                        format!(" {{ {} }}", self.transform())
                    } else {
                        String::new()
                    }
                ),
                _ => self.color(),
            };
            props.push(format!("{name} {value}"));
        }
        if self.valid {
            // Nested media and self-lit surfaces.
            if self.rng.chance(0.15) {
                let priority = self.rng.pick(&["0", "1", "2", "1000"]);
                props.push(format!("priority {priority}"));
            }
            if self.rng.chance(0.1) {
                props.push(format!("emission {}", self.color()));
            }
        }
        props.join(" ")
    }

    fn material_definition(&mut self, name: &str) {
        let parent = if !self.materials.is_empty() && self.rng.chance(0.3) {
            format!(" : {}", self.rng.pick(&self.materials.clone()))
        } else {
            String::new()
        };
        let body = self.material_body();
        self.line(&format!("material {name}{parent} {{ {body} }}"));
        self.materials.push(name.to_string());
    }

    fn transform(&mut self) -> String {
        match self.rng.below(6) {
            0 => format!("translate {}", self.vector()),
            1 => format!("rotate {}", self.vector()),
            2 => format!("rotate {} about {}", self.number(), self.vector()),
            3 => format!("scale {}", self.positive()),
            4 => format!(
                "scale <{}, {}, -{}>",
                self.positive(),
                self.positive(),
                self.positive()
            ),
            _ => {
                let m: Vec<String> = (0..16)
                    .map(|i| {
                        if i == 15 {
                            "1".to_string()
                        } else if [0, 5, 10].contains(&i) {
                            self.positive()
                        } else if i >= 12 || self.rng.chance(0.7) {
                            "0".to_string()
                        } else {
                            self.number()
                        }
                    })
                    .collect();
                format!("matrix {}", m.join(", "))
            }
        }
    }

    fn extras(&mut self) -> String {
        let mut parts = Vec::new();
        for _ in 0..self.rng.below(3) {
            parts.push(self.transform());
        }
        if self.rng.chance(0.6) {
            if !self.materials.is_empty() && self.rng.chance(0.6) {
                let m = self.rng.pick(&self.materials.clone()).clone();
                parts.push(format!("material {m}"));
            } else {
                let body = self.material_body();
                parts.push(format!("material {{ {body} }}"));
            }
        }
        parts.join(" ")
    }

    /// A shape; `solid` asks for one that CSG accepts.
    fn shape(&mut self, solid: bool) -> String {
        let kinds: &[&str] = if solid {
            &[
                "sphere",
                "box",
                "cylinder",
                "cone",
                "plane",
                "quadric",
                "ellipsoid",
                "paraboloid",
                "hyperboloid",
                "hyperboloid2",
            ]
        } else {
            &[
                "sphere",
                "sphere",
                "box",
                "cylinder",
                "cone",
                "plane",
                "disk",
                "triangle",
                "quadric",
                "ellipsoid",
                "paraboloid",
                "hyperboloid",
                "hyperboloid2",
            ]
        };
        let kind = *self.rng.pick(kinds);
        let props = match kind {
            "sphere" => format!("center {} radius {}", self.vector(), self.positive()),
            "box" => {
                let min = self.vector();
                format!(
                    "min {min} max {min} + <{}, {}, {}>",
                    self.positive(),
                    self.positive(),
                    self.positive()
                )
            }
            "cylinder" => format!(
                "base {} apex {} radius {}{}",
                self.vector(),
                self.vector(),
                self.positive(),
                if !solid && self.rng.chance(0.3) {
                    " open"
                } else {
                    ""
                }
            ),
            "cone" => format!(
                "base {} base_radius {} apex {} apex_radius {}{}",
                self.vector(),
                self.positive(),
                self.vector(),
                if self.valid {
                    self.rng.pick(&["0", "0.5"])
                } else {
                    self.rng.pick(&["0", "0.5", "1e-30"])
                },
                if !solid && self.rng.chance(0.3) {
                    " open"
                } else {
                    ""
                }
            ),
            "plane" => format!("normal {} offset {}", self.vector(), self.number()),
            "disk" => format!(
                "center {} normal {} radius {}",
                self.vector(),
                self.vector(),
                self.positive()
            ),
            "triangle" => format!(
                "vertices {}, {}, {}",
                self.vector(),
                self.vector(),
                self.vector()
            ),
            "quadric" => format!(
                "coefficients {}, {}, {}, {}, {}, {}, {}, {}, {}, {}",
                self.number(),
                self.number(),
                self.number(),
                self.number(),
                self.number(),
                self.number(),
                self.number(),
                self.number(),
                self.number(),
                self.number()
            ),
            _ => format!(
                "radii <{}, {}, {}>",
                self.positive(),
                self.positive(),
                self.positive()
            ),
        };
        let extras = self.extras();
        format!("{kind} {{ {props} {extras} }}")
    }

    fn csg(&mut self) -> String {
        let op = *self.rng.pick(&["union", "intersection", "difference"]);
        let children = 1 + self.rng.below(4);
        let mut parts = Vec::new();
        for _ in 0..children {
            if self.depth < 6 && self.rng.chance(0.3) {
                self.depth += 1;
                parts.push(self.csg());
                self.depth -= 1;
            } else {
                parts.push(self.shape(true));
            }
        }
        if self.rng.chance(0.2) {
            // Many children, all at one place: the acceleration inside CSG.
            let n = self.rng.pick(&["50", "500", "2000"]);
            parts.push(format!(
                "for i in 0..{n} {{ sphere {{ center <i * 0.001, 0, 0> radius 0.5 }} }}"
            ));
        }
        let extras = self.extras();
        format!("{op} {{ {} {extras} }}", parts.join(" "))
    }

    /// Two surfaces in one place at the origin, where the camera looks (the pixel that is
    /// explained): a rug on a floor, a poster on a wall, boxes sharing a face, a ball twice,
    /// a flat mesh on a plane. Inputs for the coincident-surface lint and explain's
    /// z-fighting finding.
    fn coincident_pair(&mut self) -> String {
        let material = if self.rng.chance(0.5) {
            format!(" material {{ {} }}", self.material_body())
        } else {
            String::new()
        };
        match self.rng.below(5) {
            0 => format!(
                "plane {{ normal <0, 1, 0> offset 0 }} disk \"rug\" {{ center <0, 0, 0> normal <0, 1, 0> radius 1{material} }}"
            ),
            1 => format!(
                "box {{ min <-1, -1, -1> max <1, 1, 0> }} triangle \"poster\" {{ vertices <-0.5, -0.5, 0>, <0.5, -0.5, 0>, <0, 0.5, 0>{material} }}"
            ),
            2 => format!(
                "box {{ min <-1, -1, -1> max <0, 1, 1> }} box {{ min <0, -1, -1> max <1, 1, 1>{material} }}"
            ),
            3 => format!("sphere {{ radius 1 }} sphere {{ radius 1{material} }}"),
            _ => {
                let name = self.write_mesh(&MeshData::open_square(), DVec3::ZERO);
                format!(
                    "plane {{ normal <0, 1, 0> offset 0 }} mesh {{ file \"{name}\"{material} }}"
                )
            }
        }
    }

    /// A `mesh` statement and the file it reads: a closed solid (box, tetrahedron,
    /// octahedron, sphere) or open triangles (a flat square, a soup), as `.obj` or `.ply`
    /// (ASCII or binary); in wild scenes sometimes a broken or missing file.
    fn mesh(&mut self) -> String {
        let data = match self.rng.below(6) {
            0 => {
                let min = DVec3::new(self.rng.range(-2.0, 0.0), self.rng.range(-2.0, 0.0), 0.0);
                let size = DVec3::new(
                    self.rng.range(0.05, 3.0),
                    *self.rng.pick(&[0.1, 0.5, 2.0]),
                    self.rng.range(0.05, 3.0),
                );
                MeshData::cuboid(min, min + size)
            }
            1 => MeshData::convex(&[DVec3::new(0.0, 0.0, 0.0), DVec3::X, DVec3::Y, DVec3::Z]),
            2 => MeshData::convex(&[
                DVec3::X,
                -DVec3::X,
                DVec3::Y,
                -DVec3::Y,
                DVec3::Z,
                -DVec3::Z,
            ]),
            3 => MeshData::sphere(3 + self.rng.below(10)),
            4 => MeshData::open_square(),
            _ => {
                let mut data = MeshData::default();
                for _ in 0..1 + self.rng.below(6) {
                    let first = data.positions.len() as u32;
                    for _ in 0..3 {
                        let p = DVec3::new(
                            self.rng.range(-2.0, 2.0),
                            self.rng.range(-2.0, 2.0),
                            self.rng.range(-2.0, 2.0),
                        );
                        data.positions.push(p);
                    }
                    data.triangles.push([first, first + 1, first + 2]);
                }
                data
            }
        };
        let name = self.write_mesh(&data, DVec3::ZERO);
        let extras = self.extras();
        let smooth = if self.rng.chance(0.5) {
            " smooth false"
        } else {
            ""
        };
        format!("mesh {{ file \"{name}\"{smooth} {extras} }}")
    }

    /// Writes `data` moved by `offset` as the case's next mesh file; returns its name.
    fn write_mesh(&mut self, data: &MeshData, offset: DVec3) -> String {
        let index = self.files.len();
        let (name, mut bytes) = match self.rng.below(4) {
            0 | 1 => (
                format!("m{index}.obj"),
                data.obj(offset, self.rng.chance(0.3), self.rng.chance(0.3)),
            ),
            2 => (format!("m{index}.ply"), data.ply_ascii(offset)),
            _ => (
                format!("m{index}.ply"),
                data.ply_binary(offset, self.rng.chance(0.5)),
            ),
        };
        if !self.valid && self.rng.chance(0.3) {
            // A broken file: a corner naming no vertex, a word for a number, cut short.
            match self.rng.below(4) {
                0 => bytes.extend_from_slice(b"\nf 1 2 99\n"),
                1 => bytes.extend_from_slice(b"\nv 1 x 3\n"),
                2 => bytes.truncate(bytes.len() / 2),
                _ => return format!("missing{index}.obj"),
            }
        }
        self.files.push((name.clone(), bytes));
        name
    }

    /// A 2 x 0.1 x 2 slab (flat, axis-aligned faces) from a mesh file, 100 to 100,000 units
    /// from the origin, seen from 4 to 400 units away: the far-mesh case of issue 26 (its
    /// faces lost hits to a bounding-box gate). The offset is in the file's coordinates or
    /// a `translate`; a `box` of the same size stands beside it.
    fn far_slab(&mut self) -> String {
        let far = *self.rng.pick(&[1e2, 1e4, 1e5]);
        let at = match self.rng.below(3) {
            0 => DVec3::new(far, 0.0, 0.0),
            1 => DVec3::splat(far),
            _ => DVec3::new(0.0, -far, far),
        };
        let thin = self.rng.below(3);
        let mut size = DVec3::splat(2.0);
        size[thin] = 0.1;
        let slab = MeshData::cuboid(-size / 2.0, size / 2.0);
        let distance = *self.rng.pick(&[4.0, 40.0, 400.0]);
        let eye = {
            let dir =
                DVec3::new(self.rng.range(-1.0, 1.0), 0.6, self.rng.range(-1.0, 1.0)).normalize();
            at + dir * distance
        };
        let point = |p: DVec3| format!("<{}, {}, {}>", p.x, p.y, p.z);
        self.valid_settings();
        let fov = self.rng.pick(&["5", "20", "45"]);
        self.line(&format!(
            "camera perspective {{ eye {} look_at {} fov {fov} }}",
            point(eye),
            point(at)
        ));
        let light = at + DVec3::new(3.0, 10.0, -4.0) * (distance / 10.0);
        self.line(&format!("light point {{ position {} }}", point(light)));
        if self.rng.chance(0.3) {
            self.line("light directional { direction <-1, -2, 1> color 0.5 }");
        }
        let body = self.material_body();
        let in_file = self.rng.chance(0.5);
        let name = self.write_mesh(&slab, if in_file { at } else { DVec3::ZERO });
        let place = if in_file {
            String::new()
        } else {
            format!(" translate {}", point(at))
        };
        self.line(&format!(
            "mesh \"slab\" {{ file \"{name}\" material {{ {body} }}{place} }}"
        ));
        if self.rng.chance(0.5) {
            let beside = at + DVec3::new(0.0, 0.0, 3.0);
            self.line(&format!(
                "box \"twin\" {{ min {} max {} }}",
                point(beside - size / 2.0),
                point(beside + size / 2.0)
            ));
        }
        if self.rng.chance(0.5) {
            self.line(&format!(
                "plane {{ normal <0, 1, 0> offset {} }}",
                at.y - 1.0
            ));
        }
        std::mem::take(&mut self.out)
    }

    fn statement(&mut self) {
        if self.rng.chance(if self.valid { 0.3 } else { 0.05 }) {
            let text = self.mesh();
            self.line(&text);
            return;
        }
        if self.valid && self.rng.chance(0.08) {
            let text = self.coincident_pair();
            self.line(&text);
            return;
        }
        // Statements that often end in a (wanted) error are rarer, so that most scenes
        // reach the tracer; valid scenes have none of them.
        let kinds = if self.valid { 35 } else { 40 };
        let text = match self.rng.below(kinds) {
            0..=17 => self.shape(false),
            18..=26 => self.csg(),
            27..=31 => {
                let inner: Vec<String> = (0..1 + self.rng.below(3))
                    .map(|_| self.shape(false))
                    .collect();
                let extras = self.extras();
                format!("group {{ {} {extras} }}", inner.join(" "))
            }
            32..=34 => {
                // A loop: sometimes the loop variable is forgotten (coincident objects).
                let n = if self.valid {
                    *self.rng.pick(&["3", "10", "100"])
                } else {
                    *self.rng.pick(&["3", "10", "100", "1000", "40000"])
                };
                let body = if self.rng.chance(0.5) {
                    "sphere { }".to_string()
                } else {
                    format!(
                        "sphere {{ center <i * {}, 0, 0> radius 0.3 }}",
                        self.positive()
                    )
                };
                match self.rng.below(4) {
                    0 => format!("for i in 0..{n} {{ {body} }}"),
                    // The programming constructs: `step`, `while` with assignment, arrays
                    // indexed by the loop variable and names formatted from it.
                    1 => format!("for i in {n}..0 step -{} {{ {body} }}", self.rng.below(4) + 1),
                    // In a block of its own, so that two loops do not define `i` twice.
                    2 => format!("if true {{ let i = 0;\nwhile i < {n} {{ {body} i = i + 1; }} }}"),
                    _ => format!(
                        "let rs = [0.1, 0.2, 0.3];\nfor i in 0..{n} {{ sphere \"s{{i}}\" {{ center <rand(1, i), i * 0.01, 0> radius rs[i % len(rs)] }} }}"
                    ),
                }
            }
            35 => {
                // Recursion that doubles: bounded only by the evaluation budget.
                let n = self.rng.pick(&["3", "8", "12", "40"]);
                format!("fn f(n) {{ if n > 0 {{ f(n - 1) f(n - 1) }} else {{ sphere {{ radius 0.1 }} }} }}\nf({n})")
            }
            36 | 37 => {
                // Expressions at the edges of arithmetic.
                let e = *self.rng.pick(&[
                    "0 / 0",
                    "1 / 0",
                    "1e308 * 10",
                    "sqrt(-1)",
                    "log(0)",
                    "pow(10, 400)",
                    "-0 * 1",
                    "1e-320 * 1e-10",
                    "exp(1000)",
                    "tan(90)",
                    "asin(2)",
                    "normalize(<0, 0, 0>)",
                    "1e39 - 1e39",
                ]);
                format!("let x = {e};\nsphere {{ radius abs(x) + 0.1 }}")
            }
            38 => {
                // Deep nesting of brackets and groups.
                let n = *self.rng.pick(&[10usize, 100, 250, 255, 300]);
                let open = "group { ".repeat(n);
                let close = " }".repeat(n);
                format!("{open}sphere {{ }}{close}")
            }
            _ => {
                let n = *self.rng.pick(&[10usize, 200, 2000]);
                let sum = vec!["1"; n].join(" + ");
                format!("sphere {{ radius ({sum}) / {n} }}")
            }
        };
        self.line(&text);
    }
}

/// Triangles written to a mesh file, counter-clockwise seen from outside when closed.
#[derive(Default)]
struct MeshData {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl MeshData {
    /// A box: 8 corners, 12 triangles.
    fn cuboid(min: DVec3, max: DVec3) -> MeshData {
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { min.x } else { max.x },
                    if i & 2 == 0 { min.y } else { max.y },
                    if i & 4 == 0 { min.z } else { max.z },
                )
            })
            .collect();
        // Each face as a quad of corner indices (bit 0 x, bit 1 y, bit 2 z).
        let quads = [
            [0, 2, 6, 4],
            [1, 3, 7, 5],
            [0, 1, 5, 4],
            [2, 3, 7, 6],
            [0, 1, 3, 2],
            [4, 5, 7, 6],
        ];
        let mut triangles = Vec::new();
        for [a, b, c, d] in quads {
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
        let mut data = MeshData {
            positions: corners,
            triangles,
        };
        data.orient_outwards();
        data
    }

    /// The hull of a few points given as every triangle of them whose plane has all the
    /// others on one side (convex position assumed).
    fn convex(points: &[DVec3]) -> MeshData {
        let n = points.len() as u32;
        let mut triangles = Vec::new();
        for a in 0..n {
            for b in a + 1..n {
                for c in b + 1..n {
                    let (pa, pb, pc) = (points[a as usize], points[b as usize], points[c as usize]);
                    let normal = (pb - pa).cross(pc - pa);
                    let sides: Vec<f64> = points.iter().map(|p| normal.dot(*p - pa)).collect();
                    let above = sides.iter().any(|s| *s > 1e-9);
                    let below = sides.iter().any(|s| *s < -1e-9);
                    if above != below {
                        triangles.push([a, b, c]);
                    }
                }
            }
        }
        let mut data = MeshData {
            positions: points.to_vec(),
            triangles,
        };
        data.orient_outwards();
        data
    }

    /// A unit sphere of `n` rings by `2n` segments.
    fn sphere(n: usize) -> MeshData {
        let mut positions = vec![DVec3::Y, -DVec3::Y];
        for ring in 1..n {
            let polar = std::f64::consts::PI * ring as f64 / n as f64;
            for segment in 0..2 * n {
                let azimuth = std::f64::consts::PI * segment as f64 / n as f64;
                positions.push(DVec3::new(
                    polar.sin() * azimuth.cos(),
                    polar.cos(),
                    polar.sin() * azimuth.sin(),
                ));
            }
        }
        let at = |ring: usize, segment: usize| (2 + (ring - 1) * 2 * n + segment % (2 * n)) as u32;
        let mut triangles = Vec::new();
        for segment in 0..2 * n {
            triangles.push([0, at(1, segment), at(1, segment + 1)]);
            triangles.push([1, at(n - 1, segment), at(n - 1, segment + 1)]);
            for ring in 1..n - 1 {
                let (a, b) = (at(ring, segment), at(ring, segment + 1));
                let (c, d) = (at(ring + 1, segment), at(ring + 1, segment + 1));
                triangles.push([a, c, d]);
                triangles.push([a, d, b]);
            }
        }
        let mut data = MeshData {
            positions,
            triangles,
        };
        data.orient_outwards();
        data
    }

    /// A flat square in the plane y = 0: open, so thin triangles.
    fn open_square() -> MeshData {
        MeshData {
            positions: vec![
                DVec3::new(-1.0, 0.0, -1.0),
                DVec3::new(1.0, 0.0, -1.0),
                DVec3::new(1.0, 0.0, 1.0),
                DVec3::new(-1.0, 0.0, 1.0),
            ],
            triangles: vec![[0, 2, 1], [0, 3, 2]],
        }
    }

    /// Turns every triangle of a convex mesh to face away from its centre.
    fn orient_outwards(&mut self) {
        let centre =
            self.positions.iter().copied().sum::<DVec3>() / self.positions.len().max(1) as f64;
        for t in &mut self.triangles {
            let [a, b, c] = t.map(|i| self.positions[i as usize]);
            if (b - a).cross(c - a).dot(a - centre) < 0.0 {
                t.swap(1, 2);
            }
        }
    }

    /// Wavefront OBJ, optionally with vertex normals (`v//vn`) and negative (relative)
    /// corner indices.
    fn obj(&self, offset: DVec3, normals: bool, relative: bool) -> Vec<u8> {
        let mut out = String::from("# written by cargo xtask fuzz\n");
        for p in &self.positions {
            let q = *p + offset;
            out.push_str(&format!("v {} {} {}\n", q.x, q.y, q.z));
        }
        if normals {
            for p in &self.positions {
                let n = p.normalize_or(DVec3::Y);
                out.push_str(&format!("vn {} {} {}\n", n.x, n.y, n.z));
            }
        }
        let count = self.positions.len() as i64;
        for t in &self.triangles {
            let corner = |i: u32| {
                let index = if relative {
                    i64::from(i) - count
                } else {
                    i64::from(i) + 1
                };
                if normals {
                    format!("{index}//{index}")
                } else {
                    index.to_string()
                }
            };
            out.push_str(&format!(
                "f {} {} {}\n",
                corner(t[0]),
                corner(t[1]),
                corner(t[2])
            ));
        }
        out.into_bytes()
    }

    fn ply_header(&self, format: &str, scalar: &str) -> String {
        format!(
            "ply\nformat {format} 1.0\ncomment written by cargo xtask fuzz\n\
             element vertex {}\nproperty {scalar} x\nproperty {scalar} y\nproperty {scalar} z\n\
             element face {}\nproperty list uchar int vertex_indices\nend_header\n",
            self.positions.len(),
            self.triangles.len()
        )
    }

    fn ply_ascii(&self, offset: DVec3) -> Vec<u8> {
        let mut out = self.ply_header("ascii", "double");
        for p in &self.positions {
            let q = *p + offset;
            out.push_str(&format!("{} {} {}\n", q.x, q.y, q.z));
        }
        for [a, b, c] in &self.triangles {
            out.push_str(&format!("3 {a} {b} {c}\n"));
        }
        out.into_bytes()
    }

    /// Binary little-endian PLY, with `float` or `double` coordinates.
    fn ply_binary(&self, offset: DVec3, double: bool) -> Vec<u8> {
        let scalar = if double { "double" } else { "float" };
        let mut out = self.ply_header("binary_little_endian", scalar).into_bytes();
        for p in &self.positions {
            let q = *p + offset;
            for x in [q.x, q.y, q.z] {
                if double {
                    out.extend_from_slice(&x.to_le_bytes());
                } else {
                    out.extend_from_slice(&(x as f32).to_le_bytes());
                }
            }
        }
        for t in &self.triangles {
            out.push(3);
            for i in t {
                out.extend_from_slice(&(*i as i32).to_le_bytes());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use std::fmt::Write;

    use super::*;

    /// The mesh files are what their headers and the scene say: closed meshes have every
    /// edge twice in opposite directions (consistently oriented), the binary PLY has the
    /// byte count its header promises, and far slabs are generated, each with its file.
    #[test]
    fn mesh_files_are_closed_and_well_formed() {
        for data in [
            MeshData::cuboid(DVec3::ZERO, DVec3::new(2.0, 0.1, 2.0)),
            MeshData::convex(&[DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]),
            MeshData::convex(&[
                DVec3::X,
                -DVec3::X,
                DVec3::Y,
                -DVec3::Y,
                DVec3::Z,
                -DVec3::Z,
            ]),
            MeshData::sphere(5),
        ] {
            let mut edges = std::collections::BTreeMap::new();
            for t in &data.triangles {
                for k in 0..3 {
                    *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
                }
            }
            for (&(a, b), &n) in &edges {
                assert_eq!(n, 1, "edge {a}-{b} used {n} times in one direction");
                assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} is open");
            }
            let binary = data.ply_binary(DVec3::ZERO, false);
            let header = data.ply_header("binary_little_endian", "float").len();
            let body = data.positions.len() * 12 + data.triangles.len() * 13;
            assert_eq!(binary.len(), header + body);
        }
        let mut far = 0;
        for seed in 0..200 {
            let case = case(&mut Rng::new(seed));
            if case.text.contains("mesh \"slab\"") {
                far += 1;
                assert_eq!(case.files.len(), 1, "{}", case.text);
            }
        }
        assert!(far > 5, "{far} far slabs in 200 cases");
    }

    #[test]
    fn scenes_are_a_function_of_the_seed_and_vary() {
        let a = scene(&mut Rng::new(5));
        let b = scene(&mut Rng::new(5));
        let c = scene(&mut Rng::new(6));
        assert_eq!(a, b);
        assert_ne!(a, c);
        let mut all = String::new();
        for seed in 0..300 {
            let _ = write!(all, "{}", scene(&mut Rng::new(seed)));
            let _ = write!(all, "{}", case(&mut Rng::new(seed)).text);
        }
        for word in [
            "mesh { file \"m0.obj\"",
            "mesh { file \"m0.ply\"",
            "mesh \"slab\"",
            "disk \"rug\"",
            "priority",
            "fresnel exact",
            "highlight blinn",
            "settings",
            "camera perspective",
            "camera orthographic",
            "light point",
            "light spot",
            "light directional",
            "union",
            "intersection",
            "difference",
            "group",
            "sphere",
            "box",
            "cylinder",
            "cone",
            "plane",
            "disk",
            "triangle",
            "quadric",
            "ellipsoid",
            "paraboloid",
            "hyperboloid2",
            "checker(",
            "stripes(",
            "fresnel schlick",
            "shadows filtered",
            "1e39",
            "1e19",
            "-0",
            "rotate",
            "matrix",
            "fn f(n)",
            "step -",
            "while i <",
            "rs[i % len(rs)]",
        ] {
            assert!(all.contains(word), "the generator never writes `{word}`");
        }
    }
}
