//! The `[[nsided]]` tables of the design file: patches bounded by a loop of 3 to 8 curves,
//! tangent (G1) on any side to another surface of the design or to a given cross-boundary
//! derivative, and with order 3 curvature-continuous (G2) to it or to a given second cross
//! derivative (see `pdeshape_geometry::nsided`).

use super::types::CurveRef;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A patch bounded by a loop of 3 to 8 curves, solving the PDE of order `2N` on a regular
/// n-gon with the sides met exactly.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NSidedSpec {
    /// Unique name of the patch (shared with the names of the other surfaces). A patch of
    /// `n ≠ 4` sides is presented as `n` four-sided pieces named `name.0`, `name.1`, …
    pub name: String,
    /// The sides in loop order; each ends where the next starts.
    pub sides: Vec<LoopSideSpec>,
    /// `N`: 1 (Laplace, positions only), 2 (the default; positions and ribbons) or 3
    /// (positions, ribbons and curvature ribbons: `g2`, `second_derivative`).
    #[serde(default = "default_order", skip_serializing_if = "is_default_order")]
    pub order: usize,
    /// The smoothing parameter `a > 0` (default 1) of `∂²/∂x² + a² ∂²/∂y²`, `x` along side 0.
    #[serde(default = "default_a", skip_serializing_if = "is_default_a")]
    pub a: f64,
    /// The degree of the correction polynomials, 0 to 24 (default 12).
    #[serde(default = "default_degree", skip_serializing_if = "is_default_degree")]
    pub degree: usize,
    /// The largest gap allowed at a corner, relative to the size of the boundary (default
    /// 1e-9).
    #[serde(default = "default_gap", skip_serializing_if = "is_default_gap")]
    pub gap_tolerance: f64,
}

/// One side of an `[[nsided]]` patch.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LoopSideSpec {
    /// The curve: the name of a curve in `[curves]`, or an inline curve table.
    pub curve: CurveRef,
    /// The parameter interval run over, from the first value to the second (default: the
    /// curve's whole domain; required for a periodic curve).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<[f64; 2]>,
    /// Run the interval backwards (default false).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reverse: bool,
    /// G1: the patch is tangent along this side to the named surface of the design (a patch,
    /// a `[[parametric]]` surface, an earlier `[[nsided]]` patch or one of its pieces).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangent_to: Option<String>,
    /// G1: the cross-boundary derivative `∂X/∂t` (t the distance from the side in side
    /// lengths), a curve over the same interval as the side's curve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub derivative: Option<CurveRef>,
    /// G2 (with `tangent_to`, order 3): the patch also takes the named surface's normal
    /// curvature across the side (default false).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub g2: bool,
    /// G2 (with `derivative`, order 3): the second cross-boundary derivative `∂²X/∂t²`, a
    /// curve over the same interval as the side's curve.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub second_derivative: Option<CurveRef>,
}

impl NSidedSpec {
    /// A patch with the default order, smoothing parameter, degree and gap tolerance.
    pub fn new(name: String, sides: Vec<LoopSideSpec>) -> NSidedSpec {
        NSidedSpec {
            name,
            sides,
            order: default_order(),
            a: default_a(),
            degree: default_degree(),
            gap_tolerance: default_gap(),
        }
    }
}

pub(super) fn default_order() -> usize {
    2
}
pub(super) fn is_default_order(n: &usize) -> bool {
    *n == 2
}
pub(super) fn default_a() -> f64 {
    1.0
}
pub(super) fn is_default_a(a: &f64) -> bool {
    *a == 1.0
}
pub(super) fn default_degree() -> usize {
    12
}
pub(super) fn is_default_degree(d: &usize) -> bool {
    *d == 12
}
fn default_gap() -> f64 {
    1e-9
}
fn is_default_gap(g: &f64) -> bool {
    *g == 1e-9
}
