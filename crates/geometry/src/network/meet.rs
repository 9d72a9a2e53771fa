//! Where the curves of a network meet, and the pieces between those points.

use super::{Edge, NetworkCurve};
use crate::curve::Domain;
use crate::{Error, Result, Vec3};

/// Segments of each curve's polyline.
pub(super) const SEGMENTS: usize = 512;

/// Segments per box of the broad phase among a network's curves.
pub(super) const CHUNK: usize = 16;

/// Segments per box of the broad phase among a loop's pieces ([`loop_crossing`]): neighbouring
/// pieces' boxes always meet at their joint, so small boxes leave few pairs of segments there.
const LOOP_CHUNK: usize = 4;

/// Gauss–Newton steps of a meeting point's refinement.
const NEWTON_STEPS: usize = 60;

/// A curve's polyline: points at equal parameter steps.
pub(super) struct Polyline {
    pub(super) points: Vec<Vec3>,
}

/// A point where curves `a` (at `s`) and `b` (at `t`) meet.
#[derive(Clone, Debug)]
pub(crate) struct Hit {
    pub(crate) a: usize,
    pub(crate) s: f64,
    pub(crate) b: usize,
    pub(crate) t: f64,
}

/// Samples every curve, refusing intervals outside a curve's domain and curves that are not
/// finite.
pub(super) fn sample_all(curves: &[NetworkCurve], segments: usize) -> Result<Vec<Polyline>> {
    let mut out = Vec::with_capacity(curves.len());
    for (i, c) in curves.iter().enumerate() {
        let place = || format!("curves[{i}]");
        if !(c.t0.is_finite() && c.t1.is_finite() && c.t0 < c.t1) {
            return Err(Error::invalid(format!(
                "the parameter interval [{}, {}] must be finite and increasing",
                c.t0, c.t1
            ))
            .at(&place()));
        }
        if let Domain::Interval(a, b) = c.curve.domain() {
            let slack = 1e-12 * (b - a).abs().max(1.0);
            if c.t0 < a - slack || c.t1 > b + slack {
                return Err(Error::invalid(format!(
                    "the interval [{}, {}] leaves the curve's domain [{a}, {b}]",
                    c.t0, c.t1
                ))
                .at(&place()));
            }
        }
        let mut points = Vec::with_capacity(segments + 1);
        for j in 0..=segments {
            let t = param(c, j as f64 / segments as f64);
            let p = c.curve.point(t);
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                return Err(
                    Error::invalid(format!("the curve is not finite at t = {t}")).at(&place()),
                );
            }
            points.push(p);
        }
        out.push(Polyline { points });
    }
    Ok(out)
}

/// The curve's parameter at the fraction `f` of its interval.
fn param(c: &NetworkCurve, f: f64) -> f64 {
    if f >= 1.0 {
        c.t1
    } else {
        c.t0 + f * (c.t1 - c.t0)
    }
}

/// The diagonal of the bounding box of every polyline.
pub(super) fn size(polylines: &[Polyline]) -> f64 {
    let (lo, hi) = bounds(polylines.iter().flat_map(|p| p.points.iter()));
    (hi - lo).norm()
}

fn bounds<'a>(points: impl Iterator<Item = &'a Vec3>) -> (Vec3, Vec3) {
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    (lo, hi)
}

