//! Finite differences for the PDE surfaces `(∂²/∂u² + a² ∂²/∂v²)^N X = F`, `N = 1, 2, 3`, on a
//! rectangular `(u, v)` grid (book §4.2.1 does `N = 1` this way; here the same idea for the
//! biharmonic and triharmonic operators), in two settings:
//!
//! - **periodic in `v`** ([`PeriodicProblem`]): the analytic solver's setting. The conditions are
//!   `∂ᵈX/∂uᵈ` at `u = 0` and `u = 1` for `d = 0 … N−1` (positions, then derivative curves, then
//!   for `N = 3` second u-derivatives). Intermediate conditions (at `0 < u < 1`) are not
//!   supported by the difference scheme.
//! - **four-sided** ([`FourSidedProblem`]): `X` on the four sides of `[0, 1] × [v₀, v₁]` and, for
//!   `N ≥ 2`, the cross-boundary derivatives `∂ᵈX/∂uᵈ` on the sides `u = 0, 1` and `∂ᵈX/∂vᵈ` on
//!   the sides `v = v₀, v₁`, `d < N`.
//!
//! ## The scheme
//!
//! With `δ²` the second central difference, `L_h = δ²_u / h_u² + a² δ²_v / h_v²` and the PDE is
//! replaced at every interior node by `L_h^N X = F`: the 5-point stencil for `N = 1`, the
//! 13-point stencil for `N = 2`, the 25-point stencil for `N = 3`. Each is second-order accurate
//! (every `δ²/h²` is `∂² + h²/12 ∂⁴ + …`).
//!
//! `L_h^N` reaches `N` nodes away, so the grid carries `N − 1` layers of ghost nodes beyond every
//! side on which derivatives are prescribed. Their equations are the derivative conditions, by
//! central differences centred on the boundary node: `(X₁ − X₋₁) / 2h = X_u` and
//! `(X₁ − 2X₀ + X₋₁) / h² = X_uu`, both O(h²). Centred (ghost) differences keep the scheme's
//! error expansion symmetric and need no extra nodes, whereas one-sided second-order formulas
//! would need three nodes inward and break the symmetry; the measured order with ghosts is 2 in
//! both settings for `N = 1, 2, 3` (see the tests).
//!
//! Why not the factored form `Δ_a W = F, Δ_a X = W` (two Poisson solves for `N = 2`)? It needs
//! `W = Δ_a X` on the boundary, which the Bloor–Wilson conditions do not give: they give `X` and
//! `X_u`, a clamped plate, so `W` has no boundary condition of its own and the two solves are
//! coupled through the boundary. The full `(2N+1)²`-point stencil with ghost nodes is solved
//! as one sparse system instead (sparse LU with a fill-reducing column ordering, faer, and one
//! step of iterative refinement); the three components of `X` share that one factorisation.
//! Periodic in `v`, the system is block circulant, and [`solve_periodic`] solves it by a real FFT
//! in `v` and one banded solve per Fourier mode in `u` (module `periodic`), with the sparse form
//! ([`solve_periodic_sparse`]) kept as its reference. Four-sided with `N = 1, 2`, eliminating the
//! boundary and ghost nodes leaves a symmetric positive definite system `L_D^N + P D Pᵀ` in the
//! interior nodes (`L_D` the 5-point operator with zero boundary values, `P D Pᵀ` diagonal on
//! the nodes next to the boundary); [`solve_four_sided`] solves it by 2-D sine transforms and a
//! capacitance matrix (module `capacitance`), with the sparse form ([`solve_four_sided_sparse`])
//! as its reference and its solver for `N = 3`.
//!
//! The result ([`FdSurface`]) interpolates the node values by a bicubic spline (periodic in `v`
//! where the grid is), so it meshes, renders and analyses like any [`Surface`].

mod capacitance;
mod dst;
mod periodic;
mod spine;
mod spline;
#[cfg(test)]
mod tests;

use crate::surface::{Partials, Spine, Surface, VDomain};
use crate::{Error, Result, Vec3, TAU};
use faer::prelude::*;
use faer::sparse::{SparseColMat, Triplet};
use spline::NodeSpline;

