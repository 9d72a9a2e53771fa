//! The book's two re-meshings of the region between a trim curve and its bounding rectangle
//! (§5.2, Figs. 5.7–5.10), for curves that are star-shaped about their centroid (convex ones).
//!
//! In grid cells, the rectangle is `[I₀, I₁] × [J₀, J₁]`: the bounding box widened by a quarter
//! of its sides (at least one cell) and out to grid lines. Its boundary's `n = 2(W + H)` grid vertices, counter-clockwise from
//! `(I₀, J₀)`, are matched to `n` points of the curve: the rays from the curve's centroid to the
//! rectangle's corners cut the curve at four points (found by bisection on the curve's own
//! parameter, so they lie on the curve), and the arc between two of them gets as many points,
//! equally spaced in arc length, as the matching side. Between the curve (row 0) and the
//! rectangle (row `L`, `L` ≈ the mean distance in cells), rows of points come from
//! - bilinear: `(1 − l/L)·c_k + (l/L)·r_k` (the four regions `R₁…R₄` of Fig. 5.8 at once);
//! - Laplace (Eq. 5.3): `M(s, θ)` with `M_ss + M_θθ = 0`, `M(0, θ_k) = c_k`, `M(1, θ_k) = r_k`,
//!   `θ_k = 2πk/n`, solved per discrete Fourier mode `m`. The book's `(u, v) ∈ [0,1] × [0,2π]`
//!   fixes the ring's proportions at 1 : 2π; here `θ` is scaled to the ring's own proportions
//!   (`T` cells thick, `n` cells around: frequency `ω = min(m, n − m)·2πT/n`), so the map is
//!   the harmonic one of the ring as it lies in the grid:
//!   `M̂_m(s) = Ĉ_m sinh(ω(1−s))/sinh ω + R̂_m sinh(ωs)/sinh ω` (`(1−s)Ĉ₀ + sR̂₀` for `ω = 0`),
//!   with the ratios evaluated as `e^{−ω(1−x)}(1 − e^{−2ωx})/(1 − e^{−2ω})` so nothing overflows.

use super::{Frame, Loop, Loops, OnTrim, ParamMesh, Scratch, TrimCurve, TrimMethod};
use crate::{Error, Result};
use realfft::RealFftPlanner;

/// The rectangle's margin around the curve's bounding box, as a fraction of the box's sides (at
/// least one grid cell), so the rectangle and the ring mesh converge as the grid is refined.
pub(super) const MARGIN: f64 = 0.25;

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// The area centroid of a polygon.
fn centroid(p: &[[f64; 2]]) -> [f64; 2] {
    let n = p.len();
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for k in 0..n {
        let (p0, p1) = (p[k], p[(k + 1) % n]);
        let w = cross(p0, p1);
        a += w;
        cx += (p0[0] + p1[0]) * w;
        cy += (p0[1] + p1[1]) * w;
    }
    [cx / (3.0 * a), cy / (3.0 * a)]
}

/// A hole's ring of points, rows `0..=L`, `n` columns; row 0 on the curve, row `L` the
/// rectangle's grid vertices `(i, j)` (unwrapped column).
struct Ring {
    rect: Vec<(usize, i64)>,
    curve_t: Vec<f64>,
    curve_uv: Vec<[f64; 2]>,
    /// Rows 1..L−1, in grid cells (unwrapped).
    inner: Vec<Vec<[f64; 2]>>,
}

/// The curve in grid cells of the loop's window.
fn curve_st(frame: &Frame, c: &TrimCurve, l: &Loop, t: f64) -> ([f64; 2], [f64; 2]) {
    let shift = l.st[0][1] - frame.scaled(l.uv[0])[1];
    let uv = c.point(t.rem_euclid(1.0));
    let s = frame.scaled(uv);
    ([s[0], s[1] + shift], uv)
}

