//! Closed trim curves in a patch's `(u, v)` parameter plane (§5.2) and their sampling.

use crate::{Error, Result, TAU};

/// The most samples of one piece of a trim curve.
pub(super) const MAX_SAMPLES: usize = 1 << 20;

/// A closed curve `c(t)`, `t ∈ [0, 1)`, in the `(u, v)` parameter plane of a surface. Its
/// inside is removed from the surface. Coordinates are those of the plane itself: a curve across
/// the seam of a periodic `v` simply has `v` values below 0 or above 2π.
#[derive(Clone, Debug, PartialEq)]
pub enum TrimCurve {
    /// `c(t) = center + R(angle) (a cos 2πt, b sin 2πt)` with `radii = [a, b]` (a circle when
    /// `a = b`); `angle` in radians, measured from the `u` axis towards `v`.
    Ellipse {
        /// Centre `[u, v]`.
        center: [f64; 2],
        /// Semi-axes `[a, b]`, both positive.
        radii: [f64; 2],
        /// Rotation of the `a` axis from the `u` axis towards `v`, radians.
        angle: f64,
    },
    /// The closed polygon through the points (the last joins the first); `t = k/n` is point `k`.
    Polyline(Vec<[f64; 2]>),
    /// The closed uniform B-spline of `degree` over the control points taken cyclically:
    /// `c(t) = Σ_i P_{i mod n} N_p(nt − i)` with the cardinal B-spline `N_p` on `[0, p+1]`.
    BSpline {
        /// The degree `p`, 1 to [`MAX_DEGREE`] and below the number of control points.
        degree: usize,
        /// The control points `P_i = [u, v]`, taken cyclically.
        points: Vec<[f64; 2]>,
    },
}

/// Largest B-spline degree accepted.
pub const MAX_DEGREE: usize = 7;

impl TrimCurve {
    /// A circle of `radius` about `center`.
    pub fn circle(center: [f64; 2], radius: f64) -> TrimCurve {
        TrimCurve::Ellipse {
            center,
            radii: [radius, radius],
            angle: 0.0,
        }
    }