/// Largest `N` supported: `(∂uu + a²∂vv)^N` up to the triharmonic operator.
pub const MAX_ORDER: usize = 3;

/// Largest number of unknowns (grid nodes with ghosts) a problem may have.
pub const MAX_UNKNOWNS: usize = 1 << 22;

/// Boundary data: a vector function of the parameter along one side.
pub type EdgeFn<'a> = &'a (dyn Fn(f64) -> Vec3 + Sync);

/// A right-hand side `F(u, v)`.
pub type SourceFn<'a> = &'a (dyn Fn(f64, f64) -> Vec3 + Sync);

/// `(∂uu + a²∂vv)^N X = F` on `[0, 1] × [0, 2π)`, periodic in `v`.
#[derive(Clone)]
pub struct PeriodicProblem<'a> {
    /// `N`, 1 to 3.
    pub order: usize,
    /// `a > 0`.
    pub a: f64,
    /// Intervals in `u` (step `1/nu`).
    pub nu: usize,
    /// Nodes over one period in `v` (step `2π/nv`).
    pub nv: usize,
    /// `start[d](v) = ∂ᵈX/∂uᵈ (0, v)`, `d = 0 … N−1`.
    pub start: Vec<EdgeFn<'a>>,
    /// `end[d](v) = ∂ᵈX/∂uᵈ (1, v)`, `d = 0 … N−1`.
    pub end: Vec<EdgeFn<'a>>,
    /// `F` (zero if `None`).
    pub source: Option<SourceFn<'a>>,
}

/// `(∂uu + a²∂vv)^N X = F` on `[0, 1] × [v₀, v₁]` with data on all four sides.
#[derive(Clone)]
pub struct FourSidedProblem<'a> {
    /// `N`, 1 to 3.
    pub order: usize,
    /// `a > 0`.
    pub a: f64,
    /// Intervals in `u` (step `1/nu`).
    pub nu: usize,
    /// Intervals in `v` (step `(v₁ − v₀)/nv`).
    pub nv: usize,
    /// `[v₀, v₁]`.
    pub v_range: (f64, f64),
    /// `u0[d](v) = ∂ᵈX/∂uᵈ (0, v)`, `d = 0 … N−1`.
    pub u0: Vec<EdgeFn<'a>>,
    /// `u1[d](v) = ∂ᵈX/∂uᵈ (1, v)`.
    pub u1: Vec<EdgeFn<'a>>,
    /// `v0[d](u) = ∂ᵈX/∂vᵈ (u, v₀)`.
    pub v0: Vec<EdgeFn<'a>>,
    /// `v1[d](u) = ∂ᵈX/∂vᵈ (u, v₁)`.
    pub v1: Vec<EdgeFn<'a>>,
    /// `F` (zero if `None`).
    pub source: Option<SourceFn<'a>>,
}

/// Size of the linear system that was solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SystemStats {
    /// Unknowns (nodes including ghost nodes).
    pub unknowns: usize,
    /// Nonzeros of the assembled matrix.
    pub nonzeros: usize,
}

/// A finite-difference solution: the node values and the bicubic spline through them.
#[derive(Clone, Debug)]
pub struct FdSurface {
    spline: NodeSpline,
    order: usize,
    a: f64,
    stats: SystemStats,
}

// Closest points by the general search (no closed form).
impl crate::surface::SurfaceNearest for FdSurface {}

