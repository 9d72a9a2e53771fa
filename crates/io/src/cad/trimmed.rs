//! The holes of a trimmed surface as CAD edges: for every trim curve `c(t)` of the `(u, v)`
//! plane, a curve in the face's parameter space (the *pcurve*) and a 3D B-spline of its image on
//! the face's net.
//!
//! - **The pcurve** is the trim curve itself where it is a B-spline already: a polyline is a
//!   degree-1 B-spline, a closed uniform B-spline is written on its knots (clamped at `t = 0` by
//!   knot insertion); both exact. An ellipse becomes the cubic Hermite interpolant of `c` and
//!   `c'` at `m` equal steps of `t`, whose deviation from the ellipse is at most
//!   `h⁴/384 · sup|c⁗| = h⁴/384 · (2π)⁴ max(r₁, r₂)` (the bound of `certify`'s module docs).
//!   The pcurve's parameter `s` is `t` times its period.
//! - **The periodic seam**: the net of a periodic surface runs over one period of `v` starting
//!   at a cut that no hole crosses (the net is re-expressed there exactly, by knot insertion:
//!   [`rotate_v`]); every pcurve is moved by whole periods into that window, so a hole across
//!   `v = 0` is one closed curve inside the face's domain.
//! - **The 3D edge** is a chain of cubic Bézier pieces interpolating the net's values
//!   `N(pc(s))` and one-sided derivatives `N_u u' + N_v v'` at nodes that include every break of
//!   the pcurve (so a polyline's corners stay corners) and every crossing of a knot line of the
//!   net (bracketed), refined until its proven deviation from `N(pc(s))` is at most a quarter
//!   of the tolerance ([`bound`]: the Hermite remainder with a majorant of `(N ∘ pc)⁗` on every
//!   cell where `N ∘ pc` is smooth, a lower-order bound on the brackets). Where no proof applies
//!   (a pcurve leaving the net's domain) the pieces are refined until the deviation found by
//!   dense sampling and local maximisation meets the same target: an estimate, not a bound.
//! - **The stated deviation** of a hole from the design's own trim image `X(c(t))` is
//!   `edge + surface + L·pcurve`, `L = (L_u² + L_v²)^{1/2}` bounding the net's slopes from its
//!   control differences (the hodograph's convex hull), by the triangle inequality
//!   `|E − X(c)| ≤ |E − N(pc)| + |N(pc) − N(c)| + |N(c) − X(c)|` (`|N(p) − N(q)| ≤
//!   L_u |Δu| + L_v |Δv| ≤ L |p − q|` along the segment, which the domain holds). The pcurve's
//!   term is always a bound; the whole is certified when the edge's and the surface's are.

mod bound;

use super::curve::BCurve;
use crate::design::SurfaceTrim;
use crate::spline::BSplineSurface;
use crate::trim::TrimCurve;
use crate::{Error, Result, Vec3, TAU};

/// One hole of a trimmed face.
#[derive(Clone, Debug)]
pub struct Hole {
    /// The trim curve's index in its `[[trims]]` entry.
    pub curve: usize,
    /// The curve in the face's `(u, v)` (`z = 0`), on the parameter `s = s₀ + period · t`.
    pub pcurve: BCurve,
    /// `s` of `t`: `s = offset + period · t`.
    pub period: f64,
    /// The move in `v` (whole periods) from the trim curve's `v` to the pcurve's.
    pub v_shift: f64,
    /// Largest `|pcurve(s) − c(t)|` in the `(u, v)` plane (a bound: 0 up to rounding when exact).
    pub pcurve_deviation: f64,
    /// The 3D edge curve, on the same parameter `s` as the pcurve.
    pub edge: BCurve,
    /// Largest `|edge(s) − N(pcurve(s))|`: a bound if `edge_certified`, else sampled (an
    /// estimate).
    pub edge_deviation: f64,
    /// True if `edge_deviation` is proven.
    pub edge_certified: bool,
    /// `edge + surface + L·pcurve` deviation from the design's `X(c(t))`.
    pub deviation: f64,
    /// True if `deviation` is proven: the edge's and the surface's deviations are.
    pub certified: bool,
    /// True if the pcurve runs counter-clockwise in `(u, v)`.
    pub counter_clockwise: bool,
}

/// Relative allowance for rounding in the exact pcurves.
const ROUNDING: f64 = 1e-12;
/// The most nodes of one edge curve.
const MAX_EDGE_NODES: usize = 1 << 16;

