//! Sensitivities: derivatives of a design's measures ([`super::VARIABLES`]) with respect to its
//! parameters, and of a [`Problem`]'s objective and constraints.
//!
//! **Why a difference is exact here.** For a fixed operator (fixed `a`) every PDE solve of a
//! patch design (analytic with its spectral remainder, or finite differences) is linear in its
//! condition curves: `X = S[C]` with `S` linear. The parameter kinds other than `a` and the
//! `v = 0` point act on a curve by an affine map of the value (translations, dilations,
//! control-point offsets, §6.1's position and scale: `C(p) = C₀ + p C₁`) or by one rotation
//! `R(θ)` between fixed affine maps (`C(θ) = A + B cos θ + D sin θ`, Rodrigues' formula). So
//! `X(p) = S[C₀] + p S[C₁]` is affine in `p`, and `(X(p + h) − X(p))/h = S[C₁] = ∂X/∂p` for
//! every `h`: no truncation error, only the rounding of the two solves (about `ε|X|/h`, so the
//! step is taken at the parameter's own scale). For a rotation,
//! `X(θ ± h) = S[A] + S[B] cos(θ ± h) + S[D] sin(θ ± h)`, so
//! `(X(θ + h) − X(θ − h)) / (2 sin h) = −S[B] sin θ + S[D] cos θ = ∂X/∂θ` exactly; with
//! `h = π/2` the divisor is 2. This is differentiating the solve by its linearity: the tangent
//! surface `∂X/∂p` is the solve of the tangent curves. The same identities hold for the curves
//! themselves (`Ċ = (C(p + h) − C(p))/h`, `(C(θ + h) − C(θ − h))/(2 sin h)`), so for a design
//! of analytic PDE patches the tangent curves of all exact parameters are built from the
//! designs at the steps without solving those designs, and every patch solves them as one block
//! of right-hand sides of its own mode systems ([`crate::design::tangent_patches`]): one
//! batched tangent solve per gradient, with the integrals' derivatives of all parameters from
//! one pass over the quadrature nodes ([`crate::analysis::integrals_derivatives`]). Designs of
//! other solvers (finite differences) take the same differences of solved designs: one solve
//! per affine parameter and two per rotation, which every solver, the spectral remainder and
//! the multi-patch conditions support as they are.
//!
//! The measures are then differentiated exactly at the same quadrature nodes
//! ([`crate::analysis::integrals_derivative`]: the chain rule through the area element, `X·n`,
//! `H`, `H²` and `K`, with the design's orientation and caps), and the derived variables by
//! their closed forms. The result is the exact derivative of the *discrete* measures the search
//! minimises.
//!
//! **Where the premise fails** the derivative is labelled [`Method::Richardson`]: central
//! differences `D(h)` of the measures, the step halved until three successive ones are in their
//! asymptotic regime (the ratio of their changes near 4), then Richardson-extrapolated,
//! `D(h) + (D(h) − D(2h))/3`, with the error estimate `|D(h) − D(2h)|/3` (which bounds the error
//! of `D(h)`, so pessimistically that of the extrapolated value); if no regime is reached in 8
//! levels, the estimate is the spread of the last three. That is the `v = 0` point (a
//! reparametrisation, not an affine map), control-point offsets of an arc-length curve, every
//! parameter of a design that is not made of PDE patches alone or has curves derived
//! non-linearly from others (`local`, `on_patch`, `tangent_field`), and the smoothing parameter
//! `a` of designs outside the batch below.
//!
//! **The smoothing parameter `a`** changes the operator `(∂²/∂u² + a² ∂²/∂v²)^N`, not the
//! curves. Mode `n`'s solutions are `g(a u)` with `g` fixed, so `(u/a) X_u` solves the
//! differentiated equation, and `∂X/∂a = (1/a) u X_u + T` with `T` the patch's tangent solve of
//! the conditions `−(1/a) ∂_u^{d_i}[u X_u](u_i, ·)` (the remainder included: see
//! [`crate::elliptic::PdePatch::smoothing_tangent_curves`]). For a design of analytic PDE
//! patches that is one more direction of the batched tangent solve, labelled
//! [`Method::Smoothing`] (`exact`); the per-parameter path keeps Richardson differences for it.
//!
//! **The shell stress `max_shear`** comes from a CalculiX analysis, which is not differentiated:
//! [`Problem::gradient`] takes forward differences of it, one design solved and analysed per
//! parameter at the step [`SHEAR_STEP`] beside the point's own (`n + 1` analyses, run side by
//! side). The measures' derivatives above stay exact.