/// Every point where two different curves meet within `tol`, except between segment pairs
/// `(a, i, b, j)` that `skip` leaves out. Two segments are refined when they come within `tol`
/// plus `reach` times their lengths of each other (1: any meeting between the samples; less
/// finds crossings, where the polylines cross too, for less work).
pub(super) fn intersections(
    curves: &[NetworkCurve],
    polylines: &[Polyline],
    tol: f64,
    reach: f64,
    chunk: usize,
    skip: &dyn Fn(usize, usize, usize, usize) -> bool,
) -> Vec<Hit> {
    // Boxes of `chunk` segments, and each polyline's box: two segments within `tol` of each
    // other lie in boxes within `tol` of each other.
    let boxes: Vec<Vec<(Vec3, Vec3)>> = polylines
        .iter()
        .map(|p| {
            p.points
                .windows(2)
                .collect::<Vec<_>>()
                .chunks(chunk)
                .map(|c| {
                    let (lo, hi) = bounds(c.iter().flat_map(|w| w.iter()));
                    (lo, hi)
                })
                .collect()
        })
        .collect();
    let whole: Vec<(Vec3, Vec3)> = polylines.iter().map(|p| bounds(p.points.iter())).collect();
    let mut hits: Vec<Hit> = Vec::new();
    for a in 0..curves.len() {
        for b in a + 1..curves.len() {
            if !overlap(&whole[a], &whole[b], tol) {
                continue;
            }
            for (ca, ba) in boxes[a].iter().enumerate() {
                for (cb, bb) in boxes[b].iter().enumerate() {
                    if !overlap(ba, bb, tol) {
                        continue;
                    }
                    let pa = &polylines[a].points;
                    let pb = &polylines[b].points;
                    let (na, nb) = (pa.len() - 1, pb.len() - 1);
                    for i in ca * chunk..((ca + 1) * chunk).min(na) {
                        for j in cb * chunk..((cb + 1) * chunk).min(nb) {
                            if skip(a, i, b, j) {
                                continue;
                            }
                            let (la, lb) = ((pa[i + 1] - pa[i]).norm(), (pb[j + 1] - pb[j]).norm());
                            let near = la + lb;
                            // The midpoints' distance less the half lengths bounds the
                            // segments' distance from below.
                            let mid = ((pa[i] + pa[i + 1]) - (pb[j] + pb[j + 1])).norm() * 0.5;
                            if mid - 0.5 * near > reach * near + tol {
                                continue;
                            }
                            let (u, w, d) = segment_closest(pa[i], pa[i + 1], pb[j], pb[j + 1]);
                            if d > reach * near + tol {
                                continue;
                            }
                            let s0 = param(&curves[a], (i as f64 + u) / na as f64);
                            let t0 = param(&curves[b], (j as f64 + w) / nb as f64);
                            if let Some((s, t)) = refine(&curves[a], &curves[b], s0, t0, tol) {
                                push_hit(&mut hits, curves, Hit { a, s, b, t }, tol);
                            }
                        }
                    }
                }
            }
        }
    }
    hits
}

/// Keeps a hit unless the same pair of curves already meets at that point.
fn push_hit(hits: &mut Vec<Hit>, curves: &[NetworkCurve], hit: Hit, tol: f64) {
    let p = curves[hit.a].curve.point(hit.s);
    let same = hits
        .iter()
        .any(|h| h.a == hit.a && h.b == hit.b && (curves[h.a].curve.point(h.s) - p).norm() <= tol);
    if !same {
        hits.push(hit);
    }
}

fn overlap(a: &(Vec3, Vec3), b: &(Vec3, Vec3), grow: f64) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] + grow && b.0[k] <= a.1[k] + grow)
}

/// The closest points of segments `[p0, p1]` and `[q0, q1]`: their fractions and distance.
fn segment_closest(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> (f64, f64, f64) {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.dot(&d1), d2.dot(&d2), d2.dot(&r));
    let tiny = 1e-300;
    let (s, t);
    if a <= tiny && e <= tiny {
        return (0.0, 0.0, r.norm());
    }
    if a <= tiny {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let s0 = if denom > tiny {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t0;
                s = s0;
            }
        }
    }
    let d = (p0 + d1 * s - (q0 + d2 * t)).norm();
    (s, t, d)
}

/// Gauss–Newton on `|A(s) − B(t)|²` from `(s, t)`, the parameters kept in their intervals:
/// the meeting parameters if the curves come within `tol` of each other there.
fn refine(
    a: &NetworkCurve,
    b: &NetworkCurve,
    mut s: f64,
    mut t: f64,
    tol: f64,
) -> Option<(f64, f64)> {
    let mut ja = [Vec3::zeros(); 2];
    let mut jb = [Vec3::zeros(); 2];
    let mut best = (f64::INFINITY, s, t);
    for _ in 0..NEWTON_STEPS {
        a.curve.jet(s, &mut ja);
        b.curve.jet(t, &mut jb);
        let r = ja[0] - jb[0];
        let d = r.norm();
        if d < best.0 {
            best = (d, s, t);
        }
        if d == 0.0 {
            break;
        }
        let (da, db) = (ja[1], jb[1]);
        let (m11, m12, m22) = (da.dot(&da), -da.dot(&db), db.dot(&db));
        let (g1, g2) = (da.dot(&r), -db.dot(&r));
        let det = m11 * m22 - m12 * m12;
        let (ds, dt) = if det > 1e-14 * m11 * m22 {
            ((-g1 * m22 + g2 * m12) / det, (g1 * m12 - g2 * m11) / det)
        } else if m11 >= m22 && m11 > 0.0 {
            (-g1 / m11, 0.0)
        } else if m22 > 0.0 {
            (0.0, -g2 / m22)
        } else {
            break;
        };
        let ns = (s + ds).clamp(a.t0, a.t1);
        let nt = (t + dt).clamp(b.t0, b.t1);
        let moved =
            (ns - s).abs() <= 1e-15 * (a.t1 - a.t0) && (nt - t).abs() <= 1e-15 * (b.t1 - b.t0);
        s = ns;
        t = nt;
        if moved {
            break;
        }
    }
    a.curve.jet(s, &mut ja);
    b.curve.jet(t, &mut jb);
    let d = (ja[0] - jb[0]).norm();
    if d < best.0 {
        best = (d, s, t);
    }
    (best.0 <= tol).then_some((best.1, best.2))
}

