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
//! in size over the range of its parameter `s = d_{i−1} / (d_{i−1} + d_{i+1})` (monotone in
//! each distance) from the curves' proven bounds over that range
//! ([`crate::curve::Curve::derivative_bounds`]), the cubics' coefficients and the neighbour
//! fields' sizes ([`super::side::ChebVec::size_bounds`]). With `a`, `b` the sides meeting at
//! the corner `c` (`X(c) = P_a(0) = P_b(1)`): the adjacent sides' blends sum to at most 1 and
//! their ribbons move from `X(c)` by at most `|s − end| sup|P'| + t sup|D| + t² sup|E| +
//! t³ sup|F|`; every other blend is at most `(min(d_a, d_b) / d_i)^q` (`B_i ≤ π_i / π_a`);
//! and the correction is at most `w Σ |c_ab|` (`|P_a P_b| ≤ 1` on the square).
//!
//! # Where there is no bound
//!
//! A curve kind without derivative bounds (arc-length or ODE curves), or a side whose curve is
//! only `C⁰` at a break inside it (a polyline; a tangent-plane ribbon needs the curve `C¹`):
//! the export samples the surface and says why. Across a break where the curve is `C^c`
//! (`c ≥ 1`), the models carry Taylor's remainder of order `c + 1` instead of 5.

use super::model::remainder_order;
use super::side::{BuiltCurvature, BuiltRibbon, BuiltSide};
use super::{NSidedPatch, NSidedSurface, MAX_SIDES};
use crate::curve::SharedCurve;
use crate::Vec3;

/// Rounding slack added to the ends of domain-coordinate enclosures (the coordinates are of
/// size ≤ 1, computed with a few operations).
const SLACK: f64 = 1e-15;

