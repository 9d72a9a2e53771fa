//! The Bloor–Wilson PDE method (book chapter 4): elliptic operators separable in `(u, v)`,
//! conditions at `u_i ∈ [0, 1]`, the analytic per-mode solution and the spectral remainder.
//!
//! The solution of `L X = 0` periodic in `v` is (Eqs. 4.11, 4.36)
//! `X(u,v) = A₀(u) + Σ_{n=1}^{M} [Aₙ(u) cos nv + Bₙ(u) sin nv] + R(u,v)`, where each `Aₙ, Bₙ`
//! solves its mode equation exactly (in a bounded basis, see `basis.rs`) and meets the Fourier coefficients of the `2N`
//! conditions, and `R` is the spectral remainder (Eqs. 4.45–4.53) that takes up what the `M`
//! modes leave of the conditions, so they hold to rounding for any periodic curves.

mod adjoint;
pub(crate) mod basis;
mod bounds;
mod operator;
mod patch;
mod smoothing;
mod tangent;

pub use adjoint::{AdjointTangent, Partial, NODE_WEIGHTS};
pub use basis::BasisKind;
pub use bounds::{mode_sum, RemainderTerm};
pub use operator::{Operator, RootGroup, MAX_HALF_ORDER};
pub use patch::{PdePatch, RowTables};
pub use tangent::{combination, TangentCurve};

use crate::curve::SharedCurve;
use crate::fourier::FourierSeries;
use crate::{Error, Result, Vec3};
use basis::Basis;
use nalgebra::DMatrix;

/// `∂ᵈX/∂uᵈ (u, v) = curve(v)` for all `v`.
#[derive(Clone, Debug)]
pub struct Condition {
    /// Where the condition holds, `u ∈ [0, 1]`.
    pub u: f64,
    /// 0 for a position curve, `d` for the `d`-th u-derivative.
    pub derivative: usize,
    /// The periodic curve `g(v)` the derivative must equal.
    pub curve: SharedCurve,
}

/// Solver options.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveOptions {
    /// Fourier modes `M` solved analytically.
    pub modes: usize,
    /// Add the spectral remainder (Eqs. 4.45–4.53) so curves that are not finite Fourier series
    /// with at most `modes` modes are met exactly.
    pub remainder: bool,
    /// Samples per curve for the Fourier analysis (0: automatic).
    pub samples: usize,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            modes: 12,
            remainder: true,
            samples: 0,
        }
    }
}

/// Largest number of Fourier modes accepted.
pub const MAX_MODES: usize = 1024;

/// What the solver reports about one Fourier mode's linear system.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeReport {
    /// The mode `n` (0 is the spine; `modes + 1` is the remainder's mode).
    pub n: usize,
    /// 2-norm condition number of the mode's condition matrix (rows and columns equilibrated) in
    /// the basis used.
    pub condition_number: f64,
    /// The basis the mode was solved in: `"chebyshev"` or `"exponential layers"`.
    pub basis: &'static str,
}

/// The error of one condition on a fine sample of `v`.
#[derive(Clone, Debug, PartialEq)]
pub struct ConditionError {
    /// The condition's `u`.
    pub u: f64,
    /// The condition's derivative order `d` (0 for a position curve).
    pub derivative: usize,
    /// `max_v |∂ᵈX(u,v) − g(v)|`.
    pub absolute: f64,
    /// `absolute` divided by the design's size (the radius of the position curves about their
    /// centroid) times `max(1, |g|/size)` for derivative curves, i.e. relative to the larger of
    /// the design's size and the condition's own magnitude.
    pub relative: f64,
}

/// A mode's solution: `2N` basis coefficients for each of `ncols` right-hand sides, plus
/// precomputed Chebyshev series for the fast paths.
#[derive(Clone, Debug)]
pub(crate) struct ModeFn {
    basis: Basis,
    /// `coef[(k, c)]`: coefficient of basis function `k` in column `c`.
    coef: DMatrix<f64>,
    /// For the Chebyshev basis: the combined series of each column and its first two
    /// x-derivatives, `series[d][c]`.
    series: Option<[Vec<Vec<f64>>; 3]>,
    /// Every coefficient is zero (a mode whose conditions have no such Fourier term): the mode
    /// adds nothing anywhere, and evaluations of the whole surface leave it out.
    pub(crate) zero: bool,
}

