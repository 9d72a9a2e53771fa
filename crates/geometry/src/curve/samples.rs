use super::{poly_jet, Curve, Domain};
use crate::check::finite_points;
use crate::{Error, Result, Vec3, TAU};

/// How closed point samples are spread over `[0, 2π)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SampleParam {
    /// Equal parameter steps.
    Uniform,
    /// Steps proportional to the chord lengths (default).
    #[default]
    Chord,
    /// Steps proportional to the square roots of the chord lengths.
    Centripetal,
}

/// Closed point samples interpolated by a periodic C² cubic spline.
///
/// The samples `P_0 … P_{N−1}` sit at parameters `0 = v_0 < v_1 < … < v_{N−1} < v_N = 2π`
/// (`P_N = P_0`) with steps `h_i = v_{i+1} − v_i` proportional to `1`, `|P_{i+1} − P_i|` or
/// `|P_{i+1} − P_i|^{1/2}` ([`SampleParam`]). The second derivatives `M_i` solve the cyclic
/// tridiagonal system `h_{i−1} M_{i−1} + 2(h_{i−1} + h_i) M_i + h_i M_{i+1} = 6[(P_{i+1} − P_i)/h_i −
/// (P_i − P_{i−1})/h_{i−1}]` (Sherman–Morrison on top of the Thomas algorithm), and on
/// `[v_i, v_{i+1}]`, with `x = v − v_i`:
/// `S(v) = P_i + [(P_{i+1} − P_i)/h_i − h_i (2M_i + M_{i+1})/6] x + M_i x²/2 + (M_{i+1} − M_i) x³/(6h_i)`.
#[derive(Clone, Debug)]
pub struct PointSamples {
    /// The samples (after dropping a repeated closing point).
    pub points: Vec<Vec3>,
    /// Their parameters `v_0 = 0 < … < v_{N−1}`, plus `v_N = 2π`.
    pub params: Vec<f64>,
    /// Power-form coefficients of each segment in `x = v − v_i`.
    segments: Vec<[Vec3; 4]>,
}

impl PointSamples {
    /// At least 3 finite points; consecutive points (and last/first) must differ.
    ///
    /// The sequence is closed implicitly: the last point must not repeat the first. If it does
    /// (within `10⁻¹²` of the size of the point set), it is dropped. Two consecutive points closer
    /// than that are an error naming both (`points[4]: equals points[3]`). Errors are placed as
    /// in a `samples` table of the design file: `points[i][c]`, `points[i]`, `points`.
    pub fn closed(points: Vec<Vec3>, param: SampleParam) -> Result<Self> {
        finite_points(&points, "points")?;
        if points.len() < 3 {
            return Err(
                Error::invalid(format!("needs at least 3 points (got {})", points.len()))
                    .at("points"),
            );
        }
        let scale = points.iter().map(|p| p.amax()).fold(0.0, f64::max);
        let tol = 1e-12 * scale.max(f64::MIN_POSITIVE);
        for i in 1..points.len() {
            if (points[i] - points[i - 1]).norm() <= tol {
                return Err(
                    Error::invalid(format!("equals points[{}]", i - 1)).at(&format!("points[{i}]"))
                );
            }
        }
        let mut points = points;
        if points.len() > 1 && (points[points.len() - 1] - points[0]).norm() <= tol {
            points.pop();
        }
        let n = points.len();
        if n < 3 {
            return Err(Error::invalid(format!(
                "a closed curve needs at least 3 distinct points (got {n})"
            ))
            .at("points"));
        }
        let steps: Vec<f64> = (0..n)
            .map(|i| {
                let chord = (points[(i + 1) % n] - points[i]).norm();
                match param {
                    SampleParam::Uniform => 1.0,
                    SampleParam::Chord => chord,
                    SampleParam::Centripetal => chord.sqrt(),
                }
            })
            .collect();
        let total: f64 = steps.iter().sum();
        let mut params = Vec::with_capacity(n + 1);
        let mut acc = 0.0;
        for s in &steps {
            params.push(TAU * acc / total);
            acc += s;
        }
        params.push(TAU);
        let h: Vec<f64> = (0..n).map(|i| params[i + 1] - params[i]).collect();
        if h.iter().any(|&x| x <= 0.0 || !x.is_finite()) {
            return Err(
                Error::invalid("the parameter steps underflow (chords too uneven)").at("points"),
            );
        }
        // Cyclic tridiagonal system for M.
        let sub: Vec<f64> = (0..n).map(|i| h[(i + n - 1) % n]).collect();
        let diag: Vec<f64> = (0..n).map(|i| 2.0 * (h[(i + n - 1) % n] + h[i])).collect();
        let sup: Vec<f64> = h.clone();
        let rhs: Vec<Vec3> = (0..n)
            .map(|i| {
                let ip = (i + 1) % n;
                let im = (i + n - 1) % n;
                ((points[ip] - points[i]) / h[i] - (points[i] - points[im]) / h[im]) * 6.0
            })
            .collect();
        let m = solve_cyclic(&sub, &diag, &sup, &rhs);
        let segments = (0..n)
            .map(|i| {
                let ip = (i + 1) % n;
                let hi = h[i];
                [
                    points[i],
                    (points[ip] - points[i]) / hi - (m[i] * 2.0 + m[ip]) * (hi / 6.0),
                    m[i] * 0.5,
                    (m[ip] - m[i]) / (6.0 * hi),
                ]
            })
            .collect();
        Ok(PointSamples {
            points,
            params,
            segments,
        })
    }
}

