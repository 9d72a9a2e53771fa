//! Dynamic PDE curves (X.-Z. Liu, X. Cui, G.-Q. Zheng, J.-H. Yong, J.-G. Sun, *Dynamic PDE
//! parametric curves*, J. Comput. Appl. Math. 2008).
//!
//! A planar or space curve `C(u, t) = (x(u, t), y(u, t)[, z(u, t)])`, `u ∈ [0, 1]`, moves under
//! one fourth-order hyperbolic equation per component (paper Eqs. 3 and 5):
//!
//! ```text
//! x_tt + a(u,t,x) x_t − (b(u,t,x) x_u)_u + (d(u,t,x) x_uu)_uu = f(u,t,x),
//! x(u,0) = x₀(u),  x_t(u,0) = v₀(u),
//! x(0,t) = p₀(t),  x(1,t) = p₁(t),  x_u(0,t) = s₀(t),  x_u(1,t) = s₁(t),
//! ```
//!
//! `a` is damping, `b` tension, `d` bending stiffness, `f` the external force. The components do not
//! interact through the equation, so each is advanced on its own by the three-level scheme (6)
//! ([`Scheme`]).
//!
//! # The grid and the end conditions
//!
//! `u_j = j h`, `h = 1/J`, `t_n = n Δt`, `Δt = T/L`. At every level the `J + 1` values are fixed by
//!
//! * row 0 and row `J`: the positions, `X_0 = p₀(t)`, `X_J = p₁(t)`;
//! * row 1 and row `J − 1`: the derivative conditions, imposed by the third-order one-sided
//!   differences `(−11X_0 + 18X_1 − 9X_2 + 2X_3)/(6h) = s₀(t)` and
//!   `(11X_J − 18X_{J−1} + 9X_{J−2} − 2X_{J−3})/(6h) = s₁(t)`;
//! * rows `2 ..= J − 2`: the difference equation (6), whose five-point stencil `j − 2 ..= j + 2`
//!   then stays inside the grid.
//!
//! This is the paper's own arrangement (it prescribes `X_1` and `X_{J−1}` and writes equation (6)
//! for `j = 2 ..= J − 2` in its analysis), with the first-order `X_1 = X_0 + h s₀` replaced by a
//! one-sided difference of third order so the boundary rows do not limit the `O(h² + Δt²)`
//! accuracy for non-zero slopes (the row couples `X_0 ..= X_3`, still inside the pentadiagonal
//! band). We deliberately do not use ghost points (equation (6) at `j = 1` with a fictitious
//! `X_{−1} = X_1 − 2h s₀`): there the ghost value enters only through the term `d_0 δ²X_0`, and in the
//! paper's own experiment (§3.3, `d = x`, which vanishes at the ends) `d_0 = 0`, so the slope
//! condition would silently drop out of the discrete problem.
//!
//! In each step the end rows are eliminated exactly (`X_0`, `X_J` are known, `X_1`, `X_{J−1}` are
//! the one-sided formulas solved for them), which leaves one banded system with two sub- and two
//! super-diagonals for `X_2 ..= X_{J−2}` per component; the cost is `O(J)` per step. Eliminating
//! rather than solving the end rows together with the stiff interior rows keeps the end conditions
//! satisfied to rounding of the formulas themselves, independent of the conditioning
//! (`~ Δt² d / h⁴`) of the interior system.
//!
//! # Cost of a step
//!
//! A step evaluates the four fields over the whole level ([`Field::fill`]: one loop per field, in
//! which a closure's body is inlined), then assembles the rows in order and hands each to the
//! streaming solver `linalg::band::Penta`, which factorises it without pivoting as it arrives, so the
//! serial chain of pivots overlaps the assembly. The unpivoted factors are used when an
//! a-posteriori growth test certifies them backward stable, else the step is solved again by LU
//! with partial pivoting inside the band; factor rows are reused while the rows equal the previous
//! step's (constant coefficients).

pub mod formula;
pub use frame::CurveFrame;
mod frame;
pub mod interp;
pub mod ode;
pub mod spline;

use std::sync::Arc;

use crate::linalg::band::Penta;
use crate::{Error, Result};

/// A coefficient or force `φ(u, t, x)` of one component (paper §3: `a, b, d, f`), shared (cheap
/// to clone). Made by [`field`] from a closure or by [`constant_field`]. The scheme evaluates a
/// whole level at once through [`Field::fill`], whose loop over the nodes is compiled for each
/// closure, so the closure's body is inlined there rather than called through a pointer per node.
#[derive(Clone)]
pub struct Field(Arc<dyn FieldFn>);