impl ModeFn {
    fn new(basis: Basis, coef: DMatrix<f64>) -> Self {
        let zero = coef.iter().all(|&x| x == 0.0);
        let series = match &basis {
            // A zero mode of the Chebyshev basis is evaluated as zeros without its series
            // (`zero_series`), the values its series of zeros would give.
            Basis::Chebyshev { .. } if zero => None,
            Basis::Chebyshev { series, .. } => {
                let len = series.iter().map(Vec::len).max().unwrap_or(0);
                let cols: Vec<Vec<f64>> = (0..coef.ncols())
                    .map(|c| {
                        let mut s = vec![0.0; len];
                        for (k, sk) in series.iter().enumerate() {
                            let w = coef[(k, c)];
                            if w != 0.0 {
                                for (a, b) in s.iter_mut().zip(sk) {
                                    *a += w * b;
                                }
                            }
                        }
                        s
                    })
                    .collect();
                let d1: Vec<Vec<f64>> = cols.iter().map(|s| basis::cheb_diff(s)).collect();
                let d2: Vec<Vec<f64>> = d1.iter().map(|s| basis::cheb_diff(s)).collect();
                Some([cols, d1, d2])
            }
            Basis::Layers(_) => None,
        };
        ModeFn {
            basis,
            coef,
            series,
            zero,
        }
    }

    fn ncols(&self) -> usize {
        self.coef.ncols()
    }

    /// A zero mode of the Chebyshev basis, kept without its combined series: its values and
    /// first two derivatives are `+0.0`, as Clenshaw's sums of a series of zeros are.
    fn zero_series(&self) -> bool {
        self.zero && self.series.is_none() && matches!(self.basis, Basis::Chebyshev { .. })
    }

    /// The mode of columns `start .. start + count` (one direction of a block solve).
    fn columns(&self, start: usize, count: usize) -> ModeFn {
        ModeFn::new(
            self.basis.clone(),
            self.coef.columns(start, count).into_owned(),
        )
    }

    /// Values and first u-derivatives of every column at `u` (one basis evaluation for both).
    fn eval01(&self, u: f64, out0: &mut [f64], out1: &mut [f64]) {
        if self.series.is_some() || self.zero_series() {
            self.eval(u, 0, out0);
            self.eval(u, 1, out1);
            return;
        }
        let mut buf = [0.0; 4 * MAX_HALF_ORDER];
        let k = self.basis.len();
        let (b0, b1) = buf.split_at_mut(2 * MAX_HALF_ORDER);
        self.basis.eval01(u, &mut b0[..k], &mut b1[..k]);
        for c in 0..self.ncols() {
            let (mut s0, mut s1) = (0.0, 0.0);
            for j in 0..k {
                s0 += b0[j] * self.coef[(j, c)];
                s1 += b1[j] * self.coef[(j, c)];
            }
            out0[c] = s0;
            out1[c] = s1;
        }
    }

    /// [`Self::eval`] for `d = 0, 1, 2` into `out[d]`, the same values bit for bit, with one
    /// basis evaluation for the three.
    fn eval012(&self, u: f64, out: [&mut [f64]; 3]) {
        if self.series.is_some() || self.zero_series() {
            for (d, o) in out.into_iter().enumerate() {
                self.eval(u, d, o);
            }
            return;
        }
        // Small operators have few basis functions: a small buffer saves clearing a large one.
        if self.basis.len() <= 8 {
            self.eval012_buffered::<8>(u, out);
        } else {
            self.eval012_buffered::<{ 2 * MAX_HALF_ORDER }>(u, out);
        }
    }