/// Solves the cyclic tridiagonal system `a_i x_{i−1} + b_i x_i + c_i x_{i+1} = r_i` (indices
/// modulo n, n ≥ 3) by Sherman–Morrison: the corners `a_0` and `c_{n−1}` become a rank-one update
/// of a tridiagonal matrix solved by the Thomas algorithm.
fn solve_cyclic(a: &[f64], b: &[f64], c: &[f64], r: &[Vec3]) -> Vec<Vec3> {
    let n = b.len();
    let beta = a[0]; // A[0][n−1]
    let alpha = c[n - 1]; // A[n−1][0]
    let gamma = -b[0];
    let mut bb = b.to_vec();
    bb[0] -= gamma;
    bb[n - 1] -= alpha * beta / gamma;
    let x = thomas(a, &bb, c, r);
    let mut u = vec![Vec3::zeros(); n];
    u[0] = Vec3::repeat(gamma);
    u[n - 1] = Vec3::repeat(alpha);
    let z = thomas(a, &bb, c, &u);
    // v = (1, 0, …, 0, β/γ); x − z (v·x)/(1 + v·z), componentwise.
    let vx = x[0] + x[n - 1] * (beta / gamma);
    let vz = z[0] + z[n - 1] * (beta / gamma);
    let fac = vx.component_div(&(Vec3::repeat(1.0) + vz));
    x.iter()
        .zip(&z)
        .map(|(xi, zi)| xi - zi.component_mul(&fac))
        .collect()
}

/// Thomas algorithm for a tridiagonal system (the corner entries `a_0`, `c_{n−1}` are ignored).
fn thomas(a: &[f64], b: &[f64], c: &[f64], r: &[Vec3]) -> Vec<Vec3> {
    let n = b.len();
    let mut cp = vec![0.0; n];
    let mut dp = vec![Vec3::zeros(); n];
    cp[0] = c[0] / b[0];
    dp[0] = r[0] / b[0];
    for i in 1..n {
        let den = b[i] - a[i] * cp[i - 1];
        cp[i] = c[i] / den;
        dp[i] = (r[i] - dp[i - 1] * a[i]) / den;
    }
    let mut x = vec![Vec3::zeros(); n];
    x[n - 1] = dp[n - 1];
    for i in (0..n - 1).rev() {
        x[i] = dp[i] - x[i + 1] * cp[i];
    }
    x
}

impl Curve for PointSamples {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let v = super::reduce_periodic(t);
        let n = self.segments.len();
        // Last i with params[i] ≤ v.
        let i = self.params[..n]
            .partition_point(|&p| p <= v)
            .saturating_sub(1);
        poly_jet(&self.segments[i], v - self.params[i], out);
    }
    /// The knots `v_0 = 0, …, v_{N−1}`: the spline is C² there, its third derivative jumps.
    fn breaks(&self) -> Vec<f64> {
        self.params[..self.segments.len()].to_vec()
    }
    fn continuity(&self) -> usize {
        2
    }
    /// One cubic per segment: Taylor's formula about the middle of each piece of `(t0, t1)`
    /// ([`super::polynomial_piece_bounds`]).
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        let pieces = super::pieces(&self.breaks(), true, t0, t1);
        super::polynomial_piece_bounds(self, 3, &pieces, out)
    }
}

#[cfg(test)]
mod tests {
    use super::super::testutil::{assert_close, check_fd, jet};
    use super::*;

