//! Expressions: arithmetic on numbers and vectors, comparisons, boolean logic, component
//! access and built-in calls. Every arithmetic result is checked: division by zero, infinity
//! and NaN are located errors, never values.

use whitted_ir::{DVec3, Diagnostic, Span};

use super::materials::{PatternDef, PatternPart};
use super::{Abort, Eval, Evaluator};
use crate::ast::*;
use crate::builtins::{call_math, CallError, Function};
use crate::value::Value;

/// Whole numbers beyond this lose precision as `f64`; loops and sizes stay below it.
const MAX_WHOLE: f64 = 9_007_199_254_740_992.0;

impl<'a> Evaluator<'a> {
    pub(super) fn eval(&mut self, expr: &Expr) -> Eval<Value> {
        self.enter(expr.span)?;
        let value = self.eval_inner(expr);
        self.leave();
        value
    }

    fn eval_inner(&mut self, expr: &Expr) -> Eval<Value> {
        let value = match &expr.kind {
            ExprKind::Number(x) => Value::Number(*x),
            ExprKind::Bool(b) => Value::Bool(*b),
            ExprKind::Color(c) => Value::Vector(*c),
            ExprKind::Vector(parts) => {
                let [x, y, z] = &**parts;
                let x = self.number(x, "a vector's x component")?;
                let y = self.number(y, "a vector's y component")?;
                let z = self.number(z, "a vector's z component")?;
                Value::Vector(DVec3::new(x, y, z))
            }
            ExprKind::Name(name) => self.name_value(name),
            ExprKind::Unary(op, inner) => {
                let value = self.eval(inner)?;
                match (op, value) {
                    (UnaryOp::Neg, Value::Number(x)) => Value::Number(-x),
                    (UnaryOp::Neg, Value::Vector(v)) => Value::Vector(-v),
                    (UnaryOp::Not, Value::Bool(b)) => Value::Bool(!b),
                    (_, Value::Poisoned) => return Err(Abort::Reported),
                    (UnaryOp::Neg, other) => {
                        return self.fail(
                            Diagnostic::error(
                                format!("cannot negate {}", other.type_name()),
                                expr.span,
                            )
                            .with_label(format!("{} here", other.type_name())),
                        )
                    }
                    (UnaryOp::Not, other) => {
                        return self.fail(
                            Diagnostic::error(
                                format!("`!` needs a boolean, not {}", other.type_name()),
                                expr.span,
                            )
                            .with_label(format!("{} here", other.type_name())),
                        )
                    }
                }
            }
            ExprKind::Binary {
                op,
                op_span,
                lhs,
                rhs,
            } => return self.binary(*op, *op_span, lhs, rhs),
            ExprKind::Field {
                base, component, ..
            } => {
                let value = self.eval(base)?;
                let Some(Component(index)) = component else {
                    return Err(Abort::Reported);
                };
                match value {
                    Value::Vector(v) => Value::Number(v[*index as usize]),
                    Value::Poisoned => return Err(Abort::Reported),
                    other => {
                        return self.fail(
                            Diagnostic::error(
                                format!("only vectors have components, not {}", other.type_name()),
                                base.span,
                            )
                            .with_label(format!("{} here", other.type_name())),
                        )
                    }
                }
            }
            ExprKind::Call(call) => self.call_value(call)?,
            ExprKind::Material(body) => Value::Material(self.material(body, None)?),
            ExprKind::Array(items) => self.array_literal(items, expr.span)?,
            ExprKind::Index { base, index } => self.index_value(base, index, expr.span)?,
            ExprKind::Str(lit) => self.string_value(lit)?,
        };
        if value == Value::Poisoned {
            return Err(Abort::Reported);
        }
        Ok(value)
    }

    /// Evaluates a number; `what` names it in the error ("a loop's start").
    pub(super) fn number(&mut self, expr: &Expr, what: &str) -> Eval<f64> {
        match self.eval(expr)? {
            Value::Number(x) => Ok(x),
            other => self.fail(
                Diagnostic::error(
                    format!("{what} must be a number, not {}", other.type_name()),
                    expr.span,
                )
                .with_label(format!("{} here", other.type_name())),
            ),
        }
    }

    pub(super) fn boolean(&mut self, expr: &Expr, what: &str) -> Eval<bool> {
        match self.eval(expr)? {
            Value::Bool(b) => Ok(b),
            other => self.fail(
                Diagnostic::error(
                    format!(
                        "{what} must be `true` or `false`, not {}",
                        other.type_name()
                    ),
                    expr.span,
                )
                .with_label(format!("{} here", other.type_name()))
                .with_hint("compare numbers with `==`, `<` or `>` to get a boolean"),
            ),
        }
    }