impl FdSurface {
    /// Intervals in `u`: nodes `u_i = i / nu`, `i = 0 … nu`.
    pub fn nu(&self) -> usize {
        self.spline.nu
    }
    /// Nodes per row in `v` (`nv` for a periodic grid, `nv + 1` for a four-sided one).
    pub fn nodes_v(&self) -> usize {
        self.spline.mv
    }
    /// `v_j` of node column `j`.
    pub fn v_node(&self, j: usize) -> f64 {
        self.spline.v0 + j as f64 * self.spline.hv
    }
    /// `u_i` of node row `i`.
    pub fn u_node(&self, i: usize) -> f64 {
        i as f64 * self.spline.hu
    }
    /// The computed `X` at node `(u_i, v_j)`.
    pub fn node(&self, i: usize, j: usize) -> Vec3 {
        self.spline.data[i * self.spline.mv + j][0]
    }
    /// True for a grid periodic in `v`.
    pub fn periodic(&self) -> bool {
        self.spline.periodic
    }
    /// `N`.
    pub fn order(&self) -> usize {
        self.order
    }
    /// `a`.
    pub fn a(&self) -> f64 {
        self.a
    }
    /// The size of the linear system.
    pub fn stats(&self) -> SystemStats {
        self.stats
    }
}

impl Surface for FdSurface {
    fn v_domain(&self) -> VDomain {
        if self.spline.periodic {
            VDomain::Periodic
        } else {
            let s = &self.spline;
            VDomain::Interval(s.v0, s.v0 + (s.mv - 1) as f64 * s.hv)
        }
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        self.spline.partials(u, v)
    }
    /// On a grid periodic in `v`, the mean of the interpolant over `v` (see the [`Spine`]
    /// implementation); `None` for a four-sided patch, which has no spine.
    fn as_spine(&self) -> Option<&dyn Spine> {
        if self.spline.periodic {
            Some(self)
        } else {
            None
        }
    }
}

fn check_operator(order: usize, a: f64) -> Result<()> {
    if !(1..=MAX_ORDER).contains(&order) {
        return Err(Error::invalid(format!(
            "the finite-difference solver supports N = 1 to {MAX_ORDER} (got {order})"
        ))
        .at("order"));
    }
    if !(a.is_finite() && a > 0.0) {
        return Err(Error::invalid(format!("must be positive and finite (got {a})")).at("a"));
    }
    Ok(())
}

fn check_count(edges: &[EdgeFn<'_>], order: usize, place: &str) -> Result<()> {
    if edges.len() != order {
        return Err(Error::invalid(format!(
            "N = {order} needs {order} boundary function{} (derivative orders 0 to {}), got {}",
            if order == 1 { "" } else { "s" },
            order - 1,
            edges.len()
        ))
        .at(place));
    }
    Ok(())
}

fn check_intervals(n: usize, min: usize, place: &str) -> Result<()> {
    if n < min {
        return Err(Error::invalid(format!("must be at least {min} (got {n})")).at(place));
    }
    Ok(())
}

/// The coefficients of `δ²ᵐ` (the `m`-th power of the second difference), offsets `−m … m`:
/// `(−1)^{m+s} C(2m, m+s)`.
fn second_difference_power(m: usize) -> Vec<f64> {
    let n = 2 * m;
    let mut c = vec![0.0; n + 1];
    let mut binom = 1.0;
    for (k, ck) in c.iter_mut().enumerate() {
        // C(n, k)
        if k > 0 {
            binom = binom * (n + 1 - k) as f64 / k as f64;
        }
        *ck = if k % 2 == 0 { binom } else { -binom };
    }
    c
}

/// The stencil of `h_u^{2N} L_h^N` as `(offset u, offset v, coefficient)`.
fn stencil(order: usize, a: f64, hu: f64, hv: f64) -> Vec<(isize, isize, f64)> {
    let r2 = (a * hu / hv).powi(2);
    let mut out: Vec<(isize, isize, f64)> = Vec::new();
    let mut binom = 1.0;
    for k in 0..=order {
        if k > 0 {
            binom = binom * (order + 1 - k) as f64 / k as f64;
        }
        let w = binom * r2.powi(k as i32);
        let cu = second_difference_power(order - k);
        let cv = second_difference_power(k);
        let (mu, mv) = ((order - k) as isize, k as isize);
        for (p, &x) in cu.iter().enumerate() {
            for (q, &y) in cv.iter().enumerate() {
                let (du, dv) = (p as isize - mu, q as isize - mv);
                let c = w * x * y;
                match out.iter_mut().find(|e| e.0 == du && e.1 == dv) {
                    Some(e) => e.2 += c,
                    None => out.push((du, dv, c)),
                }
            }
        }
    }
    out
}

/// Central difference for the `k`-th derivative centred on the boundary node, as offsets and
/// coefficients of `h^k ∂ᵏ`. Narrow (one ghost layer): `k = 1`: `(X₁ − X₋₁)/2`, `k = 2`:
/// `X₁ − 2X₀ + X₋₁`, both O(h²). Wide (two ghost layers, `N = 3`): the five-point formulas
/// `(X₋₂ − 8X₋₁ + 8X₁ − X₂)/12` and `(−X₋₂ + 16X₋₁ − 30X₀ + 16X₁ − X₂)/12`, O(h⁴). With the
/// narrow pair, `X` and the two conditions would fix the first interior node by themselves
/// (`X₁ = X₀ + hX' + h²X''/2`), and beside a corner of a four-sided patch both sides would fix it:
/// a singular system. The wide pair leaves the interior node to the PDE.
fn derivative_stencil(k: usize, wide: bool) -> &'static [(isize, f64)] {
    const W: f64 = 1.0 / 12.0;
    match (k, wide) {
        (1, false) => &[(-1, -0.5), (1, 0.5)],
        (1, true) => &[(-2, W), (-1, -8.0 * W), (1, 8.0 * W), (2, -W)],
        (_, false) => &[(-1, 1.0), (0, -2.0), (1, 1.0)],
        (_, true) => &[
            (-2, -W),
            (-1, 16.0 * W),
            (0, -30.0 * W),
            (1, 16.0 * W),
            (2, -W),
        ],
    }
}

