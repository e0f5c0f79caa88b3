//! The end-of-program reports: definitions never used, and `-D` names that match no constant.

use super::*;

impl Resolver<'_> {
    pub(super) fn report_unused(&mut self) {
        let mut unused = Vec::new();
        for definition in &self.definitions {
            let name = self.name(definition.name);
            if definition.file != 0 || definition.uses > 0 || name.starts_with('_') {
                continue;
            }
            let what = match definition.kind {
                DefKind::Material => "material",
                DefKind::Function => "function",
                _ => continue,
            };
            unused.push(
                Diagnostic::warning(format!("{what} `{name}` is never used"), definition.span)
                    .with_label("defined here")
                    .with_hint(
                        "remove it, or start its name with `_` to keep it without this warning",
                    ),
            );
        }
        self.diagnostics.extend(unused);
    }

    pub(super) fn report_unused_defines(&mut self) {
        let constants: Vec<&str> = self
            .definitions
            .iter()
            .filter(|d| d.kind == DefKind::Const && matches!(d.slot, Slot::Global(_)))
            .map(|d| self.name(d.name))
            .collect();
        for (index, define) in self.defines.iter().enumerate() {
            if self.define_used[index] {
                continue;
            }
            let name = self.name(define.name);
            let mut diagnostic = Diagnostic::error(
                format!("`-D {name}` sets a constant that the scene does not define"),
                define.name_span,
            )
            .with_label("no `const` with this name");
            let other = self
                .definitions
                .iter()
                .find(|d| d.name == define.name && d.kind != DefKind::Const);
            if let Some(other) = other {
                diagnostic = diagnostic
                    .with_secondary(
                        other.span,
                        format!("`{name}` is {} here", other.kind.describe()),
                    )
                    .with_hint(format!(
                        "only `const` values can be set with -D; write `const {name} = ...;`"
                    ));
            } else if let Some(best) = closest(name, constants.iter().copied()) {
                diagnostic = diagnostic.with_hint(format!("did you mean `{best}`?"));
            } else if constants.is_empty() {
                diagnostic = diagnostic
                    .with_hint("the scene defines no constants; `const N = 10;` defines one");
            } else {
                diagnostic = diagnostic.with_hint(format!(
                    "the scene's constants are {}",
                    list_and(&constants)
                ));
            }
            self.error(diagnostic);
        }
    }
}
