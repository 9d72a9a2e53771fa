//! What the CAD export's certified deviation of an n-sided surface needs besides the Taylor
//! models of [`super::model`]: a bound of the distance from the corner point on a cell at a
//! corner of the polygon ([`NSidedSurface::corner_reach`]), where the blends are `0/0` and no
//! model exists, and the reasons a surface has no bounds at all
//! ([`NSidedSurface::bounds_unavailable`]).
//!
//! # The corner reach
//!
//! Every quantity is bounded over the cell from its range: the distances to the sides are
//! bilinear in `(u, v)` (the piece's map is bilinear, a distance affine in the domain point),
//! so they take their extremes at the cell's corners; a side's data `P, D, E, F` are bounded
//! over the range of its parameter `s = d_{i−1} / (d_{i−1} + d_{i+1})` (monotone in each
//! distance) by majorants ([`crate::majorant`]) built from the curves' proven derivative
//! bounds ([`crate::curve::Curve::derivative_bounds`]), the Chebyshev series of neighbours'
//! fields (`|T_n| ≤ 1`) and the cubics' coefficients. With `a`, `b` the sides meeting at the
//! corner `c` (`X(c) = P_a(0) = P_b(1)`): the adjacent sides' blends sum to at most 1 and
//! their ribbons move from `X(c)` by at most `|s − end| sup|P'| + t sup|D| + t² sup|E| +
//! t³ sup|F|`; every other blend is at most `(min(d_a, d_b) / d_i)^q` (`B_i ≤ π_i / π_a`);
//! and the correction is at most `w Σ |c_ab|` (`|P_a P_b| ≤ 1` on the square).
//!
//! # Where there is no bound
//!
//! A side whose curve has a break inside it (the surface is not `C⁵` across the break's image
//! in the domain), a curve kind without derivative bounds (NURBS curves), a neighbour's field
//! long enough to be tabulated (it is evaluated by quintic Hermite pieces, `C²` across the
//! table's points): the export samples the surface and says why.

use super::side::{BuiltCurvature, BuiltRibbon, BuiltSide, ChebVec};
use super::{NSidedPatch, NSidedSurface, MAX_SIDES};
use crate::curve::SharedCurve;
use crate::majorant::{Majorant, ORDER};
use crate::Vec3;

/// Rounding slack added to the ends of domain-coordinate enclosures (the coordinates are of
/// size ≤ 1, computed with a few operations).
const SLACK: f64 = 1e-15;

/// A scalar over a cell: its values lie in `[lo, hi]`, and `m` majorises it along every line
/// (`m.0[0] = max(|lo|, |hi|)`).
#[derive(Clone, Copy, Debug)]
struct Scalar {
    lo: f64,
    hi: f64,
    m: Majorant,
}

impl Scalar {
    fn new(lo: f64, hi: f64, mut m: Majorant) -> Scalar {
        m.0[0] = lo.abs().max(hi.abs());
        Scalar { lo, hi, m }
    }
}

/// The majorant of `g(p + σ w) − g(p)`: the constant term dropped.
fn increment(mut m: Majorant) -> Majorant {
    m.0[0] = 0.0;
    m
}

/// `F(s)` for a function with `|F^{(k)}| ≤ f[k]` over the range of `s`.
fn compose(f: &[f64], s: &Scalar) -> Majorant {
    Majorant::compose1(f, &increment(s.m))
}

/// `Σ_k f_k T_k(x)` on `[−1, 1]` as a function of `s = (x + 1)/2`: bounds of its derivatives
/// `0 ..= ORDER` in `s` from the coefficients.
fn chebyshev_bounds(c: &[f64]) -> [f64; ORDER + 1] {
    let mut out = [0.0; ORDER + 1];
    for (n, cn) in c.iter().enumerate() {
        let n2 = (n * n) as f64;
        let mut t = 1.0;
        for (k, o) in out.iter_mut().enumerate() {
            if k > 0 {
                let j = (k - 1) as f64;
                t *= (n2 - j * j).max(0.0) / (2.0 * j + 1.0) * 2.0;
            }
            *o += cn.abs() * t;
        }
    }
    out
}