/// One row of the system: entries `(column, value)` and the right-hand side.
struct Row {
    entries: Vec<(usize, f64)>,
    rhs: Vec3,
}

/// The assembled system on the extended grid `i ∈ [−gu, nu + gu]`, `j ∈ [−gv, mv − 1 + gv]`
/// (`gv = 0` and `j` wrapped when periodic).
struct Layout {
    nu: usize,
    mv: usize,
    gu: usize,
    gv: usize,
    periodic: bool,
}

impl Layout {
    fn rows(&self) -> usize {
        self.nu + 1 + 2 * self.gu
    }
    fn cols(&self) -> usize {
        self.mv + 2 * self.gv
    }
    fn len(&self) -> usize {
        self.rows() * self.cols()
    }
    fn index(&self, i: isize, j: isize) -> usize {
        let j = if self.periodic {
            j.rem_euclid(self.mv as isize)
        } else {
            j
        };
        let ii = (i + self.gu as isize) as usize;
        let jj = (j + self.gv as isize) as usize;
        ii * self.cols() + jj
    }
}

/// Assembles the rows (one per unknown, in unknown order), factorises once and solves for the
/// three components; returns the node values `(nu + 1) × mv` and the system's size.
fn solve_system(layout: &Layout, rows: Vec<Row>) -> Result<(Vec<Vec3>, SystemStats)> {
    let n = layout.len();
    debug_assert_eq!(rows.len(), n);
    let mut triplets = Vec::new();
    let mut rhs = Mat::<f64>::zeros(n, 3);
    for (r, mut row) in rows.into_iter().enumerate() {
        row.entries.sort_by_key(|e| e.0);
        let mut last: Option<usize> = None;
        for (c, v) in row.entries {
            if last == Some(c) {
                let t: &mut Triplet<usize, usize, f64> = triplets.last_mut().expect("entry");
                t.val += v;
            } else {
                triplets.push(Triplet::new(r, c, v));
                last = Some(c);
            }
        }
        for k in 0..3 {
            rhs[(r, k)] = row.rhs[k];
        }
    }
    let nonzeros = triplets.len();
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
        .map_err(|e| Error::invalid(format!("cannot assemble the sparse matrix: {e:?}")))?;
    let lu = a
        .sp_lu()
        .map_err(|e| Error::invalid(format!("the difference system is singular: {e:?}")))?;
    let b = rhs.clone();
    lu.solve_in_place(rhs.as_mut());
    // One step of iterative refinement: the residual in working precision, solved again with the
    // same factors, brings the solution from `κ ε` of the data to about `ε` (for `κ ε ≪ 1`).
    let mut r = b;
    for t in &triplets {
        for k in 0..3 {
            r[(t.row, k)] -= t.val * rhs[(t.col, k)];
        }
    }
    lu.solve_in_place(r.as_mut());
    for k in 0..3 {
        for i in 0..n {
            rhs[(i, k)] += r[(i, k)];
        }
    }
    let mut x = Vec::with_capacity((layout.nu + 1) * layout.mv);
    for i in 0..=layout.nu {
        for j in 0..layout.mv {
            let r = layout.index(i as isize, j as isize);
            let p = Vec3::new(rhs[(r, 0)], rhs[(r, 1)], rhs[(r, 2)]);
            if !p.iter().all(|c| c.is_finite()) {
                return Err(Error::invalid(
                    "the difference system gave a non-finite solution (singular system)",
                ));
            }
            x.push(p);
        }
    }
    Ok((
        x,
        SystemStats {
            unknowns: n,
            nonzeros,
        },
    ))
}

