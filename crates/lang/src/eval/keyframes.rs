//! `keyframes([[t0, v0], [t1, v1], ...], t)`: the animation helper that goes piecewise
//! linearly through keys sorted by time, holding the first and last values outside them.
//! It lives here rather than with the other built-ins because its keys are an array, which
//! only the evaluator's store can read.

use whitted_ir::{DVec3, Diagnostic};

use super::{Abort, Eval, Evaluator};
use crate::ast::Call;
use crate::strings::format_number;
use crate::value::Value;

/// A key's value: what `keyframes` interpolates.
#[derive(Clone, Copy)]
enum KeyValue {
    Number(f64),
    Vector(DVec3),
}

impl KeyValue {
    fn vector(self) -> DVec3 {
        match self {
            KeyValue::Number(x) => DVec3::splat(x),
            KeyValue::Vector(v) => v,
        }
    }
}

/// The value between `a` and `b` at `u` in [0, 1], of `a`'s type.
fn between(a: KeyValue, b: KeyValue, u: f64) -> Value {
    match (a, b) {
        (KeyValue::Number(x), KeyValue::Number(y)) => Value::Number(x + (y - x) * u),
        _ => Value::Vector(a.vector() + (b.vector() - a.vector()) * u),
    }
}

impl Evaluator<'_> {
    /// `keyframes(keys, t)`. Every fault names the key (counted from 0) and points at the
    /// keys argument.
    pub(super) fn keyframes_call(&mut self, call: &Call, args: &[Value]) -> Eval<Value> {
        let keys_span = call.args.first().map_or(call.span, |a| a.span);
        let t_span = call.args.get(1).map_or(call.span, |a| a.span);
        let hint = "write the keys as `[[time, value], ...]`, times in increasing order, values all numbers or all vectors";
        let id = match args.first() {
            Some(Value::Array(id)) => *id,
            Some(Value::Poisoned) | None => return Err(Abort::Reported),
            Some(other) => {
                let found = other.type_name();
                return self.fail(
                    Diagnostic::error(
                        format!("`keyframes` needs an array of keys, not {found}"),
                        keys_span,
                    )
                    .with_label(format!("{found} here"))
                    .with_hint(hint),
                );
            }
        };
        let t = match args.get(1) {
            Some(Value::Number(t)) => *t,
            Some(Value::Poisoned) | None => return Err(Abort::Reported),
            Some(other) => {
                let found = other.type_name();
                return self.fail(
                    Diagnostic::error(
                        format!("`keyframes` needs a number for the time, not {found}"),
                        t_span,
                    )
                    .with_label(format!("{found} here"))
                    .with_hint("the time is usually `clock` or `frame`"),
                );
            }
        };
        let entries = self
            .store
            .arrays
            .get(id as usize)
            .cloned()
            .unwrap_or_default();
        if entries.is_empty() {
            return self.fail(
                Diagnostic::error(
                    "`keyframes` needs at least one key, not an empty array",
                    keys_span,
                )
                .with_label("no keys")
                .with_hint(hint),
            );
        }
        let mut keys: Vec<(f64, KeyValue)> = Vec::with_capacity(entries.len());
        for (index, entry) in entries.iter().enumerate() {
            let pair = match entry {
                Value::Array(pair) => self.store.arrays.get(*pair as usize).cloned(),
                _ => None,
            };
            let key = match pair.as_deref() {
                Some([Value::Number(time), Value::Number(x)]) => (*time, KeyValue::Number(*x)),
                Some([Value::Number(time), Value::Vector(v)]) => (*time, KeyValue::Vector(*v)),
                _ => {
                    let found = match (entry, pair.as_deref()) {
                        (Value::Array(_), Some(items)) if items.len() != 2 => {
                            format!("an array of {} elements", items.len())
                        }
                        (Value::Array(_), _) => {
                            "a pair that is not a number and a number or vector".to_string()
                        }
                        (other, _) => other.type_name().to_string(),
                    };
                    return self.fail(
                        Diagnostic::error(
                            format!(
                                "key {index} of `keyframes` must be `[time, value]` (a number and a number or vector), not {found}"
                            ),
                            keys_span,
                        )
                        .with_label(format!("key {index} is here"))
                        .with_hint(hint),
                    );
                }
            };
            if let Some(&(previous, _)) = keys.last() {
                if key.0 < previous {
                    return self.fail(
                        Diagnostic::error(
                            format!(
                                "the times of `keyframes` must not decrease: key {index} is at {} after key {} at {}",
                                format_number(key.0),
                                index - 1,
                                format_number(previous)
                            ),
                            keys_span,
                        )
                        .with_label("keys out of order")
                        .with_hint(hint),
                    );
                }
            }
            if let Some(&(_, first)) = keys.first() {
                let same = matches!(
                    (first, key.1),
                    (KeyValue::Number(_), KeyValue::Number(_))
                        | (KeyValue::Vector(_), KeyValue::Vector(_))
                );
                if !same {
                    let name = |v: KeyValue| match v {
                        KeyValue::Number(_) => "a number",
                        KeyValue::Vector(_) => "a vector",
                    };
                    return self.fail(
                        Diagnostic::error(
                            format!(
                                "the values of `keyframes` must be of one type: key 0 is {}, key {index} is {}",
                                name(first),
                                name(key.1)
                            ),
                            keys_span,
                        )
                        .with_label("mixed values")
                        .with_hint(hint),
                    );
                }
            }
            keys.push(key);
        }
        let value = match keys.as_slice() {
            [] => return Err(Abort::Reported),
            [(_, only)] => between(*only, *only, 0.0),
            [(t0, v0), ..] if t <= *t0 => between(*v0, *v0, 0.0),
            [.., (tn, vn)] if t >= *tn => between(*vn, *vn, 0.0),
            _ => {
                // t0 < t < tn: the segment with t_i <= t < t_(i+1), so t_(i+1) > t_i.
                let segment = keys
                    .windows(2)
                    .find(|w| w[0].0 <= t && t < w[1].0)
                    .map(|w| (w[0], w[1]));
                let Some(((ta, a), (tb, b))) = segment else {
                    return Err(Abort::Reported);
                };
                between(a, b, (t - ta) / (tb - ta))
            }
        };
        self.finite(value, call.span)
    }
}