use super::{
    measure_patches, measure_patches_keeping, variables, Problem, MASS, MAX_SHEAR, NVARS, YIELD,
};
use crate::analysis::{
    integrals_derivative, integrals_derivatives_at, DesignIntegrals, Integrals, NodePartials,
    Quadrature,
};
use crate::design::{
    design_a, design_parameters, parse_book_name, solve_design, tangent_patches, SolvedDesign,
    SurfaceKind,
};
use crate::optimize::{ParamKind, Parameters};
use crate::shell::ShellSetup;
use crate::spec::{CurveKind, DesignSpec, OptimizeSpec, ParameterSpec, SolverMethod};
use crate::{Error, Result};
use rayon::prelude::*;

/// The step of `max_shear`'s forward differences, relative to each parameter's scale
/// ([`Sensitivities::scales`]). The difference's error is about `h/2 |τ''|` (truncation) plus
/// `2 ε τ / h` (the stresses' rounding, [`SHEAR_ROUNDING`]); with `τ''` of the size of
/// `τ / scale²` the two balance at `h ≈ 2 √ε ≈ 6·10⁻³` scales.
pub const SHEAR_STEP: f64 = 5e-3;

/// The relative rounding of a shear stress read from CalculiX's results: six significant
/// digits (`E12.5`) per stress component, twice that for the difference `(σ₁ − σ₃)/2`.
pub const SHEAR_ROUNDING: f64 = 1e-5;

/// How a parameter's derivatives were computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// Exact: the surface is affine in the parameter; its tangent from the curves at
    /// `p + step` (in the batched tangent solve, or one extra solve at `p + step`).
    Linear {
        /// The step `h` of `(X(p + h) − X(p))/h`.
        step: f64,
    },
    /// Exact: the surface is `A + B cos θ + D sin θ`; its tangent from the curves at
    /// `θ ± step` (in the batched tangent solve, or two extra solves at `θ ± step`).
    Rotation {
        /// The step `h` of `(X(θ + h) − X(θ − h))/(2 sin h)`.
        step: f64,
    },
    /// Approximate: Richardson-extrapolated central differences of the measures, the step
    /// halved from 2 % of the parameter's scale until three successive differences are in
    /// their asymptotic regime (at most 8 levels, two solves each), with the error estimate in
    /// [`Sensitivities::errors`].
    Richardson {
        /// The smallest step `h` used (the one before it is `2h`).
        step: f64,
    },
    /// Exact: the smoothing parameter `a` of the polyharmonic operators, whose derivative is
    /// `(1/a) u X_u` plus one more direction of the batched tangent solve (see
    /// [`crate::elliptic::PdePatch::smoothing_tangent_curves`]).
    Smoothing,
}

impl Method {
    /// Whether the derivative is exact up to rounding.
    pub fn is_exact(&self) -> bool {
        !matches!(self, Method::Richardson { .. })
    }

    /// `"linear"`, `"rotation"`, `"exact"` (the smoothing parameter) or `"richardson"`.
    pub fn label(&self) -> &'static str {
        match self {
            Method::Linear { .. } => "linear",
            Method::Rotation { .. } => "rotation",
            Method::Smoothing => "exact",
            Method::Richardson { .. } => "richardson",
        }
    }
}

/// Derivatives of the measures of a design with respect to its parameters.
#[derive(Clone, Debug)]
pub struct Sensitivities {
    /// The parameters, in order.
    pub names: Vec<String>,
    /// The parameters' values at the point.
    pub parameters: Vec<f64>,
    /// The [`super::VARIABLES`] at the point (the shell measures NaN unless a [`Problem`] fills them).
    pub values: [f64; NVARS],
    /// `d_values[k][j] = ∂ VARIABLES[j] / ∂ parameter k` (NaN for `max_shear` outside
    /// [`Problem::gradient`], and for `mass` and `yield` outside a [`Problem`] with a shell
    /// set-up).
    pub d_values: Vec<[f64; NVARS]>,
    /// How each parameter's derivatives were computed ([`Method::is_exact`]).
    pub methods: Vec<Method>,
    /// Each parameter's own scale, which its steps are relative to: a length of the design
    /// (`√area`) for translations, positions and `cT`, `|value|` for dilations, scales and `a`,
    /// 1 for angles and `v_origin`.
    pub scales: Vec<f64>,
    /// Per parameter and variable, an estimate of the absolute error of `d_values`: for exact
    /// methods the rounding, about `10⁻¹² (|value| + h |derivative|) / h`; for
    /// [`Method::Richardson`] `|D(h/2) − D(h)|/3` plus that rounding.
    pub errors: Vec<[f64; NVARS]>,
    /// Design solves made (the point itself included, and two per level of each
    /// [`Method::Richardson`] parameter; none for the exact parameters of a design of analytic
    /// PDE patches, whose derivatives come from [`Sensitivities::tangent_solves`]).
    pub solves: usize,
    /// Batched tangent solves made: 1 when the exact parameters' derivatives came from one
    /// block solve of their tangent curves with the point's operator (designs of analytic PDE
    /// patches), else 0 (each exact parameter then costs one or two design solves, counted in
    /// `solves`).
    pub tangent_solves: usize,
    /// The parameters in that batch.
    pub batch: usize,
}

