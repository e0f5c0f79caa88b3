//! Object, light, camera and settings statements: each opens a builder that its block's
//! properties (`properties.rs`) fill in.
//!
//! Each property is checked where it is written, so an error points at the value that is
//! wrong ("a sphere's radius must be greater than 0"), not at the whole object. Checks that
//! involve several fields (a box's corners, a camera's view) are left to the IR validator,
//! which reports them at the object's header.

use whitted_ir::{
    Diagnostic, Handle, Light, LightKind, Mesh, Object, ObjectKind, Quadric, QuadricForm, Shape,
    Span,
};

use whitted_ir::BlockKind;

use super::builders::*;
use super::{inherit, Abort, Eval, Evaluator, Sink};
use crate::ast::*;
use crate::schema::{LightTag, ObjectTag, Prop};

impl<'a> Evaluator<'a> {
    // ---- statements that fill a builder ----------------------------------------------------

    pub(super) fn object(
        &mut self,
        tag: ObjectTag,
        kind: Ident,
        name: Option<&StrLit>,
        body: &Block,
    ) -> Eval<()> {
        let header = match name {
            Some(name) => kind.span.to(name.span),
            None => kind.span,
        };
        self.check_sink(header)?;
        let errors_before = self.error_events;
        self.targets.push(Target::Object(Box::new(ObjectBuilder {
            tag,
            fields: ShapeFields::defaults(tag),
            placement: Placement::new(),
            set: PropSet::new(),
        })));
        if tag.is_container() {
            self.sinks.push(Sink::Collect(Vec::new()));
        }
        let result = self.items(&body.items);
        let children = if tag.is_container() {
            match self.sinks.pop() {
                Some(Sink::Collect(children)) => children,
                _ => Vec::new(),
            }
        } else {
            Vec::new()
        };
        let builder = match self.targets.pop() {
            Some(Target::Object(builder)) => builder,
            _ => return Err(Abort::Reported),
        };
        result?;
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        let material = match builder.placement.material {
            Some(id) => Some(self.lower_material(id)?),
            None => None,
        };
        let kind = match tag {
            ObjectTag::Union | ObjectTag::Intersection | ObjectTag::Difference => {
                self.place_subtree(&children, builder.placement.transform, material);
                let op = match tag {
                    ObjectTag::Union => whitted_ir::CsgOp::Union,
                    ObjectTag::Intersection => whitted_ir::CsgOp::Intersection,
                    _ => whitted_ir::CsgOp::Difference,
                };
                ObjectKind::Csg { op, children }
            }
            ObjectTag::Group => {
                self.place_subtree(&children, builder.placement.transform, material);
                ObjectKind::Group { children }
            }
            _ => ObjectKind::Shape {
                shape: self.shape(tag, &builder, header)?.into(),
            },
        };
        let object = Object {
            name: self.object_name(name)?,
            kind,
            world_from_object: builder.placement.transform.into(),
            material: material.unwrap_or_else(inherit),
        };
        let handle = self.scene.objects.append(object, header);
        self.record_provenance(handle);
        self.emit(handle);
        Ok(())
    }

    /// The mesh of the file at `path` (relative to the folder of the file that names it),
    /// registered on first use so that every instance shares it. Its geometry is read
    /// after evaluation (`crate::mesh`), through the loader, at `span`.
    pub(super) fn mesh_file(&mut self, path: &str, span: Span) -> Eval<Handle<Mesh>> {
        let folder = self
            .scene
            .sources
            .get(span.file)
            .map(|source| std::path::PathBuf::from(&source.path))
            .and_then(|p| p.parent().map(std::path::Path::to_path_buf))
            .unwrap_or_default();
        let target = crate::compile::normalize(&folder.join(path));
        if let Some(&handle) = self.mesh_files.get(&target) {
            return Ok(handle);
        }
        let mesh = Mesh {
            file: target.to_string_lossy().into_owned(),
            positions: Vec::new(),
            normals: Vec::new(),
            triangles: Vec::new(),
            solid: false,
            not_solid: None,
        };
        let handle = self.scene.meshes.append(mesh, span);
        self.mesh_files.insert(target, handle);
        Ok(handle)
    }

