//! Splitting a hole one disk patch cannot span: a bridging chord between two of its boundary
//! vertices, the shortest against the loop it cuts off, cuts the loop into two pieces, each of
//! which is filled (or split again) on its own; the chord's points and their normals are
//! shared by both pieces, so the two patches meet G1 along it.
//!
//! # The chord
//!
//! A hole is split before any patch is tried when its best chord is shorter than
//! [`SPLIT_BELOW`] of the arc it cuts off (a rectangle longer than about 7:3, an L or a U with
//! narrow arms: one disk patch would crowd its map into the ends), and after every ribbon has
//! failed otherwise.
//!
//! Among the pairs of loop vertices `a`, `b` that leave at least [`MIN_ARC`] edges on either
//! side, the chord minimises `|P_b − P_a| / min(arc_ab, arc_ba)` (a neck: short across, long
//! around), subject to lying inside the hole: in the plane square to the loop's mean normal,
//! its segment crosses no edge of the loop, its midpoint is inside the loop, it leaves each
//! end at least [`MIN_CHORD_ANGLE`] away from the loop's edges there and passes no other loop
//! vertex closer than half the loop's mean edge.
//!
//! The chord is the cubic Hermite curve from `P_a` to `P_b` whose end tangents are the chord
//! `P_b − P_a` turned into the mesh's tangent planes at its ends (their lengths kept): a curve
//! of the surface to third order where the surface is smooth (on the unit sphere a chord of
//! length `L` leaves the great circle by `O(L⁴)`). Its points are about the loop's mean edge
//! apart. Its normal field runs from `N_a` to `N_b` (linear, normalised) made square to the
//! curve's tangent; each piece takes its ribbon in the plane square to it, so at every sample
//! of the chord both patches have the same tangent plane (the G1 of the split, measured as the
//! angle between the two patches' normals at the chord's points). For G2 both pieces take the
//! normal curvature of the second fundamental form interpolated linearly (as a tensor) between
//! the chord's ends.

use super::curvature::Form;
use crate::Vec3;
use nalgebra::Matrix3;

/// A chord shorter than this fraction of the arc it cuts off splits the hole before one patch
/// is tried: an `L × W` rectangle's middle chord is `W/(L + W)` of either arc (0.3 at 7:3,
/// 1/3 at 2:1), a circle's diameter `2/π` of a half; a loop that zigzags along the mesh's edges
/// has longer arcs than its outline, so it splits a little earlier.
pub(crate) const SPLIT_BELOW: f64 = 0.3;

/// The fewest loop edges a chord leaves on either side.
pub(crate) const MIN_ARC: usize = 3;

/// The smallest angle (degrees) between a chord and the loop's edges at its ends.
pub(crate) const MIN_CHORD_ANGLE: f64 = 25.0;

/// A chord across a loop: its ends (positions in the loop) and its interior points with their
/// normals (from `a` to `b`).
pub(crate) struct Chord {
    pub a: usize,
    pub b: usize,
    pub points: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// The chord's parameter `t ∈ (0, 1)` at each interior point (for interpolating forms).
    pub params: Vec<f64>,
    /// Its length over the shorter arc of the loop it cuts off.
    pub score: f64,
}

/// The best chord across the loop of `p` with vertex normals `n` (module documentation), or
/// `None` when no chord lies inside it.
pub(crate) fn best_chord(p: &[Vec3], n: &[Vec3]) -> Option<Chord> {
    let s = p.len();
    if s < 2 * MIN_ARC {
        return None;
    }
    let mean_normal: Vec3 = n.iter().sum();
    let nn = mean_normal.norm();
    if nn.is_nan() || nn <= 0.0 {
        return None;
    }
    let axis = mean_normal / nn;
    let helper = if axis.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let e1 = axis.cross(&helper).normalize();
    let e2 = axis.cross(&e1);
    let q: Vec<[f64; 2]> = p.iter().map(|v| [v.dot(&e1), v.dot(&e2)]).collect();
    // Arc length from vertex 0.
    let mut arc = vec![0.0; s + 1];
    for k in 0..s {
        arc[k + 1] = arc[k] + (p[(k + 1) % s] - p[k]).norm();
    }
    let total = arc[s];
    let mean_edge = total / s as f64;
    let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
    for a in 0..s {
        for b in a + MIN_ARC..s {
            if s - (b - a) < MIN_ARC {
                break;
            }
            let along = arc[b] - arc[a];
            let around = along.min(total - along);
            let across = (p[b] - p[a]).norm();
            let score = across / around;
            // A chord no shorter than the arc it cuts off does not narrow anything.
            if score < 0.9 {
                candidates.push((score, a, b));
            }
        }
    }
    candidates.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let clear = mean_edge * 0.5 / scale(&q, p);
    let (score, a, b) = candidates
        .into_iter()
        .find(|&(_, a, b)| inside(&q, a, b, clear))?;
    let mut chord = hermite(p, n, a, b, mean_edge);
    chord.score = score;
    Some(chord)
}

