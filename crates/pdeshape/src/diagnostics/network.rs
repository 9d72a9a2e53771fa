//! The checks of a `[[network]]`: every face against its sides, every inner curve between the
//! two faces along it, every outline curve against the surface it is tangent to.

use super::{jnum, G1_TOLERANCE};
use crate::design::{Joint, SolvedDesign, SolvedNetwork};
use crate::surface::{ClosestOptions, ClosestPointIndex, Surface};
use crate::Vec3;
use serde_json::{json, Value};
use std::fmt::Write;

/// Samples per piece of the network (between its ends).
const SAMPLES: usize = 48;

/// A face of a network.
#[derive(Clone, Debug)]
pub struct NetworkFace {
    /// The face's surface name (`name.k`; its pieces are `name.k.j` unless it has 4 sides).
    pub name: String,
    /// The curves around it, in order (one per side).
    pub curves: Vec<String>,
    /// The largest distance between the patch and a side, relative to the face's size.
    pub boundary: f64,
    /// The largest angle (radians) by which a side leaves the tangent plane its neighbour
    /// needs at a corner (0 when the network's tangent plane holds every curve there).
    pub tangent_mismatch: f64,
}

/// A piece of a network's curve between two nodes.
#[derive(Clone, Debug)]
pub struct NetworkJoint {
    /// The curve's name.
    pub curve: String,
    /// The piece's parameter interval on the curve.
    pub range: [f64; 2],
    /// `g1` (shared tangent plane), `crease`, `tangent` (to `neighbour`) or `outline`.
    pub kind: &'static str,
    /// The faces along it (their surface names).
    pub faces: Vec<String>,
    /// The neighbour surface of a `tangent` piece.
    pub neighbour: Option<String>,
    /// The largest distance between the two faces along an inner piece.
    pub g0: Option<f64>,
    /// The largest angle (radians) between the two faces' normals along an inner piece, or
    /// between the face's and the neighbour's along a `tangent` piece.
    pub g1: Option<f64>,
}

/// How a `[[network]]` was filled and how its faces meet.
#[derive(Clone, Debug)]
pub struct NetworkDiagnostics {
    /// The table's `name`.
    pub name: String,
    /// The number of nodes.
    pub nodes: usize,
    /// The nodes where the curves leave one tangent plane by more than
    /// [`design::CREASE_ANGLE`](crate::design::CREASE_ANGLE): the pieces there meet at creases.
    pub corners: Vec<Vec3>,
    /// The faces, in order.
    pub faces: Vec<NetworkFace>,
    /// The pieces, in order of the curves and along each.
    pub joints: Vec<NetworkJoint>,
}

impl NetworkDiagnostics {
    /// What deserves a warning.
    pub(super) fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        for f in &self.faces {
            if f.boundary.is_nan() || f.boundary > 1e-10 {
                w.push(format!(
                    "network '{}': face {} meets its sides only to {:.3e} (relative)",
                    self.name, f.name, f.boundary
                ));
            }
            if f.tangent_mismatch.is_nan() || f.tangent_mismatch > G1_TOLERANCE {
                w.push(format!(
                    "network '{}': at a corner of face {} a curve leaves the tangent plane by \
                     {:.3e} rad (no surface is G1 to both sides there)",
                    self.name, f.name, f.tangent_mismatch
                ));
            }
        }
        for j in &self.joints {
            let worse = |x: Option<f64>, tol: f64| x.is_some_and(|x| x.is_nan() || x > tol);
            if matches!(j.kind, "g1" | "tangent") && worse(j.g1, G1_TOLERANCE) {
                w.push(format!(
                    "network '{}': along '{}' [{:.4}, {:.4}] the faces are G1 only to {:.3e} rad",
                    self.name,
                    j.curve,
                    j.range[0],
                    j.range[1],
                    j.g1.unwrap_or(f64::NAN)
                ));
            }
            if worse(j.g0, 1e-9) {
                w.push(format!(
                    "network '{}': along '{}' the faces are apart by {:.3e}",
                    self.name,
                    j.curve,
                    j.g0.unwrap_or(f64::NAN)
                ));
            }
        }
        w
    }

    /// The lines of `pdeshape check`'s report.
    pub(super) fn report(&self, s: &mut String) {
        let sides: Vec<String> = self
            .faces
            .iter()
            .map(|f| f.curves.len().to_string())
            .collect();
        let _ = writeln!(
            s,
            "network '{}': {} faces ({} sides), {} nodes, {} corners",
            self.name,
            self.faces.len(),
            sides.join(", "),
            self.nodes,
            self.corners.len()
        );
        for f in &self.faces {
            let _ = writeln!(
                s,
                "  face {} ({}): sides met to {:.1e} (relative), corner tangent mismatch {:.1e} rad",
                f.name,
                f.curves.join(", "),
                f.boundary,
                f.tangent_mismatch
            );
        }
        for j in &self.joints {
            let what = match (j.kind, &j.neighbour) {
                ("g1", _) => format!(
                    "G1 between {}: G0 {:.1e}, G1 {:.1e} rad",
                    j.faces.join(" | "),
                    j.g0.unwrap_or(f64::NAN),
                    j.g1.unwrap_or(f64::NAN)
                ),
                ("crease", _) => format!(
                    "crease between {}: G0 {:.1e}, angle {:.1e} rad",
                    j.faces.join(" | "),
                    j.g0.unwrap_or(f64::NAN),
                    j.g1.unwrap_or(f64::NAN)
                ),
                ("tangent", Some(n)) => format!(
                    "{} tangent to '{n}': G1 {:.1e} rad",
                    j.faces.join(""),
                    j.g1.unwrap_or(f64::NAN)
                ),
                _ => format!("outline of {} (position only)", j.faces.join("")),
            };
            let _ = writeln!(
                s,
                "  '{}' [{:.4}, {:.4}]: {what}",
                j.curve, j.range[0], j.range[1]
            );
        }
    }

    /// `check --json`'s entry.
    pub(super) fn to_json(&self) -> Value {
        json!({
            "name": self.name,
            "nodes": self.nodes,
            "corners": self.corners.iter().map(|p| [jnum(p.x), jnum(p.y), jnum(p.z)]).collect::<Vec<_>>(),
            "faces": self.faces.iter().map(|f| json!({
                "name": f.name,
                "curves": f.curves,
                "boundary": jnum(f.boundary),
                "tangent_mismatch": jnum(f.tangent_mismatch),
            })).collect::<Vec<_>>(),
            "joints": self.joints.iter().map(|j| json!({
                "curve": j.curve,
                "range": [jnum(j.range[0]), jnum(j.range[1])],
                "kind": j.kind,
                "faces": j.faces,
                "neighbour": j.neighbour,
                "g0": j.g0.map(jnum),
                "g1": j.g1.map(jnum),
            })).collect::<Vec<_>>(),
        })
    }
}

