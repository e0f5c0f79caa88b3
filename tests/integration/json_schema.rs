//! A small JSON Schema checker for the subset that docs/ray-tree.schema.json uses (type,
//! const, enum, properties, required, additionalProperties, items, minItems, maxItems,
//! minimum, anyOf and local `$ref`s). Any other keyword is reported as an error, so the
//! schema cannot use a rule this checker would silently skip.

use serde_json::Value;

/// Every way `instance` breaks `schema`, as `path: problem` lines (empty when it is valid).
pub fn validate(schema: &Value, instance: &Value) -> Vec<String> {
    let mut errors = Vec::new();
    check(schema, schema, instance, "$", &mut errors);
    errors
}

fn check(root: &Value, schema: &Value, instance: &Value, path: &str, errors: &mut Vec<String>) {
    let Some(rules) = schema.as_object() else {
        errors.push(format!("{path}: the schema here is not an object"));
        return;
    };
    for (keyword, rule) in rules {
        match keyword.as_str() {
            "$schema" | "title" | "description" | "$defs" => {}
            "$ref" => match resolve(root, rule) {
                Some(target) => check(root, target, instance, path, errors),
                None => errors.push(format!("{path}: cannot resolve $ref {rule}")),
            },
            "type" => {
                let allowed: Vec<&str> = match rule {
                    Value::String(name) => vec![name.as_str()],
                    Value::Array(names) => names.iter().filter_map(Value::as_str).collect(),
                    _ => vec![],
                };
                if !allowed.iter().any(|name| has_type(instance, name)) {
                    errors.push(format!("{path}: {instance} is not of type {rule}"));
                }
            }
            "const" => {
                if instance != rule {
                    errors.push(format!("{path}: {instance} is not {rule}"));
                }
            }
            "enum" => {
                let options = rule.as_array().map_or(&[][..], Vec::as_slice);
                if !options.contains(instance) {
                    errors.push(format!("{path}: {instance} is not one of {rule}"));
                }
            }
            "minimum" => {
                if let (Some(value), Some(minimum)) = (instance.as_f64(), rule.as_f64()) {
                    if value < minimum {
                        errors.push(format!("{path}: {value} is below {minimum}"));
                    }
                }
            }
            "required" => {
                if let Some(object) = instance.as_object() {
                    for name in rule
                        .as_array()
                        .into_iter()
                        .flatten()
                        .filter_map(Value::as_str)
                    {
                        if !object.contains_key(name) {
                            errors.push(format!("{path}: missing required `{name}`"));
                        }
                    }
                }
            }
            "properties" => {
                if let (Some(object), Some(properties)) = (instance.as_object(), rule.as_object()) {
                    for (name, value) in object {
                        if let Some(property) = properties.get(name) {
                            check(root, property, value, &format!("{path}.{name}"), errors);
                        }
                    }
                }
            }
            "additionalProperties" => {
                let properties = rules.get("properties").and_then(Value::as_object);
                if let (Some(object), Value::Bool(false)) = (instance.as_object(), rule) {
                    for name in object.keys() {
                        if !properties.is_some_and(|p| p.contains_key(name)) {
                            errors.push(format!("{path}: unexpected property `{name}`"));
                        }
                    }
                }
            }
            "items" => {
                for (i, item) in instance.as_array().into_iter().flatten().enumerate() {
                    check(root, rule, item, &format!("{path}[{i}]"), errors);
                }
            }
            "minItems" | "maxItems" => {
                if let (Some(items), Some(bound)) = (instance.as_array(), rule.as_u64()) {
                    let len = items.len() as u64;
                    let broken = if keyword == "minItems" {
                        len < bound
                    } else {
                        len > bound
                    };
                    if broken {
                        errors.push(format!("{path}: {len} items breaks {keyword} {bound}"));
                    }
                }
            }
            "anyOf" => {
                let options = rule.as_array().map_or(&[][..], Vec::as_slice);
                let mut why = Vec::new();
                let passes = options.iter().any(|option| {
                    let mut option_errors = Vec::new();
                    check(root, option, instance, path, &mut option_errors);
                    why.extend(option_errors.iter().cloned());
                    option_errors.is_empty()
                });
                if !passes {
                    errors.push(format!("{path}: matches none of anyOf"));
                    // Say why each option failed, so that a deep mistake is still named.
                    errors.extend(why);
                }
            }
            other => errors.push(format!("{path}: unsupported schema keyword `{other}`")),
        }
    }
}

fn resolve<'a>(root: &'a Value, reference: &Value) -> Option<&'a Value> {
    let name = reference.as_str()?.strip_prefix("#/$defs/")?;
    root.get("$defs")?.get(name)
}

fn has_type(value: &Value, name: &str) -> bool {
    match name {
        "null" => value.is_null(),
        "boolean" => value.is_boolean(),
        "string" => value.is_string(),
        "array" => value.is_array(),
        "object" => value.is_object(),
        "number" => value.is_number(),
        "integer" => value.is_u64() || value.is_i64(),
        _ => false,
    }
}

#[test]
fn the_checker_catches_each_kind_of_mistake() {
    let schema = serde_json::json!({
        "type": "object",
        "required": ["a", "b"],
        "additionalProperties": false,
        "properties": {
            "a": { "$ref": "#/$defs/count" },
            "b": { "type": "array", "items": { "enum": ["x", "y"] }, "minItems": 1, "maxItems": 2 },
            "c": { "anyOf": [{ "type": "null" }, { "const": 3 }] }
        },
        "$defs": { "count": { "type": "integer", "minimum": 0 } }
    });
    assert_eq!(
        validate(&schema, &serde_json::json!({"a": 1, "b": ["x"], "c": 3})),
        Vec::<String>::new()
    );
    let cases = [
        (serde_json::json!({"a": 1}), "missing required `b`"),
        (serde_json::json!({"a": -1, "b": ["x"]}), "is below 0"),
        (serde_json::json!({"a": 1.5, "b": ["x"]}), "is not of type"),
        (serde_json::json!({"a": 1, "b": ["z"]}), "is not one of"),
        (serde_json::json!({"a": 1, "b": []}), "breaks minItems"),
        (
            serde_json::json!({"a": 1, "b": ["x", "x", "y"]}),
            "breaks maxItems",
        ),
        (
            serde_json::json!({"a": 1, "b": ["x"], "d": 0}),
            "unexpected property `d`",
        ),
        (
            serde_json::json!({"a": 1, "b": ["x"], "c": 4}),
            "matches none of anyOf",
        ),
    ];
    for (instance, expected) in cases {
        let errors = validate(&schema, &instance);
        assert!(
            errors.iter().any(|e| e.contains(expected)),
            "{instance}: {errors:?}"
        );
    }
    let unsupported = serde_json::json!({ "pattern": "^a" });
    assert!(validate(&unsupported, &serde_json::json!("a"))[0].contains("unsupported"));
}