/// The net re-expressed on `v ∈ [start, start + P]` (`P` its `v` period, the net closed in
/// `v`): cut at `start` (reduced into the domain) by inserting the knot to multiplicity `q`,
/// the two pieces joined the other way round, the knots moved to begin at `start`. The same
/// surface up to rounding.
pub(crate) fn rotate_v(net: &BSplineSurface, start: f64) -> Result<BSplineSurface> {
    let t = net.transposed();
    let q = t.degree()[0];
    let [[a, b], _] = t.domain();
    let period = b - a;
    let mut cut = a + (start - a).rem_euclid(period);
    // A cut within rounding of a knot (the old seam) is that knot.
    if let Some(&k) = t
        .knots_u()
        .iter()
        .find(|&&k| (k - cut).abs() <= 1e-12 * period)
    {
        cut = k;
    }
    let mut t = t;
    if cut > a && cut < b {
        let mult = |n: &BSplineSurface| n.knots_u().iter().filter(|&&k| k == cut).count();
        while mult(&t) < q {
            t = t.insert_knot_u(cut)?;
        }
        let k = t.knots_u().to_vec();
        let r = k.iter().position(|&x| x == cut).unwrap_or(0);
        let nv = t.counts()[1];
        let c = t.control();
        let rows = t.counts()[0];
        // Right piece: rows r−1 … rows−1 on knots [cut⁴ … b^q]; left piece rows 1 … r−1
        // (row 0 is the last row: the net is closed) on knots moved by the period.
        let mut knots = vec![cut];
        knots.extend_from_slice(&k[r..k.len() - 1]);
        knots.extend(k[q + 1..=r + q - 1].iter().map(|x| x + period));
        knots.push(cut + period);
        let mut control = c[(r - 1) * nv..rows * nv].to_vec();
        control.extend_from_slice(&c[nv..r * nv]);
        t = BSplineSurface::new(t.degree(), knots, t.knots_v().to_vec(), control)?;
    }
    let shift = start - t.domain()[0][0];
    let knots: Vec<f64> = t.knots_u().iter().map(|x| x + shift).collect();
    Ok(BSplineSurface::new(
        t.degree(),
        knots,
        t.knots_v().to_vec(),
        t.control().to_vec(),
    )?
    .transposed())
}

/// The pcurve of a trim curve before any move in `v`: the curve, its period in `s` and its
/// deviation bound in `(u, v)`; `lipschitz` and `budget` size an ellipse's interpolant so that
/// `lipschitz · deviation ≤ budget`.
fn pcurve(curve: &TrimCurve, lipschitz: f64, budget: f64) -> Result<(BCurve, f64, f64)> {
    let p2 = |p: [f64; 2]| Vec3::new(p[0], p[1], 0.0);
    match curve {
        TrimCurve::Polyline(pts) => {
            let n = pts.len();
            let mut knots = vec![0.0];
            knots.extend((0..=n).map(|k| k as f64));
            knots.push(n as f64);
            let mut points: Vec<Vec3> = pts.iter().map(|&p| p2(p)).collect();
            points.push(points[0]);
            Ok((BCurve::new(1, knots, points)?, n as f64, 0.0))
        }
        TrimCurve::BSpline { degree, points } => {
            let (p, n) = (*degree, points.len());
            let knots: Vec<f64> = (0..=n + 2 * p).map(|j| j as f64 - p as f64).collect();
            let ctrl: Vec<Vec3> = (0..n + p).map(|j| p2(points[(j + n - p) % n])).collect();
            let mut c = BCurve::new(p, knots, ctrl)?.clamped();
            let first = c.points[0];
            *c.points.last_mut().unwrap() = first;
            let size = points
                .iter()
                .fold(1.0f64, |m, q| m.max(q[0].abs()).max(q[1].abs()));
            Ok((c, n as f64, ROUNDING * size))
        }
        TrimCurve::Ellipse { radii, angle, .. } => {
            let r = radii[0].max(radii[1]);
            // h⁴/384 · (2π)⁴ r · L ≤ budget with h = 1/m.
            let need = TAU * (r * lipschitz / (384.0 * budget)).powf(0.25);
            let m = (need.ceil().max(8.0) as usize).min(MAX_EDGE_NODES);
            let s: Vec<f64> = (0..=m).map(|k| k as f64 / m as f64).collect();
            let (sa, ca) = angle.sin_cos();
            let x: Vec<Vec3> = (0..=m)
                .map(|k| p2(curve.point(if k == m { 0.0 } else { s[k] })))
                .collect();
            let d: Vec<Vec3> = s
                .iter()
                .map(|&t| {
                    let (st, ct) = (TAU * t).sin_cos();
                    let (dx, dy) = (-radii[0] * st * TAU, radii[1] * ct * TAU);
                    Vec3::new(ca * dx - sa * dy, sa * dx + ca * dy, 0.0)
                })
                .collect();
            let c = BCurve::hermite_chain(&s, &x, &d, &d);
            let h = 1.0 / m as f64;
            let bound = h.powi(4) / 384.0 * TAU.powi(4) * r;
            let size = 1.0f64.max(x.iter().fold(0.0f64, |m, p| m.max(p.amax())));
            Ok((c, 1.0, bound + ROUNDING * size))
        }
    }
}

