//! `[[nurbs]]` reference surfaces: (rational) tensor-product B-spline nets, checked and built.
//!
//! The surface is the quotient `X = A / W` of two B-spline surfaces of the geometry layer on the
//! same knots, `A = Σ N_i M_j w_ij P_ij` and `W = Σ N_i M_j w_ij` (the latter with the weights as
//! the first coordinate of its control points), so the basis and its exact derivatives are the
//! geometry layer's ([`BSplineSurface`]); the partials of the quotient follow from Leibniz's rule
//! on `A = W X`: `X_u = (A_u − W_u X)/W`, `X_uu = (A_uu − 2 W_u X_u − W_uu X)/W`,
//! `X_uv = (A_uv − W_u X_v − W_v X_u − W_uv X)/W`, and likewise in `v`.

use crate::spec::NurbsSpec;
use crate::spline::BSplineSurface;
use crate::surface::{Partials, Surface, VDomain};
use crate::{Error, Result, Vec3};

/// The highest degree a `[[nurbs]]` table may have in either direction.
const MAX_DEGREE: usize = 30;

/// A (rational) tensor-product B-spline surface: `u ∈ [0, 1]` runs linearly over the domain of
/// `knots_u`, `v` over that of `knots_v` in its own knot parameter (as for [`BSplineSurface`]).
#[derive(Clone, Debug, PartialEq)]
pub struct NurbsSurface {
    /// `A`: the weighted control points (the points themselves when there are no weights).
    numerator: BSplineSurface,
    /// `W`: the weights as the first coordinate, `None` for a polynomial surface.
    weights: Option<BSplineSurface>,
}

impl NurbsSurface {
    /// The surface of a `[[nurbs]]` table; errors name the field at `place` (`nurbs[2]`).
    pub fn from_spec(spec: &NurbsSpec, place: &str) -> Result<Self> {
        let at = |field: &str| format!("{place}.{field}");
        for (k, p) in spec.degree.iter().enumerate() {
            if !(1..=MAX_DEGREE).contains(p) {
                return Err(
                    Error::invalid(format!("must be 1 to {MAX_DEGREE}, got {p}"))
                        .at(&at(&format!("degree[{k}]"))),
                );
            }
        }
        let rows = spec.control.len();
        let cols = spec.control.first().map_or(0, Vec::len);
        if rows == 0 || cols == 0 {
            return Err(
                Error::invalid("needs at least one row of control points").at(&at("control"))
            );
        }
        for (i, r) in spec.control.iter().enumerate() {
            if r.len() != cols {
                return Err(Error::invalid(format!(
                    "has {} points; row 0 has {cols} (every row the same length)",
                    r.len()
                ))
                .at(&at(&format!("control[{i}]"))));
            }
        }
        let [p, q] = spec.degree;
        for (field, knots, n, d) in [
            ("knots_u", &spec.knots_u, rows, p),
            ("knots_v", &spec.knots_v, cols, q),
        ] {
            if knots.len() != n + d + 1 {
                return Err(Error::invalid(format!(
                    "has {} values; {n} control points of degree {d} need {}",
                    knots.len(),
                    n + d + 1
                ))
                .at(&at(field)));
            }
        }
        let weights = match &spec.weights {
            None => None,
            Some(w) => {
                if w.len() != rows {
                    return Err(Error::invalid(format!(
                        "has {} rows; control has {rows}",
                        w.len()
                    ))
                    .at(&at("weights")));
                }
                for (i, r) in w.iter().enumerate() {
                    if r.len() != cols {
                        return Err(Error::invalid(format!(
                            "has {} weights; the control rows have {cols} points",
                            r.len()
                        ))
                        .at(&at(&format!("weights[{i}]"))));
                    }
                    if let Some(j) = r.iter().position(|x| !(x.is_finite() && *x > 0.0)) {
                        return Err(Error::invalid(format!(
                            "must be a positive number, got {}",
                            r[j]
                        ))
                        .at(&at(&format!("weights[{i}][{j}]"))));
                    }
                }
                Some(w)
            }
        };
        let weight = |i: usize, j: usize| weights.map_or(1.0, |w| w[i][j]);
        let mut points = Vec::with_capacity(rows * cols);
        let mut ws = Vec::with_capacity(rows * cols);
        for (i, r) in spec.control.iter().enumerate() {
            for (j, c) in r.iter().enumerate() {
                let w = weight(i, j);
                points.push(Vec3::new(c[0], c[1], c[2]) * w);
                ws.push(Vec3::new(w, 0.0, 0.0));
            }
        }
        let net = |control: Vec<Vec3>| {
            BSplineSurface::new(
                spec.degree,
                spec.knots_u.clone(),
                spec.knots_v.clone(),
                control,
            )
        };
        let numerator = net(points).map_err(|e| e.at(place))?;
        let weights = match weights {
            Some(_) => Some(net(ws).map_err(|e| e.at(place))?),
            None => None,
        };
        Ok(NurbsSurface { numerator, weights })
    }

