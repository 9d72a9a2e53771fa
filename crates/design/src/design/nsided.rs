//! Builds the `[[nsided]]` patches: sides from the design's curves, ribbons from its surfaces.

use super::curves::CurveBuilder;
use super::solved::{DesignSurface, SurfaceKind};
use crate::curve::Domain;
use crate::curve::SharedCurve;
use crate::nsided::{shape_tensor, NSidedOptions, NSidedPatch, Ribbon, Side};
use crate::spec::{NSidedSpec, OperatorSpec};
use crate::surface::{ClosestOptions, ClosestPointIndex, Surface};
use crate::{Error, Result, Vec3};
use std::sync::Arc;

/// Chebyshev–Lobatto points on `[0, 1]` at which a neighbour's normal is sampled; the
/// patch's ribbon interpolates these samples (the check reports the angle to the neighbour's
/// own normals between them).
pub(super) const NORMAL_SAMPLES: usize = 128;

/// How far a side may lie from the surface it is tangent to, relative to the patch's size.
const ON_SURFACE: f64 = 1e-7;

/// Builds every `[[nsided]]` patch and appends its surfaces (one for four sides, else one per
/// piece) to `surfaces`; each may be tangent to any surface before it.
pub(crate) fn build_nsided(
    specs: &[NSidedSpec],
    builder: &mut CurveBuilder<'_>,
    surfaces: &mut Vec<DesignSurface>,
) -> Result<()> {
    for (i, spec) in specs.iter().enumerate() {
        let place = format!("nsided[{i}]");
        let patch = build_one(spec, builder, surfaces, &place).map_err(|e| e.at(&place))?;
        let operator = OperatorSpec::Polyharmonic {
            order: spec.order,
            a: spec.a,
        };
        push_surfaces(&Arc::new(patch), &spec.name, &place, &operator, surfaces)?;
    }
    Ok(())
}

/// Appends the surfaces of an n-sided patch: `name` for four sides, else its pieces
/// `name.0`, `name.1`, … (refused if a name is taken, at `place.name`).
fn push_surfaces(
    patch: &Arc<NSidedPatch>,
    name: &str,
    place: &str,
    operator: &OperatorSpec,
    surfaces: &mut Vec<DesignSurface>,
) -> Result<()> {
    let mut new = Vec::new();
    push_pieces(patch, name, place, operator, &mut new);
    append_unique(surfaces, new, place)
}

/// The surfaces of an n-sided patch, as [`push_surfaces`] names them, appended to `out`
/// without a check of their names.
pub(super) fn push_pieces(
    patch: &Arc<NSidedPatch>,
    name: &str,
    place: &str,
    operator: &OperatorSpec,
    out: &mut Vec<DesignSurface>,
) {
    let pieces = patch.surfaces();
    let many = pieces.len() > 1;
    for (k, piece) in pieces.into_iter().enumerate() {
        let name = if many {
            format!("{name}.{k}")
        } else {
            name.to_string()
        };
        out.push(DesignSurface {
            name,
            place: place.to_string(),
            kind: SurfaceKind::NSided(Arc::new(piece)),
            operator: Some(operator.clone()),
            conditions: Vec::new(),
        });
    }
}

/// Appends `new` to `surfaces`, refused at `place.name` where a name is taken (by a surface
/// before, or twice among `new`): one set of the names, not a search per surface (a fitted
/// patchwork has thousands of pieces).
pub(super) fn append_unique(
    surfaces: &mut Vec<DesignSurface>,
    new: Vec<DesignSurface>,
    place: &str,
) -> Result<()> {
    let mut names: std::collections::HashSet<&str> =
        surfaces.iter().map(|s| s.name.as_str()).collect();
    for s in &new {
        if !names.insert(s.name.as_str()) {
            return Err(
                Error::not_unique(format!("the surface name '{}' is used twice", s.name))
                    .at(&format!("{place}.name")),
            );
        }
    }
    surfaces.extend(new);
    Ok(())
}

/// The surface `name` among those built before the table that asks for it (a refusal lists
/// them).
pub(super) fn find_surface<'a>(
    surfaces: &'a [DesignSurface],
    name: &str,
) -> Result<&'a DesignSurface> {
    surfaces.iter().find(|x| x.name == name).ok_or_else(|| {
        let names: Vec<&str> = surfaces.iter().map(|x| x.name.as_str()).collect();
        Error::invalid(format!(
            "no surface '{name}' before this table (there are: {})",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        ))
    })
}

