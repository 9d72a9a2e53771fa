//! B-spline and Bézier solutions of linear constant-coefficient PDEs (seed 003: L. Sun and
//! C. Zhu, *B-spline solutions of general Euler–Lagrange equations*; book §8.3: harmonic and
//! biharmonic Bézier surfaces).
//!
//! A tensor-product B-spline surface `x(u, v) = Σ P_ij N_{i,p}(u) N_{j,q}(v)` with unknown
//! control points is substituted into
//! `a x_uu + b x_uv + c x_vv + d x_u + e x_v + f x = g` or
//! `a x_uuuu + b x_uuuv + c x_uuvv + d x_uvvv + e x_vvvv = 0` (seed 003 Eq. 4). On each knot
//! span the residual is a polynomial; all its coefficients must vanish (Lemmas 1–2, Algorithms
//! 1–2). The user fixes some control points; the engine reports the rank, which control points
//! the equations determine and which stay free, picks the free ones by minimising the operator's
//! quadratic functional (Eq. 1, §2), and names the equations that contradict the fixed points.
//! Everything runs in `f64` or in exact rationals ([`num_rational::BigRational`]).
//!
//! ```
//! use pdeshape_geometry::splinepde::{solve, clamped_uniform, Operator, SplineProblem};
//! // A bicubic Bézier patch solving the Laplace equation, first and last rows fixed.
//! let dir = clamped_uniform::<f64>(3, 1);
//! let fixed = (0..4)
//!     .flat_map(|j| [([0, j], [0.0, j as f64, 0.0]), ([3, j], [3.0, j as f64, 1.0])])
//!     .collect();
//! let net = solve(&SplineProblem { u: dir.clone(), v: dir, operator: Operator::laplace(), fixed })
//!     .unwrap();
//! let r = net.residual(&0.3, &0.7);
//! assert!(r.iter().all(|x| x.abs() < 1e-12));
//! ```

// Control-point indices are computed from several loop variables at once; index loops read
// closer to the formulas than zipped iterators.
#![allow(clippy::needless_range_loop)]

mod basis;
mod bezier;
mod engine;
pub mod export;
mod linalg;
mod operator;
/// The crate's one scalar trait, under the path the engine's modules import it from.
mod scalar {
    pub use crate::scalar::Scalar;
}

pub use basis::{Direction, Span};
pub use bezier::{
    a_coef, b_coef, bezier_direction, bezier_from_rings, biharmonic_mask, clamped_uniform,
    harmonic_bezier, harmonic_mask, ring_indices,
};
pub use engine::{
    assemble, functional_matrix, solve, EquationLabel, Point, SolveReport, SplineNet, SplineProblem,
};
pub use linalg::{Mat, Solve};
pub use num_rational::BigRational;
pub use operator::{InnerTerm, Operator};
pub use scalar::Scalar;

use crate::surface::{Partials, Surface, VDomain};
use crate::Vec3;

impl Surface for SplineNet<f64> {
    /// `v` runs over the knot domain `[v_q, v_{m+1}]`.
    fn v_domain(&self) -> VDomain {
        let (a, b) = self.v.domain();
        VDomain::Interval(a, b)
    }

    /// `u ∈ [0, 1]` is mapped linearly onto the knot domain `[u_p, u_{n+1}]`. The basis and its
    /// first two derivatives are computed once per direction for all six partials.
    fn partials(&self, s: f64, v: f64) -> Partials {
        let (u0, u1) = self.u.domain();
        let l = u1 - u0;
        let u = (u0 + s.clamp(0.0, 1.0) * l).clamp(u0, u1);
        let (v0, v1) = self.v.domain();
        let v = v.clamp(v0, v1);
        let (i0, bu) = self.u.basis_derivatives_at(&u, 2);
        let (j0, bv) = self.v.basis_derivatives_at(&v, 2);
        let (p, q, nv) = (self.u.degree, self.v.degree, self.v.count());
        // (ku, kv) of x, x_u, x_v, x_uu, x_uv, x_vv.
        const ORDERS: [(usize, usize); 6] = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
        let mut d = [Vec3::zeros(); 6];
        for r in 0..=p {
            for t in 0..=q {
                let c = &self.control[(i0 - p + r) * nv + (j0 - q + t)];
                let c = Vec3::new(c[0], c[1], c[2]);
                for (k, &(ku, kv)) in ORDERS.iter().enumerate() {
                    let w = bu[ku][r] * bv[kv][t];
                    if w != 0.0 {
                        d[k] += c * w;
                    }
                }
            }
        }
        for (k, &(ku, _)) in ORDERS.iter().enumerate() {
            d[k] *= l.powi(ku as i32);
        }
        Partials {
            x: d[0],
            xu: d[1],
            xv: d[2],
            xuu: d[3],
            xuv: d[4],
            xvv: d[5],
        }
    }

    /// The interior knots (mapped onto `u ∈ [0, 1]`, and in `v` as they are): the surface is
    /// a polynomial between them, so quadrature panels end there.
    fn breaks(&self) -> (Vec<f64>, Vec<f64>) {
        let interior = |d: &Direction<f64>| -> Vec<f64> {
            let (a, b) = d.domain();
            let mut k: Vec<f64> = d
                .knots
                .iter()
                .copied()
                .filter(|&x| x > a && x < b)
                .collect();
            k.dedup();
            k
        };
        let (u0, u1) = self.u.domain();
        let u = interior(&self.u)
            .into_iter()
            .map(|x| (x - u0) / (u1 - u0))
            .collect();
        (u, interior(&self.v))
    }
}

#[cfg(test)]
mod tests;