/// What a [`Field`] holds: a closure or a constant.
trait FieldFn: Send + Sync {
    fn at(&self, u: f64, t: f64, x: f64) -> f64;
    fn fill(&self, offset: f64, h: f64, t: f64, x: &[f64], out: &mut [f64]);
}

struct Closure<F>(F);

impl<F: Fn(f64, f64, f64) -> f64 + Send + Sync> FieldFn for Closure<F> {
    fn at(&self, u: f64, t: f64, x: f64) -> f64 {
        (self.0)(u, t, x)
    }

    fn fill(&self, offset: f64, h: f64, t: f64, x: &[f64], out: &mut [f64]) {
        for (k, (o, &xk)) in out.iter_mut().zip(x).enumerate() {
            *o = (self.0)((k as f64 + offset) * h, t, xk);
        }
    }
}

struct Constant(f64);

impl FieldFn for Constant {
    fn at(&self, _: f64, _: f64, _: f64) -> f64 {
        self.0
    }

    fn fill(&self, _: f64, _: f64, _: f64, _: &[f64], out: &mut [f64]) {
        out.fill(self.0);
    }
}

impl Field {
    /// `φ(u, t, x)`.
    pub fn at(&self, u: f64, t: f64, x: f64) -> f64 {
        self.0.at(u, t, x)
    }

    /// `out[k] = φ((k + offset) h, t, x[k])` for every `k` (`x` and `out` of equal length).
    pub fn fill(&self, offset: f64, h: f64, t: f64, x: &[f64], out: &mut [f64]) {
        assert_eq!(x.len(), out.len(), "Field::fill needs one x per output");
        self.0.fill(offset, h, t, x, out);
    }
}

/// A function of one variable: an end condition of `t` or an initial profile of `u`.
pub type Scalar = Arc<dyn Fn(f64) -> f64 + Send + Sync>;

/// Watches a run: called after every level `n` with `t_n` and, on the levels asked for, the nodal
/// points `C(u_j, t_n)`.
pub type Observer<'a> = dyn FnMut(usize, f64, Option<&[crate::Vec3]>) + 'a;

/// Wraps a closure `(u, t, x) ↦ φ` as a [`Field`].
pub fn field(f: impl Fn(f64, f64, f64) -> f64 + Send + Sync + 'static) -> Field {
    Field(Arc::new(Closure(f)))
}

/// The constant field `φ ≡ c`.
pub fn constant_field(c: f64) -> Field {
    Field(Arc::new(Constant(c)))
}

/// Wraps a closure of one variable as a [`Scalar`].
pub fn scalar(f: impl Fn(f64) -> f64 + Send + Sync + 'static) -> Scalar {
    Arc::new(f)
}

/// The constant function `≡ c`.
pub fn constant(c: f64) -> Scalar {
    Arc::new(move |_| c)
}

/// One component `x(u, t)` of a dynamic PDE curve: Eq. (5) with non-zero, time-dependent end
/// conditions (Eq. 4 with the §3.3 generalisation `x_u(0,t) = s₀(t)`).
#[derive(Clone)]
pub struct Component {
    /// Damping `a(u, t, x)`.
    pub a: Field,
    /// Tension `b(u, t, x)`.
    pub b: Field,
    /// Bending stiffness `d(u, t, x)`.
    pub d: Field,
    /// External force `f(u, t, x)`.
    pub f: Field,
    /// `p₀(t) = x(0, t)`.
    pub start: Scalar,
    /// `p₁(t) = x(1, t)`.
    pub end: Scalar,
    /// `s₀(t) = x_u(0, t)`.
    pub start_slope: Scalar,
    /// `s₁(t) = x_u(1, t)`.
    pub end_slope: Scalar,
    /// Initial position `x₀(u) = x(u, 0)`.
    pub position: Scalar,
    /// Initial velocity `v₀(u) = x_t(u, 0)`.
    pub velocity: Scalar,
}

