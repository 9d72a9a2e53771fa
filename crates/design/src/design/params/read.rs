//! Reading and checking one `[[parameters]]` entry: its kind and the keys it takes, its bounds,
//! its value (given, else the neutral one).

use super::kind::ParamKind;
use crate::spec::{
    key_path, AxisSpec, CurveKind, CurveSpec, DesignParameterSpec, DesignSpec, DriveKind,
};
use crate::{Error, Result, Vec3};

pub(super) fn unknown_curve_error(curve: &str, spec: &DesignSpec, what: &str) -> Error {
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

/// Reads one entry's kind and checks which keys it takes (static checks only).
pub(super) fn read_kind(
    spec: &DesignSpec,
    p: &DesignParameterSpec,
    place: &str,
) -> Result<ParamKind> {
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
pub(super) fn check_bounds(p: &DesignParameterSpec, kind: &ParamKind, place: &str) -> Result<()> {
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
pub(super) fn value_of(p: &DesignParameterSpec, neutral: f64, place: &str) -> Result<f64> {
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
