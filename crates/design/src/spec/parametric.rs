//! The `[[parametric]]` tables of the design file: surfaces given by formulas in `u` and `v`.

use super::types::DomainSpec;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A surface `X(u, v) = (x, y, z)` given by three formulas in `u ∈ [0, 1]` and `v`, for shapes
/// the PDE method cannot produce exactly (a sphere, a cylinder, a torus). Partial derivatives
/// are symbolic, so analysis and normals are exact.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ParametricSpec {
    /// Unique name of the surface (shared with the names of `[[patches]]`).
    pub name: String,
    /// The formulas of the three coordinates in `u` and `v`, e.g. `x = "sin(pi*u)*cos(v)"`.
    pub x: String,
    /// The y coordinate as a formula in u and v.
    pub y: String,
    /// The z coordinate as a formula in u and v.
    pub z: String,
    /// The `v` domain: `"periodic"` (`v ∈ [0, 2π)`, the default; the formulas must repeat
    /// after 2π) or an interval `[v0, v1]`.
    #[serde(default, skip_serializing_if = "DomainSpec::is_periodic")]
    pub domain: DomainSpec,
    /// A reference surface (default false): a neighbour that `[[nsided]]` and `[[network]]`
    /// sides may be tangent to (`tangent_to`) and that `check` measures against, but not part
    /// of the design's output (meshes, CAD files, pictures, measures). Faces read from a CAD
    /// part by `pdeshape import` are reference surfaces: their formulas cover the box of their
    /// parameters, not the trimmed face.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reference: bool,
}
