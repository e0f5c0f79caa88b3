//! Random scene text: every setting, camera, light, material, pattern, shape, CSG operation
//! and transform of the language, with numbers drawn from ordinary values and from the edges
//! (±0, 1e-30, 1e19, 1e39, 1e308, ...), plus loops, functions and deep nesting.

use super::rng::Rng;

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
}

/// A whole random scene.
pub fn scene(rng: &mut Rng) -> String {
    let wild = *rng.pick(&[0.0, 0.02, 0.1, 0.3]);
    let mut g = Generator {
        rng,
        out: String::new(),
        wild,
        materials: Vec::new(),
        depth: 0,
    };
    g.settings();
    if g.rng.chance(0.8) {
        g.camera();
    }
    let lights = match g.rng.below(10) {
        0 => 0,
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
    g.out
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

    fn camera(&mut self) {
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
                "ior" => self
                    .rng
                    .pick(&[
                        "1", "1.5", "2.4", "1.33", "1e308", "1e-30", "1e39", "1.0001",
                    ])
                    .to_string(),
                "fresnel" => self.rng.pick(&["off", "schlick"]).to_string(),
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
                self.rng.pick(&["0", "0.5", "1e-30"]),
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

    fn statement(&mut self) {
        // Statements that often end in a (wanted) error are rarer, so that most scenes
        // reach the tracer.
        let text = match self.rng.below(40) {
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
                let n = *self.rng.pick(&["3", "10", "100", "1000", "40000"]);
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
                    // The second step's constructs: `step`, `while` with assignment, arrays
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

#[cfg(test)]
mod tests {
    use std::fmt::Write;

    use super::*;

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
        }
        for word in [
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