impl Sensitivities {
    /// Whether every parameter's derivatives are exact.
    pub fn all_exact(&self) -> bool {
        self.methods.iter().all(Method::is_exact)
    }
}

/// Why the surfaces of `spec` may not be linear in its curves (`None`: they are; see the module
/// documentation).
pub fn nonlinear_design(spec: &DesignSpec) -> Option<String> {
    let others = [
        ("[[nurbs]]", spec.nurbs.is_empty()),
        ("[[nsided]]", spec.nsided.is_empty()),
        ("[[network]]", spec.network.is_empty()),
        ("[[patchwork]]", spec.patchwork.is_empty()),
        ("[[disk]]", spec.disk.is_empty()),
        ("[[spine]]", spec.spine.is_empty()),
        ("[blend]", spec.blend.is_none()),
        ("[spline]", spec.spline.is_none()),
        ("[dynamic]", spec.dynamic.is_none()),
    ];
    if let Some((what, _)) = others.iter().find(|(_, empty)| !empty) {
        return Some(format!("the design has {what} surfaces"));
    }
    for (name, c) in &spec.curves {
        let why = match &c.kind {
            CurveKind::Local { .. } => "a local edit",
            CurveKind::OnPatch { .. } => "an on_patch curve",
            CurveKind::TangentField { .. } => "a tangent_field curve",
            _ => continue,
        };
        return Some(format!("curve '{name}' is {why}"));
    }
    None
}

/// Whether the parameter `kind` acts on `spec`'s surfaces affinely (`Some(false)`), by a
/// rotation (`Some(true)`), or neither (`None`).
fn exact_kind(spec: &DesignSpec, kind: &ParamKind) -> Option<bool> {
    match kind {
        ParamKind::Translate { .. }
        | ParamKind::Dilate { .. }
        | ParamKind::Position { .. }
        | ParamKind::Scale { .. } => Some(false),
        ParamKind::ControlOffset { curve } => {
            (!spec.curves.get(curve).is_some_and(|c| c.arc_length)).then_some(false)
        }
        ParamKind::Rotate { .. } | ParamKind::Angle { .. } => Some(true),
        ParamKind::Smoothing | ParamKind::VOrigin { .. } => None,
    }
}

/// The parameter's own scale: a length `size` for lengths, `|value|` for factors, `a` and
/// scale distances, 1 for angles.
fn unit(kind: &ParamKind, value: f64, size: f64) -> f64 {
    let own = |v: f64| if v.abs() > 0.0 { v.abs() } else { size };
    match kind {
        ParamKind::Translate { .. }
        | ParamKind::Position { .. }
        | ParamKind::ControlOffset { .. } => size,
        ParamKind::Dilate { .. } | ParamKind::Scale { .. } | ParamKind::Smoothing => own(value),
        ParamKind::Rotate { .. } | ParamKind::Angle { .. } | ParamKind::VOrigin { .. } => 1.0,
    }
}

/// Step of an exact affine difference, relative to the parameter's scale.
const LINEAR_STEP: f64 = 0.5;
/// Step of a rotation's exact central difference (`2 sin h = 2`).
const ROTATION_STEP: f64 = std::f64::consts::FRAC_PI_2;
/// Larger step of the Richardson differences, relative to the parameter's scale.
const RICHARDSON_STEP: f64 = 0.02;
/// Relative rounding of a solve and its integrals assumed in the error estimates.
const ROUNDING: f64 = 1e-12;
/// Most step halvings of the Richardson differences.
const RICHARDSON_LEVELS: usize = 8;

/// Whether three successive central differences `D_{i−2}, D_{i−1}, D_i` (step halved each time,
/// the last `h`) are in their asymptotic regime for every base integral (area … gauss): the
/// ratio `(D_{i−2} − D_{i−1})/(D_{i−1} − D_i)` lies in `[2.5, 6]` (4 for an `h²` error), or the
/// last change is within rounding (`10⁻¹¹ · |value| / h`).
fn richardson_regime(d: &[[f64; NVARS]], values: &[f64; NVARS], h: f64) -> bool {
    (0..5).all(|j| {
        let (a, b) = (d[0][j] - d[1][j], d[1][j] - d[2][j]);
        let noise = 10.0 * ROUNDING * values[j].abs().max(d[2][j].abs() * h) / h;
        b.abs() <= noise || (2.5..=6.0).contains(&(a / b))
    })
}