/// The bounds of a vector Chebyshev field's derivatives (the Euclidean norm of the three
/// coordinates' bounds), or `None` for a tabulated (long) series.
fn field_bounds(f: &ChebVec) -> Option<[f64; ORDER + 1]> {
    let [x, y, z] = coordinate_bounds(f)?;
    Some(std::array::from_fn(|k| x[k].hypot(y[k]).hypot(z[k])))
}

/// Each coordinate's derivative bounds of a Chebyshev field ([`chebyshev_bounds`]).
fn coordinate_bounds(f: &ChebVec) -> Option<[[f64; ORDER + 1]; 3]> {
    let c = f.coordinate_series()?;
    Some([0, 1, 2].map(|i| chebyshev_bounds(&c[i])))
}

/// Bounds of `Σ_m a_m s^m`'s derivatives `0 ..= ORDER` (vector coefficients) for `|s| ≤ 1`.
fn cubic_bounds(a: [f64; 4]) -> [f64; ORDER + 1] {
    std::array::from_fn(|k| (k..4).map(|m| a[m] * falling(m, k) as f64).sum::<f64>())
}

/// `m! / (m − k)!`.
fn falling(m: usize, k: usize) -> usize {
    (m + 1 - k..=m).product()
}

/// The monomial coefficients' norms of the cubic Hermite `[v0, m0, v1, m1]` on `[0, 1]`.
fn hermite_monomials(c: [Vec3; 4]) -> [f64; 4] {
    let [v0, m0, v1, m1] = c;
    [
        v0.norm(),
        m0.norm(),
        (v0 * -3.0 - m0 * 2.0 + v1 * 3.0 - m1).norm(),
        (v0 * 2.0 + m0 - v1 * 2.0 + m1).norm(),
    ]
}

fn hermite_monomials_scalar(c: &[f64; 4]) -> [f64; 4] {
    let v = |x: f64| Vec3::new(x, 0.0, 0.0);
    hermite_monomials([v(c[0]), v(c[1]), v(c[2]), v(c[3])])
}

/// Bounds of `s ↦ curve(t0 + s (t1 − t0))` and its derivatives `0 ..= len − 1` over
/// `s ∈ [a, b]`, or `None` where the curve has a break strictly inside or no bounds.
fn curve_bounds(
    curve: &SharedCurve,
    t0: f64,
    t1: f64,
    [a, b]: [f64; 2],
    len: usize,
) -> Option<[f64; 6]> {
    let dt = t1 - t0;
    let (ta, tb) = (t0 + a * dt, t0 + b * dt);
    let (lo, hi) = (ta.min(tb), ta.max(tb));
    // A periodic curve's breaks repeat with the period.
    let tau = std::f64::consts::TAU;
    let inside = |x: f64| [x - tau, x, x + tau].iter().any(|&y| lo < y && y < hi);
    if curve.breaks().into_iter().any(inside) {
        return None;
    }
    let mut out = [0.0; 6];
    let hi = if hi > lo {
        hi
    } else {
        lo + f64::EPSILON * lo.abs().max(1.0)
    };
    if !curve.derivative_bounds(lo, hi, &mut out[..len]) {
        return None;
    }
    let mut f = 1.0;
    for o in out.iter_mut().take(len) {
        *o *= f * (1.0 + 1e-15);
        f *= dt.abs();
    }
    Some(out)
}

/// The size of the correction's coefficients.
pub(super) struct Correction {
    /// `Σ |c_ab|` (`|P_a P_b| ≤ 1` on the square).
    total: f64,
}

impl Correction {
    fn new(patch: &NSidedPatch) -> Correction {
        Correction {
            total: patch.coeffs.iter().map(|c| c.norm()).sum(),
        }
    }
}

/// The majorised data of one side over a cell: `P, D, E, F` composed with `s`.
struct SideMajorants {
    p: Majorant,
    d: Majorant,
    e: Majorant,
    f: Majorant,
}