    fn star(n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let a = TAU * i as f64 / n as f64;
                let r = if i % 2 == 0 { 2.0 } else { 1.2 };
                Vec3::new(r * a.cos(), r * a.sin(), 0.3 * (3.0 * a).sin())
            })
            .collect()
    }

    #[test]
    fn interpolates_and_is_c2() {
        for param in [
            SampleParam::Uniform,
            SampleParam::Chord,
            SampleParam::Centripetal,
        ] {
            let pts = star(7);
            let s = PointSamples::closed(pts.clone(), param).unwrap();
            assert_eq!(s.params.len(), 8);
            for (i, p) in pts.iter().enumerate() {
                // At a knot x = 0, so the value is the sample itself, bit for bit.
                assert_close(&s.point(s.params[i]), p, 0.0, "interpolation");
                // One-sided jets at the knot v_i: from segment i−1 (at x = h) and segment i.
                let im = (i + 6) % 7;
                let mut left = [Vec3::zeros(); 4];
                poly_jet(&s.segments[im], s.params[im + 1] - s.params[im], &mut left);
                let right = jet(&s, s.params[i]);
                for d in 0..3 {
                    let scale = right[d].norm().max(1.0);
                    assert_close(&left[d], &right[d], 1e-13 * scale, "C2 at knot");
                }
                // The third derivative jumps in general.
            }
            // Chord parameter: steps proportional to chords.
            if param == SampleParam::Chord {
                let c0 = (pts[1] - pts[0]).norm();
                let c1 = (pts[2] - pts[1]).norm();
                let r = (s.params[1] - s.params[0]) / (s.params[2] - s.params[1]);
                assert!((r - c0 / c1).abs() < 1e-14);
            }
            let mid: Vec<f64> = (0..7)
                .map(|i| 0.5 * (s.params[i] + s.params[i + 1]))
                .collect();
            check_fd(&s, &mid, 1e-5, 5, 3.0);
            // Periodic.
            assert_close(&s.point(-0.5), &s.point(TAU - 0.5), 1e-14, "periodic");
        }
    }

    #[test]
    fn reproduces_a_smooth_curve_closely() {
        // Uniform samples of a circle: the periodic spline converges at O(h⁴).
        let err = |n: usize| {
            let pts: Vec<Vec3> = (0..n)
                .map(|i| {
                    let a = TAU * i as f64 / n as f64;
                    Vec3::new(a.cos(), a.sin(), 0.0)
                })
                .collect();
            let s = PointSamples::closed(pts, SampleParam::Uniform).unwrap();
            (0..200)
                .map(|k| {
                    let v = TAU * (k as f64 + 0.5) / 200.0;
                    (s.point(v) - Vec3::new(v.cos(), v.sin(), 0.0)).norm()
                })
                .fold(0.0, f64::max)
        };
        let (e1, e2) = (err(16), err(32));
        let order = (e1 / e2).log2();
        assert!(order > 3.8 && order < 4.2, "order {order}: {e1:e} {e2:e}");
    }

    #[test]
    fn closing_point_is_dropped_and_errors_name_points() {
        let mut pts = star(5);
        pts.push(pts[0]);
        let s = PointSamples::closed(pts, SampleParam::Chord).unwrap();
        assert_eq!(s.points.len(), 5);
        let mut pts = star(6);
        pts[4] = pts[3];
        let e = PointSamples::closed(pts, SampleParam::Chord)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "points[4]: equals points[3]");
        let pts = vec![Vec3::x(), Vec3::y(), Vec3::x()];
        assert!(PointSamples::closed(pts, SampleParam::Uniform).is_err());
        assert!(PointSamples::closed(vec![Vec3::x(), Vec3::y()], SampleParam::Uniform).is_err());
        assert!(PointSamples::closed(vec![], SampleParam::Uniform).is_err());
        let mut pts = star(5);
        pts[2].z = f64::NAN;
        let e = PointSamples::closed(pts, SampleParam::Chord)
            .unwrap_err()
            .to_string();
        assert!(e.contains("points[2]"), "{e}");
        let mut pts = star(5);
        pts[1].x = f64::NEG_INFINITY;
        assert!(PointSamples::closed(pts, SampleParam::Centripetal).is_err());
    }

    #[test]
    fn refusals_are_placed_and_worded_as_in_the_design_file() {
        let err = |p: Vec<Vec3>| {
            PointSamples::closed(p, SampleParam::Chord)
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            err(vec![Vec3::x(), Vec3::y()]),
            "points: needs at least 3 points (got 2)"
        );
        assert_eq!(
            err(vec![Vec3::x(), Vec3::new(0.0, f64::NAN, 0.0)]),
            "points[1][1]: must be finite (got NaN)"
        );
        assert_eq!(
            err(vec![Vec3::x(), Vec3::y(), Vec3::x()]),
            "points: a closed curve needs at least 3 distinct points (got 2)"
        );
        let mut pts = star(4);
        pts[2] = pts[1];
        assert_eq!(err(pts), "points[2]: equals points[1]");
    }
}

#[cfg(test)]
mod bound_tests {
    use super::super::testutil::check_bounds;
    use super::*;

    /// The Taylor bounds of the cubic pieces hold; the third derivative is constant on a piece,
    /// so its bound is attained (ratio 1); the fourth is zero.
    #[test]
    fn bounds_hold_and_are_tight() {
        let pts: Vec<Vec3> = (0..11)
            .map(|i| {
                let t = TAU * i as f64 / 11.0;
                Vec3::new(
                    t.cos() * (1.0 + 0.2 * (3.0 * t).sin()),
                    t.sin(),
                    0.1 * t.sin(),
                )
            })
            .collect();
        for param in [
            SampleParam::Uniform,
            SampleParam::Chord,
            SampleParam::Centripetal,
        ] {
            let s = PointSamples::closed(pts.clone(), param).unwrap();
            let r = check_bounds(&s, 4, 60, 2.0);
            eprintln!("samples {param:?}: {r:?}");
            assert!(r[3] <= 1.0 + 1e-6, "{r:?}");
            assert!(r[..3].iter().all(|&x| x <= 3.0), "{r:?}");
            assert_eq!(r[4], 0.0);
            assert_eq!(s.breaks().len(), 11);
        }
    }
}