/// A scalar's range over a cell.
#[derive(Clone, Copy, Debug)]
struct Scalar {
    lo: f64,
    hi: f64,
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
/// `s ∈ [a, b]` (over the pieces between the curve's breaks, one-sided at a break), or `None`
/// where the curve has no bounds.
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
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for m in maps {
            let val = c + dot(m[0]);
            lo = lo.min(val);
            hi = hi.max(val);
        }
        Scalar {
            lo: lo - SLACK,
            hi: hi + SLACK,
        }
    }

    /// The distances to the sides over the cell (`≥ 0` inside the polygon).
    fn distances(&self, maps: &[[[f64; 2]; 4]; 4]) -> Vec<Scalar> {
        let poly = &self.patch.poly;
        (0..poly.n)
            .map(|i| {
                let nrm = poly.normal(i);
                let c = poly.distance(i, [0.0, 0.0]);
                let s = Self::affine(maps, nrm, c);
                Scalar {
                    lo: s.lo.max(0.0),
                    hi: s.hi,
                }
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

/// Bounds of `|P|, |D|, |E|, |F|` and `|P'|` over `s ∈ range`, from the curves' bounds over
/// the range, the cubics' coefficients (`Σ |a_m|` for `s ∈ [0, 1]`) and the neighbour
/// fields' sizes ([`ChebVec::norm_bound`]).
fn side_sizes(side: &BuiltSide, range: [f64; 2]) -> Option<[f64; 5]> {
    let pos = curve_bounds(&side.side.curve, side.side.t0, side.side.t1, range, 2)?;
    let (p, tangent) = (pos[0], pos[1]);
    let cubic = |a: [f64; 4]| a.iter().sum::<f64>();
    let d = match &side.ribbon {
        BuiltRibbon::Free(c) => cubic(hermite_monomials(*c)),
        BuiltRibbon::Derivative { curve, t0, t1 } => curve_bounds(curve, *t0, *t1, range, 1)?[0],
        BuiltRibbon::Plane { normal, a, b } => {
            // |a N × P' + b P'| ≤ (|a| |N| + |b|) |P'|.
            let (a, b) = (
                cubic(hermite_monomials_scalar(a)),
                cubic(hermite_monomials_scalar(b)),
            );
            (a * normal.norm_bound() + b) * tangent
        }
    };
    // The free part of E: e₀ + (e₁ − e₀) s + δ₀ h₁₀(s) + δ₁ h₁₁(s), h₁₀ = s − 2s² + s³,
    // h₁₁ = −s² + s³.
    let [e0, e1] = side.e;
    let [d0, d1] = side.e_slope;
    let lin = cubic([
        e0.norm(),
        (e1 - e0 + d0).norm(),
        (d0 * -2.0 - d1).norm(),
        (d0 + d1).norm(),
    ]);
    let e = match (&side.curvature, &side.ribbon) {
        (BuiltCurvature::Free, _) => lin,
        (BuiltCurvature::Explicit { curve, t0, t1 }, _) => {
            0.5 * curve_bounds(curve, *t0, *t1, range, 1)?[0]
        }
        (BuiltCurvature::Neighbour(k), BuiltRibbon::Plane { normal, a, b }) => {
            // E = l + N g, g = κ/2 − N·l, κ = a² K₀ + 2ab K₁ + b² K₂.
            let nrm = normal.norm_bound();
            let (a, b) = (
                cubic(hermite_monomials_scalar(a)),
                cubic(hermite_monomials_scalar(b)),
            );
            let [k0, k1, k2] = k.size_bounds();
            let kappa = a * a * k0 + 2.0 * a * b * k1 + b * b * k2;
            lin + nrm * (0.5 * kappa + nrm * lin)
        }
        (BuiltCurvature::Neighbour(_), _) => return None,
    };
    let [f0, f1] = side.f;
    let f = f0.norm() + (f1 - f0).norm();
    Some([p, d, e, f, tangent].map(|x| x * (1.0 + 1e-14)))
}

/// The most sides, for arrays on the stack.
const _: () = assert!(MAX_SIDES <= 8);

impl NSidedSurface {
    /// Why the patch has no cell bounds anywhere, if it has none: a side's curve (or explicit
    /// ribbon) only `C⁰` at a break inside the side (`C¹` under a tangent-plane ribbon), or
    /// without derivative bounds.
    pub fn bounds_unavailable(&self) -> Option<String> {
        let patch = &*self.patch;
        for (i, side) in patch.sides.iter().enumerate() {
            let curve = ("curve", &side.side.curve, side.side.t0, side.side.t1, 0);
            let mut curves = vec![curve];
            match &side.ribbon {
                BuiltRibbon::Derivative { curve, t0, t1 } => {
                    curves.push(("ribbon", curve, *t0, *t1, 0));
                }
                // A tangent-plane ribbon differentiates the side's curve.
                BuiltRibbon::Plane { .. } => curves.push(("tangent", curve.1, curve.2, curve.3, 1)),
                BuiltRibbon::Free(_) => {}
            }
            if let BuiltCurvature::Explicit { curve, t0, t1 } = &side.curvature {
                curves.push(("second derivative", curve, *t0, *t1, 0));
            }
            for (what, curve, t0, t1, shift) in curves {
                let (lo, hi) = (t0.min(t1), t0.max(t1));
                let tau = std::f64::consts::TAU;
                let inside = |x: &f64| [x - tau, *x, x + tau].iter().any(|&y| lo < y && y < hi);
                let broken = curve.breaks().into_iter().find(inside);
                let m = remainder_order(curve, broken.is_some(), shift).unwrap_or(0);
                // A model of order 1 (a constant and the range) would need a box per tolerance.
                if let (Some(b), true) = (broken, m < 2) {
                    return Some(format!(
                        "side {i}'s {what} is only C{} at its break t = {b} (the models need \
                         C{} there)",
                        curve.continuity().saturating_sub(shift),
                        shift + 1
                    ));
                }
                let order = |m: usize| {
                    let len = m + shift + 1;
                    (len <= 6).then(|| curve_bounds(curve, t0, t1, [0.0, 1.0], len))?
                };
                if order(m).is_none() && (m <= 4 || order(4).is_none()) {
                    return Some(format!("side {i}'s {what} has no derivative bounds"));
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