    fn shape(&mut self, tag: ObjectTag, builder: &ObjectBuilder, header: Span) -> Eval<Shape> {
        let f = &builder.fields;
        let required = match tag {
            ObjectTag::Triangle => {
                Some((Prop::Vertices, "vertices <0, 0, 0>, <1, 0, 0>, <0, 1, 0>"))
            }
            ObjectTag::Mesh => Some((Prop::File, "file \"models/gem.obj\"")),
            ObjectTag::Quadric => Some((
                Prop::Coefficients,
                "coefficients <1, 1, 1>, <0, 0, 0>, <0, 0, 0>, -1",
            )),
            _ => None,
        };
        if let Some((prop, example)) = required {
            if !builder.set.has(prop) {
                return self.fail(
                    Diagnostic::error(
                        format!(
                            "{} needs `{}`",
                            crate::schema::article(tag.name()),
                            prop.name()
                        ),
                        header,
                    )
                    .with_label(format!("no `{}` given", prop.name()))
                    .with_hint(format!("for example: `{example}`")),
                );
            }
        }
        let r = f.radii;
        let inverse_square = |x: f64| 1.0 / (x * x);
        let quadric = |form, c: [f64; 10]| Shape::Quadric {
            form,
            quadric: Quadric::from_coefficients(c),
        };
        Ok(match tag {
            ObjectTag::Sphere => Shape::Sphere {
                center: f.center,
                radius: f.radius,
            },
            ObjectTag::Plane => Shape::Plane {
                normal: f.normal,
                offset: f.offset,
            },
            ObjectTag::Box => Shape::Box {
                min: f.min,
                max: f.max,
            },
            ObjectTag::Cylinder => Shape::Cylinder {
                base: f.base,
                apex: f.apex,
                radius: f.radius,
                capped: !f.open,
            },
            ObjectTag::Cone => Shape::Cone {
                base: f.base,
                base_radius: f.base_radius,
                apex: f.apex,
                apex_radius: f.apex_radius,
                capped: !f.open,
            },
            ObjectTag::Torus => Shape::Torus {
                major: f.major,
                minor: f.minor,
            },
            ObjectTag::Disk => Shape::Disk {
                center: f.center,
                normal: f.normal,
                radius: f.radius,
            },
            ObjectTag::Mesh => match f.mesh {
                Some(mesh) => Shape::Mesh {
                    mesh,
                    smooth: f.smooth,
                },
                // `file` was given (checked above) but failed, and said so.
                None => return Err(Abort::Reported),
            },
            ObjectTag::Triangle => Shape::Triangle {
                a: f.vertices[0],
                b: f.vertices[1],
                c: f.vertices[2],
            },
            ObjectTag::Quadric => quadric(QuadricForm::General, f.coefficients),
            // x²/a² + y²/b² + z²/c² - 1
            ObjectTag::Ellipsoid => quadric(
                QuadricForm::Ellipsoid,
                [
                    inverse_square(r.x),
                    inverse_square(r.y),
                    inverse_square(r.z),
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    -1.0,
                ],
            ),
            // x²/a² + z²/c² - y/b: opens upwards; at height b its cross-section has radii a, c.
            ObjectTag::Paraboloid => quadric(
                QuadricForm::EllipticParaboloid,
                [
                    inverse_square(r.x),
                    0.0,
                    inverse_square(r.z),
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    -1.0 / r.y,
                    0.0,
                    0.0,
                ],
            ),
            // x²/a² - y²/b² + z²/c² - 1: one sheet around the y axis, waist radii a and c.
            ObjectTag::Hyperboloid => quadric(
                QuadricForm::HyperboloidOneSheet,
                [
                    inverse_square(r.x),
                    -inverse_square(r.y),
                    inverse_square(r.z),
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    -1.0,
                ],
            ),
            // x²/a² - y²/b² + z²/c² + 1: two sheets opening along ±y, tips at y = ±b.
            ObjectTag::Hyperboloid2 => quadric(
                QuadricForm::HyperboloidTwoSheets,
                [
                    inverse_square(r.x),
                    -inverse_square(r.y),
                    inverse_square(r.z),
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    0.0,
                    1.0,
                ],
            ),
            ObjectTag::Union
            | ObjectTag::Intersection
            | ObjectTag::Difference
            | ObjectTag::Group => return Err(Abort::Reported),
        })
    }

