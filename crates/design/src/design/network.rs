//! Builds the `[[network]]` tables: the faces of a network of curves as n-sided patches that
//! share a tangent plane along every inner curve (G1 across the network), and tangent to a
//! named surface along outline curves that ask for it.

use super::curves::CurveBuilder;
use super::nsided::{
    append_unique, find_surface, interval, lobatto_interpolate, push_pieces, sample_normals,
    NORMAL_SAMPLES,
};
use super::solved::DesignSurface;
use crate::network::{Network, NetworkCurve, NetworkOptions, Run};
use crate::nsided::{NSidedOptions, NSidedPatch, Ribbon, Side, MAX_SIDES};
use crate::spec::{CurveRef, NetworkSpec, OperatorSpec};
use crate::{Error, Result, Vec3};
use std::sync::Arc;

/// A node whose pieces leave its tangent plane by more than this (radians, 1°) is a corner of
/// the network: the pieces at it meet at creases.
pub const CREASE_ANGLE: f64 = std::f64::consts::PI / 180.0;

/// How the faces along a piece of the network meet it.
#[derive(Clone, Debug, PartialEq)]
pub enum Joint {
    /// Two faces share the piece and a tangent plane along it (G1).
    Shared,
    /// Two faces share the piece and meet at a crease (G0): asked for (`crease = true`), or
    /// an end of the piece is a corner of the network (see [`CREASE_ANGLE`]), or the order is
    /// 1.
    Crease,
    /// One face, tangent to the named surface along the piece.
    TangentTo(String),
    /// One face, its position only (the network's outline).
    Outline,
}

/// A solved `[[network]]`.
#[derive(Clone)]
pub struct SolvedNetwork {
    /// The table's `name`.
    pub name: String,
    /// The nodes, pieces and faces found.
    pub network: Network,
    /// Per curve of the table, its name in messages (`rim`, or `network[0].curves[2]` for an
    /// inline curve).
    pub curve_names: Vec<String>,
    /// Per face, the patch filling it (the surfaces `name.k` or `name.k.j`).
    pub faces: Vec<Arc<NSidedPatch>>,
    /// Per piece (`network.edges`), how the faces along it meet.
    pub joints: Vec<Joint>,
}

impl std::fmt::Debug for SolvedNetwork {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SolvedNetwork")
            .field("name", &self.name)
            .field("faces", &self.faces.len())
            .field("joints", &self.joints)
            .finish()
    }
}

impl SolvedNetwork {
    /// Where piece `edge` runs along face `face`: the face's side and the interval of that
    /// side's parameter `s ∈ [0, 1]` the piece covers (from the piece's start to its end).
    pub fn place_on_face(&self, edge: usize, face: usize) -> Option<(usize, f64, f64)> {
        let e = &self.network.edges[edge];
        for (k, side) in self.network.faces[face].sides.iter().enumerate() {
            if side.iter().any(|r| r.edge == edge) {
                let (t0, t1) = side_interval(&self.network, side);
                let s = |t: f64| (t - t0) / (t1 - t0);
                return Some((k, s(e.t0), s(e.t1)));
            }
        }
        None
    }

    /// The names of the curves around face `k`, in order.
    pub fn face_curves(&self, k: usize) -> Vec<&str> {
        self.network.faces[k]
            .sides
            .iter()
            .map(|side| self.curve_names[self.network.edges[side[0].edge].curve].as_str())
            .collect()
    }
}

/// Builds every `[[network]]`, appending its faces' surfaces to `surfaces`; a face may be
/// tangent to any surface before it.
pub(crate) fn build_networks(
    specs: &[NetworkSpec],
    builder: &mut CurveBuilder<'_>,
    surfaces: &mut Vec<DesignSurface>,
) -> Result<Vec<SolvedNetwork>> {
    let mut out = Vec::with_capacity(specs.len());
    for (i, spec) in specs.iter().enumerate() {
        let place = format!("network[{i}]");
        let solved = build_one(spec, builder, surfaces, &place).map_err(|e| e.at(&place))?;
        push_faces(&solved, spec.order, spec.a, &place, surfaces)?;
        out.push(solved);
    }
    Ok(out)
}

