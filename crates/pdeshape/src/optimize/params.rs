//! Design parameters in the book's notation (§7.5): `c_kP_i` with `c` a curve, `P` the kind of
//! change (`T` translation, `R` rotation, `D` dilation) and `i` the axis; the smoothing parameter
//! `a`; and `c_T`, the amplitude of the control-point offsets of a B-spline curve (Eq. 7.6).
//! A parameter vector acts by editing the [`DesignSpec`] (transform steps appended to the named
//! curve, `a` replaced, control points moved), so the design is rebuilt exactly as a design file
//! with those edits would be.

use crate::curve::Domain;
use crate::design::build_curves;
use crate::spec::{
    key_path, CurveKind, CurveSpec, DesignSpec, OperatorSpec, OptimizeSpec, ParameterSpec,
    TransformStep, V3,
};
use crate::{Error, Result, Vec3};
use std::collections::BTreeMap;

/// What a parameter changes.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamKind {
    /// `c_kT_i`: translation of the curve along axis `i` (0, 1, 2 for x, y, z).
    Translate { curve: String, axis: usize },
    /// `c_kR_i`: rotation of the curve by the value (radians) about the axis `i` through the
    /// curve's centroid.
    Rotate { curve: String, axis: usize },
    /// `c_kD_i`: dilation of the curve by the value along axis `i` about its centroid.
    Dilate { curve: String, axis: usize },
    /// The smoothing parameter `a` of every polyharmonic operator of the design.
    Smoothing,
    /// `c_T`: the control point `c_j` of a B-spline curve moves by `(−1)^j c_T n_j`, `n_j` the
    /// unit normal of the control polygon at `c_j` in the `xy` plane, pointing away from the
    /// polygon's centroid (§7.5.1, Fig. 7.5: alternate points out and in make the ridges).
    ControlOffset { curve: String },
}

/// One design parameter with its bounds.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// The name as written (`d1Dx`, `a`, `d1cT`).
    pub name: String,
    pub kind: ParamKind,
    pub min: f64,
    pub max: f64,
    pub initial: f64,
}

/// The parameters of a design, ready to act on its spec.
#[derive(Clone, Debug)]
pub struct Parameters {
    pub list: Vec<Parameter>,
    /// Centroid of every curve that is rotated or dilated (the fixed point of those maps).
    centroids: BTreeMap<String, Vec3>,
    /// Unit offset direction `(−1)^j n_j` of every control point of the `cT` curves.
    offsets: BTreeMap<String, Vec<Vec3>>,
}

fn axis_of(c: char) -> Option<usize> {
    match c {
        'x' => Some(0),
        'y' => Some(1),
        'z' => Some(2),
        _ => None,
    }
}