/// Evaluates boundary data and refuses non-finite values, naming the place and parameter.
fn data(f: EdgeFn<'_>, t: f64, place: &str, d: usize, name: &str) -> Result<Vec3> {
    let p = f(t);
    if p.iter().all(|c| c.is_finite()) {
        Ok(p)
    } else {
        Err(
            Error::invalid(format!("not finite at {name} = {t} (got {p:?})"))
                .at(&format!("{place}[{d}]")),
        )
    }
}

fn source(f: Option<SourceFn<'_>>, u: f64, v: f64) -> Result<Vec3> {
    let Some(f) = f else {
        return Ok(Vec3::zeros());
    };
    let p = f(u, v);
    if p.iter().all(|c| c.is_finite()) {
        Ok(p)
    } else {
        Err(Error::invalid(format!("not finite at u = {u}, v = {v}")).at("source"))
    }
}

fn pde_row(
    layout: &Layout,
    st: &[(isize, isize, f64)],
    i: isize,
    j: isize,
    f: Vec3,
    scale: f64,
) -> Row {
    Row {
        entries: st
            .iter()
            .map(|&(du, dv, c)| (layout.index(i + du, j + dv), c))
            .collect(),
        rhs: f * scale,
    }
}

/// Solves a [`PeriodicProblem`]: a real FFT in `v` and one banded solve per Fourier mode in `u`
/// (module `periodic`); the same discrete solution as the sparse system of
/// [`solve_periodic_sparse`], to rounding, in a small fraction of its time.
pub fn solve_periodic(p: &PeriodicProblem<'_>) -> Result<FdSurface> {
    let layout = periodic_layout(p)?;
    let x = periodic::solve_modes(p)?;
    let hv = TAU / p.nv as f64;
    // The size of the system the modes solve together (that of the sparse form).
    let st = stencil(p.order, p.a, 1.0 / p.nu as f64, hv);
    let mut distinct: Vec<(isize, isize)> = st
        .iter()
        .map(|e| (e.0, e.1.rem_euclid(p.nv as isize)))
        .collect();
    distinct.sort_unstable();
    distinct.dedup();
    let g = layout.gu;
    let mut per_column = (p.nu - 1) * distinct.len();
    for k in 0..=g {
        let width = if k == 0 {
            1
        } else {
            derivative_stencil(k, p.order == 3).len()
        };
        per_column += if k == 0 { 2 } else { 2 * width };
    }
    Ok(FdSurface {
        spline: NodeSpline::new(x, p.nu, p.nv, true, 0.0, hv),
        order: p.order,
        a: p.a,
        stats: SystemStats {
            unknowns: layout.len(),
            nonzeros: per_column * p.nv,
        },
    })
}

