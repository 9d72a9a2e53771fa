//! `[[trims]]`: holes cut out of a surface by closed curves in its `(u, v)` parameter plane
//! (§5.2).

use schemars::JsonSchema;
use serde::de::Deserializer;
use serde::{Deserialize, Serialize};

/// The holes of one surface.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TrimSpec {
    /// The surface's name (a patch's `name`, a `[[parametric]]` name, …); may be left out when
    /// the design has a single surface.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<String>,
    /// How the region around the holes is re-meshed: `"cdt"` (default; any curves),
    /// `"bilinear"` or `"laplace"` (the book's methods, convex curves).
    #[serde(default, skip_serializing_if = "TrimMethodSpec::is_default")]
    pub method: TrimMethodSpec,
    /// The trim curves, each a closed curve in `(u, v)`; their insides are removed.
    #[serde(
        deserialize_with = "deserialize_curves",
        serialize_with = "serialize_curves"
    )]
    #[schemars(with = "Vec<TrimCurveSpec>")]
    pub curves: Vec<TrimCurveSpec>,
}

/// The re-meshing method's name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum TrimMethodSpec {
    /// `"cdt"`: constrained Delaunay triangulation of the band around the holes (any curves;
    /// the default).
    #[default]
    Cdt,
    /// `"bilinear"`: the book's bilinear four-region mesh (convex curves, §5.2).
    Bilinear,
    /// `"laplace"`: the book's Laplace mapping of the annulus (Eq. 5.3; convex curves).
    Laplace,
}

impl TrimMethodSpec {
    fn is_default(&self) -> bool {
        *self == TrimMethodSpec::Cdt
    }
}

/// A closed curve in the `(u, v)` plane, by `type`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(tag = "type")]
pub enum TrimCurveSpec {
    /// `center + radius (cos θ, sin θ)`.
    #[serde(rename = "circle")]
    Circle {
        /// Centre [u, v].
        center: [f64; 2],
        /// Radius in (u, v) (> 0).
        radius: f64,
    },
    /// `center + R(angle) (a cos θ, b sin θ)` with `radii = [a, b]`; `angle` in radians.
    #[serde(rename = "ellipse")]
    Ellipse {
        /// Centre [u, v].
        center: [f64; 2],
        /// Semi-axes [a, b] (> 0).
        radii: [f64; 2],
        /// Rotation of the a axis from the u axis, radians.
        #[serde(default, skip_serializing_if = "super::write::is_zero")]
        angle: f64,
    },
    /// The closed polygon through `points` (the last joins the first).
    #[serde(rename = "polyline")]
    Polyline {
        /// The corners [u, v] in order.
        points: Vec<[f64; 2]>,
    },
    /// The closed uniform B-spline of `degree` (default 3) over `points` taken cyclically.
    #[serde(rename = "bspline")]
    Bspline {
        /// Degree (default 3).
        #[serde(default = "default_degree")]
        degree: usize,
        /// Control points [u, v], taken cyclically.
        points: Vec<[f64; 2]>,
    },
}

fn default_degree() -> usize {
    3
}

/// Reads the curve tables by their `type` key, keeping the path of an error inside them.
fn deserialize_curves<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<TrimCurveSpec>, D::Error> {
    let tables = Vec::<toml::Table>::deserialize(d)?;
    tables
        .into_iter()
        .map(|t| super::types::deserialize_tagged(t, "type", ""))
        .collect()
}

fn serialize_curves<S: serde::Serializer>(v: &[TrimCurveSpec], s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::SerializeSeq;
    let mut seq = s.serialize_seq(Some(v.len()))?;
    for c in v {
        seq.serialize_element(&super::write::Tagged {
            tag: "type",
            value: c,
        })?;
    }
    seq.end()
}

/// Reads one curve table by its `type` key (the `path` of an `on_patch` curve).
pub(crate) fn deserialize_curve<'de, D: Deserializer<'de>>(
    d: D,
) -> Result<TrimCurveSpec, D::Error> {
    let table = toml::Table::deserialize(d)?;
    super::types::deserialize_tagged(table, "type", "")
}

/// Writes one curve table with its `type` key.
pub(crate) fn serialize_curve<S: serde::Serializer>(
    c: &TrimCurveSpec,
    s: S,
) -> Result<S::Ok, S::Error> {
    super::write::Tagged {
        tag: "type",
        value: c,
    }
    .serialize(s)
}