/// The derivatives of the [`super::VARIABLES`] (shell measures NaN) from the integrals `t` and their
/// derivatives `dt`, with the spontaneous curvature `c0`.
pub fn d_variables(t: &Integrals, dt: &Integrals, c0: f64) -> [f64; NVARS] {
    let pi = std::f64::consts::PI;
    let r0 = t.equivalent_radius();
    let dr0 = dt.area / (8.0 * pi * r0);
    let nu = t.reduced_volume();
    let v0 = 4.0 * pi / 3.0 * r0 * r0 * r0;
    [
        dt.area,
        dt.volume,
        dt.mean,
        dt.mean_sq,
        dt.gauss,
        4.0 * dt.mean_sq - 2.0 * dt.gauss,
        4.0 * dt.mean_sq,
        4.0 * dt.mean_sq + 4.0 * c0 * dt.mean + c0 * c0 * dt.area,
        dt.volume / v0 - 3.0 * nu * dr0 / r0,
        c0 * dr0,
        0.0,
        f64::NAN,
        f64::NAN,
        f64::NAN,
    ]
}

/// One parameter's method, derivatives, error estimates, solves and scale.
type Derivatives = (Method, [f64; NVARS], [f64; NVARS], usize, f64);

/// A design to differentiate: its parameters' kinds and values, and how to set one.
struct Point<'a> {
    spec: DesignSpec,
    names: Vec<String>,
    kinds: Vec<ParamKind>,
    values: Vec<f64>,
    /// The design with parameter `k` set to a value (the others at `values`).
    at: &'a (dyn Fn(usize, f64) -> DesignSpec + Sync),
    quadrature: (usize, usize),
    c0: f64,
    /// Whether the exact parameters of a design of analytic PDE patches share one batched
    /// tangent solve (else each costs its own solves of the design at its steps).
    batched: bool,
}

impl Point<'_> {
    /// The derivatives of the parameters `batch` (exact kinds, a design of analytic PDE
    /// patches) from one batched tangent solve: each parameter's tangent condition curves are
    /// the exact differences of the curves of designs at steps of the parameter (built, not
    /// solved: `(C(p + h) − C(p))/h` for an affine parameter, `(C(θ + h) − C(θ − h))/(2 sin h)`
    /// for a rotation), every patch solves all of them as one block of right-hand sides, and
    /// the integrals' derivatives come from one pass over the quadrature nodes.
    ///
    /// With `smoothing`, the derivative with respect to the operators' `a` joins the batch as
    /// one more direction (its tangent curves from the point's patches) and is returned last.
    #[allow(clippy::too_many_arguments)]
    fn batch(
        &self,
        batch: &[usize],
        smoothing: bool,
        built: &SolvedDesign,
        (at, kept): (&DesignIntegrals, Option<&NodePartials>),
        q: &Quadrature,
        size: f64,
        rounding: &dyn Fn(&[f64; NVARS], f64) -> [f64; NVARS],
    ) -> Result<Vec<Derivatives>> {
        if batch.is_empty() && !smoothing {
            return Ok(Vec::new());
        }
        let rotation = |k: usize| matches!(exact_kind(&self.spec, &self.kinds[k]), Some(true));
        let steps: Vec<(f64, f64)> = batch
            .iter()
            .map(|&k| {
                let u = unit(&self.kinds[k], self.values[k], size);
                if rotation(k) {
                    (ROTATION_STEP, u)
                } else {
                    (LINEAR_STEP * u, u)
                }
            })
            .collect();
        // The designs at the steps: `p + h` for an affine parameter, `θ ± h` for a rotation.
        let designs: Vec<(DesignSpec, Option<DesignSpec>)> = batch
            .iter()
            .zip(&steps)
            .map(|(&k, &(h, _))| {
                let p = self.values[k];
                let minus = rotation(k).then(|| (self.at)(k, p - h));
                ((self.at)(k, p + h), minus)
            })
            .collect();
        let directions: Vec<Vec<(f64, &DesignSpec)>> = designs
            .iter()
            .zip(&steps)
            .map(|((plus, minus), &(h, _))| match minus {
                Some(minus) => {
                    let c = 1.0 / (2.0 * h.sin());
                    vec![(c, plus), (-c, minus)]
                }
                None => vec![(1.0 / h, plus), (-1.0 / h, &self.spec)],
            })
            .collect();
        let tangents = tangent_patches(built, &self.spec, &directions, smoothing)?;
        let dts = integrals_derivatives_at(built, at, kept, &tangents, q)?;
        let mut out: Vec<Derivatives> = batch
            .iter()
            .zip(&steps)
            .zip(&dts)
            .map(|((&k, &(h, u)), dt)| {
                let d = d_variables(&at.total, dt, self.c0);
                let method = if rotation(k) {
                    Method::Rotation { step: h }
                } else {
                    Method::Linear { step: h }
                };
                (method, d, rounding(&d, h), 0, u)
            })
            .collect();
        if smoothing {
            let a = design_a(&self.spec).unwrap_or(1.0);
            let u = unit(&ParamKind::Smoothing, a, size);
            let d = d_variables(&at.total, &dts[batch.len()], self.c0);
            out.push((Method::Smoothing, d, rounding(&d, u), 0, u));
        }
        Ok(out)
    }
}