    /// The block after a call statement: transforms and a material for what the call made.
    pub(super) fn modifiers(&mut self, block: &Block) -> Eval<Placement> {
        let errors_before = self.error_events;
        self.targets
            .push(Target::Modifiers(Placement::new(), PropSet::new()));
        let result = self.items(&block.items);
        let placement = match self.targets.pop() {
            Some(Target::Modifiers(placement, _)) => placement,
            _ => Placement::new(),
        };
        result?;
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        Ok(placement)
    }

    pub(super) fn settings(&mut self, item: Span, body: &Block) -> Eval<()> {
        let start = item.start as usize;
        let header = Span::new(item.file, start, start + "settings".len());
        let previous = self.enter_written_block(BlockKind::Settings, header, body.span);
        self.targets.push(Target::Settings);
        let result = self.items(&body.items);
        self.targets.pop();
        self.leave_written_block(previous);
        result.map(|_| ())
    }

    pub(super) fn camera(
        &mut self,
        tag: crate::schema::CameraTag,
        header: Span,
        body: &Block,
    ) -> Eval<()> {
        if let Some(first) = self.camera_span {
            return self.fail(
                Diagnostic::error("the scene already has a camera", header)
                    .with_label("a second camera")
                    .with_secondary(first, "the first camera")
                    .with_hint("a scene has one camera; remove one of them"),
            );
        }
        let errors_before = self.error_events;
        let previous = self.enter_written_block(BlockKind::Camera, header, body.span);
        self.targets.push(Target::Camera(CameraBuilder::new(tag)));
        let result = self.items(&body.items);
        self.leave_written_block(previous);
        let builder = match self.targets.pop() {
            Some(Target::Camera(builder)) => builder,
            _ => return Err(Abort::Reported),
        };
        result?;
        // Claim the camera even if its body failed, so a second one is still reported.
        self.camera_span = Some(header);
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        self.scene.camera = builder.build();
        Ok(())
    }

    pub(super) fn light(
        &mut self,
        tag: LightTag,
        header: Span,
        name: Option<&StrLit>,
        body: &Block,
    ) -> Eval<()> {
        if self.scene.lights.len() >= self.limits.max_lights {
            let limit = self.limits.max_lights;
            return self.fatal(
                Diagnostic::error(format!("the lights limit ({limit}) was reached"), header)
                    .with_label("one light too many")
                    .with_hint("every shading point visits every light; see \"Limits\" in docs/language.md"),
            );
        }
        let errors_before = self.error_events;
        let previous = self.enter_written_block(BlockKind::Light, header, body.span);
        self.targets.push(Target::Light(LightBuilder::new()));
        let result = self.items(&body.items);
        self.leave_written_block(previous);
        let builder = match self.targets.pop() {
            Some(Target::Light(builder)) => builder,
            _ => return Err(Abort::Reported),
        };
        result?;
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        let needs_position = tag != LightTag::Directional;
        let needs_direction = tag != LightTag::Point;
        for (needed, prop) in [
            (needs_position, Prop::Position),
            (needs_direction, Prop::Direction),
        ] {
            if needed && !builder.set.has(prop) {
                return self.fail(
                    Diagnostic::error(
                        format!("a {} light needs a `{}`", tag.name(), prop.name()),
                        header,
                    )
                    .with_label(format!("no `{}` given", prop.name())),
                );
            }
        }
        if tag == LightTag::Spot && builder.inner > builder.outer {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "a spot light's `inner` angle ({}) must not be larger than its `outer` angle ({})",
                        builder.inner, builder.outer
                    ),
                    header,
                )
                .with_label("inner > outer"),
            );
        }
        let kind = match tag {
            LightTag::Point => LightKind::Point {
                position: builder.position,
                attenuation: builder.attenuation,
            },
            LightTag::Directional => LightKind::Directional {
                direction: builder.direction,
            },
            LightTag::Spot => LightKind::Spot {
                position: builder.position,
                direction: builder.direction,
                inner_angle_degrees: builder.inner,
                outer_angle_degrees: builder.outer,
                attenuation: builder.attenuation,
            },
        };
        let name = self.name_text(name)?;
        self.scene.lights.append(
            Light {
                name,
                color: builder.color,
                kind,
            },
            header,
        );
        Ok(())
    }
}
