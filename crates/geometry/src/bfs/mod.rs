//! Smoothing PDE splines on C¹ Bogner–Fox–Schmit (BFS) rectangles, and blending surfaces built
//! from them (M. Pasadas, M. L. Rodríguez, *Blending surfaces by smoothing PDE splines*, seed 004).
//!
//! The finite-element space `X_h` is the bicubic Hermite space on a rectangular partition of
//! `Ω = [0, 1]²`: at every node the degrees of freedom are `u, ∂x u, ∂y u, ∂x∂y u`, so the
//! functions are C¹ and lie in `H²(Ω)` (the paper's `X_h ⊂ H^n ∩ C^{n−1}` with `n = 2`). The
//! discrete PDE spline (Definition 2, Eq. 7) minimises, component by component,
//!
//! ```text
//! J(v) = Σ_i |v(a_i) − β_i|² + ε ((v, v)_L − 2 (f, v)_0)          (Eq. 6)
//! ```
//!
//! over the functions of `X_h` whose constrained degrees of freedom take given values (the
//! paper's `τ v = y`, Eqs. 4–8; here any subset of the nodal degrees of freedom may be fixed).
//!
//! The energy `(u, v)_L = ∫ wᵤᵀ M w_v` is given by a symmetric matrix `M` acting on
//! `w = (u, u_x, u_y, u_xx, u_xy, u_yy)` ([`Energy`]); its Euler–Lagrange operator is the
//! paper's `L` (Eq. 1). Only energies whose second-order block is positive definite are accepted
//! (the pointwise Legendre condition): they are coercive on `H²` modulo affine functions whatever
//! the boundary conditions, so the spline exists and is unique as soon as the fixed degrees of
//! freedom and the data points determine an affine function.
//!
//! Theorem 6 writes the minimiser as the saddle point of `[C D; Dᵀ 0]`. Every constraint here
//! fixes one nodal degree of freedom, so [`SplineSystem`] eliminates them instead: the reduced
//! matrix `C_ff = (AᵀA + εR)_ff` is symmetric positive definite and is factorised by a sparse
//! Cholesky factorisation (half the work and memory of an indefinite LU of the bordered system,
//! no pivoting for the zero block), whose symbolic analysis depends only on the partition and the
//! set of fixed degrees of freedom and is reused for new data points, ε, energies and values.
//! The three coordinates share one factorisation.

// Element-level numerics index several parallel arrays by local degree of freedom.
#![allow(clippy::needless_range_loop)]

mod blend;
mod element;
mod primitives;
mod surface;
mod system;

pub use blend::{blend, Blend, BlendProblem, BlendReport, Join, JoinReport};
pub use element::{element_matrix, hermite_1d, GAUSS4};
pub use primitives::{Cylinder, Plane};
pub use surface::{BSplineNet, BezierPatch, BfsSurface};
pub use system::{SplineFactor, SplineSystem};

use crate::{Error, Result};

/// Degrees of freedom per node: `u, ∂x u, ∂y u, ∂x∂y u` (in this order).
pub(crate) const DOFS_PER_NODE: usize = 4;

/// A tensor-product partition of `Ω = [0, 1]²` into rectangles `[x_i, x_{i+1}] × [y_j, y_{j+1}]`,
/// optionally periodic in `x` (the nodes at `x = 1` are those at `x = 0`, so every function of
/// the space is C¹-periodic in `x`: a closed tube).
#[derive(Clone, Debug, PartialEq)]
pub struct Partition {
    xs: Vec<f64>,
    ys: Vec<f64>,
    periodic_x: bool,
}

