//! The [`Surface`] trait: every solver returns something that evaluates anywhere with exact
//! partial derivatives, so tessellation, export, analysis and pictures work on all of them alike.
//!
//! Beside it, small abilities: the parameter domain ([`Surface::parameter_domain`],
//! [`ParameterDomain`]), the spine of a surface periodic in `v` ([`Spine`],
//! [`Surface::as_spine`]) and the closest point to a point in space ([`closest_point`],
//! [`ClosestPointIndex`], [`SurfaceNearest`]).

use crate::Vec3;

mod closest;
mod domain;
mod parametric;
mod spine;
pub use closest::{closest_point, Closest, ClosestOptions, ClosestPointIndex, SurfaceNearest};
pub use domain::{Interval, ParameterDomain};
pub use parametric::{FourthPartials, ParametricSurface};
pub use spine::Spine;

/// `X` and its partial derivatives up to second order at one `(u, v)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Partials {
    /// Position `X(u, v)`.
    pub x: Vec3,
    /// First partial derivative `∂X/∂u`.
    pub xu: Vec3,
    /// First partial derivative `∂X/∂v`.
    pub xv: Vec3,
    /// Second partial derivative `∂²X/∂u²`.
    pub xuu: Vec3,
    /// Second partial derivative `∂²X/∂u∂v`.
    pub xuv: Vec3,
    /// Second partial derivative `∂²X/∂v²`.
    pub xvv: Vec3,
}

/// The one rule for where a surface's normal degenerates: `|X_u × X_v| ≤ 10⁻¹⁰ (|X_u|² + |X_v|²)`,
/// i.e. the cross product is rounding noise next to the derivatives themselves (at a pole `X_v`
/// is zero up to rounding and its direction is meaningless). `cross` is `|X_u × X_v|`, `size` is
/// `|X_u|² + |X_v|²` (both scale alike, so any common scaling of `X_u`, `X_v` may be applied
/// first); NaN counts as degenerate. Every place that decides whether `X_u × X_v` gives the
/// normal (normals, row evaluators, curvature) asks this function.
#[inline(always)]
pub fn normal_degenerates(cross: f64, size: f64) -> bool {
    cross.partial_cmp(&(1e-10 * size)) != Some(std::cmp::Ordering::Greater)
}

impl Partials {
    /// Unit normal `X_u × X_v / |X_u × X_v|`. Where that degenerates ([`normal_degenerates`]: a
    /// pole, a position curve shrunk to a point, so `X_v = 0`), the limit normal `X_u × X_uv` is
    /// used, and `X_uv × X_v` where `X_u` vanishes; zero if all of these vanish.
    pub fn normal(&self) -> Vec3 {
        self.normal_or_none().unwrap_or_else(Vec3::zeros)
    }

    /// [`Partials::normal`], or `None` where it does not exist (`X_u × X_v` degenerates and so do
    /// both pole limits).
    pub fn normal_or_none(&self) -> Option<Vec3> {
        // One common scale, so huge or tiny coordinates neither overflow nor underflow and the
        // relative sizes of the derivatives are kept.
        let m = self.xu.amax().max(self.xv.amax()).max(self.xuv.amax());
        let (xu, xv, xuv) = if m > 0.0 && m.is_finite() {
            (self.xu / m, self.xv / m, self.xuv / m)
        } else {
            (self.xu, self.xv, self.xuv)
        };
        let n = xu.cross(&xv);
        let len = n.norm();
        if !normal_degenerates(len, xu.norm_squared() + xv.norm_squared()) {
            return Some(n / len);
        }
        [xu.cross(&xuv), xuv.cross(&xv)].into_iter().find_map(|m| {
            let s = m.norm();
            (s > 1e-300).then(|| m / s)
        })
    }
}