impl Component {
    /// Checks that `a ≥ 0`, `b ≥ 0` and `d > 0` (the lower bounds the paper's theory assumes, with
    /// its remark that `a` or `b` may vanish) at the nodes `u_j = j/samples`, times
    /// `t = k T / samples`, evaluated along the initial profile. Reports the first violation.
    pub fn check_positivity(&self, t_end: f64, samples: usize) -> Result<()> {
        let samples = samples.max(1);
        for k in 0..=samples {
            let t = t_end * k as f64 / samples as f64;
            for j in 0..=samples {
                let u = j as f64 / samples as f64;
                let x = (self.position)(u);
                let checks = [
                    ("a", self.a.at(u, t, x), false),
                    ("b", self.b.at(u, t, x), false),
                    ("d", self.d.at(u, t, x), true),
                ];
                for (name, v, strict) in checks {
                    let bad = !v.is_finite() || v < 0.0 || (strict && v == 0.0);
                    if bad {
                        return Err(Error::invalid(format!(
                            "{name}(u = {u}, t = {t}, x = {x}) = {v}; the theory needs {}",
                            if strict { "> 0" } else { ">= 0" }
                        ))
                        .at(name));
                    }
                }
            }
        }
        Ok(())
    }
}

/// The space–time grid of the scheme: `J` intervals in `u`, `L` steps up to `t = T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeGrid {
    /// `J ≥ 5`, the number of intervals of `[0, 1]`.
    pub intervals: usize,
    /// `L ≥ 1`, the number of time steps.
    pub steps: usize,
    /// `T > 0`, the final time.
    pub t_end: f64,
}

impl TimeGrid {
    /// Checks `J ≥ 5`, `L ≥ 1`, `T` finite and positive.
    pub fn validate(&self) -> Result<()> {
        if self.intervals < 5 {
            return Err(Error::invalid(format!(
                "J = {} intervals; the stencil and the one-sided end rows need at least 5",
                self.intervals
            ))
            .at("intervals"));
        }
        if self.steps == 0 {
            return Err(Error::invalid("L = 0 steps; at least one is needed").at("steps"));
        }
        if !(self.t_end.is_finite() && self.t_end > 0.0) {
            return Err(
                Error::invalid(format!("T = {}; must be finite and > 0", self.t_end)).at("t_end"),
            );
        }
        Ok(())
    }

    /// `h = 1/J`.
    pub fn h(&self) -> f64 {
        1.0 / self.intervals as f64
    }

    /// `Δt = T/L`.
    pub fn dt(&self) -> f64 {
        self.t_end / self.steps as f64
    }

    /// The nodes `u_j = j h`, `j = 0 ..= J`.
    pub fn nodes(&self) -> Vec<f64> {
        (0..=self.intervals)
            .map(|j| j as f64 / self.intervals as f64)
            .collect()
    }
}

/// The discrete bending energy `Σ_{j=1}^{J−1} |δ²C_j|² h` of nodal points `C_j = C(j/J)` (the
/// square of the paper's `‖δ²C‖`), a measure of fairness.
pub fn bending_energy(nodes: &[crate::Vec3]) -> f64 {
    if nodes.len() < 3 {
        return 0.0;
    }
    let jn = nodes.len() - 1;
    let h = 1.0 / jn as f64;
    (1..jn)
        .map(|j| ((nodes[j + 1] - nodes[j] * 2.0 + nodes[j - 1]) / (h * h)).norm_squared())
        .sum::<f64>()
        * h
}

/// The end slopes `C_u(0)`, `C_u(1)` of nodal points as the scheme imposes them: the third-order
/// one-sided differences `(−11C_0 + 18C_1 − 9C_2 + 2C_3)/(6h)` and its mirror. Needs `J ≥ 3`.
pub fn end_slopes(nodes: &[crate::Vec3]) -> (crate::Vec3, crate::Vec3) {
    let n = nodes.len() - 1;
    let h = 1.0 / n as f64;
    let s0 = (nodes[1] * 18.0 - nodes[0] * 11.0 - nodes[2] * 9.0 + nodes[3] * 2.0) / (6.0 * h);
    let s1 = (nodes[n] * 11.0 - nodes[n - 1] * 18.0 + nodes[n - 2] * 9.0 - nodes[n - 3] * 2.0)
        / (6.0 * h);
    (s0, s1)
}

/// The discrete `L²` norm of the paper, `‖φ‖ = (Σ_{j=0}^{J} φ_j² h)^{1/2}`.
pub fn l2_norm(values: &[f64], h: f64) -> f64 {
    (values.iter().map(|v| v * v).sum::<f64>() * h).sqrt()
}