impl NSidedSurface {
    /// The cell's corners in the domain with the map's partials.
    fn cell_maps(&self, u: [f64; 2], v: [f64; 2]) -> [[[f64; 2]; 4]; 4] {
        [
            self.domain_map(u[0], v[0]),
            self.domain_map(u[1], v[0]),
            self.domain_map(u[0], v[1]),
            self.domain_map(u[1], v[1]),
        ]
    }

    /// `c + g · (x, y)` over the cell (see the module documentation).
    fn affine(maps: &[[[f64; 2]; 4]; 4], g: [f64; 2], c: f64) -> Scalar {
        let dot = |a: [f64; 2]| g[0] * a[0] + g[1] * a[1];
        let (mut lo, mut hi, mut d1) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for m in maps {
            let val = c + dot(m[0]);
            lo = lo.min(val);
            hi = hi.max(val);
            d1 = d1.max(dot(m[1]).hypot(dot(m[2])));
        }
        let mut m = Majorant::zero();
        m.0[1] = d1 * (1.0 + 1e-15);
        m.0[2] = 0.5 * dot(maps[0][3]).abs() * (1.0 + 1e-15);
        Scalar::new(lo - SLACK, hi + SLACK, m)
    }

    /// The distances to the sides over the cell (`≥ 0` inside the polygon).
    fn distances(&self, maps: &[[[f64; 2]; 4]; 4]) -> Vec<Scalar> {
        let poly = &self.patch.poly;
        (0..poly.n)
            .map(|i| {
                let nrm = poly.normal(i);
                let c = poly.distance(i, [0.0, 0.0]);
                let s = Self::affine(maps, nrm, c);
                Scalar::new(s.lo.max(0.0), s.hi, s.m)
            })
            .collect()
    }

    /// For the cell `[u0, u1] × [v0, v1]` with a corner of the polygon at one of its corners:
    /// that corner's point `X(c)` and a bound of `|X − X(c)|` over the cell (see the module
    /// documentation); `None` if no corner of the cell is a corner of the polygon.
    pub fn corner_reach(&self, u: [f64; 2], v: [f64; 2]) -> Option<(Vec3, f64)> {
        let patch = &*self.patch;
        let n = patch.poly.n;
        let maps = self.cell_maps(u, v);
        let k = maps
            .iter()
            .find_map(|m| patch.poly.vertex_near(m[0], 1e-12))?;
        // Vertex k starts side k (s = 0 there) and ends side k − 1 (s = 1).
        let (a, b) = (k, (k + n - 1) % n);
        let corner = patch.sides[k].position(0.0)[0];
        let d = self.distances(&maps);
        let q = if patch.options.order == 3 { 4 } else { 3 };
        let near = d[a].hi.min(d[b].hi);
        // The adjacent sides' blends sum to at most 1; the others are bounded one by one.
        let (mut adjacent, mut others) = (0.0f64, 0.0f64);
        for i in 0..n {
            let (dm, dp) = (d[(i + n - 1) % n], d[(i + 1) % n]);
            let range = side_range(dm, dp);
            let th = d[i].hi / patch.poly.side;
            let side = &patch.sides[i];
            let sizes = side_sizes(side, range)?;
            let tail = th * (sizes[1] + th * (sizes[2] + th * sizes[3]));
            if i == a || i == b {
                // |P(s) − P(end)| ≤ |s − end| sup|P'|, the end inside the range.
                let end = if i == a { 0.0 } else { 1.0 };
                let far = (range[0] - end).abs().max((range[1] - end).abs());
                adjacent = adjacent.max(far * sizes[4] + tail);
            } else {
                let blend = (near / d[i].lo).powi(q);
                if !blend.is_finite() {
                    return None;
                }
                others += blend * (sizes[0] + tail + corner.norm());
            }
        }
        let corr = patch
            .correction_bounds
            .get_or_init(|| Box::new(Correction::new(patch)));
        let mut w = 1.0;
        for (di, &m) in d.iter().zip(&patch.basis.multiplicity) {
            w *= (di.hi / patch.basis.inradius).powi(m as i32);
        }
        let reach = adjacent + others + w * corr.total;
        Some((corner, reach * (1.0 + 1e-12)))
    }
}

