//! Materials and patterns: evaluated into tables (so values are small ids), and lowered into
//! the IR on first use, with inheritance already applied. A pattern of two colours becomes
//! two derived IR materials (the host material with each colour as its diffuse).

use whitted_ir::{
    BlockKind, DMat4, DVec3, Diagnostic, Handle, Material, Pattern, PatternKind, Span,
};

use super::builders::{MaterialBuilder, PropSet, Target};
use super::{Abort, Eval, Evaluator};
use crate::ast::*;
use crate::value::{MaterialId, PatternId, Value};

/// One side of a pattern.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum PatternPart {
    Color(DVec3),
    Material(MaterialId),
}

#[derive(Clone, Debug)]
pub(crate) struct PatternDef {
    pub kind: PatternKind,
    pub a: PatternPart,
    pub b: PatternPart,
    pub scale: f64,
    pub pattern_from_object: DMat4,
}

/// An evaluated material: its resolved fields, its pattern, and its IR handle once lowered.
#[derive(Clone, Debug)]
pub(crate) struct MaterialDef {
    pub material: Material,
    pub pattern: Option<PatternId>,
    pub span: Span,
    pub lowered: Option<Handle<Material>>,
}

impl<'a> Evaluator<'a> {
    pub(super) fn add_pattern(&mut self, pattern: PatternDef) -> PatternId {
        self.patterns.push(pattern);
        (self.patterns.len() - 1) as PatternId
    }

    /// Evaluates `material [: parent] { ... }` into a new table entry.
    pub(super) fn material(
        &mut self,
        body: &MaterialBody,
        name: Option<String>,
    ) -> Eval<MaterialId> {
        let (material, pattern) = match &body.parent {
            None => (Material::default(), None),
            Some(parent) => match self.name_value(parent) {
                Value::Material(id) => {
                    let def = &self.materials[id as usize];
                    (def.material.clone(), def.pattern)
                }
                Value::Poisoned => return Err(Abort::Reported),
                other => {
                    let text = self.name(parent.ident.sym);
                    return self.fail(
                        Diagnostic::error(
                            format!("`{text}` is {}, not a material", other.type_name()),
                            parent.ident.span,
                        )
                        .with_label("a material is derived from another material"),
                    );
                }
            },
        };
        self.check_material_budget(body.header, false)?;
        let errors_before = self.error_events;
        self.targets
            .push(Target::Material(Box::new(MaterialBuilder {
                material,
                pattern,
                set: PropSet::new(),
            })));
        let previous = self.enter_written_block(BlockKind::Material, body.header, body.block.span);
        let result = self.items(&body.block.items);
        self.leave_written_block(previous);
        let builder = match self.targets.pop() {
            Some(Target::Material(builder)) => builder,
            _ => return Err(Abort::Reported),
        };
        result?;
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        let mut material = builder.material;
        material.name = name;
        self.warn_if_material_gains_energy(&material, body.header);
        self.materials.push(MaterialDef {
            material,
            pattern: builder.pattern,
            span: body.header,
            lowered: None,
        });
        Ok((self.materials.len() - 1) as MaterialId)
    }

    /// Warns when `reflective + transmissive` exceeds 1 on a channel: every bounce would then
    /// return more light than arrives, and deep recursion washes the object out to white.
    fn warn_if_material_gains_energy(&mut self, material: &Material, span: Span) {
        let (kr, kt) = (material.reflective, material.transmissive);
        let sums = [kr.r + kt.r, kr.g + kt.g, kr.b + kt.b];
        let largest = sums.iter().copied().fold(0.0, f64::max);
        if largest > 1.0 + 1e-9 && self.warned_materials.insert(span) {
            let hint = match material.fresnel {
                whitted_ir::Fresnel::Schlick | whitted_ir::Fresnel::Exact => "with `fresnel schlick` or `fresnel exact`, `transmissive` is already split between reflection and refraction: set `reflective 0` for plain glass (by default the tracer scales the two down to add up to 1 at each surface; with `energy_clamp off` they are used as given)",
                whitted_ir::Fresnel::Off => "keep `reflective + transmissive` at most 1 on every channel (by default the tracer scales the two down to add up to 1 at each surface; with `energy_clamp off` they are used as given)",
            };
            self.diagnostics.push(
                Diagnostic::warning(
                    format!("this material reflects and transmits more light than it receives (reflective + transmissive = {largest})"),
                    span,
                )
                .with_label("returns more light than arrives")
                .with_hint(hint),
            );
        }
    }