/// The five weights `w_{−2..=2}` of the spatial operator of (6) at row `j`:
/// `(Λ X)_j = −(1/h)[b_{j+1/2} δX_j − b_{j−1/2} δX_{j−1}]
///           + (1/h²)[d_{j+1} δ²X_{j+1} − 2 d_j δ²X_j + d_{j−1} δ²X_{j−1}] = Σ_k w_k X_{j+k}`.
/// `ih2 = 1/h²`, `ih4 = 1/h⁴`.
#[inline(always)]
fn stencil(bh: &[f64], d: &[f64], j: usize, ih2: f64, ih4: f64) -> [f64; 5] {
    let (bm, bp) = (bh[j - 1], bh[j]);
    let (dm, d0, dp) = (d[j - 1], d[j], d[j + 1]);
    [
        dm * ih4,
        -bm * ih2 - 2.0 * (d0 + dm) * ih4,
        (bm + bp) * ih2 + (dp + 4.0 * d0 + dm) * ih4,
        -bp * ih2 - 2.0 * (dp + d0) * ih4,
        dp * ih4,
    ]
}

#[inline(always)]
fn apply(w: &[f64; 5], x: &[f64], j: usize) -> f64 {
    w[0] * x[j - 2] + w[1] * x[j - 1] + w[2] * x[j] + w[3] * x[j + 1] + w[4] * x[j + 2]
}

/// Row `j ∈ {2, 3, J − 3, J − 2}` of the step's system with the end values eliminated:
/// `row = [A_{j,j−2}, …, A_{j,j+2}]` over `X_{j−2} ..= X_{j+2}` and its right-hand side `r`
/// become the row over the unknowns `X_2 ..= X_{J−2}` (same offsets, relative to the unknown
/// `j − 2`). `ends = [p₀, left, right, p₁]`: `X_0 = p₀`, `X_J = p₁`,
/// `X_1 = left + X_2/2 − X_3/9`, `X_{J−1} = right + X_{J−2}/2 − X_{J−3}/9`.
fn eliminate_ends(
    row: [f64; 5],
    mut r: f64,
    j: usize,
    jn: usize,
    ends: [f64; 4],
) -> ([f64; 5], f64) {
    let [p0, left, right, p1] = ends;
    let mut out = [0.0; 5];
    // Column c of the grid is offset c + 2 − j; the unknown X_c sits at the same offset.
    for (k, &val) in row.iter().enumerate() {
        let c = j + k - 2;
        if c == 0 {
            r -= val * p0;
        } else if c == jn {
            r -= val * p1;
        } else if c == 1 {
            r -= val * left;
            out[4 - j] += val * 0.5;
            out[5 - j] -= val / 9.0;
        } else if c == jn - 1 {
            r -= val * right;
            out[jn - j] += val * 0.5;
            out[jn - j - 1] -= val / 9.0;
        } else {
            out[k] += val;
        }
    }
    (out, r)
}

/// Coefficients at level `n` (paper §3.1 notation): `a_j^n, d_j^n, f_j^n` at the nodes with
/// `X_j^n`, and `b_{j+1/2}^n` at the midpoints with `(X_j^n + X_{j+1}^n)/2` (kept in `xm`).
struct Level {
    a: Vec<f64>,
    bh: Vec<f64>,
    d: Vec<f64>,
    f: Vec<f64>,
    xm: Vec<f64>,
}

fn finite_or_err(name: &str, v: f64, u: f64, t: f64, x: f64) -> Result<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::invalid(format!(
            "{name}(u = {u}, t = {t}, x = {x}) = {v} is not finite"
        ))
        .at(name))
    }
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().fold(true, |ok, v| ok & v.is_finite())
}

impl Level {
    fn empty() -> Level {
        Level {
            a: Vec::new(),
            bh: Vec::new(),
            d: Vec::new(),
            f: Vec::new(),
            xm: Vec::new(),
        }
    }

