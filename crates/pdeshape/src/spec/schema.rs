//! The JSON schema of the design file: schemars' schema of [`DesignSpec`] with the limits the
//! reader enforces added as `minimum`/`maximum`/`exclusiveMinimum`/`maxItems`/`maxLength`, and
//! without single-element `allOf` wrappers (editors' language servers recurse on them).

use super::limits::*;
use super::DesignSpec;
use serde_json::{json, Map, Value};

/// The schema as a JSON value.
pub fn schema_value() -> Value {
    let schema = schemars::schema_for!(DesignSpec);
    let mut v = serde_json::to_value(&schema).unwrap_or(Value::Null);
    unwrap_all_of(&mut v);
    add_limits(&mut v);
    if let Value::Object(root) = &mut v {
        if let Some(Value::Object(props)) = root.get_mut("properties") {
            if let Some(Value::Object(curves)) = props.get_mut("curves") {
                curves.insert("maxProperties".into(), json!(MAX_CURVES));
            }
        }
    }
    v
}

/// `{"allOf": [X], ...}` becomes `X` merged with the other keys.
fn unwrap_all_of(v: &mut Value) {
    match v {
        Value::Object(m) => {
            if let Some(Value::Array(items)) = m.get("allOf") {
                if items.len() == 1 {
                    if let Value::Object(inner) = items[0].clone() {
                        m.remove("allOf");
                        for (k, x) in inner {
                            m.entry(k).or_insert(x);
                        }
                    }
                }
            }
            for x in m.values_mut() {
                unwrap_all_of(x);
            }
        }
        Value::Array(items) => items.iter_mut().for_each(unwrap_all_of),
        _ => {}
    }
}

fn is_type(p: &Map<String, Value>, t: &str) -> bool {
    match p.get("type") {
        Some(Value::String(s)) => s == t,
        Some(Value::Array(a)) => a.iter().any(|x| x == t),
        _ => false,
    }
}

fn set(p: &mut Map<String, Value>, key: &str, value: Value) {
    p.insert(key.to_string(), value);
}