/// Measures every network of a solved design.
pub(super) fn network_diagnostics(built: &SolvedDesign) -> Vec<NetworkDiagnostics> {
    built.networks.iter().map(|n| one(n, built)).collect()
}

fn one(n: &SolvedNetwork, built: &SolvedDesign) -> NetworkDiagnostics {
    let net = &n.network;
    let face_name = |k: usize| format!("{}.{k}", n.name);
    let faces = n
        .faces
        .iter()
        .enumerate()
        .map(|(k, patch)| {
            let report = patch.report(SAMPLES);
            NetworkFace {
                name: face_name(k),
                curves: n.face_curves(k).into_iter().map(str::to_string).collect(),
                boundary: report.boundary.iter().fold(0.0f64, |a, b| a.max(*b)) / report.size,
                tangent_mismatch: report
                    .corners
                    .iter()
                    .fold(0.0f64, |a, c| a.max(c.tangent_mismatch)),
            }
        })
        .collect();
    let mut joints = Vec::with_capacity(net.edges.len());
    for (e, edge) in net.edges.iter().enumerate() {
        let along = net.faces_of(e);
        let points = |f: usize| -> Vec<(Vec3, Vec3)> {
            let Some((side, sa, sb)) = n.place_on_face(e, f) else {
                return Vec::new();
            };
            (0..SAMPLES)
                .map(|q| {
                    let s = sa + (sb - sa) * (q as f64 + 0.5) / SAMPLES as f64;
                    n.faces[f].boundary_normal(side, s)
                })
                .collect()
        };
        let (kind, neighbour, g0, g1) = match &n.joints[e] {
            Joint::Shared | Joint::Crease if along.len() == 2 => {
                let (a, b) = (points(along[0].0), points(along[1].0));
                let (mut g0, mut g1) = (0.0f64, 0.0f64);
                for ((pa, na), (pb, nb)) in a.iter().zip(&b) {
                    g0 = nan_max(g0, (pa - pb).norm());
                    g1 = nan_max(g1, line_angle(*na, *nb));
                }
                let kind = if n.joints[e] == Joint::Shared {
                    "g1"
                } else {
                    "crease"
                };
                (kind, None, Some(g0), Some(g1))
            }
            Joint::TangentTo(name) => {
                let g1 = built
                    .surfaces
                    .iter()
                    .find(|s| &s.name == name)
                    .map(|target| g1_to_surface(&points(along[0].0), target.surface()));
                ("tangent", Some(name.clone()), None, g1)
            }
            _ => ("outline", None, None, None),
        };
        joints.push(NetworkJoint {
            curve: n.curve_names[edge.curve].clone(),
            range: [edge.t0, edge.t1],
            kind,
            faces: along.iter().map(|(f, _)| face_name(*f)).collect(),
            neighbour,
            g0,
            g1,
        });
    }
    NetworkDiagnostics {
        name: n.name.clone(),
        nodes: net.nodes.len(),
        corners: net
            .nodes
            .iter()
            .filter(|x| x.residual > crate::design::CREASE_ANGLE)
            .map(|x| x.point)
            .collect(),
        faces,
        joints,
    }
}

/// The largest angle between the normals at `points` and a surface's normals at their
/// closest points on it.
pub(super) fn g1_to_surface(points: &[(Vec3, Vec3)], surface: &dyn Surface) -> f64 {
    let index = ClosestPointIndex::new(surface, &ClosestOptions::default());
    let mut worst: f64 = 0.0;
    for (p, n) in points {
        let angle = index.closest(*p).map_or(f64::NAN, |c| {
            line_angle(*n, surface.partials(c.u, c.v).normal())
        });
        worst = nan_max(worst, angle);
    }
    worst
}

/// The angle between two lines (up to orientation), accurate for tiny angles.
fn line_angle(a: Vec3, b: Vec3) -> f64 {
    a.cross(&b).norm().atan2(a.dot(&b).abs())
}

/// The larger of two numbers, NaN if either is.
fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}
