//! The conversion of one 6.837 scene file: the top-level blocks (cameras, `Background`,
//! `Lights`, `Materials`, `Group`) into the IR, the course's switches into its settings,
//! then validation.
//!
//! How the course's model maps onto whitted's (docs/courses.md says it for users):
//! the material's ambient coefficient is 1, so the ambient term is `ambientLight·kd` as in
//! the course; highlights are Blinn-Phong `ks·(N·H)^exponent`; point lights' attenuation
//! `1 / (a + b·d + c·d²)` is not clamped; the camera's `direction` is the view direction and
//! its right-hand vector is `direction × up`, which is whitted's camera basis too; angles
//! are in degrees, as the course's parser read them.

use std::path::{Path, PathBuf};

use whitted_ir::{
    limits, Attenuation, BlockKind, Camera, Color, DMat4, DVec3, Diagnostic, Fresnel, Handle,
    Highlight, Light, LightKind, Material, Projection, Scene, SceneFormat, Settings, ShadowMode,
    SourceFile, SourceMap, Span, WrittenBlock, WrittenProperty,
};

use crate::reader::{Read, Reader};
use crate::tokens::Token;
use crate::{Conversion, CourseOptions, MeshLoader};

/// The course's background when a scene gives none (and its ambient light: none).
const DEFAULT_BACKGROUND: Color = Color::gray(0.5);

/// Reads the 6.837 scene `bytes` (the file at `path`) into a validated scene.
pub fn convert(
    path: &Path,
    bytes: Vec<u8>,
    loader: &mut dyn MeshLoader,
    options: &CourseOptions,
) -> Conversion {
    let mut sources = SourceMap::new();
    let display = path.to_string_lossy().into_owned();
    let text = match decode(&display, bytes, &mut sources) {
        Ok(text) => text,
        Err(diagnostic) => {
            return Conversion {
                sources,
                scene: None,
                diagnostics: vec![*diagnostic],
            }
        }
    };
    let file = sources.add(SourceFile::new(display, text.as_str()));
    let folder = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut converter = Converter {
        reader: Reader::new(&text, file),
        scene: Scene {
            sources,
            ..Scene::default()
        },
        materials: Vec::new(),
        current_material: None,
        default_material: None,
        loader,
        folder,
        warnings: Vec::new(),
        depth: 0,
        meshes: Vec::new(),
        background: None,
        ambient: None,
        seen: Vec::new(),
    };
    let outcome = converter.file();
    let Converter {
        mut scene,
        mut warnings,
        background,
        ambient,
        ..
    } = converter;
    if let Err(diagnostic) = outcome {
        warnings.retain(|d| d.is_error());
        warnings.push(*diagnostic);
        return Conversion {
            sources: scene.sources,
            scene: None,
            diagnostics: warnings,
        };
    }
    // The course's reader: a scene without lights is ray cast in flat colour, its ambient
    // light white (unless the scene gives one).
    let ambient = ambient.or((scene.lights.is_empty()).then_some(Color::WHITE));
    scene.settings = settings(options, background, ambient);
    scene.format = SceneFormat::Mit6837;
    warnings.extend(energy_note(&scene));
    let sources = scene.sources.clone();
    match whitted_ir::validate(scene) {
        Ok(valid) => Conversion {
            sources,
            scene: Some(valid),
            diagnostics: warnings,
        },
        Err(invalid) => {
            let mut diagnostics = invalid.diagnostics;
            diagnostics.extend(warnings);
            Conversion {
                sources,
                scene: None,
                diagnostics,
            }
        }
    }
}