/// The faces of a solved network (or patchwork) as the design's surfaces `name.k` (their pieces
/// `name.k.j`), each with the polyharmonic operator of order `order` and parameter `a`.
pub(super) fn push_faces(
    solved: &SolvedNetwork,
    order: usize,
    a: f64,
    place: &str,
    surfaces: &mut Vec<DesignSurface>,
) -> Result<()> {
    let operator = OperatorSpec::Polyharmonic { order, a };
    let mut new = Vec::new();
    for (k, patch) in solved.faces.iter().enumerate() {
        let name = format!("{}.{k}", solved.name);
        push_pieces(patch, &name, place, &operator, &mut new);
    }
    append_unique(surfaces, new, place)
}

fn build_one(
    spec: &NetworkSpec,
    builder: &mut CurveBuilder<'_>,
    surfaces: &[DesignSurface],
    place: &str,
) -> Result<SolvedNetwork> {
    if !(1..=2).contains(&spec.order) {
        return Err(Error::invalid(format!(
            "must be 1 or 2 (got {}); order 3 is not available for networks",
            spec.order
        ))
        .at("order"));
    }
    let mut curves = Vec::with_capacity(spec.curves.len());
    let mut curve_names = Vec::with_capacity(spec.curves.len());
    for (j, c) in spec.curves.iter().enumerate() {
        let at = format!("curves[{j}]");
        let curve = builder.reference(&c.curve, &format!("{place}.{at}.curve"))?;
        let [t0, t1] = interval(&curve, c.range).map_err(|e| e.at(&at))?;
        curves.push(NetworkCurve {
            curve,
            t0: t0.min(t1),
            t1: t0.max(t1),
        });
        curve_names.push(match &c.curve {
            CurveRef::Name(n) => n.clone(),
            CurveRef::Inline(_) => format!("{place}.{at}"),
        });
    }
    let options = NetworkOptions {
        tolerance: spec.tolerance,
    };
    let mut network = Network::find(&curves, &options)?;

    // Outline curves tangent to a surface: the surface's normals along each piece, which also
    // become the normals of the nodes at the piece's ends.
    let mut tangent: Vec<Option<Vec<Vec3>>> = vec![None; network.edges.len()];
    for (e, edge) in network.edges.clone().iter().enumerate() {
        let c = &spec.curves[edge.curve];
        let Some(name) = &c.tangent_to else { continue };
        let at = format!("curves[{}].tangent_to", edge.curve);
        if network.faces_of(e).len() != 1 {
            return Err(Error::invalid(format!(
                "'{}' is not on the network's outline, so it has no side left for '{name}'",
                curve_names[edge.curve]
            ))
            .at(&at));
        }
        let target = find_surface(surfaces, name).map_err(|e| e.at(&at))?;
        let side = Side::position(network.curves[edge.curve].curve.clone(), edge.t0, edge.t1);
        let normals = sample_normals(&side, target.surface()).map_err(|e| e.at(&at))?;
        network.set_normal(edge.start, normals[0]);
        network.set_normal(edge.end, normals[NORMAL_SAMPLES]);
        tangent[e] = Some(normals);
    }

    // How the faces meet along every piece.
    let joints: Vec<Joint> = (0..network.edges.len())
        .map(|e| {
            let edge = &network.edges[e];
            let c = &spec.curves[edge.curve];
            if network.faces_of(e).len() == 2 {
                let corner = network.nodes[edge.start].residual > CREASE_ANGLE
                    || network.nodes[edge.end].residual > CREASE_ANGLE;
                if c.crease || corner || spec.order == 1 {
                    Joint::Crease
                } else {
                    Joint::Shared
                }
            } else {
                match &c.tangent_to {
                    Some(name) if spec.order == 2 => Joint::TangentTo(name.clone()),
                    _ => Joint::Outline,
                }
            }
        })
        .collect();
    let fields: Vec<Option<Arc<Vec<Vec3>>>> = (0..network.edges.len())
        .map(|e| match &joints[e] {
            Joint::Shared => Some(Arc::new(network.normal_samples(e, NORMAL_SAMPLES))),
            Joint::TangentTo(_) => tangent[e].clone().map(Arc::new),
            _ => None,
        })
        .collect();

    let mut faces = Vec::with_capacity(network.faces.len());
    for face in &network.faces {
        let names: Vec<&str> = face
            .sides
            .iter()
            .map(|s| curve_names[network.edges[s[0].edge].curve].as_str())
            .collect();
        let what = format!("the face bounded by {}", names.join(", "));
        let n = face.sides.len();
        if !(3..=MAX_SIDES).contains(&n) {
            return Err(Error::invalid(format!(
                "{what} has {n} sides; a face needs 3 to {MAX_SIDES} (add or remove a curve \
                 across it)"
            )));
        }
        let mut edges_seen: Vec<usize> = face.runs().map(|r| r.edge).collect();
        edges_seen.sort_unstable();
        if edges_seen.windows(2).any(|w| w[0] == w[1]) {
            return Err(Error::invalid(format!(
                "{what} runs along one piece on both sides (a curve that ends inside it)"
            )));
        }
        let mut sides = Vec::with_capacity(n);
        for side in &face.sides {
            let (t0, t1) = side_interval(&network, side);
            let curve = network.curves[network.edges[side[0].edge].curve]
                .curve
                .clone();
            let ribbon = side_ribbon(&network, side, &fields, t0, t1);
            sides.push(Side {
                curve,
                t0,
                t1,
                ribbon,
            });
        }
        let size = face_size(&sides);
        let options = NSidedOptions {
            order: spec.order,
            a: spec.a,
            degree: spec.degree,
            // Two curve points within the tolerance of one node.
            gap_tolerance: 2.0 * network.tolerance / size + 1e-12,
        };
        let patch = NSidedPatch::solve(sides, &options).map_err(|e| {
            let message = format!("{what}: {}", e.message());
            Error::invalid(message)
        })?;
        faces.push(Arc::new(patch));
    }
    if faces.is_empty() {
        return Err(Error::invalid(
            "the network encloses no face: its curves meet, but every loop they make turns \
             outwards",
        ));
    }
    Ok(SolvedNetwork {
        name: spec.name.clone(),
        network,
        curve_names,
        faces,
        joints,
    })
}