/// The limits, by property name (and the sibling that identifies the table where a name is
/// shared).
fn add_limits(v: &mut Value) {
    match v {
        Value::Object(m) => {
            if let Some(Value::Object(props)) = m.get_mut("properties") {
                let polyharmonic = props.contains_key("order") && props.contains_key("a");
                for (name, p) in props.iter_mut() {
                    let Value::Object(p) = p else { continue };
                    let number = is_type(p, "number");
                    let integer = is_type(p, "integer");
                    let array = is_type(p, "array");
                    let string = is_type(p, "string");
                    match name.as_str() {
                        "order" if integer && polyharmonic => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(20));
                        }
                        "a" if number && polyharmonic => {
                            set(p, "minimum", json!(MIN_SMOOTHING));
                            set(p, "maximum", json!(MAX_SMOOTHING));
                        }
                        "modes" if integer => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(256));
                        }
                        "samples" if integer => set(p, "maximum", json!(1 << 16)),
                        "radius" | "rx" | "ry" if number => set(p, "exclusiveMinimum", json!(0)),
                        "u" if number => {
                            set(p, "minimum", json!(0));
                            set(p, "maximum", json!(1));
                        }
                        "derivative" if integer => set(p, "maximum", json!(39)),
                        "degree" if integer => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(30));
                        }
                        "steps" | "max_steps" if integer => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(MAX_STEPS));
                        }
                        "intervals" if integer => {
                            set(p, "minimum", json!(5));
                            set(p, "maximum", json!(MAX_INTERVALS));
                        }
                        "evaluations" if integer => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(MAX_EVALUATIONS));
                        }
                        "polish" if integer => set(p, "maximum", json!(MAX_POLISH)),
                        "chains" if integer => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(MAX_CHAINS));
                        }
                        "nu" if integer => {
                            set(p, "minimum", json!(2));
                            set(p, "maximum", json!(MAX_GRID_VERTICES / 3));
                        }
                        "nv" if integer => {
                            set(p, "minimum", json!(3));
                            set(p, "maximum", json!(MAX_GRID_VERTICES / 2));
                        }
                        "cos" | "sin" if array => set(p, "maxItems", json!(MAX_FOURIER_TERMS)),
                        "constraints" if array => set(p, "maxItems", json!(MAX_CONSTRAINTS)),
                        "parameters" if array => set(p, "maxItems", json!(MAX_PARAMETERS)),
                        "patches" if array => set(p, "maxItems", json!(MAX_PATCHES)),
                        _ if array => {
                            p.entry("maxItems").or_insert(json!(MAX_ARRAY_ITEMS));
                        }
                        _ if string => {
                            p.entry("maxLength").or_insert(json!(MAX_STRING_CHARS));
                        }
                        _ => {}
                    }
                }
            }
            for x in m.values_mut() {
                add_limits(x);
            }
        }
        Value::Array(items) => items.iter_mut().for_each(add_limits),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn find<'a>(v: &'a Value, name: &str, out: &mut Vec<&'a Map<String, Value>>) {
        match v {
            Value::Object(m) => {
                if let Some(Value::Object(props)) = m.get("properties") {
                    if let Some(Value::Object(p)) = props.get(name) {
                        out.push(p);
                    }
                }
                m.values().for_each(|x| find(x, name, out));
            }
            Value::Array(a) => a.iter().for_each(|x| find(x, name, out)),
            _ => {}
        }
    }

    fn count_single_all_of(v: &Value) -> usize {
        match v {
            Value::Object(m) => {
                let here = matches!(m.get("allOf"), Some(Value::Array(a)) if a.len() == 1);
                usize::from(here) + m.values().map(count_single_all_of).sum::<usize>()
            }
            Value::Array(a) => a.iter().map(count_single_all_of).sum(),
            _ => 0,
        }
    }

    #[test]
    fn no_single_element_all_of() {
        let raw = serde_json::to_value(schemars::schema_for!(DesignSpec)).unwrap();
        assert!(
            count_single_all_of(&raw) > 0,
            "the wrappers this removes exist"
        );
        assert_eq!(count_single_all_of(&schema_value()), 0);
    }

    #[test]
    fn limits_are_in_the_schema() {
        let s = schema_value();
        let mut v = Vec::new();
        find(&s, "order", &mut v);
        let get = |p: &Map<String, Value>, k: &str| p.get(k).cloned().unwrap_or(Value::Null);
        assert!(v
            .iter()
            .any(|p| get(p, "minimum") == 1 && get(p, "maximum") == 20));
        let mut v = Vec::new();
        find(&s, "a", &mut v);
        assert!(v
            .iter()
            .any(|p| get(p, "minimum") == 1e-6 && get(p, "maximum") == 1e6));
        let mut v = Vec::new();
        find(&s, "radius", &mut v);
        assert!(!v.is_empty() && v.iter().all(|p| get(p, "exclusiveMinimum") == 0));
        for (name, key, value) in [
            ("steps", "maximum", json!(MAX_STEPS)),
            ("intervals", "maximum", json!(MAX_INTERVALS)),
            ("evaluations", "maximum", json!(MAX_EVALUATIONS)),
            ("polish", "maximum", json!(MAX_POLISH)),
            ("chains", "maximum", json!(MAX_CHAINS)),
            ("cos", "maxItems", json!(MAX_FOURIER_TERMS)),
            ("constraints", "maxItems", json!(MAX_CONSTRAINTS)),
            ("u", "maximum", json!(1)),
            ("modes", "minimum", json!(1)),
        ] {
            let mut v = Vec::new();
            find(&s, name, &mut v);
            assert!(!v.is_empty(), "{name}");
            assert!(v.iter().all(|p| get(p, key) == value), "{name}: {v:?}");
        }
    }
}
