//! A compact S-expression dump of the syntax tree, for the parser's snapshot tests: one line
//! per item, expressions fully bracketed so precedence is visible.

use std::fmt::Write;

use crate::ast::*;
use crate::intern::Interner;

pub fn dump(items: &[Item], functions: &[FnDef], interner: &Interner) -> String {
    let mut out = String::new();
    let dumper = Dumper {
        functions,
        interner,
    };
    for item in items {
        dumper.item(item, 0, &mut out);
    }
    out
}

struct Dumper<'a> {
    functions: &'a [FnDef],
    interner: &'a Interner,
}

impl Dumper<'_> {
    fn name(&self, ident: &Ident) -> &str {
        self.interner.name(ident.sym)
    }

    fn block(&self, block: &Block, depth: usize, out: &mut String) {
        for item in &block.items {
            self.item(item, depth, out);
        }
    }

    fn item(&self, item: &Item, depth: usize, out: &mut String) {
        let pad = "  ".repeat(depth);
        let line = match &item.kind {
            ItemKind::Import { path, .. } => format!("import {:?}", path.value),
            ItemKind::Const(b) => format!("const {} = {}", self.name(&b.name), self.expr(&b.value)),
            ItemKind::Let(b) => format!("let {} = {}", self.name(&b.name), self.expr(&b.value)),
            ItemKind::Fn(id) => {
                let Some(f) = self.functions.get(*id) else {
                    return;
                };
                let params: Vec<&str> = f.params.iter().map(|p| self.name(p)).collect();
                let _ = writeln!(out, "{pad}fn {}({})", self.name(&f.name), params.join(", "));
                self.block(&f.body, depth + 1, out);
                return;
            }
            ItemKind::For {
                var,
                start,
                end,
                inclusive,
                step,
                body,
                ..
            } => {
                let op = if *inclusive { "..=" } else { ".." };
                let step = step
                    .as_ref()
                    .map_or(String::new(), |s| format!(" step {}", self.expr(s)));
                let _ = writeln!(
                    out,
                    "{pad}for {} in {}{op}{}{step}",
                    self.name(var),
                    self.expr(start),
                    self.expr(end)
                );
                self.block(body, depth + 1, out);
                return;
            }
            ItemKind::If {
                condition,
                then,
                otherwise,
            } => {
                let _ = writeln!(out, "{pad}if {}", self.expr(condition));
                self.block(then, depth + 1, out);
                match otherwise.as_deref() {
                    Some(Else::If(inner)) => {
                        let _ = writeln!(out, "{pad}else");
                        self.item(inner, depth + 1, out);
                    }
                    Some(Else::Block(block)) => {
                        let _ = writeln!(out, "{pad}else");
                        self.block(block, depth + 1, out);
                    }
                    None => {}
                }
                return;
            }
            ItemKind::Return(value) => format!("return {}", self.expr(value)),
            ItemKind::While { condition, body } => {
                let _ = writeln!(out, "{pad}while {}", self.expr(condition));
                self.block(body, depth + 1, out);
                return;
            }
            ItemKind::Assign { target, value } => {
                format!("{} = {}", self.name(&target.ident), self.expr(value))
            }
            ItemKind::Settings(body) => {
                let _ = writeln!(out, "{pad}settings");
                self.block(body, depth + 1, out);
                return;
            }
            ItemKind::Camera { kind, body, .. } => {
                let _ = writeln!(out, "{pad}camera {}", self.name(kind));
                self.block(body, depth + 1, out);
                return;
            }
            ItemKind::Light {
                kind, name, body, ..
            } => {
                let name = name
                    .as_ref()
                    .map(|n| format!(" {:?}", n.value))
                    .unwrap_or_default();
                let _ = writeln!(out, "{pad}light {}{name}", self.name(kind));
                self.block(body, depth + 1, out);
                return;
            }
            ItemKind::Material { name, body, .. } => {
                let _ = writeln!(
                    out,
                    "{pad}material {}{}",
                    self.name(name),
                    self.parent(body)
                );
                self.block(&body.block, depth + 1, out);
                return;
            }
            ItemKind::Object {
                kind, name, body, ..
            } => {
                let name = name
                    .as_ref()
                    .map(|n| format!(" {:?}", n.value))
                    .unwrap_or_default();
                let _ = writeln!(out, "{pad}object {}{name}", self.name(kind));
                self.block(body, depth + 1, out);
                return;
            }
            ItemKind::Call { call, modifiers } => {
                let _ = writeln!(out, "{pad}call {}", self.call(call));
                if let Some(block) = modifiers {
                    self.block(block, depth + 1, out);
                }
                return;
            }
            ItemKind::Property(p) => {
                let values: Vec<String> = p.values.iter().map(|v| self.expr(v)).collect();
                let about = p
                    .about
                    .as_ref()
                    .map(|a| format!(" about {}", self.expr(a)))
                    .unwrap_or_default();
                let _ = writeln!(
                    out,
                    "{pad}{} {}{about}",
                    self.name(&p.name),
                    values.join(", ")
                );
                if let Some(block) = &p.block {
                    self.block(block, depth + 1, out);
                }
                return;
            }
        };
        let _ = writeln!(out, "{pad}{line}");
    }

    fn parent(&self, body: &MaterialBody) -> String {
        body.parent
            .as_ref()
            .map(|p| format!(" : {}", self.name(&p.ident)))
            .unwrap_or_default()
    }

    fn call(&self, call: &Call) -> String {
        let args: Vec<String> = call.args.iter().map(|a| self.expr(a)).collect();
        format!("{}({})", self.name(&call.callee), args.join(", "))
    }

    fn expr(&self, expr: &Expr) -> String {
        match &expr.kind {
            ExprKind::Number(x) => format!("{x}"),
            ExprKind::Bool(b) => format!("{b}"),
            ExprKind::Color(c) => format!("#<{:.4}, {:.4}, {:.4}>", c.x, c.y, c.z),
            ExprKind::Vector(parts) => {
                let [x, y, z] = &**parts;
                format!("<{}, {}, {}>", self.expr(x), self.expr(y), self.expr(z))
            }
            ExprKind::Name(name) => self.name(&name.ident).to_string(),
            ExprKind::Unary(op, inner) => {
                let symbol = match op {
                    UnaryOp::Neg => "-",
                    UnaryOp::Not => "!",
                };
                format!("({symbol}{})", self.expr(inner))
            }
            ExprKind::Binary { op, lhs, rhs, .. } => {
                format!("({} {} {})", self.expr(lhs), op.symbol(), self.expr(rhs))
            }
            ExprKind::Field { base, field, .. } => {
                format!("{}.{}", self.expr(base), self.name(field))
            }
            ExprKind::Call(call) => self.call(call),
            ExprKind::Material(body) => {
                let mut inner = String::new();
                self.block(&body.block, 0, &mut inner);
                let inner: Vec<&str> = inner.lines().map(str::trim).collect();
                format!("material{} {{ {} }}", self.parent(body), inner.join("; "))
            }
            ExprKind::Array(items) => {
                let items: Vec<String> = items.iter().map(|i| self.expr(i)).collect();
                format!("[{}]", items.join(", "))
            }
            ExprKind::Index { base, index } => {
                format!("{}[{}]", self.expr(base), self.expr(index))
            }
            ExprKind::Str(lit) => format!("{:?}", lit.value),
        }
    }
}
