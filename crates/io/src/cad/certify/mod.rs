//! Tensor B-spline approximations of every kind of design surface, each with the largest
//! deviation it may have from the surface and how that number is known ([`Certificate`]).
//!
//! # The bound for the analytic PDE patch
//!
//! The approximant is the bicubic Hermite interpolant `H = H_u H_v` on a uniform grid of steps
//! `h_u`, `h_v` ([`super::hermite`]). In one variable, for `t ∈ [t_0, t_1]`,
//! `f(t) − H f(t) = (t − t_0)²(t − t_1)² f[t_0, t_0, t_1, t_1, t]`, and by the Hermite–Genocchi
//! formula the divided difference is a mean of `f⁗/24` with a non-negative weight of integral
//! one, so `|f − H f| ≤ h⁴/384 · sup|f⁗|` for vector-valued `f` in the Euclidean norm. On the
//! tensor grid, `X − H_u H_v X = (X − H_u X) + H_u (X − H_v X)`; the cubic Hermite interpolant
//! of `e` is bounded by `max|e| + h_u/4 · max|e_u|` over the nodes (its value weights are
//! non-negative and sum to one; its slope weights are `t(1 − t)²` and `t²(1 − t)`, of total
//! size `t(1 − t) ≤ 1/4`, times `h_u`), and `e_u = X_u − H_v X_u`. Hence
//!
//! `|X − H X| ≤ h_u⁴/384 · sup|∂_u⁴X| + h_v⁴/384 · (sup|∂_v⁴X| + h_u/4 · sup|∂_u∂_v⁴X|)`.
//!
//! For `X = A₀(u) + Σ Aₙ(u) cos nv + Bₙ(u) sin nv`, `|a cos θ + b sin θ| ≤ (|a|² + |b|²)^{1/2}`
//! gives `sup|∂_u^d ∂_v^k X| ≤ Σ_n n^k (αₙ² + βₙ²)^{1/2}` with `αₙ, βₙ` the bounds of
//! `sup|Aₙ^{(d)}|, sup|Bₙ^{(d)}|` over `u ∈ [0, 1]` from the stored series
//! (`PdePatch::mode_derivative_bounds`). The steps are chosen so that each of the two terms is at
//! most half the tolerance; a rounding allowance of `ROUNDING` times the size of the patch is
//! added (the nodal data and the control points are computed in floating point).
//!
//! # Exact kinds
//!
//! The finite-difference surface and the BFS blend are C¹ piecewise bicubics with nodal data
//! `X, X_u, X_v, X_uv`: their Hermite interpolant on their own nodes is themselves. A spline
//! net is a B-spline already (its `u` knots mapped onto `[0, 1]` as its [`Surface`] does). Their
//! bound is the rounding allowance.
//!
//! # The bound for formula surfaces
//!
//! The argument above holds cell by cell: on a cell `[u_i, u_{i+1}] × [v_j, v_{j+1}]` the error
//! of the bicubic Hermite interpolant involves only the cell's own nodal data, so with the
//! suprema taken over the cell and its own steps,
//!
//! `|X − H X| ≤ h_u⁴/384 · M_u4 + h_v⁴/384 · (M_v4 + h_u/4 · M_u1v4)` on the cell,
//!
//! and the grid need not be uniform. For a formula surface (`[[parametric]]`) the fourth-order
//! partials `∂u⁴, ∂v⁴, ∂u∂v⁴` of each component are derived symbolically (exmex's
//! differentiation over the formula's tree, [`ParametricSurface::fourth_partials`]) and
//! evaluated over the cell in interval arithmetic with outward rounding
//! ([`crate::formula::interval`]); the Euclidean norm of the three components' enclosures
//! bounds each `M`. The formula itself is evaluated over the cell first, and every function
//! refuses an interval on which it is not analytic (a pole of `tan`, a division by an interval
//! containing 0, `sqrt` or `ln` reaching 0, a kink of `abs`, …): a cell with enclosures is one
//! on which the components are analytic, so the symbolic partials are the true ones and the
//! Hermite remainder applies. Rows and columns of cells whose bound exceeds the tolerance
//! (less the rounding allowance) are cut into the number of equal pieces that the fourth root
//! of the excess asks for, until every cell meets it ([`approximate_formula`]); the figure
//! reported is the largest cell bound plus the rounding allowance,
//! [`Certificate::Intervals`]. A cell without enclosures is halved in the direction that
//! isolates the trouble; if it still has none after [`MAX_DEPTH`] halvings (a singular point
//! of the formulas on the surface, e.g. `u^2.5` at `u = 0`), or the grid would exceed
//! [`MAX_CELLS`], the surface is sampled instead and the reason is reported.
//!
//! # The bound for the analytic PDE patch with a spectral remainder
//!
//! With an active remainder `X = X̃ + Σ_i w_i(u) Δ_i(v)`: `X̃` the `M` Fourier modes, `w_i` the
//! scalar cardinal functions of mode `M + 1` and `Δ_i = g_i − fitted_i` (condition curve `g_i`
//! less the Fourier series `fitted_i = ∂ᵈX̃(u_i, ·)`), so `∂_u^a ∂_v^b X = ∂_u^a ∂_v^b X̃ +
//! Σ_i w_i^{(a)} Δ_i^{(b)}`. The cell argument above needs `X` C⁴ inside each cell: every break
//! of every active condition curve ([`crate::curve::Curve::breaks`]) is a `v` node. On a
//! column `[v_a, v_b]` of cells, with `F` the Fourier part's sums above
//! ([`PdePatch::fourier_partial_bound`]), `Wd_i ≥ sup|w_i^{(d)}|` from the cardinal
//! functions' stored series (as for the modes, per scalar column), `|g_i⁽ᵏ⁾|` from
//! [`crate::curve::Curve::derivative_bounds`] on the column and `|fitted_i⁽ᵏ⁾| ≤ Σ nᵏ σₙ`:
//!
//! `M_u4 ≤ F_u4 + Σ W4_i D0_i`, `M_v4 ≤ F_v4 + Σ W0_i D4_i`, `M_u1v4 ≤ F_u1v4 + Σ W1_i D4_i`,
//!
//! `D4_i = sup|g_i⁗| + sup|fitted_i⁗|` and `D0_i ≥ sup|Δ_i|` on the column: the smaller of
//! `sup|g_i| + sup|fitted_i|` and Taylor's formula about the column's middle `m` with
//! half-width `r`, `Σ_{j<4} |Δ_i⁽ʲ⁾(m)| rʲ/j! + D4_i r⁴/24` (the remainder is small, so this is
//! what keeps the `u` term small). At a node that is a break, the Hermite interpolant takes
//! `X_v`, `X_uv` from the curve's jet there, one side's; if `g_i'` jumped, the cell on the
//! other side would see slope data off by the jump. A bound `J_i` of the jump comes from
//! Taylor's formula on each side (`slope_jump`: `g'(b∓) = g'(x) + (b − x) g''(x) +
//! (b − x)²/2 · g'''(x) + ρ`, `|ρ| ≤ δ³/6 · sup|g⁗|`, `x = b ± δ`; rounding size for the C¹
//! curves of practice), and slope data off by `e` at the two `v` ends of a cell move the
//! bicubic by at most `h_v · t(1 − t) · max e ≤ h_v/4 · max e` (then through `H_u`: `+ h_u/4`
//! times that of the `u`-derivative), adding `h_v/4 · Σ_i J_i (W0_i + h_u/4 · W1_i)` to the
//! `v` term of the cells next to the break. `u` nodes stay uniform (`W` are bounds over all
//! of `[0, 1]`); columns whose `v` term exceeds half the budget are cut, as for formula
//! surfaces ([`shared_v_nodes`]). The periodic analytic patches of one design share their `v`
//! nodes (the union of every patch's breaks, cut until each patch's columns meet its budget),
//! so the boundary rows of patches that meet stay identical (`approximate_design`). The
//! figure is reported as [`Certificate::Intervals`] (largest column bounds, number of cells).
//!
//! # The bound for spine-edited patches
//!
//! `X̃ = Ã₀(u) + R(u) D(u, v)` with the base patch's radial part `D` (modes `n ≥ 1`), the new
//! spine `Ã₀` (Bézier curve plus wave) and the rotation `R` (one Chebyshev series in frame
//! mode, `I` when translating) has the derivative sums of
//! `crate::design::SpineEdited::derivative_sums` (Leibniz's rule with the bounds of each
//! factor over the whole patch); the uniform grid and the bound are then those of the analytic
//! patch. A base with an active remainder, or frames without a settled series, leave the patch
//! sampled.
//!
//! # The bound for n-sided patches
//!
//! An n-sided piece is certified a posteriori, cell by cell of the grid: on a box `B` of a
//! cell, `NSidedSurface::taylor_model` gives a polynomial `P` of degree 4 in the box's
//! coordinates `σ ∈ [−1, 1]²` and radii `r_c` with `|X_c − P_c| ≤ r_c` on `B` (Taylor-model
//! arithmetic over the blends, side parameters, ribbons and correction; see
//! `geometry/src/nsided/model.rs`). The cell's bicubic Hermite interpolant `H`, re-expanded in
//! the box's `σ`, is a polynomial too, and `P − H` (degree ≤ 4 in each variable) is bounded by
//! its largest Bernstein coefficient on the square (the convex hull property), so
//! `|X − H| ≤ (Σ_c (max|b_c| + r_c)²)^{1/2}` on `B`. Where that exceeds the budget the box is
//! split in four, up to 14 times; the box at a corner of the polygon, where the blends are
//! `0/0` and there is no model, is bounded by `|X − X(c)| + |H − X(c)|`: the corner reach
//! (`NSidedSurface::corner_reach`) plus the largest distance of `H`'s Bernstein points from
//! `X(c)`. A cell whose sampled deviation already exceeds the budget, or whose boxes do not
//! all meet it, has its row and column cut (the direction from the model's quartic terms
//! `c₄₀`, `c₀₄`, about the Hermite interpolant's error in each direction); a cell's check
//! depends only on its corners, so the cells of rows and columns not cut keep theirs. The
//! figure is the largest box bound plus the rounding allowance,
//! [`Certificate::Models`]. Across a break of a side's curve where the curve is `C^c` the
//! models' remainders are of order `c + 1`, and a curve whose jet is exact only to order `e`
//! (`Curve::exact_order`) is modelled to that order (remainder `e + 1`); a side only `C⁰` at a
//! break inside it (`C¹` under a tangent-plane ribbon) or a curve kind without bounds leaves the
//! piece sampled, with the reason.
//!
//! # Sampled kinds
//!
//! PDE patches with an active spectral remainder whose condition curves give no derivative
//! bounds (arc-length reparametrisations, ODE curves, formula curves touching a pole; the note
//! names the condition), the spine edits above without bounds and formula surfaces without
//! interval bounds carry no derivative bounds. They are interpolated on grids refined
//! until the deviation on a dense sample (a 5 × 5 lattice in every cell, corners included) is
//! at most half the tolerance; the reported figure is that sampled maximum, marked
//! [`Certificate::Sampled`]: an estimate, not a bound.

