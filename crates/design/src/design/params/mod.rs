//! Design parameters (`[[parameters]]`): named, bounded values that act on the design's curves
//! and operators. The book's parameters on a curve (§6.1): the position parameter `X₁` (the
//! curve's point at `v₁` dragged, the curve following), the angling parameter `θ` (the curve
//! turned about a line through `X₁`), the scaling parameter `s = |X₁X₂|` (the curve resized
//! about `X₁`), and the `v = 0` point (§6.4, `v_origin`); and those of §7.5: translation,
//! rotation and dilation about the curve's centroid (`c_kT_i`, `c_kR_i`, `c_kD_i`), the
//! control-point offsets `c_T` and the smoothing parameter `a`.
//!
//! A parameter acts by editing the design as a file would: transform steps appended to the
//! driven curves, `v_origin` or `a` replaced, control points moved. [`resolve_parameters`] turns
//! a design with parameters into the design without them that [`super::compile`] solves; the
//! optimiser (`optimize::Parameters`) drives the same entries by name, so there is one
//! mechanism. A parameter at its neutral value leaves the design exactly as written.
//!
//! Order: the §7.5 kinds act first, grouped per curve as the optimiser's names always did
//! (dilation, rotations about x, y, z, translation, all about the centroid of the curve as
//! written); then the §6.1 and §6.4 kinds act in the order they are written, each on the curves
//! as the ones before it left them (so `X₁` is found on the curve as already moved).

use super::curves::{CurveBuilder, CurveCache};
use crate::curve::{Curve, Domain};
use crate::spec::{
    key_path, AxisSpec, CurveKind, CurveSpec, DesignParameterSpec, DesignSpec, DriveKind,
    OperatorSpec, TransformStep, V3,
};
use crate::{Error, Result, Vec3};
use std::borrow::Cow;
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
    /// The position parameter `X₁` (§6.1): the curve translated so that coordinate `axis` of
    /// its point at `v1` becomes the value.
    Position { curve: String, v1: f64, axis: usize },
    /// The angling parameter `θ` (§6.1): the curve rotated by the value (radians, right-handed)
    /// about the line through its point at `v1` along the unit vector `axis`.
    Angle { curve: String, v1: f64, axis: Vec3 },
    /// The scaling parameter `s` (§6.1): the curve scaled uniformly about its point `X₁` at
    /// `v1` so that the distance to its point `X₂` at `v2` becomes the value.
    Scale { curve: String, v1: f64, v2: f64 },
    /// The `v = 0` point (§6.4): the curve's `v_origin` becomes the value (radians).
    VOrigin { curve: String },
}

impl ParamKind {
    /// The driven curve, if any.
    pub fn curve(&self) -> Option<&str> {
        match self {
            ParamKind::Smoothing => None,
            ParamKind::Translate { curve, .. }
            | ParamKind::Rotate { curve, .. }
            | ParamKind::Dilate { curve, .. }
            | ParamKind::ControlOffset { curve }
            | ParamKind::Position { curve, .. }
            | ParamKind::Angle { curve, .. }
            | ParamKind::Scale { curve, .. }
            | ParamKind::VOrigin { curve } => Some(curve),
        }
    }

    /// Whether it is one of §7.5's kinds (acting before the others, grouped per curve).
    fn is_book_7_5(&self) -> bool {
        matches!(
            self,
            ParamKind::Translate { .. }
                | ParamKind::Rotate { .. }
                | ParamKind::Dilate { .. }
                | ParamKind::Smoothing
                | ParamKind::ControlOffset { .. }
        )
    }

