//! `for ... step`, `while` and assignment (`i = i + 1;`). Every iteration is an evaluation
//! step: a stepped `for` is refused before it starts when its count would pass the limit,
//! like a plain `for`; a `while` stops with an error at the iteration that passes it.

use whitted_ir::Diagnostic;

use super::{Eval, Evaluator, Flow};
use crate::ast::*;
use crate::value::Value;

impl<'a> Evaluator<'a> {
    /// `for i in start..end step s` (or `..=`): `s` is a whole number other than zero; a
    /// negative step counts down, towards `end`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn stepped_loop(
        &mut self,
        var: crate::ast::Ident,
        slot: Slot,
        start: &Expr,
        end: &Expr,
        inclusive: bool,
        step: &Expr,
        body: &Block,
    ) -> Eval<Flow> {
        let first = i128::from(self.whole_number(start, "a loop's start")?);
        let last = i128::from(self.whole_number(end, "a loop's end")?);
        let by = i128::from(self.whole_number(step, "a loop's step")?);
        if by == 0 {
            return self.fail(
                Diagnostic::error("a loop's step cannot be 0", step.span)
                    .with_label("this is 0")
                    .with_hint(
                        "a loop that never moves would never end; count down with a negative step",
                    ),
            );
        }
        // The values taken are first, first + by, ... while they are before `last` (or at it,
        // for `..=`) in the step's direction.
        let span = if by > 0 { last - first } else { first - last };
        let span = if inclusive { span + 1 } else { span };
        let count = if span <= 0 {
            0
        } else {
            (span + by.abs() - 1) / by.abs()
        };
        // The last value taken (one step before the first when there is none).
        let shown_last = first + (count.max(0) - 1).saturating_mul(by);
        self.show_range(var.span, first, shown_last, by);
        let count = u64::try_from(count).unwrap_or(u64::MAX);
        self.budget_loop(count, start.span.to(step.span))?;
        let mut value = first;
        for _ in 0..count {
            self.set_slot(slot, Value::Number(value as f64));
            self.trail.next_iteration(value as f64);
            if let flow @ Flow::Return(_) = self.items(&body.items)? {
                return Ok(flow);
            }
            value += by;
        }
        Ok(Flow::Normal)
    }

    /// Counts a loop's iterations against the budget before it runs.
    fn budget_loop(&mut self, count: u64, range: whitted_ir::Span) -> Eval<()> {
        let limit = self.limits.max_evaluation_steps;
        if self.steps.saturating_add(count) > limit {
            let mut diagnostic = Diagnostic::error(
                format!(
                    "this loop would run {count} times, past the evaluation steps limit ({limit} loop iterations and calls in total)"
                ),
                range,
            )
            .with_label(format!("{count} iterations"));
            if self.steps > 0 {
                diagnostic = diagnostic.with_hint(format!(
                    "{} steps (iterations and calls) have already run",
                    self.steps
                ));
            }
            return self.fatal(diagnostic.with_hint(
                "the limit keeps a mistake from running for days; see \"Limits\" in docs/language.md",
            ));
        }
        self.steps += count;
        Ok(())
    }

    /// `while condition { ... }`: one evaluation step per iteration.
    pub(super) fn while_loop(&mut self, condition: &Expr, body: &Block) -> Eval<Flow> {
        let mut iterations: u64 = 0;
        while self.boolean(condition, "a `while` condition")? {
            let limit = self.limits.max_evaluation_steps;
            if self.steps >= limit {
                return self.fatal(
                    Diagnostic::error(
                        format!(
                            "this `while` loop reached the evaluation steps limit ({limit} loop iterations and calls in total) after {iterations} iterations"
                        ),
                        condition.span,
                    )
                    .with_label("still true")
                    .with_hint("does the body change what the condition tests? See \"Limits\" in docs/language.md"),
                );
            }
            self.steps += 1;
            iterations += 1;
            if let flow @ Flow::Return(_) = self.items(&body.items)? {
                return Ok(flow);
            }
        }
        Ok(Flow::Normal)
    }

    /// `name = value;`.
    pub(super) fn assign(&mut self, target: &Name, value: &Expr) -> Eval<()> {
        let slot = match target.res {
            Res::Local(i) => Slot::Local(i),
            Res::Global(i) => Slot::Global(i),
            // Reported by the resolver.
            _ => return Err(super::Abort::Reported),
        };
        let value = self.eval(value)?;
        self.set_slot(slot, value);
        Ok(())
    }
}