/// The range of a side's parameter from its neighbours' distances ([`super::model`]'s).
fn side_range(dm: Scalar, dp: Scalar) -> [f64; 2] {
    let (lo, hi) = super::model::side_range((dm.lo, dm.hi), (dp.lo, dp.hi));
    [lo, hi]
}

/// Bounds of `|P|, |D|, |E|, |F|` and `|P'|` over `s ∈ range`.
fn side_sizes(side: &BuiltSide, range: [f64; 2]) -> Option<[f64; 5]> {
    let s = Scalar::new(range[0], range[1], Majorant::zero());
    let m = side_majorants(side, &s, range)?;
    let p = curve_bounds(&side.side.curve, side.side.t0, side.side.t1, range, 2)?;
    Some([m.p.0[0], m.d.0[0], m.e.0[0], m.f.0[0], p[1]])
}

/// The side's `P, D, E, F` composed with `s` (values in `range`).
fn side_majorants(side: &BuiltSide, s: &Scalar, range: [f64; 2]) -> Option<SideMajorants> {
    let plane = matches!(side.ribbon, BuiltRibbon::Plane { .. });
    let pos = curve_bounds(
        &side.side.curve,
        side.side.t0,
        side.side.t1,
        range,
        if plane { 6 } else { 5 },
    )?;
    let p = compose(&pos[..5], s);
    let tangent = compose(&pos[1..6], s);
    let d = match &side.ribbon {
        BuiltRibbon::Free(c) => compose(&cubic_bounds(hermite_monomials(*c)), s),
        BuiltRibbon::Derivative { curve, t0, t1 } => {
            compose(&curve_bounds(curve, *t0, *t1, range, 5)?[..5], s)
        }
        BuiltRibbon::Plane { normal, a, b } => {
            let nrm = compose(&field_bounds(normal)?, s);
            let a = compose(&cubic_bounds(hermite_monomials_scalar(a)), s);
            let b = compose(&cubic_bounds(hermite_monomials_scalar(b)), s);
            // |N × P'| ≤ |N| |P'| coefficientwise.
            a.mul(&nrm.mul(&tangent)).add(&b.mul(&tangent))
        }
    };
    // The free part of E: e₀ + (e₁ − e₀) s + δ₀ h₁₀(s) + δ₁ h₁₁(s), h₁₀ = s − 2s² + s³,
    // h₁₁ = −s² + s³.
    let [e0, e1] = side.e;
    let [d0, d1] = side.e_slope;
    let lin = compose(
        &cubic_bounds([
            e0.norm(),
            (e1 - e0 + d0).norm(),
            (d0 * -2.0 - d1).norm(),
            (d0 + d1).norm(),
        ]),
        s,
    );
    let e = match (&side.curvature, &side.ribbon) {
        (BuiltCurvature::Free, _) => lin,
        (BuiltCurvature::Explicit { curve, t0, t1 }, _) => {
            compose(&curve_bounds(curve, *t0, *t1, range, 5)?[..5], s).scale(0.5)
        }
        (BuiltCurvature::Neighbour(k), BuiltRibbon::Plane { normal, a, b }) => {
            // E = l + N g, g = κ/2 − N·l, κ = a² K₀ + 2ab K₁ + b² K₂.
            let nrm = compose(&field_bounds(normal)?, s);
            let a = compose(&cubic_bounds(hermite_monomials_scalar(a)), s);
            let b = compose(&cubic_bounds(hermite_monomials_scalar(b)), s);
            let [k0, k1, k2] = coordinate_bounds(k)?.map(|c| compose(&c, s));
            let kappa = a
                .mul(&a)
                .mul(&k0)
                .add(&a.mul(&b).mul(&k1).scale(2.0))
                .add(&b.mul(&b).mul(&k2));
            let g = kappa.scale(0.5).add(&nrm.mul(&lin));
            lin.add(&nrm.mul(&g))
        }
        (BuiltCurvature::Neighbour(_), _) => return None,
    };
    let [f0, f1] = side.f;
    let f = compose(&cubic_bounds([f0.norm(), (f1 - f0).norm(), 0.0, 0.0]), s);
    Some(SideMajorants { p, d, e, f })
}