    /// Evaluates the coefficients of level `n` at time `t` into the buffers of `self`, one field
    /// at a time over the whole level. With `positivity`, refuses `a < 0`, `b < 0` or `d ≤ 0` at
    /// any node (midpoint for `b`).
    fn evaluate(
        &mut self,
        comp: &Component,
        x: &[f64],
        t: f64,
        h: f64,
        positivity: bool,
    ) -> Result<()> {
        let n = x.len();
        for v in [&mut self.a, &mut self.d, &mut self.f] {
            v.resize(n, 0.0);
        }
        self.bh.resize(n - 1, 0.0);
        self.xm.clear();
        self.xm.extend(x.windows(2).map(|w| 0.5 * (w[0] + w[1])));
        comp.a.fill(0.0, h, t, x, &mut self.a);
        comp.d.fill(0.0, h, t, x, &mut self.d);
        comp.f.fill(0.0, h, t, x, &mut self.f);
        comp.b.fill(0.5, h, t, &self.xm, &mut self.bh);
        let finite =
            all_finite(&self.a) & all_finite(&self.d) & all_finite(&self.f) & all_finite(&self.bh);
        self.validate(finite, x, t, h, positivity)
    }

    /// After all values of a level were evaluated (`finite`: whether all are finite): the first
    /// non-finite value in the order `a, d, f` per node, then `b` per midpoint, is an error; with
    /// `positivity`, so is the first violation of the lower bounds.
    fn validate(&self, finite: bool, x: &[f64], t: f64, h: f64, positivity: bool) -> Result<()> {
        if !finite {
            for (j, &xj) in x.iter().enumerate() {
                let u = j as f64 * h;
                finite_or_err("a", self.a[j], u, t, xj)?;
                finite_or_err("d", self.d[j], u, t, xj)?;
                finite_or_err("f", self.f[j], u, t, xj)?;
            }
            for (j, (&b, &xm)) in self.bh.iter().zip(&self.xm).enumerate() {
                finite_or_err("b", b, (j as f64 + 0.5) * h, t, xm)?;
            }
        }
        if positivity {
            self.check_positivity(x, t, h)?;
        }
        Ok(())
    }

    fn check_positivity(&self, x: &[f64], t: f64, h: f64) -> Result<()> {
        let bad = |name: &str, v: f64, u: f64, xv: f64, strict: bool| {
            Error::invalid(format!(
                "{name}(u = {u}, t = {t}, x = {xv}) = {v}; the theory of the scheme needs \
                 {name} {} (check_positivity is on)",
                if strict { "> 0" } else { ">= 0" }
            ))
            .at(name)
        };
        for (j, &xj) in x.iter().enumerate() {
            let u = j as f64 * h;
            if self.a[j] < 0.0 {
                return Err(bad("a", self.a[j], u, xj, false));
            }
            if self.d[j] <= 0.0 {
                return Err(bad("d", self.d[j], u, xj, true));
            }
        }
        for (j, &b) in self.bh.iter().enumerate() {
            if b < 0.0 {
                let xm = 0.5 * (x[j] + x[j + 1]);
                return Err(bad("b", b, (j as f64 + 0.5) * h, xm, false));
            }
        }
        Ok(())
    }
}

/// The three-level finite-difference scheme (6) for one component.
///
/// With `X̄^n = (X^{n+1} + X^{n−1})/2`, `∂_t X^n = (X^{n+1} − X^{n−1})/(2Δt)` and
/// `∂_tt X^n = (X^{n+1} − 2X^n + X^{n−1})/Δt²`, row `j = 2 ..= J − 2` reads
///
/// ```text
/// ∂_tt X_j^n + a_j^n ∂_t X_j^n + (Λ^n X̄^n)_j = f_j^n,
/// ```
///
/// where `Λ^n` is the operator of (6) with coefficients frozen at level `n`. Because the unknown
/// `X^{n+1}` enters only through the averages, each step is the linear pentadiagonal system
///
/// ```text
/// (1 + a_j Δt/2) X_j^{n+1} + (Δt²/2)(Λ X^{n+1})_j
///     = 2X_j^n − (1 − a_j Δt/2) X_j^{n−1} − (Δt²/2)(Λ X^{n−1})_j + Δt² f_j^n,
/// ```
///
/// completed by the end rows described in the [module documentation](self), all at `t_{n+1}`.
///
/// The second level comes from the Taylor start of §3.1,
/// `X_j^1 = X_j^0 + Δt v₀(u_j) + (Δt²/2) x_tt(u_j, 0)`, where `x_tt(·, 0) = f − a v₀ − Λ x₀` is the
/// PDE evaluated at `t = 0` (the paper prints `x_t0` for this `x_tt0`); `Λ x₀` is the discrete
/// operator applied to the initial profile (second-order accurate). Rows 0, 1, `J−1`, `J` of level 1
/// come from the end conditions at `t = Δt`.
pub struct Scheme<'a> {
    comp: &'a Component,
    grid: TimeGrid,
    h: f64,
    dt: f64,
    level: usize,
    previous: Vec<f64>,
    current: Vec<f64>,
    matrix: Penta,
    solution: Vec<f64>,
    coefficients: Level,
    positivity: bool,
}

