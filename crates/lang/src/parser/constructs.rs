//! Tree building for the constructs of the language's second step: expression-bodied
//! functions (`fn square(x) = x * x;`) and indexing (`colours[i % 2]`). Arrays, `while`,
//! `step` and assignments are built in the item and primary matches of the parent module.

use pest::iterators::Pair;

use super::{ParseContext, Rule};
use crate::ast::*;

impl ParseContext<'_> {
    /// `= expr ;` after a function's parameters: a body of one `return expr;`.
    pub(super) fn expr_body(&mut self, pair: Pair<'_, Rule>) -> Block {
        let span = self.span(&pair);
        // The same two levels a block and its item add, so depth limits hold alike.
        self.depth += 2;
        let value = match pair.into_inner().next() {
            Some(expr) => self.expr(expr),
            None => Expr {
                kind: ExprKind::Number(0.0),
                span,
            },
        };
        self.depth -= 2;
        let item = Item {
            span: value.span,
            kind: ItemKind::Return(value),
        };
        Block {
            items: vec![item],
            span,
        }
    }

    /// `base[index]`.
    pub(super) fn index(&mut self, base: Expr, pair: Pair<'_, Rule>) -> Expr {
        let index_span = self.span(&pair);
        let index = match pair.into_inner().next() {
            Some(expr) => self.expr(expr),
            None => Expr {
                kind: ExprKind::Number(0.0),
                span: index_span,
            },
        };
        let span = base.span.to(index_span);
        Expr {
            kind: ExprKind::Index {
                base: Box::new(base),
                index: Box::new(index),
            },
            span,
        }
    }
}