/// The unit normal `X_u × X_v / |X_u × X_v|` from the first partials alone, both scaled by the
/// larger's largest component first (so huge or tiny surfaces neither overflow nor underflow);
/// `None` where it degenerates ([`normal_degenerates`]), where [`Partials::normal`] takes the
/// limit from the second partials. What the row evaluators that skip second partials compute.
pub fn first_order_normal(xu: Vec3, xv: Vec3) -> Option<Vec3> {
    let m = xu.amax().max(xv.amax());
    let (a, b) = if m > 0.0 && m.is_finite() {
        (xu / m, xv / m)
    } else {
        (xu, xv)
    };
    let n = a.cross(&b);
    let len = n.norm();
    (!normal_degenerates(len, a.norm_squared() + b.norm_squared())).then(|| n / len)
}

/// The parameter domain in `v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VDomain {
    /// Periodic with period 2π.
    Periodic,
    /// `[start, end]`.
    Interval(f64, f64),
}

/// A parametric surface `X(u, v)` with `u` in [`Surface::u_range`] (`[0, 1]` unless the surface
/// says otherwise) and `v` in [`Surface::v_domain`].
pub trait Surface: Send + Sync {
    /// The `v` domain.
    fn v_domain(&self) -> VDomain;

    /// The interval `u` runs over: `[0, 1]` unless the surface overrides it. Surfaces whose own
    /// parameter lives on another range (knot domains, partitions, formula domains) may report
    /// it here instead of mapping it onto `[0, 1]`; `partials` then takes `u` in that range.
    fn u_range(&self) -> Interval {
        Interval::UNIT
    }

    /// True if the surface is closed in `u`: the sides `u = start` and `u = end` of
    /// [`Surface::u_range`] are the same curve and the surface continues across it (a cylinder
    /// parametrised by angle in `u`). False unless the surface overrides it.
    fn u_periodic(&self) -> bool {
        false
    }

    /// The whole parameter domain: [`Surface::u_range`], [`Surface::u_periodic`] and
    /// [`Surface::v_domain`] together.
    fn parameter_domain(&self) -> ParameterDomain {
        ParameterDomain {
            u: self.u_range(),
            u_periodic: self.u_periodic(),
            v: self.v_domain(),
        }
    }

    /// Interior parameter values where the surface is only finitely smooth (the knots of a
    /// spline): `u` values inside [`Surface::u_range`] and `v` values inside an interval
    /// [`Surface::v_domain`]. Quadrature panels end there, so that its rules converge at their
    /// full order on each smooth piece. None unless the surface overrides it.
    fn breaks(&self) -> (Vec<f64>, Vec<f64>) {
        (Vec::new(), Vec::new())
    }

    /// The surface's spine `A₀(u)` if it has one (see [`Spine`]); `None` unless the surface
    /// overrides it.
    fn as_spine(&self) -> Option<&dyn Spine> {
        None
    }

    /// `X` and exact partials up to second order.
    fn partials(&self, u: f64, v: f64) -> Partials;

    /// `X(u, v)`.
    fn point(&self, u: f64, v: f64) -> Vec3 {
        self.partials(u, v).x
    }

    /// `[X, X_u, X_v]`: the first three of [`Surface::partials`] (the same values), for
    /// callers that need no second derivatives; surfaces whose second derivatives cost much
    /// override it.
    fn first_partials(&self, u: f64, v: f64) -> [Vec3; 3] {
        let p = self.partials(u, v);
        [p.x, p.xu, p.xv]
    }

    /// An evaluator for whole rows of a tensor grid with the given `v` values. Surfaces with
    /// structure (the PDE patch: a sum of products) override this with per-column tables so a
    /// grid is a few small matrix products.
    fn row_evaluator<'a>(&'a self, vs: &'a [f64]) -> Box<dyn RowEvaluator + 'a> {
        Box::new(PointwiseRows { surface: self, vs })
    }

    /// An evaluator of `X` and its partials up to second order along whole rows `u = const`
    /// at the given `v` values (for quadrature and analysis). Surfaces with structure override
    /// this with per-column tables; the values are those of [`Surface::partials`] up to rounding.
    fn partials_rows<'a>(&'a self, vs: &'a [f64]) -> Box<dyn PartialsRows + 'a> {
        Box::new(PointwisePartials { surface: self, vs })
    }