fn check_breaks(b: &[f64], name: &str) -> Result<()> {
    if b.len() < 2 {
        return Err(
            Error::invalid(format!("needs at least 2 breakpoints (got {})", b.len())).at(name),
        );
    }
    if b[0] != 0.0 || b[b.len() - 1] != 1.0 {
        return Err(Error::invalid(format!(
            "must run from 0 to 1 (got {} … {})",
            b[0],
            b[b.len() - 1]
        ))
        .at(name));
    }
    for (i, w) in b.windows(2).enumerate() {
        if w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) {
            return Err(Error::invalid(format!(
                "must increase strictly (got {} then {})",
                w[0], w[1]
            ))
            .at(&format!("{name}[{}]", i + 1)));
        }
    }
    Ok(())
}

/// Most elements accepted in one direction (keeps indices in `u32` and memory bounded).
pub const MAX_ELEMENTS_PER_SIDE: usize = 4096;

impl Partition {
    /// `nx × ny` equal rectangles.
    pub fn uniform(nx: usize, ny: usize, periodic_x: bool) -> Result<Self> {
        for (n, name) in [(nx, "nx"), (ny, "ny")] {
            if n == 0 || n > MAX_ELEMENTS_PER_SIDE {
                return Err(Error::invalid(format!(
                    "must be between 1 and {MAX_ELEMENTS_PER_SIDE} (got {n})"
                ))
                .at(name));
            }
        }
        let xs = (0..=nx).map(|i| i as f64 / nx as f64).collect();
        let ys = (0..=ny).map(|j| j as f64 / ny as f64).collect();
        Self::new(xs, ys, periodic_x)
    }

    /// The partition with breakpoints `xs` and `ys` (each strictly increasing from 0 to 1).
    pub fn new(xs: Vec<f64>, ys: Vec<f64>, periodic_x: bool) -> Result<Self> {
        check_breaks(&xs, "xs")?;
        check_breaks(&ys, "ys")?;
        for (b, name) in [(&xs, "xs"), (&ys, "ys")] {
            if b.len() - 1 > MAX_ELEMENTS_PER_SIDE {
                return Err(Error::invalid(format!(
                    "at most {MAX_ELEMENTS_PER_SIDE} elements per side (got {})",
                    b.len() - 1
                ))
                .at(name));
            }
        }
        Ok(Partition { xs, ys, periodic_x })
    }

    /// Breakpoints in `x`.
    pub fn xs(&self) -> &[f64] {
        &self.xs
    }
    /// Breakpoints in `y`.
    pub fn ys(&self) -> &[f64] {
        &self.ys
    }
    /// Elements in `x`.
    pub fn nx(&self) -> usize {
        self.xs.len() - 1
    }
    /// Elements in `y`.
    pub fn ny(&self) -> usize {
        self.ys.len() - 1
    }
    /// True when the space is periodic in `x`.
    pub fn periodic_x(&self) -> bool {
        self.periodic_x
    }
    /// Distinct node columns (`nx` when periodic, else `nx + 1`).
    pub fn node_columns(&self) -> usize {
        if self.periodic_x {
            self.nx()
        } else {
            self.nx() + 1
        }
    }
    /// Number of distinct nodes.
    pub fn nodes(&self) -> usize {
        self.node_columns() * (self.ny() + 1)
    }
    /// Number of degrees of freedom (`4 ×` nodes).
    pub fn dofs(&self) -> usize {
        DOFS_PER_NODE * self.nodes()
    }
    /// Number of elements.
    pub fn elements(&self) -> usize {
        self.nx() * self.ny()
    }
    /// The node at breakpoints `(x_i, y_j)`, `0 ≤ i ≤ nx`, `0 ≤ j ≤ ny` (`i = nx` is `i = 0`
    /// when periodic).
    pub fn node(&self, i: usize, j: usize) -> usize {
        j * self.node_columns() + i % self.node_columns()
    }
    /// The global degree of freedom `k` (0: `u`, 1: `u_x`, 2: `u_y`, 3: `u_xy`) of node `(i, j)`.
    pub fn dof(&self, i: usize, j: usize, k: usize) -> usize {
        DOFS_PER_NODE * self.node(i, j) + k
    }
    /// The 16 global degrees of freedom of element `(i, j)` in local order
    /// `4 (a + 2b) + k` for the corner `(x_{i+a}, y_{j+b})`.
    pub fn element_dofs(&self, i: usize, j: usize) -> [usize; 16] {
        let mut out = [0; 16];
        for b in 0..2 {
            for a in 0..2 {
                for k in 0..4 {
                    out[4 * (a + 2 * b) + k] = self.dof(i + a, j + b, k);
                }
            }
        }
        out
    }
    /// The element `(i, j)` containing `(x, y)` (points on shared edges go to either side;
    /// points outside `Ω` to the nearest element).
    pub fn locate(&self, x: f64, y: f64) -> (usize, usize) {
        (span(&self.xs, x), span(&self.ys, y))
    }
}

