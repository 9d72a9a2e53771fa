//! The `[[network]]` tables of the design file: curves that cross, whose faces are filled with
//! n-sided PDE patches that share a tangent plane along every inner curve (see
//! `pdeshape_geometry::network`).

use super::nsided::{
    default_a, default_degree, default_order, is_default_a, is_default_degree, is_default_order,
};
use super::types::CurveRef;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A network of curves that cross or meet: every face it encloses (3 to 8 sides) becomes an
/// n-sided PDE patch, G1 to its neighbours across every inner curve.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NetworkSpec {
    /// Unique name; face `k` is the surface `name.k` (its pieces `name.k.0`, … when it does
    /// not have four sides).
    pub name: String,
    /// The curves, in any order and direction.
    pub curves: Vec<NetworkCurveSpec>,
    /// `N`: 1 (Laplace, positions only) or 2 (the default; G1 across inner curves).
    #[serde(default = "default_order", skip_serializing_if = "is_default_order")]
    pub order: usize,
    /// The smoothing parameter `a > 0` (default 1) of every face's operator.
    #[serde(default = "default_a", skip_serializing_if = "is_default_a")]
    pub a: f64,
    /// The degree of the faces' correction polynomials, 0 to 24 (default 12).
    #[serde(default = "default_degree", skip_serializing_if = "is_default_degree")]
    pub degree: usize,
    /// How close two curves must come to meet, relative to the size of the network (default
    /// 1e-9).
    #[serde(
        default = "default_tolerance",
        skip_serializing_if = "is_default_tolerance"
    )]
    pub tolerance: f64,
}

/// One curve of a `[[network]]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NetworkCurveSpec {
    /// The curve: the name of a curve in `[curves]`, or an inline curve table.
    pub curve: CurveRef,
    /// The parameter interval used (default: the curve's whole domain; required for a
    /// periodic curve).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<[f64; 2]>,
    /// For a curve on the network's outline: the faces along it are tangent (G1) to the named
    /// surface of the design.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangent_to: Option<String>,
    /// The faces on either side of this curve meet at a crease (G0) instead of sharing a
    /// tangent plane (default false).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub crease: bool,
}

fn default_tolerance() -> f64 {
    1e-9
}
fn is_default_tolerance(g: &f64) -> bool {
    *g == 1e-9
}