fn ring(
    frame: &Frame,
    c: &TrimCurve,
    l: &Loop,
    k: usize,
    method: TrimMethod,
) -> Result<(Ring, [i64; 4])> {
    let place = format!("curves[{k}]");
    let cen = centroid(&l.st);
    let n = l.st.len();
    for q in 0..n {
        if cross(sub(l.st[q], cen), sub(l.st[(q + 1) % n], cen)) <= 0.0 {
            return Err(Error::invalid(format!(
                "the {} method needs a curve that is star-shaped about its centroid (convex); \
                 this one is not: use method = \"cdt\"",
                method.word()
            ))
            .at(&place));
        }
    }
    let (lo, hi) = super::curve::bbox(&l.st);
    let (mu, mv) = (
        (MARGIN * (hi[0] - lo[0])).max(1.0),
        (MARGIN * (hi[1] - lo[1])).max(1.0),
    );
    let (i0, i1) = ((lo[0] - mu).floor() as i64, (hi[0] + mu).ceil() as i64);
    let (j0, j1) = ((lo[1] - mv).floor() as i64, (hi[1] + mv).ceil() as i64);
    let fits_u = i0 >= 0 && i1 < frame.nu as i64;
    let fits_v = frame.periodic || (j0 >= 0 && j1 < frame.nv as i64);
    if !(fits_u && fits_v) || j1 - j0 >= frame.nv as i64 {
        return Err(Error::invalid(format!(
            "the {} method needs the curve's bounding rectangle, widened to grid lines and by \
             one cell, inside the patch; this curve is too close to its edge: use method = \"cdt\"",
            method.word()
        ))
        .at(&place));
    }
    let (w, h) = ((i1 - i0) as usize, (j1 - j0) as usize);
    let mut rect = Vec::with_capacity(2 * (w + h));
    for i in i0..i1 {
        rect.push((i as usize, j0));
    }
    for j in j0..j1 {
        rect.push((i1 as usize, j));
    }
    for i in (i0 + 1..=i1).rev() {
        rect.push((i as usize, j1));
    }
    for j in (j0 + 1..=j1).rev() {
        rect.push((i0 as usize, j));
    }
    let corners = [(i0, j0), (i1, j0), (i1, j1), (i0, j1)];
    let starts = [0, w, w + h, 2 * w + h];
    // The loop's parameters, increasing counter-clockwise (the loop may run against t).
    let forward = {
        let (a, b) = (l.t[0], l.t[1]);
        let d = (b - a).rem_euclid(1.0);
        d < 0.5
    };
    let dir = if forward { 1.0 } else { -1.0 };
    // Unwrapped parameters along the loop (counter-clockwise).
    let mut tl = Vec::with_capacity(n + 1);
    tl.push(l.t[0]);
    for q in 1..=n {
        let prev = tl[q - 1];
        let raw = l.t[q % n];
        let step = (dir * (raw - prev)).rem_euclid(1.0);
        tl.push(prev + dir * step);
    }
    // Corner parameters: the ray from the centroid through the corner crosses the curve once.
    let mut tc = [0.0; 4];
    for (m, &(ci, cj)) in corners.iter().enumerate() {
        let d = [ci as f64 - cen[0], cj as f64 - cen[1]];
        let side = |t: f64| cross(d, sub(curve_st(frame, c, l, t).0, cen));
        // Samples q, q+1 with the ray between them (angle from ≤ to >).
        let q = (0..n)
            .find(|&q| {
                let a = cross(d, sub(l.st[q], cen));
                let b = cross(d, sub(l.st[(q + 1) % n], cen));
                a <= 0.0 && b > 0.0 && dot(d, sub(l.st[q], cen)) > 0.0
            })
            .ok_or_else(|| Error::invalid("no crossing of a corner ray").at(&place))?;
        let (mut a, mut b) = (tl[q], tl[q + 1]);
        for _ in 0..80 {
            let mid = 0.5 * (a + b);
            if side(mid) <= 0.0 {
                a = mid;
            } else {
                b = mid;
            }
        }
        tc[m] = if side(a) == 0.0 { a } else { b };
    }
    // Corner parameters increasing counter-clockwise from corner 0.
    for m in 1..4 {
        while dir * (tc[m] - tc[m - 1]) <= 0.0 {
            tc[m] += dir;
        }
    }
    let mut t_end = tc[0] + dir;
    while dir * (t_end - tc[3]) <= 0.0 {
        t_end += dir;
    }
    let ends = [tc[0], tc[1], tc[2], tc[3], t_end];
    let mut curve_t = Vec::with_capacity(rect.len());
    let mut curve_pts = Vec::with_capacity(rect.len());
    let mut curve_uv = Vec::with_capacity(rect.len());
    for m in 0..4 {
        let p = if m % 2 == 0 { w } else { h };
        let (a, b) = (ends[m], ends[m + 1]);
        // Arc length table along [a, b] in grid cells.
        let dense = 32 * p;
        let pts: Vec<[f64; 2]> = (0..=dense)
            .map(|q| curve_st(frame, c, l, a + (b - a) * q as f64 / dense as f64).0)
            .collect();
        let mut cum = vec![0.0];
        for q in 0..dense {
            let e = sub(pts[q + 1], pts[q]);
            cum.push(cum[q] + e[0].hypot(e[1]));
        }
        let total = cum[dense];
        let mut seg = 0;
        for q in 0..p {
            let target = total * q as f64 / p as f64;
            while seg + 1 < dense && cum[seg + 1] < target {
                seg += 1;
            }
            let f = if cum[seg + 1] > cum[seg] {
                (target - cum[seg]) / (cum[seg + 1] - cum[seg])
            } else {
                0.0
            };
            let t = if q == 0 {
                a
            } else {
                a + (b - a) * (seg as f64 + f) / dense as f64
            };
            let (st, uv) = curve_st(frame, c, l, t);
            curve_t.push(t.rem_euclid(1.0));
            curve_pts.push(st);
            curve_uv.push(uv);
        }
    }
    debug_assert_eq!(starts[3] + h, rect.len());
    let outer: Vec<[f64; 2]> = rect.iter().map(|&(i, j)| [i as f64, j as f64]).collect();
    let mean = outer
        .iter()
        .zip(&curve_pts)
        .map(|(r, c)| sub(*r, *c))
        .map(|d| d[0].hypot(d[1]))
        .sum::<f64>()
        / outer.len() as f64;
    let layers = (mean.round() as usize).max(1);
    let inner = match method {
        TrimMethod::Laplace => laplace_rows(&curve_pts, &outer, layers, mean),
        _ => (1..layers)
            .map(|row| {
                let f = row as f64 / layers as f64;
                curve_pts
                    .iter()
                    .zip(&outer)
                    .map(|(c, r)| [(1.0 - f) * c[0] + f * r[0], (1.0 - f) * c[1] + f * r[1]])
                    .collect()
            })
            .collect(),
    };
    Ok((
        Ring {
            rect,
            curve_t,
            curve_uv,
            inner,
        },
        [i0, i1, j0, j1],
    ))
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Rows `1..L` of the discrete Fourier solution of Eq. 5.3 between `inner` (s = 0) and `outer`
/// (s = 1).
fn laplace_rows(
    inner: &[[f64; 2]],
    outer: &[[f64; 2]],
    layers: usize,
    thickness: f64,
) -> Vec<Vec<[f64; 2]>> {
    let n = inner.len();
    // θ scaled to the ring's proportions: a ring `thickness` cells thick and `n` cells around.
    let aspect = crate::TAU * thickness / n as f64;
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(n);
    let inv = planner.plan_fft_inverse(n);
    let spectrum = |data: &[[f64; 2]], c: usize| {
        let mut x: Vec<f64> = data.iter().map(|p| p[c]).collect();
        let mut out = fwd.make_output_vec();
        fwd.process(&mut x, &mut out).expect("sizes from the plan");
        out
    };
    let (ci, co) = (
        [spectrum(inner, 0), spectrum(inner, 1)],
        [spectrum(outer, 0), spectrum(outer, 1)],
    );
    // sinh(ωx)/sinh(ω) without overflow.
    let ratio = |w: f64, x: f64| {
        if w == 0.0 {
            x
        } else {
            (-w * (1.0 - x)).exp() * (1.0 - (-2.0 * w * x).exp()) / (1.0 - (-2.0 * w).exp())
        }
    };
    (1..layers)
        .map(|row| {
            let s = row as f64 / layers as f64;
            let mut cols = [vec![0.0; n], vec![0.0; n]];
            for c in 0..2 {
                let mut h = inv.make_input_vec();
                for (m, hm) in h.iter_mut().enumerate() {
                    let w = m.min(n - m) as f64 * aspect;
                    *hm = ci[c][m] * ratio(w, 1.0 - s) + co[c][m] * ratio(w, s);
                }
                // The imaginary parts of the mean (and of the Nyquist term) must be zero.
                h[0].im = 0.0;
                if n.is_multiple_of(2) {
                    h[n / 2].im = 0.0;
                }
                inv.process(&mut h, &mut cols[c])
                    .expect("sizes from the plan");
            }
            (0..n)
                .map(|k| [cols[0][k] / n as f64, cols[1][k] / n as f64])
                .collect()
        })
        .collect()
}

/// The trimmed domain by the book's bilinear or Laplace method.
pub(super) fn mesh(
    frame: &Frame,
    loops: &Loops,
    curves: &[TrimCurve],
    method: TrimMethod,
    pm: &mut ParamMesh,
    scratch: &mut Scratch,
) -> Result<()> {
    let (nu, nv, cols) = (frame.nu, frame.nv, frame.cols());
    let mut rings = Vec::new();
    let removed = &mut scratch.removed;
    removed.clear();
    removed.resize((nu - 1) * cols, false);
    let mut dropped = vec![0u8; nu * nv];
    for l in &loops.loops {
        let (r, [i0, i1, j0, j1]) = ring(frame, &curves[l.curve], l, l.curve, method)?;
        for i in i0..i1 {
            for j in j0..j1 {
                let cell = &mut removed[i as usize * cols + frame.col(j)];
                if *cell {
                    return Err(Error::invalid(format!(
                        "the bounding rectangles of two trims overlap; the {} method meshes \
                         each hole in its own rectangle: use method = \"cdt\"",
                        method.word()
                    ))
                    .at(&format!("curves[{}]", l.curve)));
                }
                *cell = true;
                if i > i0 && j > j0 {
                    dropped[i as usize * nv + frame.col(j)] = 1;
                }
            }
        }
        rings.push((l.curve, r));
    }
    let id = &mut scratch.id;
    // Each ring adds its curve's and inner rows' vertices and two triangles a column between
    // consecutive rows (curve, inner rows, rectangle).
    let extra = rings.iter().fold([0, 0], |[v, t], (_, r)| {
        let n = r.rect.len();
        [v + n * (1 + r.inner.len()), t + 2 * n * (1 + r.inner.len())]
    });
    frame.kept_grid(&dropped, 1, removed, extra, pm, id);
    for (curve, r) in &rings {
        let n = r.rect.len();
        let mut rows: Vec<Vec<u32>> = Vec::new();
        let first = pm.uv.len() as u32;
        for (k, (&t, &uv)) in r.curve_t.iter().zip(&r.curve_uv).enumerate() {
            pm.on_trim.push(OnTrim {
                vertex: first + k as u32,
                curve: *curve,
                t,
            });
            pm.uv.push(uv);
        }
        rows.push((first..first + n as u32).collect());
        for row in &r.inner {
            let first = pm.uv.len() as u32;
            for p in row {
                let v = frame.v0 + p[1] * frame.dv;
                let v = if frame.periodic {
                    v.rem_euclid(crate::TAU)
                } else {
                    v
                };
                pm.uv.push([frame.u0 + p[0] * frame.du, v]);
            }
            rows.push((first..first + n as u32).collect());
        }
        rows.push(
            r.rect
                .iter()
                .map(|&(i, j)| id[i * nv + frame.col(j)])
                .collect(),
        );
        for l in 0..rows.len() - 1 {
            for k in 0..n {
                let k1 = (k + 1) % n;
                let (a, b, c, d) = (rows[l][k], rows[l + 1][k], rows[l + 1][k1], rows[l][k1]);
                pm.triangles.push([a, b, c]);
                pm.triangles.push([a, c, d]);
            }
        }
    }
    Ok(())
}
