//! The JSON schema of the design file: schemars' schema of [`DesignSpec`] with the limits the
//! reader enforces added as `minimum`/`maximum`/`exclusiveMinimum`/`maxItems`/`maxLength`, and
//! without single-element `allOf` wrappers (editors' language servers recurse on them).

use super::limits::*;
use super::DesignSpec;
use serde_json::{json, Map, Value};

/// The schema as a JSON value.
pub(super) fn schema_value() -> Value {
    let schema = schemars::schema_for!(DesignSpec);
    let mut v = serde_json::to_value(&schema).unwrap_or(Value::Null);
    add_rig(&mut v);
    unwrap_all_of(&mut v);
    add_limits(&mut v);
    add_descriptions(&mut v);
    allow_time_formulas(&mut v);
    tag_curves_by_type(&mut v);
    if let Value::Object(root) = &mut v {
        if let Some(Value::Object(props)) = root.get_mut("properties") {
            if let Some(Value::Object(curves)) = props.get_mut("curves") {
                curves.insert("maxProperties".into(), json!(MAX_CURVES));
            }
        }
    }
    v
}

/// The schema of a morph file ([`super::time::MorphFile`]): schemars' schema without
/// single-element `allOf` wrappers, the ease's bound and a title saying what it is for.
pub(super) fn morph_schema_value() -> Value {
    let schema = schemars::schema_for!(super::time::MorphFile);
    let mut v = serde_json::to_value(&schema).unwrap_or(Value::Null);
    unwrap_all_of(&mut v);
    if let Value::Object(root) = &mut v {
        root.insert(
            "title".into(),
            json!("pdeshape morph file: two designs of one structure interpolated over time"),
        );
    }
    if let Some(Value::Object(ease)) = v.pointer_mut("/definitions/MorphSpec/properties/ease") {
        ease.insert("exclusiveMinimum".into(), json!(0));
    }
    v
}

/// `[rig]` (spec::rig), which the timed-design reader applies and removes before the design is
/// read: its schema joins the design's as an optional property.
fn add_rig(root: &mut Value) {
    let rig =
        serde_json::to_value(schemars::schema_for!(super::rig::RigSpec)).unwrap_or(Value::Null);
    let Value::Object(mut rig) = rig else { return };
    let defs = rig.remove("definitions");
    rig.remove("$schema");
    rig.remove("title");
    let Value::Object(root) = root else { return };
    if let Some(Value::Object(all)) = root.get_mut("definitions") {
        if let Some(Value::Object(defs)) = defs {
            all.extend(defs);
        }
        all.insert("RigSpec".into(), Value::Object(rig));
    }
    if let Some(Value::Object(props)) = root.get_mut("properties") {
        props.insert(
            "rig".into(),
            json!({
                "$ref": "#/definitions/RigSpec",
                "description": "A skeleton of hinged bones with keyframed joint angles posing the curves attached to them (needs [time]; book §8.1.3.1)."
            }),
        );
    }
}

/// The sections whose numbers are never formulas in `t` (they have formula languages of their
/// own, or define time itself): see `spec::time`.
const NO_TIME_FORMULAS: &[&str] = &[
    "DynamicSpec",
    "OptimizeSpec",
    "ParametricSpec",
    "TimeSpec",
    "FormulaText",
    "RigSpec",
    "BoneSpec",
];