    /// [`Self::eval012`] of the layer basis with buffers of `B ≥ basis.len()` entries: the
    /// products with the coefficient columns are those of [`Self::eval`] (same terms, same
    /// order).
    fn eval012_buffered<const B: usize>(&self, u: f64, out: [&mut [f64]; 3]) {
        let mut buf = [[0.0; B]; 3];
        let k = self.basis.len();
        let [b0, b1, b2] = &mut buf;
        self.basis
            .eval012(u, [&mut b0[..k], &mut b1[..k], &mut b2[..k]]);
        let rows = self.coef.nrows();
        let coef = self.coef.as_slice();
        for (b, out) in buf.iter().zip(out) {
            let b = &b[..k];
            for (c, o) in out.iter_mut().enumerate().take(self.ncols()) {
                let col = &coef[c * rows..c * rows + k];
                *o = b.iter().zip(col).map(|(x, y)| x * y).sum();
            }
        }
    }

    /// `d`-th u-derivative of every column at `u` into `out[c]`.
    fn eval(&self, u: f64, d: usize, out: &mut [f64]) {
        if d <= 2 && self.zero_series() {
            let n = self.ncols().min(out.len());
            out[..n].fill(0.0);
            return;
        }
        if let (Some(series), true) = (&self.series, d <= 2) {
            let x = 2.0 * u - 1.0;
            let scale = 2f64.powi(d as i32);
            basis::clenshaw_lanes(&series[d], x, scale, out);
            return;
        }
        let mut buf = [0.0; 2 * MAX_HALF_ORDER];
        let b = &mut buf[..self.basis.len()];
        self.basis.eval(u, d, b);
        for (c, o) in out.iter_mut().enumerate().take(self.ncols()) {
            *o = (0..b.len()).map(|k| b[k] * self.coef[(k, c)]).sum();
        }
    }
}

/// Solves `L X = 0` for the conditions (their count must be `2N`).
pub fn solve(
    operator: &Operator,
    conditions: Vec<Condition>,
    options: &SolveOptions,
) -> Result<PdePatch> {
    let nn = operator.half_order();
    check_conditions(nn, &conditions)?;
    if options.modes > MAX_MODES {
        return Err(Error::invalid(format!(
            "at most {MAX_MODES} Fourier modes (got {})",
            options.modes
        ))
        .at("modes"));
    }
    let m = options.modes;
    let samples = if options.samples == 0 {
        (8 * m).max(64).next_power_of_two()
    } else {
        options.samples
    };
    let (series, exact): (Vec<FourierSeries>, Vec<bool>) = conditions
        .iter()
        .enumerate()
        .map(|(i, c)| {
            condition_series(&*c.curve, m, samples)
                .map_err(|e| e.at(&format!("conditions[{i}].curve")))
        })
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .unzip();
    let at: Vec<(f64, usize)> = conditions.iter().map(|c| (c.u, c.derivative)).collect();

    let mut modes = Vec::with_capacity(m + 1);
    let mut reports = Vec::with_capacity(m + 2);
    for n in 0..=m {
        let mut rhs = DMatrix::<f64>::zeros(2 * nn, 6);
        for (i, s) in series.iter().enumerate() {
            let (c, sn) = if n == 0 {
                (s.a0, Vec3::zeros())
            } else {
                (s.cos[n - 1], s.sin[n - 1])
            };
            for k in 0..3 {
                rhs[(i, k)] = c[k];
                rhs[(i, 3 + k)] = sn[k];
            }
        }
        let (f, report) = solve_mode(operator, n, &at, rhs)?;
        modes.push(f);
        reports.push(report);
    }

    let mut cardinal = None;
    let (patch, distances, active) = assemble(
        operator,
        conditions,
        &series,
        &exact,
        modes,
        reports,
        options,
        &at,
        &mut cardinal,
    )?;
    check_a_posteriori(&patch, &distances, &active, patch.remainder.is_some())?;
    Ok(patch)
}

/// A condition curve's Fourier series of `m` modes (as [`FourierSeries::from_curve`] makes it)
/// and whether the curve is a finite series within those modes, from one call of
/// [`Curve::fourier`] (which builds the series of every part of a combined curve).
pub(crate) fn condition_series(
    curve: &dyn crate::curve::Curve,
    m: usize,
    samples: usize,
) -> Result<(FourierSeries, bool)> {
    let own = curve.fourier();
    let within = own.as_ref().is_some_and(|f| f.modes() <= m);
    let series = match own {
        Some(f) if m <= crate::fourier::MAX_MODES && samples <= crate::fourier::MAX_SAMPLES => {
            f.truncated(m)
        }
        _ => FourierSeries::from_curve(curve, m, samples)?,
    };
    Ok((series, within))
}