    /// A number that must be whole (loop bounds).
    pub(super) fn whole_number(&mut self, expr: &Expr, what: &str) -> Eval<i64> {
        let x = self.number(expr, what)?;
        if x.fract() != 0.0 || x.abs() > MAX_WHOLE {
            return self.fail(
                Diagnostic::error(format!("{what} must be a whole number, not {x}"), expr.span)
                    .with_label("not a whole number")
                    .with_hint("`floor`, `ceil` and `round` make whole numbers"),
            );
        }
        Ok(x as i64)
    }

    fn binary(&mut self, op: BinaryOp, op_span: Span, lhs: &Expr, rhs: &Expr) -> Eval<Value> {
        // `&&` and `||` look at their right side only when they need to.
        if matches!(op, BinaryOp::And | BinaryOp::Or) {
            let what = format!("the left side of `{}`", op.symbol());
            let left = self.boolean(lhs, &what)?;
            if (op == BinaryOp::And && !left) || (op == BinaryOp::Or && left) {
                return Ok(Value::Bool(left));
            }
            let what = format!("the right side of `{}`", op.symbol());
            return Ok(Value::Bool(self.boolean(rhs, &what)?));
        }
        let left = self.eval(lhs)?;
        let right = self.eval(rhs)?;
        if let Some(result) = self.compare_stored(op, left, right) {
            return Ok(result);
        }
        use BinaryOp::*;
        use Value::{Bool, Number as N, Vector as V};
        let result = match (op, left, right) {
            (Add, N(a), N(b)) => N(a + b),
            (Add, V(a), V(b)) => V(a + b),
            (Sub, N(a), N(b)) => N(a - b),
            (Sub, V(a), V(b)) => V(a - b),
            (Mul, N(a), N(b)) => N(a * b),
            (Mul, V(a), N(b)) => V(a * b),
            (Mul, N(a), V(b)) => V(b * a),
            (Mul, V(a), V(b)) => V(a * b),
            // `0.0` also matches `-0.0`.
            (Div | Rem, _, N(0.0)) => return self.division_by_zero(op, rhs),
            (Div, _, V(b)) if b.cmpeq(DVec3::ZERO).any() => return self.division_by_zero(op, rhs),
            (Div, N(a), N(b)) => N(a / b),
            (Div, V(a), N(b)) => V(a / b),
            (Div, V(a), V(b)) => V(a / b),
            (Rem, N(a), N(b)) => N(a.rem_euclid(b)),
            (Lt, N(a), N(b)) => Bool(a < b),
            (Le, N(a), N(b)) => Bool(a <= b),
            (Gt, N(a), N(b)) => Bool(a > b),
            (Ge, N(a), N(b)) => Bool(a >= b),
            (Eq | Ne, a, b) if a.same_type(&b) => {
                let equal = a == b;
                Bool(if op == Eq { equal } else { !equal })
            }
            (_, a, b) => {
                let verb = match op {
                    Add => "add",
                    Sub => "subtract",
                    Mul => "multiply",
                    Div => "divide",
                    Rem => "take the remainder of",
                    Eq | Ne => "compare",
                    _ => "order",
                };
                let mut diagnostic = Diagnostic::error(
                    format!(
                        "cannot {verb} {} and {} with `{}`",
                        a.type_name(),
                        b.type_name(),
                        op.symbol()
                    ),
                    op_span,
                )
                .with_label("this operator")
                .with_secondary(lhs.span, a.type_name())
                .with_secondary(rhs.span, b.type_name());
                if matches!(op, Lt | Le | Gt | Ge) && (a.same_type(&b)) {
                    diagnostic =
                        diagnostic.with_hint("only numbers can be ordered with `<` and `>`");
                }
                return self.fail(diagnostic);
            }
        };
        self.finite(result, op_span)
    }

    fn division_by_zero<T>(&mut self, op: BinaryOp, rhs: &Expr) -> Eval<T> {
        let what = if op == BinaryOp::Rem {
            "remainder of a division by zero"
        } else {
            "division by zero"
        };
        self.fail(Diagnostic::error(what.to_string(), rhs.span).with_label("this is zero"))
    }