/// Every other number may be written as a formula in `t`, a string starting with `=`
/// (`spec::time`): `"type": "number"` becomes `["number", "string"]` with a pattern. Limits stay
/// where they are, since `minimum`/`maximum` constrain numbers only and `pattern` strings only.
fn allow_time_formulas(root: &mut Value) {
    fn walk(v: &mut Value) {
        match v {
            Value::Object(m) => {
                let widened = match m.get("type") {
                    Some(Value::String(t)) if t == "number" => Some(json!(["number", "string"])),
                    Some(Value::Array(ts))
                        if ts.contains(&json!("number")) && !ts.contains(&json!("string")) =>
                    {
                        let mut ts = ts.clone();
                        ts.push(json!("string"));
                        Some(Value::Array(ts))
                    }
                    _ => None,
                };
                if let Some(t) = widened {
                    m.insert("type".into(), t);
                    m.insert("pattern".into(), json!("^\\s*="));
                }
                for x in m.values_mut() {
                    walk(x);
                }
            }
            Value::Array(items) => items.iter_mut().for_each(walk),
            _ => {}
        }
    }
    let Value::Object(m) = root else { return };
    for (key, x) in m.iter_mut() {
        match (key.as_str(), x) {
            ("definitions", Value::Object(defs)) => {
                for (name, def) in defs.iter_mut() {
                    if !NO_TIME_FORMULAS.contains(&name.as_str()) {
                        walk(def);
                    }
                }
            }
            ("properties", Value::Object(props)) => {
                for (name, p) in props.iter_mut() {
                    if !["dynamic", "optimize", "parametric", "time", "rig"]
                        .contains(&name.as_str())
                    {
                        walk(p);
                    }
                }
            }
            _ => {}
        }
    }
}

/// `CurveSpec`'s `oneOf` of one object per `type` becomes a chain of `if`/`then`/`else` on
/// `type` (`if type is "circle" then the circle's object else if …`, the last `else` naming the
/// types), so a validator reports a key the chosen type does not take ("Additional properties
/// are not allowed ('rx' was unexpected)") or a missing one, instead of "not valid under any of
/// the schemas listed in the 'oneOf' keyword". The table's own `properties` list every key of
/// every type with a description that says which types take it, with no further structure: an
/// editor's language server that completes keys from `properties` without reading `type` (Even
/// Better TOML's does not read the document's values) offers those 40 names, not the thousands
/// of nested keys the branches of a `oneOf` expand to.
fn tag_curves_by_type(root: &mut Value) {
    let Some(Value::Object(curve)) = root.pointer_mut("/definitions/CurveSpec") else {
        return;
    };
    let Some(Value::Array(variants)) = curve.remove("oneOf") else {
        return;
    };
    let tag_of = |v: &Value| {
        v.pointer("/properties/type/enum/0")
            .and_then(Value::as_str)
            .map(str::to_string)
    };
    let types: Vec<String> = variants.iter().filter_map(tag_of).collect();
    // key → (description, the types that take it), in the order of first use.
    let mut keys: Vec<(String, String, Vec<String>)> = Vec::new();
    for v in &variants {
        let tag = tag_of(v).unwrap_or_default();
        for (k, p) in v
            .get("properties")
            .and_then(Value::as_object)
            .into_iter()
            .flatten()
        {
            if k == "type" {
                continue;
            }
            let text = p.get("description").and_then(Value::as_str).unwrap_or("");
            match keys.iter_mut().find(|(name, _, _)| name == k) {
                Some((_, _, ts)) => ts.push(tag.clone()),
                None => keys.push((k.clone(), text.to_string(), vec![tag.clone()])),
            }
        }
    }
    let mut props = Map::new();
    props.insert(
        "type".into(),
        json!({
            "description": format!("The kind of curve: {}.", types.join(", ")),
            "type": "string",
            "enum": types,
        }),
    );
    for (k, text, ts) in keys {
        let text = if ts.len() == types.len() {
            format!("{text} (every type)")
        } else {
            format!("{text} (type {})", ts.join(", "))
        };
        props.insert(k, json!({ "description": text }));
    }
    let mut chain = json!({
        "properties": { "type": {
            "description": format!("None of the kinds: {}.", types.join(", ")),
            "enum": types,
        } },
    });
    for v in variants.into_iter().rev() {
        let tag = tag_of(&v).unwrap_or_default();
        chain = json!({
            "if": {
                "properties": { "type": {
                    "description": format!("A {tag} curve: the keys below."),
                    "const": tag,
                } },
                "required": ["type"],
            },
            "then": v,
            "else": chain,
        });
    }
    curve.insert("type".into(), json!("object"));
    curve.insert("required".into(), json!(["type"]));
    curve.insert("properties".into(), Value::Object(props));
    if let Value::Object(chain) = chain {
        curve.extend(chain);
    }
}

