//! The generated JSON Schemas validate every shipped species and scenario file.

use super::*;
use crate::load::ron_options;

/// A tiny JSON Schema checker: `$ref`, `type`, `const`, `properties`, `required`,
/// `additionalProperties`, `items`, `prefixItems`, `oneOf`, `anyOf` (what the generated schemas
/// use). JSON has no infinity: serde writes it as `null`, taken for a number.
fn validate(
    v: &serde_json::Value,
    s: &serde_json::Value,
    root: &serde_json::Value,
    path: &str,
) -> Vec<String> {
    use serde_json::Value as J;
    if let Some(r) = s.get("$ref").and_then(J::as_str) {
        let name = r.trim_start_matches("#/$defs/");
        return validate(v, &root["$defs"][name], root, path);
    }
    if let Some(c) = s.get("const") {
        return if v == c {
            vec![]
        } else {
            vec![format!("{path}: {v} is not {c}")]
        };
    }
    for (key, need_one) in [("oneOf", true), ("anyOf", false)] {
        if let Some(alts) = s.get(key).and_then(J::as_array) {
            let ok = alts
                .iter()
                .filter(|a| validate(v, a, root, path).is_empty())
                .count();
            return if ok == 1 || (!need_one && ok > 0) {
                vec![]
            } else {
                vec![format!("{path}: {v} matches {ok} of {key}")]
            };
        }
    }
    let mut out = Vec::new();
    match (s.get("type").and_then(J::as_str), v) {
        (Some("null"), J::Null)
        | (Some("number"), J::Number(_) | J::Null)
        | (Some("boolean"), J::Bool(_))
        | (Some("string"), J::String(_)) => {}
        (Some("integer"), J::Number(n)) if n.is_i64() || n.is_u64() => {}
        (Some("array"), J::Array(a)) => {
            for (i, x) in a.iter().enumerate() {
                let item = s
                    .get("prefixItems")
                    .and_then(|p| p.get(i))
                    .or(s.get("items"));
                if let Some(item) = item {
                    out.extend(validate(x, item, root, &format!("{path}[{i}]")));
                }
            }
        }
        (Some("object"), J::Object(m)) => {
            for (k, x) in m {
                match s.get("properties").and_then(|p| p.get(k)) {
                    Some(p) => out.extend(validate(x, p, root, &format!("{path}.{k}"))),
                    None => match s.get("additionalProperties") {
                        Some(J::Bool(false)) => {
                            out.push(format!("{path}: key `{k}` is not in the schema"))
                        }
                        Some(a) => out.extend(validate(x, a, root, &format!("{path}.{k}"))),
                        None => {}
                    },
                }
            }
            for r in s
                .get("required")
                .and_then(J::as_array)
                .into_iter()
                .flatten()
            {
                if !m.contains_key(r.as_str().unwrap_or("")) {
                    out.push(format!("{path}: required `{r}` missing"));
                }
            }
        }
        (t, v) => out.push(format!("{path}: {v} is not of type {t:?}")),
    }
    out
}

#[test]
fn the_json_schemas_validate_the_shipped_files() {
    let species = json_schema::species();
    let scenario = json_schema::scenario();
    let mut n = 0;
    for (p, text) in shipped("behaviors") {
        let def: crate::species::SpeciesDef = ron_options().from_str(&text).unwrap();
        let v = serde_json::to_value(&def).unwrap();
        let e = validate(&v, &species, &species, "");
        assert!(e.is_empty(), "{}:\n{}", p.display(), e.join("\n"));
        n += 1;
    }
    for (p, text) in shipped("scenarios") {
        let def: crate::scenario::ScenarioDef = ron_options().from_str(&text).unwrap();
        let v = serde_json::to_value(&def).unwrap();
        let e = validate(&v, &scenario, &scenario, "");
        assert!(e.is_empty(), "{}:\n{}", p.display(), e.join("\n"));
        n += 1;
    }
    assert!(n >= 10, "{n} files");
    // The checker can fail: an unknown key, a wrong variant.
    let mut v = serde_json::to_value(
        ron_options()
            .from_str::<crate::species::SpeciesDef>(&shipped("behaviors")[0].1)
            .unwrap(),
    )
    .unwrap();
    v["bogus"] = serde_json::json!(1);
    v["body"]["locomotion"] = serde_json::json!("Hovering");
    let e = validate(&v, &species, &species, "");
    assert!(
        e.iter().any(|e| e.contains("`bogus` is not in the schema")),
        "{e:?}"
    );
    assert!(e.iter().any(|e| e.contains(".body.locomotion")), "{e:?}");
    assert_eq!(
        species["$schema"],
        "https://json-schema.org/draft/2020-12/schema"
    );
}