    /// An evaluator of `[X, X_u, X_v]` along whole rows `u = const` at the given `v` values: by
    /// default the first three of [`Surface::partials_rows`] (whose per-column tables serve
    /// structured surfaces); surfaces whose second derivatives cost much override it with
    /// [`Surface::first_partials`] point by point.
    fn first_partials_rows<'a>(&'a self, vs: &'a [f64]) -> Box<dyn FirstPartialsRows + 'a> {
        Box::new(FirstOfPartials(self.partials_rows(vs)))
    }
}

/// Evaluates `[X, X_u, X_v]` along one grid row `u = const`.
pub trait FirstPartialsRows: Send + Sync {
    /// `out[j] = [X, X_u, X_v](u, v_j)` for every column `j`.
    fn eval_row(&self, u: f64, out: &mut [[Vec3; 3]]);
}

struct FirstOfPartials<'a>(Box<dyn PartialsRows + 'a>);

impl FirstPartialsRows for FirstOfPartials<'_> {
    fn eval_row(&self, u: f64, out: &mut [[Vec3; 3]]) {
        let mut row = vec![Partials::default(); out.len()];
        self.0.eval_row(u, &mut row);
        for (o, p) in out.iter_mut().zip(&row) {
            *o = [p.x, p.xu, p.xv];
        }
    }
}

/// [`FirstPartialsRows`] from [`Surface::first_partials`] at every point.
pub struct PointwiseFirstPartials<'a, S: Surface + ?Sized> {
    /// The surface.
    pub surface: &'a S,
    /// The row's `v` values.
    pub vs: &'a [f64],
}

impl<S: Surface + ?Sized> FirstPartialsRows for PointwiseFirstPartials<'_, S> {
    fn eval_row(&self, u: f64, out: &mut [[Vec3; 3]]) {
        for (o, &v) in out.iter_mut().zip(self.vs) {
            *o = self.surface.first_partials(u, v);
        }
    }
}

/// Evaluates [`Partials`] along one grid row `u = const`.
pub trait PartialsRows: Send + Sync {
    /// `out[j] = partials(u, v_j)` for every column `j` (`out` has one entry per `v`).
    fn eval_row(&self, u: f64, out: &mut [Partials]);
}

struct PointwisePartials<'a, S: Surface + ?Sized> {
    surface: &'a S,
    vs: &'a [f64],
}

impl<S: Surface + ?Sized> PartialsRows for PointwisePartials<'_, S> {
    fn eval_row(&self, u: f64, out: &mut [Partials]) {
        for (o, &v) in out.iter_mut().zip(self.vs) {
            *o = self.surface.partials(u, v);
        }
    }
}

/// One grid row in structure-of-arrays form: positions `(x, y, z)` and unit normals
/// `(nx, ny, nz)` of every column, plus scratch space an evaluator may keep between the rows it
/// fills (a row buffer lives for many rows on one thread).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RowBuf {
    /// x coordinates of the positions, one per column.
    pub x: Vec<f64>,
    /// y coordinates of the positions.
    pub y: Vec<f64>,
    /// z coordinates of the positions.
    pub z: Vec<f64>,
    /// x components of the unit normals.
    pub nx: Vec<f64>,
    /// y components of the unit normals.
    pub ny: Vec<f64>,
    /// z components of the unit normals.
    pub nz: Vec<f64>,
    /// Working space an evaluator may keep between the rows it fills; not part of the row's values.
    pub scratch: Vec<f64>,
}

impl RowBuf {
    /// A row of `nv` columns, zeroed.
    pub fn new(nv: usize) -> Self {
        let v = vec![0.0; nv];
        RowBuf {
            x: v.clone(),
            y: v.clone(),
            z: v.clone(),
            nx: v.clone(),
            ny: v.clone(),
            nz: v,
            scratch: Vec::new(),
        }
    }
    /// Number of columns.
    pub fn len(&self) -> usize {
        self.x.len()
    }
    /// True for a row without columns.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
    /// Sets column `j`.
    pub fn set(&mut self, j: usize, p: Vec3, n: Vec3) {
        (self.x[j], self.y[j], self.z[j]) = (p.x, p.y, p.z);
        (self.nx[j], self.ny[j], self.nz[j]) = (n.x, n.y, n.z);
    }
    /// Position of column `j`.
    pub fn point(&self, j: usize) -> Vec3 {
        Vec3::new(self.x[j], self.y[j], self.z[j])
    }
    /// Unit normal of column `j`.
    pub fn normal(&self, j: usize) -> Vec3 {
        Vec3::new(self.nx[j], self.ny[j], self.nz[j])
    }
}