/// The patch of the solved `modes` of `conditions` (whose Fourier series are `series`, `exact`
/// where the curve is a finite series within the modes), with
/// the spectral remainder when a condition needs it; also each condition's coefficient distance
/// and whether it takes part in the remainder. `cardinal` holds the remainder's cardinal
/// functions and their report once solved (they depend on the operator and the conditions'
/// places only, so a batch of patches with the same operator and places shares them).
#[allow(clippy::too_many_arguments)]
fn assemble(
    operator: &Operator,
    conditions: Vec<Condition>,
    series: &[FourierSeries],
    exact: &[bool],
    modes: Vec<ModeFn>,
    mut reports: Vec<ModeReport>,
    options: &SolveOptions,
    at: &[(f64, usize)],
    cardinal: &mut Option<(ModeFn, ModeReport)>,
) -> Result<(PdePatch, Vec<f64>, Vec<bool>)> {
    let nn = operator.half_order();
    let m = modes.len() - 1;
    // The remainder (Eqs. 4.50–4.53) takes up Δ_i(v) = g_i(v) − ∂ᵈX̃(u_i, v): the Fourier tail of
    // curves that are not finite series within M modes, and whatever the mode systems left at
    // the conditions beyond rounding (high modes with intermediate conditions have solutions as
    // large as e^{anu} between the conditions, so their values at the ends carry that much
    // rounding). Conditions whose Δ is at rounding level stay out of it: multiplying rounding
    // noise by a cardinal function of mode M + 1 (huge at an intermediate u for large a) would
    // only add noise.
    let fitted: Vec<FourierSeries> = conditions
        .iter()
        .map(|c| patch::fitted_series(&modes, c.u, c.derivative))
        .collect();
    // Measured against the larger of the curve's own size and the design's (a point curve at
    // the origin has size 0).
    let design_size = series.iter().map(series_size).fold(0.0, f64::max);
    let distances: Vec<f64> = series
        .iter()
        .zip(&fitted)
        .map(|(s, f)| series_distance(s, f))
        .collect();
    let active: Vec<bool> = exact
        .iter()
        .zip(series.iter().zip(&distances))
        .map(|(&exact, (s, &dist))| {
            !exact || dist > ROUNDING_LEFTOVER * series_size(s).max(design_size)
        })
        .collect();
    let remainder = if options.remainder && active.iter().any(|&a| a) {
        if cardinal.is_none() {
            *cardinal = Some(solve_mode(
                operator,
                m + 1,
                at,
                DMatrix::identity(2 * nn, 2 * nn),
            )?);
        }
        let (cardinal, report) = cardinal.clone().expect("solved above");
        reports.push(report);
        Some(patch::Remainder {
            cardinal,
            fitted,
            active: active.clone(),
        })
    } else {
        None
    };
    let patch = PdePatch::new(operator.clone(), conditions, modes, remainder, reports);
    Ok((patch, distances, active))
}

/// Leftover of a condition (relative to the size of its Fourier coefficients) below which it
/// stays out of the remainder: well below the 1e-10 the conditions must meet, and above the
/// rounding of well-conditioned mode systems, so the remainder is not switched on for nothing.
const ROUNDING_LEFTOVER: f64 = 1e-13;

/// Relative condition error above which a solution is refused: the mode systems were too
/// ill-conditioned for double precision (e.g. intermediate curves with high modes and a large
/// `a`, whose exact solutions are as large as `e^{a n u}`).
const MAX_CONDITION_ERROR: f64 = 1e-5;

/// Condition number of a mode system up to which a missed condition is not blamed on the
/// conditioning: a system of condition number 43 is well conditioned, so the numbers of the
/// curves must be at fault. (Above it, the condition number estimates the growth `e^{a n u}`
/// only roughly: a system estimated at 10⁶ can miss its conditions by 100 %.)
const ILL_CONDITIONED: f64 = 1e3;

