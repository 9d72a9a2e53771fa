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
//! use pdeshape::splinepde::{solve, clamped_uniform, Operator, SplineProblem};
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

    /// `u ∈ [0, 1]` is mapped linearly onto the knot domain `[u_p, u_{n+1}]`.
    fn partials(&self, s: f64, v: f64) -> Partials {
        let (u0, u1) = self.u.domain();
        let l = u1 - u0;
        let u = (u0 + s.clamp(0.0, 1.0) * l).clamp(u0, u1);
        let (v0, v1) = self.v.domain();
        let v = v.clamp(v0, v1);
        let d = |ku: usize, kv: usize| {
            let p = self.derivative(&u, &v, ku, kv);
            Vec3::new(p[0], p[1], p[2]) * l.powi(ku as i32)
        };
        Partials {
            x: d(0, 0),
            xu: d(1, 0),
            xv: d(0, 1),
            xuu: d(2, 0),
            xuv: d(1, 1),
            xvv: d(0, 2),
        }
    }
}

#[cfg(test)]
mod tests;
