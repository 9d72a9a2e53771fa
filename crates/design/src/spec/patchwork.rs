//! The `[[patchwork]]` tables of the design file: a layout of corners, edges and faces given
//! explicitly (what `pdeshape fit` writes for a general mesh), every face an n-sided PDE patch,
//! the faces on either side of an edge sharing the tangent planes the edge carries (see
//! `design/patchwork.rs`).

use super::nsided::{
    default_a, default_degree, default_order, is_default_a, is_default_degree, is_default_order,
};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A patch layout: corners with their tangent planes, edges between corners (cubic Hermite
/// curves with a normal field along them) and faces (loops of 3 to 8 corners), each face an
/// n-sided PDE patch, G1 across every edge two faces share.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PatchworkSpec {
    /// Unique name; face `k` is the surface `name.k` (its pieces `name.k.0`, … when it does
    /// not have four sides).
    pub name: String,
    /// `N`: 1 (Laplace, positions only; edges are creases) or 2 (the default; G1 across edges).
    #[serde(default = "default_order", skip_serializing_if = "is_default_order")]
    pub order: usize,
    /// The smoothing parameter `a > 0` (default 1) of every face's operator.
    #[serde(default = "default_a", skip_serializing_if = "is_default_a")]
    pub a: f64,
    /// The degree of the faces' correction polynomials, 0 to 24 (default 12).
    #[serde(default = "default_degree", skip_serializing_if = "is_default_degree")]
    pub degree: usize,
    /// The corners [x, y, z].
    pub points: Vec<[f64; 3]>,
    /// The normal of the tangent plane at each corner (one per point; any length but 0).
    pub normals: Vec<[f64; 3]>,
    /// The edges between corners.
    pub edges: Vec<PatchworkEdgeSpec>,
    /// The faces: loops of 3 to 8 corner indices, counterclockwise about the normals; every
    /// pair of consecutive corners is an edge, and an edge is run by at most two faces, in
    /// opposite directions.
    pub faces: Vec<Vec<usize>>,
}

/// One edge of a `[[patchwork]]`: the cubic Hermite curve from corner `ends[0]` (at
/// parameter 0) to `ends[1]` (at 1).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PatchworkEdgeSpec {
    /// The corners it joins (indices into `points`).
    pub ends: [usize; 2],
    /// The curve's derivatives at its start and end (`d0`, `d1` of a Hermite curve).
    pub tangents: [[f64; 3]; 2],
    /// The normal field between the ends: samples at the inner Chebyshev–Lobatto points
    /// `s_j = (1 − cos(πj/m))/2`, `j = 1 … m − 1`, of the curve's parameter (the ends take the
    /// corners' normals); empty: turned linearly from one corner's normal to the other's.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub normals: Vec<[f64; 3]>,
    /// The faces on either side meet at a crease (G0) instead of sharing a tangent plane
    /// (default false).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub crease: bool,
    /// The normals at the edge's start and end when they are not its corners' `normals`: at a
    /// corner on a sharp feature of the surface (the corner of a box, a point of a drilled
    /// hole's rim) the faces on either side of the feature have tangent planes of their own,
    /// and each edge leaving the corner takes the plane of the faces it runs between. The
    /// edge's normal field then starts and ends with these, and its end tangents are judged
    /// against them. Two edges along which a face shares its neighbours' tangent planes must
    /// give that face's corner between them the same normal; where they do not, both are
    /// creases.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end_normals: Option<[[f64; 3]; 2]>,
}
