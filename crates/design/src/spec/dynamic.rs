//! The `[dynamic]` section of a design file: a dynamic PDE curve (`pdeshape curve`), either a
//! general run of the scheme (components `[dynamic.x]`, `[dynamic.y]`, `[dynamic.z]` with their
//! coefficients, force, end conditions and initial data as formulas) or an interpolation (§4:
//! `points`, end points and tangents). Every key is documented in `docs/design-file.md`.

use super::write::{is_false, never};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A formula string, or a plain number (a constant).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum FormulaText {
    /// A number: the constant of that value.
    Number(f64),
    /// A formula in the variables its key allows (`u`, `t`, `x`: see the key), e.g.
    /// `"0.1*sin(t)"`.
    Text(String),
}

impl FormulaText {
    /// The formula's text (a number in its shortest round-trip form).
    pub fn text(&self) -> String {
        match self {
            FormulaText::Number(x) => format!("{x:?}"),
            FormulaText::Text(s) => s.clone(),
        }
    }
}

/// One component of a general run: Eq. (5) with its end conditions and initial data.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ComponentSpec {
    /// Damping `a(u, t, x)` (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub a: Option<FormulaText>,
    /// Tension `b(u, t, x)` (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b: Option<FormulaText>,
    /// Bending stiffness `d(u, t, x)`.
    pub d: FormulaText,
    /// Force `f(u, t, x)` (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f: Option<FormulaText>,
    /// `x(0, t)`, a formula in `t`.
    pub start: FormulaText,
    /// `x(1, t)`, a formula in `t`.
    pub end: FormulaText,
    /// `x_u(0, t)`, a formula in `t`.
    pub start_slope: FormulaText,
    /// `x_u(1, t)`, a formula in `t`.
    pub end_slope: FormulaText,
    /// Initial position `x(u, 0)`, a formula in `u`.
    pub position: FormulaText,
    /// Initial velocity `x_t(u, 0)`, a formula in `u` (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<FormulaText>,
    /// An exact solution `x(u, t)` to compare with (reported as the discrete L² error at `T`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exact: Option<FormulaText>,
}

/// How the parameters of the interpolated points are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
pub enum ParamsSpec {
    /// Chord length of the data polygon, fixed.
    #[serde(rename = "fixed")]
    Fixed,
    /// The closest node of the current curve, after every step.
    #[serde(rename = "closest-each-step")]
    ClosestEachStep,
    /// The closest node of the current curve, at every force update.
    #[serde(rename = "closest-each-update")]
    ClosestEachUpdate,
}

/// The `[dynamic]` section.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DynamicSpec {
    /// Grid intervals `J ≥ 5` (run: required; interpolation: default 200).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intervals: Option<usize>,
    /// Run: time steps `L ≥ 1`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<usize>,
    /// Run: final time `T > 0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t_end: Option<f64>,
    /// Run: check `a ≥ 0`, `b ≥ 0`, `d > 0` along the solution at every level (default false).
    #[serde(default, skip_serializing_if = "is_false")]
    #[schemars(skip_serializing_if = "never")]
    pub check_positivity: bool,
    /// Keep every k-th level as a frame (default: L/10 for a run, 1000 for an interpolation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frames_every: Option<usize>,
    /// Run: the components.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<ComponentSpec>,
    /// Run: the second component's initial curve (as x).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<ComponentSpec>,
    /// Run: the third component's initial curve (as x).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<ComponentSpec>,
    /// Interpolation: the interior points `p_1 … p_{n−1}` (2 or 3 coordinates each).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<Vec<f64>>>,
    /// Interpolation: the end points and end tangents (derivatives in `u ∈ [0, 1]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<Vec<f64>>,
    /// Interpolation: the end point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end: Option<Vec<f64>>,
    /// Interpolation: the derivative at the start (u ∈ [0, 1]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_tangent: Option<Vec<f64>>,
    /// Interpolation: the derivative at the end (u ∈ [0, 1]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end_tangent: Option<Vec<f64>>,
    /// Interpolation: bending stiffness `D` (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness: Option<f64>,
    /// Interpolation: tension `B` (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tension: Option<f64>,
    /// Interpolation: damping `A` (default 2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<f64>,
    /// Interpolation: force constant `k` (default 500).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k: Option<f64>,
    /// Interpolation: kernel half-width `ε` (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eps: Option<f64>,
    /// Interpolation: distance tolerance relative to the data size (default 1e-3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Interpolation: time step `Δt` (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dt: Option<f64>,
    /// Interpolation: settled when the largest nodal speed is below `speed · size` (default 1e-4).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed: Option<f64>,
    /// Interpolation: largest number of steps (default 200000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<usize>,
    /// Interpolation: `fixed` (default), `closest-each-step` or `closest-each-update`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub params: Option<ParamsSpec>,
}