/// The course's switches as settings: everything else is fixed by the course's model.
fn settings(
    options: &CourseOptions,
    background: Option<Color>,
    ambient: Option<Color>,
) -> Settings {
    Settings {
        width: options.width,
        height: options.height,
        max_depth: options.bounces,
        min_weight: options.weight,
        samples_per_pixel: options.samples,
        sampling: options.sampling,
        filter: options.filter,
        filter_radius: options.filter_radius,
        background: background.unwrap_or(DEFAULT_BACKGROUND),
        ambient: ambient.unwrap_or(Color::BLACK),
        // The error-bounded offset, not the course's fixed epsilon: it differs from the
        // course's images only where the course's had acne.
        epsilon: None,
        shadows: if options.transparent_shadows {
            ShadowMode::Filtered
        } else if options.shadows {
            ShadowMode::Opaque
        } else {
            ShadowMode::None
        },
        highlight: Highlight::Blinn,
        shade_back: options.shade_back,
        attenuation_clamp: false,
        // The course adds `reflectiveColor·trace + transparentColor·trace` as given.
        energy_clamp: false,
        // Without `-shade_back` the handout colours a surface seen from behind black.
        back_ambient: false,
        // The course's Phong adds the highlight whatever N·L is.
        highlight_gate: false,
        sample_position: options.sample_position,
        ..Settings::default()
    }
}

/// The note, once per scene, that a material's reflective and transparent colours add up to
/// more than 1 and are used as given (the course's model; whitted's own language scales them
/// down), so that a bright result is not a surprise.
fn energy_note(scene: &whitted_ir::Scene) -> Option<Diagnostic> {
    let mut over = scene.materials.iter_with_spans().filter(|(_, m, _)| {
        let (kr, kt) = (m.reflective, m.transmissive);
        [kr.r + kt.r, kr.g + kt.g, kr.b + kt.b]
            .iter()
            .any(|sum| *sum > 1.0 + 1e-9)
    });
    let (_, first, span) = over.next()?;
    let others = over.count();
    let (kr, kt) = (first.reflective, first.transmissive);
    let more = match others {
        0 => String::new(),
        1 => " (and 1 other material)".to_string(),
        n => format!(" (and {n} other materials)"),
    };
    Some(
        Diagnostic::warning(
            format!(
                "this material's reflectiveColor + transparentColor is more than 1{more}: the course adds reflective·trace + transparent·trace as given, so it returns more light than arrives"
            ),
            span,
        )
        .with_label(format!(
            "reflective {} {} {} + transparent {} {} {}",
            kr.r, kr.g, kr.b, kt.r, kt.g, kt.b
        ))
        .with_hint(
            "this is the course's model (docs/courses.md, \"Reflection and refraction\"); a scene in whitted's language scales the two down to add up to 1 unless it sets `energy_clamp off`",
        ),
    )
}

/// The file's text, or an error at its first byte that is not UTF-8 (or past the size
/// limit). The file is added to `sources` either way, so the error can show it.
pub(crate) fn decode(
    display: &str,
    bytes: Vec<u8>,
    sources: &mut SourceMap,
) -> Result<String, Box<Diagnostic>> {
    if bytes.len() > limits::MAX_SOURCE_BYTES {
        let file = sources.add(SourceFile::new(display, ""));
        return Err(Box::new(Diagnostic::error(
            format!(
                "`{display}` has {} bytes, past {}",
                bytes.len(),
                limits::describe("source size")
            ),
            Span::new(file, 0, 0),
        )));
    }
    match String::from_utf8(bytes) {
        Ok(text) => Ok(text),
        Err(error) => {
            let at = error.utf8_error().valid_up_to();
            let lossy = String::from_utf8_lossy(error.as_bytes()).into_owned();
            // The lossy text has the same bytes up to the first bad one.
            let file = sources.add(SourceFile::new(display, lossy.as_str()));
            Err(Box::new(
                Diagnostic::error(
                    format!("`{display}` is not UTF-8 text: byte {at} is not valid UTF-8"),
                    Span::new(file, at, at),
                )
                .with_label("not UTF-8"),
            ))
        }
    }
}

