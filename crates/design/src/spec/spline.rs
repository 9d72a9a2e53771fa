//! The `[spline]` section of a design file: a B-spline or Bézier surface solving a linear PDE
//! (see `docs/design-file.md`, section "[spline]").

use super::types::V3;
use super::write::{is_false, is_zero, never, serialize_kind};
use schemars::JsonSchema;
use serde::{Deserialize, Deserializer, Serialize};

/// `[spline]`: degrees, knots, the PDE, and the control points the designer fixes.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SplineSpec {
    /// Degrees `[p, q]` in u and v, each 1 to 20.
    #[serde(deserialize_with = "deserialize_pair")]
    pub degree: [usize; 2],
    /// Spans `[s_u, s_v]` of clamped uniform knot vectors on `[0, 1]` (default `[1, 1]`: a
    /// Bézier patch). Not allowed together with `knots_u`/`knots_v`.
    #[serde(
        default,
        deserialize_with = "deserialize_some_pair",
        skip_serializing_if = "Option::is_none"
    )]
    pub spans: Option<[usize; 2]>,
    /// The full knot vector in u (`n_u + p + 1` non-decreasing values); with `knots_v`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub knots_u: Option<Vec<f64>>,
    /// The full knot vector in v (`n_v + q + 1` values); with `knots_u`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub knots_v: Option<Vec<f64>>,
    /// The PDE (a table with `kind`).
    #[serde(
        deserialize_with = "deserialize_spline_operator",
        serialize_with = "serialize_kind"
    )]
    #[schemars(with = "SplineOperatorSpec")]
    pub operator: SplineOperatorSpec,
    /// Solve in exact rational arithmetic (every number of the file taken at its exact binary
    /// value) instead of `f64` (default false).
    #[serde(default, skip_serializing_if = "is_false")]
    #[schemars(skip_serializing_if = "never")]
    pub exact: bool,
    /// A whole control net, `n_u` rows of `n_v` points `[x, y, z]` (row `i` along u), from
    /// which `fix` takes the fixed points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub net: Option<Vec<Vec<V3>>>,
    /// Which points of `net` are fixed: "boundary" (the outer ring), "two-rings" (boundary and
    /// the ring inside it), "first-last-rows" (rows `i = 0` and `i = n_u − 1`), or "all".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fix: Option<FixSpec>,
    /// Individually fixed control points (added to those of `net`/`fix`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fixed: Vec<FixedPointSpec>,
}

/// Which points of `net` are fixed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
pub enum FixSpec {
    /// The outer ring of the net: rows `i = 0` and `i = n_u − 1`, columns `j = 0` and
    /// `j = n_v − 1`.
    #[serde(rename = "boundary")]
    Boundary,
    /// The outer ring and the ring just inside it.
    #[serde(rename = "two-rings")]
    TwoRings,
    /// Rows `i = 0` and `i = n_u − 1` only (the two u-boundaries).
    #[serde(rename = "first-last-rows")]
    FirstLastRows,
    /// Every point of the net (nothing left for the PDE to solve).
    #[serde(rename = "all")]
    All,
}

/// One fixed control point.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct FixedPointSpec {
    /// `[i, j]`: `i` along u, `j` along v, from 0.
    pub index: [usize; 2],
    /// `[x, y, z]`.
    pub point: V3,
}

/// The PDE of a `[spline]` section.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(tag = "kind")]
pub enum SplineOperatorSpec {
    /// `a x_uu + b x_uv + c x_vv + d x_u + e x_v + f x = g` (coefficients default 0).
    #[serde(rename = "second-order")]
    Second {
        /// Coefficient of x_uu.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        a: f64,
        /// Coefficient of x_uv.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        b: f64,
        /// Coefficient of x_vv.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        c: f64,
        /// Coefficient of x_u.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        d: f64,
        /// Coefficient of x_v.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        e: f64,
        /// Coefficient of x.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        f: f64,
        /// Constant right-hand side (default `[0, 0, 0]`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        g: Option<V3>,
    },
    /// `a x_uuuu + b x_uuuv + c x_uuvv + d x_uvvv + e x_vvvv = 0` (coefficients default 0).
    #[serde(rename = "fourth-order")]
    Fourth {
        /// Coefficient of x_uuuu.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        a: f64,
        /// Coefficient of x_uuuv.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        b: f64,
        /// Coefficient of x_uuvv.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        c: f64,
        /// Coefficient of x_uvvv.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        d: f64,
        /// Coefficient of x_vvvv.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        e: f64,
    },
    /// `x_uu + x_vv = 0`.
    #[serde(rename = "laplace")]
    Laplace {},
    /// `x_uuuu + 2 x_uuvv + x_vvvv = 0` (`L_{1,0,2,0,1}`).
    #[serde(rename = "biharmonic")]
    Biharmonic {},
    /// `x_uuvv = 0` (`L_{0,0,1,0,0}`, the Coons functional).
    #[serde(rename = "coons")]
    Coons {},
    /// `x_uuuu + 2a² x_uuvv + a⁴ x_vvvv = 0` (`F_a = L_{1,0,2a²,0,a⁴}`).
    #[serde(rename = "modified-biharmonic")]
    ModifiedBiharmonic {
        /// The parameter a of F_a.
        a: f64,
    },
}

/// Exactly two whole numbers, one for u and one for v (a fixed-size array would quietly ignore
/// a third).
fn deserialize_pair<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<[usize; 2], D::Error> {
    let v = Vec::<usize>::deserialize(d)?;
    match v[..] {
        [a, b] => Ok([a, b]),
        _ => Err(serde::de::Error::custom(format!(
            "expected two whole numbers [u, v], got {} of them",
            v.len()
        ))),
    }
}

fn deserialize_some_pair<'de, D: Deserializer<'de>>(
    d: D,
) -> std::result::Result<Option<[usize; 2]>, D::Error> {
    deserialize_pair(d).map(Some)
}

fn deserialize_spline_operator<'de, D: Deserializer<'de>>(
    d: D,
) -> std::result::Result<SplineOperatorSpec, D::Error> {
    let table = toml::Table::deserialize(d)?;
    super::types::deserialize_tagged(table, "kind", "")
}

#[cfg(test)]
mod tests {
    const EXAMPLE: &str = include_str!("../../../../examples/spline/example1.toml");

    #[test]
    fn degrees_and_spans_are_exactly_two_numbers() {
        assert!(super::super::parse_design(EXAMPLE).is_ok());
        for (from, to) in [
            ("degree = [3, 3]", "degree = [3, 3, 3]"),
            ("degree = [3, 3]", "degree = [3]"),
        ] {
            assert!(EXAMPLE.contains(from));
            let text = EXAMPLE.replace(from, to);
            let e = super::super::parse_design(&text).unwrap_err().to_string();
            assert!(e.contains("expected two whole numbers"), "{to}: {e}");
        }
        let spans = EXAMPLE.replace("degree = [3, 3]", "degree = [3, 3]\nspans = [1, 1, 1]");
        let e = super::super::parse_design(&spans).unwrap_err().to_string();
        assert!(e.contains("expected two whole numbers"), "{e}");
    }
}