    /// Refuses infinity and NaN, pointing at the operation (`at`) that made them.
    pub(super) fn finite(&mut self, value: Value, at: Span) -> Eval<Value> {
        let ok = match value {
            Value::Number(x) => x.is_finite(),
            Value::Vector(v) => v.is_finite(),
            _ => true,
        };
        if ok {
            return Ok(value);
        }
        let nan = match value {
            Value::Number(x) => x.is_nan(),
            Value::Vector(v) => v.is_nan(),
            _ => false,
        };
        let what = if nan {
            "not a number (NaN)"
        } else {
            "infinite"
        };
        self.fail(
            Diagnostic::error(format!("the result of this arithmetic is {what}"), at)
                .with_label(format!("{what} after this"))
                .with_hint("numbers must stay finite; check for very large values"),
        )
    }

    pub(super) fn call_builtin(&mut self, function: Function, call: &Call) -> Eval<Value> {
        let (low, high) = function.arity();
        if call.args.len() < low || call.args.len() > high {
            // Reported by the resolver; evaluation only goes on to find other errors.
            return Err(Abort::Reported);
        }
        let mut args = [Value::Poisoned; 3];
        for (slot, arg) in args.iter_mut().zip(&call.args) {
            *slot = self.eval(arg)?;
        }
        let count = call.args.len().min(3);
        if matches!(
            function,
            Function::Checker
                | Function::Stripes
                | Function::Marble
                | Function::Wood
                | Function::Turbulence
        ) {
            return self.pattern(function, call, &args[..count]);
        }
        if function == Function::Len {
            return self.len_call(call, &args[..count]);
        }
        if function == Function::Keyframes {
            return self.keyframes_call(call, &args[..count]);
        }
        match call_math(function, &args[..count]) {
            Ok(value) => self.finite(value, call.span),
            Err(CallError::ArgumentType { index, expected }) => {
                let (span, found) = match (call.args.get(index), args.get(index)) {
                    (Some(arg), Some(value)) => (arg.span, value.type_name()),
                    _ => (call.span, "nothing"),
                };
                self.fail(
                    Diagnostic::error(
                        format!("`{}` needs {expected} here, not {found}", function.name()),
                        span,
                    )
                    .with_label(format!("{found} here"))
                    .with_hint(format!("it is called as `{}`", function.signature())),
                )
            }
            Err(CallError::Domain(message)) => {
                self.fail(Diagnostic::error(message, call.span).with_label("in this call"))
            }
        }
    }

    /// `checker(a, b, size)`, `stripes(a, b, width)` and the noise patterns `marble`, `wood`
    /// and `turbulence`: each side a colour or a material.
    fn pattern(&mut self, function: Function, call: &Call, args: &[Value]) -> Eval<Value> {
        let mut parts = [PatternPart::Color(DVec3::ZERO); 2];
        for (index, part) in parts.iter_mut().enumerate() {
            *part = match args.get(index) {
                Some(Value::Number(x)) if *x >= 0.0 => PatternPart::Color(DVec3::splat(*x)),
                Some(Value::Vector(v)) if v.cmpge(DVec3::ZERO).all() => PatternPart::Color(*v),
                Some(Value::Material(id)) => PatternPart::Material(*id),
                Some(value) => {
                    let span = call.args.get(index).map_or(call.span, |a| a.span);
                    let found = match value {
                        Value::Number(_) | Value::Vector(_) => "a negative colour",
                        other => other.type_name(),
                    };
                    return self.fail(
                        Diagnostic::error(
                            format!(
                                "`{}` takes two colours or materials, not {found}",
                                function.name()
                            ),
                            span,
                        )
                        .with_label(format!("{found} here"))
                        .with_hint(format!("it is called as `{}`", function.signature())),
                    );
                }
                None => return Err(Abort::Reported),
            };
        }
        let scale = match args.get(2) {
            None => 1.0,
            Some(Value::Number(x)) if *x > 0.0 => *x,
            Some(value) => {
                let span = call.args.get(2).map_or(call.span, |a| a.span);
                let found = match value {
                    Value::Number(x) => format!("{x}"),
                    other => other.type_name().to_string(),
                };
                return self.fail(
                    Diagnostic::error(
                        format!("a pattern's size must be a number greater than 0, not {found}"),
                        span,
                    )
                    .with_label("the size"),
                );
            }
        };
        let kind = match function {
            Function::Checker => whitted_ir::PatternKind::Checker,
            Function::Marble => whitted_ir::PatternKind::Marble,
            Function::Wood => whitted_ir::PatternKind::Wood,
            Function::Turbulence => whitted_ir::PatternKind::Turbulence,
            _ => whitted_ir::PatternKind::Stripes,
        };
        Ok(Value::Pattern(self.add_pattern(PatternDef {
            kind,
            a: parts[0],
            b: parts[1],
            scale,
            pattern_from_object: whitted_ir::DMat4::IDENTITY,
        })))
    }
}