/// Checks the solution meets its conditions. Conditions outside the remainder are bounded by
/// the coefficient distance `Σ |ĝ − ∂ᵈX̃|` of their Fourier series (free); those in the remainder
/// are sampled.
fn check_a_posteriori(
    patch: &PdePatch,
    distances: &[f64],
    active: &[bool],
    has_remainder: bool,
) -> Result<()> {
    let sampled = if has_remainder {
        patch
            .condition_errors_where(16, |i| active[i])
            .into_iter()
            .map(|e| e.absolute)
            .collect()
    } else {
        vec![0.0; distances.len()]
    };
    for (i, c) in patch.conditions().iter().enumerate() {
        let err = if has_remainder && active[i] {
            sampled[i]
        } else {
            distances[i]
        };
        let rel = err / patch.scale();
        if rel.is_nan() || rel > MAX_CONDITION_ERROR {
            let worst = patch
                .mode_reports()
                .iter()
                .map(|r| r.condition_number)
                .fold(0.0, f64::max);
            // Say what the facts are: ill-conditioned mode systems only when their condition
            // numbers are large; otherwise the numbers themselves are out of the range double
            // precision can solve with.
            let message = if !rel.is_finite() {
                format!(
                    "the solution is not finite at this condition (u = {}): the numbers of its curves or of a are too large for double precision (largest condition number of the mode systems {})",
                    crate::check::num(c.u),
                    crate::check::num((worst * 100.0).round() / 100.0)
                )
            } else if worst > ILL_CONDITIONED {
                format!(
                    "the solution misses this condition by {rel:.1e} (relative): the mode systems are too ill-conditioned for double precision (largest condition number {worst:.1e}); intermediate curves with high modes and a large a ask for surfaces as large as e^(a·n·u) — use fewer modes, a smaller a, or move the curve (u = {})",
                    crate::check::num(c.u)
                )
            } else {
                format!(
                    "the solution misses this condition by {rel:.1e} (relative) although the mode systems are well conditioned (largest condition number {worst:.1e}): the numbers of its curves span too many orders of magnitude for double precision (u = {})",
                    crate::check::num(c.u)
                )
            };
            return Err(Error::invalid(message).at(&format!("conditions[{i}]")));
        }
    }
    Ok(())
}

/// `Σ |coefficient differences|` of two series with the same number of modes.
fn series_distance(a: &FourierSeries, b: &FourierSeries) -> f64 {
    (a.a0 - b.a0).norm()
        + a.cos
            .iter()
            .zip(&b.cos)
            .chain(a.sin.iter().zip(&b.sin))
            .map(|(x, y)| (x - y).norm())
            .sum::<f64>()
}

/// `Σ |coefficients|`, a bound on the series' values.
fn series_size(a: &FourierSeries) -> f64 {
    a.a0.norm() + a.cos.iter().chain(&a.sin).map(|x| x.norm()).sum::<f64>()
}

/// Count, range and uniqueness of the conditions.
fn check_conditions(nn: usize, conditions: &[Condition]) -> Result<()> {
    if conditions.len() != 2 * nn {
        return Err(Error::not_unique(format!(
            "an operator of order {} needs {} conditions, got {}",
            2 * nn,
            2 * nn,
            conditions.len()
        )));
    }
    for (i, c) in conditions.iter().enumerate() {
        let place = format!("conditions[{i}]");
        if !(c.u.is_finite() && (0.0..=1.0).contains(&c.u)) {
            return Err(Error::invalid(format!("must lie in [0, 1] (got {})", c.u))
                .at(&format!("{place}.u")));
        }
        if c.derivative >= 2 * nn {
            return Err(Error::invalid(format!(
                "derivative order {} is too high for an operator of order {} (at most {})",
                c.derivative,
                2 * nn,
                2 * nn - 1
            ))
            .at(&format!("{place}.derivative")));
        }
        for (j, o) in conditions[..i].iter().enumerate() {
            if o.u == c.u && o.derivative == c.derivative {
                let what = if c.derivative == 0 {
                    "the position".to_string()
                } else {
                    format!("derivative {}", c.derivative)
                };
                return Err(Error::not_unique(format!(
                    "prescribes {what} at u = {} like conditions[{j}]",
                    c.u
                ))
                .at(&place));
            }
        }
    }
    Ok(())
}