impl<'a> Scheme<'a> {
    /// Sets up levels 0 and 1 (the scheme is then at `n = 1`, `t = Δt`).
    pub fn new(comp: &'a Component, grid: TimeGrid) -> Result<Self> {
        Self::with_positivity(comp, grid, false)
    }

    /// As [`Scheme::new`]; with `positivity`, every level's coefficients are checked for the
    /// lower bounds the paper's theory assumes (`a ≥ 0`, `b ≥ 0` at the midpoints, `d > 0` at the
    /// nodes, evaluated on the current solution, as the scheme uses them), and the first
    /// violation is an error naming `u, t, x` and the value.
    pub fn with_positivity(comp: &'a Component, grid: TimeGrid, positivity: bool) -> Result<Self> {
        grid.validate()?;
        let h = grid.h();
        let dt = grid.dt();
        let jn = grid.intervals;
        let mut x0 = Vec::with_capacity(jn + 1);
        let mut v0 = Vec::with_capacity(jn + 1);
        for j in 0..=jn {
            let u = j as f64 * h;
            let p = (comp.position)(u);
            let v = (comp.velocity)(u);
            if !p.is_finite() {
                return Err(
                    Error::invalid(format!("x(u = {u}, 0) = {p} is not finite")).at("position")
                );
            }
            if !v.is_finite() {
                return Err(
                    Error::invalid(format!("x_t(u = {u}, 0) = {v} is not finite")).at("velocity"),
                );
            }
            x0.push(p);
            v0.push(v);
        }
        let mut lv = Level::empty();
        lv.evaluate(comp, &x0, 0.0, h, positivity)?;
        let mut x1 = vec![0.0; jn + 1];
        for j in 2..=jn - 2 {
            let w = stencil(&lv.bh, &lv.d, j, 1.0 / (h * h), 1.0 / (h * h * h * h));
            let xtt = lv.f[j] - lv.a[j] * v0[j] - apply(&w, &x0, j);
            x1[j] = x0[j] + dt * v0[j] + 0.5 * dt * dt * xtt;
        }
        let mut scheme = Scheme {
            comp,
            grid,
            h,
            dt,
            level: 1,
            previous: x0,
            current: Vec::new(),
            matrix: Penta::zeros(jn - 3),
            solution: vec![0.0; jn - 3],
            coefficients: lv,
            positivity,
        };
        scheme.impose_ends(&mut x1, dt)?;
        scheme.current = x1;
        Ok(scheme)
    }

    /// Fills rows 0, 1, `J−1`, `J` of a level from the end conditions at time `t`, given rows
    /// `2 ..= J−2`: the positions, and `X_1`, `X_{J−1}` solved from the third-order one-sided
    /// differences `6h·s₀ = −11X_0 + 18X_1 − 9X_2 + 2X_3` (and its mirror at `u = 1`), which are
    /// exact for cubics.
    fn impose_ends(&self, x: &mut [f64], t: f64) -> Result<()> {
        let (p0, p1, s0, s1) = self.ends(t)?;
        let jn = self.grid.intervals;
        let h = self.h;
        x[0] = p0;
        x[jn] = p1;
        x[1] = (6.0 * h * s0 + 11.0 * p0 + 9.0 * x[2] - 2.0 * x[3]) / 18.0;
        x[jn - 1] = (11.0 * p1 + 9.0 * x[jn - 2] - 2.0 * x[jn - 3] - 6.0 * h * s1) / 18.0;
        Ok(())
    }

    fn ends(&self, t: f64) -> Result<(f64, f64, f64, f64)> {
        let c = self.comp;
        let vals = [
            ("start", (c.start)(t)),
            ("end", (c.end)(t)),
            ("start_slope", (c.start_slope)(t)),
            ("end_slope", (c.end_slope)(t)),
        ];
        for (name, v) in vals {
            if !v.is_finite() {
                return Err(
                    Error::invalid(format!("{name}(t = {t}) = {v} is not finite")).at(name),
                );
            }
        }
        Ok((vals[0].1, vals[1].1, vals[2].1, vals[3].1))
    }