/// `L_u`, `L_v`: bounds of `|N_u|`, `|N_v|` over the whole net from its control differences.
pub(crate) fn slope_bounds(net: &BSplineSurface) -> [f64; 2] {
    let [p, q] = net.degree();
    let [nu, nv] = net.counts();
    let (ku, kv, c) = (net.knots_u(), net.knots_v(), net.control());
    let mut l = [0.0f64; 2];
    for i in 0..nu {
        for j in 0..nv {
            if i + 1 < nu {
                let den = ku[i + p + 1] - ku[i + 1];
                if den > 0.0 {
                    l[0] = l[0].max(p as f64 * (c[(i + 1) * nv + j] - c[i * nv + j]).norm() / den);
                }
            }
            if j + 1 < nv {
                let den = kv[j + q + 1] - kv[j + 1];
                if den > 0.0 {
                    l[1] = l[1].max(q as f64 * (c[i * nv + j + 1] - c[i * nv + j]).norm() / den);
                }
            }
        }
    }
    l
}

/// The net's point and one-sided derivative along a pcurve at `s`.
fn along(net: &BSplineSurface, pc: &BCurve, s: f64, left: bool) -> (Vec3, Vec3) {
    let q = pc.point(s);
    let d = pc.derivative(s, left);
    let x = net.derivative(q.x, q.y, 0, 0);
    let t = net.derivative(q.x, q.y, 1, 0) * d.x + net.derivative(q.x, q.y, 0, 1) * d.y;
    (x, t)
}

/// The largest `|edge(s) − N(pc(s))|`: 9 samples in each piece of the edge, then golden-section
/// maximisation around the 8 largest.
pub(crate) fn edge_deviation(net: &BSplineSurface, pc: &BCurve, edge: &BCurve) -> f64 {
    let dev = |s: f64| {
        let q = pc.point(s);
        (edge.point(s) - net.derivative(q.x, q.y, 0, 0)).norm()
    };
    let breaks = edge.breaks();
    let mut samples: Vec<(f64, f64, f64)> = Vec::new();
    for w in breaks.windows(2) {
        let h = (w[1] - w[0]) / 8.0;
        for k in 0..=8 {
            let s = w[0] + h * k as f64;
            samples.push((dev(s), s, h));
        }
    }
    samples.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut worst = samples.first().map_or(0.0, |x| x.0);
    let [lo, hi] = edge.domain();
    for &(_, s, h) in samples.iter().take(8) {
        worst = worst.max(golden_max(&dev, (s - h).max(lo), (s + h).min(hi), 40));
    }
    worst
}

/// `f` at the end of `iterations` golden-section steps towards a largest value on `[a, b]`
/// (a local maximum when `f` is unimodal there).
pub(crate) fn golden_max(f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64, iterations: usize) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..iterations {
        let (x1, x2) = (b - g * (b - a), a + g * (b - a));
        if f(x1) > f(x2) {
            b = x2;
        } else {
            a = x1;
        }
    }
    f(0.5 * (a + b))
}

/// The edge of a pcurve on the net with its deviation and whether that is proven: the proven
/// edge of [`bound`] if it applies, else pieces refined (doubled) until the sampled deviation is
/// at most `target`.
fn edge_curve(net: &BSplineSurface, pc: &BCurve, target: f64) -> Result<(BCurve, f64, bool)> {
    if let Some((edge, dev)) = bound::proven_edge(net, pc, target) {
        return Ok((edge, dev, true));
    }
    let breaks = pc.breaks();
    let mut per = (32 / (breaks.len() - 1)).max(1);
    loop {
        let mut s = Vec::new();
        for w in breaks.windows(2) {
            for k in 0..per {
                s.push(w[0] + (w[1] - w[0]) * k as f64 / per as f64);
            }
        }
        s.push(*breaks.last().unwrap());
        let (mut x, mut right, mut left) = (Vec::new(), Vec::new(), Vec::new());
        for &si in &s {
            let (p, r) = along(net, pc, si, false);
            let (_, l) = along(net, pc, si, true);
            x.push(p);
            right.push(r);
            left.push(l);
        }
        // A closed curve: its end is its start, bit for bit.
        let n = x.len();
        x[n - 1] = x[0];
        let edge = BCurve::hermite_chain(&s, &x, &right, &left);
        let dev = edge_deviation(net, pc, &edge);
        if !dev.is_finite() {
            return Err(Error::invalid(
                "a hole's edge has a value that is not finite",
            ));
        }
        if dev <= target || s.len() * 2 > MAX_EDGE_NODES {
            return Ok((edge, dev, false));
        }
        per *= 2;
    }
}