    /// The curve's kind as the design file writes it.
    pub fn kind(&self) -> &'static str {
        match self {
            TrimCurve::Ellipse { radii, .. } if radii[0] == radii[1] => "circle",
            TrimCurve::Ellipse { .. } => "ellipse",
            TrimCurve::Polyline(_) => "polyline",
            TrimCurve::BSpline { .. } => "bspline",
        }
    }

    /// Refuses values that do not make a closed curve: non-finite numbers, radii ≤ 0, fewer
    /// than 3 points, a degree outside `1..=7` or not below the number of control points.
    pub fn validate(&self) -> Result<()> {
        let finite = |p: &[f64]| p.iter().all(|x| x.is_finite());
        match self {
            TrimCurve::Ellipse {
                center,
                radii,
                angle,
            } => {
                if !finite(center) {
                    return Err(Error::invalid("must be finite").at("center"));
                }
                if !(radii.iter().all(|r| r.is_finite() && *r > 0.0)) {
                    return Err(Error::invalid(format!(
                        "must be finite and positive (got {radii:?})"
                    ))
                    .at("radius"));
                }
                if !angle.is_finite() {
                    return Err(Error::invalid("must be finite").at("angle"));
                }
            }
            TrimCurve::Polyline(p) | TrimCurve::BSpline { points: p, .. } => {
                if p.len() < 3 {
                    return Err(Error::invalid(format!(
                        "a closed curve needs at least 3 points (got {})",
                        p.len()
                    ))
                    .at("points"));
                }
                if let Some(k) = p.iter().position(|q| !finite(q)) {
                    return Err(Error::invalid("must be finite").at(&format!("points[{k}]")));
                }
                if let TrimCurve::BSpline { degree, .. } = self {
                    if *degree == 0 || *degree > MAX_DEGREE || *degree >= p.len() {
                        return Err(Error::invalid(format!(
                            "must be between 1 and {} for {} control points (got {degree})",
                            MAX_DEGREE.min(p.len() - 1),
                            p.len()
                        ))
                        .at("degree"));
                    }
                }
                if let TrimCurve::Polyline(_) = self {
                    if let Some(k) = (0..p.len()).find(|&k| p[k] == p[(k + 1) % p.len()]) {
                        return Err(Error::invalid(format!(
                            "points {k} and {} are equal",
                            (k + 1) % p.len()
                        ))
                        .at("points"));
                    }
                }
            }
        }
        Ok(())
    }

    /// A box `(lo, hi)` that holds the whole curve: the ellipse's own extent (`a cos θ`,
    /// `b sin θ` combined per axis), the polygon's vertices, and the B-spline's control points
    /// (its basis functions are non-negative and sum to one, so every point of the curve is a
    /// convex combination of control points). Exact for ellipses and polygons.
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        match self {
            TrimCurve::Ellipse {
                center,
                radii,
                angle,
            } => {
                let (s, c) = angle.sin_cos();
                // u = cu + a cos θ cos φ − b sin θ sin φ: amplitude hypot(a cos θ, b sin θ).
                let half = [
                    (radii[0] * c).hypot(radii[1] * s),
                    (radii[0] * s).hypot(radii[1] * c),
                ];
                (
                    [center[0] - half[0], center[1] - half[1]],
                    [center[0] + half[0], center[1] + half[1]],
                )
            }
            TrimCurve::Polyline(p) | TrimCurve::BSpline { points: p, .. } => bbox(p),
        }
    }

    /// The extent `(lo, hi)` of `n` points `c(k/n)`, `k = 0, …, n − 1`.
    pub fn sampled_extent(&self, n: usize) -> ([f64; 2], [f64; 2]) {
        let points: Vec<[f64; 2]> = (0..n).map(|k| self.point(k as f64 / n as f64)).collect();
        bbox(&points)
    }

    /// `c(t)` for `t ∈ [0, 1]` (`c(1) = c(0)`).
    pub fn point(&self, t: f64) -> [f64; 2] {
        match self {
            TrimCurve::Ellipse {
                center,
                radii,
                angle,
            } => {
                let (s, c) = (TAU * t).sin_cos();
                let (x, y) = (radii[0] * c, radii[1] * s);
                let (sa, ca) = angle.sin_cos();
                [center[0] + ca * x - sa * y, center[1] + sa * x + ca * y]
            }
            TrimCurve::Polyline(p) => {
                let n = p.len();
                let x = t * n as f64;
                let k = (x.floor() as usize).min(n - 1);
                let f = x - k as f64;
                let (a, b) = (p[k], p[(k + 1) % n]);
                if f == 0.0 {
                    a
                } else {
                    [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
                }
            }
            TrimCurve::BSpline { degree, points } => {
                let n = points.len();
                let x = t * n as f64;
                let k = x.floor() as i64;
                let mut out = [0.0; 2];
                for i in k - *degree as i64..=k {
                    let w = cardinal_bspline(*degree, x - i as f64);
                    let p = points[i.rem_euclid(n as i64) as usize];
                    out[0] += w * p[0];
                    out[1] += w * p[1];
                }
                out
            }
        }
    }

    /// `c(t)`, `c'(t)` and `c''(t)` (derivatives in `t`). A polyline's derivative is the one of
    /// the segment that starts at or after `t` (its corners have none); its second derivative is
    /// zero. A B-spline of degree 1 (resp. 2) has no second derivative (resp. none at its knots):
    /// the one from the right is given.
    pub fn jet(&self, t: f64) -> [[f64; 2]; 3] {
        match self {
            TrimCurve::Ellipse { radii, angle, .. } => {
                let w = TAU;
                let (s, c) = (w * t).sin_cos();
                let (sa, ca) = angle.sin_cos();
                let rot = |x: f64, y: f64| [ca * x - sa * y, sa * x + ca * y];
                let d1 = rot(-w * radii[0] * s, w * radii[1] * c);
                let d2 = rot(-w * w * radii[0] * c, -w * w * radii[1] * s);
                [self.point(t), d1, d2]
            }
            TrimCurve::Polyline(p) => {
                let n = p.len();
                let x = t.rem_euclid(1.0) * n as f64;
                let k = (x.floor() as usize).min(n - 1);
                let (a, b) = (p[k], p[(k + 1) % n]);
                let d = [n as f64 * (b[0] - a[0]), n as f64 * (b[1] - a[1])];
                [self.point(t), d, [0.0; 2]]
            }
            TrimCurve::BSpline { degree, points } => {
                let n = points.len();
                let x = t * n as f64;
                let k = x.floor() as i64;
                let p = *degree;
                let nf = n as f64;
                let mut out = [self.point(t), [0.0; 2], [0.0; 2]];
                for i in k - p as i64..=k {
                    let y = x - i as f64;
                    // N_p'(y) = N_{p−1}(y) − N_{p−1}(y − 1); N_p'' from N_{p−2} likewise.
                    let w1 = cardinal_bspline(p - 1, y) - cardinal_bspline(p - 1, y - 1.0);
                    let w2 = if p >= 2 {
                        cardinal_bspline(p - 2, y) - 2.0 * cardinal_bspline(p - 2, y - 1.0)
                            + cardinal_bspline(p - 2, y - 2.0)
                    } else {
                        0.0
                    };
                    let q = points[i.rem_euclid(n as i64) as usize];
                    for c in 0..2 {
                        out[1][c] += nf * w1 * q[c];
                        out[2][c] += nf * nf * w2 * q[c];
                    }
                }
                out
            }
        }
    }

    /// Parameters `t ∈ [0, 1)` where a derivative of `c` may jump: the corners `k/n` of a
    /// polyline and the knots `k/n` of a B-spline (`n` points); none for an ellipse.
    pub fn breaks(&self) -> Vec<f64> {
        match self {
            TrimCurve::Ellipse { .. } => Vec::new(),
            TrimCurve::Polyline(p) | TrimCurve::BSpline { points: p, .. } => {
                let n = p.len();
                (0..n).map(|k| k as f64 / n as f64).collect()
            }
        }
    }

    /// The range `[lo, hi]` of each coordinate that holds the whole curve: the control
    /// points' (the curve lies in their convex hull), or the ellipse's `center ± amplitude`.
    pub fn coordinate_range(&self) -> [[f64; 2]; 2] {
        match self {
            TrimCurve::Ellipse { center, .. } => {
                let amp = self.amplitudes();
                [0, 1].map(|c| [center[c] - amp[c], center[c] + amp[c]])
            }
            TrimCurve::Polyline(p) | TrimCurve::BSpline { points: p, .. } => {
                let (lo, hi) = bbox(p);
                [[lo[0], hi[0]], [lo[1], hi[1]]]
            }
        }
    }

    /// The amplitudes `(A_u, A_v)` of an ellipse's coordinates `center + A cos(2πt + φ)`
    /// (zero for the other kinds).
    fn amplitudes(&self) -> [f64; 2] {
        match self {
            TrimCurve::Ellipse { radii, angle, .. } => {
                let (sa, ca) = angle.sin_cos();
                [
                    (ca * radii[0]).hypot(sa * radii[1]),
                    (sa * radii[0]).hypot(ca * radii[1]),
                ]
            }
            _ => [0.0; 2],
        }
    }

    /// Proven bounds `[U, V]` with `U[k] ≥ |u^{(k)}(t)|`, `V[k] ≥ |v^{(k)}(t)|` (`k ≤ 5`,
    /// derivatives in `t`) on the open pieces of `(t0, t1)` between [`TrimCurve::breaks`] (the
    /// curve is periodic with period 1; `t0 > t1` or a span of a whole period or more: every
    /// piece).
    ///
    /// - An ellipse's coordinate is `center + A cos(2πt + φ)`: `|c^{(k)}| ≤ (2π)^k A`, `k ≥ 1`,
    ///   and `|c| ≤ |center| + A`.
    /// - A closed uniform B-spline `Σ P_i N_p(nt − i)` of degree `p` on the piece
    ///   `nt ∈ [j, j + 1]` has the `k`-th derivative `n^k Σ_i ∇^k P_i N_{p−k}(nt − i)` over
    ///   `i = j − p + k ..= j` (`N_p' (y) = N_{p−1}(y) − N_{p−1}(y − 1)`, the cardinal
    ///   B-splines non-negative with sum one), so `n^k max |∇^k P_i|` over the piece's points
    ///   `P_{j−p} … P_j` bounds it (zero for `k > p`). A polyline is the case `p = 1` with the
    ///   piece `[k/n, (k+1)/n]` running from point `k` to point `k + 1`.
    pub fn coordinate_bounds(&self, t0: f64, t1: f64) -> [[f64; 6]; 2] {
        let mut out = [[0.0; 6]; 2];
        let (points, degree, shift) = match self {
            TrimCurve::Ellipse { center, .. } => {
                let amp = self.amplitudes();
                for (c, o) in out.iter_mut().enumerate() {
                    for (k, x) in o.iter_mut().enumerate() {
                        *x = if k == 0 {
                            center[c].abs() + amp[c]
                        } else {
                            TAU.powi(k as i32) * amp[c]
                        };
                    }
                }
                return out;
            }
            // Piece j of a polyline runs over the points j, j + 1: the B-spline indices shifted.
            TrimCurve::Polyline(p) => (p, 1, 1),
            TrimCurve::BSpline { degree, points } => (points, *degree, 0),
        };
        let n = points.len();
        let nf = n as f64;
        let (x0, x1) = (t0 * nf, t1 * nf);
        let (first, count) = if x0.is_finite() && x1.is_finite() && x1 > x0 && x1 - x0 < nf {
            let first = x0.floor();
            (first as i64, ((x1.ceil() - first) as usize).clamp(1, n))
        } else {
            (0, n)
        };
        for j in first..first + count as i64 {
            let piece: Vec<[f64; 2]> = (j - degree as i64..=j)
                .map(|i| points[(i + shift).rem_euclid(n as i64) as usize])
                .collect();
            for (c, o) in out.iter_mut().enumerate() {
                let mut diff: Vec<f64> = piece.iter().map(|q| q[c]).collect();
                for (k, ok) in o.iter_mut().enumerate() {
                    if k > degree {
                        break;
                    }
                    if k > 0 {
                        diff = diff.windows(2).map(|w| w[1] - w[0]).collect();
                    }
                    let m = nf.powi(k as i32) * diff.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    *ok = ok.max(m);
                }
            }
        }
        out
    }

    /// The orientation of the curve in the `(u, v)` plane (`u` across, `v` up): `1` if
    /// counter-clockwise (positive enclosed area), `-1` if clockwise.
    pub fn orientation(&self) -> f64 {
        let (_, p) = self.sample([1.0, 1.0], 1e-2 * self.extent());
        if signed_area(&p) >= 0.0 {
            1.0
        } else {
            -1.0
        }
    }

    /// Parameters of the polyline's corners (`k/n`); empty for smooth curves.
    fn corners(&self) -> Vec<f64> {
        match self {
            TrimCurve::Polyline(p) => (0..p.len()).map(|k| k as f64 / p.len() as f64).collect(),
            _ => vec![0.0],
        }
    }

    /// Samples of the curve about `spacing` apart (at most [`MAX_SAMPLES`] a piece), measured after scaling `u` by `1/scale[0]`
    /// and `v` by `1/scale[1]` (in grid cells): the parameters `t` and the points `c(t)` exactly
    /// as [`TrimCurve::point`] gives them. A polyline keeps its corners. At least 8 samples.
    pub fn sample(&self, scale: [f64; 2], spacing: f64) -> (Vec<f64>, Vec<[f64; 2]>) {
        let len =
            |a: [f64; 2], b: [f64; 2]| ((b[0] - a[0]) / scale[0]).hypot((b[1] - a[1]) / scale[1]);
        let corners = self.corners();
        let pieces = corners.len();
        // Dense chord lengths along each piece between corners.
        const DENSE: usize = 256;
        let dense = if matches!(self, TrimCurve::Polyline(_)) {
            1
        } else {
            DENSE
        };
        let mut ts = Vec::new();
        // Cumulative chord lengths along each piece, and their total.
        let cums: Vec<Vec<f64>> = (0..pieces)
            .map(|k| {
                let (a, b) = (
                    corners[k],
                    if k + 1 < pieces { corners[k + 1] } else { 1.0 },
                );
                std::iter::once(0.0)
                    .chain((0..dense).scan(0.0, |acc, m| {
                        let t0 = a + (b - a) * m as f64 / dense as f64;
                        let t1 = a + (b - a) * (m + 1) as f64 / dense as f64;
                        *acc += len(self.point(t0), self.point(t1));
                        Some(*acc)
                    }))
                    .collect()
            })
            .collect();
        let total: f64 = cums.iter().map(|c| c[dense]).sum();
        let min_total = 8usize;
        for (k, cum) in cums.iter().enumerate() {
            let (a, b) = (
                corners[k],
                if k + 1 < pieces { corners[k + 1] } else { 1.0 },
            );
            let l = cum[dense];
            // At most MAX_SAMPLES a piece: a curve longer than that (a radius of 1e300) is far
            // outside any patch's domain, which the caller then refuses, instead of sampling it
            // until memory runs out.
            let share = ((min_total as f64 * l / total).ceil() as usize).min(MAX_SAMPLES);
            let m = (((l / spacing).round().min(MAX_SAMPLES as f64)) as usize)
                .max(share)
                .max(1);
            // Parameters at equal chord length (linear inversion of the dense table).
            let mut seg = 0;
            for q in 0..m {
                let target = l * q as f64 / m as f64;
                while seg + 1 < dense && cum[seg + 1] < target {
                    seg += 1;
                }
                let (c0, c1) = (cum[seg], cum[seg + 1]);
                let f = if c1 > c0 {
                    (target - c0) / (c1 - c0)
                } else {
                    0.0
                };
                ts.push(a + (b - a) * (seg as f64 + f) / dense as f64);
            }
        }
        let pts = ts.iter().map(|&t| self.point(t)).collect();
        (ts, pts)
    }

    /// The enclosed area in the `(u, v)` plane (positive), from a fine polygon (exact for a
    /// polyline and an ellipse up to 10⁻¹² relative).
    pub fn area(&self) -> f64 {
        match self {
            TrimCurve::Ellipse { radii, .. } => std::f64::consts::PI * radii[0] * radii[1],
            _ => {
                let (_, p) = self.sample([1.0, 1.0], 1e-3 * self.extent());
                signed_area(&p).abs()
            }
        }
    }

    /// Largest side of the bounding box of the control data.
    fn extent(&self) -> f64 {
        let (_, p) = match self {
            TrimCurve::Ellipse { radii, .. } => return 2.0 * radii[0].max(radii[1]),
            TrimCurve::Polyline(p) | TrimCurve::BSpline { points: p, .. } => ((), p),
        };
        let (lo, hi) = bbox(p);
        (hi[0] - lo[0]).max(hi[1] - lo[1])
    }
}