/// The state of one conversion: the reader, the scene being built and what the format
/// keeps between blocks (the materials by index, the current `MaterialIndex`).
pub(crate) struct Converter<'a, 'l> {
    pub reader: Reader<'a>,
    pub scene: Scene,
    /// `Materials` in file order: `MaterialIndex i` is `materials[i]`.
    pub materials: Vec<Handle<Material>>,
    /// The last `MaterialIndex`: as in the course's reader it holds until the next one,
    /// across group boundaries.
    pub current_material: Option<Handle<Material>>,
    /// Made on first use, for a group read before any `MaterialIndex`.
    pub default_material: Option<Handle<Material>>,
    pub loader: &'l mut dyn MeshLoader,
    /// The scene file's folder: mesh files are found relative to it.
    pub folder: PathBuf,
    /// Warnings (and errors that do not stop the reading).
    pub warnings: Vec<Diagnostic>,
    /// Nested groups and transforms, bounded by the nesting limit.
    pub depth: usize,
    /// Mesh files read so far (by path), each parsed and held once however often it is used.
    pub meshes: Vec<(PathBuf, Handle<whitted_ir::Mesh>)>,
    background: Option<Color>,
    ambient: Option<Color>,
    /// The top-level blocks read so far, each at most once.
    seen: Vec<(&'static str, Span)>,
}

impl<'a> Converter<'a, '_> {
    fn file(&mut self) -> Read<()> {
        let mut camera_seen = false;
        while let Some(token) = self.reader.tokens.next_token() {
            match token.text {
                "OrthographicCamera" | "PerspectiveCamera" => {
                    self.once("camera", token)?;
                    self.camera(token)?;
                    camera_seen = true;
                }
                "Background" => {
                    self.once("Background", token)?;
                    self.background(token)?;
                }
                "Lights" => {
                    self.once("Lights", token)?;
                    self.lights(token)?;
                }
                "Materials" => {
                    self.once("Materials", token)?;
                    self.material_list(token)?;
                }
                "Group" => {
                    self.once("Group", token)?;
                    let root = self.group(token, DMat4::IDENTITY)?;
                    self.scene.roots.push(root);
                }
                _ => {
                    return Err(Box::new(
                        Diagnostic::error(
                            format!(
                                "expected a camera, `Background`, `Lights`, `Materials` or \
                                 `Group`, found `{}`",
                                token.text
                            ),
                            self.reader.span(token),
                        )
                        .with_label("not a top-level block")
                        .with_hint(
                            "a 6.837 scene is a camera (`OrthographicCamera` or \
                             `PerspectiveCamera`), `Background`, `Lights`, `Materials` and one \
                             `Group` of objects",
                        ),
                    ))
                }
            }
        }
        if !camera_seen {
            let file = self.reader.file;
            return Err(Box::new(
                Diagnostic::error("the scene has no camera", Span::new(file, 0, 0))
                    .with_hint("add `OrthographicCamera { ... }` or `PerspectiveCamera { ... }`"),
            ));
        }
        Ok(())
    }

    /// Refuses a second block of the same kind.
    fn once(&mut self, what: &'static str, token: Token<'_>) -> Read<()> {
        let span = self.reader.span(token);
        if let Some((_, first)) = self.seen.iter().find(|(w, _)| *w == what) {
            return Err(Box::new(
                Diagnostic::error(format!("a second {what} in one scene"), span)
                    .with_label("given again here")
                    .with_secondary(*first, "first given here"),
            ));
        }
        self.seen.push((what, span));
        Ok(())
    }

    /// A nonzero vector (a direction or a normal).
    pub(crate) fn direction(&mut self, what: &str) -> Read<DVec3> {
        let start = self.reader.tokens.peek();
        let v = self.reader.vector(what)?;
        if v.length() > 0.0 && v.length().is_finite() {
            return Ok(v);
        }
        let span = match start {
            Some(t) => Span::new(self.reader.file, t.start, t.end),
            None => Span::detached(),
        };
        Err(Box::new(
            Diagnostic::error(format!("{what} must not be zero"), span).with_label("zero vector"),
        ))
    }

    pub(crate) fn color(&mut self, what: &str) -> Read<Color> {
        let v = self.reader.vector(what)?;
        Ok(Color::new(v.x, v.y, v.z))
    }