/// The ratio of lengths in the plane to lengths in space (about 1; the plane shortens slanted
/// edges): the mean of the loop's edges in the plane over their mean in space.
fn scale(q: &[[f64; 2]], p: &[Vec3]) -> f64 {
    let s = p.len();
    let (mut a, mut b) = (0.0, 0.0);
    for k in 0..s {
        let j = (k + 1) % s;
        a += (q[j][0] - q[k][0]).hypot(q[j][1] - q[k][1]);
        b += (p[j] - p[k]).norm();
    }
    if b > 0.0 {
        b / a.max(f64::MIN_POSITIVE)
    } else {
        1.0
    }
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn dot2(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn len2(a: [f64; 2]) -> f64 {
    a[0].hypot(a[1])
}

/// Whether the segment `q_a q_b` lies inside the polygon `q` (module documentation), with
/// clearance `clear` (in the plane) from the other vertices.
fn inside(q: &[[f64; 2]], a: usize, b: usize, clear: f64) -> bool {
    let s = q.len();
    let (qa, qb) = (q[a], q[b]);
    let d = sub(qb, qa);
    let l = len2(d);
    if l.is_nan() || l <= 0.0 {
        return false;
    }
    let cos_limit = MIN_CHORD_ANGLE.to_radians().cos();
    // The chord leaves each end away from the loop's edges there.
    for (v, dir) in [(a, d), (b, [-d[0], -d[1]])] {
        for w in [(v + 1) % s, (v + s - 1) % s] {
            let e = sub(q[w], q[v]);
            let le = len2(e);
            if le > 0.0 && dot2(e, dir) > cos_limit * le * l {
                return false;
            }
        }
    }
    // It enters the polygon at `a`: between the incoming and outgoing edges, on the inside
    // (the loop runs counterclockwise about the mean normal).
    let enters = |v: usize, dir: [f64; 2]| {
        let prev = sub(q[(v + s - 1) % s], q[v]);
        let next = sub(q[(v + 1) % s], q[v]);
        // The inside lies counterclockwise from `next` to `prev`.
        let c = cross2(next, prev);
        let (x, y) = (cross2(next, dir), cross2(dir, prev));
        if c >= 0.0 {
            x > 0.0 && y > 0.0
        } else {
            x > 0.0 || y > 0.0
        }
    };
    if !enters(a, d) || !enters(b, [-d[0], -d[1]]) {
        return false;
    }
    for k in 0..s {
        let j = (k + 1) % s;
        if k == a || j == a || k == b || j == b {
            continue;
        }
        let (p0, p1) = (q[k], q[j]);
        let (c0, c1) = (cross2(d, sub(p0, qa)), cross2(d, sub(p1, qa)));
        let e = sub(p1, p0);
        let (c2, c3) = (cross2(e, sub(qa, p0)), cross2(e, sub(qb, p0)));
        if c0 * c1 <= 0.0 && c2 * c3 <= 0.0 {
            return false;
        }
        // Clearance from vertex k (the ends' neighbours are held off by the angle above).
        if k == (a + 1) % s || k == (b + 1) % s {
            continue;
        }
        let t = (dot2(sub(p0, qa), d) / (l * l)).clamp(0.0, 1.0);
        let foot = [qa[0] + t * d[0], qa[1] + t * d[1]];
        if len2(sub(p0, foot)) < clear {
            return false;
        }
    }
    true
}

/// The Hermite chord from vertex `a` to vertex `b` (module documentation).
fn hermite(p: &[Vec3], n: &[Vec3], a: usize, b: usize, spacing: f64) -> Chord {
    let (pa, pb) = (p[a], p[b]);
    let c = pb - pa;
    let len = c.norm();
    let turn = |nv: Vec3| {
        let t = c - nv * nv.dot(&c);
        let m = t.norm();
        if m > 0.0 {
            t * (len / m)
        } else {
            c
        }
    };
    let (ta, tb) = (turn(n[a]), turn(n[b]));
    let count = ((len / spacing).round() as usize).saturating_sub(1);
    let (mut points, mut normals, mut params) = (Vec::new(), Vec::new(), Vec::new());
    for i in 1..=count {
        let t = i as f64 / (count + 1) as f64;
        let (t2, t3) = (t * t, t * t * t);
        let x = pa * (2.0 * t3 - 3.0 * t2 + 1.0)
            + ta * (t3 - 2.0 * t2 + t)
            + pb * (-2.0 * t3 + 3.0 * t2)
            + tb * (t3 - t2);
        let dx = pa * (6.0 * t2 - 6.0 * t)
            + ta * (3.0 * t2 - 4.0 * t + 1.0)
            + pb * (-6.0 * t2 + 6.0 * t)
            + tb * (3.0 * t2 - 2.0 * t);
        let mut nv = n[a] * (1.0 - t) + n[b] * t;
        let dd = dx.norm_squared();
        if dd > 0.0 {
            nv -= dx * (nv.dot(&dx) / dd);
        }
        let m = nv.norm();
        points.push(x);
        normals.push(if m > 0.0 { nv / m } else { n[a] });
        params.push(t);
    }
    Chord {
        a,
        b,
        points,
        normals,
        params,
        score: 0.0,
    }
}

/// The form at parameter `t` of a chord between forms `fa` and `fb`, with respect to `normal`:
/// the tensors interpolated linearly.
pub(crate) fn interpolate_form(fa: &Form, fb: &Form, t: f64, normal: Vec3) -> Form {
    let m: Matrix3<f64> = fa.tensor() * (1.0 - t) + fb.tensor() * t;
    Form::from_tensor(normal, &m)
}
