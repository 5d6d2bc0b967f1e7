//! A body's shape against its schema in the served OpenAPI document, before serde reads it.
//!
//! serde's derived structs also take a JSON array, field by field in order
//! (`"limit_switches": [-5, 5, true]`), and serde refuses `2.0` for an integer field although
//! JSON Schema counts it as one. Here, walking the body beside its component schema: an array
//! where the document says object is a 422 at its path, and a whole number written with a
//! fraction (`2.0`, up to 2^53) where it says integer is read as that integer. Everything else
//! (ranges, enums, required fields) stays with serde and the service's checks.

use std::sync::OnceLock;

use serde_json::{Map, Value};

use crate::error::AppError;

/// `components.schemas` of the served document.
fn schemas() -> &'static Map<String, Value> {
    static SCHEMAS: OnceLock<Map<String, Value>> = OnceLock::new();
    SCHEMAS.get_or_init(|| {
        let doc = serde_json::to_value(super::ApiDoc::document()).expect("the document serialises");
        doc["components"]["schemas"]
            .as_object()
            .cloned()
            .unwrap_or_default()
    })
}

/// Checks (and normalises) `value` against the component schema `name`; unknown names pass.
pub fn check(name: &str, value: &mut Value) -> Result<(), AppError> {
    let Some(schema) = schemas().get(name) else {
        return Ok(());
    };
    walk(schema, value, &mut String::new(), false)
}

/// After serde has read a body: a field the document does not know in a closed object
/// (`additionalProperties: false`) that serde let pass — a tagged variant without fields
/// ignores unknown ones. (Run after serde, whose refusals name the field and what was
/// expected, as `renamed to distance`.)
pub fn check_closed(name: &str, value: &Value) -> Result<(), AppError> {
    let Some(schema) = schemas().get(name) else {
        return Ok(());
    };
    walk(schema, &mut value.clone(), &mut String::new(), true)
}

fn resolve(schema: &Value) -> &Value {
    match schema.get("$ref").and_then(Value::as_str) {
        Some(r) => r
            .strip_prefix("#/components/schemas/")
            .and_then(|n| schemas().get(n))
            .unwrap_or(&Value::Null),
        None => schema,
    }
}

fn types(schema: &Value) -> Vec<&str> {
    match schema.get("type") {
        Some(Value::String(t)) => vec![t.as_str()],
        Some(Value::Array(ts)) => ts.iter().filter_map(Value::as_str).collect(),
        _ if schema.get("properties").is_some() => vec!["object"],
        _ => Vec::new(),
    }
}

fn at(path: &str) -> String {
    if path.is_empty() {
        "body".into()
    } else {
        path.to_owned()
    }
}

fn walk(
    schema: &Value,
    value: &mut Value,
    path: &mut String,
    closed_too: bool,
) -> Result<(), AppError> {
    let schema = resolve(schema);
    for key in ["oneOf", "anyOf"] {
        if let Some(branches) = schema.get(key).and_then(Value::as_array) {
            return walk_branches(branches, value, path, closed_too);
        }
    }
    if let Some(all) = schema.get("allOf").and_then(Value::as_array) {
        for s in all {
            walk(s, value, path, closed_too)?;
        }
    }
    let ts = types(schema);
    match value {
        Value::Array(items) => {
            if ts.contains(&"object") && !ts.contains(&"array") {
                return Err(AppError::field(
                    &at(path),
                    "must be a JSON object, not an array",
                ));
            }
            if let Some(item) = schema.get("items") {
                let len = path.len();
                for (i, v) in items.iter_mut().enumerate() {
                    path.push_str(&format!("[{i}]"));
                    walk(item, v, path, closed_too)?;
                    path.truncate(len);
                }
            }
        }
        Value::Object(map) => {
            let props = schema.get("properties").and_then(Value::as_object);
            let extra = schema.get("additionalProperties").filter(|a| a.is_object());
            let closed =
                closed_too && schema.get("additionalProperties") == Some(&Value::Bool(false));
            for (k, v) in map.iter_mut() {
                let Some(s) = props.and_then(|p| p.get(k)).or(extra) else {
                    // serde ignores an unknown field where it has nothing to read (a
                    // variant without fields): the document says the object is closed.
                    if closed {
                        let mut field = path.clone();
                        if !field.is_empty() {
                            field.push('.');
                        }
                        field.push_str(k);
                        return Err(AppError::field(&field, "unknown field"));
                    }
                    continue;
                };
                let len = path.len();
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
                walk(s, v, path, closed_too)?;
                path.truncate(len);
            }
        }
        Value::Number(n) if ts.contains(&"integer") && !n.is_i64() && !n.is_u64() => {
            if let Some(f) = n
                .as_f64()
                .filter(|f| f.fract() == 0.0 && f.abs() <= 9_007_199_254_740_992.0)
            {
                *value = Value::from(f as i64);
            }
        }
        _ => {}
    }
    Ok(())
}

