//! Rows of a tessellation of an n-sided patch's surfaces: positions and unit normals from
//! first-order jets of the interpolant and the correction (`eval_domain_to::<1>`: no second
//! derivatives, the sides' data to their first derivatives, the correction as one nested sum,
//! nothing allocated per point). The values are those of [`Surface::partials`] to rounding:
//! the same operations on the same numbers, only the second-order ones left out. Where
//! `X_u × X_v` degenerates ([`first_order_normal`] gives none), the point takes the normal of
//! [`Surface::partials`], whose second derivatives give the limit normal there.

use super::NSidedSurface;
use crate::surface::{first_order_normal, RowBuf, RowEvaluator, Surface};

/// The row evaluator of one [`NSidedSurface`] at the given `v` values.
pub(super) struct Rows<'a> {
    surface: &'a NSidedSurface,
    vs: &'a [f64],
}

impl<'a> Rows<'a> {
    pub(super) fn new(surface: &'a NSidedSurface, vs: &'a [f64]) -> Rows<'a> {
        Rows { surface, vs }
    }
}

impl RowEvaluator for Rows<'_> {
    fn eval_row(&self, u: f64, row: &mut RowBuf) {
        let patch = &self.surface.patch;
        for (j, &v) in self.vs.iter().enumerate() {
            let [p, pu, pv, _] = self.surface.domain_map(u, v);
            let x = patch.eval_domain_to::<1>(p);
            let xu = x.d[0] * pu[0] + x.d[1] * pu[1];
            let xv = x.d[0] * pv[0] + x.d[1] * pv[1];
            let normal =
                first_order_normal(xu, xv).unwrap_or_else(|| self.surface.partials(u, v).normal());
            row.set(j, x.v, normal);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{spherical_polygon, square_patch};
    use super::super::tests_g2::spherical_polygon_g2;
    use super::super::{NSidedOptions, NSidedPatch, NSidedSurface};
    use crate::surface::{RowBuf, Surface};
    use std::sync::Arc;

    /// Parameters at and near the ends of `[0, 1]` (the polygon's corners and sides, where
    /// the blends are 0/0 or nearly so) and inside.
    const TS: [f64; 16] = [
        0.0,
        1e-14,
        1e-11,
        1e-9,
        1e-7,
        1e-5,
        1e-3,
        0.05,
        0.25,
        0.37,
        0.5,
        0.81,
        0.999,
        1.0 - 1e-9,
        1.0 - 1e-14,
        1.0,
    ];

    /// Rows against [`Surface::partials`] at every pair of [`TS`] on every surface of the
    /// patch. Positions are the same operations on the same numbers, so they agree to a few
    /// units of rounding of the position's size; a normal `X_u × X_v / |…|` is computed from
    /// the same `X_u`, `X_v` scaled by another power of the largest partial, so it agrees
    /// to rounding amplified by `1/sin θ`, `θ` the angle between `X_u` and `X_v`. Returns the
    /// largest errors relative to those bounds.
    fn compare(patch: &Arc<NSidedPatch>, what: &str) -> (f64, f64) {
        let eps = f64::EPSILON;
        let (mut worst_x, mut worst_n) = (0.0f64, 0.0f64);
        for s in patch.surfaces() {
            let eval = s.row_evaluator(&TS);
            let mut row = RowBuf::new(TS.len());
            for &u in &TS {
                eval.eval_row(u, &mut row);
                for (j, &v) in TS.iter().enumerate() {
                    let p = s.partials(u, v);
                    // The first partials without the second: the same operations on the same
                    // numbers (bit for bit).
                    assert_eq!(
                        s.first_partials(u, v),
                        [p.x, p.xu, p.xv],
                        "{what}, ({u}, {v})"
                    );
                    let dx = (row.point(j) - p.x).norm();
                    let bound_x = 4.0 * eps * p.x.norm().max(patch.size());
                    let sin = p.xu.cross(&p.xv).norm() / (p.xu.norm() * p.xv.norm());
                    let dn = (row.normal(j) - p.normal()).norm();
                    let bound_n = 16.0 * eps / sin;
                    assert!(
                        dx <= bound_x && dn <= bound_n,
                        "{what}, piece {:?}, (u, v) = ({u}, {v}): position off by {dx:e} \
                         (bound {bound_x:e}), normal by {dn:e} (bound {bound_n:e})",
                        s.piece()
                    );
                    assert!((row.normal(j).norm() - 1.0).abs() <= 4.0 * eps);
                    worst_x = worst_x.max(dx / bound_x);
                    worst_n = worst_n.max(dn / bound_n);
                }
            }
        }
        (worst_x, worst_n)
    }

    #[test]
    fn rows_agree_with_the_partials_for_every_kind_of_side() {
        // Tangent-plane ribbons, three to eight sides (four: one square).
        for n in 3..=8 {
            let p = NSidedPatch::solve(spherical_polygon(n, 0.6), &NSidedOptions::default());
            let r = compare(&Arc::new(p.unwrap()), &format!("G1 sphere, n = {n}"));
            eprintln!("G1 sphere n = {n}: {r:?}");
        }
        // Curvature ribbons (order 3).
        for n in [3, 5, 6] {
            let opts = NSidedOptions {
                order: 3,
                degree: 10,
                ..Default::default()
            };
            let p = NSidedPatch::solve(spherical_polygon_g2(n, 0.6), &opts);
            let r = compare(&Arc::new(p.unwrap()), &format!("G2 sphere, n = {n}"));
            eprintln!("G2 sphere n = {n}: {r:?}");
        }
        // Explicit ribbons and position-only sides on the square, orders 1 and 2.
        for (order, ribbons) in [(2, true), (2, false), (1, false)] {
            let p = square_patch(order, ribbons);
            let r = compare(&p, &format!("square, order {order}, ribbons {ribbons}"));
            eprintln!("square order {order} ribbons {ribbons}: {r:?}");
        }
    }

    /// The rows are the surface's: at a corner of the polygon the position is the corner's
    /// exactly (the 0/0 of the blends is not evaluated there).
    #[test]
    fn a_row_through_a_corner_has_the_corner() {
        let patch =
            Arc::new(NSidedPatch::solve(spherical_polygon(5, 0.6), &Default::default()).unwrap());
        for (k, s) in patch.surfaces().iter().enumerate() {
            let s: &NSidedSurface = s;
            let mut row = RowBuf::new(2);
            s.row_evaluator(&[0.0, 1.0]).eval_row(0.0, &mut row);
            assert_eq!(row.point(0), patch.sides[k].position(0.0)[0]);
            assert!(row.normal(0).iter().all(|c| c.is_finite()));
        }
    }
}