    /// What it drives, in words (`check` prints it).
    pub fn describe(&self) -> String {
        const AXES: [&str; 3] = ["x", "y", "z"];
        match self {
            ParamKind::Translate { curve, axis } => {
                format!("translation of curve '{curve}' along {}", AXES[*axis])
            }
            ParamKind::Rotate { curve, axis } => format!(
                "rotation (rad) of curve '{curve}' about the {} axis through its centroid",
                AXES[*axis]
            ),
            ParamKind::Dilate { curve, axis } => format!(
                "dilation of curve '{curve}' along {} about its centroid",
                AXES[*axis]
            ),
            ParamKind::Smoothing => "the smoothing parameter a".to_string(),
            ParamKind::ControlOffset { curve } => {
                format!("control-point offsets c_T of curve '{curve}'")
            }
            ParamKind::Position { curve, v1, axis } => format!(
                "position: {} of X1, the point of curve '{curve}' at v = {v1}",
                AXES[*axis]
            ),
            ParamKind::Angle { curve, v1, axis } => format!(
                "angle (rad) of curve '{curve}' about [{}, {}, {}] through X1 (v = {v1})",
                axis.x, axis.y, axis.z
            ),
            ParamKind::Scale { curve, v1, v2 } => {
                format!("scale: |X1X2| of curve '{curve}' (v = {v1} and {v2}), about X1")
            }
            ParamKind::VOrigin { curve } => format!("v = 0 point (v_origin) of curve '{curve}'"),
        }
    }
}

/// A `[[parameters]]` entry read and checked, with its neutral value (the value that leaves
/// the design as written) and its value (given, else the neutral one).
#[derive(Clone, Debug, PartialEq)]
pub struct DesignParameter {
    pub name: String,
    /// Where it is in the file: `parameters[i]`.
    pub place: String,
    pub kind: ParamKind,
    /// Further curves that follow the same map.
    pub with: Vec<String>,
    pub min: f64,
    pub max: f64,
    pub neutral: f64,
    pub value: f64,
}

fn axis_of(c: char) -> Option<usize> {
    match c {
        'x' => Some(0),
        'y' => Some(1),
        'z' => Some(2),
        _ => None,
    }
}

fn unknown_curve_error(curve: &str, spec: &DesignSpec, what: &str) -> Error {
    let names: Vec<String> = spec.curves.keys().map(|k| key_path(k)).collect();
    Error::invalid(format!(
        "{what}the curve '{curve}', which is not in [curves] (known: {})",
        if names.is_empty() {
            "none".to_string()
        } else {
            names.join(", ")
        }
    ))
}

/// Reads a parameter name in the book's notation (§7.5): `a`, `<curve>cT`, or
/// `<curve><T|R|D><x|y|z>`.
pub fn parse_book_name(name: &str, spec: &DesignSpec) -> Result<ParamKind> {
    let known = |curve: &str| -> Result<String> {
        if spec.curves.contains_key(curve) {
            Ok(curve.to_string())
        } else {
            Err(unknown_curve_error(
                curve,
                spec,
                &format!("'{name}' refers to "),
            ))
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
        "unknown parameter '{name}': expected the name of a [[parameters]] entry, 'a', \
         '<curve>cT', or '<curve>' followed by T (translation), R (rotation) or D (dilation) \
         and an axis x, y or z, e.g. 'd1Dx'"
    )))
}

/// The operator's `a` if it is polyharmonic.
pub fn poly_a(op: &Option<OperatorSpec>) -> Option<f64> {
    match op {
        None => Some(1.0),
        Some(OperatorSpec::Polyharmonic { a, .. }) => Some(*a),
        Some(_) => None,
    }
}

/// Whether the design's top-level operator is used by some patch.
pub fn top_level_used(spec: &DesignSpec) -> bool {
    match &spec.patches {
        None => true,
        Some(ps) => ps.iter().any(|p| p.operator.is_none()),
    }
}