/// `N_p(x)`: the cardinal B-spline of degree `p` on the knots `0, 1, …, p+1`.
fn cardinal_bspline(p: usize, x: f64) -> f64 {
    if !(0.0..(p + 1) as f64).contains(&x) {
        return 0.0;
    }
    // Cox–de Boor on integer knots: values N_{0}(x − j) for j = 0..=p, raised degree by degree.
    let mut n = [0.0; MAX_DEGREE + 1];
    let k = x.floor() as usize;
    n[k] = 1.0;
    for d in 1..=p {
        for j in 0..=p - d {
            let y = x - j as f64;
            n[j] = (y * n[j] + (d as f64 + 1.0 - y) * n[j + 1]) / d as f64;
        }
    }
    n[0]
}

/// The shoelace area, positive for a counter-clockwise polygon.
pub(crate) fn signed_area(p: &[[f64; 2]]) -> f64 {
    let n = p.len();
    0.5 * (0..n)
        .map(|k| {
            let (a, b) = (p[k], p[(k + 1) % n]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum::<f64>()
}

/// Bounding box `(lo, hi)` of points.
pub(crate) fn bbox(p: &[[f64; 2]]) -> ([f64; 2], [f64; 2]) {
    p.iter().fold(
        ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
        |(lo, hi), q| {
            (
                [lo[0].min(q[0]), lo[1].min(q[1])],
                [hi[0].max(q[0]), hi[1].max(q[1])],
            )
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cardinal_bspline_is_a_partition_of_unity() {
        for p in 1..=MAX_DEGREE {
            for k in 0..50 {
                let x = k as f64 * 0.137;
                let s: f64 = (-(p as i64) - 1..=x.floor() as i64 + 1)
                    .map(|i| cardinal_bspline(p, x - i as f64))
                    .sum();
                assert!((s - 1.0).abs() < 1e-14, "p={p} x={x} sum={s}");
            }
        }
        // Quadratic: N_2(1.5) = 3/4.
        assert!((cardinal_bspline(2, 1.5) - 0.75).abs() < 1e-15);
    }

    #[test]
    fn bounds_hold_the_curve_and_are_exact_for_ellipses_and_polygons() {
        let curves = [
            TrimCurve::Ellipse {
                center: [0.4, 2.0],
                radii: [0.3, 0.1],
                angle: 0.7,
            },
            TrimCurve::circle([0.5, 1.0], 0.2),
            TrimCurve::Polyline(vec![[0.1, 0.2], [0.9, 0.4], [0.5, 1.7]]),
            TrimCurve::BSpline {
                degree: 3,
                points: vec![[0.2, 1.0], [0.5, 0.6], [0.8, 1.0], [0.6, 1.8], [0.4, 1.8]],
            },
        ];
        for (k, c) in curves.iter().enumerate() {
            let (lo, hi) = c.bounds();
            // A multiple of the polygon's 3 vertices, so its samples take them in.
            let (slo, shi) = c.sampled_extent(21000);
            for i in 0..2 {
                assert!(lo[i] - 1e-15 <= slo[i] && shi[i] <= hi[i] + 1e-15, "{k}");
            }
            if k < 3 {
                // Samples 2π/21000 apart reach the extremes of an ellipse to within
                // (1 − cos(π/21000)) of the semi-axis, ~1.2e-8 · 0.3; the polygon's at its
                // vertices.
                for i in 0..2 {
                    assert!(
                        slo[i] - lo[i] < 1e-8 && hi[i] - shi[i] < 1e-8,
                        "{k}: {lo:?} {hi:?} {slo:?} {shi:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn closed_bspline_is_closed_and_sampled_on_the_curve() {
        let c = TrimCurve::BSpline {
            degree: 3,
            points: vec![[0.2, 1.0], [0.5, 0.6], [0.8, 1.0], [0.6, 1.8], [0.4, 1.8]],
        };
        let (a, b) = (c.point(0.0), c.point(1.0));
        assert!((a[0] - b[0]).abs() < 1e-15 && (a[1] - b[1]).abs() < 1e-15);
        let (ts, ps) = c.sample([0.01, 0.02], 1.0);
        assert!(ts.len() > 50);
        for (t, p) in ts.iter().zip(&ps) {
            assert_eq!(c.point(*t), *p);
        }
    }

    #[test]
    fn polyline_samples_keep_the_corners_and_ellipse_area_is_exact() {
        let sq = TrimCurve::Polyline(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        let (_, p) = sq.sample([0.1, 0.1], 1.0);
        assert_eq!(p.len(), 40);
        for c in [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]] {
            assert!(p.contains(&c));
        }
        assert!((sq.area() - 1.0).abs() < 1e-12);
        let e = TrimCurve::Ellipse {
            center: [0.0, 0.0],
            radii: [0.3, 0.1],
            angle: 0.4,
        };
        let (_, p) = e.sample([1.0, 1.0], 1e-4);
        assert!((signed_area(&p) - e.area()).abs() < 1e-6 * e.area());
    }

    #[test]
    fn jets_are_the_derivatives_of_the_points() {
        let curves = [
            TrimCurve::Ellipse {
                center: [0.4, 2.0],
                radii: [0.1, 0.3],
                angle: 0.7,
            },
            TrimCurve::BSpline {
                degree: 3,
                points: vec![[0.2, 1.0], [0.5, 0.6], [0.8, 1.0], [0.6, 1.8], [0.4, 1.8]],
            },
            TrimCurve::BSpline {
                degree: 4,
                points: vec![[0.2, 1.0], [0.5, 0.6], [0.8, 1.0], [0.6, 1.8], [0.4, 1.8]],
            },
            TrimCurve::Polyline(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
        ];
        // Central differences with h = 1e-4 err by h²/6 times the next derivative (≤ 1e3 here
        // in t-units): ≤ 2e-6, well inside the bounds below; a wrong factor n or 2π is not.
        let h = 1e-4;
        for c in &curves {
            for k in 0..37 {
                let t = 0.013 + k as f64 / 37.0;
                let j = c.jet(t);
                assert_eq!(j[0], c.point(t));
                let (a, b) = (c.point(t - h), c.point(t + h));
                let (ja, jb) = (c.jet(t - h), c.jet(t + h));
                for i in 0..2 {
                    let d1 = (b[i] - a[i]) / (2.0 * h);
                    let d2 = (jb[1][i] - ja[1][i]) / (2.0 * h);
                    let s = 1.0 + j[1][i].abs();
                    assert!(
                        (d1 - j[1][i]).abs() < 1e-4 * s,
                        "{c:?} t={t} {d1} {}",
                        j[1][i]
                    );
                    let s2 = 1.0 + j[2][i].abs();
                    assert!(
                        (d2 - j[2][i]).abs() < 1e-3 * s2,
                        "{c:?} t={t} {d2} {}",
                        j[2][i]
                    );
                }
            }
        }
        assert_eq!(curves[0].orientation(), 1.0);
        assert_eq!(curves[3].orientation(), 1.0);
        let cw = TrimCurve::Polyline(vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]]);
        assert_eq!(cw.orientation(), -1.0);
    }

    #[test]
    fn bad_curves_are_refused_with_their_place() {
        let e = TrimCurve::circle([0.5, 1.0], -0.1).validate().unwrap_err();
        assert_eq!(e.place(), "radius");
        let e = TrimCurve::BSpline {
            degree: 3,
            points: vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.place(), "degree");
        let e = TrimCurve::Polyline(vec![[0.0, 0.0], [f64::NAN, 0.0], [1.0, 1.0]])
            .validate()
            .unwrap_err();
        assert_eq!(e.place(), "points[1]");
    }
}