fn span(b: &[f64], x: f64) -> usize {
    let n = b.len() - 1;
    // First breakpoint > x, minus one, clamped to the element range.
    let k = b.partition_point(|&t| t <= x);
    k.saturating_sub(1).min(n - 1)
}

/// The quadratic energy `(u, v)_L = ∫_Ω w_uᵀ M w_v` with `w = (u, u_x, u_y, u_xx, u_xy, u_yy)`
/// and a constant symmetric block-diagonal `M = diag(m₀, M₁, M₂)`; by Eq. 1 its Euler–Lagrange
/// operator is `L u = Σ (−1)^{|j|} ∂^j (p_ij ∂^i u)` with `p_ij = M_ij`.
///
/// Accepted: `M₂` (the `(u_xx, u_xy, u_yy)` block) positive definite, `M₁` positive
/// semi-definite, `m₀ ≥ 0`. This is the Legendre condition, stronger than the paper's strong
/// ellipticity (3), which only bounds the symbol: forms such as `a (u_xx v_yy + u_yy v_xx)` have
/// an elliptic symbol but vanish on infinitely many functions when derivatives are free on part
/// of the boundary, and are refused.
#[derive(Clone, Debug, PartialEq)]
pub struct Energy {
    m: [[f64; 6]; 6],
}

impl Energy {
    /// The §6 family: the operator `∂x⁴ + 2a ∂x²∂y² + a² ∂y⁴` with
    /// `(u, v)_L = ∫ u_xx v_xx + 2a u_xy v_xy + a² u_yy v_yy`, `a > 0`. (The paper's `a` plays
    /// the role of the book's `a²`: this is `(∂xx + a ∂yy)²`.)
    pub fn section6(a: f64) -> Result<Self> {
        if !(a.is_finite() && a > 0.0) {
            return Err(Error::invalid(format!("must be positive and finite (got {a})")).at("a"));
        }
        Self::general(1.0, 0.0, 2.0 * a, 0.0, a * a)
    }

    /// Seed 003's family `L_{a,b,c,d,e}`:
    /// `(u, u)_L = ∫ a|u_xx|² + b⟨u_xx, u_xy⟩ + c|u_xy|² + d⟨u_xy, u_yy⟩ + e|u_yy|²` (twice
    /// seed 003's functional, which carries a factor ½), with Euler–Lagrange operator
    /// `a ∂x⁴ + b ∂x³∂y + c ∂x²∂y² + d ∂x∂y³ + e ∂y⁴`. Biharmonic: `(1, 0, 2, 0, 1)`.
    pub fn general(a: f64, b: f64, c: f64, d: f64, e: f64) -> Result<Self> {
        Self::quadratic(
            [[a, b / 2.0, 0.0], [b / 2.0, c, d / 2.0], [0.0, d / 2.0, e]],
            [[0.0; 2]; 2],
            0.0,
        )
    }