    fn camera(&mut self, keyword: Token<'a>) -> Read<()> {
        let orthographic = keyword.text == "OrthographicCamera";
        let last = if orthographic { "size" } else { "angle" };
        let known = ["center", "direction", "up", last];
        let (mut center, mut direction, mut up, mut extent) = (None, None, None, None);
        let names = [("center", "eye"), ("up", "up")];
        let span =
            self.written_fields(keyword, BlockKind::Camera, &names, &known, |this, field| {
                match field.text {
                    "center" => center = Some(this.reader.vector("the camera's center")?),
                    "direction" => direction = Some(this.direction("the camera's direction")?),
                    "up" => up = Some(this.direction("the camera's up")?),
                    "size" if orthographic => extent = Some(this.reader.number("the view's size")?),
                    "angle" if !orthographic => {
                        extent = Some(this.reader.number("the field of view in degrees")?)
                    }
                    _ => return Ok(false),
                }
                Ok(true)
            })?;
        let (Some(center), Some(direction), Some(up), Some(extent)) =
            (center, direction, up, extent)
        else {
            return self.missing(span, keyword.text, &known);
        };
        if direction.normalize().cross(up.normalize()).length() < 1e-9 {
            return Err(Box::new(Diagnostic::error(
                "the camera's `up` is parallel to its `direction`",
                span,
            )));
        }
        self.scene.camera = Camera {
            eye: center,
            look_at: center + direction.normalize(),
            up,
            projection: if orthographic {
                Projection::Orthographic {
                    view_height: extent,
                }
            } else {
                Projection::Perspective {
                    vertical_fov_degrees: extent,
                }
            },
        };
        self.scene.camera_span = span;
        Ok(())
    }

    fn background(&mut self, keyword: Token<'a>) -> Read<()> {
        let (mut color, mut ambient) = (None, None);
        let names = [("color", "background"), ("ambientLight", "ambient")];
        let known = ["color", "ambientLight"];
        self.written_fields(
            keyword,
            BlockKind::Settings,
            &names,
            &known,
            |this, field| {
                match field.text {
                    "color" => color = Some(this.color("the background colour")?),
                    "ambientLight" => ambient = Some(this.color("the ambient light")?),
                    _ => return Ok(false),
                }
                Ok(true)
            },
        )?;
        self.background = color;
        self.ambient = ambient;
        Ok(())
    }

    fn lights(&mut self, keyword: Token<'a>) -> Read<()> {
        self.reader.expect("{")?;
        self.reader.expect("numLights")?;
        let count = self
            .reader
            .count("the number of lights", limits::MAX_LIGHTS, "lights")?;
        for read in 0..=count {
            let token = self.reader.next("a light or `}`")?;
            match token.text {
                "}" if read == count => return Ok(()),
                "}" => {
                    return self.reader.error_at(
                        token,
                        format!("`numLights` is {count}, but the block has {read} lights"),
                    )
                }
                "DirectionalLight" | "PointLight" if read == count => {
                    return self.reader.error_at(
                        token,
                        format!("`numLights` is {count}, but here is one more light"),
                    )
                }
                "DirectionalLight" => self.directional_light(token)?,
                "PointLight" => self.point_light(token)?,
                other => {
                    return self.reader.error_at(
                        token,
                        format!(
                            "expected `DirectionalLight`, `PointLight` or `}}` in `{}`, found \
                             `{other}`",
                            keyword.text
                        ),
                    )
                }
            }
        }
        Ok(())
    }

    fn directional_light(&mut self, keyword: Token<'a>) -> Read<()> {
        let known = ["direction", "color"];
        let (mut direction, mut color) = (None, None);
        let names = [("direction", "direction"), ("color", "color")];
        let span =
            self.written_fields(keyword, BlockKind::Light, &names, &known, |this, field| {
                match field.text {
                    "direction" => direction = Some(this.direction("the light's direction")?),
                    "color" => color = Some(this.color("the light's colour")?),
                    _ => return Ok(false),
                }
                Ok(true)
            })?;
        let (Some(direction), Some(color)) = (direction, color) else {
            return self.missing(span, keyword.text, &known);
        };
        self.scene.lights.append(
            Light {
                name: None,
                color,
                kind: LightKind::Directional { direction },
            },
            span,
        );
        Ok(())
    }