use super::hermite::hermite_interpolant;
use crate::design::SurfaceKind;
use crate::spline::BSplineSurface;
use crate::{Error, Result, Vec3};

mod analytic;
mod exact;
mod formula;
mod nsided;
mod remainder;
mod sampled;
pub use analytic::{approximate_pde, pde_grid};
use analytic::{approximate_with_sums, sums_grid};
use exact::{clamp_u, exact};
pub use formula::approximate_formula;
pub use nsided::approximate_nsided;
use remainder::approximate_remainder;
pub use remainder::{approximate_pde_on, shared_v_nodes, PdePlan};
pub use sampled::{approximate_sampled, sampled_deviation};

/// Relative rounding allowance added to every bound.
pub const ROUNDING: f64 = 1e-12;
/// The most nodes per direction an approximation may use.
pub const MAX_NODES: usize = 4096;
/// The most grid cells (`m × n` intervals) one surface's approximation may use: a net of about
/// a million control points (≈ 25 MB), and for a sampled surface about 7 million evaluations
/// of its deviation. Beyond it the tolerance is refused rather than the export run for minutes.
pub(crate) const MAX_CELLS: usize = 1 << 18;

fn too_many_cells(tolerance: f64) -> Error {
    Error::invalid(format!(
        "the tolerance {tolerance:e} needs more than {MAX_CELLS} grid cells on one surface"
    ))
    .at("tolerance")
}

