//! The `[[spine]]` tables of the design file: edits of the spine `A₀(u)` of a PDE patch (§5.3).

use super::types::V3;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A new spine for one PDE patch (book §5.3, Fig. 5.13). The patch keeps its radial part
/// `X − A₀ = Σ Aₙ cos nv + Bₙ sin nv (+ remainder)` and follows the new spine. The spine is the
/// patch's degree-`2N − 1` polynomial; give exactly one of `control`, `moves`, `hermite`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpineSpec {
    /// The patch, by its `[[patches]]` name; omitted for a single-patch design.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patch: Option<String>,
    /// How the sections follow the new spine: `"frame"` (default) turns them with the spine's
    /// rotation-minimising frame, so they stay across the spine; `"translate"` only moves them
    /// (the book's plain replacement of `A₀`).
    #[serde(default, skip_serializing_if = "SpineCarry::is_frame")]
    pub carry: SpineCarry,
    /// The new spine's `2N` Bézier control points (degree `2N − 1` on `u ∈ [0, 1]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control: Option<Vec<V3>>,
    /// Displacements of the solved spine's Bézier control points.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub moves: Vec<SpineMove>,
    /// The new spine as a cubic Hermite curve (biharmonic patches, `N = 2`; Eq. 5.4 and the
    /// corrected Eqs. 5.5–5.8).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hermite: Option<SpineHermite>,
}

/// How the sections of a patch follow an edited spine.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum SpineCarry {
    /// `X̃ = Ã₀ + R (X − A₀)`, `R(u)` the rotation from the old spine's rotation-minimising
    /// frame to the new one's.
    #[default]
    Frame,
    /// `X̃ = X − A₀ + Ã₀` (book §5.3).
    Translate,
}

impl SpineCarry {
    fn is_frame(&self) -> bool {
        *self == SpineCarry::Frame
    }
}

/// Control point `index` of the solved spine moves by `by`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpineMove {
    /// 0-based index of the Bézier control point (`0 … 2N − 1`).
    pub index: usize,
    /// The displacement.
    pub by: V3,
}

/// A cubic spine from its end positions and end speeds: `A₀(0) = p0`, `A₀(1) = p1`,
/// `A₀'(0) = d0`, `A₀'(1) = d1`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpineHermite {
    pub p0: V3,
    pub p1: V3,
    pub d0: V3,
    pub d1: V3,
}