/// The network's node points and its pieces: the curves cut at every meeting point and at
/// their ends, meeting points within `tol` made one node, and pieces with a free end dropped
/// (repeatedly).
pub(super) fn pieces(
    curves: &[NetworkCurve],
    hits: &[Hit],
    tol: f64,
) -> Result<(Vec<Vec3>, Vec<Edge>)> {
    // Incidences: (curve, parameter, point).
    let mut marks: Vec<(usize, f64, Vec3)> = Vec::new();
    for (i, c) in curves.iter().enumerate() {
        marks.push((i, c.t0, c.curve.point(c.t0)));
        marks.push((i, c.t1, c.curve.point(c.t1)));
    }
    for h in hits {
        let p = curves[h.a].curve.point(h.s);
        marks.push((h.a, h.s, p));
        marks.push((h.b, h.t, curves[h.b].curve.point(h.t)));
    }
    // One node per cluster of points within `tol` (union–find).
    let mut parent: Vec<usize> = (0..marks.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    // Pairs within `tol`, found along the marks sorted by x.
    let mut by_x: Vec<usize> = (0..marks.len()).collect();
    by_x.sort_by(|&a, &b| marks[a].2.x.total_cmp(&marks[b].2.x));
    for (k, &i) in by_x.iter().enumerate() {
        for &j in &by_x[k + 1..] {
            if marks[j].2.x - marks[i].2.x > tol {
                break;
            }
            if (marks[i].2 - marks[j].2).norm() <= tol {
                let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                if ri != rj {
                    parent[rj.max(ri)] = rj.min(ri);
                }
            }
        }
    }
    let mut node_of_root = vec![usize::MAX; marks.len()];
    let mut points = Vec::new();
    let mut node_of = vec![0; marks.len()];
    for (i, node) in node_of.iter_mut().enumerate() {
        let r = root(&mut parent, i);
        if node_of_root[r] == usize::MAX {
            node_of_root[r] = points.len();
            points.push(marks[r].2);
        }
        *node = node_of_root[r];
    }
    // Cut every curve at its marks.
    let mut edges = Vec::new();
    for (i, c) in curves.iter().enumerate() {
        let mut on: Vec<(f64, usize)> = marks
            .iter()
            .zip(&node_of)
            .filter(|(m, _)| m.0 == i)
            .map(|(m, &n)| (m.1, n))
            .collect();
        on.sort_by(|x, y| x.0.total_cmp(&y.0));
        let close = 1e-12 * (c.t1 - c.t0);
        on.dedup_by(|later, earlier| later.1 == earlier.1 && later.0 - earlier.0 <= close);
        for w in on.windows(2) {
            if w[1].0 - w[0].0 <= close {
                continue;
            }
            if w[0].1 == w[1].1
                && (c.curve.point(0.5 * (w[0].0 + w[1].0)) - points[w[0].1]).norm() <= tol
            {
                continue;
            }
            edges.push(Edge {
                curve: i,
                t0: w[0].0,
                t1: w[1].0,
                start: w[0].1,
                end: w[1].1,
            });
        }
    }
    // Drop pieces with a free end, repeatedly.
    loop {
        let mut degree = vec![0usize; points.len()];
        for e in &edges {
            degree[e.start] += 1;
            degree[e.end] += 1;
        }
        let before = edges.len();
        edges.retain(|e| degree[e.start] > 1 && degree[e.end] > 1);
        if edges.len() == before {
            break;
        }
    }
    if edges.is_empty() {
        return Err(Error::invalid(
            "the curves of the network do not enclose anything: no piece of a curve meets \
             others at both ends",
        ));
    }
    // Keep only the nodes the pieces use.
    let mut renumber = vec![usize::MAX; points.len()];
    let mut kept = Vec::new();
    for e in edges.iter_mut() {
        for n in [&mut e.start, &mut e.end] {
            if renumber[*n] == usize::MAX {
                renumber[*n] = kept.len();
                kept.push(points[*n]);
            }
            *n = renumber[*n];
        }
    }
    Ok((kept, edges))
}

/// Sub-curves per side of a loop in [`loop_crossing`].
const LOOP_PIECES: usize = 8;

/// Polyline segments per sub-curve in [`loop_crossing`].
const LOOP_SEGMENTS: usize = 32;

/// The first place where a loop of curves `(curve, t0, t1)` meets itself other than where
/// consecutive sides join: sides that cross or touch, or a side that crosses itself (found
/// between eighths of the sides). Returns the two sides, their parameters `s ∈ [0, 1]` along
/// them and the point; `ends` is how far from a corner a meeting still counts as the corner.
pub(crate) fn loop_crossing(
    sides: &[(crate::curve::SharedCurve, f64, f64)],
    tol: f64,
    ends: f64,
) -> Option<(usize, f64, usize, f64, Vec3)> {
    let mut pieces = Vec::with_capacity(sides.len() * LOOP_PIECES);
    for (curve, t0, t1) in sides {
        let (lo, hi) = (t0.min(*t1), t0.max(*t1));
        for q in 0..LOOP_PIECES {
            pieces.push(NetworkCurve {
                curve: curve.clone(),
                t0: lo + (hi - lo) * q as f64 / LOOP_PIECES as f64,
                t1: lo + (hi - lo) * (q + 1) as f64 / LOOP_PIECES as f64,
            });
        }
    }
    let polylines = sample_all(&pieces, LOOP_SEGMENTS).ok()?;
    let n = sides.len();
    // The piece at a side's start and at its end (pieces run with the parameter).
    let first = |i: usize| {
        let (_, t0, t1) = &sides[i];
        i * LOOP_PIECES + if t0 < t1 { 0 } else { LOOP_PIECES - 1 }
    };
    let last = |i: usize| {
        let (_, t0, t1) = &sides[i];
        i * LOOP_PIECES + if t0 < t1 { LOOP_PIECES - 1 } else { 0 }
    };
    // Each piece's ends and each side's, evaluated once: the joints are asked for at every
    // pair of segments of two neighbouring pieces' boxes.
    let piece_ends: Vec<[Vec3; 2]> = pieces
        .iter()
        .map(|p| [p.curve.point(p.t0), p.curve.point(p.t1)])
        .collect();
    let side_ends: Vec<[Vec3; 2]> = sides
        .iter()
        .map(|(curve, t0, t1)| [curve.point(*t0), curve.point(*t1)])
        .collect();
    // The point two pieces share as neighbours along the loop, if they are neighbours.
    let joint = |a: usize, b: usize| -> Option<Vec3> {
        let (i, j) = (a / LOOP_PIECES, b / LOOP_PIECES);
        if i == j && a.abs_diff(b) == 1 {
            return Some(piece_ends[a][usize::from(a < b)]);
        }
        if j == (i + 1) % n && a == last(i) && b == first(j) {
            return Some(side_ends[i][1]);
        }
        if i == (j + 1) % n && b == last(j) && a == first(i) {
            return Some(side_ends[i][0]);
        }
        None
    };
    // The segments of two neighbouring pieces that end at their joint meet there: not
    // searched (anything else near the joint still is).
    let at_joint = |a: usize, i: usize, b: usize, j: usize| {
        let Some(x) = joint(a, b) else {
            return false;
        };
        let (pa, pb) = (&polylines[a].points, &polylines[b].points);
        let touches = |p: &[Vec3], k: usize| p[k] == x || p[k + 1] == x;
        touches(pa, i) && touches(pb, j)
    };
    let hits = intersections(&pieces, &polylines, tol, 0.25, LOOP_CHUNK, &at_joint);
    for h in hits {
        let p = pieces[h.a].curve.point(h.s);
        // Neighbouring pieces meet where they join, by design.
        if joint(h.a, h.b).is_some_and(|x| (p - x).norm() <= ends) {
            continue;
        }
        let along = |k: usize, t: f64| {
            let (_, t0, t1) = &sides[k / LOOP_PIECES];
            (t - t0) / (t1 - t0)
        };
        return Some((
            h.a / LOOP_PIECES,
            along(h.a, h.s),
            h.b / LOOP_PIECES,
            along(h.b, h.t),
            p,
        ));
    }
    None
}
