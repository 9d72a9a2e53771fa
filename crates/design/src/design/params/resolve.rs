//! Applying the entries: the §7.5 kinds first, per curve, then the §6.1 and §6.4 kinds as
//! transform steps and `v_origin`s in the order they are written.

use super::book::{design_a, BookEdits};
use super::kind::{DesignParameter, ParamKind};
use super::read::{check_bounds, read_kind, value_of};
use crate::curve::{Curve, Domain};
use crate::design::curves::{CurveBuilder, CurveCache};
use crate::spec::{DesignSpec, TransformStep, V3};
use crate::{Error, Result, Vec3};

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
pub(super) fn run(spec: &DesignSpec) -> Result<(DesignSpec, Vec<DesignParameter>)> {
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
