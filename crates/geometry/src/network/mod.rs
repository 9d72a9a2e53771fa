//! Networks of curves that cross: where they meet, the pieces between the meeting points, the
//! faces those pieces bound, and one tangent plane per meeting point with a normal field along
//! every piece, so that the patches filling two faces on either side of a piece can share it
//! (G1 across the network).
//!
//! # Method
//!
//! - **Meeting points** ([`find`](Network::find)): every curve is sampled as a polyline;
//!   segments of two curves that come close are refined by Gauss–Newton on `|A(s) − B(t)|²`
//!   (the parameters kept in their intervals, so an end lying on another curve is found), and
//!   a pair meets where the distance is at most the tolerance. Meeting points and curve ends
//!   within the tolerance of each other are one node.
//! - **Pieces**: each curve is cut at its nodes; pieces that end at a node no other piece
//!   reaches (overshoots of a sketch) are dropped, repeatedly.
//! - **Tangent planes**: at a node, the plane that fits the unit tangents of its pieces best
//!   (the eigenvector of `Σ t tᵀ` with the smallest eigenvalue is its normal); the largest
//!   angle of a tangent out of that plane is the node's residual (0 where two smooth curves
//!   cross). Normals are oriented consistently by carrying each across the pieces with a
//!   rotation-minimising frame (the double-reflection method).
//! - **Faces**: at every node the pieces are ordered counterclockwise about the normal; a face
//!   is traced by leaving each node on the piece that comes just clockwise of the one it
//!   arrived on, so faces lie to the left and run counterclockwise. A face is *filled* when
//!   the mean of its corner angles (measured in the tangent planes) is below `π`; the loop
//!   around the network's outside turns the other way (its corners are the reflex
//!   complements of the inner ones) and is left open. Consecutive sides of a face that are
//!   adjacent pieces of one curve (a T-junction on the far side) are one side of the face.
//! - **Normal fields** ([`normal_samples`](Network::normal_samples)): along a piece, the start
//!   node's normal carried by the rotation-minimising frame, turned about the tangent by an
//!   angle growing linearly to what the end node's normal needs. Both faces along a piece use
//!   the same samples, so their tangent planes agree along it.

mod faces;
pub(crate) mod meet;
mod normals;
pub use normals::{lobatto, normal_to};
#[cfg(test)]
mod tests;

use crate::curve::SharedCurve;
use crate::{Error, Result, Vec3};

/// The most curves of one network (their meeting points are sought pair by pair).
pub const MAX_CURVES: usize = 256;

/// One curve of a network: `curve` run over `[t0, t1]`.
#[derive(Clone, Debug)]
pub struct NetworkCurve {
    /// The curve.
    pub curve: SharedCurve,
    /// The start of the interval used.
    pub t0: f64,
    /// The end of the interval used (`t0 < t1`).
    pub t1: f64,
}

/// Options of [`Network::find`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NetworkOptions {
    /// How close two curves must come to meet, relative to the size of the network (the
    /// diagonal of its bounding box).
    pub tolerance: f64,
}

impl Default for NetworkOptions {
    fn default() -> Self {
        NetworkOptions { tolerance: 1e-9 }
    }
}

/// A point where pieces of the network meet.
#[derive(Clone, Debug)]
pub struct Node {
    /// The point (the first curve point found there).
    pub point: Vec3,
    /// The unit normal of the node's tangent plane, oriented consistently over the network.
    pub normal: Vec3,
    /// The largest angle (radians) between a piece's tangent at the node and the tangent
    /// plane: 0 when the pieces can share one tangent plane there.
    pub residual: f64,
    /// The number of piece ends at the node.
    pub valence: usize,
}

/// A piece of a curve between two nodes.
#[derive(Clone, Debug)]
pub struct Edge {
    /// The index of the curve in the list given to [`Network::find`].
    pub curve: usize,
    /// The curve's parameter at the start node.
    pub t0: f64,
    /// The curve's parameter at the end node (`t0 < t1`).
    pub t1: f64,
    /// The start node.
    pub start: usize,
    /// The end node.
    pub end: usize,
}

/// A piece of a face's boundary: an edge, run forwards or backwards.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Run {
    /// The edge.
    pub edge: usize,
    /// Whether the face runs the edge from its start to its end.
    pub forward: bool,
}

/// A loop of the network: its sides in counterclockwise order, each one or more adjacent
/// pieces of one curve run in one direction.
#[derive(Clone, Debug)]
pub struct Face {
    /// The sides; side `k` ends where side `k + 1` starts.
    pub sides: Vec<Vec<Run>>,
    /// The sum of the corner angles (radians) in the nodes' tangent planes.
    pub angle_sum: f64,
}