    /// Stops evaluation when one more material would pass the materials limit: material
    /// definitions evaluated (used or not) count, and so do materials in the IR.
    fn check_material_budget(&mut self, span: Span, in_ir: bool) -> Eval<()> {
        let limit = self.limits.max_materials;
        let count = if in_ir {
            self.scene.materials.len()
        } else {
            self.materials.len()
        };
        if count < limit {
            return Ok(());
        }
        self.fatal(
            Diagnostic::error(format!("the materials limit ({limit}) was reached"), span)
                .with_label("one material too many")
                .with_hint(
                    "define a material once, before a loop, and use it by name inside; see \"Limits\" in docs/language.md",
                ),
        )
    }

    /// The IR handle of a material, appending it (and its pattern's parts) on first use.
    pub(super) fn lower_material(&mut self, id: MaterialId) -> Eval<Handle<Material>> {
        let index = id as usize;
        let Some(def) = self.materials.get(index) else {
            return Err(Abort::Reported);
        };
        if let Some(handle) = def.lowered {
            return Ok(handle);
        }
        let span = def.span;
        // A pattern's parts may be patterned materials themselves: bound the chain.
        self.enter(span)?;
        let result = self.lower_material_inner(index);
        self.leave();
        result
    }

    fn lower_material_inner(&mut self, index: usize) -> Eval<Handle<Material>> {
        let def = self.materials[index].clone();
        self.check_material_budget(def.span, true)?;
        let mut material = def.material;
        if let Some(pattern_id) = def.pattern {
            let Some(pattern) = self.patterns.get(pattern_id as usize).cloned() else {
                return Err(Abort::Reported);
            };
            let a = self.lower_part(pattern.a, &material, "a", def.span)?;
            let b = self.lower_part(pattern.b, &material, "b", def.span)?;
            material.pattern = Some(Pattern {
                kind: pattern.kind,
                a,
                b,
                scale: pattern.scale,
                pattern_from_object: pattern.pattern_from_object,
            });
        }
        let handle = self.scene.materials.append(material, def.span);
        self.materials[index].lowered = Some(handle);
        Ok(handle)
    }

    fn lower_part(
        &mut self,
        part: PatternPart,
        host: &Material,
        suffix: &str,
        span: Span,
    ) -> Eval<Handle<Material>> {
        match part {
            PatternPart::Material(id) => self.lower_material(id),
            PatternPart::Color(color) => {
                self.check_material_budget(span, true)?;
                let derived = Material {
                    name: host.name.as_ref().map(|n| format!("{n}/{suffix}")),
                    diffuse: whitted_ir::Color::new(color.x, color.y, color.z),
                    pattern: None,
                    ..host.clone()
                };
                Ok(self.scene.materials.append(derived, span))
            }
        }
    }

    /// A pattern moved by a transform block: `diffuse checker(a, b, 1) { rotate <0, 45, 0> }`.
    /// The block places the pattern in object space, so the pattern sees the inverse.
    pub(super) fn transformed_pattern(
        &mut self,
        pattern: PatternId,
        block: &Block,
    ) -> Eval<PatternId> {
        let errors_before = self.error_events;
        self.targets.push(Target::PatternTransform(DMat4::IDENTITY));
        let result = self.items(&block.items);
        let transform = match self.targets.pop() {
            Some(Target::PatternTransform(m)) => m,
            _ => DMat4::IDENTITY,
        };
        result?;
        if self.error_events > errors_before {
            return Err(Abort::Reported);
        }
        if !transform.is_finite() || transform.determinant().abs() < 1e-12 {
            return self.fail(
                Diagnostic::error("this pattern transform cannot be undone", block.span)
                    .with_label("not invertible")
                    .with_hint("a scale by zero flattens the pattern"),
            );
        }
        let Some(mut def) = self.patterns.get(pattern as usize).cloned() else {
            return Err(Abort::Reported);
        };
        def.pattern_from_object *= transform.inverse();
        Ok(self.add_pattern(def))
    }

    /// The value a resolved name refers to.
    pub(super) fn name_value(&self, name: &Name) -> Value {
        match name.res {
            Res::Local(slot) => self
                .stack
                .get(self.base + slot as usize)
                .copied()
                .unwrap_or(Value::Poisoned),
            Res::Global(slot) => self
                .globals
                .get(slot as usize)
                .copied()
                .unwrap_or(Value::Poisoned),
            Res::Builtin(constant) => {
                if constant.is_clock() {
                    self.clock_read.set(true);
                }
                constant.value(&self.clock)
            }
            Res::Word(_) | Res::Unresolved | Res::Error => Value::Poisoned,
        }
    }
}