/// How the deviation of an approximation is known.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Certificate {
    /// The surface is piecewise polynomial and reproduced exactly (up to rounding).
    Exact,
    /// A proven bound from bounds of the surface's derivatives (the analytic PDE patch).
    Derivatives {
        /// `sup|∂_u⁴X|` over the patch.
        m_u4: f64,
        /// `sup|∂_v⁴X|` over the patch.
        m_v4: f64,
        /// `sup|∂_u∂_v⁴X|` over the patch.
        m_u1v4: f64,
    },
    /// A proven bound from interval enclosures of the fourth-order partials over every grid
    /// cell (formula surfaces); the largest enclosures over the cells and the number of cells.
    Intervals {
        /// Largest enclosure of `|∂_u⁴X|` over the cells.
        m_u4: f64,
        /// Largest enclosure of `|∂_v⁴X|` over the cells.
        m_v4: f64,
        /// Largest enclosure of `|∂_u∂_v⁴X|` over the cells.
        m_u1v4: f64,
        /// Number of grid cells.
        cells: usize,
    },
    /// A proven bound from Taylor models of the surface over boxes of every grid cell
    /// (n-sided patches): the number of cells and of boxes.
    Models {
        /// Number of grid cells.
        cells: usize,
        /// Number of boxes the cells were checked on.
        boxes: usize,
    },
    /// The largest deviation on a dense sample: an estimate, not a bound.
    Sampled,
}