/// The most sides, for arrays on the stack.
const _: () = assert!(MAX_SIDES <= 8);

impl NSidedSurface {
    /// Why the patch has no cell bounds anywhere, if it has none: a side's curve (or explicit
    /// ribbon) with a break inside the side or without derivative bounds, or a neighbour's field
    /// tabulated rather than a series.
    pub fn bounds_unavailable(&self) -> Option<String> {
        let patch = &*self.patch;
        for (i, side) in patch.sides.iter().enumerate() {
            let mut curves = vec![("curve", &side.side.curve, side.side.t0, side.side.t1)];
            if let BuiltRibbon::Derivative { curve, t0, t1 } = &side.ribbon {
                curves.push(("ribbon", curve, *t0, *t1));
            }
            if let BuiltCurvature::Explicit { curve, t0, t1 } = &side.curvature {
                curves.push(("second derivative", curve, *t0, *t1));
            }
            for (what, curve, t0, t1) in curves {
                let (lo, hi) = (t0.min(t1), t0.max(t1));
                let tau = std::f64::consts::TAU;
                let inside = |x: &f64| [x - tau, *x, x + tau].iter().any(|&y| lo < y && y < hi);
                if let Some(b) = curve.breaks().iter().find(|x| inside(x)) {
                    return Some(format!(
                        "side {i}'s {what} has a break at t = {b} (its fourth derivative is \
                         not defined there)"
                    ));
                }
                if curve_bounds(curve, t0, t1, [0.0, 1.0], 6).is_none()
                    && curve_bounds(curve, t0, t1, [0.0, 1.0], 5).is_none()
                {
                    return Some(format!("side {i}'s {what} has no derivative bounds"));
                }
            }
            if let BuiltRibbon::Plane { normal, .. } = &side.ribbon {
                if normal.coordinate_series().is_none() {
                    return Some(format!(
                        "side {i}'s neighbour normal needs more than a short Chebyshev series"
                    ));
                }
                if curve_bounds(&side.side.curve, side.side.t0, side.side.t1, [0.0, 1.0], 6)
                    .is_none()
                {
                    return Some(format!(
                        "side {i}'s curve has no bounds of its fifth derivative (a tangent-plane \
                         ribbon differentiates its tangent)"
                    ));
                }
            }
            if let BuiltCurvature::Neighbour(k) = &side.curvature {
                if k.coordinate_series().is_none() {
                    return Some(format!(
                        "side {i}'s neighbour curvature needs more than a short Chebyshev series"
                    ));
                }
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::spherical_polygon;
    use super::*;
    use crate::surface::Surface;
    use std::sync::Arc;

    /// Every point of a corner cell is within the corner reach of the corner point (the
    /// measured overestimation is printed), and no other cell has a reach.
    #[test]
    fn the_corner_reach_holds_on_spherical_polygons() {
        for n in [3, 4, 5] {
            let patch = Arc::new(
                NSidedPatch::solve(spherical_polygon(n, 0.6), &Default::default()).unwrap(),
            );
            let s = &patch.surfaces()[0];
            let (u, v) = ([0.0, 0.01], [0.0, 0.01]);
            let (c, reach) = s.corner_reach(u, v).expect("the corner cell");
            let mut far = 0.0f64;
            for i in 0..=20 {
                for j in 0..=20 {
                    let x = s.point(0.01 * i as f64 / 20.0, 0.01 * j as f64 / 20.0);
                    far = far.max((x - c).norm());
                }
            }
            eprintln!("n = {n}, corner cell: reach {reach:.3e}, sampled {far:.3e}");
            assert!(reach >= far, "n = {n}: {reach:e} < {far:e}");
            assert!(s.corner_reach([0.4, 0.5], [0.0, 0.01]).is_none());
        }
    }
}
