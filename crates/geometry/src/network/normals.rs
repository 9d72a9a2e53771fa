//! Tangent planes at the nodes of a network and normal fields along its pieces.

use super::{Network, NetworkCurve, Node};
use crate::{Error, Result, Vec3};
use nalgebra::Matrix3;
use std::collections::VecDeque;

/// Rotation-minimising steps along a piece when the nodes' normals are oriented.
const ORIENT_STEPS: usize = 128;

/// Rotation-minimising steps between two samples of a normal field.
const FIELD_SUBSTEPS: usize = 8;

/// The unit tangent of a network curve at `t`, along increasing `t` (a chord where the
/// derivative vanishes).
pub(super) fn curve_tangent(c: &NetworkCurve, t: f64) -> Vec3 {
    let mut jet = [Vec3::zeros(); 2];
    c.curve.jet(t, &mut jet);
    let n = jet[1].norm();
    if n > 0.0 && n.is_finite() {
        return jet[1] / n;
    }
    let h = 1e-6 * (c.t1 - c.t0);
    let (a, b) = if t + h <= c.t1 {
        (t, t + h)
    } else {
        (t - h, t)
    };
    let d = c.curve.point(b) - c.curve.point(a);
    d / d.norm().max(1e-300)
}

/// The unit direction in which half-edge `h` (`2e`: edge `e` from its start, `2e + 1`: from its
/// end) leaves its node.
pub(super) fn leaving(net: &Network, h: usize) -> Vec3 {
    let e = &net.edges[h / 2];
    let c = &net.curves[e.curve];
    if h.is_multiple_of(2) {
        curve_tangent(c, e.t0)
    } else {
        -curve_tangent(c, e.t1)
    }
}

/// The half-edges leaving each node.
pub(super) fn leaving_by_node(net: &Network, nodes: usize) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new(); nodes];
    for (i, e) in net.edges.iter().enumerate() {
        out[e.start].push(2 * i);
        out[e.end].push(2 * i + 1);
    }
    out
}

/// The nodes with their tangent planes, normals oriented consistently over each connected
/// part of the network.
pub(super) fn nodes(net: &Network, points: &[Vec3]) -> Result<Vec<Node>> {
    let out = leaving_by_node(net, points.len());
    let mut normals: Vec<Option<Vec3>> = Vec::with_capacity(points.len());
    let mut residuals = Vec::with_capacity(points.len());
    for hs in &out {
        let tangents: Vec<Vec3> = hs.iter().map(|&h| leaving(net, h)).collect();
        let (n, r) = plane(&tangents);
        normals.push(n);
        residuals.push(r);
    }
    // Orient by carrying normals across the pieces, breadth first from a node with a plane.
    let mut done = vec![false; points.len()];
    while let Some(seed) = (0..points.len()).find(|&k| !done[k] && normals[k].is_some()) {
        done[seed] = true;
        let mut queue = VecDeque::from([seed]);
        while let Some(k) = queue.pop_front() {
            let nk = normals[k].expect("oriented nodes have normals");
            for &h in &out[k] {
                let e = &net.edges[h / 2];
                let (from, to, other) = if h.is_multiple_of(2) {
                    (e.t0, e.t1, e.end)
                } else {
                    (e.t1, e.t0, e.start)
                };
                if done[other] {
                    continue;
                }
                let c = &net.curves[e.curve];
                let carried = transport(c, from, to, nk, ORIENT_STEPS);
                normals[other] = Some(match normals[other] {
                    Some(m) if m.dot(&carried) < 0.0 => -m,
                    Some(m) => m,
                    None => {
                        // No plane of its own (its pieces are collinear): the carried normal,
                        // kept normal to them.
                        let mut m = carried;
                        for &g in &out[other] {
                            let t = leaving(net, g);
                            m -= t * t.dot(&m);
                        }
                        let len = m.norm();
                        if len > 1e-12 {
                            m / len
                        } else {
                            carried
                        }
                    }
                });
                done[other] = true;
                queue.push_back(other);
            }
        }
    }
    if let Some(k) = (0..points.len()).find(|&k| !done[k]) {
        let p = points[k];
        return Err(Error::invalid(format!(
            "the curves meeting near ({:.4e}, {:.4e}, {:.4e}) and every node joined to it \
             run along one line, so they span no surface",
            p.x, p.y, p.z
        )));
    }
    Ok((0..points.len())
        .map(|k| {
            let normal = normals[k].expect("every node is oriented");
            let residual = out[k]
                .iter()
                .map(|&h| leaving(net, h).dot(&normal).abs().min(1.0).asin())
                .fold(0.0, f64::max);
            Node {
                point: points[k],
                normal,
                residual: residual.max(residuals[k]),
                valence: out[k].len(),
            }
        })
        .collect())
}