impl Certificate {
    /// A word for reports.
    pub fn word(&self) -> &'static str {
        match self {
            Certificate::Exact => "exact",
            Certificate::Derivatives { .. }
            | Certificate::Intervals { .. }
            | Certificate::Models { .. } => "certified",
            Certificate::Sampled => "sampled, not certified",
        }
    }
    /// The relation a report prints between "deviation" and its figure: `≤` for a bound, `≈`
    /// for an estimate.
    pub fn relation(&self) -> &'static str {
        if self.is_certified() {
            "≤"
        } else {
            "≈"
        }
    }
    /// True if the deviation is proven to hold everywhere on the surface.
    pub fn is_certified(&self) -> bool {
        !matches!(self, Certificate::Sampled)
    }
}

/// A B-spline approximation of one surface, in the surface's own parameters.
#[derive(Clone, Debug)]
pub struct Approximation {
    /// The tensor B-spline net.
    pub net: BSplineSurface,
    /// Closed in `[u, v]`: the first and last control rows are the same points.
    pub closed: [bool; 2],
    /// The largest deviation `|X − S|` over the whole patch (see `certificate`).
    pub deviation: f64,
    /// How `deviation` is known: a proven bound or a sampled estimate.
    pub certificate: Certificate,
    /// Why a surface of a kind that is usually certified was only sampled.
    pub note: Option<String>,
}

/// The approximation of a design surface at `tolerance`; periodic analytic PDE patches use at
/// least `min_v` intervals in `v` (so that patches meeting along an edge can share it).
pub fn approximate(kind: &SurfaceKind, tolerance: f64, min_v: usize) -> Result<Approximation> {
    match kind {
        SurfaceKind::Pde(p) => match pde_grid(p, tolerance, min_v) {
            Some(grid) => {
                let (m, n) = grid?;
                approximate_pde(p, m, n)
            }
            None => approximate_remainder(p, tolerance, min_v),
        },
        SurfaceKind::Fd(f) => {
            let us: Vec<f64> = (0..=f.nu()).map(|i| f.u_node(i)).collect();
            let periodic = f.periodic();
            let cols = f.nodes_v() + usize::from(periodic);
            let vs: Vec<f64> = (0..cols).map(|j| f.v_node(j)).collect();
            Ok(exact(
                hermite_interpolant(&**f, &us, &vs, [false, periodic])?,
                [false, periodic],
            ))
        }
        SurfaceKind::Blend(b) => {
            let part = b.surface.partition();
            let closed = [part.periodic_x(), false];
            Ok(exact(
                hermite_interpolant(&b.surface, part.xs(), part.ys(), closed)?,
                closed,
            ))
        }
        SurfaceKind::Spline(_, net) => {
            let b = clamp_u(&clamp_u(&net.to_bspline()?)?.transposed())?.transposed();
            let [[a, e], _] = b.domain();
            let ku: Vec<f64> = b.knots_u().iter().map(|k| (k - a) / (e - a)).collect();
            let b =
                BSplineSurface::new(b.degree(), ku, b.knots_v().to_vec(), b.control().to_vec())?;
            Ok(exact(b, [false, false]))
        }
        SurfaceKind::NSided(s) => approximate_nsided(s, tolerance, min_v),
        SurfaceKind::Disk(s) => {
            let mut a = approximate_sampled(&**s, tolerance, min_v)?;
            a.note =
                Some("disk patches have no derivative bounds yet: the deviation is sampled".into());
            Ok(a)
        }
        SurfaceKind::Parametric(p) => approximate_formula(p, tolerance),
        SurfaceKind::Nurbs(s) => {
            // Reference surfaces are not exported; a direct caller gets a sampled fit.
            let mut a = approximate_sampled(&**s, tolerance, min_v)?;
            a.note = Some("a [[nurbs]] reference surface: the deviation is sampled".into());
            Ok(a)
        }
        SurfaceKind::SpineEdited(s) => match s.derivative_sums() {
            Some(sums) => {
                let (m, n) = sums_grid(sums, tolerance, min_v)?;
                approximate_with_sums(&**s, sums, m, n)
            }
            None => {
                let mut a = approximate_sampled(&**s, tolerance, min_v)?;
                a.note = Some(
                    "the spine edit has no derivative bounds (its base patch has a spectral \
                     remainder, or its frames have no settled Chebyshev series)"
                        .into(),
                );
                Ok(a)
            }
        },
    }
}

/// The largest distance between two rows of points.
pub(crate) fn row_distance(a: &[Vec3], b: &[Vec3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}