impl Face {
    /// Every run of the face, in order.
    pub fn runs(&self) -> impl Iterator<Item = &Run> {
        self.sides.iter().flatten()
    }
}

/// A network of curves, its nodes, pieces and faces.
#[derive(Clone, Debug)]
pub struct Network {
    /// The curves as given.
    pub curves: Vec<NetworkCurve>,
    /// The nodes.
    pub nodes: Vec<Node>,
    /// The pieces between nodes, in the order of the curves and along each.
    pub edges: Vec<Edge>,
    /// The faces to fill, in a fixed order (of their first edge).
    pub faces: Vec<Face>,
    /// The loops left open: the network's outer boundary (and any loop that turns the other
    /// way).
    pub open: Vec<Face>,
    /// The diagonal of the network's bounding box.
    pub size: f64,
    /// The absolute meeting tolerance.
    pub tolerance: f64,
}

impl Network {
    /// Finds the nodes, pieces and faces of a network of curves. Errors name the curve (as
    /// `curves[i]`) or the face (by its curves) at fault.
    pub fn find(curves: &[NetworkCurve], options: &NetworkOptions) -> Result<Network> {
        if curves.len() < 2 {
            return Err(Error::invalid(
                "a network needs at least 2 curves that cross or meet",
            ));
        }
        if curves.len() > MAX_CURVES {
            return Err(Error::invalid(format!(
                "{} curves; a network has at most {MAX_CURVES}",
                curves.len()
            )));
        }
        if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
            return Err(Error::invalid("the tolerance must be finite and > 0"));
        }
        let polylines = meet::sample_all(curves, meet::SEGMENTS)?;
        let size = meet::size(&polylines);
        if !(size > 0.0 && size.is_finite()) {
            return Err(Error::invalid("the curves of the network span no space"));
        }
        let tolerance = options.tolerance * size;
        let hits = meet::intersections(
            curves,
            &polylines,
            tolerance,
            1.0,
            meet::CHUNK,
            &|_, _, _, _| false,
        );
        let (points, edges) = meet::pieces(curves, &hits, tolerance)?;
        let mut network = Network {
            curves: curves.to_vec(),
            nodes: Vec::new(),
            edges,
            faces: Vec::new(),
            open: Vec::new(),
            size,
            tolerance,
        };
        network.nodes = normals::nodes(&network, &points)?;
        let (faces, open) = faces::trace(&network)?;
        network.faces = faces;
        network.open = open;
        Ok(network)
    }

    /// The faces (index, side) that run along `edge`: two for a piece inside the network, one
    /// on its boundary.
    pub fn faces_of(&self, edge: usize) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for (f, face) in self.faces.iter().enumerate() {
            for (k, side) in face.sides.iter().enumerate() {
                if side.iter().any(|r| r.edge == edge) {
                    out.push((f, k));
                }
            }
        }
        out
    }

    /// The unit tangent of `edge` at its start (`at_start`) or end, pointing along the curve.
    pub fn tangent(&self, edge: usize, at_start: bool) -> Vec3 {
        let e = &self.edges[edge];
        normals::curve_tangent(&self.curves[e.curve], if at_start { e.t0 } else { e.t1 })
    }

    /// The normal field along `edge` at the Chebyshev–Lobatto points `s_j = (1 − cos(πj/m))/2`,
    /// `j = 0 … m`, of the edge run forwards (`t = t0 + s (t1 − t0)`): unit vectors normal to
    /// the curve, from the start node's normal to the end node's (each projected normal to
    /// the curve where the node's tangent plane does not hold it).
    pub fn normal_samples(&self, edge: usize, m: usize) -> Vec<Vec3> {
        normals::edge_field(self, edge, m)
    }

    /// Replaces node `k`'s normal (a neighbour surface's, say), keeping the orientation of the
    /// network's normals.
    pub fn set_normal(&mut self, k: usize, normal: Vec3) {
        let n = normal.normalize();
        let n = if n.dot(&self.nodes[k].normal) < 0.0 {
            -n
        } else {
            n
        };
        // The residual is now measured against this plane.
        let at_k = self.edges.iter().enumerate().flat_map(|(e, edge)| {
            let start = (edge.start == k).then_some(2 * e);
            let end = (edge.end == k).then_some(2 * e + 1);
            start.into_iter().chain(end)
        });
        let residual = at_k
            .map(|h| normals::leaving(self, h).dot(&n).abs().min(1.0).asin())
            .fold(0.0, f64::max);
        let node = &mut self.nodes[k];
        node.normal = n;
        node.residual = residual;
    }

    /// The edges that two filled faces share.
    pub fn inner_edges(&self) -> Vec<usize> {
        (0..self.edges.len())
            .filter(|&e| self.faces_of(e).len() == 2)
            .collect()
    }
}
