//! JSON Schemas (draft 2020-12) of the species and scenario formats, generated from the same
//! table as completion ([`super::schema`]), for tools without the language server. They
//! describe a file's structure as serde writes it in JSON: a struct is an object, a unit variant
//! a string, another variant an object with one key (`{"Within": ["Food", 2.0]}`), a vector an
//! array of three numbers. RON spellings (`Chase(d0: 0.6)`) map onto it one to one.

use super::schema::{self, Args, Field, Form, TypeDef, NAME_TYPES};
use serde_json::{json, Map, Value};

/// The schema of the format whose root type is `root` (`SpeciesDef`, `ScenarioDef`).
pub fn schema_of(root: &str, title: &str) -> Value {
    let mut defs = Map::new();
    let mut todo = vec![root.to_string()];
    while let Some(n) = todo.pop() {
        if defs.contains_key(&n) {
            continue;
        }
        let Some(t) = schema::get(&n) else { continue };
        defs.insert(n.clone(), type_schema(t, &mut todo));
    }
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": format!("https://shoal.invalid/schemas/{}.schema.json", title.to_lowercase()),
        "title": title,
        "description": format!("The shoal {} format, as serde writes it in JSON (files are RON).", title.to_lowercase()),
        "$ref": format!("#/$defs/{root}"),
        "$defs": defs,
    })
}

fn type_schema(t: &TypeDef, todo: &mut Vec<String>) -> Value {
    let mut s = match &t.form {
        Form::Struct(f) => object(f, todo),
        Form::Enum(vs) => {
            let one: Vec<Value> = vs
                .iter()
                .map(|v| {
                    let inner = match &v.args {
                        Args::Unit => return json!({ "const": v.name, "description": v.doc }),
                        Args::Named(f) => object(f, todo),
                        Args::Tuple(a) if a.len() == 1 => ty(a[0], todo),
                        Args::Tuple(a) => json!({
                            "type": "array",
                            "prefixItems": a.iter().map(|x| ty(x, todo)).collect::<Vec<_>>(),
                            "minItems": a.len(),
                            "maxItems": a.len(),
                        }),
                    };
                    json!({
                        "type": "object",
                        "properties": { v.name: inner },
                        "required": [v.name],
                        "additionalProperties": false,
                        "description": v.doc,
                    })
                })
                .collect();
            json!({ "oneOf": one })
        }
        Form::Either(alts) => {
            json!({ "anyOf": alts.iter().map(|a| ty(a, todo)).collect::<Vec<_>>() })
        }
    };
    if let Some(o) = s.as_object_mut() {
        o.insert("description".into(), json!(t.doc));
    }
    s
}

fn object(fields: &[Field], todo: &mut Vec<String>) -> Value {
    let mut props = Map::new();
    for f in fields {
        let mut p = ty(f.ty, todo);
        if let Some(o) = p.as_object_mut() {
            o.insert("description".into(), json!(f.doc));
        }
        props.insert(f.name.to_string(), p);
    }
    let required: Vec<&str> = fields
        .iter()
        .filter(|f| f.required)
        .map(|f| f.name)
        .collect();
    json!({
        "type": "object",
        "properties": props,
        "required": required,
        "additionalProperties": false,
    })
}

/// The schema of a value of type `t`.
fn ty(t: &str, todo: &mut Vec<String>) -> Value {
    let t = t.trim();
    if let Some(inner) = schema::wrapped(t, "Option") {
        return json!({ "anyOf": [ty(inner, todo), { "type": "null" }] });
    }
    if let Some(inner) = schema::wrapped(t, "Box") {
        return ty(inner, todo);
    }
    if let Some(inner) = schema::wrapped(t, "Vec") {
        return json!({ "type": "array", "items": ty(inner, todo) });
    }
    if let Some(v) = schema::map_value(t) {
        return json!({ "type": "object", "additionalProperties": ty(v, todo) });
    }
    match t {
        "f32" | "f64" => json!({ "type": "number" }),
        "u8" | "u16" | "u32" | "u64" | "usize" => json!({ "type": "integer", "minimum": 0 }),
        "i64" => json!({ "type": "integer" }),
        "bool" => json!({ "type": "boolean" }),
        "Vec3" => json!({
            "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3
        }),
        "(f32, f32)" => json!({
            "type": "array", "items": { "type": "number" }, "minItems": 2, "maxItems": 2
        }),
        _ if t == "String" || NAME_TYPES.contains(&t) => json!({ "type": "string" }),
        _ => {
            todo.push(t.to_string());
            json!({ "$ref": format!("#/$defs/{t}") })
        }
    }
}

/// The species format's schema.
pub fn species() -> Value {
    schema_of("SpeciesDef", "Species")
}

/// The scenario format's schema.
pub fn scenario() -> Value {
    schema_of("ScenarioDef", "Scenario")
}