fn sub(a: &Integrals, b: &Integrals, s: f64) -> Integrals {
    Integrals {
        area: (a.area - b.area) * s,
        volume: (a.volume - b.volume) * s,
        mean: (a.mean - b.mean) * s,
        mean_sq: (a.mean_sq - b.mean_sq) * s,
        gauss: (a.gauss - b.gauss) * s,
    }
}

impl Point<'_> {
    fn run(&self) -> Result<Sensitivities> {
        let q = Quadrature::fixed(self.quadrature.0, self.quadrature.1);
        let built = solve_design(&self.spec)?;
        // The batch's adjoint weighs the point's partials at the quadrature nodes again: kept
        // from its integrals.
        let (at, kept) = if self.batched {
            let (at, kept) = measure_patches_keeping(&built, &q)?;
            (at, Some(kept))
        } else {
            (measure_patches(&built, &q)?, None)
        };
        let t = at.total;
        let values = variables(&t, self.c0);
        let size = t.area.abs().sqrt().max(f64::MIN_POSITIVE);
        let design_reason = nonlinear_design(&self.spec);
        let solve = |k: usize, v: f64| -> Result<SolvedDesign> {
            solve_design(&(self.at)(k, v)).map_err(|e| {
                let message = format!(
                    "the design with {} = {v} (a step of the derivative) cannot be solved: {}",
                    self.names[k],
                    e.detail()
                );
                e.with_message(message)
            })
        };
        let rounding = |d: &[f64; NVARS], h: f64| -> [f64; NVARS] {
            std::array::from_fn(|j| ROUNDING * (values[j].abs() + h * d[j].abs()) / h)
        };
        let exact = |k: usize| {
            if design_reason.is_none() {
                exact_kind(&self.spec, &self.kinds[k])
            } else {
                None
            }
        };
        // The exact parameters of a design of analytic PDE patches: one batched tangent solve.
        let batchable = self.batched
            && self.spec.solver.method == SolverMethod::Analytic
            && built
                .surfaces
                .iter()
                .all(|s| matches!(s.kind, SurfaceKind::Pde(_)));
        let batch: Vec<usize> = if batchable {
            (0..self.kinds.len())
                .filter(|&k| exact(k).is_some())
                .collect()
        } else {
            Vec::new()
        };
        // The smoothing parameter `a` of such a design joins the batch as one more direction.
        let smoothing: Vec<usize> = if batchable && design_reason.is_none() {
            (0..self.kinds.len())
                .filter(|&k| self.kinds[k] == ParamKind::Smoothing)
                .collect()
        } else {
            Vec::new()
        };
        let batched = self.batch(
            &batch,
            !smoothing.is_empty(),
            &built,
            (&at, kept.as_ref()),
            &q,
            size,
            &rounding,
        )?;
        let per: Vec<Result<Derivatives>> = (0..self.kinds.len())
            .into_par_iter()
            .map(|k| {
                let p = self.values[k];
                let kind = &self.kinds[k];
                let u = unit(kind, p, size);
                if batch.contains(&k) {
                    return Ok(batched[batch.iter().position(|&b| b == k).unwrap_or(0)]);
                }
                if smoothing.contains(&k) {
                    return Ok(batched[batch.len()]);
                }
                match exact(k) {
                    Some(false) => {
                        let h = LINEAR_STEP * u;
                        let plus = solve(k, p + h)?;
                        let dt = integrals_derivative(
                            &built,
                            &at,
                            &[(1.0 / h, &plus), (-1.0 / h, &built)],
                            &q,
                        )?;
                        let d = d_variables(&t, &dt, self.c0);
                        Ok((Method::Linear { step: h }, d, rounding(&d, h), 1, u))
                    }
                    Some(true) => {
                        let h = ROTATION_STEP;
                        let c = 1.0 / (2.0 * h.sin());
                        let plus = solve(k, p + h)?;
                        let minus = solve(k, p - h)?;
                        let dt =
                            integrals_derivative(&built, &at, &[(c, &plus), (-c, &minus)], &q)?;
                        let d = d_variables(&t, &dt, self.c0);
                        Ok((Method::Rotation { step: h }, d, rounding(&d, h), 2, u))
                    }
                    None => {
                        let h0 = RICHARDSON_STEP * u;
                        let m = |v: f64| -> Result<Integrals> {
                            Ok(measure_patches(&solve(k, v)?, &q)?.total)
                        };
                        // Central differences D_i at h_i = h0 / 2^i until they are in their
                        // asymptotic regime (see `richardson_regime`).
                        let mut levels: Vec<[f64; NVARS]> = Vec::new();
                        let mut solves = 0;
                        let mut pick = None;
                        for i in 0..RICHARDSON_LEVELS {
                            let h = h0 * 0.5f64.powi(i as i32);
                            let (a, b) = (m(p + h)?, m(p - h)?);
                            solves += 2;
                            levels.push(d_variables(&t, &sub(&a, &b, 0.5 / h), self.c0));
                            if i >= 2 && richardson_regime(&levels[i - 2..], &values, h) {
                                pick = Some(i);
                                break;
                            }
                        }
                        let last = levels.len() - 1;
                        let (d1, d2) = (levels[last - 1], levels[last]);
                        let h = h0 * 0.5f64.powi(last as i32);
                        let d: [f64; NVARS] =
                            std::array::from_fn(|j| d2[j] + (d2[j] - d1[j]) / 3.0);
                        let r = rounding(&d, h);
                        let err = match pick {
                            Some(_) => std::array::from_fn(|j| (d2[j] - d1[j]).abs() / 3.0 + r[j]),
                            // No regime: the spread of the last three levels, pessimistically.
                            None => std::array::from_fn(|j| {
                                (levels[last - 2][j] - d2[j]).abs() + (d1[j] - d2[j]).abs() + r[j]
                            }),
                        };
                        Ok((Method::Richardson { step: h }, d, err, solves, u))
                    }
                }
            })
            .collect();
        let mut out = Sensitivities {
            names: self.names.clone(),
            parameters: self.values.clone(),
            values,
            d_values: Vec::new(),
            methods: Vec::new(),
            scales: Vec::new(),
            errors: Vec::new(),
            solves: 1,
            tangent_solves: usize::from(!batch.is_empty() || !smoothing.is_empty()),
            batch: batch.len() + smoothing.len(),
        };
        for r in per {
            let (m, d, e, s, u) = r?;
            out.methods.push(m);
            out.scales.push(u);
            out.d_values.push(d);
            out.errors.push(e);
            out.solves += s;
        }
        Ok(out)
    }
}