/// Condition number above which a mode system counts as singular.
const SINGULAR: f64 = 1e14;
/// Condition number below which the layer basis is kept without trying the Chebyshev basis.
const LAYERS_GOOD: f64 = 1e5;

/// Solves one mode: picks the basis, builds the condition matrix `A[i][k] = ψ_k^{(d_i)}(u_i)`,
/// equilibrates it and solves with partial pivoting plus one step of iterative refinement.
fn solve_mode(
    op: &Operator,
    n: usize,
    at: &[(f64, usize)],
    rhs: DMatrix<f64>,
) -> Result<(ModeFn, ModeReport)> {
    let setup = mode_setup(op, n, at)?;
    let ModeSetup { basis, a, cond } = &*setup;
    // Zero data (the conditions have no such Fourier term): the system is linear and
    // homogeneous and its matrix regular (checked above), so its one solution is zero.
    let coef = if rhs.iter().all(|&x| x == 0.0) {
        DMatrix::zeros(a.ncols(), rhs.ncols())
    } else {
        solve_equilibrated(a, &rhs).ok_or_else(|| {
            Error::not_unique(format!("the system for Fourier mode {n} is singular"))
        })?
    };
    let report = ModeReport {
        n,
        condition_number: *cond,
        basis: basis.kind().name(),
    };
    Ok((ModeFn::new(basis.clone(), coef), report))
}

/// What a mode system's matrix depends on: the operator (its coefficients, and whether it was
/// given as `(∂uu + a²∂vv)^N`, whose roots are exact), the mode and the places of the
/// conditions (`u` and the derivative order), bit for bit, and the SVD's iteration cap. Not
/// the curves.
#[derive(Clone, PartialEq, Eq, Hash)]
struct SetupKey {
    cap: usize,
    smoothing: Option<u64>,
    coefficients: Vec<u64>,
    n: usize,
    at: Vec<(u64, usize)>,
}

/// A mode system's basis (the better conditioned of the two representations), its condition
/// matrix and its condition number.
struct ModeSetup {
    basis: Basis,
    a: DMatrix<f64>,
    cond: f64,
}

/// Setups kept for re-solving with other curves (an animation's frames, a dragged curve):
/// the choice of basis and the singular values of its matrix are computed once per operator,
/// mode and places. Bounded: emptied when full.
static SETUPS: std::sync::LazyLock<
    std::sync::Mutex<std::collections::HashMap<SetupKey, std::sync::Arc<ModeSetup>>>,
> = std::sync::LazyLock::new(Default::default);
const MAX_SETUPS: usize = 4096;

/// The setup of mode `n`: from [`SETUPS`], or chosen and remembered (a singular system is
/// refused and not remembered).
fn mode_setup(op: &Operator, n: usize, at: &[(f64, usize)]) -> Result<std::sync::Arc<ModeSetup>> {
    let key = SetupKey {
        cap: crate::linalg::decomp::max_iterations(at.len()),
        smoothing: op.smoothing_parameter().map(f64::to_bits),
        coefficients: op.coefficients().iter().map(|c| c.to_bits()).collect(),
        n,
        at: at.iter().map(|&(u, d)| (u.to_bits(), d)).collect(),
    };
    let lock = || SETUPS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(s) = lock().get(&key) {
        return Ok(s.clone());
    }
    let setup = std::sync::Arc::new(choose_basis(op, n, at)?);
    let mut setups = lock();
    if setups.len() >= MAX_SETUPS {
        setups.clear();
    }
    setups.insert(key, setup.clone());
    Ok(setup)
}

