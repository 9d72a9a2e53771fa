//! The `[[disk]]` tables of the design file: polyharmonic patches on the unit disk bounded by
//! one closed loop of samples (see `pdeshape_geometry::disk`), the patches `pdeshape fill`
//! writes for the holes it fills.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A patch solving `Δ^N X = 0` on the unit disk (`u = r`, `v = θ`), through a closed loop of
/// boundary samples at equally spaced angles, with the ribbon `∂X/∂r` for `N ≥ 2` and
/// `∂²X/∂r²` for `N = 3`. With `samples_per_edge = k > 1`, the samples are the closed polyline
/// through `points` (and through `derivatives` and `second`), `k` per edge.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DiskSpec {
    /// Unique name of the patch (shared with the names of the other surfaces).
    pub name: String,
    /// `N`: 1 (positions only), 2 (the default; with `derivatives`) or 3 (with `second` too).
    #[serde(default = "default_order", skip_serializing_if = "is_default_order")]
    pub order: usize,
    /// The boundary points in loop order (at least 3), point `k` at `θ = 2πk/(n k_e)`
    /// (`k_e` = `samples_per_edge`); the patch's normal `X_r × X_θ` points to the side from
    /// which they run counterclockwise.
    pub points: Vec<[f64; 3]>,
    /// `∂X/∂r` at the points (outward, across the loop): required for order 2 and 3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub derivatives: Option<Vec<[f64; 3]>>,
    /// `∂²X/∂r²` at the points: required for order 3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub second: Option<Vec<[f64; 3]>>,
    /// Samples per edge of the closed polyline through the points, 1 to 64 (default 1: the
    /// points are the samples).
    #[serde(
        default = "default_per_edge",
        skip_serializing_if = "is_default_per_edge"
    )]
    pub samples_per_edge: usize,
}

fn default_order() -> usize {
    2
}
fn is_default_order(n: &usize) -> bool {
    *n == 2
}
fn default_per_edge() -> usize {
    1
}
fn is_default_per_edge(n: &usize) -> bool {
    *n == 1
}
