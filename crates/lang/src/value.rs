//! Run-time values: small and `Copy`, so loops and calls never clone anything heavier than
//! 32 bytes. Materials and patterns live in the evaluator's tables; values hold their ids.

use whitted_ir::DVec3;

/// Index of a material in the evaluator's material table.
pub type MaterialId = u32;
/// Index of a pattern in the evaluator's pattern table.
pub type PatternId = u32;
/// Index of an array in the evaluator's array table.
pub type ArrayId = u32;
/// Index of a string in the evaluator's string table.
pub type StrId = u32;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Number(f64),
    Bool(bool),
    /// Positions, directions and colours alike (a colour's components are red, green, blue).
    Vector(DVec3),
    Material(MaterialId),
    Pattern(PatternId),
    /// `[a, b, c]`: compare with `Evaluator::values_equal`, not `==` (ids, not contents).
    Array(ArrayId),
    /// `"ball {i}"`, formatted: compare like arrays.
    Str(StrId),
    /// The value of a binding whose definition failed (already reported), so that its uses
    /// stay quiet instead of repeating the error.
    Poisoned,
}

impl Value {
    /// "a number", "a vector", ...: how messages name a value's type.
    pub fn type_name(&self) -> &'static str {
        match self {
            Value::Number(_) => "a number",
            Value::Bool(_) => "a boolean",
            Value::Vector(_) => "a vector",
            Value::Material(_) => "a material",
            Value::Pattern(_) => "a pattern",
            Value::Array(_) => "an array",
            Value::Str(_) => "a string",
            Value::Poisoned => "an invalid value",
        }
    }

    /// Whether two values have the same type (used to check `-D` overrides).
    pub fn same_type(&self, other: &Value) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
    }
}
