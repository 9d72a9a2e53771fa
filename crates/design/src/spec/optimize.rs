//! The `[optimize]` section of the design file: design parameters (§7.5, Tables 7.2 and 7.4),
//! the objective, constraints and the options of the search. Documented key by key in
//! `docs/design-file.md`.

use super::write::{is_zero, never};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `[optimize]`: what `pdeshape optimize` varies, what it minimises, and how it searches.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OptimizeSpec {
    /// The quantity to minimise: a formula in the variables of the design's integrals (`area`,
    /// `volume`, `mean`, `mean_sq`, `gauss`, `bending`, `willmore`, `helfrich`, `nu`, `c0`,
    /// `C0`) and of its shell analysis (`mass` in kg, `max_shear` and `yield` in Pa; `[shell]`),
    /// e.g. `"bending"`, `"helfrich / (8*pi)"` or `"1000 * mass"`.
    pub objective: String,
    /// The spontaneous curvature `C0` used by `helfrich` and `c0` (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    #[schemars(skip_serializing_if = "never")]
    pub spontaneous_curvature: f64,
    /// The design parameters, each with bounds.
    pub parameters: Vec<ParameterSpec>,
    /// Equality and inequality constraints on formulas of the same variables.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub constraints: Vec<ConstraintSpec>,
    /// Seed of the random numbers: the same seed gives the same result (default 1).
    #[serde(default = "default_seed")]
    pub seed: u64,
    /// Evaluations of the objective by simulated annealing, all chains together (default 2000).
    #[serde(default = "default_evaluations")]
    pub evaluations: usize,
    /// Independent annealing chains, run in parallel (default 4).
    #[serde(default = "default_chains")]
    pub chains: usize,
    /// Further evaluations for the Nelder–Mead polish of the best point (default 200; 0: none).
    #[serde(default = "default_polish")]
    pub polish: usize,
    /// `s` of the annealing schedule `c_m = c_0 e^{(s−1)m}` (Eq. 7.3), `0 < s < 1`; by default
    /// chosen so that the last level is at `c_0 · 10⁻⁵`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cooling: Option<f64>,
    /// The initial control parameter `c_0`; by default estimated from trial moves so that a typical
    /// uphill move is accepted with probability 0.8 at the start.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature: Option<f64>,
    /// Gauss–Legendre points in `u` per patch for the integrals of the search (default 24).
    #[serde(default = "default_quad_u")]
    pub quadrature_u: usize,
    /// Trapezoid points in `v` per patch for the integrals of the search (default 48).
    #[serde(default = "default_quad_v")]
    pub quadrature_v: usize,
}

fn default_seed() -> u64 {
    1
}
fn default_evaluations() -> usize {
    2000
}
fn default_chains() -> usize {
    4
}
fn default_polish() -> usize {
    200
}
fn default_quad_u() -> usize {
    24
}
fn default_quad_v() -> usize {
    48
}

/// One design parameter.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ParameterSpec {
    /// The name of a `[[parameters]]` entry, or a parameter in the book's notation (§7.5):
    /// `<curve><T|R|D><x|y|z>` for a translation (length), a
    /// rotation (radians, about the curve's centroid) or a dilation (factor, about the centroid)
    /// of the named curve, e.g. `d1Dx`; `a` for the smoothing parameter of every polyharmonic
    /// operator; `<curve>cT` for the amplitude of the control-point offsets of a B-spline curve.
    pub name: String,
    /// Lower bound (required for a name in the book's notation; for a `[[parameters]]` entry
    /// the default is that entry's `min`, and a given one must not lie below it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// Upper bound (as `min`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// Start value (default: the neutral value, 0 for translations, rotations and `cT`, 1 for
    /// dilations, the design's own `a` for `a`; for a `[[parameters]]` entry, its value).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial: Option<f64>,
}

/// A constraint `expr = equal`, `expr ≥ min` or `expr ≤ max`, enforced by the quadratic penalty
/// `weight · violation²` added to the objective.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSpec {
    /// A formula in the same variables as the objective, e.g. `"nu"` or `"volume"`.
    pub expr: String,
    /// Target value of an equality constraint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub equal: Option<f64>,
    /// Lower bound of an inequality constraint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// Upper bound of an inequality constraint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// Penalty weight (default 10⁴).
    #[serde(default = "default_weight")]
    pub weight: f64,
}

fn default_weight() -> f64 {
    1e4
}
