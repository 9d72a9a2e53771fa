//! The `[shell]` section of the design file: the thin-shell strength analysis of `pdeshape
//! shell` (thickness, material, element grid, clamped edges, loads, the solver's time limit).
//! Every value is in SI units (metres, pascals, newtons per metre, kilograms per cubic metre,
//! seconds); the design's coordinates are converted to metres by its `units`. Every key may be
//! left out; without the section the analysis is the book's set-up (§7.5.1): the first patch's
//! `u = 0` edge clamped and 15 N/m on the last patch's `u = 1` edge, along the axis towards the
//! base. Documented key by key in `docs/design-file.md`.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `[shell]`: the shell model of the design's surfaces.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ShellSpec {
    /// Wall thickness in metres, `0 < t ≤ 0.1` (default 0.0005, half a millimetre).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// The wall's isotropic material (default: general-purpose polystyrene).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<MaterialSpec>,
    /// Element grid cells per patch `[nu, nv]`: rows along `u` (1 to 400) and cells around `v`
    /// (2 to 1000); eight-node quadrilaterals (default `[8, 32]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elements: Option<[usize; 2]>,
    /// Edges with every displacement and rotation fixed (default: the first patch's `u = 0`
    /// edge; `[]` for none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clamped: Option<Vec<EdgeSpec>>,
    /// Line loads on edges (default: 15 N/m on the last patch's `u = 1` edge along the axis
    /// towards the base, the book's weight of a stack; `[]` for none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_loads: Option<Vec<LineLoadSpec>>,
    /// Uniform pressure in pascals on every element, positive along the surface normals
    /// (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pressure: Option<f64>,
    /// Wall-clock limit of one solver run in seconds, `0 < s ≤ 86400` (default 300).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_limit: Option<f64>,
}

/// An isotropic linear-elastic material; a key left out takes polystyrene's value.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Young's modulus `E` in pascals, positive (polystyrene: 3.0e9).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub youngs_modulus: Option<f64>,
    /// Poisson's ratio `ν`, `−1 < ν < 0.5` (polystyrene: 0.33).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poisson_ratio: Option<f64>,
    /// Density in kg/m³, positive (polystyrene: 1050).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Tensile yield stress in pascals, positive (polystyrene: 40e6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yield_stress: Option<f64>,
}

/// A boundary edge of a named patch.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EdgeSpec {
    /// The patch's name (of `[[patches]]` or `[[parametric]]`).
    pub patch: String,
    /// `"u0"` for the edge `u = 0`, `"u1"` for `u = 1`.
    pub side: SideSpec,
}

/// A line load along an edge.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LineLoadSpec {
    /// The patch's name.
    pub patch: String,
    /// `"u0"` or `"u1"`.
    pub side: SideSpec,
    /// Force per unit length of the edge in N/m, finite (may be negative).
    pub force: f64,
    /// Direction of the force, a non-zero vector (normalised); default: from the loaded edge's
    /// centroid towards the first clamped edge's centroid (along a container's axis, towards
    /// its base).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<[f64; 3]>,
}

/// An edge of a patch in its parameter `u`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
pub enum SideSpec {
    /// The edge `u = 0`.
    #[serde(rename = "u0")]
    U0,
    /// The edge `u = 1`.
    #[serde(rename = "u1")]
    U1,
}