/// The object of each curve type in the schema's `if`/`then`/`else` chain on `type`
/// ([`tag_curves_by_type`]), in order.
#[cfg(test)]
pub(crate) fn curve_variants(schema: &Value) -> Vec<&Value> {
    let mut out = Vec::new();
    let mut at = &schema["definitions"]["CurveSpec"];
    while at.get("if").is_some() {
        out.push(&at["then"]);
        at = &at["else"];
    }
    out
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

/// Descriptions of the properties whose Rust fields carry none (fields of enum variants, the
/// tags schemars adds): `(definition, variant tag or "", property, text)`.
const DESCRIPTIONS: &[(&str, &str, &str, &str)] = &[
    ("CurveSpec", "circle", "center", "Centre of the circle [x, y, z]."),
    ("CurveSpec", "circle", "radius", "Radius (> 0)."),
    ("CurveSpec", "circle", "normal", "Normal of the circle's plane (default [0, 0, 1]); v runs counter-clockwise about it."),
    ("CurveSpec", "ellipse", "center", "Centre of the ellipse [x, y, z]."),
    ("CurveSpec", "ellipse", "axis1", "The point at v = 0 minus the centre (with axis2; instead of rx, ry)."),
    ("CurveSpec", "ellipse", "axis2", "The point at v = π/2 minus the centre (with axis1)."),
    ("CurveSpec", "ellipse", "rx", "Semi-axis along the start direction (> 0; with ry)."),
    ("CurveSpec", "ellipse", "ry", "Semi-axis perpendicular to it in the plane (> 0; with rx)."),
    ("CurveSpec", "ellipse", "normal", "Normal of the plane of rx, ry (default [0, 0, 1])."),
    ("CurveSpec", "point", "at", "The point [x, y, z] the whole curve sits on (a pole)."),
    ("CurveSpec", "bspline", "control", "Control points [x, y, z]."),
    ("CurveSpec", "bspline", "degree", "Polynomial degree (1 to 30)."),
    ("CurveSpec", "bspline", "knots", "Periodic: the control.len() + 1 increasing breakpoints (default uniform); open: the full clamped knot vector."),
    ("CurveSpec", "bspline", "periodic", "Closed periodic curve over [0, 2π] (default true) or an open clamped one."),
    ("CurveSpec", "bezier", "control", "Control points [x, y, z] (degree = count − 1)."),
    ("CurveSpec", "hermite", "p0", "Position at the start."),
    ("CurveSpec", "hermite", "p1", "Position at the end."),
    ("CurveSpec", "hermite", "d0", "Derivative at the start."),
    ("CurveSpec", "hermite", "d1", "Derivative at the end."),
    ("CurveSpec", "fourier", "a0", "The constant term [x, y, z]."),
    ("CurveSpec", "fourier", "cos", "Coefficients of cos v, cos 2v, … (one [x, y, z] each)."),
    ("CurveSpec", "fourier", "sin", "Coefficients of sin v, sin 2v, … (one [x, y, z] each)."),
    ("CurveSpec", "samples", "points", "The closed sequence of points [x, y, z] (the last is not repeated)."),
    ("CurveSpec", "samples", "param", "How the samples are spread over [0, 2π]: uniform, chord (default) or centripetal."),
    ("CurveSpec", "formula", "x", "x as a formula in v."),
    ("CurveSpec", "formula", "y", "y as a formula in v."),
    ("CurveSpec", "formula", "z", "z as a formula in v."),
    ("CurveSpec", "formula", "domain", "The range of v: periodic over [0, 2π] (default) or an interval."),
    ("CurveSpec", "derivative", "position", "The position curve (name or inline table)."),
    ("CurveSpec", "derivative", "direction", "The direction curve (name or inline table)."),
    ("CurveSpec", "derivative", "scale", "The factor s of X_u = s (direction − position)."),
    ("CurveSpec", "local", "curve", "The curve edited (name or inline table)."),
    ("CurveSpec", "local", "from", "Start of the edited interval of v."),
    ("CurveSpec", "local", "to", "End of the edited interval of v (below from: across v = 0 on a periodic curve)."),
    ("CurveSpec", "local", "at", "The handle's parameter (default the middle of the interval)."),
    ("CurveSpec", "local", "along", "Move of the handle from C(from) towards C(to)."),
    ("CurveSpec", "local", "across", "Move of the handle in the plane of the three points, towards the handle."),
    ("CurveSpec", "local", "normal", "Move of the handle perpendicular to that plane."),
    ("DynamicSpec", "", "y", "Run: the second component's initial curve (as x)."),
    ("DynamicSpec", "", "z", "Run: the third component's initial curve (as x)."),
    ("DynamicSpec", "", "end", "Interpolation: the end point."),
    ("DynamicSpec", "", "start_tangent", "Interpolation: the derivative at the start (u ∈ [0, 1])."),
    ("DynamicSpec", "", "end_tangent", "Interpolation: the derivative at the end (u ∈ [0, 1])."),
    ("EnergySpec", "section6", "a", "The smoothing parameter a (> 0)."),
    ("EnergySpec", "general", "a", "Weight of |u_xx|²."),
    ("EnergySpec", "general", "b", "Weight of ⟨u_xx, u_xy⟩."),
    ("EnergySpec", "general", "c", "Weight of |u_xy|²."),
    ("EnergySpec", "general", "d", "Weight of ⟨u_xy, u_yy⟩."),
    ("EnergySpec", "general", "e", "Weight of |u_yy|²."),
    ("EnergySpec", "general", "mixed", "How the mixed terms are formed."),
    ("OperatorSpec", "sixth-order", "a", "Coefficient of ∂u⁶."),
    ("OperatorSpec", "sixth-order", "b", "Coefficient of ∂u⁴∂v²."),
    ("OperatorSpec", "sixth-order", "c", "Coefficient of ∂u²∂v⁴."),
    ("OperatorSpec", "sixth-order", "d", "Coefficient of ∂v⁶."),
    ("OperatorSpec", "general", "coefficients", "[c_0, …, c_N]: c_k multiplies ∂u^(2N−2k) ∂v^(2k)."),
    ("ParametricSpec", "", "y", "The y coordinate as a formula in u and v."),
    ("ParametricSpec", "", "z", "The z coordinate as a formula in u and v."),
    ("PointSpec", "", "at", "The site [u, v] in [0, 1]²."),
    ("PointSpec", "", "value", "The point [x, y, z] the surface takes there."),
    ("SpineHermite", "", "p0", "A₀(0), the spine's start."),
    ("SpineHermite", "", "p1", "A₀(1), the spine's end."),
    ("SpineHermite", "", "d0", "A₀'(0), the speed at the start."),
    ("SpineHermite", "", "d1", "A₀'(1), the speed at the end."),
    ("SplineOperatorSpec", "second-order", "a", "Coefficient of x_uu."),
    ("SplineOperatorSpec", "second-order", "b", "Coefficient of x_uv."),
    ("SplineOperatorSpec", "second-order", "c", "Coefficient of x_vv."),
    ("SplineOperatorSpec", "second-order", "d", "Coefficient of x_u."),
    ("SplineOperatorSpec", "second-order", "e", "Coefficient of x_v."),
    ("SplineOperatorSpec", "second-order", "f", "Coefficient of x."),
    ("SplineOperatorSpec", "fourth-order", "a", "Coefficient of x_uuuu."),
    ("SplineOperatorSpec", "fourth-order", "b", "Coefficient of x_uuuv."),
    ("SplineOperatorSpec", "fourth-order", "c", "Coefficient of x_uuvv."),
    ("SplineOperatorSpec", "fourth-order", "d", "Coefficient of x_uvvv."),
    ("SplineOperatorSpec", "fourth-order", "e", "Coefficient of x_vvvv."),
    ("SplineOperatorSpec", "modified-biharmonic", "a", "The parameter a of F_a."),
    ("SurfaceSpec", "cylinder", "base", "Centre of the cylinder's base circle."),
    ("SurfaceSpec", "cylinder", "axis", "Axis vector: v runs from base to base + axis."),
    ("SurfaceSpec", "cylinder", "radius", "Radius (> 0)."),
    ("SurfaceSpec", "plane", "origin", "The point at u = v = 0."),
    ("SurfaceSpec", "plane", "du", "The step along u (u ∈ [0, 1])."),
    ("SurfaceSpec", "plane", "dv", "The step along v."),
    ("SurfaceSpec", "patch", "name", "The name of the design's surface."),
    ("TransformStep", "translate", "translate", "The vector [x, y, z] added to every point."),
    ("TransformStep", "rotate", "rotate", "A rotation: axis, angle (degrees) and the point about."),
    ("TransformStep", "rotate", "axis", "Direction of the rotation axis (right-handed)."),
    ("TransformStep", "rotate", "about", "A point on the rotation axis (default the origin)."),
    ("TransformStep", "scale", "scale", "A uniform scaling: factor and the fixed point about."),
    ("TransformStep", "scale", "factor", "The factor (non-zero)."),
    ("TransformStep", "scale", "about", "The fixed point (default the origin)."),
    ("TransformStep", "dilate", "dilate", "A scaling along the axes: factors and the fixed point about."),
    ("TransformStep", "dilate", "factors", "[fx, fy, fz], each non-zero."),
    ("TransformStep", "dilate", "about", "The fixed point (default the origin)."),
    ("TrimCurveSpec", "circle", "center", "Centre [u, v]."),
    ("TrimCurveSpec", "circle", "radius", "Radius in (u, v) (> 0)."),
    ("TrimCurveSpec", "ellipse", "center", "Centre [u, v]."),
    ("TrimCurveSpec", "ellipse", "radii", "Semi-axes [a, b] (> 0)."),
    ("TrimCurveSpec", "ellipse", "angle", "Rotation of the a axis from the u axis, radians."),
    ("TrimCurveSpec", "polyline", "points", "The corners [u, v] in order."),
    ("TrimCurveSpec", "bspline", "points", "Control points [u, v], taken cyclically."),
    ("TrimCurveSpec", "bspline", "degree", "Degree (default 3)."),
];

/// Fills missing property descriptions from [`DESCRIPTIONS`]; the tag of a variant (`type`,
/// `kind`) is described by its value and the variant's own description.
fn add_descriptions(root: &mut Value) {
    let Some(Value::Object(defs)) = root.get_mut("definitions") else {
        return;
    };
    for (def, d) in defs.iter_mut() {
        let Value::Object(d) = d else { continue };
        if let Some(Value::Array(variants)) = d.get_mut("oneOf") {
            for variant in variants.iter_mut() {
                let Value::Object(variant) = variant else {
                    continue;
                };
                let summary = variant.get("description").and_then(Value::as_str).map(|t| {
                    t.split(". ")
                        .next()
                        .unwrap_or(t)
                        .trim_end_matches('.')
                        .to_string()
                });
                let Some(Value::Object(props)) = variant.get_mut("properties") else {
                    continue;
                };
                let tag = props
                    .iter()
                    .find_map(|(k, p)| {
                        let e = p.get("enum")?.as_array()?;
                        (matches!(k.as_str(), "type" | "kind") && e.len() == 1)
                            .then(|| e[0].as_str().map(str::to_string))?
                    })
                    .or_else(|| (props.len() == 1).then(|| props.keys().next().cloned())?)
                    .unwrap_or_default();
                describe(def, &tag, props, summary.as_deref());
                // Externally tagged variants: `{ rotate = { axis, … } }`.
                if let Some(Value::Object(inner)) = props.get_mut(&tag) {
                    if let Some(Value::Object(p)) = inner.get_mut("properties") {
                        describe(def, &tag, p, None);
                    }
                }
            }
        }
        if let Some(Value::Object(props)) = d.get_mut("properties") {
            describe(def, "", props, None);
        }
    }
}

fn describe(def: &str, tag: &str, props: &mut Map<String, Value>, summary: Option<&str>) {
    for (name, p) in props.iter_mut() {
        let Value::Object(p) = p else { continue };
        if p.contains_key("description") {
            continue;
        }
        let text = DESCRIPTIONS
            .iter()
            .find(|(d, t, n, _)| *d == def && *t == tag && n == name)
            .map(|(.., text)| text.to_string())
            .or_else(|| {
                (matches!(name.as_str(), "type" | "kind") && !tag.is_empty()).then(|| {
                    format!(
                        "\"{tag}\": {}.",
                        summary.unwrap_or("this kind").trim_end_matches('.')
                    )
                })
            });
        if let Some(text) = text {
            p.insert("description".into(), Value::String(text));
        }
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

/// Appends a limit JSON Schema cannot express (a product of two fields) to the description.
fn note(p: &mut Map<String, Value>, text: &str) {
    let d = p.get("description").and_then(Value::as_str).unwrap_or("");
    let joined = if d.is_empty() {
        text.to_string()
    } else {
        format!("{} {text}", d.trim_end())
    };
    p.insert("description".into(), Value::String(joined));
}

/// Most elements along each side of a `[blend]` (`bfs::MAX_ELEMENTS_PER_SIDE`; a test keeps
/// them equal, since `spec` does not import the solvers).
const BLEND_ELEMENTS_PER_SIDE: usize = 4096;
/// Most spans of a `[spline]` in each direction (`design::spline`).
const SPLINE_SPANS: usize = 1000;

/// The limits on products of two fields, which JSON Schema cannot state: in the descriptions.
const GRID_PRODUCT: &str = "Limit: nu × nv ≤ 67108864 vertices, and the grids of all patches \
     together within the memory budget of the limits table (docs/design-file.md).";
const SPLINE_PRODUCT: &str =
    "Limit: (degree + spans) in u times (degree + spans) in v ≤ 10000 control points.";
fn step_product() -> String {
    format!("Limit: steps × intervals ≤ {MAX_STEP_WORK} (about a minute of work).")
}

/// The limits, by property name (and the sibling that identifies the table where a name is
/// shared).
fn add_limits(v: &mut Value) {
    match v {
        Value::Object(m) => {
            if let Some(Value::Object(props)) = m.get_mut("properties") {
                let polyharmonic = props.contains_key("order") && props.contains_key("a");
                // The table a property sits in, from its siblings (names are shared).
                let dynamic = props.contains_key("stiffness") && props.contains_key("t_end");
                let time = props.contains_key("fps") && props.contains_key("loop");
                let blend = props.contains_key("epsilon") && props.contains_key("elements");
                let energy_a = props.contains_key("kind")
                    && props.contains_key("a")
                    && !props.contains_key("b");
                let data_point = props.contains_key("at") && props.contains_key("value");
                let derivative_curve =
                    props.contains_key("position") && props.contains_key("direction");
                let uniform_scale = props.contains_key("factor") && props.contains_key("about");
                let dilation = props.contains_key("factors") && props.contains_key("about");
                let spline = props.contains_key("spans") && props.contains_key("net");
                let props_has_alpha = props.contains_key("alpha") && props.contains_key("omega");
                let shell = props.contains_key("thickness") && props.contains_key("clamped");
                let material = props.contains_key("youngs_modulus");
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
                        // A trim ellipse's semi-axes `[a, b]`.
                        "radii" if array => {
                            if let Some(Value::Object(items)) = p.get_mut("items") {
                                set(items, "exclusiveMinimum", json!(0));
                            }
                        }
                        "u" if number => {
                            set(p, "minimum", json!(0));
                            set(p, "maximum", json!(1));
                        }
                        "derivative" if integer => set(p, "maximum", json!(39)),
                        "degree" if integer => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(30));
                        }
                        // `[spline] degree = [p, q]`, each 1 to 20.
                        "degree" if array => {
                            set(p, "maxItems", json!(2));
                            if let Some(Value::Object(items)) = p.get_mut("items") {
                                set(items, "minimum", json!(1));
                                set(items, "maximum", json!(20));
                            }
                        }
                        "steps" | "max_steps" if integer => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(MAX_STEPS));
                            note(p, &step_product());
                        }
                        "intervals" if integer => {
                            set(p, "minimum", json!(5));
                            set(p, "maximum", json!(MAX_INTERVALS));
                            note(p, &step_product());
                        }
                        "evaluations" if integer => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(MAX_EVALUATIONS));
                            note(
                                p,
                                "At least `chains` (each chain starts with one evaluation).",
                            );
                        }
                        "polish" if integer => set(p, "maximum", json!(MAX_POLISH)),
                        "chains" if integer => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(MAX_CHAINS));
                        }
                        "nu" if integer => {
                            set(p, "minimum", json!(2));
                            set(p, "maximum", json!(MAX_GRID_VERTICES / 3));
                            note(p, GRID_PRODUCT);
                        }
                        "nv" if integer => {
                            set(p, "minimum", json!(3));
                            set(p, "maximum", json!(MAX_GRID_VERTICES / 2));
                            note(p, GRID_PRODUCT);
                        }
                        "cos" | "sin" if array => set(p, "maxItems", json!(MAX_FOURIER_TERMS)),
                        // `[[spine]] wave.amplitude`: the coefficients of Ω(u).
                        "amplitude" if array && props_has_alpha => {
                            set(p, "minItems", json!(1));
                            set(p, "maxItems", json!(crate::spec::MAX_WAVE_TERMS));
                        }
                        // `[shell]` (spec::shell; checked by shell::ShellSetup).
                        "thickness" if number && shell => {
                            set(p, "exclusiveMinimum", json!(0));
                            set(p, "maximum", json!(0.1));
                        }
                        "time_limit" if number && shell => {
                            set(p, "exclusiveMinimum", json!(0));
                            set(p, "maximum", json!(86400));
                        }
                        "elements" if array && shell => {
                            set(p, "minItems", json!(2));
                            set(p, "maxItems", json!(2));
                            if let Some(Value::Object(items)) = p.get_mut("items") {
                                set(items, "minimum", json!(1));
                                set(items, "maximum", json!(1000));
                            }
                        }
                        "youngs_modulus" | "density" | "yield_stress" if number && material => {
                            set(p, "exclusiveMinimum", json!(0))
                        }
                        "poisson_ratio" if number && material => {
                            set(p, "exclusiveMinimum", json!(-1));
                            set(p, "exclusiveMaximum", json!(0.5));
                        }
                        // `[dynamic]` interpolation (dynamic::Interpolation::validate).
                        "stiffness" | "k" | "eps" | "tolerance" | "dt" | "speed" | "t_end"
                            if number && dynamic =>
                        {
                            set(p, "exclusiveMinimum", json!(0))
                        }
                        "tension" | "damping" if number && dynamic => set(p, "minimum", json!(0)),
                        "frames_every" if integer && dynamic => set(p, "minimum", json!(1)),
                        // `[time]` (spec::time): 1 frame only for a loop.
                        "frames" if integer && time => {
                            set(p, "minimum", json!(1));
                            set(p, "maximum", json!(super::time::MAX_FRAMES));
                        }
                        "fps" if number && time => set(p, "exclusiveMinimum", json!(0)),
                        // `[blend]` (design::blend, bfs).
                        "elements" if array && blend => {
                            set(p, "minItems", json!(2));
                            set(p, "maxItems", json!(2));
                            if let Some(Value::Object(items)) = p.get_mut("items") {
                                set(items, "minimum", json!(1));
                                set(items, "maximum", json!(BLEND_ELEMENTS_PER_SIDE));
                            }
                        }
                        "epsilon" if number && blend => set(p, "exclusiveMinimum", json!(0)),
                        "a" if number && energy_a => set(p, "exclusiveMinimum", json!(0)),
                        "at" if array && data_point => {
                            if let Some(Value::Object(items)) = p.get_mut("items") {
                                set(items, "minimum", json!(0));
                                set(items, "maximum", json!(1));
                            }
                        }
                        // Factors that would collapse the curve.
                        "scale" if number && derivative_curve => set(p, "not", json!({"const": 0})),
                        "factor" if number && uniform_scale => set(p, "not", json!({"const": 0})),
                        "factors" if array && dilation => {
                            if let Some(Value::Object(items)) = p.get_mut("items") {
                                set(items, "not", json!({"const": 0}));
                            }
                        }
                        // `[spline] spans = [m, n]`, each 1 to 1000.
                        "spans" if array && spline => {
                            note(p, SPLINE_PRODUCT);
                            set(p, "minItems", json!(2));
                            set(p, "maxItems", json!(2));
                            if let Some(Value::Object(items)) = p.get_mut("items") {
                                set(items, "minimum", json!(1));
                                set(items, "maximum", json!(SPLINE_SPANS));
                            }
                        }
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

    /// Every property, wherever it is, with where it is.
    fn properties<'a>(v: &'a Value, path: String, out: &mut Vec<(String, &'a Value)>) {
        match v {
            Value::Object(m) => {
                if let Some(Value::Object(props)) = m.get("properties") {
                    for (k, p) in props {
                        out.push((format!("{path}/{k}"), p));
                    }
                }
                for (k, x) in m {
                    properties(x, format!("{path}/{k}"), out);
                }
            }
            Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    properties(x, format!("{path}[{i}]"), out);
                }
            }
            _ => {}
        }
    }

    #[test]
    fn every_property_has_a_description() {
        let schema = schema_value();
        let mut all = Vec::new();
        properties(&schema, String::new(), &mut all);
        assert!(all.len() > 250, "{}", all.len());
        let missing: Vec<&String> = all
            .iter()
            .filter(|(_, p)| {
                p.get("description")
                    .and_then(Value::as_str)
                    .is_none_or(|d| d.trim().is_empty())
            })
            .map(|(path, _)| path)
            .collect();
        assert!(
            missing.is_empty(),
            "{} without a description: {missing:#?}",
            missing.len()
        );
        // Every row of the table is used (a renamed field would leave its text behind).
        let text = schema_value().to_string();
        let unused: Vec<_> = DESCRIPTIONS
            .iter()
            .filter(|(_, _, _, desc)| !text.contains(&serde_json::to_string(desc).unwrap()))
            .map(|(d, t, n, _)| format!("{d} {t} {n}"))
            .collect();
        assert!(unused.is_empty(), "unused rows: {unused:#?}");
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
    fn the_solvers_bound_copied_here_is_the_solvers() {
        assert_eq!(BLEND_ELEMENTS_PER_SIDE, crate::bfs::MAX_ELEMENTS_PER_SIDE);
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
        // Where a radius is checked (not the curve table's list of keys, which only names it
        // with a description).
        v.retain(|p| p.len() > 1);
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
            v.retain(|p| p.len() > 1);
            assert!(!v.is_empty(), "{name}");
            assert!(v.iter().all(|p| get(p, key) == value), "{name}: {v:?}");
        }
        // Products of two fields, stated where JSON Schema cannot check them.
        for (name, text) in [
            ("nu", MAX_GRID_VERTICES.to_string()),
            ("nv", MAX_GRID_VERTICES.to_string()),
            ("steps", MAX_STEP_WORK.to_string()),
            ("intervals", MAX_STEP_WORK.to_string()),
            ("spans", "10000 control points".to_string()),
        ] {
            let mut v = Vec::new();
            find(&s, name, &mut v);
            assert!(!v.is_empty(), "{name}");
            for p in v {
                let d = get(p, "description");
                assert!(d.as_str().is_some_and(|d| d.contains(&text)), "{name}: {d}");
            }
        }
    }
}
