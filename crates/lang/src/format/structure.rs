//! What the formatter needs from the syntax tree: where each block's items start and end,
//! and the roles of the operators and brackets whose spacing depends on what they do.

use std::collections::HashMap;

use crate::ast::{Block, Call, Else, Expr, ExprKind, FnDef, Item, ItemKind};

use super::tokens::Roles;

/// A `{ ... }` block: where it closes and the spans of its items.
#[derive(Debug)]
pub(super) struct BlockShape {
    pub close: u32,
    pub items: Vec<(u32, u32)>,
}

#[derive(Debug, Default)]
pub(super) struct Structure {
    /// The spans of the file's top-level items.
    pub file_items: Vec<(u32, u32)>,
    /// Every block, by the offset of its `{`.
    pub blocks: HashMap<u32, BlockShape>,
    pub roles: Roles,
}

/// Collects the structure of a parsed file. The walk recurses as deep as the tree does,
/// which the parser's depth limit bounds (the caller runs on the compiler's large stack).
pub(super) fn collect(text: &str, items: &[Item], functions: &[FnDef]) -> Structure {
    let mut walk = Walk {
        text,
        functions,
        out: Structure::default(),
    };
    walk.out.file_items = items.iter().map(|i| (i.span.start, i.span.end)).collect();
    for item in items {
        walk.item(item);
    }
    walk.out
}

struct Walk<'a> {
    text: &'a str,
    functions: &'a [FnDef],
    out: Structure,
}

impl Walk<'_> {
    fn item(&mut self, item: &Item) {
        match &item.kind {
            ItemKind::Import { .. } => {}
            ItemKind::Const(binding) | ItemKind::Let(binding) => self.expr(&binding.value),
            ItemKind::Fn(id) => {
                if let Some(function) = self.functions.get(*id) {
                    self.out.roles.params_after.push(function.name.span.end);
                    // `fn f(x) = x * x;` has a body made by the parser, not a block.
                    if self.is_block(&function.body) {
                        self.block(&function.body);
                    } else {
                        for inner in &function.body.items {
                            self.item(inner);
                        }
                    }
                }
            }
            ItemKind::For {
                start,
                end,
                step,
                body,
                ..
            } => {
                self.expr(start);
                self.expr(end);
                if let Some(step) = step {
                    self.expr(step);
                }
                self.block(body);
            }
            ItemKind::While { condition, body } => {
                self.expr(condition);
                self.block(body);
            }
            ItemKind::Assign { value, .. } | ItemKind::Return(value) => self.expr(value),
            ItemKind::If {
                condition,
                then,
                otherwise,
            } => {
                self.expr(condition);
                self.block(then);
                match otherwise.as_deref() {
                    Some(Else::If(inner)) => self.item(inner),
                    Some(Else::Block(block)) => self.block(block),
                    None => {}
                }
            }
            ItemKind::Settings(body)
            | ItemKind::Camera { body, .. }
            | ItemKind::Light { body, .. }
            | ItemKind::Object { body, .. } => self.block(body),
            ItemKind::Material { body, .. } => self.block(&body.block),
            ItemKind::Call { call, modifiers } => {
                self.call(call);
                if let Some(block) = modifiers {
                    self.block(block);
                }
            }
            ItemKind::Property(property) => {
                for value in &property.values {
                    self.expr(value);
                }
                if let Some(about) = &property.about {
                    self.expr(about);
                }
                if let Some(block) = &property.block {
                    self.block(block);
                }
            }
        }
    }

    fn is_block(&self, block: &Block) -> bool {
        let (start, end) = (block.span.start as usize, block.span.end as usize);
        end > start
            && self.text.as_bytes().get(start) == Some(&b'{')
            && self.text.as_bytes().get(end - 1) == Some(&b'}')
    }

    fn block(&mut self, block: &Block) {
        if self.is_block(block) {
            let shape = BlockShape {
                close: block.span.end - 1,
                items: block
                    .items
                    .iter()
                    .map(|i| (i.span.start, i.span.end))
                    .collect(),
            };
            self.out.blocks.insert(block.span.start, shape);
        }
        for item in &block.items {
            self.item(item);
        }
    }

    fn call(&mut self, call: &Call) {
        self.out.roles.calls.insert(call.callee.span.end);
        for arg in &call.args {
            self.expr(arg);
        }
    }

    fn expr(&mut self, expr: &Expr) {
        match &expr.kind {
            ExprKind::Number(_)
            | ExprKind::Bool(_)
            | ExprKind::Color(_)
            | ExprKind::Name(_)
            | ExprKind::Str(_) => {}
            ExprKind::Vector(parts) => {
                for part in parts.iter() {
                    self.expr(part);
                }
            }
            ExprKind::Unary(_, operand) => self.expr(operand),
            ExprKind::Binary {
                op_span, lhs, rhs, ..
            } => {
                self.out
                    .roles
                    .binary
                    .insert(op_span.start, op_span.end - op_span.start);
                self.expr(lhs);
                self.expr(rhs);
            }
            ExprKind::Field { base, .. } => self.expr(base),
            ExprKind::Call(call) => self.call(call),
            ExprKind::Material(body) => self.block(&body.block),
            ExprKind::Array(elements) => {
                for element in elements {
                    self.expr(element);
                }
            }
            ExprKind::Index { base, index } => {
                self.out.roles.index_after.push(base.span.end);
                self.expr(base);
                self.expr(index);
            }
        }
    }
}