/// The design's own `a`: the top-level operator's if some patch uses it, else the first patch
/// override's; `None` if no polyharmonic operator is used.
pub fn design_a(spec: &DesignSpec) -> Option<f64> {
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

/// Sets `a` in every polyharmonic operator that some patch uses.
pub(crate) fn set_a(spec: &mut DesignSpec, a: f64) {
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

/// Mean point of a curve over its domain: the mean term `a₀` of its exact Fourier series where
/// it has one, else 512 samples of the periodic domain or the midpoint rule on an open interval.
/// Coordinates below 10⁻¹³ of the largest are rounding noise and set to 0.
fn centroid(curve: &dyn Curve) -> Vec3 {
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

fn sampled_mean(curve: &dyn Curve) -> Vec3 {
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

/// The edits of one curve by §7.5's kinds.
#[derive(Clone, Debug, Default)]
pub struct CurveEdit {
    translate: Option<[f64; 3]>,
    rotate: [Option<f64>; 3],
    dilate: Option<[f64; 3]>,
    pub offset: Option<f64>,
}

/// What §7.5's kinds need from the design as written: the centroid of every rotated or dilated
/// curve (the fixed point of those maps) and the offset directions of every `c_T` curve.
#[derive(Clone, Debug, Default)]
pub struct BookEdits {
    centroids: BTreeMap<String, Vec3>,
    offsets: BTreeMap<String, Vec<Vec3>>,
}

impl BookEdits {
    /// Prepares the kinds `kinds` (with the place of each, for errors) on `spec`.
    pub fn new<'a>(
        spec: &DesignSpec,
        kinds: impl Iterator<Item = (&'a ParamKind, String)>,
    ) -> Result<BookEdits> {
        let mut e = BookEdits::default();
        let mut curves = None;
        for (kind, place) in kinds {
            match kind {
                ParamKind::Rotate { curve, .. } | ParamKind::Dilate { curve, .. }
                    if !e.centroids.contains_key(curve) =>
                {
                    if curves.is_none() {
                        // The curves as written: without the `[[parameters]]`.
                        let mut bare = spec.clone();
                        bare.parameters.clear();
                        curves = Some(super::build_curves(&bare)?);
                    }
                    let built = curves.as_ref().and_then(|cs| {
                        cs.iter()
                            .find(|c| &c.name == curve)
                            .map(|c| c.curve.clone())
                    });
                    if let Some(c) = built {
                        e.centroids.insert(curve.clone(), centroid(c.as_ref()));
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
                        e.offsets
                            .insert(curve.clone(), control_offsets(control, *periodic, &place)?);
                    }
                }
                _ => {}
            }
        }
        Ok(e)
    }

    /// The edits of `(kind, value)` pairs grouped per curve.
    pub fn per_curve<'a>(
        pairs: impl Iterator<Item = (&'a ParamKind, f64)>,
    ) -> BTreeMap<String, CurveEdit> {
        let mut edits: BTreeMap<String, CurveEdit> = BTreeMap::new();
        for (kind, v) in pairs {
            match kind {
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
                _ => {}
            }
        }
        edits
    }

    /// The transform steps appended to `curve`: the dilation `diag(D_x, D_y, D_z)` about the
    /// centroid, then the rotations about the x, y and z axes through the centroid (radians in
    /// the parameters, degrees in the file), then the translation `(T_x, T_y, T_z)`.
    pub fn steps(&self, curve: &str, e: &CurveEdit) -> Vec<TransformStep> {
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

    /// The control points of a `c_T` curve with the offsets of amplitude `amp` applied.
    pub fn moved_control(&self, curve: &str, control: &[V3], amp: f64) -> Vec<V3> {
        match self.offsets.get(curve) {
            Some(dirs) => control
                .iter()
                .zip(dirs)
                .map(|(c, d)| [c[0] + amp * d.x, c[1] + amp * d.y, c[2] + amp * d.z])
                .collect(),
            None => control.to_vec(),
        }
    }

    /// Applies `(kind, value)` pairs of §7.5's kinds to `spec`.
    pub fn apply<'a>(
        &self,
        spec: &mut DesignSpec,
        pairs: impl Iterator<Item = (&'a ParamKind, f64)> + Clone,
    ) {
        for (curve, e) in Self::per_curve(pairs.clone()) {
            let steps = self.steps(&curve, &e);
            if let Some(c) = spec.curves.get_mut(&curve) {
                if let (Some(amp), CurveKind::BSpline { control, .. }) = (e.offset, &mut c.kind) {
                    *control = self.moved_control(&curve, control, amp);
                }
                c.transform.extend(steps);
            }
        }
        let a = pairs
            .filter(|(k, _)| **k == ParamKind::Smoothing)
            .map(|(_, v)| v)
            .last();
        if let Some(a) = a {
            set_a(spec, a);
        }
    }
}

/// The `[[parameters]]` of a design, read and checked, with their neutral values; the design
/// they do not change (its curves and operators as written) is `spec`.
pub fn design_parameters(spec: &DesignSpec) -> Result<Vec<DesignParameter>> {
    run(spec).map(|(_, list)| list)
}

/// The design with the values of its `[[parameters]]` applied and the table emptied (borrowed
/// when it has none): what [`super::compile`] solves. Errors name their place
/// (`parameters[2].v2`, …).
pub fn resolve_parameters(spec: &DesignSpec) -> Result<Cow<'_, DesignSpec>> {
    if spec.parameters.is_empty() {
        return Ok(Cow::Borrowed(spec));
    }
    run(spec).map(|(s, _)| Cow::Owned(s))
}

/// Sets the value of the parameter `name` (`None`: back to its neutral value, i.e. no `value`
/// key), checked against its bounds; returns the old value. Errors name the parameter.
pub fn set_parameter(spec: &mut DesignSpec, name: &str, value: Option<f64>) -> Result<Option<f64>> {
    let Some((i, p)) = spec
        .parameters
        .iter_mut()
        .enumerate()
        .find(|(_, p)| p.name == name)
    else {
        let names: Vec<&str> = spec.parameters.iter().map(|p| p.name.as_str()).collect();
        return Err(Error::invalid(format!(
            "the design has no parameter named '{name}' (known: {})",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        ))
        .at("parameters"));
    };
    if let Some(v) = value {
        if !(v.is_finite() && p.min <= v && v <= p.max) {
            return Err(Error::invalid(format!(
                "the value {v} of '{name}' lies outside [min, max] = [{}, {}]",
                p.min, p.max
            ))
            .at(&format!("parameters[{i}].value")));
        }
    }
    Ok(std::mem::replace(&mut p.value, value))
}

/// Reads one entry's kind and checks which keys it takes (static checks only).
fn read_kind(spec: &DesignSpec, p: &DesignParameterSpec, place: &str) -> Result<ParamKind> {
    let at = |key: &str| format!("{place}.{key}");
    let kind = p.kind;
    let word = kind.word();
    let takes_curve = kind != DriveKind::Smoothing;
    let takes_v1 = matches!(
        kind,
        DriveKind::Position | DriveKind::Angle | DriveKind::Scale
    );
    let takes_with = takes_v1 || kind == DriveKind::VOrigin;
    let takes_axis = matches!(
        kind,
        DriveKind::Position
            | DriveKind::Angle
            | DriveKind::Translate
            | DriveKind::Rotate
            | DriveKind::Dilate
    );
    let refuse = |present: bool, key: &str| -> Result<()> {
        if present {
            Err(Error::invalid(format!("a {word} parameter takes no `{key}`")).at(&at(key)))
        } else {
            Ok(())
        }
    };
    refuse(!takes_curve && p.curve.is_some(), "curve")?;
    refuse(!takes_v1 && p.v1.is_some(), "v1")?;
    refuse(kind != DriveKind::Scale && p.v2.is_some(), "v2")?;
    refuse(!takes_with && !p.with.is_empty(), "with")?;
    refuse(!takes_axis && p.axis.is_some(), "axis")?;
    refuse(kind != DriveKind::Angle && p.plane.is_some(), "plane")?;
    let need = |x: Option<f64>, key: &str| -> Result<f64> {
        match x {
            None => Err(Error::invalid(format!("a {word} parameter needs `{key}`")).at(place)),
            Some(v) if !v.is_finite() => {
                Err(Error::invalid(format!("must be finite (got {v})")).at(&at(key)))
            }
            Some(v) => Ok(v),
        }
    };
    // Curves an affine map or a v_origin can act on (not curves on patches).
    let check_curve = |name: &str, key: &str| -> Result<()> {
        match spec.curves.get(name) {
            None => Err(unknown_curve_error(name, spec, "refers to ").at(&at(key))),
            Some(CurveSpec {
                kind: CurveKind::OnPatch { .. } | CurveKind::TangentField { .. },
                ..
            }) => Err(Error::invalid(format!(
                "the curve '{name}' lies on a patch (on_patch, tangent_field): move its (u, v) \
                 path instead"
            ))
            .at(&at(key))),
            Some(_) => Ok(()),
        }
    };
    let curve = if takes_curve {
        let c = p
            .curve
            .clone()
            .ok_or_else(|| Error::invalid(format!("a {word} parameter needs `curve`")).at(place))?;
        check_curve(&c, "curve")?;
        c
    } else {
        String::new()
    };
    for (k, w) in p.with.iter().enumerate() {
        check_curve(w, &format!("with[{k}]"))?;
        if *w == curve || p.with[..k].contains(w) {
            return Err(Error::invalid(format!("the curve '{w}' is named twice"))
                .at(&at(&format!("with[{k}]"))));
        }
    }
    let coordinate = |required: bool| -> Result<usize> {
        match &p.axis {
            Some(AxisSpec::Name(a)) => Ok(a.index()),
            Some(AxisSpec::Vector(_)) => Err(Error::invalid(format!(
                "a {word} parameter takes a coordinate axis \"x\", \"y\" or \"z\""
            ))
            .at(&at("axis"))),
            None if required => Err(Error::invalid(format!(
                "a {word} parameter needs `axis` (\"x\", \"y\" or \"z\")"
            ))
            .at(place)),
            None => Ok(0),
        }
    };
    Ok(match kind {
        DriveKind::Position => ParamKind::Position {
            v1: need(p.v1, "v1")?,
            axis: coordinate(true)?,
            curve,
        },
        DriveKind::Angle => {
            let v1 = need(p.v1, "v1")?;
            let axis = match (&p.axis, p.plane) {
                (Some(_), Some(_)) => {
                    return Err(Error::invalid(
                        "give either `plane` or `axis`, not both".to_string(),
                    )
                    .at(&at("plane")))
                }
                (None, None) => {
                    return Err(Error::invalid(
                        "an angle parameter needs `plane` (\"xy\", \"xz\", \"yz\") or `axis`"
                            .to_string(),
                    )
                    .at(place))
                }
                (None, Some(plane)) => {
                    let mut a = Vec3::zeros();
                    a[plane.normal_index()] = 1.0;
                    a
                }
                (Some(AxisSpec::Name(n)), None) => {
                    let mut a = Vec3::zeros();
                    a[n.index()] = 1.0;
                    a
                }
                (Some(AxisSpec::Vector(v)), None) => {
                    let a = Vec3::new(v[0], v[1], v[2]);
                    let n = a.norm();
                    if !(n.is_finite() && n > 0.0) {
                        return Err(Error::invalid(format!(
                            "the axis must be a non-zero finite vector (got {v:?})"
                        ))
                        .at(&at("axis")));
                    }
                    a / n
                }
            };
            ParamKind::Angle { curve, v1, axis }
        }
        DriveKind::Scale => {
            let v1 = need(p.v1, "v1")?;
            let v2 = need(p.v2, "v2")?;
            if v1 == v2 {
                return Err(Error::invalid(format!(
                    "must differ from v1 = {v1}: s is the distance between the curve's points at \
                     v1 and v2"
                ))
                .at(&at("v2")));
            }
            ParamKind::Scale { curve, v1, v2 }
        }
        DriveKind::VOrigin => ParamKind::VOrigin { curve },
        DriveKind::Translate => ParamKind::Translate {
            axis: coordinate(true)?,
            curve,
        },
        DriveKind::Rotate => ParamKind::Rotate {
            axis: coordinate(true)?,
            curve,
        },
        DriveKind::Dilate => ParamKind::Dilate {
            axis: coordinate(true)?,
            curve,
        },
        DriveKind::ControlOffset => {
            if !matches!(
                spec.curves.get(&curve).map(|c| &c.kind),
                Some(CurveKind::BSpline { .. })
            ) {
                return Err(Error::invalid(format!(
                    "control_offset needs a bspline curve, but '{curve}' is not one"
                ))
                .at(&at("curve")));
            }
            ParamKind::ControlOffset { curve }
        }
        DriveKind::Smoothing => ParamKind::Smoothing,
    })
}

/// Checks bounds and the kind-specific ranges of one entry.
fn check_bounds(p: &DesignParameterSpec, kind: &ParamKind, place: &str) -> Result<()> {
    let at = |key: &str| format!("{place}.{key}");
    for (key, x) in [("min", p.min), ("max", p.max)] {
        if !x.is_finite() {
            return Err(Error::invalid(format!("must be finite (got {x})")).at(&at(key)));
        }
    }
    if p.min >= p.max {
        return Err(Error::invalid(format!(
            "must be greater than min = {} (got {})",
            p.min, p.max
        ))
        .at(&at("max")));
    }
    match kind {
        ParamKind::Dilate { .. } if p.min <= 0.0 && p.max >= 0.0 => {
            return Err(Error::invalid(format!(
                "a dilation's range must not contain 0 (got [{}, {}])",
                p.min, p.max
            ))
            .at(&at("min")))
        }
        ParamKind::Smoothing if p.min <= 0.0 => {
            return Err(Error::invalid(format!(
                "the smoothing parameter a must stay positive (got min = {})",
                p.min
            ))
            .at(&at("min")))
        }
        ParamKind::Scale { .. } if p.min <= 0.0 => {
            return Err(Error::invalid(format!(
                "the distance s = |X1X2| must stay positive (got min = {})",
                p.min
            ))
            .at(&at("min")))
        }
        _ => {}
    }
    if let Some(v) = p.value {
        if !(v.is_finite() && p.min <= v && v <= p.max) {
            return Err(Error::invalid(format!(
                "{v} lies outside [min, max] = [{}, {}]",
                p.min, p.max
            ))
            .at(&at("value")));
        }
    }
    Ok(())
}

/// The value of an entry: the given one, else the neutral one, which must lie in the bounds.
fn value_of(p: &DesignParameterSpec, neutral: f64, place: &str) -> Result<f64> {
    match p.value {
        Some(v) => Ok(v),
        None if p.min <= neutral && neutral <= p.max => Ok(neutral),
        None => Err(Error::invalid(format!(
            "the neutral value {neutral} (the design as written) lies outside [min, max] = [{}, \
             {}]: give `value` or widen the bounds",
            p.min, p.max
        ))
        .at(&format!("{place}.min"))),
    }
}

/// The curve `name` as `spec` builds it (with its dependencies).
fn build_one(spec: &DesignSpec, name: &str, place: &str) -> Result<crate::curve::SharedCurve> {
    let cache = CurveCache::default();
    let mut builder = CurveBuilder::new(&spec.curves, &cache);
    let curve = builder.named(name, place)?;
    Ok(curve)
}

/// The point of `curve` at `v`, refused outside an open curve's domain.
fn point_at(curve: &dyn Curve, v: f64, place: &str) -> Result<Vec3> {
    if let Domain::Interval(a, b) = curve.domain() {
        if !(a..=b).contains(&v) {
            return Err(
                Error::invalid(format!("{v} lies outside the curve's domain [{a}, {b}]")).at(place),
            );
        }
    }
    let p = curve.point(v);
    if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
        return Err(Error::invalid(format!("the curve's point at {v} is not finite")).at(place));
    }
    Ok(p)
}

fn v3(p: &Vec3) -> V3 {
    [p.x, p.y, p.z]
}

/// Appends `step` to the transform of `curve` and of every curve in `with`.
fn push_step(spec: &mut DesignSpec, curve: &str, with: &[String], step: TransformStep) {
    for name in std::iter::once(curve).chain(with.iter().map(String::as_str)) {
        if let Some(c) = spec.curves.get_mut(name) {
            c.transform.push(step.clone());
        }
    }
}

/// Reads, checks and applies every entry: the resolved design and the entries.
fn run(spec: &DesignSpec) -> Result<(DesignSpec, Vec<DesignParameter>)> {
    let mut kinds = Vec::with_capacity(spec.parameters.len());
    for (i, p) in spec.parameters.iter().enumerate() {
        let place = format!("parameters[{i}]");
        if p.name.trim().is_empty() {
            return Err(Error::invalid("must not be empty").at(&format!("{place}.name")));
        }
        if let Some(j) = spec.parameters[..i].iter().position(|q| q.name == p.name) {
            return Err(Error::invalid(format!(
                "the parameter '{}' is given twice (also parameters[{j}])",
                p.name
            ))
            .at(&format!("{place}.name")));
        }
        let kind = read_kind(spec, p, &place)?;
        check_bounds(p, &kind, &place)?;
        kinds.push(kind);
    }

    // §7.5's kinds, on the design as written, grouped per curve; at their neutral value they
    // leave the design as it is (no step).
    let mut out = spec.clone();
    out.parameters.clear();
    let mut list: Vec<Option<DesignParameter>> = vec![None; kinds.len()];
    let book: Vec<usize> = (0..kinds.len())
        .filter(|&i| kinds[i].is_book_7_5())
        .collect();
    if !book.is_empty() {
        let edits = BookEdits::new(
            spec,
            book.iter()
                .map(|&i| (&kinds[i], format!("parameters[{i}].curve"))),
        )?;
        let mut pairs = Vec::new();
        for &i in &book {
            let p = &spec.parameters[i];
            let place = format!("parameters[{i}]");
            let neutral = match &kinds[i] {
                ParamKind::Dilate { .. } => 1.0,
                ParamKind::Smoothing => design_a(spec).ok_or_else(|| {
                    Error::invalid(
                        "'smoothing' needs a polyharmonic operator, and the design uses none",
                    )
                    .at(&format!("{place}.kind"))
                })?,
                _ => 0.0,
            };
            let value = value_of(p, neutral, &place)?;
            if value != neutral {
                pairs.push((&kinds[i], value));
            }
            list[i] = Some(DesignParameter {
                name: p.name.clone(),
                place,
                kind: kinds[i].clone(),
                with: p.with.clone(),
                min: p.min,
                max: p.max,
                neutral,
                value,
            });
        }
        edits.apply(&mut out, pairs.iter().map(|(k, v)| (*k, *v)));
    }

    // §6.1 and §6.4, in the order written.
    for (i, kind) in kinds.iter().enumerate() {
        if kind.is_book_7_5() {
            continue;
        }
        let p = &spec.parameters[i];
        let place = format!("parameters[{i}]");
        let at = |key: &str| format!("{place}.{key}");
        let (neutral, value) = match kind {
            ParamKind::VOrigin { curve } => {
                let neutral = out.curves.get(curve).map_or(0.0, |c| c.v_origin);
                let value = value_of(p, neutral, &place)?;
                if value != neutral {
                    for name in std::iter::once(curve).chain(&p.with) {
                        if let Some(c) = out.curves.get_mut(name) {
                            c.v_origin = value;
                        }
                    }
                }
                (neutral, value)
            }
            ParamKind::Position { curve, v1, axis } => {
                let c = build_one(&out, curve, &at("curve"))?;
                let x1 = point_at(c.as_ref(), *v1, &at("v1"))?;
                let neutral = x1[*axis];
                let value = value_of(p, neutral, &place)?;
                if value != neutral {
                    let mut d = [0.0; 3];
                    d[*axis] = value - neutral;
                    push_step(&mut out, curve, &p.with, TransformStep::Translate(d));
                }
                (neutral, value)
            }
            ParamKind::Angle { curve, v1, axis } => {
                let value = value_of(p, 0.0, &place)?;
                if value != 0.0 {
                    let c = build_one(&out, curve, &at("curve"))?;
                    let x1 = point_at(c.as_ref(), *v1, &at("v1"))?;
                    let step = TransformStep::Rotate {
                        axis: v3(axis),
                        angle: value.to_degrees(),
                        about: v3(&x1),
                    };
                    push_step(&mut out, curve, &p.with, step);
                }
                (0.0, value)
            }
            ParamKind::Scale { curve, v1, v2 } => {
                let c = build_one(&out, curve, &at("curve"))?;
                let x1 = point_at(c.as_ref(), *v1, &at("v1"))?;
                let x2 = point_at(c.as_ref(), *v2, &at("v2"))?;
                let d0 = (x2 - x1).norm();
                let size = x1.amax().max(x2.amax()).max(f64::MIN_POSITIVE);
                if d0.is_nan() || d0 <= 1e-14 * size {
                    return Err(Error::invalid(format!(
                        "the curve's points at v1 = {v1} and v2 = {v2} coincide (|X1X2| = {d0:e}), \
                         so no scale makes their distance s"
                    ))
                    .at(&at("v2")));
                }
                let value = value_of(p, d0, &place)?;
                if value != d0 {
                    let step = TransformStep::Scale {
                        factor: value / d0,
                        about: v3(&x1),
                    };
                    push_step(&mut out, curve, &p.with, step);
                }
                (d0, value)
            }
            // §7.5's kinds are applied above.
            _ => continue,
        };
        list[i] = Some(DesignParameter {
            name: p.name.clone(),
            place,
            kind: kind.clone(),
            with: p.with.clone(),
            min: p.min,
            max: p.max,
            neutral,
            value,
        });
    }
    Ok((out, list.into_iter().flatten().collect()))
}