/// Reads a parameter name: `a`, `<curve>cT`, or `<curve><T|R|D><x|y|z>`.
fn parse_name(name: &str, spec: &DesignSpec) -> Result<ParamKind> {
    let known = |curve: &str| -> Result<String> {
        if spec.curves.contains_key(curve) {
            Ok(curve.to_string())
        } else {
            let names: Vec<String> = spec.curves.keys().map(|k| key_path(k)).collect();
            Err(Error::invalid(format!(
                "'{name}' refers to the curve '{curve}', which is not in [curves] (known: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            )))
        }
    };
    if name == "a" {
        return Ok(ParamKind::Smoothing);
    }
    if let Some(curve) = name.strip_suffix("cT") {
        if !curve.is_empty() {
            return Ok(ParamKind::ControlOffset {
                curve: known(curve)?,
            });
        }
    }
    let chars: Vec<char> = name.chars().collect();
    if chars.len() >= 3 {
        let (kind, axis) = (chars[chars.len() - 2], chars[chars.len() - 1]);
        if let Some(axis) = axis_of(axis) {
            let curve: String = chars[..chars.len() - 2].iter().collect();
            match kind {
                'T' => {
                    return Ok(ParamKind::Translate {
                        curve: known(&curve)?,
                        axis,
                    })
                }
                'R' => {
                    return Ok(ParamKind::Rotate {
                        curve: known(&curve)?,
                        axis,
                    })
                }
                'D' => {
                    return Ok(ParamKind::Dilate {
                        curve: known(&curve)?,
                        axis,
                    })
                }
                _ => {}
            }
        }
    }
    Err(Error::invalid(format!(
        "unknown parameter '{name}': expected 'a', '<curve>cT', or '<curve>' followed by T \
         (translation), R (rotation) or D (dilation) and an axis x, y or z, e.g. 'd1Dx'"
    )))
}

/// The operator's `a` if it is polyharmonic.
fn poly_a(op: &Option<OperatorSpec>) -> Option<f64> {
    match op {
        None => Some(1.0),
        Some(OperatorSpec::Polyharmonic { a, .. }) => Some(*a),
        Some(_) => None,
    }
}

/// Whether the design's top-level operator is used by some patch.
fn top_level_used(spec: &DesignSpec) -> bool {
    match &spec.patches {
        None => true,
        Some(ps) => ps.iter().any(|p| p.operator.is_none()),
    }
}

/// The design's own `a`: the top-level operator's if some patch uses it, else the first patch
/// override's; `None` if no polyharmonic operator is used.
fn design_a(spec: &DesignSpec) -> Option<f64> {
    if top_level_used(spec) {
        if let Some(a) = poly_a(&spec.operator) {
            return Some(a);
        }
    }
    spec.patches
        .iter()
        .flatten()
        .filter(|p| p.operator.is_some())
        .find_map(|p| poly_a(&p.operator))
}

/// Mean point of a curve over its domain: the mean term `a₀` of its exact Fourier series where
/// it has one, else 512 samples of the periodic domain or the midpoint rule on an open interval.
/// Coordinates below 10⁻¹³ of the largest are rounding noise and set to 0.
fn centroid(curve: &dyn crate::curve::Curve) -> Vec3 {
    let mut c = curve
        .fourier()
        .map_or_else(|| sampled_mean(curve), |f| f.a0);
    let big = c.amax();
    for x in c.iter_mut() {
        if x.abs() < 1e-13 * big {
            *x = 0.0;
        }
    }
    c
}

fn sampled_mean(curve: &dyn crate::curve::Curve) -> Vec3 {
    const S: usize = 512;
    let (t0, t1, offset) = match curve.domain() {
        Domain::Periodic => (0.0, crate::TAU, 0.0),
        Domain::Interval(a, b) => (a, b, 0.5),
    };
    let mut sum = Vec3::zeros();
    for k in 0..S {
        let t = t0 + (t1 - t0) * (k as f64 + offset) / S as f64;
        sum += curve.point(t);
    }
    sum / S as f64
}

/// `(−1)^j n_j` for the control points of a B-spline (see [`ParamKind::ControlOffset`]).
fn control_offsets(control: &[V3], periodic: bool, place: &str) -> Result<Vec<Vec3>> {
    let pts: Vec<Vec3> = control.iter().map(|c| Vec3::new(c[0], c[1], 0.0)).collect();
    let n = pts.len();
    let centre = pts.iter().sum::<Vec3>() / n as f64;
    let mut out = Vec::with_capacity(n);
    for j in 0..n {
        let (prev, next) = if periodic {
            (pts[(j + n - 1) % n], pts[(j + 1) % n])
        } else {
            (pts[j.saturating_sub(1)], pts[(j + 1).min(n - 1)])
        };
        let t = next - prev;
        let mut normal = Vec3::new(t.y, -t.x, 0.0);
        let len = normal.norm();
        if len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(Error::invalid(format!(
                "the control polygon has no normal in the xy plane at control point {j}"
            ))
            .at(place));
        }
        normal /= len;
        if normal.dot(&(pts[j] - centre)) < 0.0 {
            normal = -normal;
        }
        let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
        out.push(normal * sign);
    }
    Ok(out)
}

impl Parameters {
    /// Reads and checks the parameters of `[optimize]`: names (curves must exist; `cT` only on
    /// B-splines; `a` only with a polyharmonic operator), bounds `min < max`, finite, dilations
    /// and `a` bounded away from 0, the initial value inside the bounds, no name twice. Errors
    /// name their place, `optimize.parameters[i].<key>`.
    pub fn new(spec: &DesignSpec, opt: &OptimizeSpec) -> Result<Parameters> {
        if opt.parameters.is_empty() {
            return Err(
                Error::invalid("at least one parameter is needed").at("optimize.parameters")
            );
        }
        let mut list = Vec::new();
        let mut centroids = BTreeMap::new();
        let mut offsets = BTreeMap::new();
        let mut curves = None;
        for (i, p) in opt.parameters.iter().enumerate() {
            let place = format!("optimize.parameters[{i}]");
            list.push(Self::one(spec, p, &place)?);
            if list[..i].iter().any(|q| q.name == p.name) {
                return Err(
                    Error::invalid(format!("the parameter '{}' is given twice", p.name))
                        .at(&format!("{place}.name")),
                );
            }
            match &list[i].kind {
                ParamKind::Rotate { curve, .. } | ParamKind::Dilate { curve, .. }
                    if !centroids.contains_key(curve) =>
                {
                    if curves.is_none() {
                        curves = Some(build_curves(spec)?);
                    }
                    let built = curves.as_ref().and_then(|cs| {
                        cs.iter()
                            .find(|c| &c.name == curve)
                            .map(|c| c.curve.clone())
                    });
                    if let Some(c) = built {
                        centroids.insert(curve.clone(), centroid(c.as_ref()));
                    }
                }
                ParamKind::ControlOffset { curve } => {
                    if let Some(CurveSpec {
                        kind:
                            CurveKind::BSpline {
                                control, periodic, ..
                            },
                        ..
                    }) = spec.curves.get(curve)
                    {
                        offsets.insert(
                            curve.clone(),
                            control_offsets(control, *periodic, &format!("{place}.name"))?,
                        );
                    }
                }
                _ => {}
            }
        }
        Ok(Parameters {
            list,
            centroids,
            offsets,
        })
    }

    fn one(spec: &DesignSpec, p: &ParameterSpec, place: &str) -> Result<Parameter> {
        let kind = parse_name(&p.name, spec).map_err(|e| e.at(&format!("{place}.name")))?;
        for (key, x) in [("min", p.min), ("max", p.max)] {
            if !x.is_finite() {
                return Err(Error::invalid(format!("must be finite (got {x})"))
                    .at(&format!("{place}.{key}")));
            }
        }
        if p.min >= p.max {
            return Err(Error::invalid(format!(
                "must be greater than min = {} (got {})",
                p.min, p.max
            ))
            .at(&format!("{place}.max")));
        }
        match &kind {
            ParamKind::Dilate { .. } if p.min <= 0.0 && p.max >= 0.0 => {
                return Err(Error::invalid(format!(
                    "a dilation's range must not contain 0 (got [{}, {}])",
                    p.min, p.max
                ))
                .at(&format!("{place}.min")))
            }
            ParamKind::Smoothing if p.min <= 0.0 => {
                return Err(Error::invalid(format!(
                    "the smoothing parameter a must stay positive (got min = {})",
                    p.min
                ))
                .at(&format!("{place}.min")))
            }
            ParamKind::ControlOffset { curve }
                if !matches!(
                    spec.curves.get(curve).map(|c| &c.kind),
                    Some(CurveKind::BSpline { .. })
                ) =>
            {
                return Err(Error::invalid(format!(
                    "'{}' needs a bspline curve, but '{curve}' is not one",
                    p.name
                ))
                .at(&format!("{place}.name")));
            }
            _ => {}
        }
        let neutral = match &kind {
            ParamKind::Dilate { .. } => 1.0,
            ParamKind::Smoothing => design_a(spec).ok_or_else(|| {
                Error::invalid(
                    "'a' needs a polyharmonic operator, and the design uses none".to_string(),
                )
                .at(&format!("{place}.name"))
            })?,
            _ => 0.0,
        };
        let initial = p.initial.unwrap_or(neutral);
        if !(p.min..=p.max).contains(&initial) {
            let key = if p.initial.is_some() {
                "initial"
            } else {
                "min"
            };
            return Err(Error::invalid(format!(
                "the initial value {initial} lies outside [min, max] = [{}, {}]",
                p.min, p.max
            ))
            .at(&format!("{place}.{key}")));
        }
        Ok(Parameter {
            name: p.name.clone(),
            kind,
            min: p.min,
            max: p.max,
            initial,
        })
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Whether there are none (never, once built).
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The initial values.
    pub fn initial(&self) -> Vec<f64> {
        self.list.iter().map(|p| p.initial).collect()
    }

    /// The bounds `(min, max)` of every parameter.
    pub fn bounds(&self) -> Vec<(f64, f64)> {
        self.list.iter().map(|p| (p.min, p.max)).collect()
    }

    /// The edits of `x` grouped per curve: `(dilation, rotation, translation)` with neutral
    /// entries where no parameter acts, plus which kinds are present.
    fn per_curve(&self, x: &[f64]) -> BTreeMap<String, CurveEdit> {
        let mut edits: BTreeMap<String, CurveEdit> = BTreeMap::new();
        for (p, &v) in self.list.iter().zip(x) {
            match &p.kind {
                ParamKind::Translate { curve, axis } => {
                    let e = edits.entry(curve.clone()).or_default();
                    e.translate.get_or_insert([0.0; 3])[*axis] = v;
                }
                ParamKind::Rotate { curve, axis } => {
                    let e = edits.entry(curve.clone()).or_default();
                    e.rotate[*axis] = Some(v);
                }
                ParamKind::Dilate { curve, axis } => {
                    let e = edits.entry(curve.clone()).or_default();
                    e.dilate.get_or_insert([1.0; 3])[*axis] = v;
                }
                ParamKind::ControlOffset { curve } => {
                    edits.entry(curve.clone()).or_default().offset = Some(v);
                }
                ParamKind::Smoothing => {}
            }
        }
        edits
    }

    /// The transform steps the parameters append to `curve`: the dilation `diag(D_x, D_y, D_z)`
    /// about the centroid, then the rotations about the x, y and z axes through the centroid
    /// (radians in the parameters, degrees in the file), then the translation `(T_x, T_y, T_z)`.
    fn steps(&self, curve: &str, e: &CurveEdit) -> Vec<TransformStep> {
        let c = self
            .centroids
            .get(curve)
            .copied()
            .unwrap_or_else(Vec3::zeros);
        let about = [c.x, c.y, c.z];
        let mut steps = Vec::new();
        if let Some(factors) = e.dilate {
            steps.push(TransformStep::Dilate { factors, about });
        }
        for (axis, angle) in e.rotate.iter().enumerate() {
            if let Some(angle) = angle {
                let mut unit = [0.0; 3];
                unit[axis] = 1.0;
                steps.push(TransformStep::Rotate {
                    axis: unit,
                    angle: angle.to_degrees(),
                    about,
                });
            }
        }
        if let Some(t) = e.translate {
            steps.push(TransformStep::Translate(t));
        }
        steps
    }

    /// The control points of a `cT` curve with the offsets of amplitude `amp` applied.
    fn moved_control(&self, curve: &str, control: &[V3], amp: f64) -> Vec<V3> {
        let dirs = &self.offsets[curve];
        control
            .iter()
            .zip(dirs)
            .map(|(c, d)| [c[0] + amp * d.x, c[1] + amp * d.y, c[2] + amp * d.z])
            .collect()
    }

    /// The design with the parameter values `x` applied (see the module documentation). `x` has
    /// one value per parameter, in the order of `[optimize].parameters`.
    pub fn apply(&self, base: &DesignSpec, x: &[f64]) -> DesignSpec {
        let mut spec = base.clone();
        for (curve, e) in self.per_curve(x) {
            let steps = self.steps(&curve, &e);
            if let Some(c) = spec.curves.get_mut(&curve) {
                if let (Some(amp), CurveKind::BSpline { control, .. }) = (e.offset, &mut c.kind) {
                    *control = self.moved_control(&curve, control, amp);
                }
                c.transform.extend(steps);
            }
        }
        if let Some(a) = self.smoothing(x) {
            set_a(&mut spec, a);
        }
        spec
    }

    fn smoothing(&self, x: &[f64]) -> Option<f64> {
        self.list
            .iter()
            .zip(x)
            .find(|(p, _)| p.kind == ParamKind::Smoothing)
            .map(|(_, v)| *v)
    }

    /// The design file's text with the parameter values `x` applied, keeping the file's layout
    /// and comments: transform steps appended to `curves.<name>.transform`, `a` written into
    /// the polyharmonic operators, moved control points written into `control`.
    pub fn apply_to_text(&self, text: &str, base: &DesignSpec, x: &[f64]) -> Result<String> {
        use toml_edit::{value, Array, DocumentMut, InlineTable, Item, Value};
        let mut doc: DocumentMut = text
            .parse()
            .map_err(|e: toml_edit::TomlError| Error::invalid(e.message().to_string()))?;
        let num_array = |v: &[f64; 3]| -> Value {
            let mut a = Array::new();
            for x in v {
                a.push(*x);
            }
            Value::Array(a)
        };
        for (curve, e) in self.per_curve(x) {
            let place = format!("curves.{}", key_path(&curve));
            let table = doc
                .get_mut("curves")
                .and_then(|c| c.get_mut(&curve))
                .and_then(|c| c.as_table_like_mut())
                .ok_or_else(|| Error::invalid("cannot edit this curve's table").at(&place))?;
            if let (
                Some(amp),
                Some(CurveSpec {
                    kind: CurveKind::BSpline { control, .. },
                    ..
                }),
            ) = (e.offset, base.curves.get(&curve))
            {
                let mut arr = Array::new();
                for c in self.moved_control(&curve, control, amp) {
                    arr.push(num_array(&c));
                }
                table.insert("control", value(arr));
            }
            let steps: Vec<InlineTable> = self
                .steps(&curve, &e)
                .iter()
                .map(|s| {
                    let mut inner = InlineTable::new();
                    let mut outer = InlineTable::new();
                    match s {
                        TransformStep::Translate(t) => {
                            outer.insert("translate", num_array(t));
                        }
                        TransformStep::Rotate { axis, angle, about } => {
                            inner.insert("axis", num_array(axis));
                            inner.insert("angle", Value::from(*angle));
                            inner.insert("about", num_array(about));
                            outer.insert("rotate", Value::InlineTable(inner));
                        }
                        TransformStep::Dilate { factors, about } => {
                            inner.insert("factors", num_array(factors));
                            inner.insert("about", num_array(about));
                            outer.insert("dilate", Value::InlineTable(inner));
                        }
                        TransformStep::Scale { factor, about } => {
                            inner.insert("factor", Value::from(*factor));
                            inner.insert("about", num_array(about));
                            outer.insert("scale", Value::InlineTable(inner));
                        }
                    }
                    outer
                })
                .collect();
            match table.get_mut("transform") {
                Some(Item::Value(Value::Array(arr))) => {
                    for s in steps {
                        arr.push(Value::InlineTable(s));
                    }
                }
                Some(Item::ArrayOfTables(arr)) => {
                    for s in steps {
                        arr.push(s.into_table());
                    }
                }
                Some(_) => {
                    return Err(Error::invalid("expected an array of steps")
                        .at(&format!("{place}.transform")))
                }
                None => {
                    let mut arr = Array::new();
                    for s in steps {
                        arr.push(Value::InlineTable(s));
                    }
                    table.insert("transform", value(arr));
                }
            }
        }
        if let Some(a) = self.smoothing(x) {
            if top_level_used(base) {
                if base.operator.is_none() {
                    let mut t = InlineTable::new();
                    t.insert("kind", Value::from("polyharmonic"));
                    t.insert("a", Value::from(a));
                    doc.insert("operator", value(t));
                } else if poly_a(&base.operator).is_some() {
                    if let Some(op) = doc.get_mut("operator").and_then(|o| o.as_table_like_mut()) {
                        op.insert("a", value(a));
                    }
                }
            }
            if let Some(patches) = &base.patches {
                for (i, p) in patches.iter().enumerate() {
                    if p.operator.is_none() || poly_a(&p.operator).is_none() {
                        continue;
                    }
                    match doc.get_mut("patches") {
                        Some(Item::ArrayOfTables(arr)) => {
                            if let Some(op) = arr
                                .get_mut(i)
                                .and_then(|t| t.get_mut("operator"))
                                .and_then(|o| o.as_table_like_mut())
                            {
                                op.insert("a", value(a));
                            }
                        }
                        Some(Item::Value(Value::Array(arr))) => {
                            if let Some(op) = arr
                                .get_mut(i)
                                .and_then(|v| v.as_inline_table_mut())
                                .and_then(|t| t.get_mut("operator"))
                                .and_then(|o| o.as_inline_table_mut())
                            {
                                op.insert("a", Value::from(a));
                            }
                        }
                        _ => {}
                    }
                }
            }
        }
        Ok(doc.to_string())
    }
}

/// Sets `a` in every polyharmonic operator that some patch uses.
fn set_a(spec: &mut DesignSpec, a: f64) {
    if top_level_used(spec) {
        match &mut spec.operator {
            None => spec.operator = Some(OperatorSpec::Polyharmonic { order: 2, a }),
            Some(OperatorSpec::Polyharmonic { a: old, .. }) => *old = a,
            Some(_) => {}
        }
    }
    for p in spec.patches.iter_mut().flatten() {
        if let Some(OperatorSpec::Polyharmonic { a: old, .. }) = &mut p.operator {
            *old = a;
        }
    }
}

/// The edits of one curve.
#[derive(Clone, Debug, Default)]
struct CurveEdit {
    translate: Option<[f64; 3]>,
    rotate: [Option<f64>; 3],
    dilate: Option<[f64; 3]>,
    offset: Option<f64>,
}