    /// The current level `n`.
    pub fn level(&self) -> usize {
        self.level
    }

    /// The current time `t_n = n Δt`.
    pub fn time(&self) -> f64 {
        self.level as f64 * self.dt
    }

    /// The grid.
    pub fn grid(&self) -> TimeGrid {
        self.grid
    }

    /// `X^n`, the values at the nodes `u_j = j h`.
    pub fn values(&self) -> &[f64] {
        &self.current
    }

    /// `X^{n−1}`.
    pub fn previous(&self) -> &[f64] {
        &self.previous
    }

    /// Whether the final level `L` has been reached.
    pub fn finished(&self) -> bool {
        self.level >= self.grid.steps
    }

    /// Advances from level `n` to `n + 1` (one pentadiagonal solve).
    pub fn step(&mut self) -> Result<()> {
        self.step_with_force(None)
    }

    /// Advances one level with an additional force `g_j` added to `f_j^n` at every node (used when
    /// the force depends on the whole curve, as the attraction forces of §4 do).
    pub fn step_with_force(&mut self, extra: Option<&[f64]>) -> Result<()> {
        let jn = self.grid.intervals;
        if let Some(g) = extra {
            if g.len() != jn + 1 {
                return Err(Error::invalid(format!(
                    "extra force has {} values, the grid has {}",
                    g.len(),
                    jn + 1
                )));
            }
        }
        let (h, dt) = (self.h, self.dt);
        let t_n = self.time();
        let t_next = t_n + dt;
        let (p0, p1, s0, s1) = match self.ends(t_next) {
            Ok(ends) => ends,
            Err(e) => {
                // Report a broken coefficient of this level before a broken end condition.
                let mut lv = Level::empty();
                lv.evaluate(self.comp, &self.current, t_n, h, self.positivity)?;
                return Err(e);
            }
        };
        let comp = self.comp;
        let lv = &mut self.coefficients;
        let m = &mut self.matrix;
        let half = 0.5 * dt * dt;
        // Unknowns X_2 ..= X_{J−2} (index j − 2). The end rows are eliminated exactly:
        // X_0 = p₀, X_J = p₁ and, from the one-sided slope rows,
        // X_1 = (6h s₀ + 11 X_0 + 9 X_2 − 2 X_3)/18, X_{J−1} = (11 X_J + 9 X_{J−2} − 2 X_{J−3} − 6h s₁)/18.
        let left = (6.0 * h * s0 + 11.0 * p0) / 18.0;
        let right = (11.0 * p1 - 6.0 * h * s1) / 18.0;
        let (ih2, ih4) = (1.0 / (h * h), 1.0 / (h * h * h * h));
        let dt2 = dt * dt;
        let (cur, prev) = (&self.current[..=jn], &self.previous[..=jn]);
        // The coefficients of level n (user code, called in one pass of its own), then one pass
        // over the rows that assembles row j and does its step of the factorisation: the serial
        // chain of pivots runs alongside the assembly's arithmetic.
        lv.evaluate(comp, cur, t_n, h, self.positivity)?;
        let mut stream = m.begin();
        for j in 2..=jn - 2 {
            let w = stencil(&lv.bh, &lv.d, j, ih2, ih4);
            let ad = 0.5 * lv.a[j] * dt;
            let force = lv.f[j] + extra.map_or(0.0, |g| g[j]);
            let r = 2.0 * cur[j] - (1.0 - ad) * prev[j] - half * apply(&w, prev, j) + dt2 * force;
            let row = [
                half * w[0],
                half * w[1],
                1.0 + ad + half * w[2],
                half * w[3],
                half * w[4],
            ];
            if j >= 4 && j + 4 <= jn {
                m.push(&mut stream, j - 2, row, r);
            } else {
                let (row, r) = eliminate_ends(row, r, j, jn, [p0, left, right, p1]);
                m.push(&mut stream, j - 2, row, r);
            }
        }
        let solution = &mut self.solution;
        m.finish(stream, solution)?;
        if let Some((i, v)) = solution.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::invalid(format!(
                "the solution became non-finite ({v} at u = {}, t = {t_next})",
                (i + 2) as f64 * h
            )));
        }
        let mut next = std::mem::take(&mut self.previous);
        next[2..=jn - 2].copy_from_slice(solution);
        self.impose_ends(&mut next, t_next)?;
        self.previous = std::mem::replace(&mut self.current, next);
        self.level += 1;
        Ok(())
    }

    /// Advances to the final level `L`.
    pub fn run(&mut self) -> Result<()> {
        while !self.finished() {
            self.step()?;
        }
        Ok(())
    }
}

