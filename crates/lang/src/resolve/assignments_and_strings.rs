//! Names in assignments (`i = i + 1;`, only to `let` bindings of the same function or file)
//! and in the `{name}` holes of formatted strings, and the string after an object's name that
//! shows its braces are missing (`sphere "ball"`).

use whitted_ir::Diagnostic;

use super::{DefKind, Resolver};
use crate::ast::*;
use crate::schema::Context;

impl Resolver<'_> {
    /// `name = value;`: the name must be a `let` binding this code owns.
    pub(super) fn assign(
        &mut self,
        target: &mut Name,
        value: &mut Expr,
        _cx: Context,
        program: &mut Program,
    ) {
        self.expr(value, program);
        let sym = target.ident.sym;
        let text = self.name(sym);
        target.res = Res::Error;
        let Some(def) = self.lookup(sym) else {
            let candidates = self
                .visible_names()
                .into_iter()
                .filter(|(_, kind)| *kind == DefKind::Let)
                .map(|(n, _)| n)
                .collect();
            self.unknown(target.ident, "name", candidates);
            return;
        };
        let definition = &self.definitions[def];
        let (kind, slot, span) = (definition.kind, definition.slot, definition.span);
        if kind != DefKind::Let {
            let hint = match kind {
                DefKind::Const => "a constant keeps its value; define it with `let` to change it",
                DefKind::LoopVariable => "a loop variable takes each value of its range in turn; use a `let` inside the loop",
                DefKind::Parameter => "copy the parameter into a `let` first: `let n = n;` then change `n`",
                _ => "only names made with `let` can be given a new value",
            };
            self.error(
                Diagnostic::error(
                    format!(
                        "`{text}` is {}; it cannot be given a new value",
                        kind.describe()
                    ),
                    target.ident.span,
                )
                .with_label("assigned here")
                .with_secondary(span, "defined here")
                .with_hint(hint),
            );
            return;
        }
        if self.current_function.is_some() && matches!(slot, Slot::Global(_)) {
            self.error(
                Diagnostic::error(
                    format!("a function cannot change `{text}`, which is defined outside it"),
                    target.ident.span,
                )
                .with_label("assigned here")
                .with_secondary(span, "defined here")
                .with_hint("return the new value from the function instead"),
            );
            return;
        }
        self.link(target.ident.span, def);
        target.res = match slot {
            Slot::Local(slot) => Res::Local(slot),
            Slot::Global(slot) => Res::Global(slot),
            Slot::None => Res::Error,
        };
    }

    /// Resolves the `{name}` holes of a formatted string.
    pub(super) fn string_holes(&mut self, lit: Option<&mut StrLit>) {
        let Some(lit) = lit else { return };
        for part in &mut lit.parts {
            if let StrPart::Hole(name) = part {
                self.name_ref(name);
            }
        }
    }

    /// `sphere "ball"` without its braces parses as a property named `sphere` whose value
    /// is a string; no property takes a string, so it is an object missing its `{ }`.
    pub(super) fn is_unbraced_object(&self, property: &Property) -> bool {
        matches!(
            property.values.first().map(|v| &v.kind),
            Some(ExprKind::Str(_))
        ) && property.block.is_none()
            && crate::schema::ObjectTag::ALL
                .iter()
                .any(|tag| tag.name() == self.name(property.name.sym))
    }

    pub(super) fn unbraced_object(&mut self, property: &Property) {
        let text = self.name(property.name.sym);
        let span = property
            .values
            .first()
            .map_or(property.name.span, |v| property.name.span.to(v.span));
        self.error(
            Diagnostic::error(format!("`{text}` needs `{{ ... }}` after its name"), span)
                .with_label("an object without its braces")
                .with_hint(format!(
                    "write `{text} \"name\" {{ }}`, with its properties inside the braces"
                )),
        );
    }
}
