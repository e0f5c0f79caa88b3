//! The format's objects: `Group` (with `numObjects` and `MaterialIndex`), `Sphere`, `Plane`,
//! `Triangle`, `TriangleMesh` and `Transform`, each appended to the IR with its full
//! `world_from_object` (a `Transform` is folded into the objects below it, not a node).

use whitted_ir::{
    limits, DMat4, DVec3, Diagnostic, Handle, Material, Object, ObjectKind, Shape, Span,
};

use crate::convert::Converter;
use crate::reader::Read;
use crate::tokens::Token;

/// The words that start an object.
const OBJECTS: &[&str] = &[
    "Group",
    "Sphere",
    "Plane",
    "Triangle",
    "TriangleMesh",
    "Transform",
];

/// The words of a transform inside `Transform { ... }`.
const TRANSFORMS: &[&str] = &[
    "Scale",
    "UniformScale",
    "Translate",
    "XRotate",
    "YRotate",
    "ZRotate",
    "Rotate",
    "Matrix",
];

/// How one transform word composes with the ones before it in its block.
enum Step {
    /// Multiplied on the right: it applies to the object before the ones written earlier.
    Then(DMat4),
    /// `Matrix`, multiplied on the left: it applies after the ones written earlier.
    Before(DMat4),
}

impl<'a> Converter<'a, '_> {
    /// One object starting at `keyword`, under the transform `world_from_parent`.
    fn object(&mut self, keyword: Token<'a>, world_from_parent: DMat4) -> Read<Handle<Object>> {
        match keyword.text {
            "Group" => self.group(keyword, world_from_parent),
            "Transform" => self.transform(keyword, world_from_parent),
            "Sphere" => self.sphere(keyword, world_from_parent),
            "Plane" => self.plane(keyword, world_from_parent),
            "Triangle" => self.triangle(keyword, world_from_parent),
            "TriangleMesh" => self.triangle_mesh(keyword, world_from_parent),
            other => Err(Box::new(
                Diagnostic::error(
                    format!("expected an object, found `{other}`"),
                    self.reader.span(keyword),
                )
                .with_label("not an object")
                .with_hint(format!("the objects are {}", crate::convert::list(OBJECTS))),
            )),
        }
    }

    /// Counts one more nested group or transform against the nesting limit.
    fn enter(&mut self, keyword: Token<'_>) -> Read<()> {
        self.depth += 1;
        if self.depth > limits::MAX_NESTING {
            return self.reader.error_at(
                keyword,
                format!(
                    "groups and transforms nest past {}",
                    limits::describe("nesting")
                ),
            );
        }
        Ok(())
    }

    /// Appends an object, within the objects limit.
    pub(crate) fn append(&mut self, object: Object, span: Span) -> Read<Handle<Object>> {
        if self.scene.objects.len() >= limits::MAX_OBJECTS {
            return Err(Box::new(Diagnostic::error(
                format!("this object is past {}", limits::describe("objects")),
                span,
            )));
        }
        Ok(self.scene.objects.append(object, span))
    }

    /// The material of a shape: the last `MaterialIndex`.
    fn shape_material(&self, keyword: Token<'_>) -> Read<Handle<Material>> {
        match self.current_material {
            Some(material) => Ok(material),
            None => Err(Box::new(
                Diagnostic::error(
                    format!("this `{}` has no material", keyword.text),
                    self.reader.span(keyword),
                )
                .with_label("no `MaterialIndex` before it")
                .with_hint("put `MaterialIndex i` before it in its group"),
            )),
        }
    }

    /// A group's material: the current one, or a default made once (a group's own material
    /// colours nothing; the IR needs one).
    fn group_material(&mut self) -> Handle<Material> {
        if let Some(material) = self.current_material.or(self.default_material) {
            return material;
        }
        let handle = self.scene.materials.append(
            Material {
                name: Some("default".into()),
                ..Material::default()
            },
            Span::detached(),
        );
        self.default_material = Some(handle);
        handle
    }

    pub(crate) fn group(
        &mut self,
        keyword: Token<'a>,
        world_from_parent: DMat4,
    ) -> Read<Handle<Object>> {
        self.enter(keyword)?;
        self.reader.expect("{")?;
        self.reader.expect("numObjects")?;
        let count = self
            .reader
            .count("the number of objects", limits::MAX_OBJECTS, "objects")?;
        let mut children = Vec::new();
        let end = loop {
            let token = self.reader.next("an object, `MaterialIndex` or `}`")?;
            match token.text {
                "}" => break token,
                "MaterialIndex" => {
                    let at = self.reader.tokens.peek();
                    let index = self.reader.count(
                        "a material index",
                        limits::MAX_MATERIALS,
                        "materials",
                    )?;
                    match self.materials.get(index) {
                        Some(&material) => self.current_material = Some(material),
                        None => {
                            let at = at.map_or(Span::detached(), |t| self.reader.span(t));
                            return Err(Box::new(
                                Diagnostic::error(
                                    format!(
                                        "there is no material {index}: {} defined before this",
                                        match self.materials.len() {
                                            0 => "no materials are".to_string(),
                                            1 => "only material 0 is".to_string(),
                                            n => format!("materials 0 to {} are", n - 1),
                                        }
                                    ),
                                    at,
                                )
                                .with_label("no such material")
                                .with_hint(
                                    "`Materials` must come before the `Group` that uses them",
                                ),
                            ));
                        }
                    }
                }
                _ => {
                    if children.len() == count && OBJECTS.contains(&token.text) {
                        return self.reader.error_at(
                            token,
                            format!("`numObjects` is {count}, but here is one more object"),
                        );
                    }
                    children.push(self.object(token, world_from_parent)?);
                }
            }
        };
        if children.len() != count {
            return self.reader.error_at(
                end,
                format!(
                    "`numObjects` is {count}, but the group has {} object{}",
                    children.len(),
                    if children.len() == 1 { "" } else { "s" }
                ),
            );
        }
        self.depth -= 1;
        let material = self.group_material();
        let span = Span::new(self.reader.file, keyword.start, end.end);
        self.append(
            Object {
                name: None,
                kind: ObjectKind::Group { children },
                world_from_object: world_from_parent.into(),
                material,
            },
            span,
        )
    }

    /// `Transform { <transforms> <object> }`, composed as the course's reader composed them:
    /// each transform multiplies on the right (the last one written applies to the object
    /// first), except `Matrix`, which multiplies on the left (it applies after the transforms
    /// written before it in the same block). The block's transform applies under the
    /// parent's.
    fn transform(&mut self, keyword: Token<'a>, world_from_parent: DMat4) -> Read<Handle<Object>> {
        self.enter(keyword)?;
        self.reader.expect("{")?;
        let mut local = DMat4::IDENTITY;
        let object = loop {
            let token = self.reader.next("a transform or an object")?;
            match self.transform_step(token)? {
                Some(Step::Then(step)) => local *= step,
                Some(Step::Before(matrix)) => local = matrix * local,
                None if OBJECTS.contains(&token.text) => {
                    break self.object(token, world_from_parent * local)?
                }
                None => {
                    return Err(Box::new(
                        Diagnostic::error(
                            format!("expected a transform or an object, found `{}`", token.text),
                            self.reader.span(token),
                        )
                        .with_hint(format!(
                            "the transforms are {}; the objects are {}",
                            crate::convert::list(TRANSFORMS),
                            crate::convert::list(OBJECTS)
                        )),
                    ))
                }
            }
        };
        self.reader.expect("}")?;
        self.depth -= 1;
        Ok(object)
    }

    /// `Transform { <transforms> }` with no object: a procedural material's matrix, composed
    /// as an object's `Transform` composes its transforms.
    pub(crate) fn transform_only(&mut self, keyword: Token<'a>) -> Read<DMat4> {
        self.reader.expect("{")?;
        let mut local = DMat4::IDENTITY;
        loop {
            let token = self.reader.next("a transform or `}`")?;
            match self.transform_step(token)? {
                Some(Step::Then(step)) => local *= step,
                Some(Step::Before(matrix)) => local = matrix * local,
                None if token.text == "}" => return Ok(local),
                None => {
                    return Err(Box::new(
                        Diagnostic::error(
                            format!(
                                "expected a transform or `}}` in a material's `{}`, found `{}`",
                                keyword.text, token.text
                            ),
                            self.reader.span(token),
                        )
                        .with_hint(format!(
                            "the transforms are {}; a material's `Transform` holds no object",
                            crate::convert::list(TRANSFORMS)
                        )),
                    ))
                }
            }
        }
    }

    /// The transform that the word `token` starts, read with its argument; `None` for a
    /// word that is not a transform (nothing is read then).
    fn transform_step(&mut self, token: Token<'a>) -> Read<Option<Step>> {
        let step = match token.text {
            "Scale" => DMat4::from_scale(self.argument(|r| r.reader.vector("a scale factor"))?),
            "UniformScale" => DMat4::from_scale(DVec3::splat(
                self.argument(|r| r.reader.number("a scale factor"))?,
            )),
            "Translate" => {
                DMat4::from_translation(self.argument(|r| r.reader.vector("a translation"))?)
            }
            "XRotate" => DMat4::from_rotation_x(self.argument(Self::degrees)?),
            "YRotate" => DMat4::from_rotation_y(self.argument(Self::degrees)?),
            "ZRotate" => DMat4::from_rotation_z(self.argument(Self::degrees)?),
            "Rotate" => self.rotate(token)?,
            "Matrix" => return Ok(Some(Step::Before(self.matrix(token)?))),
            _ => return Ok(None),
        };
        Ok(Some(Step::Then(step)))
    }

    /// A transform's argument, bare (`Scale 1 2 3`) or in braces (`Scale { 1 2 3 }`, as some
    /// years of the course wrote it).
    fn argument<T>(&mut self, read: impl FnOnce(&mut Self) -> Read<T>) -> Read<T> {
        if self.reader.tokens.peek().is_some_and(|t| t.text == "{") {
            self.reader.expect("{")?;
            let value = read(self)?;
            self.reader.expect("}")?;
            Ok(value)
        } else {
            read(self)
        }
    }

    /// An angle in degrees, as radians.
    fn degrees(&mut self) -> Read<f64> {
        Ok(self.reader.number("an angle in degrees")?.to_radians())
    }

    /// `Rotate { x y z degrees }` as the course's reader read it, or with names,
    /// `Rotate { axis x y z angle degrees }`.
    fn rotate(&mut self, keyword: Token<'a>) -> Read<DMat4> {
        let open = self.reader.expect("{")?;
        let named = self
            .reader
            .tokens
            .peek()
            .is_some_and(|t| t.text == "axis" || t.text == "angle");
        let (axis, angle) = if named {
            let (mut axis, mut angle) = (None, None);
            loop {
                let token = self.reader.next("`axis`, `angle` or `}`")?;
                let slot_is_set = match token.text {
                    "}" => break,
                    "axis" => axis.is_some(),
                    "angle" => angle.is_some(),
                    other => {
                        return self.reader.error_at(
                            token,
                            format!("`Rotate` has no field `{other}`: it takes `axis` and `angle`"),
                        )
                    }
                };
                if slot_is_set {
                    return self.reader.error_at(
                        token,
                        format!("`{}` is given twice in this `Rotate`", token.text),
                    );
                }
                if token.text == "axis" {
                    axis = Some(self.direction("the rotation axis")?);
                } else {
                    angle = Some(self.degrees()?);
                }
            }
            match (axis, angle) {
                (Some(axis), Some(angle)) => (axis, angle),
                _ => {
                    let span = Span::new(self.reader.file, keyword.start, open.end);
                    return self.missing(span, keyword.text, &["axis", "angle"]);
                }
            }
        } else {
            let axis = self.direction("the rotation axis")?;
            let angle = self.degrees()?;
            self.reader.expect("}")?;
            (axis, angle)
        };
        Ok(DMat4::from_axis_angle(axis.normalize(), angle))
    }

    /// `Matrix { 16 numbers }`, row by row as written (the translation in the fourth
    /// column); the last row must be `0 0 0 1`.
    fn matrix(&mut self, keyword: Token<'a>) -> Read<DMat4> {
        self.reader.expect("{")?;
        let mut rows = [0.0; 16];
        for (i, entry) in rows.iter_mut().enumerate() {
            *entry = self.reader.number(&format!(
                "entry {} of the matrix's row {}",
                i % 4 + 1,
                i / 4 + 1
            ))?;
        }
        let end = self.reader.expect("}")?;
        if rows[12..] != [0.0, 0.0, 0.0, 1.0] {
            return Err(Box::new(
                Diagnostic::error(
                    "the matrix's last row must be `0 0 0 1`",
                    Span::new(self.reader.file, keyword.start, end.end),
                )
                .with_hint(
                    "the matrix is read row by row, with the translation in the fourth column",
                ),
            ));
        }
        Ok(DMat4::from_cols_array(&rows).transpose())
    }

    fn shape(
        &mut self,
        keyword: Token<'a>,
        shape: Shape,
        span: Span,
        world_from_object: DMat4,
    ) -> Read<Handle<Object>> {
        let material = self.shape_material(keyword)?;
        self.append(
            Object {
                name: None,
                kind: ObjectKind::Shape {
                    shape: shape.into(),
                },
                world_from_object: world_from_object.into(),
                material,
            },
            span,
        )
    }

    fn sphere(&mut self, keyword: Token<'a>, world: DMat4) -> Read<Handle<Object>> {
        let known = ["center", "radius"];
        let (mut center, mut radius) = (None, None);
        let span = self.fields(keyword, &known, |this, field| {
            match field.text {
                "center" => center = Some(this.reader.vector("the sphere's center")?),
                "radius" => radius = Some(this.reader.number("the sphere's radius")?),
                _ => return Ok(false),
            }
            Ok(true)
        })?;
        let (Some(center), Some(radius)) = (center, radius) else {
            return self.missing(span, keyword.text, &known);
        };
        self.shape(keyword, Shape::Sphere { center, radius }, span, world)
    }

    fn plane(&mut self, keyword: Token<'a>, world: DMat4) -> Read<Handle<Object>> {
        let known = ["normal", "offset"];
        let (mut normal, mut offset) = (None, None);
        let span = self.fields(keyword, &known, |this, field| {
            match field.text {
                "normal" => normal = Some(this.direction("the plane's normal")?),
                "offset" => offset = Some(this.reader.number("the plane's offset")?),
                _ => return Ok(false),
            }
            Ok(true)
        })?;
        let (Some(normal), Some(offset)) = (normal, offset) else {
            return self.missing(span, keyword.text, &known);
        };
        // The course normalised the normal and kept the offset: the plane is `offset`
        // along the unit normal from the origin.
        let shape = Shape::Plane {
            normal: normal.normalize(),
            offset,
        };
        self.shape(keyword, shape, span, world)
    }

    fn triangle(&mut self, keyword: Token<'a>, world: DMat4) -> Read<Handle<Object>> {
        let known = ["vertex0", "vertex1", "vertex2"];
        let mut corners = [None; 3];
        let span = self.fields(keyword, &known, |this, field| {
            let i = match field.text {
                "vertex0" => 0,
                "vertex1" => 1,
                "vertex2" => 2,
                _ => return Ok(false),
            };
            corners[i] = Some(this.reader.vector("a triangle corner")?);
            Ok(true)
        })?;
        let [Some(a), Some(b), Some(c)] = corners else {
            return self.missing(span, keyword.text, &known);
        };
        self.shape(keyword, Shape::Triangle { a, b, c }, span, world)
    }

    fn triangle_mesh(&mut self, keyword: Token<'a>, world: DMat4) -> Read<Handle<Object>> {
        let known = ["obj_file"];
        let mut file = None;
        let span = self.fields(keyword, &known, |this, field| {
            if field.text != "obj_file" {
                return Ok(false);
            }
            file = Some(this.reader.next("the name of an .obj file")?);
            Ok(true)
        })?;
        let Some(file) = file else {
            return self.missing(span, keyword.text, &known);
        };
        let material = self.shape_material(keyword)?;
        self.mesh(file, span, world, material)
    }
}