/// The curve parameters at the start and end of a face's side (its runs are adjacent pieces
/// of one curve, run one way).
fn side_interval(network: &Network, side: &[Run]) -> (f64, f64) {
    let end = |r: &Run, first: bool| {
        let e = &network.edges[r.edge];
        match (r.forward, first) {
            (true, true) | (false, false) => e.t0,
            _ => e.t1,
        }
    };
    (end(&side[0], true), end(&side[side.len() - 1], false))
}

/// A side's ribbon: the tangent plane of its pieces' normal fields when every piece has one,
/// else its position only.
fn side_ribbon(
    network: &Network,
    side: &[Run],
    fields: &[Option<Arc<Vec<Vec3>>>],
    t0: f64,
    t1: f64,
) -> Ribbon {
    let mut parts = Vec::with_capacity(side.len());
    for r in side {
        let Some(field) = &fields[r.edge] else {
            return Ribbon::Position;
        };
        let e = &network.edges[r.edge];
        parts.push((e.t0, e.t1, field.clone()));
    }
    Ribbon::TangentPlane(Arc::new(move |s: f64| {
        let t = t0 + s * (t1 - t0);
        let (a, b, field) = parts
            .iter()
            .find(|(a, b, _)| t >= a.min(*b) && t <= a.max(*b))
            .unwrap_or_else(|| {
                let first = &parts[0];
                let last = &parts[parts.len() - 1];
                if (t - first.0).abs().min((t - first.1).abs())
                    <= (t - last.0).abs().min((t - last.1).abs())
                {
                    first
                } else {
                    last
                }
            });
        lobatto_interpolate(field, ((t - a) / (b - a)).clamp(0.0, 1.0))
    }))
}

/// The diagonal of the bounding box of a face's sides (sampled).
fn face_size(sides: &[Side]) -> f64 {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for side in sides {
        for j in 0..=16 {
            let p = side.point(j as f64 / 16.0);
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
    }
    (hi - lo).norm().max(1e-300)
}