fn periodic_layout(p: &PeriodicProblem<'_>) -> Result<Layout> {
    let n = p.order;
    check_operator(n, p.a)?;
    check_intervals(p.nu, (2 * n).max(4), "nu")?;
    check_intervals(p.nv, (2 * n + 1).max(4), "nv")?;
    check_count(&p.start, n, "start")?;
    check_count(&p.end, n, "end")?;
    let layout = Layout {
        nu: p.nu,
        mv: p.nv,
        gu: n - 1,
        gv: 0,
        periodic: true,
    };
    check_size(&layout)?;
    Ok(layout)
}

/// Solves a [`PeriodicProblem`] as one sparse system (sparse LU, faer): the reference that
/// [`solve_periodic`] is tested against.
pub fn solve_periodic_sparse(p: &PeriodicProblem<'_>) -> Result<FdSurface> {
    let n = p.order;
    let layout = periodic_layout(p)?;
    let hu = 1.0 / p.nu as f64;
    let hv = TAU / p.nv as f64;
    let st = stencil(n, p.a, hu, hv);
    let scale = hu.powi(2 * n as i32);
    let g = layout.gu as isize;
    let nu = p.nu as isize;
    let mut rows = Vec::with_capacity(layout.len());
    for i in -g..=nu + g {
        for j in 0..p.nv as isize {
            let v = j as f64 * hv;
            let u = i as f64 * hu;
            let row = if (1..nu).contains(&i) {
                pde_row(&layout, &st, i, j, source(p.source, u, v)?, scale)
            } else {
                // Boundary node b and the condition's derivative order k.
                let (b, k, edges, place) = if i <= 0 {
                    (0, (-i) as usize, &p.start, "start")
                } else {
                    (nu, (i - nu) as usize, &p.end, "end")
                };
                let val = data(edges[k], v, place, k, "v")?;
                let c = BoundaryCondition {
                    b,
                    k,
                    along_u: true,
                    wide: n == 3,
                    val,
                    h: hu,
                };
                boundary_row(&layout, j, &c)
            };
            rows.push(row);
        }
    }
    let (x, stats) = solve_system(&layout, rows)?;
    Ok(FdSurface {
        spline: NodeSpline::new(x, p.nu, p.nv, true, 0.0, hv),
        order: n,
        a: p.a,
        stats,
    })
}

/// A condition `∂ᵏX = val` centred on the boundary node `b` of a grid line (`along_u`: `b` is a
/// `u` index and the condition's differences run along `u`; else `b` is a `v` index), scaled by
/// `hᵏ`; `wide`: the first derivative by the wide stencil of `N = 3`.
struct BoundaryCondition {
    b: isize,
    k: usize,
    along_u: bool,
    wide: bool,
    val: Vec3,
    h: f64,
}

/// The row of condition `c` on grid line `j`: at node `(b, j)` (`along_u`) or `(j, b)` (along v,
/// with `b` the v index and `j` the u index).
fn boundary_row(layout: &Layout, j: isize, c: &BoundaryCondition) -> Row {
    let &BoundaryCondition {
        b,
        k,
        along_u,
        wide,
        val,
        h,
    } = c;
    let at = |s: isize| {
        if along_u {
            layout.index(b + s, j)
        } else {
            layout.index(j, b + s)
        }
    };
    if k == 0 {
        return Row {
            entries: vec![(at(0), 1.0)],
            rhs: val,
        };
    }
    Row {
        entries: derivative_stencil(k, wide)
            .iter()
            .map(|&(s, c)| (at(s), c))
            .collect(),
        rhs: val * h.powi(k as i32),
    }
}

fn check_size(layout: &Layout) -> Result<()> {
    let n = (layout.nu + 1 + 2 * layout.gu).checked_mul(layout.mv + 2 * layout.gv);
    if n.is_none_or(|n| n > MAX_UNKNOWNS) {
        return Err(Error::invalid(format!(
            "a {} × {} grid has more than {MAX_UNKNOWNS} unknowns; refusing to allocate it",
            layout.nu, layout.mv
        ))
        .at("nu × nv"));
    }
    Ok(())
}