/// `spec` with the value of `[[parameters]]` entry `j` set to `v`, its bounds widened to hold
/// `v` (a derivative's step may leave them).
fn set_entry(spec: &mut DesignSpec, j: usize, v: f64) {
    if let Some(e) = spec.parameters.get_mut(j) {
        e.value = Some(v);
        e.min = e.min.min(v);
        e.max = e.max.max(v);
    }
}

impl Parameters {
    /// The design with the values `x` applied, entries' bounds widened to hold them.
    fn apply_unbounded(&self, base: &DesignSpec, x: &[f64]) -> DesignSpec {
        let mut spec = self.apply(base, x);
        for (p, &v) in self.list.iter().zip(x) {
            if let Some(j) = p.entry {
                set_entry(&mut spec, j, v);
            }
        }
        spec
    }
}

/// Sensitivities of the measures of a design with respect to named parameters (`[[parameters]]`
/// entries, or names in the book's notation such as `d1Tx`, `a`, `d1cT`), at the design's
/// current values (an entry's value, a book name's neutral value: 0, 1 for a dilation, the
/// design's `a`), with `qu × qv` quadrature nodes per patch as in [`super::measure`]. `C₀` is
/// the `[optimize]` spontaneous curvature if the design has one, else 0; the shell measures are
/// NaN.
pub fn sensitivities(
    spec: &DesignSpec,
    names: &[String],
    qu: usize,
    qv: usize,
) -> Result<Sensitivities> {
    if names.is_empty() {
        return Err(Error::invalid("give at least one parameter").at("names"));
    }
    let entries = if spec.parameters.is_empty() {
        Vec::new()
    } else {
        design_parameters(spec)?
    };
    let mut params = Vec::with_capacity(names.len());
    for (i, name) in names.iter().enumerate() {
        let place = format!("names[{i}]");
        let (lo, hi) = if let Some(e) = entries.iter().find(|e| &e.name == name) {
            (e.min, e.max)
        } else {
            let kind = parse_book_name(name, spec).map_err(|e| e.at(&place))?;
            let v = match kind {
                ParamKind::Dilate { .. } => 1.0,
                ParamKind::Smoothing => design_a(spec).ok_or_else(|| {
                    Error::invalid("'a' needs a polyharmonic operator, and the design uses none")
                        .at(&place)
                })?,
                _ => 0.0,
            };
            // Bounds only for the parameters' checks: the steps do not look at them.
            match kind {
                ParamKind::Dilate { .. } | ParamKind::Smoothing => (v / 4.0, 4.0 * v),
                _ => (v - 1.0, v + 1.0),
            }
        };
        params.push(ParameterSpec {
            name: name.clone(),
            min: Some(lo),
            max: Some(hi),
            initial: None,
        });
    }
    let opt = OptimizeSpec {
        parameters: params,
        ..toml::from_str("objective = \"area\"\nparameters = []")
            .map_err(|e| Error::invalid(e.to_string()))?
    };
    let ps = Parameters::new(spec, &opt)?;
    let x0 = ps.initial();
    let at = |k: usize, v: f64| {
        let mut x = x0.clone();
        x[k] = v;
        ps.apply_unbounded(spec, &x)
    };
    let c0 = spec
        .optimize
        .as_ref()
        .map_or(0.0, |o| o.spontaneous_curvature);
    Point {
        spec: ps.apply(spec, &x0),
        names: names.to_vec(),
        kinds: ps.list.iter().map(|p| p.kind.clone()).collect(),
        values: x0.clone(),
        at: &at,
        quadrature: (qu, qv),
        c0,
        batched: true,
    }
    .run()
}