/// The parameter interval of a side or network curve: `range`, else the curve's domain
/// (refused for a periodic curve, which has no ends).
pub(super) fn interval(curve: &SharedCurve, range: Option<[f64; 2]>) -> Result<[f64; 2]> {
    match (range, curve.domain()) {
        (Some(r), _) => Ok(r),
        (None, Domain::Interval(a, b)) => Ok([a, b]),
        (None, Domain::Periodic) => Err(Error::invalid(
            "a periodic curve needs `range = [t0, t1]`: it has no ends",
        )),
    }
}

fn build_one(
    spec: &NSidedSpec,
    builder: &mut CurveBuilder<'_>,
    surfaces: &[DesignSurface],
    place: &str,
) -> Result<NSidedPatch> {
    let mut sides = Vec::with_capacity(spec.sides.len());
    for (j, s) in spec.sides.iter().enumerate() {
        let at = format!("{place}.sides[{j}]");
        let curve = builder.reference(&s.curve, &format!("{at}.curve"))?;
        let [t0, t1] = interval(&curve, s.range).map_err(|e| e.at(&format!("sides[{j}]")))?;
        let (t0, t1) = if s.reverse { (t1, t0) } else { (t0, t1) };
        if s.g2 && s.tangent_to.is_none() {
            return Err(Error::invalid(
                "`g2` needs `tangent_to`: the surface whose curvature the patch takes (or give \
                 `derivative` and `second_derivative`)",
            )
            .at(&format!("sides[{j}].g2")));
        }
        if s.second_derivative.is_some() && s.derivative.is_none() {
            return Err(Error::invalid(
                "`second_derivative` needs `derivative`: the first cross derivative it goes with",
            )
            .at(&format!("sides[{j}].second_derivative")));
        }
        let ribbon = match (&s.tangent_to, &s.derivative) {
            (Some(_), Some(_)) => {
                return Err(
                    Error::invalid("give `tangent_to` or `derivative`, not both")
                        .at(&format!("sides[{j}]")),
                )
            }
            (None, None) => Ribbon::Position,
            (None, Some(d)) => {
                let first = builder.reference(d, &format!("{at}.derivative"))?;
                match &s.second_derivative {
                    Some(w) => Ribbon::Derivatives {
                        first,
                        second: builder.reference(w, &format!("{at}.second_derivative"))?,
                        t0,
                        t1,
                    },
                    None => Ribbon::Derivative {
                        curve: first,
                        t0,
                        t1,
                    },
                }
            }
            (Some(name), None) if s.g2 => {
                let target = find_surface(surfaces, name)
                    .map_err(|e| e.at(&format!("sides[{j}].tangent_to")))?;
                let side = Side::position(curve.clone(), t0, t1);
                let (normals, shapes) = sample_shapes(&side, target.surface())
                    .map_err(|e| e.at(&format!("sides[{j}].tangent_to")))?;
                let normals = Arc::new(normals);
                Ribbon::Curvature {
                    normal: Arc::new(move |s| lobatto_interpolate(&normals, s)),
                    shape: Arc::new(move |s| {
                        // Row by row: the interpolant of each row of the tensors.
                        let rows: [Vec3; 3] = [0, 1, 2].map(|r| lobatto_interpolate(&shapes[r], s));
                        nalgebra::Matrix3::from_rows(&[
                            rows[0].transpose(),
                            rows[1].transpose(),
                            rows[2].transpose(),
                        ])
                    }),
                }
            }
            (Some(name), None) => {
                let target = find_surface(surfaces, name)
                    .map_err(|e| e.at(&format!("sides[{j}].tangent_to")))?;
                let side = Side::position(curve.clone(), t0, t1);
                let normals = sample_normals(&side, target.surface())
                    .map_err(|e| e.at(&format!("sides[{j}].tangent_to")))?;
                Ribbon::TangentPlane(Arc::new(move |s| lobatto_interpolate(&normals, s)))
            }
        };
        sides.push(Side {
            curve,
            t0,
            t1,
            ribbon,
        });
    }
    let options = NSidedOptions {
        order: spec.order,
        a: spec.a,
        degree: spec.degree,
        gap_tolerance: spec.gap_tolerance,
    };
    NSidedPatch::solve(sides, &options)
}