    fn point_light(&mut self, keyword: Token<'a>) -> Read<()> {
        let known = ["position", "color", "attenuation"];
        let (mut position, mut color, mut attenuation) = (None, None, None);
        let names = [
            ("position", "position"),
            ("color", "color"),
            ("attenuation", "attenuation"),
        ];
        let span =
            self.written_fields(keyword, BlockKind::Light, &names, &known, |this, field| {
                match field.text {
                    "position" => position = Some(this.reader.vector("the light's position")?),
                    "color" => color = Some(this.color("the light's colour")?),
                    "attenuation" => {
                        let at = this.reader.span(field);
                        let terms = this.reader.vector("an attenuation term")?;
                        if terms.min_element() < 0.0 || terms == DVec3::ZERO {
                            return Err(Box::new(
                                Diagnostic::error(
                                    "the attenuation terms must be at least 0 and not all 0",
                                    at,
                                )
                                .with_hint("the light falls off as 1 / (a + b·d + c·d²)"),
                            ));
                        }
                        attenuation = Some(Attenuation {
                            constant: terms.x,
                            linear: terms.y,
                            quadratic: terms.z,
                        });
                    }
                    _ => return Ok(false),
                }
                Ok(true)
            })?;
        let (Some(position), Some(color)) = (position, color) else {
            return self.missing(span, keyword.text, &known[..2]);
        };
        self.scene.lights.append(
            Light {
                name: None,
                color,
                kind: LightKind::Point {
                    position,
                    // The course's default: no fall-off.
                    attenuation: attenuation.unwrap_or(Attenuation::NONE),
                },
            },
            span,
        );
        Ok(())
    }

    fn material_list(&mut self, keyword: Token<'a>) -> Read<()> {
        self.reader.expect("{")?;
        self.reader.expect("numMaterials")?;
        let count = self.reader.count(
            "the number of materials",
            limits::MAX_MATERIALS,
            "materials",
        )?;
        for read in 0..=count {
            let token = self.reader.next("a material or `}`")?;
            match token.text {
                "}" if read == count => return Ok(()),
                "}" => {
                    return self.reader.error_at(
                        token,
                        format!("`numMaterials` is {count}, but the block has {read} materials"),
                    )
                }
                "PhongMaterial" | "Material" if read == count => {
                    return self.reader.error_at(
                        token,
                        format!("`numMaterials` is {count}, but here is one more material"),
                    )
                }
                "PhongMaterial" | "Material" => self.material(token)?,
                "Checkerboard" | "Noise" | "Marble" | "Wood" if read == count => {
                    return self.reader.error_at(
                        token,
                        format!("`numMaterials` is {count}, but here is one more material"),
                    )
                }
                "Checkerboard" | "Noise" | "Marble" | "Wood" => self.procedural(token, read)?,
                other => {
                    return self.reader.error_at(
                        token,
                        format!(
                            "expected `PhongMaterial`, `Material`, `Checkerboard`, `Noise`, \
                             `Marble`, `Wood` or `}}` in `{}`, found `{other}`",
                            keyword.text
                        ),
                    )
                }
            }
        }
        Ok(())
    }

    fn material(&mut self, keyword: Token<'a>) -> Read<()> {
        let known = [
            "diffuseColor",
            "specularColor",
            "exponent",
            "reflectiveColor",
            "transparentColor",
            "indexOfRefraction",
        ];
        // The course's defaults; ka = 1 makes the ambient term ambientLight·kd.
        let mut m = Material {
            name: None,
            ambient: Color::WHITE,
            diffuse: Color::WHITE,
            specular: Color::BLACK,
            shininess: 1.0,
            reflective: Color::BLACK,
            transmissive: Color::BLACK,
            ior: 1.0,
            fresnel: Fresnel::Off,
            ..Material::default()
        };
        let names = [
            ("diffuseColor", "diffuse"),
            ("specularColor", "specular"),
            ("exponent", "shininess"),
            ("reflectiveColor", "reflective"),
            ("transparentColor", "transmissive"),
            ("indexOfRefraction", "ior"),
        ];
        let span = self.written_fields(
            keyword,
            BlockKind::Material,
            &names,
            &known,
            |this, field| {
                match field.text {
                    "diffuseColor" => m.diffuse = this.color("the diffuse colour")?,
                    "specularColor" => m.specular = this.color("the specular colour")?,
                    "exponent" => m.shininess = this.reader.number("the specular exponent")?,
                    "reflectiveColor" => m.reflective = this.color("the reflective colour")?,
                    "transparentColor" => m.transmissive = this.color("the transparent colour")?,
                    "indexOfRefraction" => m.ior = this.reader.number("the index of refraction")?,
                    _ => return Ok(false),
                }
                Ok(true)
            },
        )?;
        let handle = self.scene.materials.append(m, span);
        self.materials.push(handle);
        Ok(())
    }

