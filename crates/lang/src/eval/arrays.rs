//! Arrays (`[red, blue]`, `colours[i % 2]`, `len(a)`) and the store that arrays and strings
//! live in. Values stay `Copy`: they hold an id into this store, which grows until the
//! compilation ends and is bounded by the value memory limit.

use whitted_ir::limits::{MAX_ARRAY_LENGTH, MAX_VALUE_BYTES};
use whitted_ir::{Diagnostic, Span};

use super::{Eval, Evaluator};
use crate::ast::*;
use crate::strings::format_number;
use crate::value::Value;

/// Every array and string made so far in one compilation.
#[derive(Default)]
pub(super) struct Store {
    pub(super) arrays: Vec<Vec<Value>>,
    pub(super) strings: Vec<String>,
    /// Bytes of `arrays` and `strings` together, for the value memory limit.
    bytes: u64,
}

impl<'a> Evaluator<'a> {
    /// Counts `bytes` more against the value memory limit; `span` made them.
    pub(super) fn charge(&mut self, bytes: usize, span: Span) -> Eval<()> {
        self.store.bytes = self.store.bytes.saturating_add(bytes as u64);
        if self.store.bytes > MAX_VALUE_BYTES {
            return self.fatal(
                Diagnostic::error(
                    format!(
                        "the value memory limit ({MAX_VALUE_BYTES} bytes of arrays and strings) was reached"
                    ),
                    span,
                )
                .with_label("this value goes past it")
                .with_hint("every array and string made lives until the scene is compiled; make them once, outside loops"),
            );
        }
        Ok(())
    }

    /// `[a, b, c]`.
    pub(super) fn array_literal(&mut self, items: &[Expr], span: Span) -> Eval<Value> {
        if items.len() > MAX_ARRAY_LENGTH {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "this array has {} elements, past the array length limit ({MAX_ARRAY_LENGTH})",
                        items.len()
                    ),
                    span,
                )
                .with_label("too long")
                .with_hint("see \"Limits\" in docs/language.md"),
            );
        }
        // The elements and the array's own header: an empty array still costs memory.
        let bytes = items.len() * std::mem::size_of::<Value>() + std::mem::size_of::<Vec<Value>>();
        self.charge(bytes, span)?;
        let mut values = Vec::with_capacity(items.len());
        for item in items {
            values.push(self.eval(item)?);
        }
        let id = self.store.arrays.len() as u32;
        self.store.arrays.push(values);
        Ok(Value::Array(id))
    }

    /// `base[index]`: bounds-checked, with a whole-number index.
    pub(super) fn index_value(&mut self, base: &Expr, index: &Expr, span: Span) -> Eval<Value> {
        let container = self.eval(base)?;
        let id = match container {
            Value::Array(id) => id,
            Value::Vector(_) => {
                return self.fail(
                    Diagnostic::error("vectors have components, not indices", span)
                        .with_label("a vector indexed here")
                        .with_hint("write `v.x`, `v.y` and `v.z` (or `.r`, `.g`, `.b`) for `v[0]`, `v[1]` and `v[2]`"),
                )
            }
            other => {
                return self.fail(
                    Diagnostic::error(
                        format!("only arrays can be indexed, not {}", other.type_name()),
                        base.span,
                    )
                    .with_label(format!("{} here", other.type_name())),
                )
            }
        };
        let i = self.number(index, "an array index")?;
        let len = self.store.arrays.get(id as usize).map_or(0, Vec::len);
        if i.fract() != 0.0 {
            return self.fail(
                Diagnostic::error(
                    format!(
                        "an array index must be a whole number, not {}",
                        format_number(i)
                    ),
                    index.span,
                )
                .with_label("not a whole number")
                .with_hint("`floor`, `ceil` and `round` make whole numbers"),
            );
        }
        if i < 0.0 || i >= len as f64 {
            let valid = match len {
                0 => "the array is empty".to_string(),
                1 => "the only index is 0".to_string(),
                n => format!("indices go from 0 to {}", n - 1),
            };
            return self.fail(
                Diagnostic::error(
                    format!(
                        "index {} is out of range for an array of length {len}",
                        format_number(i)
                    ),
                    index.span,
                )
                .with_label(valid)
                .with_hint("`a[i % len(a)]` cycles through an array"),
            );
        }
        let value = self
            .store
            .arrays
            .get(id as usize)
            .and_then(|a| a.get(i as usize))
            .copied();
        value.ok_or(super::Abort::Reported)
    }

    /// `len(array)` or `len(string)`.
    pub(super) fn len_call(&mut self, call: &Call, args: &[Value]) -> Eval<Value> {
        match args.first() {
            Some(Value::Array(id)) => Ok(Value::Number(
                self.store.arrays.get(*id as usize).map_or(0, Vec::len) as f64,
            )),
            Some(Value::Str(id)) => Ok(Value::Number(
                self.store
                    .strings
                    .get(*id as usize)
                    .map_or(0, |s| s.chars().count()) as f64,
            )),
            Some(other) => {
                let found = other.type_name();
                let span = call.args.first().map_or(call.span, |a| a.span);
                self.fail(
                    Diagnostic::error(
                        format!("`len` needs an array or a string, not {found}"),
                        span,
                    )
                    .with_label(format!("{found} here"))
                    .with_hint("`length(v)` is the length of a vector"),
                )
            }
            None => Err(super::Abort::Reported),
        }
    }

    /// `==` and `!=` on arrays and strings compare contents; `None` for other values.
    pub(super) fn compare_stored(&self, op: BinaryOp, left: Value, right: Value) -> Option<Value> {
        if !matches!(op, BinaryOp::Eq | BinaryOp::Ne)
            || !matches!(left, Value::Array(_) | Value::Str(_))
            || !left.same_type(&right)
        {
            return None;
        }
        let equal = self.values_equal(left, right);
        Some(Value::Bool(if op == BinaryOp::Eq { equal } else { !equal }))
    }

    /// Equality by contents, for arrays (element by element) and strings. A loop can nest
    /// arrays a million deep (`a = [a];`), so the walk keeps its own stack.
    fn values_equal(&self, a: Value, b: Value) -> bool {
        let mut pending = vec![(a, b)];
        while let Some(pair) = pending.pop() {
            match pair {
                (Value::Str(x), Value::Str(y)) => {
                    if self.store.strings.get(x as usize) != self.store.strings.get(y as usize) {
                        return false;
                    }
                }
                (Value::Array(x), Value::Array(y)) => {
                    let (Some(x), Some(y)) = (
                        self.store.arrays.get(x as usize),
                        self.store.arrays.get(y as usize),
                    ) else {
                        return false;
                    };
                    if x.len() != y.len() {
                        return false;
                    }
                    pending.extend(x.iter().copied().zip(y.iter().copied()));
                }
                (p, q) => {
                    if p != q {
                        return false;
                    }
                }
            }
        }
        true
    }
}