/// The neighbour's unit normals at the side's Chebyshev–Lobatto points (by closest point).
pub(super) fn sample_normals(side: &Side, surface: &dyn Surface) -> Result<Vec<Vec3>> {
    let index = ClosestPointIndex::new(surface, &ClosestOptions::default());
    let mut points = Vec::with_capacity(NORMAL_SAMPLES + 1);
    let mut size: f64 = 0.0;
    for j in 0..=NORMAL_SAMPLES {
        let s = lobatto(j);
        let p = side.point(s);
        points.push(p);
        size = size.max((p - points[0]).norm());
    }
    let mut normals = Vec::with_capacity(points.len());
    for (j, p) in points.iter().enumerate() {
        let Some(c) = index.closest(*p) else {
            return Err(Error::invalid(format!(
                "no point of the surface was found near the side at s = {:.4}",
                lobatto(j)
            )));
        };
        if c.distance > ON_SURFACE * size.max(1e-300) {
            return Err(Error::invalid(format!(
                "the side does not lie on the surface: at s = {:.4} it is {:.3e} away",
                lobatto(j),
                c.distance
            )));
        }
        let n = surface.partials(c.u, c.v).normal_or_none().ok_or_else(|| {
            Error::invalid(format!(
                "the surface has no normal where the side meets it (s = {:.4})",
                lobatto(j)
            ))
        })?;
        normals.push(n);
    }
    // One orientation along the side (a closest point on a seam may come from either side).
    for j in 1..normals.len() {
        if normals[j].dot(&normals[j - 1]) < 0.0 {
            normals[j] = -normals[j];
        }
    }
    Ok(normals)
}

/// The neighbour's unit normals and second fundamental forms (as tensors, the rows of each
/// in one list per row) at the side's Chebyshev–Lobatto points, by closest point: the data of
/// a G2 ribbon. The forms are taken against the normals as oriented by [`sample_normals`].
pub(super) fn sample_shapes(
    side: &Side,
    surface: &dyn Surface,
) -> Result<(Vec<Vec3>, [Vec<Vec3>; 3])> {
    let normals = sample_normals(side, surface)?;
    let index = ClosestPointIndex::new(surface, &ClosestOptions::default());
    let mut rows = [Vec::new(), Vec::new(), Vec::new()];
    for (j, n) in normals.iter().enumerate() {
        let s = lobatto(j);
        let c = index.closest(side.point(s)).ok_or_else(|| {
            Error::invalid(format!(
                "no point of the surface was found near the side at s = {s:.4}"
            ))
        })?;
        let (m, shape) = shape_tensor(&surface.partials(c.u, c.v)).ok_or_else(|| {
            Error::invalid(format!(
                "the surface has no curvature where the side meets it (s = {s:.4})"
            ))
        })?;
        let shape = if m.dot(n) < 0.0 { -shape } else { shape };
        for (r, row) in rows.iter_mut().enumerate() {
            row.push(shape.row(r).transpose());
        }
    }
    Ok((normals, rows))
}

/// The `j`-th Chebyshev–Lobatto point of [`NORMAL_SAMPLES`] on `[0, 1]`, increasing.
fn lobatto(j: usize) -> f64 {
    0.5 * (1.0 - (std::f64::consts::PI * j as f64 / NORMAL_SAMPLES as f64).cos())
}

/// The polynomial through `values` at the Chebyshev–Lobatto points, at `s` (barycentric
/// formula).
pub(super) fn lobatto_interpolate(values: &[Vec3], s: f64) -> Vec3 {
    let n = values.len() - 1;
    let mut num = Vec3::zeros();
    let mut den = 0.0;
    for (j, v) in values.iter().enumerate() {
        let x = lobatto(j);
        let d = s - x;
        if d == 0.0 {
            return *v;
        }
        let mut w = if j % 2 == 0 { 1.0 } else { -1.0 };
        if j == 0 || j == n {
            w *= 0.5;
        }
        num += v * (w / d);
        den += w / d;
    }
    num / den
}