    /// The domain `[[u0, u1], [v0, v1]]` in knot parameters.
    pub fn knot_domain(&self) -> [[f64; 2]; 2] {
        self.numerator.domain()
    }

    /// True when the surface has weights (a NURBS, not a polynomial B-spline surface).
    pub fn is_rational(&self) -> bool {
        self.weights.is_some()
    }
}

/// Checks the names of the `[[nurbs]]` tables: non-empty, unique among themselves and against
/// `taken` (the names of the PDE patches and the `[[parametric]]` surfaces).
pub(crate) fn validate_nurbs_names(specs: &[NurbsSpec], taken: &[String]) -> Result<()> {
    for (i, s) in specs.iter().enumerate() {
        let place = format!("nurbs[{i}].name");
        if s.name.trim().is_empty() {
            return Err(Error::invalid("must not be empty").at(&place));
        }
        if let Some(j) = specs[..i].iter().position(|q| q.name == s.name) {
            return Err(
                Error::invalid(format!("'{}' is already the name of nurbs[{j}]", s.name))
                    .at(&place),
            );
        }
        if taken.contains(&s.name) {
            return Err(Error::invalid(format!(
                "'{}' is already the name of another surface",
                s.name
            ))
            .at(&place));
        }
    }
    Ok(())
}

/// The partials of `X = A / W` from those of `A` and of `W` (its first coordinate).
fn quotient(a: &Partials, w: &Partials) -> Partials {
    let (w0, wu, wv) = (w.x.x, w.xu.x, w.xv.x);
    let (wuu, wuv, wvv) = (w.xuu.x, w.xuv.x, w.xvv.x);
    let x = a.x / w0;
    let xu = (a.xu - x * wu) / w0;
    let xv = (a.xv - x * wv) / w0;
    Partials {
        x,
        xu,
        xv,
        xuu: (a.xuu - xu * (2.0 * wu) - x * wuu) / w0,
        xuv: (a.xuv - xu * wv - xv * wu - x * wuv) / w0,
        xvv: (a.xvv - xv * (2.0 * wv) - x * wvv) / w0,
    }
}

impl Surface for NurbsSurface {
    fn v_domain(&self) -> VDomain {
        self.numerator.v_domain()
    }

    fn breaks(&self) -> (Vec<f64>, Vec<f64>) {
        let [[u0, u1], [v0, v1]] = self.knot_domain();
        let inner = |knots: &[f64], a: f64, b: f64, map: &dyn Fn(f64) -> f64| {
            let mut out: Vec<f64> = knots
                .iter()
                .filter(|k| **k > a && **k < b)
                .map(|k| map(*k))
                .collect();
            out.dedup();
            out
        };
        (
            inner(self.numerator.knots_u(), u0, u1, &|k| (k - u0) / (u1 - u0)),
            inner(self.numerator.knots_v(), v0, v1, &|k| k),
        )
    }

    fn partials(&self, u: f64, v: f64) -> Partials {
        let a = self.numerator.partials(u, v);
        match &self.weights {
            None => a,
            Some(w) => quotient(&a, &w.partials(u, v)),
        }
    }
}