/// The normal of the plane that fits unit `tangents` best and the largest angle of a tangent
/// out of it; `None` when the tangents lie along one line.
fn plane(tangents: &[Vec3]) -> (Option<Vec3>, f64) {
    let mut m = Matrix3::zeros();
    for t in tangents {
        m += t * t.transpose();
    }
    let eig = m.symmetric_eigen();
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let (small, mid, large) = (
        eig.eigenvalues[order[0]],
        eig.eigenvalues[order[1]],
        eig.eigenvalues[order[2]],
    );
    let _ = small;
    if large.is_nan() || large <= 0.0 || mid <= 1e-10 * large {
        return (None, 0.0);
    }
    let n: Vec3 = eig.eigenvectors.column(order[0]).into();
    let n = n.normalize();
    let residual = tangents
        .iter()
        .map(|t| t.dot(&n).abs().min(1.0).asin())
        .fold(0.0, f64::max);
    (Some(n), residual)
}

/// `r` carried from parameter `from` to `to` of the curve by its rotation-minimising frame
/// (double reflection, `steps` steps), first made normal to the curve.
pub(super) fn transport(c: &NetworkCurve, from: f64, to: f64, r: Vec3, steps: usize) -> Vec3 {
    let mut state = Frame::start(c, from, r);
    for k in 1..=steps {
        let t = from + (to - from) * k as f64 / steps as f64;
        state.step(c, t);
    }
    state.r
}

/// A point of a rotation-minimising frame: position, unit tangent and unit normal `r ⟂ t`.
struct Frame {
    x: Vec3,
    t: Vec3,
    r: Vec3,
}

impl Frame {
    fn start(c: &NetworkCurve, at: f64, r: Vec3) -> Frame {
        let t = curve_tangent(c, at);
        Frame {
            x: c.curve.point(at),
            t,
            r: normal_to(t, r),
        }
    }

    /// One double-reflection step to the curve's point at `at`.
    fn step(&mut self, c: &NetworkCurve, at: f64) {
        let x = c.curve.point(at);
        let t = curve_tangent(c, at);
        let v1 = x - self.x;
        let c1 = v1.dot(&v1);
        let (rl, tl) = if c1 > 0.0 {
            (
                self.r - v1 * (2.0 / c1 * v1.dot(&self.r)),
                self.t - v1 * (2.0 / c1 * v1.dot(&self.t)),
            )
        } else {
            (self.r, self.t)
        };
        let v2 = t - tl;
        let c2 = v2.dot(&v2);
        let r = if c2 > 0.0 {
            rl - v2 * (2.0 / c2 * v2.dot(&rl))
        } else {
            rl
        };
        *self = Frame {
            x,
            t,
            r: normal_to(t, r),
        };
    }
}

/// `r` made unit and normal to the unit vector `t` (any normal if `r` is along `t`).
pub fn normal_to(t: Vec3, r: Vec3) -> Vec3 {
    let m = r - t * t.dot(&r);
    let len = m.norm();
    if len > 1e-12 * r.norm().max(1e-300) {
        return m / len;
    }
    let a = if t.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    t.cross(&a).normalize()
}

/// The `j`-th of `m + 1` Chebyshev–Lobatto points on `[0, 1]`, increasing.
pub fn lobatto(j: usize, m: usize) -> f64 {
    0.5 * (1.0 - (std::f64::consts::PI * j as f64 / m as f64).cos())
}

/// See [`Network::normal_samples`].
pub(super) fn edge_field(net: &Network, edge: usize, m: usize) -> Vec<Vec3> {
    let m = m.max(1);
    let e = &net.edges[edge];
    let c = &net.curves[e.curve];
    let at = |s: f64| e.t0 + s * (e.t1 - e.t0);
    let mut frame = Frame::start(c, e.t0, net.nodes[e.start].normal);
    let mut carried = Vec::with_capacity(m + 1);
    carried.push((frame.t, frame.r));
    for j in 1..=m {
        let (a, b) = (lobatto(j - 1, m), lobatto(j, m));
        for k in 1..=FIELD_SUBSTEPS {
            let s = if k == FIELD_SUBSTEPS {
                b
            } else {
                a + (b - a) * k as f64 / FIELD_SUBSTEPS as f64
            };
            frame.step(c, at(s));
        }
        carried.push((frame.t, frame.r));
    }
    // The turn about the end tangent that takes the carried normal to the end node's.
    let (t_end, r_end) = carried[m];
    let target = normal_to(t_end, net.nodes[e.end].normal);
    let turn = r_end.cross(&target).dot(&t_end).atan2(r_end.dot(&target));
    carried
        .iter()
        .enumerate()
        .map(|(j, (t, r))| {
            let angle = turn * lobatto(j, m);
            let (sin, cos) = angle.sin_cos();
            (r * cos + t.cross(r) * sin).normalize()
        })
        .collect()
}