/// Solves a [`FourSidedProblem`]. The corner values come from the sides `u = 0, 1`; the sides
/// `v = v₀, v₁` must agree with them there (to `1e-9` of the data's size).
///
/// For `N = 1, 2` the system is solved by sine transforms and a capacitance matrix on the nodes
/// next to the boundary (module `capacitance`): the same discrete solution as the sparse LU of
/// [`solve_four_sided_sparse`], to rounding, in a small fraction of its time. `N = 3` uses the
/// sparse LU.
pub fn solve_four_sided(p: &FourSidedProblem<'_>) -> Result<FdSurface> {
    let setup = FourSided::new(p)?;
    if p.order > 2 {
        return solve_four_sided_sparse(p);
    }
    let (x, stats) = capacitance::solve(p, &setup)?;
    Ok(setup.surface(p, x, stats))
}

/// Solves a [`FourSidedProblem`] as one sparse system (sparse LU with a fill-reducing column
/// ordering, faer): the reference that [`solve_four_sided`] is tested against, and its solver
/// for `N = 3`.
pub fn solve_four_sided_sparse(p: &FourSidedProblem<'_>) -> Result<FdSurface> {
    let setup = FourSided::new(p)?;
    let layout = &setup.layout;
    let mut rows = Vec::with_capacity(layout.len());
    setup.walk(p, |i, j, node| {
        rows.push(match node {
            FourSidedNode::Pde(f) => pde_row(layout, &setup.stencil, i, j, f, setup.scale),
            FourSidedNode::Condition(c) => {
                let line = if c.along_u { j } else { i };
                boundary_row(layout, line, &c)
            }
            FourSidedNode::Unused => Row {
                entries: vec![(layout.index(i, j), 1.0)],
                rhs: Vec3::zeros(),
            },
        });
        Ok(())
    })?;
    let (x, stats) = solve_system(layout, rows)?;
    Ok(setup.surface(p, x, stats))
}

/// What the four-sided system says at one node of the extended grid.
enum FourSidedNode {
    /// An interior node: the PDE, with the source `F` there (not yet scaled by `h_u^{2N}`).
    Pde(Vec3),
    /// A condition on the line through the node.
    Condition(BoundaryCondition),
    /// A ghost node that no interior stencil reaches (near the corners): `X = 0`.
    Unused,
}

/// The checked four-sided problem: grid, steps and stencil.
struct FourSided {
    layout: Layout,
    hu: f64,
    hv: f64,
    stencil: Vec<(isize, isize, f64)>,
    /// `h_u^{2N}`, the scale of the PDE rows.
    scale: f64,
}

impl FourSided {
    fn new(p: &FourSidedProblem<'_>) -> Result<Self> {
        let n = p.order;
        check_operator(n, p.a)?;
        check_intervals(p.nu, (2 * n).max(4), "nu")?;
        check_intervals(p.nv, (2 * n).max(4), "nv")?;
        let (va, vb) = p.v_range;
        if !(va.is_finite() && vb.is_finite() && va < vb) {
            return Err(Error::invalid(format!(
                "must be an increasing finite interval (got [{va}, {vb}])"
            ))
            .at("v_range"));
        }
        for (e, place) in [(&p.u0, "u0"), (&p.u1, "u1"), (&p.v0, "v0"), (&p.v1, "v1")] {
            check_count(e, n, place)?;
        }
        let g = n - 1;
        let layout = Layout {
            nu: p.nu,
            mv: p.nv + 1,
            gu: g,
            gv: g,
            periodic: false,
        };
        check_size(&layout)?;
        // Corners.
        let mut size: f64 = 1e-300;
        let mut corners = Vec::new();
        for (ue, u) in [(&p.u0, 0.0), (&p.u1, 1.0)] {
            for (ve, v, vplace) in [(&p.v0, va, "v0"), (&p.v1, vb, "v1")] {
                let a = ue[0](v);
                let b = ve[0](u);
                size = size.max(a.norm()).max(b.norm());
                corners.push((a, b, u, v, vplace));
            }
        }
        for (a, b, u, v, vplace) in corners {
            // (Non-finite data are reported where the nodes are set.)
            if (a - b).norm() > 1e-9 * size {
                return Err(Error::invalid(format!(
                    "does not meet the side u = {u} at its corner (u, v) = ({u}, {v}): {b:?} against {a:?}"
                ))
                .at(&format!("{vplace}[0]")));
            }
        }
        let hu = 1.0 / p.nu as f64;
        let hv = (vb - va) / p.nv as f64;
        Ok(FourSided {
            layout,
            hu,
            hv,
            stencil: stencil(n, p.a, hu, hv),
            scale: hu.powi(2 * n as i32),
        })
    }