impl crate::surface::SurfaceNearest for NurbsSurface {}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quarter cylinder of radius `r` about the z axis, `z ∈ [0, 2]`, as a rational
    /// quadratic × linear net (knots in `u` on `[0, 3]`, in `v` on `[-1, 1]`).
    fn quarter_cylinder(r: f64) -> NurbsSpec {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        NurbsSpec {
            name: "c".into(),
            degree: [2, 1],
            knots_u: vec![0.0, 0.0, 0.0, 3.0, 3.0, 3.0],
            knots_v: vec![-1.0, -1.0, 1.0, 1.0],
            control: vec![
                vec![[r, 0.0, 0.0], [r, 0.0, 2.0]],
                vec![[r, r, 0.0], [r, r, 2.0]],
                vec![[0.0, r, 0.0], [0.0, r, 2.0]],
            ],
            weights: Some(vec![vec![1.0, 1.0], vec![h, h], vec![1.0, 1.0]]),
        }
    }

    #[test]
    fn a_rational_quarter_circle_net_is_the_cylinder_with_exact_partials() {
        let s = NurbsSurface::from_spec(&quarter_cylinder(0.5), "nurbs[0]").unwrap();
        assert!(s.is_rational());
        for i in 0..=6 {
            for j in 0..=6 {
                let (u, v) = (i as f64 / 6.0, -1.0 + 2.0 * j as f64 / 6.0);
                let p = s.partials(u, v);
                assert!((p.x.x.hypot(p.x.y) - 0.5).abs() < 1e-15, "{p:?}");
                assert!((p.x.z - (v + 1.0)).abs() < 1e-15);
                // Against central differences of the surface's own points and first partials.
                let e = 1e-5;
                let fd = |f: &dyn Fn(f64, f64) -> Vec3, du: f64, dv: f64| {
                    (f(u + du, v + dv) - f(u - du, v - dv)) / (2.0 * e)
                };
                let x = |u, v| s.partials(u, v).x;
                let xu = |u, v| s.partials(u, v).xu;
                let xv = |u, v| s.partials(u, v).xv;
                for (exact, approx) in [
                    (p.xu, fd(&x, e, 0.0)),
                    (p.xv, fd(&x, 0.0, e)),
                    (p.xuu, fd(&xu, e, 0.0)),
                    (p.xuv, fd(&xu, 0.0, e)),
                    (p.xuv, fd(&xv, e, 0.0)),
                    (p.xvv, fd(&xv, 0.0, e)),
                ] {
                    assert!((exact - approx).norm() < 1e-8, "{exact:?} vs {approx:?}");
                }
                // The normal curvature across the rulings is the circle's, 1/r.
                let n = p.normal();
                let k = -p.xuu.dot(&n) / p.xu.norm_squared();
                assert!((k.abs() - 2.0).abs() < 1e-12, "{k}");
            }
        }
    }

    #[test]
    fn bad_nets_are_refused_at_their_field() {
        let good = quarter_cylinder(1.0);
        let place = |f: &dyn Fn(&mut NurbsSpec)| {
            let mut s = good.clone();
            f(&mut s);
            let e = NurbsSurface::from_spec(&s, "nurbs[3]").unwrap_err();
            format!("{}: {}", e.place(), e.message())
        };
        assert!(place(&|s| s.degree = [0, 1]).starts_with("nurbs[3].degree[0]:"));
        assert!(place(&|s| {
            s.control[1].pop();
        })
        .starts_with("nurbs[3].control[1]:"));
        assert!(place(&|s| {
            s.knots_u.pop();
        })
        .starts_with("nurbs[3].knots_u:"));
        assert!(place(&|s| s.weights.as_mut().unwrap()[2][1] = 0.0)
            .starts_with("nurbs[3].weights[2][1]:"));
        assert!(place(&|s| {
            s.weights.as_mut().unwrap().pop();
        })
        .starts_with("nurbs[3].weights:"));
        assert!(place(&|s| s.knots_v = vec![1.0, 1.0, -1.0, -1.0]).starts_with("nurbs[3]"));
        assert!(place(&|s| s.control[0][0][2] = f64::NAN).starts_with("nurbs[3]"));
        assert!(place(&|s| s.control.clear()).starts_with("nurbs[3].control:"));
    }
}