/// A dynamic PDE curve: two (planar) or three (space) independent components.
#[derive(Clone)]
pub struct DynamicCurve {
    /// `x, y[, z]`.
    pub components: Vec<Component>,
}

impl DynamicCurve {
    /// The nodal values `values` (one vector per component, as [`DynamicCurve::solve`] returns
    /// them) at time `t` as a core curve: the clamped C² cubic spline through the nodes whose end
    /// derivatives are the slope conditions `s₀(t)`, `s₁(t)` (missing components zero).
    pub fn to_curve(&self, values: &[Vec<f64>], t: f64) -> Result<spline::NodalCurve> {
        if values.len() != self.components.len() || values.is_empty() {
            return Err(Error::invalid(format!(
                "{} value vectors for {} components",
                values.len(),
                self.components.len()
            )));
        }
        let n = values[0].len();
        if values.iter().any(|v| v.len() != n) {
            return Err(Error::invalid("value vectors of different lengths"));
        }
        let mut nodes = vec![crate::Vec3::zeros(); n];
        let (mut d0, mut d1) = (crate::Vec3::zeros(), crate::Vec3::zeros());
        for (c, (comp, v)) in self.components.iter().zip(values).enumerate() {
            for (p, x) in nodes.iter_mut().zip(v) {
                p[c] = *x;
            }
            d0[c] = (comp.start_slope)(t);
            d1[c] = (comp.end_slope)(t);
        }
        spline::NodalCurve::new(nodes, d0, d1)
    }

    /// Solves every component up to `t = T` and returns `X^L`, one vector of `J + 1` nodal values
    /// per component.
    pub fn solve(&self, grid: TimeGrid) -> Result<Vec<Vec<f64>>> {
        self.solve_observed(grid, false, 0, &mut |_, _, _| {})
    }

    /// As [`DynamicCurve::solve`], advancing the components in lockstep. `observer(n, t_n, nodes)`
    /// is called after every level `n = 0 ..= L`; `nodes` (the points `C(u_j, t_n)`, missing
    /// components zero) is given at `n = 0`, at every `every`-th level and at `n = L`, `None`
    /// otherwise (`every = 0`: first and last level only). With `positivity` the coefficients are
    /// checked at every level ([`Scheme::with_positivity`]).
    pub fn solve_observed(
        &self,
        grid: TimeGrid,
        positivity: bool,
        every: usize,
        observer: &mut Observer<'_>,
    ) -> Result<Vec<Vec<f64>>> {
        if !(1..=3).contains(&self.components.len()) {
            return Err(Error::invalid(format!(
                "a curve has 1 to 3 components, got {}",
                self.components.len()
            ))
            .at("components"));
        }
        const NAMES: [&str; 3] = ["x", "y", "z"];
        let mut schemes = Vec::with_capacity(self.components.len());
        for (i, comp) in self.components.iter().enumerate() {
            schemes
                .push(Scheme::with_positivity(comp, grid, positivity).map_err(|e| e.at(NAMES[i]))?);
        }
        let nodes = |previous: bool, schemes: &[Scheme]| -> Vec<crate::Vec3> {
            (0..=grid.intervals)
                .map(|j| {
                    let mut p = crate::Vec3::zeros();
                    for (c, s) in schemes.iter().enumerate() {
                        p[c] = if previous {
                            s.previous()[j]
                        } else {
                            s.values()[j]
                        };
                    }
                    p
                })
                .collect()
        };
        let wants = |n: usize| n == 0 || n == grid.steps || (every > 0 && n.is_multiple_of(every));
        let first = nodes(true, &schemes);
        observer(0, 0.0, Some(&first));
        loop {
            let n = schemes[0].level();
            let t = schemes[0].time();
            if wants(n) {
                let now = nodes(false, &schemes);
                observer(n, t, Some(&now));
            } else {
                observer(n, t, None);
            }
            if schemes[0].finished() {
                break;
            }
            for (i, s) in schemes.iter_mut().enumerate() {
                s.step().map_err(|e| e.at(NAMES[i]))?;
            }
        }
        Ok(schemes.iter().map(|s| s.values().to_vec()).collect())
    }
}

#[cfg(test)]
mod tests;
