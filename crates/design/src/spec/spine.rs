//! The `[[spine]]` tables of the design file: edits of the spine `A₀(u)` of a PDE patch (§5.3).

use super::types::V3;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A new spine for one PDE patch (book §5.3, Fig. 5.13). The patch keeps its radial part
/// `X − A₀ = Σ Aₙ cos nv + Bₙ sin nv (+ remainder)` and follows the new spine. The spine is the
/// patch's degree-`2N − 1` polynomial; give at most one of `control`, `moves`, `hermite` (none
/// keeps the solved spine), and optionally a `wave` added to it (§8.1.3.2).
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
    /// A lateral wave added to the spine (fish locomotion, §8.1.3.2, Eq. 8.9).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wave: Option<SpineWave>,
}

/// The most coefficients of a spine wave's amplitude polynomial.
pub const MAX_WAVE_TERMS: usize = 8;

/// A lateral wave on a spine (book §8.1.3.2, Eq. 8.9): the spine moves by `w(u) d` with `d` the
/// unit `direction` and, with `Ω(u) = Σ amplitude[k] uᵏ` on the patch's `u ∈ [0, 1]`,
///
/// * travelling: `w = Ω(u) sin(α u − 2π ω time + phase)` (crests run towards growing `u` at
///   `2π ω / α` per unit of time; carangiform and anguilliform swimming);
/// * standing: `w = Ω(u) cos(α u + phase) sin(2π ω time)` (Eq. 8.9 as printed; the body flaps
///   in place with nodes where `cos(α u + φ) = 0`).
///
/// Write `time = "= t"` in a design with `[time]` to animate it.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpineWave {
    /// `"travelling"` (default) or `"standing"`.
    #[serde(default, skip_serializing_if = "WaveKind::is_travelling")]
    pub kind: WaveKind,
    /// The coefficients `a₀, a₁, …` of the amplitude `Ω(u) = Σ aₖ uᵏ` (1 to 8 of them), in the
    /// design's length unit.
    pub amplitude: Vec<f64>,
    /// The wave number `α` in radians per unit of `u` (`α / 2π` waves along the patch).
    pub alpha: f64,
    /// The frequency `ω` in cycles per unit of time.
    pub omega: f64,
    /// The phase `φ` in radians.
    #[serde(default)]
    pub phase: f64,
    /// The time at which the wave is taken (default 0; `"= t"` follows the animation).
    #[serde(default)]
    pub time: f64,
    /// The direction of the displacement (any non-zero vector; it is normalised), across the
    /// spine.
    pub direction: V3,
}

/// Standing or travelling spine wave.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum WaveKind {
    /// `Ω(u) sin(α u − 2π ω t + φ)`.
    #[default]
    Travelling,
    /// `Ω(u) cos(α u + φ) sin(2π ω t)` (Eq. 8.9).
    Standing,
}

impl WaveKind {
    fn is_travelling(&self) -> bool {
        *self == WaveKind::Travelling
    }
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
    /// A₀(0), the spine's start.
    pub p0: V3,
    /// A₀(1), the spine's end.
    pub p1: V3,
    /// A₀'(0), the speed at the start.
    pub d0: V3,
    /// A₀'(1), the speed at the end.
    pub d1: V3,
}
