//! The §7.5 kinds the optimiser shares: the book's names (`c_kT_i`, `c_kR_i`, `c_kD_i`, `c_T`,
//! `a`), the smoothing parameter `a` of the design's operators, and `BookEdits`, the translations,
//! rotations, dilations about a curve's centroid and control-point offsets they make.

use super::kind::ParamKind;
use super::read::unknown_curve_error;
use crate::curve::{Curve, Domain};
use crate::spec::{CurveKind, CurveSpec, DesignSpec, OperatorSpec, TransformStep, V3};
use crate::{Error, Result, Vec3};
use std::collections::BTreeMap;

fn axis_of(c: char) -> Option<usize> {
    match c {
        'x' => Some(0),
        'y' => Some(1),
        'z' => Some(2),
        _ => None,
    }
}

/// Every name of the book's notation that [`parse_book_name`] reads for `spec`: `a`, then for
/// each curve (in name order) `<curve>T<x|y|z>`, `<curve>R<x|y|z>`, `<curve>D<x|y|z>`, and
/// `<curve>cT` for a B-spline curve.
pub fn book_names(spec: &DesignSpec) -> Vec<String> {
    let mut out = vec!["a".to_string()];
    for (name, c) in &spec.curves {
        for kind in ['T', 'R', 'D'] {
            for axis in ['x', 'y', 'z'] {
                out.push(format!("{name}{kind}{axis}"));
            }
        }
        if matches!(c.kind, CurveKind::BSpline { .. }) {
            out.push(format!("{name}cT"));
        }
    }
    out
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
        "unknown parameter '{}': expected the name of a [[parameters]] entry, 'a', \
         '<curve>cT', or '<curve>' followed by T (translation), R (rotation) or D (dilation) \
         and an axis x, y or z, e.g. 'd1Dx'",
        crate::spec::words::user_text(name)
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
pub(super) fn centroid(curve: &dyn Curve) -> Vec3 {
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
                        curves = Some(crate::design::build_curves(&bare)?);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every listed name reads back, each curve has its nine names, and a B-spline its `cT`.
    #[test]
    fn every_book_name_listed_is_read() {
        let spec = crate::spec::parse_design(
            "[curves.rim]\ntype = \"circle\"\ncenter = [0, 0, 1]\nradius = 1\n\
             [curves.net]\ntype = \"bspline\"\ndegree = 3\n\
             control = [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]]\n",
        )
        .unwrap();
        let names = book_names(&spec);
        assert_eq!(names.len(), 1 + 9 + 10, "{names:?}");
        assert!(names.contains(&"netcT".to_string()));
        assert!(!names.contains(&"rimcT".to_string()));
        for n in &names {
            parse_book_name(n, &spec).unwrap_or_else(|e| panic!("{n}: {e}"));
        }
    }
}
