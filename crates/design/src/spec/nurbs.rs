//! The `[[nurbs]]` tables of the design file: (rational) tensor-product B-spline surfaces, the
//! faces `pdeshape import` reads from `B_SPLINE_SURFACE_WITH_KNOTS` (and its rational form).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A reference surface `X(s, t) = Σ_ij N_i(s) M_j(t) w_ij P_ij / Σ_ij N_i(s) M_j(t) w_ij` with
/// the B-splines `N_i` of degree `degree[0]` on `knots_u` and `M_j` of degree `degree[1]` on
/// `knots_v` (all weights 1 when `weights` is left out: a polynomial B-spline surface). As a
/// surface of the design, `u ∈ [0, 1]` runs linearly over the `knots_u` domain and `v` is the
/// knot parameter of `knots_v`; its partial derivatives are exact to second order. Like a
/// `[[parametric]]` surface with `reference = true`, it is a neighbour that `[[nsided]]` and
/// `[[network]]` sides may be tangent to (`tangent_to`) and that `check` measures against, not
/// part of the design's output; it covers the surface's whole parameter box, not a trimmed face.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NurbsSpec {
    /// Unique name of the surface (shared with the names of the other surfaces).
    pub name: String,
    /// The degrees `[p, q]` in `u` and in `v`, each 1 to 30.
    pub degree: [usize; 2],
    /// The full knot vector in `u`, non-decreasing: `rows + p + 1` values.
    pub knots_u: Vec<f64>,
    /// The full knot vector in `v`, non-decreasing: `columns + q + 1` values.
    pub knots_v: Vec<f64>,
    /// The control points as rows along `u`, each row the points along `v`
    /// (`control[i][j] = P_ij`, as STEP lists them).
    pub control: Vec<Vec<[f64; 3]>>,
    /// Positive weights in the same rows (`weights[i][j] = w_ij`): a rational surface (NURBS).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<Vec<Vec<f64>>>,
}