    /// Visits every node of the extended grid in unknown order (`i` outer, `j` inner, from
    /// `−g` to `nu + g` and `nv + g`), evaluating the data there; the first non-finite datum stops
    /// the walk with its place.
    fn walk(
        &self,
        p: &FourSidedProblem<'_>,
        mut visit: impl FnMut(isize, isize, FourSidedNode) -> Result<()>,
    ) -> Result<()> {
        let n = p.order;
        let layout = &self.layout;
        let (hu, hv, va) = (self.hu, self.hv, p.v_range.0);
        let (g, nu, nv) = (n as isize - 1, p.nu as isize, p.nv as isize);
        // Ghost nodes that no interior stencil reaches (near the corners: for N = 3 the second
        // ghost layer beside a corner) take no condition; the corner's data are already set by
        // the other nodes.
        let mut referenced = vec![false; layout.len()];
        for i in 1..nu {
            for j in 1..nv {
                for &(du, dv, _) in &self.stencil {
                    referenced[layout.index(i + du, j + dv)] = true;
                }
            }
        }
        for i in -g..=nu + g {
            for j in -g..=nv + g {
                let u = i as f64 * hu;
                let v = va + j as f64 * hv;
                let in_u = (0..=nu).contains(&i);
                let in_v = (0..=nv).contains(&j);
                let ghost = !(in_u && in_v);
                let node = if ghost && !referenced[layout.index(i, j)] {
                    FourSidedNode::Unused
                } else if (1..nu).contains(&i) && (1..nv).contains(&j) {
                    FourSidedNode::Pde(source(p.source, u, v)?)
                } else if in_v && !(1..nu).contains(&i) {
                    // Sides u = 0, 1 (with the corners) and their ghosts.
                    let (b, k, e, place) = if i <= 0 {
                        (0, (-i) as usize, &p.u0, "u0")
                    } else {
                        (nu, (i - nu) as usize, &p.u1, "u1")
                    };
                    let val = data(e[k], v, place, k, "v")?;
                    let second = if b == 0 { -2 } else { nu + 2 };
                    FourSidedNode::Condition(BoundaryCondition {
                        b,
                        k,
                        along_u: true,
                        wide: n == 3 && referenced[layout.index(second, j)],
                        val,
                        h: hu,
                    })
                } else if in_u {
                    // Sides v = v₀, v₁ and their ghosts.
                    let (b, k, e, place) = if j <= 0 {
                        (0, (-j) as usize, &p.v0, "v0")
                    } else {
                        (nv, (j - nv) as usize, &p.v1, "v1")
                    };
                    let val = data(e[k], u, place, k, "u")?;
                    let second = if b == 0 { -2 } else { nv + 2 };
                    FourSidedNode::Condition(BoundaryCondition {
                        b,
                        k,
                        along_u: false,
                        wide: n == 3 && referenced[layout.index(i, second)],
                        val,
                        h: hv,
                    })
                } else {
                    unreachable!("corner ghosts are never referenced")
                };
                visit(i, j, node)?;
            }
        }
        Ok(())
    }

    fn surface(&self, p: &FourSidedProblem<'_>, x: Vec<Vec3>, stats: SystemStats) -> FdSurface {
        FdSurface {
            spline: NodeSpline::new(x, p.nu, p.nv + 1, false, p.v_range.0, self.hv),
            order: p.order,
            a: p.a,
            stats,
        }
    }
}