/// `oneOf`/`anyOf`: an array is refused when no branch takes one; an object or number is
/// walked by the branches that take its type (the first that passes wins, else the first
/// error), so that a tagged variant's fields are checked by their own schema.
fn walk_branches(
    branches: &[Value],
    value: &mut Value,
    path: &mut String,
    closed_too: bool,
) -> Result<(), AppError> {
    let kind = match value {
        Value::Array(_) => "array",
        Value::Object(_) => "object",
        Value::Number(_) => "number",
        _ => return Ok(()),
    };
    let fits = |s: &Value| {
        let ts = types(resolve(s));
        ts.is_empty()
            || ts.contains(&kind)
            || (kind == "number" && ts.contains(&"integer"))
            || resolve(s).get("oneOf").is_some()
            || resolve(s).get("anyOf").is_some()
    };
    let candidates: Vec<&Value> = branches.iter().filter(|s| fits(s)).collect();
    if candidates.is_empty() {
        return match kind {
            "array" => Err(AppError::field(
                &at(path),
                "must be a JSON object, not an array",
            )),
            _ => Ok(()),
        };
    }
    // A tagged variant: the branch whose `kind` (or other single-value tag) matches.
    let tagged = candidates.iter().find(|s| {
        let props = resolve(s).get("properties").and_then(Value::as_object);
        props.is_some_and(|p| {
            p.iter().any(|(k, v)| {
                v.get("enum")
                    .and_then(Value::as_array)
                    .is_some_and(|e| e.len() == 1 && value.get(k) == e.first())
            })
        })
    });
    if let Some(s) = tagged {
        return walk(s, value, path, closed_too);
    }
    // No tag given: the branch whose tag may be left out (it has a default, e.g. a simulated
    // drive without `kind`) is the one meant, so that its errors are reported.
    let untagged_default = candidates.iter().find(|s| {
        let r = resolve(s);
        let props = r.get("properties").and_then(Value::as_object);
        let required = r.get("required").and_then(Value::as_array);
        props.is_some_and(|p| {
            p.iter().any(|(k, v)| {
                v.get("enum")
                    .and_then(Value::as_array)
                    .is_some_and(|e| e.len() == 1)
                    && value.get(k).is_none()
                    && !required.is_some_and(|req| req.iter().any(|x| x == k))
            })
        })
    });
    if let Some(s) = untagged_default {
        return walk(s, value, path, closed_too);
    }
    let mut first_err = None;
    for s in candidates {
        let mut attempt = value.clone();
        match walk(s, &mut attempt, path, closed_too) {
            Ok(()) => {
                *value = attempt;
                return Ok(());
            }
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    Err(first_err.expect("at least one candidate"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn an_array_for_a_nested_object_is_refused_at_its_path() {
        let mut v = json!({"name": "a", "unit": "mm", "dynamics": {}, "drive": {"limit_switches": [-5, 5, true]}});
        let e = check("AxisConfigDto", &mut v).unwrap_err();
        assert_eq!(e.problem().errors[0].field, "drive.limit_switches");
        let v = json!({"name": "a", "unit": "mm", "dynamics": {}, "drive": {"plant": {"kind": "ideal", "x": 1}}});
        let e = check_closed("AxisConfigDto", &v).unwrap_err();
        assert_eq!(e.problem().errors[0].field, "drive.plant.x");
        let mut v = json!({"name": "a", "unit": "mm", "dynamics": [1, 2, 3, 4, 5, 6]});
        let e = check("AxisConfigDto", &mut v).unwrap_err();
        assert_eq!(e.problem().errors[0].field, "dynamics");
    }

    #[test]
    fn a_whole_number_with_a_fraction_is_read_as_an_integer() {
        let mut v = json!({"master": "x", "ratio_numerator": 1, "ratio_denominator": 2.0});
        check("GearInBody", &mut v).unwrap();
        assert!(v["ratio_denominator"].is_u64());
        let mut v = json!({"master": "x", "ratio_numerator": 1, "ratio_denominator": 2.5});
        check("GearInBody", &mut v).unwrap();
        assert!(v["ratio_denominator"].is_f64(), "left for serde to refuse");
        // Arrays that are arrays stay.
        let mut v =
            json!({"channels": [{"axis": "x", "signal": "set_position"}], "duration_s": 1.0});
        check("RecordingRequest", &mut v).unwrap();
    }
}