    /// The energy with second-order block `second` (on `(u_xx, u_xy, u_yy)`), first-order block
    /// `first` (on `(u_x, u_y)`) and zeroth-order weight `zeroth`. Refuses non-finite entries,
    /// asymmetric blocks, a second-order block that is not positive definite, a first-order
    /// block that is not positive semi-definite and a negative `zeroth`.
    pub fn quadratic(second: [[f64; 3]; 3], first: [[f64; 2]; 2], zeroth: f64) -> Result<Self> {
        let all = second.iter().flatten().chain(first.iter().flatten());
        for x in all.chain(std::iter::once(&zeroth)) {
            if !x.is_finite() {
                return Err(Error::invalid(format!(
                    "energy coefficients must be finite (got {x})"
                )));
            }
        }
        let m2 = nalgebra::Matrix3::from_fn(|i, j| second[i][j]);
        let m1 = nalgebra::Matrix2::from_fn(|i, j| first[i][j]);
        if (m2 - m2.transpose()).amax() > 0.0 || (m1 - m1.transpose()).amax() > 0.0 {
            return Err(Error::invalid("the energy matrix must be symmetric"));
        }
        let not_converged = || Error::invalid("the energy's eigenvalues could not be computed");
        let ev2 = crate::linalg::decomp::symmetric_eigenvalues(nalgebra::DMatrix::from_fn(
            3,
            3,
            |i, j| m2[(i, j)],
        ))
        .ok_or_else(not_converged)?;
        let (lo, hi) = (ev2.min(), ev2.amax());
        if lo.is_nan() || lo <= 1e-12 * hi {
            return Err(Error::invalid(format!(
                "the second-order part of the energy, the matrix {:?} on (u_xx, u_xy, u_yy), is \
                 not positive definite (eigenvalues {:.3e} … {:.3e}): such an (u, v)_L is not \
                 coercive where boundary derivatives are free (the form a(u_xx v_yy + u_yy v_xx) \
                 vanishes on every solution of u_xx + a u_yy = 0); for ∂x⁴ + 2a∂x²∂y² + a²∂y⁴ use \
                 u_xx v_xx + 2a u_xy v_xy + a² u_yy v_yy, which has the same Euler–Lagrange operator",
                second, lo, hi
            )));
        }
        let ev1 = crate::linalg::decomp::symmetric_eigenvalues(nalgebra::DMatrix::from_fn(
            2,
            2,
            |i, j| m1[(i, j)],
        ))
        .ok_or_else(not_converged)?;
        if ev1.min() < -1e-12 * ev1.amax() {
            return Err(Error::invalid(format!(
                "the first-order part of the energy {first:?} on (u_x, u_y) must be positive \
                 semi-definite (smallest eigenvalue {:.3e})",
                ev1.min()
            )));
        }
        if zeroth < 0.0 {
            return Err(Error::invalid(format!(
                "the zeroth-order weight must not be negative (got {zeroth})"
            )));
        }
        let mut m = [[0.0; 6]; 6];
        m[0][0] = zeroth;
        for i in 0..2 {
            for j in 0..2 {
                m[1 + i][1 + j] = first[i][j];
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                m[3 + i][3 + j] = second[i][j];
            }
        }
        Ok(Energy { m })
    }

    /// The 6 × 6 matrix `M` on `(u, u_x, u_y, u_xx, u_xy, u_yy)`.
    pub fn matrix(&self) -> &[[f64; 6]; 6] {
        &self.m
    }

    /// True when the energy has no first- or zeroth-order part: it then vanishes exactly on the
    /// affine functions.
    pub fn is_pure_second_order(&self) -> bool {
        (0..3).all(|i| (0..6).all(|j| self.m[i][j] == 0.0))
    }

    /// Coefficients of the fourth-order part of the Euler–Lagrange operator,
    /// `[∂x⁴, ∂x³∂y, ∂x²∂y², ∂x∂y³, ∂y⁴]`.
    pub fn operator_coefficients(&self) -> [f64; 5] {
        let p = |i: usize, j: usize| self.m[3 + i][3 + j];
        [
            p(0, 0),
            2.0 * p(0, 1),
            2.0 * p(0, 2) + p(1, 1),
            2.0 * p(1, 2),
            p(2, 2),
        ]
    }
}

#[cfg(test)]
mod tests;
