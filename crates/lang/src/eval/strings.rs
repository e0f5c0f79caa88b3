//! String values and formatted names: `"ball {i}"` fills each `{name}` hole with the value
//! the name has when the string is evaluated (numbers as written, `3` not `3.0`).

use whitted_ir::limits::MAX_STRING_BYTES;
use whitted_ir::{Diagnostic, NameId};

use super::{Abort, Eval, Evaluator};
use crate::ast::*;
use crate::strings::format_number;
use crate::value::Value;

impl<'a> Evaluator<'a> {
    /// A string in an expression: formatted and stored.
    pub(super) fn string_value(&mut self, lit: &StrLit) -> Eval<Value> {
        let text = self.format_string(lit)?;
        self.charge(text.len() + std::mem::size_of::<String>(), lit.span)?;
        let id = self.store.strings.len() as u32;
        self.store.strings.push(text);
        Ok(Value::Str(id))
    }

    /// The name of an object or light, formatted.
    /// The object's name, kept in the scene's name table. (The table refuses only past
    /// 2^32 - 1 names, which the memory budget charged here stops long before.)
    pub(super) fn object_name(&mut self, name: Option<&StrLit>) -> Eval<Option<NameId>> {
        let Some(text) = self.name_text(name)? else {
            return Ok(None);
        };
        Ok(self.scene.object_names.add(&text))
    }

    /// A light's or object's name as text, charged to the memory budget.
    pub(super) fn name_text(&mut self, name: Option<&StrLit>) -> Eval<Option<String>> {
        let Some(lit) = name else { return Ok(None) };
        let text = self.format_string(lit)?;
        self.charge(text.len() + std::mem::size_of::<String>(), lit.span)?;
        Ok(Some(text))
    }

    fn format_string(&mut self, lit: &StrLit) -> Eval<String> {
        if lit.parts.is_empty() {
            return self.bounded(lit.value.clone(), lit);
        }
        let mut text = String::new();
        for part in &lit.parts {
            match part {
                StrPart::Text(piece) => text.push_str(piece),
                StrPart::Hole(name) => {
                    let value = self.name_value(name);
                    match value {
                        Value::Number(x) => text.push_str(&format_number(x)),
                        Value::Bool(b) => text.push_str(if b { "true" } else { "false" }),
                        Value::Vector(v) => text.push_str(&format!(
                            "<{}, {}, {}>",
                            format_number(v.x),
                            format_number(v.y),
                            format_number(v.z)
                        )),
                        Value::Str(id) => {
                            let piece = self.store.strings.get(id as usize);
                            text.push_str(piece.map_or("", String::as_str));
                        }
                        Value::Poisoned => return Err(Abort::Reported),
                        other @ (Value::Array(_) | Value::Material(_) | Value::Pattern(_)) => {
                            let found = other.type_name();
                            return self.fail(
                                Diagnostic::error(
                                    format!("{found} cannot be written in a string"),
                                    name.ident.span,
                                )
                                .with_label(format!("{found} here"))
                                .with_hint(
                                    "strings hold numbers, booleans, vectors and other strings",
                                ),
                            );
                        }
                    }
                }
            }
            if text.len() > MAX_STRING_BYTES {
                break;
            }
        }
        self.bounded(text, lit)
    }

    /// Refuses strings over the string length limit.
    fn bounded(&mut self, text: String, lit: &StrLit) -> Eval<String> {
        if text.len() <= MAX_STRING_BYTES {
            return Ok(text);
        }
        self.fail(
            Diagnostic::error(
                format!(
                    "this string is longer than the string length limit ({MAX_STRING_BYTES} bytes)"
                ),
                lit.span,
            )
            .with_label("too long")
            .with_hint("see \"Limits\" in docs/language.md"),
        )
    }
}