    /// A block of named fields, `{ name value ... }`, in any order, each at most once:
    /// `field` reads the value of each name it knows and returns `false` for a name it does
    /// not. Returns the span from `keyword` to the closing brace.
    pub(crate) fn fields(
        &mut self,
        keyword: Token<'a>,
        known: &[&str],
        mut field: impl FnMut(&mut Self, Token<'a>) -> Read<bool>,
    ) -> Read<Span> {
        self.reader.expect("{")?;
        let mut seen: Vec<(&str, Span)> = Vec::new();
        loop {
            let token = self
                .reader
                .next(&format!("a field of `{}` or `}}`", keyword.text))?;
            if token.text == "}" {
                return Ok(Span::new(self.reader.file, keyword.start, token.end));
            }
            let at = self.reader.span(token);
            if let Some((_, first)) = seen.iter().find(|(name, _)| *name == token.text) {
                return Err(Box::new(
                    Diagnostic::error(
                        format!("`{}` is given twice in this `{}`", token.text, keyword.text),
                        at,
                    )
                    .with_label("given again here")
                    .with_secondary(*first, "first given here"),
                ));
            }
            seen.push((token.text, at));
            if !field(self, token)? {
                return Err(Box::new(
                    Diagnostic::error(
                        format!("`{}` has no field `{}`", keyword.text, token.text),
                        at,
                    )
                    .with_label("unknown field")
                    .with_hint(format!("its fields are {}", list(known))),
                ));
            }
        }
    }

    /// [`Converter::fields`] for a block whose fields are settings or properties of the
    /// language (`names`: each field's name there): records where each was written in the
    /// scene's table, as the language does for its own blocks.
    pub(crate) fn written_fields(
        &mut self,
        keyword: Token<'a>,
        kind: BlockKind,
        names: &[(&str, &'static str)],
        known: &[&str],
        mut field: impl FnMut(&mut Self, Token<'a>) -> Read<bool>,
    ) -> Read<Span> {
        let body_start = self.reader.tokens.peek().map_or(keyword.end, |t| t.start);
        let mut found: Vec<(Token<'a>, usize, usize)> = Vec::new();
        let span = self.fields(keyword, known, |this, name| {
            let start = this.reader.tokens.peek().map_or(name.end, |t| t.start);
            let known = field(this, name)?;
            found.push((name, start, this.reader.tokens.last_end()));
            Ok(known)
        })?;
        let file = self.reader.file;
        let block = self.scene.written.add_block(WrittenBlock {
            kind,
            header: span,
            body: Span::new(file, body_start, span.end as usize),
        });
        for (name, start, end) in found {
            if let Some((_, language)) = names.iter().find(|(ours, _)| *ours == name.text) {
                self.scene.written.add_property(WrittenProperty {
                    block,
                    name: language,
                    name_span: self.reader.span(name),
                    value_span: Span::new(file, start, end.max(start)),
                });
            }
        }
        Ok(span)
    }

    /// The error for a block that lacks a required field.
    pub(crate) fn missing<T>(&self, span: Span, keyword: &str, required: &[&str]) -> Read<T> {
        Err(Box::new(
            Diagnostic::error(format!("`{keyword}` needs {}", list(required)), span)
                .with_label("a field is missing"),
        ))
    }
}

/// `a`, `b` and `c`.
pub(crate) fn list(words: &[&str]) -> String {
    let quoted: Vec<String> = words.iter().map(|w| format!("`{w}`")).collect();
    match quoted.split_last() {
        None => String::new(),
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
    }
}
