//! Properties in their blocks: whether the block accepts the name (from the property table),
//! how many values it takes, and the words some properties take instead of expressions.

use super::*;

impl Resolver<'_> {
    pub(super) fn property(&mut self, property: &mut Property, cx: Context, program: &mut Program) {
        let name = self.name(property.name.sym);
        let prop = *self
            .property_rows
            .entry((property.name.sym, cx))
            .or_insert_with(|| cx.property_named(name));
        match (prop, cx) {
            (_, Context::Unknown) => {}
            (Some(prop), _) => property.prop = Some(prop),
            (None, Context::Statements { .. }) => {
                self.error(
                    Diagnostic::error(format!("`{name}` cannot go here"), property.name.span)
                        .with_label("not inside an object, light, camera or material")
                        .with_hint(
                            "properties such as `radius` go inside the braces of an object, a light, a camera, a material or `settings`",
                        ),
                );
            }
            (None, _) => {
                let allowed = cx.properties();
                let names: Vec<&str> = allowed.iter().map(|p| p.name()).collect();
                let mut diagnostic = Diagnostic::error(
                    format!("`{name}` is not a property of {}", cx.describe()),
                    property.name.span,
                )
                .with_label("unknown property");
                diagnostic = match closest(name, names.iter().copied()) {
                    Some(best) => diagnostic.with_hint(format!("did you mean `{best}`?")),
                    None => diagnostic.with_hint(format!(
                        "{} takes {}",
                        cx.describe(),
                        list_and(&names)
                    )),
                };
                if let Some(advice) = crate::hints::foreign(name) {
                    diagnostic = diagnostic.with_hint(advice);
                }
                self.error(diagnostic);
            }
        }

        if let Some(prop) = property.prop {
            self.check_arity(property, prop);
            if let Some(words) = prop.words() {
                for value in &mut property.values {
                    self.word(value, prop, words);
                }
            }
            if property.about.is_some() && prop != Prop::Rotate {
                self.error(
                    Diagnostic::error(
                        format!("`about` only goes with `rotate`, not `{name}`"),
                        property.name.span,
                    )
                    .with_label("not a rotation")
                    .with_hint("`rotate 30 about <0, 1, 0>` turns 30 degrees about an axis"),
                );
            }
            if let Some(block) = &property.block {
                if prop != Prop::Diffuse {
                    let span = block.span;
                    self.error(
                        Diagnostic::error(format!("`{name}` does not take a block"), span)
                            .with_label("unexpected block")
                            .with_hint("only a pattern takes a block of transforms: `diffuse checker(a, b, 1) { rotate <0, 45, 0> }`"),
                    );
                }
            }
        }
        if property.prop.and_then(Prop::words).is_none() {
            for value in &mut property.values {
                self.expr(value, program);
            }
        }
        if let Some(about) = &mut property.about {
            self.expr(about, program);
        }
        if let Some(block) = &mut property.block {
            self.block(block, Context::PatternTransform, program);
        }
    }

    pub(super) fn check_arity(&mut self, property: &Property, prop: Prop) {
        let name = prop.name();
        let count = property.values.len();
        let span = property.values.first().map_or(property.name.span, |first| {
            property
                .values
                .last()
                .map_or(first.span, |last| first.span.to(last.span))
        });
        match prop.arity() {
            Arity::Flag | Arity::Numbers(_) => {}
            Arity::One if count != 1 => {
                let mut diagnostic =
                    Diagnostic::error(format!("`{name}` takes one value, not {count}"), span)
                        .with_label(format!("{count} values"));
                if count == 3 {
                    diagnostic =
                        diagnostic.with_hint("a vector is written in angle brackets: `<x, y, z>`");
                }
                self.error(diagnostic);
            }
            Arity::Exactly(n) if count != n => {
                self.error(
                    Diagnostic::error(
                        format!("`{name}` takes {n} values separated by commas, not {count}"),
                        span,
                    )
                    .with_label(format!("{count} values")),
                );
            }
            _ => {}
        }
    }

    /// A value that must be one of a few words (`shadows filtered`).
    pub(super) fn word(&mut self, value: &mut Expr, prop: Prop, words: &[&str]) {
        if let ExprKind::Name(name) = &mut value.kind {
            let text = self.name(name.ident.sym);
            if let Some(index) = words.iter().position(|w| *w == text) {
                name.res = Res::Word(index as u8);
                return;
            }
            let mut diagnostic = Diagnostic::error(
                format!("`{}` is {}, not `{text}`", prop.name(), list_or(words)),
                value.span,
            )
            .with_label("unknown word");
            if let Some(best) = closest(text, words.iter().copied()) {
                diagnostic = diagnostic.with_hint(format!("did you mean `{best}`?"));
            }
            self.error(diagnostic);
            name.res = Res::Error;
            return;
        }
        self.error(
            Diagnostic::error(
                format!("`{}` is {}", prop.name(), list_or(words)),
                value.span,
            )
            .with_label("expected one of these words"),
        );
    }
}