/// Picks the basis of mode `n` and builds the condition matrix `A[i][k] = ψ_k^{(d_i)}(u_i)`;
/// refuses a singular system.
fn choose_basis(op: &Operator, n: usize, at: &[(f64, usize)]) -> Result<ModeSetup> {
    let mut best: Option<(Basis, DMatrix<f64>, f64)> = None;
    let mut candidates = Vec::new();
    if n > 0 {
        candidates.push(Basis::layers(op, n));
    }
    for attempt in 0..2 {
        if attempt == 1 {
            if best.as_ref().is_some_and(|b| b.2 <= LAYERS_GOOD) {
                break;
            }
            if let Some(c) = Basis::chebyshev(op, n) {
                candidates.push(c);
            }
        }
        while let Some(basis) = candidates.pop() {
            let a = condition_matrix(&basis, at);
            let cond = condition_number(&a);
            if best
                .as_ref()
                .is_none_or(|b| cond < b.2 || (b.2.is_nan() && !cond.is_nan()))
            {
                best = Some((basis, a, cond));
            }
        }
    }
    let (basis, a, cond) =
        best.ok_or_else(|| Error::not_unique(format!("Fourier mode {n} has no usable basis")))?;
    if cond.is_nan() || cond > SINGULAR {
        let which = if n == 0 {
            "the spine (mode 0)".to_string()
        } else {
            format!("Fourier mode {n}")
        };
        let cond = if cond.is_nan() {
            format!(
                "its singular values could not be computed within {} sweeps",
                crate::linalg::decomp::max_iterations(a.nrows().max(a.ncols()))
            )
        } else {
            format!("condition number {cond:.1e}")
        };
        return Err(Error::not_unique(format!(
            "the system for {which} is singular or numerically singular ({cond}); check that the conditions fix the surface (e.g. at least one position curve) and that derivative orders are modest"
        )));
    }
    Ok(ModeSetup { basis, a, cond })
}

fn condition_matrix(basis: &Basis, at: &[(f64, usize)]) -> DMatrix<f64> {
    let k = basis.len();
    let mut a = DMatrix::<f64>::zeros(at.len(), k);
    let mut row = vec![0.0; k];
    for (i, &(u, d)) in at.iter().enumerate() {
        basis.eval(u, d, &mut row);
        for j in 0..k {
            a[(i, j)] = row[j];
        }
    }
    a
}

/// Row and column scalings that make every row and column of `a` peak at 1.
fn equilibrate(a: &DMatrix<f64>) -> (Vec<f64>, Vec<f64>) {
    let r: Vec<f64> = (0..a.nrows())
        .map(|i| {
            let m = a.row(i).amax();
            if m > 0.0 && m.is_finite() {
                1.0 / m
            } else {
                1.0
            }
        })
        .collect();
    let c: Vec<f64> = (0..a.ncols())
        .map(|j| {
            let m = (0..a.nrows())
                .map(|i| (a[(i, j)] * r[i]).abs())
                .fold(0.0, f64::max);
            if m > 0.0 && m.is_finite() {
                1.0 / m
            } else {
                1.0
            }
        })
        .collect();
    (r, c)
}

fn scaled(a: &DMatrix<f64>, r: &[f64], c: &[f64]) -> DMatrix<f64> {
    DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] * r[i] * c[j])
}

fn condition_number(a: &DMatrix<f64>) -> f64 {
    if a.iter().any(|x| !x.is_finite()) {
        return f64::INFINITY;
    }
    let (r, c) = equilibrate(a);
    // An SVD that does not converge within its cap counts as singular (NaN) rather than
    // running forever.
    let Some(s) = crate::linalg::decomp::singular_values(scaled(a, &r, &c)) else {
        return f64::NAN;
    };
    let max = s.max();
    let min = s.min();
    if min > 0.0 {
        max / min
    } else {
        f64::INFINITY
    }
}

fn solve_equilibrated(a: &DMatrix<f64>, b: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let (r, c) = equilibrate(a);
    let lu = scaled(a, &r, &c).lu();
    let rb = DMatrix::from_fn(b.nrows(), b.ncols(), |i, j| b[(i, j)] * r[i]);
    let mut y = lu.solve(&rb)?;
    // One step of iterative refinement on the scaled system.
    let sa = scaled(a, &r, &c);
    let resid = &rb - &sa * &y;
    if let Some(dy) = lu.solve(&resid) {
        y += dy;
    }
    let x = DMatrix::from_fn(y.nrows(), y.ncols(), |i, j| y[(i, j)] * c[i]);
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests;