/// The `v` window `[cut, cut + 2π]` of a periodic face: `0` if no pcurve crosses `v = 0`
/// (mod 2π), else the point of the circle farthest from every pcurve's `v` range (its control
/// points' range, which holds the curve's). Refused if the ranges leave no free `v`.
fn seam_cut(ranges: &[[f64; 2]]) -> Result<f64> {
    let norm: Vec<[f64; 2]> = ranges
        .iter()
        .map(|&[lo, hi]| {
            let a = lo.rem_euclid(TAU);
            [a, a + (hi - lo)]
        })
        .collect();
    // Distance of x from the covered ranges (0 inside one).
    let clearance = |x: f64| {
        norm.iter()
            .map(|&[a, b]| {
                let y = if x < a { x + TAU } else { x };
                if y <= b {
                    0.0
                } else {
                    (y - b).min(a + TAU - y)
                }
            })
            .fold(f64::INFINITY, f64::min)
    };
    if clearance(0.0) > 0.0 {
        return Ok(0.0);
    }
    let best = (0..1440)
        .map(|k| TAU * k as f64 / 1440.0)
        .max_by(|&x, &y| clearance(x).total_cmp(&clearance(y)))
        .unwrap_or(0.0);
    if clearance(best) <= 0.0 {
        return Err(Error::invalid(
            "the holes cover every v of the periodic surface: a face needs a free seam",
        ));
    }
    Ok(best)
}

/// The holes of one trimmed surface on its net (`surface_deviation`: the net's deviation from
/// the design's surface, proven if `surface_certified`), with the net moved onto the `v`
/// window the holes need when `v` is periodic. `tolerance` sizes the pcurves and the edges.
pub fn holes(
    trim: &SurfaceTrim,
    net: &BSplineSurface,
    periodic_v: bool,
    surface_deviation: f64,
    surface_certified: bool,
    tolerance: f64,
) -> Result<(BSplineSurface, Vec<Hole>)> {
    let [lu, lv] = slope_bounds(net);
    let lipschitz = lu.hypot(lv);
    let mut curves = Vec::with_capacity(trim.curves.len());
    for (k, c) in trim.curves.iter().enumerate() {
        let (pc, period, dev) =
            pcurve(c, lipschitz, 0.05 * tolerance).map_err(|e| e.at(&format!("curves[{k}]")))?;
        curves.push((pc, period, dev));
    }
    let range = |pc: &BCurve| {
        pc.points
            .iter()
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], p| {
                [a.min(p.y), b.max(p.y)]
            })
    };
    let mut net = net.clone();
    let mut shifts = vec![0.0; curves.len()];
    if periodic_v {
        let ranges: Vec<[f64; 2]> = curves.iter().map(|(pc, _, _)| range(pc)).collect();
        let cut = seam_cut(&ranges)?;
        let [_, [v0, _]] = net.domain();
        if cut != 0.0 {
            net = rotate_v(&net, v0 + cut)?;
        }
        let start = net.domain()[1][0];
        for (k, r) in ranges.iter().enumerate() {
            shifts[k] = TAU * ((start - r[0]) / TAU).ceil();
        }
    }
    let mut out = Vec::with_capacity(curves.len());
    for (k, (mut pc, period, pdev)) in curves.into_iter().enumerate() {
        for p in &mut pc.points {
            p.y += shifts[k];
        }
        let (edge, edev, proven) = edge_curve(&net, &pc, 0.25 * tolerance)?;
        let area: f64 = {
            let [a, b] = pc.domain();
            let n = 4096;
            let pts: Vec<Vec3> = (0..n)
                .map(|i| pc.point(a + (b - a) * i as f64 / n as f64))
                .collect();
            (0..n)
                .map(|i| {
                    let (p, q) = (pts[i], pts[(i + 1) % n]);
                    p.x * q.y - p.y * q.x
                })
                .sum()
        };
        out.push(Hole {
            curve: k,
            pcurve: pc,
            period,
            v_shift: shifts[k],
            pcurve_deviation: pdev,
            edge,
            edge_deviation: edev,
            edge_certified: proven,
            deviation: edev + surface_deviation + lipschitz * pdev,
            certified: proven && surface_certified,
            counter_clockwise: area > 0.0,
        });
    }
    Ok((net, out))
}