/// A constraint's value and gradient.
#[derive(Clone, Debug)]
pub struct ConstraintGradient {
    /// The formula's text.
    pub text: String,
    /// The formula's value `g`.
    pub value: f64,
    /// `∂g/∂x_k`.
    pub gradient: Vec<f64>,
    /// `g = equal` …
    pub equal: Option<f64>,
    /// … or `g ≥ min` and/or `g ≤ max`.
    pub min: Option<f64>,
    /// See `min`.
    pub max: Option<f64>,
}

/// The objective, the constraints and the penalised total with their gradients at a point.
#[derive(Clone, Debug)]
pub struct ProblemGradient {
    /// The objective `f`.
    pub objective: f64,
    /// `∂f/∂x_k`.
    pub d_objective: Vec<f64>,
    /// Each constraint.
    pub constraints: Vec<ConstraintGradient>,
    /// The penalties' sum `Σ w · violation²` (as [`super::Evaluation::penalty`]).
    pub penalty: f64,
    /// Its gradient.
    pub d_penalty: Vec<f64>,
    /// The measures' sensitivities underneath.
    pub sensitivities: Sensitivities,
}

impl Problem {
    /// The sensitivities of the measures at `x` (the search's parameters, in the order of
    /// `[optimize].parameters`), with `mass` and `yield` filled in when the problem has a shell
    /// set-up (`max_shear` stays NaN here: [`Problem::gradient`] differences the shell analysis).
    pub fn sensitivities(&self, x: &[f64]) -> Result<Sensitivities> {
        self.sensitivities_with(x, true)
    }

    /// [`Problem::sensitivities`] with every exact parameter differentiated by its own solves
    /// of the design at its steps (one per affine parameter, two per rotation) instead of the
    /// batched tangent solve: the same derivatives to rounding, at the cost of a solve per
    /// parameter; a check of the batch, and what designs of other solvers always take.
    pub fn sensitivities_per_parameter(&self, x: &[f64]) -> Result<Sensitivities> {
        self.sensitivities_with(x, false)
    }

