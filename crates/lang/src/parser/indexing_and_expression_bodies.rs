//! Tree building for expression-bodied functions (`fn square(x) = x * x;`) and indexing
//! (`colours[i % 2]`), and the hint for `fn f(x) { x * x }`. Arrays, `while`, `step` and
//! assignments are built in the item and primary matches of the parent module.

use pest::iterators::Pair;
use pest::Parser as _;
use whitted_ir::{Diagnostic, Span};

use super::{ParseContext, Rule, SceneParser};
use crate::ast::*;
use crate::lexical;

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
        index_expr(base, index, index_span)
    }
}

/// `base[index]`; `index_span` covers the brackets.
pub(super) fn index_expr(base: Expr, index: Expr, index_span: Span) -> Expr {
    let span = base.span.to(index_span);
    Expr {
        kind: ExprKind::Index {
            base: Box::new(base),
            index: Box::new(index),
        },
        span,
    }
}

/// `fn f(x) { x * x }` is a syntax error (a body holds statements); when the body is one
/// expression, the error gets a hint towards `fn f(x) = x * x;`.
pub(super) fn expression_body_hint(
    diagnostic: Diagnostic,
    text: &str,
    brackets: &lexical::Brackets,
) -> Diagnostic {
    let Some(at) = diagnostic.span.map(|s| s.start) else {
        return diagnostic;
    };
    let Some(pair) = brackets.innermost_brace_around(at) else {
        return diagnostic;
    };
    let (open, close) = (pair.open as usize, pair.close as usize);
    let (Some(before), Some(body)) = (text.get(..open), text.get(open + 1..close)) else {
        return diagnostic;
    };
    let Some(header) = function_header(before) else {
        return diagnostic;
    };
    let body = body.trim();
    let is_expression = !body.is_empty() && SceneParser::parse(Rule::define_value, body).is_ok();
    if !is_expression {
        return diagnostic;
    }
    // A long body is not repeated whole in the hint.
    let body = if body.len() > 60 || body.contains('\n') {
        "..."
    } else {
        body
    };
    diagnostic.with_hint(format!(
        "a function's block holds statements; for a function that is one expression, write `{header} = {body};` (or `return {body};` in the block)"
    ))
}

/// `fn name(params)` when `before` ends with one (spaces allowed between the parts).
fn function_header(before: &str) -> Option<&str> {
    let trimmed = before.trim_end();
    let params_start = trimmed.strip_suffix(')')?.rfind('(')?;
    let name_part = trimmed[..params_start].trim_end();
    // By characters, so that a wide character before the name cannot split a slice.
    let name_start = name_part
        .char_indices()
        .rev()
        .find(|&(_, c)| !(c.is_ascii_alphanumeric() || c == '_'))
        .map_or(0, |(i, c)| i + c.len_utf8());
    let keyword = name_part[..name_start].trim_end();
    if name_start == name_part.len() || !keyword.ends_with("fn") {
        return None;
    }
    let fn_start = keyword.len() - 2;
    let boundary = keyword[..fn_start]
        .chars()
        .next_back()
        .is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '_'));
    boundary.then(|| &trimmed[fn_start..])
}

#[cfg(test)]
mod tests {
    use super::super::parse_file;
    use super::*;
    use crate::intern::Interner;

    /// The tree dump of `input`, which must parse.
    fn dump(input: &str) -> String {
        let mut interner = Interner::default();
        let mut functions = Vec::new();
        let mut cx = ParseContext::new(whitted_ir::FileId(0), &mut interner, &mut functions, 4096);
        let items = match parse_file(input, &mut cx, 256) {
            Ok(items) => items,
            Err(error) => panic!("{input}: {}", error.message),
        };
        assert!(cx.errors.is_empty(), "{:?}", cx.errors);
        crate::ast_dump::dump(&items, &functions, &interner)
    }

    #[test]
    fn indexing_and_expression_bodies_parse() {
        insta::assert_snapshot!(dump(
            r#"fn sq(x) = x * x;
let a = [1, [2, 3], "s {a}",];
let e = [];
let v = a[1][0] + sq(a[0]) * len(a);
for i in 10..=0 step -2 { x = i; }
while i < 3 && a[i] != 0 { i = i + 1; }
sphere "ball {i}" { }
"#
        ));
    }

    #[test]
    fn an_index_binds_tighter_than_operators_and_after_fields() {
        let text = dump("let x = -a[1].y * b[2];");
        assert!(text.contains("((-a[1].y) * b[2])"), "{text}");
    }

    #[test]
    fn function_headers_are_recognised_only_after_fn() {
        assert_eq!(function_header("fn f(x) "), Some("fn f(x)"));
        assert_eq!(
            function_header("\nfn  area (w, h)"),
            Some("fn  area (w, h)")
        );
        assert_eq!(function_header("sphere "), None);
        assert_eq!(function_header("myfn f(x)"), None);
        assert_eq!(function_header("ring(3)"), None);
        assert_eq!(function_header(")"), None);
        // A wide character just before the name or the keyword.
        assert_eq!(function_header("é f(x)"), None);
        assert_eq!(function_header("éf(x)"), None);
        assert_eq!(function_header("é fn f(x)"), Some("fn f(x)"));
    }
}
