//! The Bloor–Wilson PDE method (book chapter 4): elliptic operators separable in `(u, v)`,
//! conditions at `u_i ∈ [0, 1]`, the analytic per-mode solution and the spectral remainder.

use crate::curve::SharedCurve;
use crate::surface::{Partials, Surface, VDomain};
use crate::{Result, Vec3};

/// A constant-coefficient operator `Σ_{k=0}^{N} c_k ∂u^{2N−2k} ∂v^{2k}` of order `2N`.
#[derive(Clone, Debug, PartialEq)]
pub struct Operator {
    coefficients: Vec<f64>,
}

impl Operator {
    /// `(∂²/∂u² + a² ∂²/∂v²)^N`, `N = 1…20`, `a > 0` (Eqs. 4.1, 4.10, 4.35).
    pub fn polyharmonic(n: usize, a: f64) -> Result<Self> {
        let _ = (n, a);
        todo!("solver")
    }
    /// `a ∂u⁶ + b ∂u⁴∂v² + c ∂u²∂v⁴ + d ∂v⁶` (Eq. 4.54).
    pub fn sixth_order(a: f64, b: f64, c: f64, d: f64) -> Result<Self> {
        Self::general(vec![a, b, c, d])
    }
    /// `Σ c_k ∂u^{2N−2k} ∂v^{2k}` from `[c_0, …, c_N]`; must be elliptic.
    pub fn general(coefficients: Vec<f64>) -> Result<Self> {
        let _ = coefficients;
        todo!("solver")
    }
    /// `N` (the operator has order `2N` and takes `2N` conditions).
    pub fn half_order(&self) -> usize {
        self.coefficients.len() - 1
    }
    /// `[c_0, …, c_N]`.
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }
}

/// `∂ᵈX/∂uᵈ (u, v) = curve(v)` for all `v`.
#[derive(Clone, Debug)]
pub struct Condition {
    pub u: f64,
    /// 0 for a position curve, `d` for the `d`-th u-derivative.
    pub derivative: usize,
    pub curve: SharedCurve,
}

/// Solver options.
#[derive(Clone, Debug, PartialEq)]
pub struct SolveOptions {
    /// Fourier modes `M` solved analytically.
    pub modes: usize,
    /// Add the spectral remainder (Eqs. 4.45–4.53) so curves that are not finite Fourier series
    /// are met exactly.
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

/// What the solver reports about one Fourier mode's linear system.
#[derive(Clone, Debug, PartialEq)]
pub struct ModeReport {
    /// The mode `n` (0 is the spine; `modes + 1` is the remainder's mode).
    pub n: usize,
    /// 2-norm condition number of the mode's condition matrix in the basis used.
    pub condition_number: f64,
    /// The basis the mode was solved in.
    pub basis: &'static str,
}

/// The error of one condition on a fine sample of `v`.
#[derive(Clone, Debug, PartialEq)]
pub struct ConditionError {
    pub u: f64,
    pub derivative: usize,
    /// `max_v |∂ᵈX(u,v) − g(v)|`.
    pub absolute: f64,
    /// `absolute` divided by the design's size (the largest `|g(v)|` over all position conditions).
    pub relative: f64,
}

/// A solved Bloor–Wilson patch `X(u,v) = A₀(u) + Σ [Aₙ(u) cos nv + Bₙ(u) sin nv] + R(u,v)`.
#[derive(Debug)]
pub struct PdePatch {}

/// Solves the PDE for the conditions (their count must be `2N`).
pub fn solve(
    operator: &Operator,
    conditions: Vec<Condition>,
    options: &SolveOptions,
) -> Result<PdePatch> {
    let _ = (operator, conditions, options);
    todo!("solver")
}

impl PdePatch {
    /// The spine `A₀(u)` (§5.3) and its derivatives: `spine(u, 0)` is the centre line.
    pub fn spine(&self, u: f64, derivative: usize) -> Vec3 {
        let _ = (u, derivative);
        todo!("solver")
    }
    /// One report per mode system solved.
    pub fn mode_reports(&self) -> &[ModeReport] {
        todo!("solver")
    }
    /// The conditions this patch was solved for.
    pub fn conditions(&self) -> &[Condition] {
        todo!("solver")
    }
    /// The operator.
    pub fn operator(&self) -> &Operator {
        todo!("solver")
    }
    /// Condition errors on `samples` equally spaced `v`.
    pub fn condition_errors(&self, samples: usize) -> Vec<ConditionError> {
        let _ = samples;
        todo!("solver")
    }
}

impl Surface for PdePatch {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        let _ = (u, v);
        todo!("solver")
    }
}