    /// [`Problem::sensitivities`], the exact parameters batched into one tangent solve where the
    /// design allows it (`batched`) or each differentiated by its own solves.
    fn sensitivities_with(&self, x: &[f64], batched: bool) -> Result<Sensitivities> {
        if x.len() != self.parameters.len() {
            return Err(Error::invalid(format!(
                "expected {} parameter values, got {}",
                self.parameters.len(),
                x.len()
            ))
            .at("x"));
        }
        // The designs at the steps need no `[optimize]` section (nothing of a design's solve
        // reads it): left out of the base they are cloned from, once per step.
        let steps_base = DesignSpec {
            optimize: None,
            ..self.base.clone()
        };
        let at = |k: usize, v: f64| {
            let mut y = x.to_vec();
            y[k] = v;
            self.parameters.apply_unbounded(&steps_base, &y)
        };
        let mut s = Point {
            spec: self.parameters.apply_unbounded(&self.base, x),
            names: self
                .parameters
                .list
                .iter()
                .map(|p| p.name.clone())
                .collect(),
            kinds: self
                .parameters
                .list
                .iter()
                .map(|p| p.kind.clone())
                .collect(),
            values: x.to_vec(),
            at: &at,
            quadrature: self.quadrature,
            c0: self.spontaneous_curvature,
            batched,
        }
        .run()?;
        if let Some(st) = &self.strength {
            let setup = &st.setup;
            let m2 = setup.metres * setup.metres;
            let rho_t = setup.material.density * setup.thickness * m2;
            s.values[MASS] = rho_t * s.values[0];
            s.values[YIELD] = setup.material.yield_stress;
            for (d, e) in s.d_values.iter_mut().zip(&mut s.errors) {
                d[MASS] = rho_t * d[0];
                e[MASS] = rho_t * e[0];
                d[YIELD] = 0.0;
                e[YIELD] = 0.0;
            }
        }
        Ok(s)
    }

    /// `max_shear` at `x` and its forward differences (see [`SHEAR_STEP`]): `n + 1` designs
    /// solved and analysed by CalculiX, side by side; the value and derivatives go into `s`,
    /// the solves into `s.solves`.
    fn shear_differences(
        &self,
        setup: &ShellSetup,
        x: &[f64],
        s: &mut Sensitivities,
    ) -> Result<()> {
        let n = x.len();
        let steps: Vec<f64> = s
            .scales
            .iter()
            .map(|&c| SHEAR_STEP * if c > 0.0 { c } else { 1.0 })
            .collect();
        let shear = (0..=n)
            .into_par_iter()
            .map(|k| {
                let mut y = x.to_vec();
                if k < n {
                    y[k] += steps[k];
                }
                let built = solve_design(&self.parameters.apply_unbounded(&self.base, &y))?;
                self.max_shear(setup, &built)
            })
            .collect::<Result<Vec<f64>>>()?;
        let tau = shear[n];
        s.values[MAX_SHEAR] = tau;
        for k in 0..n {
            s.d_values[k][MAX_SHEAR] = (shear[k] - tau) / steps[k];
            s.errors[k][MAX_SHEAR] = 2.0 * SHEAR_ROUNDING * tau.abs() / steps[k];
        }
        s.solves += n + 1;
        Ok(())
    }

    /// The objective, the constraints and their gradients at `x` (the search's parameters, in
    /// the order of `[optimize].parameters`). Where a formula uses `max_shear`, its derivatives
    /// are forward differences of the shell analysis ([`SHEAR_STEP`]; `n + 1` analyses).
    pub fn gradient(&self, x: &[f64]) -> Result<ProblemGradient> {
        let mut s = self.sensitivities(x)?;
        if let Some(st) = self.strength.as_ref().filter(|st| st.solve) {
            self.shear_differences(&st.setup, x, &mut s)?;
        }
        let n = x.len();
        let chain = |grad: &[f64; NVARS]| -> Vec<f64> {
            (0..n)
                .map(|k| {
                    (0..NVARS)
                        .filter(|&j| grad[j] != 0.0)
                        .map(|j| grad[j] * s.d_values[k][j])
                        .sum()
                })
                .collect()
        };
        let (objective, df) = self.objective.gradient(&s.values)?;
        let d_objective = chain(&df);
        let mut penalty = 0.0;
        let mut d_penalty = vec![0.0; n];
        let mut constraints = Vec::with_capacity(self.constraints.len());
        for c in &self.constraints {
            let (g, dg) = c.formula.gradient(&s.values)?;
            let gradient = chain(&dg);
            let violation = c.violation(&s.values);
            penalty += c.weight * violation * violation;
            if violation != 0.0 {
                for (p, d) in d_penalty.iter_mut().zip(&gradient) {
                    *p += 2.0 * c.weight * violation * d;
                }
            }
            constraints.push(ConstraintGradient {
                text: c.formula.text.clone(),
                value: g,
                gradient,
                equal: c.equal,
                min: c.min,
                max: c.max,
            });
        }
        Ok(ProblemGradient {
            objective,
            d_objective,
            constraints,
            penalty,
            d_penalty,
            sensitivities: s,
        })
    }
}

#[cfg(test)]
mod tests;
