//! Builds the `[[patchwork]]` tables: a layout given corner by corner. Every edge is a cubic
//! Hermite curve between its corners with a normal field along it (the corners' normals at its
//! ends); every face is an n-sided patch whose sides are its edges, each side a tangent-plane
//! ribbon on its edge's field, so the two faces along an edge share its tangent planes (G1).
//! The result is presented as a [`SolvedNetwork`] (its nodes, pieces and faces are the
//! layout's), so `check` measures it like any network.

use super::network::{push_faces, Joint, SolvedNetwork, CREASE_ANGLE};
use super::solved::DesignSurface;
use crate::curve::{Hermite, SharedCurve};
use crate::network::{Edge, Face, Network, NetworkCurve, Node, Run};
use crate::nsided::{NSidedOptions, NSidedPatch, Ribbon, Side, MAX_SIDES};
use crate::spec::PatchworkSpec;
use crate::{Error, Result, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::Arc;

/// The angle (radians) by which a face's corner may leave the plane an edge there gives it
/// with its own `end_normals` before that edge is made a crease: rounding's, far below what
/// `check` reports as a corner's tangent mismatch.
const OWN_PLANE_ANGLE: f64 = 1e-9;

/// The most corners, edges or faces of one layout.
pub const MAX_PATCHWORK_ITEMS: usize = 1 << 20;

/// Builds every `[[patchwork]]`, appending its faces' surfaces to `surfaces`.
pub(crate) fn build_patchworks(
    specs: &[PatchworkSpec],
    surfaces: &mut Vec<DesignSurface>,
) -> Result<Vec<SolvedNetwork>> {
    let mut out = Vec::with_capacity(specs.len());
    for (i, spec) in specs.iter().enumerate() {
        let place = format!("patchwork[{i}]");
        let solved = build_one(spec, &place).map_err(|e| e.at(&place))?;
        push_faces(&solved, spec.order, spec.a, &place, surfaces)?;
        out.push(solved);
    }
    Ok(out)
}

fn vec3(p: &[f64; 3]) -> Vec3 {
    Vec3::new(p[0], p[1], p[2])
}

fn finite(p: &[f64; 3], at: &str) -> Result<Vec3> {
    if p.iter().all(|x| x.is_finite()) {
        Ok(vec3(p))
    } else {
        Err(Error::invalid(format!("[{}, {}, {}] is not finite", p[0], p[1], p[2])).at(at))
    }
}

/// The `j`-th of `m + 1` Chebyshev–Lobatto points on `[0, 1]`, increasing.
fn lobatto(j: usize, m: usize) -> f64 {
    0.5 * (1.0 - (std::f64::consts::PI * j as f64 / m as f64).cos())
}

/// The polynomial through `values` at the Chebyshev–Lobatto points, at `s` (barycentric).
fn interpolate(values: &[Vec3], s: f64) -> Vec3 {
    let m = values.len() - 1;
    let mut num = Vec3::zeros();
    let mut den = 0.0;
    for (j, v) in values.iter().enumerate() {
        let d = s - lobatto(j, m);
        if d == 0.0 {
            return *v;
        }
        let mut w = if j % 2 == 0 { 1.0 } else { -1.0 };
        if j == 0 || j == m {
            w *= 0.5;
        }
        num += v * (w / d);
        den += w / d;
    }
    num / den
}

fn tangent(curve: &SharedCurve, s: f64) -> Vec3 {
    let mut d = [Vec3::zeros(); 2];
    curve.jet(s, &mut d);
    d[1]
}

fn build_one(spec: &PatchworkSpec, place: &str) -> Result<SolvedNetwork> {
    if !(1..=2).contains(&spec.order) {
        return Err(Error::invalid(format!(
            "must be 1 or 2 (got {}); order 3 is not available for a patchwork",
            spec.order
        ))
        .at("order"));
    }
    let n_points = spec.points.len();
    if n_points < 3 {
        return Err(Error::invalid(format!(
            "a patchwork needs at least 3 corners (got {n_points})"
        ))
        .at("points"));
    }
    for (what, len) in [
        ("points", n_points),
        ("edges", spec.edges.len()),
        ("faces", spec.faces.len()),
    ] {
        if len > MAX_PATCHWORK_ITEMS {
            return Err(Error::invalid(format!(
                "{len} items; a patchwork has at most {MAX_PATCHWORK_ITEMS}"
            ))
            .at(what));
        }
    }
    if spec.normals.len() != n_points {
        return Err(Error::invalid(format!(
            "{} normals for {n_points} points (one per point)",
            spec.normals.len()
        ))
        .at("normals"));
    }
    let points = spec
        .points
        .iter()
        .enumerate()
        .map(|(i, p)| finite(p, &format!("points[{i}]")))
        .collect::<Result<Vec<_>>>()?;
    let mut normals = Vec::with_capacity(n_points);
    for (i, n) in spec.normals.iter().enumerate() {
        let at = format!("normals[{i}]");
        let v = finite(n, &at)?;
        if v.norm() == 0.0 {
            return Err(Error::invalid("a normal of length 0").at(&at));
        }
        normals.push(v.normalize());
    }

    // Edges: the curves, and the lookup from a pair of corners.
    let mut by_pair: HashMap<(usize, usize), usize> = HashMap::new();
    let mut curves = Vec::with_capacity(spec.edges.len());
    let mut edges = Vec::with_capacity(spec.edges.len());
    // Each edge's normals at its start and end (its corners', or its own `end_normals`).
    let mut end_normals: Vec<[Vec3; 2]> = Vec::with_capacity(spec.edges.len());
    for (e, edge) in spec.edges.iter().enumerate() {
        let at = format!("edges[{e}]");
        let [a, b] = edge.ends;
        if a >= n_points || b >= n_points {
            return Err(Error::invalid(format!(
                "corner {} does not exist ({n_points} points)",
                a.max(b)
            ))
            .at(&format!("{at}.ends")));
        }
        if a == b {
            return Err(
                Error::invalid("an edge joins a corner to itself").at(&format!("{at}.ends"))
            );
        }
        if let Some(other) = by_pair.insert((a.min(b), a.max(b)), e) {
            return Err(Error::invalid(format!(
                "edges[{other}] already joins corners {a} and {b}"
            ))
            .at(&format!("{at}.ends")));
        }
        let d0 = finite(&edge.tangents[0], &format!("{at}.tangents[0]"))?;
        let d1 = finite(&edge.tangents[1], &format!("{at}.tangents[1]"))?;
        if d0.norm() == 0.0 || d1.norm() == 0.0 {
            return Err(Error::invalid("a tangent of length 0").at(&format!("{at}.tangents")));
        }
        if (points[b] - points[a]).norm() == 0.0 {
            return Err(
                Error::invalid(format!("corners {a} and {b} are the same point"))
                    .at(&format!("{at}.ends")),
            );
        }
        for (j, n) in edge.normals.iter().enumerate() {
            let v = finite(n, &format!("{at}.normals[{j}]"))?;
            if v.norm() == 0.0 {
                return Err(
                    Error::invalid("a normal of length 0").at(&format!("{at}.normals[{j}]"))
                );
            }
        }
        let mut ends = [normals[a], normals[b]];
        if let Some(given) = &edge.end_normals {
            for (k, n) in given.iter().enumerate() {
                let where_ = format!("{at}.end_normals[{k}]");
                let v = finite(n, &where_)?;
                if v.norm() == 0.0 {
                    return Err(Error::invalid("a normal of length 0").at(&where_));
                }
                ends[k] = v.normalize();
            }
        }
        end_normals.push(ends);
        let curve: SharedCurve = Arc::new(Hermite::new(points[a], points[b], d0, d1));
        curves.push(NetworkCurve {
            curve,
            t0: 0.0,
            t1: 1.0,
        });
        edges.push(Edge {
            curve: e,
            t0: 0.0,
            t1: 1.0,
            start: a,
            end: b,
        });
    }

    // Faces: runs of edges, each edge at most once per direction.
    let mut runs_of: Vec<Vec<(usize, bool)>> = vec![Vec::new(); edges.len()];
    let mut faces = Vec::with_capacity(spec.faces.len());
    for (f, corners) in spec.faces.iter().enumerate() {
        let at = format!("faces[{f}]");
        let n = corners.len();
        if !(3..=MAX_SIDES).contains(&n) {
            return Err(Error::invalid(format!(
                "a face of {n} corners; a face has 3 to {MAX_SIDES}"
            ))
            .at(&at));
        }
        let mut sides = Vec::with_capacity(n);
        for k in 0..n {
            let (a, b) = (corners[k], corners[(k + 1) % n]);
            if a >= n_points || b >= n_points {
                return Err(Error::invalid(format!(
                    "corner {} does not exist ({n_points} points)",
                    a.max(b)
                ))
                .at(&at));
            }
            let Some(&e) = by_pair.get(&(a.min(b), a.max(b))) else {
                return Err(Error::invalid(format!(
                    "no edge joins corners {a} and {b} (side {k})"
                ))
                .at(&at));
            };
            let forward = edges[e].start == a;
            if let Some(&(g, _)) = runs_of[e].iter().find(|(_, fw)| *fw == forward) {
                return Err(Error::invalid(format!(
                    "faces[{g}] already runs edges[{e}] from corner {a} to {b}: neighbouring \
                     faces run their shared edge in opposite directions"
                ))
                .at(&at));
            }
            runs_of[e].push((f, forward));
            sides.push(vec![Run { edge: e, forward }]);
        }
        faces.push(Face {
            sides,
            angle_sum: 0.0,
        });
    }
    if faces.is_empty() {
        return Err(Error::invalid("a patchwork needs at least one face").at("faces"));
    }

    // Per edge its normal field: its end normals at the ends, the given samples between, each
    // made normal to the curve.
    let fields: Vec<Arc<Vec<Vec3>>> = spec
        .edges
        .iter()
        .zip(&curves)
        .zip(&end_normals)
        .map(|((edge, c), &[na, nb])| {
            let inner: Vec<Vec3> = if edge.normals.is_empty() {
                Vec::new()
            } else {
                edge.normals.iter().map(vec3).collect()
            };
            let mut values = Vec::with_capacity(inner.len() + 2);
            values.push(na);
            values.extend(inner);
            values.push(nb);
            let m = values.len() - 1;
            for (j, v) in values.iter_mut().enumerate() {
                let t = tangent(&c.curve, lobatto(j, m));
                let t = t / t.norm().max(1e-300);
                let n = *v - t * v.dot(&t);
                *v = if n.norm() > 1e-12 {
                    n.normalize()
                } else {
                    v.normalize()
                };
            }
            Arc::new(values)
        })
        .collect();

    // Nodes: the corners, their normals and how far the edges' tangents leave their planes
    // (each edge's own plane at its ends).
    let mut residual = vec![0.0f64; n_points];
    let mut valence = vec![0usize; n_points];
    for (e, edge) in edges.iter().enumerate() {
        for (end, (k, s)) in [(edge.start, 0.0), (edge.end, 1.0)].into_iter().enumerate() {
            let t = tangent(&curves[e].curve, s);
            let angle = (t.dot(&end_normals[e][end]).abs() / t.norm())
                .min(1.0)
                .asin();
            residual[k] = residual[k].max(angle);
            valence[k] += 1;
        }
    }
    let nodes: Vec<Node> = (0..n_points)
        .map(|k| Node {
            point: points[k],
            normal: normals[k],
            residual: residual[k],
            valence: valence[k],
        })
        .collect();
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for p in &points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let size = (hi - lo).norm();
    let network = Network {
        curves,
        nodes,
        edges,
        faces,
        open: Vec::new(),
        size,
        tolerance: 1e-9 * size,
    };

    let mut joints: Vec<Joint> = (0..network.edges.len())
        .map(|e| {
            let edge = &network.edges[e];
            if runs_of[e].len() == 2 {
                let corner = network.nodes[edge.start].residual > CREASE_ANGLE
                    || network.nodes[edge.end].residual > CREASE_ANGLE;
                if spec.edges[e].crease || corner || spec.order == 1 {
                    Joint::Crease
                } else {
                    Joint::Shared
                }
            } else {
                Joint::Outline
            }
        })
        .collect();
    // A face's corner takes the one tangent plane of the edges there that share their planes:
    // where two such edges give it different normals, both are creases, and where the other
    // edge (a crease or an outline) leaves that plane, so is the sharing one. Until no corner
    // changes (an edge made a crease is judged again at its other end). The angle allowed is
    // the node's (`CREASE_ANGLE`) where both edges take their corner's normal, and rounding's
    // (`OWN_PLANE_ANGLE`) where one has its own: a plane given for that edge alone is met
    // exactly or not at all.
    let own = |e: usize| spec.edges[e].end_normals.is_some();
    let end_of = |e: usize, v: usize| usize::from(network.edges[e].start != v);
    let leaving = |e: usize, v: usize| tangent(&network.curves[e].curve, end_of(e, v) as f64);
    loop {
        let mut changed = false;
        for corners in &spec.faces {
            let n = corners.len();
            for k in 0..n {
                let v = corners[k];
                let (prev, next) = (corners[(k + n - 1) % n], corners[(k + 1) % n]);
                let (Some(&a), Some(&b)) = (
                    by_pair.get(&(prev.min(v), prev.max(v))),
                    by_pair.get(&(v.min(next), v.max(next))),
                ) else {
                    continue;
                };
                let shared = |e: usize| joints[e] == Joint::Shared;
                let allowed = if own(a) || own(b) {
                    OWN_PLANE_ANGLE
                } else {
                    CREASE_ANGLE
                };
                let off_plane = |e: usize, n: Vec3| {
                    let t = leaving(e, v);
                    (t.dot(&n).abs() / t.norm()).min(1.0).asin() > allowed
                };
                let (na, nb) = (end_normals[a][end_of(a, v)], end_normals[b][end_of(b, v)]);
                let creased: &[usize] = match (shared(a), shared(b)) {
                    // (The angle by its sine and cosine: an arccosine of a cosine rounded
                    // to 1 − ε would read 1.5·10⁻⁸ rad between equal normals.)
                    (true, true) if na.cross(&nb).norm().atan2(na.dot(&nb)) > allowed => &[a, b],
                    (true, false) if off_plane(b, na) => &[a],
                    (false, true) if off_plane(a, nb) => &[b],
                    _ => &[],
                };
                for &e in creased {
                    joints[e] = Joint::Crease;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }

    let options = NSidedOptions {
        order: spec.order,
        a: spec.a,
        degree: spec.degree,
        gap_tolerance: 1e-9,
    };
    let patches = network
        .faces
        .par_iter()
        .enumerate()
        .map(|(f, face)| {
            let sides = face
                .runs()
                .map(|r| {
                    let (t0, t1) = if r.forward { (0.0, 1.0) } else { (1.0, 0.0) };
                    let ribbon = match joints[r.edge] {
                        Joint::Shared => {
                            let field = fields[r.edge].clone();
                            Ribbon::TangentPlane(Arc::new(move |s: f64| {
                                interpolate(&field, t0 + s * (t1 - t0))
                            }))
                        }
                        _ => Ribbon::Position,
                    };
                    Side {
                        curve: network.curves[r.edge].curve.clone(),
                        t0,
                        t1,
                        ribbon,
                    }
                })
                .collect();
            NSidedPatch::solve(sides, &options)
                .map(Arc::new)
                .map_err(|e| e.at(&format!("faces[{f}]")))
        })
        .collect::<Result<Vec<_>>>()?;
    let curve_names = (0..network.edges.len())
        .map(|e| format!("{place}.edges[{e}]"))
        .collect();
    Ok(SolvedNetwork {
        name: spec.name.clone(),
        network,
        curve_names,
        faces: patches,
        joints,
    })
}