/// Evaluates positions and unit normals along one grid row `u = const`.
pub trait RowEvaluator: Send + Sync {
    /// Fills `row` (of `vs.len()` columns) with `X(u, v_j)` and `n(u, v_j)` for every column `j`.
    fn eval_row(&self, u: f64, row: &mut RowBuf);
}

struct PointwiseRows<'a, S: Surface + ?Sized> {
    surface: &'a S,
    vs: &'a [f64],
}

impl<S: Surface + ?Sized> RowEvaluator for PointwiseRows<'_, S> {
    fn eval_row(&self, u: f64, row: &mut RowBuf) {
        for (j, &v) in self.vs.iter().enumerate() {
            let p = self.surface.partials(u, v);
            row.set(j, p.x, p.normal());
        }
    }
}

/// The unit cylinder `(cos v, sin v, u)`, periodic in `v`: a surface with exact partials for
/// tests of meshing and sampling, shared by the unit tests of the layers above (feature
/// `test-support`, enabled only by their dev-dependencies).
#[cfg(any(test, feature = "test-support"))]
pub struct UnitCylinder;

#[cfg(any(test, feature = "test-support"))]
impl Surface for UnitCylinder {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        let (s, c) = v.sin_cos();
        Partials {
            x: Vec3::new(c, s, u),
            xu: Vec3::new(0.0, 0.0, 1.0),
            xv: Vec3::new(-s, c, 0.0),
            xvv: Vec3::new(-c, -s, 0.0),
            ..Default::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_are_unit_robust_and_have_a_pole_limit() {
        let p = Partials {
            xu: Vec3::new(2.0, 0.0, 0.0),
            xv: Vec3::new(0.0, 3.0, 0.0),
            ..Default::default()
        };
        assert_eq!(p.normal(), Vec3::new(0.0, 0.0, 1.0));
        // Huge and tiny scales neither overflow nor underflow.
        for s in [1e300, 1e-300] {
            let q = Partials {
                xu: p.xu * s,
                xv: p.xv * s,
                ..Default::default()
            };
            assert!(
                (q.normal() - Vec3::new(0.0, 0.0, 1.0)).norm() < 1e-15,
                "scale {s}"
            );
        }
        // A pole (X_v = 0): the limit normal X_u × X_uv.
        let pole = Partials {
            xu: Vec3::new(1.0, 0.0, 0.0),
            xuv: Vec3::new(0.0, 1.0, 0.0),
            ..Default::default()
        };
        assert_eq!(pole.normal(), Vec3::new(0.0, 0.0, 1.0));
        assert_eq!(Partials::default().normal(), Vec3::zeros());
        assert_eq!(Partials::default().normal_or_none(), None);
        assert_eq!(pole.normal_or_none(), Some(Vec3::new(0.0, 0.0, 1.0)));
    }

    #[test]
    fn the_degeneracy_rule_is_relative_and_refuses_nan() {
        assert!(!normal_degenerates(2e-10, 1.0));
        assert!(normal_degenerates(1e-10, 1.0));
        assert!(!normal_degenerates(2e-30, 1e-20));
        assert!(normal_degenerates(f64::NAN, 1.0));
        assert!(normal_degenerates(0.0, 0.0));
        // A nearly parallel pair: X_u × X_v below the rule gives the pole limit instead.
        let p = Partials {
            xu: Vec3::new(1.0, 0.0, 0.0),
            xv: Vec3::new(1.0, 1e-11, 0.0),
            xuv: Vec3::new(0.0, 0.0, 1.0),
            ..Default::default()
        };
        assert_eq!(p.normal(), Vec3::new(0.0, -1.0, 0.0));
    }
}

#[cfg(test)]
mod tests_abilities;
