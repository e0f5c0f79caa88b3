//! Names and calls inside expressions: each name to its definition or built-in, each call to
//! its function, with argument counts checked.

use super::*;

impl Resolver<'_> {
    pub(super) fn name_ref(&mut self, name: &mut Name) {
        let sym = name.ident.sym;
        if let Some(def) = self.lookup(sym) {
            let definition = &self.definitions[def];
            name.res = match definition.slot {
                Slot::Local(slot) => Res::Local(slot),
                Slot::Global(slot) => Res::Global(slot),
                Slot::None => {
                    let text = self.name(sym);
                    self.note_use(def);
                    self.error(
                        Diagnostic::error(
                            format!("`{text}` is a function, not a value"),
                            name.ident.span,
                        )
                        .with_label("a function")
                        .with_hint(format!("call it with arguments in brackets: `{text}(...)`")),
                    );
                    Res::Error
                }
            };
            if name.res != Res::Error {
                self.note_use(def);
                self.link(name.ident.span, def);
            }
            return;
        }
        let text = self.name(sym);
        if let Some(constant) = Constant::from_name(text) {
            name.res = Res::Builtin(constant);
            return;
        }
        name.res = Res::Error;
        if Function::from_name(text).is_some() {
            self.error(
                Diagnostic::error(
                    format!("`{text}` is a built-in function, not a value"),
                    name.ident.span,
                )
                .with_label("a function")
                .with_hint(format!("call it with arguments in brackets: `{text}(...)`")),
            );
            return;
        }
        let mut candidates: Vec<&str> = self
            .visible_names()
            .into_iter()
            .filter(|(_, kind)| *kind != DefKind::Function)
            .map(|(n, _)| n)
            .collect();
        candidates.extend(Constant::ALL.iter().map(|c| c.name()));
        self.unknown(name.ident, "name", candidates);
    }

    pub(super) fn call(&mut self, call: &mut Call, program: &mut Program) {
        for arg in &mut call.args {
            self.expr(arg, program);
        }
        let sym = call.callee.sym;
        let text = self.name(sym);
        let given = call.args.len();
        if let Some(def) = self.lookup(sym) {
            let definition = &self.definitions[def];
            match definition.function {
                Some(id) => {
                    self.note_use(def);
                    self.link(call.callee.span, def);
                    call.target = CallTarget::User(id);
                    let expected = program.functions.get(id).map_or(0, |f| f.params.len());
                    if expected != given {
                        let defined = program.functions.get(id).map(|f| f.name.span);
                        let mut diagnostic = Diagnostic::error(
                            format!(
                                "`{text}` takes {} but is given {}",
                                plural(expected, "argument"),
                                given
                            ),
                            call.span,
                        )
                        .with_label(format!("{} given", plural(given, "argument")));
                        if let Some(span) = defined {
                            diagnostic = diagnostic.with_secondary(span, "defined here");
                        }
                        self.error(diagnostic);
                    }
                }
                None => {
                    let what = definition.kind.describe();
                    self.error(
                        Diagnostic::error(
                            format!("`{text}` is {what}, not a function"),
                            call.callee.span,
                        )
                        .with_label("cannot be called")
                        .with_secondary(self.definitions[def].span, "defined here"),
                    );
                    call.target = CallTarget::Error;
                }
            }
            return;
        }
        if let Some(function) = Function::from_name(text) {
            call.target = CallTarget::Builtin(function);
            let (low, high) = function.arity();
            if given < low || given > high {
                let wanted = if low == high {
                    plural(low, "argument")
                } else {
                    format!("{low} or {high} arguments")
                };
                self.error(
                    Diagnostic::error(
                        format!("`{text}` takes {wanted} but is given {given}"),
                        call.span,
                    )
                    .with_label(format!("{} given", plural(given, "argument")))
                    .with_hint(format!("it is called as `{}`", function.signature())),
                );
            }
            return;
        }
        call.target = CallTarget::Error;
        let mut candidates: Vec<&str> = self
            .visible_names()
            .into_iter()
            .filter(|(_, kind)| *kind == DefKind::Function)
            .map(|(n, _)| n)
            .collect();
        candidates.extend(Function::ALL.iter().map(|f| f.name()));
        if Prop::ALL.iter().any(|p| p.name() == text) {
            self.error(
                Diagnostic::error(format!("unknown function `{text}`"), call.callee.span)
                    .with_label("no function with this name")
                    .with_hint(format!(
                        "`{text}` is a property; put a space before its value: `{text} (...)`"
                    )),
            );
            return;
        }
        self.unknown(call.callee, "function", candidates);
    }

    pub(super) fn expr(&mut self, expr: &mut Expr, program: &mut Program) {
        match &mut expr.kind {
            ExprKind::Number(_) | ExprKind::Bool(_) | ExprKind::Color(_) => {}
            ExprKind::Vector(parts) => {
                for part in parts.iter_mut() {
                    self.expr(part, program);
                }
            }
            ExprKind::Name(name) => self.name_ref(name),
            ExprKind::Unary(_, inner) => self.expr(inner, program),
            ExprKind::Binary { lhs, rhs, .. } => {
                self.expr(lhs, program);
                self.expr(rhs, program);
            }
            ExprKind::Field {
                base,
                field,
                component,
            } => {
                self.expr(base, program);
                let text = self.name(field.sym);
                *component = match text {
                    "x" | "r" => Some(Component(0)),
                    "y" | "g" => Some(Component(1)),
                    "z" | "b" => Some(Component(2)),
                    _ => {
                        let mut diagnostic = Diagnostic::error(
                            format!("unknown field `.{text}`"),
                            field.span,
                        )
                        .with_label("not a component")
                        .with_hint(
                            "vectors have `.x`, `.y` and `.z`; colours also `.r`, `.g` and `.b`",
                        );
                        if let Some(best) = closest(text, ["x", "y", "z", "r", "g", "b"]) {
                            diagnostic = diagnostic.with_hint(format!("did you mean `.{best}`?"));
                        }
                        self.error(diagnostic);
                        None
                    }
                };
            }
            ExprKind::Call(call) => self.call(call, program),
            ExprKind::Material(body) => self.material_body(body, program),
            ExprKind::Array(items) => items.iter_mut().for_each(|i| self.expr(i, program)),
            ExprKind::Index { base, index } => {
                self.expr(base, program);
                self.expr(index, program);
            }
            ExprKind::Str(lit) => self.string_holes(Some(lit)),
        }
    }
}
