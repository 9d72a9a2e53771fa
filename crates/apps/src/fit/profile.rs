//! Open profiles (sections of an open sheet, book §4.6) as periodic curves.
//!
//! The PDE patches of pdeshape take periodic boundary curves. An open profile `c(t)`,
//! `t ∈ [0, 1]`, is closed by an even reflection: the curve
//!
//! ```text
//! C(v) = c((1 − cos v) / 2),   v ∈ [0, 2π)
//! ```
//!
//! runs along the profile for `0 ≤ v ≤ π` and back over it for `π ≤ v ≤ 2π`. It is a function
//! of `cos v`, so its Fourier series has cosine terms only (the `sin` list of the design's
//! Fourier curve is empty), and it is as smooth as `c` itself: the series is the Chebyshev
//! series of `c` and converges as fast. (Reflecting `c` at uniform speed instead, `t = v/π`,
//! would put a corner in `C` at both ends wherever the profile's end tangent is not zero, and
//! the coefficients would fall only as `1/n²`.) A biharmonic patch between such curves is even
//! in `v` mode by mode, `X(u, 2π − v) = X(u, v)`: it covers the sheet once for `0 ≤ v ≤ π` and
//! again, over the same points, for `π ≤ v ≤ 2π`.
//!
//! The profile itself is, as in the book, the cubic spline (natural, C²) through the section's
//! points, sampled at the `S` equally spaced `v_k = 2πk/S`. Its parameter `t` is the
//! cumulative length along the profile of the projections on the frame's `e₁` (the direction
//! across the sheet), plus a twentieth of the length itself so that it always increases:
//! on a sheet that is a graph over its plane, equal `t` on neighbouring profiles are nearly
//! the same place across the sheet, so the patches between them do not shear. `v = 0` is the
//! end with the smaller `e₁` coordinate on every profile.

use super::frame::FileFrame;
use super::section::{AxisFrame, Section};
use crate::{Error, Result, Vec3, TAU};

/// Share of a step's own length added to its projection on `e₁` in the profile's parameter.
const LENGTH_SHARE: f64 = 0.05;

/// The section of an open sheet at height `h` given by the polyline `line` (in the plane), as
/// the even periodic curve of the module documentation sampled at `samples` angles.
pub(super) fn from_polyline(
    line: &[Vec3],
    frame: &AxisFrame,
    h: f64,
    samples: usize,
    file: FileFrame,
) -> Result<Section> {
    closed_evenly(line, (frame, h, file), samples, Interpolant::Spline)
}

/// An end of a sheet: the arc of the mesh's boundary beyond the last plane, as
/// [`from_polyline`] but interpolated linearly. The boundary is itself a polyline and turns
/// sharply where it passes from the sides (along the axis, where the parameter hardly grows)
/// to the end (across it); a spline through such a corner overshoots by about the jump in
/// speed times the next step (measured: a tenth of the sheet's width on a rectangular sheet).
pub(super) fn from_edge_arc(
    line: &[Vec3],
    frame: &AxisFrame,
    h: f64,
    samples: usize,
    file: FileFrame,
) -> Result<Section> {
    closed_evenly(line, (frame, h, file), samples, Interpolant::Linear)
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Interpolant {
    Spline,
    Linear,
}

/// [`from_polyline`] and [`from_edge_arc`]; `at` is the plane: its frame, its height and the
/// frame messages name it in.
fn closed_evenly(
    line: &[Vec3],
    at: (&AxisFrame, f64, FileFrame),
    samples: usize,
    how: Interpolant,
) -> Result<Section> {
    let (frame, h, file) = at;
    // Points closer than a millionth of the profile's length to the previous one are merged:
    // a spline needs distinct parameters.
    let total: f64 = line.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    if !(total.is_finite() && total > 0.0) || line.len() < 2 {
        return Err(Error::invalid(format!(
            "the section {} is a degenerate profile of {} points",
            frame.plane(h, file),
            line.len()
        )));
    }
    let mut pts: Vec<Vec3> = Vec::with_capacity(line.len());
    for p in line {
        match pts.last() {
            Some(q) if (p - q).norm() <= 1e-6 * total => {}
            _ => pts.push(*p),
        }
    }
    if pts.len() < 2 {
        return Err(Error::invalid(format!(
            "the section {} is a degenerate profile",
            frame.plane(h, file)
        )));
    }
    if pts[0].dot(&frame.e1) > pts[pts.len() - 1].dot(&frame.e1) {
        pts.reverse();
    }
    let mut t = vec![0.0];
    for w in pts.windows(2) {
        let d = w[1] - w[0];
        let step = d.dot(&frame.e1).abs() + LENGTH_SHARE * d.norm();
        t.push(t[t.len() - 1] + step);
    }
    let end = t[t.len() - 1];
    for x in t.iter_mut() {
        *x /= end;
    }
    let spline = match how {
        Interpolant::Spline => NaturalSpline::new(&t, &pts),
        Interpolant::Linear => NaturalSpline::linear(&t, &pts),
    };
    let points: Vec<Vec3> = (0..samples)
        .map(|k| spline.at(0.5 * (1.0 - (TAU * k as f64 / samples as f64).cos())))
        .collect();
    let centroid = pts.iter().sum::<Vec3>() / pts.len() as f64;
    Ok(Section {
        height: h,
        centroid,
        points,
    })
}

/// The natural cubic spline through `(tᵢ, pᵢ)`, `t` increasing.
struct NaturalSpline {
    t: Vec<f64>,
    p: Vec<Vec3>,
    /// Second derivatives at the knots.
    m: Vec<Vec3>,
}

impl NaturalSpline {
    fn new(t: &[f64], p: &[Vec3]) -> Self {
        let n = t.len();
        let mut m = vec![Vec3::zeros(); n];
        if n > 2 {
            // Tridiagonal system for the interior second derivatives (Thomas algorithm):
            // hᵢ₋₁ mᵢ₋₁ + 2(hᵢ₋₁ + hᵢ) mᵢ + hᵢ mᵢ₊₁ = 6 (Δᵢ − Δᵢ₋₁), m₀ = mₙ₋₁ = 0.
            let h: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
            let slope: Vec<Vec3> = (0..n - 1).map(|i| (p[i + 1] - p[i]) / h[i]).collect();
            let mut diag = vec![0.0; n];
            let mut rhs = vec![Vec3::zeros(); n];
            for i in 1..n - 1 {
                diag[i] = 2.0 * (h[i - 1] + h[i]);
                rhs[i] = (slope[i] - slope[i - 1]) * 6.0;
            }
            for i in 2..n - 1 {
                let w = h[i - 1] / diag[i - 1];
                diag[i] -= w * h[i - 1];
                let r = rhs[i - 1] * w;
                rhs[i] -= r;
            }
            for i in (1..n - 1).rev() {
                let next = if i + 1 < n - 1 {
                    m[i + 1] * h[i]
                } else {
                    Vec3::zeros()
                };
                m[i] = (rhs[i] - next) / diag[i];
            }
        }
        NaturalSpline {
            t: t.to_vec(),
            p: p.to_vec(),
            m,
        }
    }

    /// The polyline through the points (second derivatives zero everywhere).
    fn linear(t: &[f64], p: &[Vec3]) -> Self {
        NaturalSpline {
            t: t.to_vec(),
            p: p.to_vec(),
            m: vec![Vec3::zeros(); t.len()],
        }
    }

    fn at(&self, x: f64) -> Vec3 {
        let n = self.t.len();
        let i = match self.t.partition_point(|&s| s <= x) {
            0 => 0,
            k => (k - 1).min(n - 2),
        };
        let h = self.t[i + 1] - self.t[i];
        let a = (self.t[i + 1] - x) / h;
        let b = (x - self.t[i]) / h;
        self.p[i] * a
            + self.p[i + 1] * b
            + (self.m[i] * (a * a * a - a) + self.m[i + 1] * (b * b * b - b)) * (h * h / 6.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::section::fourier;

    fn frame() -> AxisFrame {
        AxisFrame {
            origin: Vec3::zeros(),
            e1: Vec3::x(),
            e2: Vec3::z(),
            axis: -Vec3::y(),
        }
    }

    /// The spline reproduces a cubic exactly where its natural end conditions hold (a straight
    /// line), and follows a smooth curve to O(h⁴) inside.
    #[test]
    fn spline_interpolates() {
        let t: Vec<f64> = (0..=20).map(|i| (i as f64 / 20.0).powf(1.3)).collect();
        let line: Vec<Vec3> = t
            .iter()
            .map(|&x| Vec3::new(x, 2.0 * x - 1.0, 0.5))
            .collect();
        let s = NaturalSpline::new(&t, &line);
        for k in 0..=100 {
            let x = k as f64 / 100.0;
            assert!((s.at(x) - Vec3::new(x, 2.0 * x - 1.0, 0.5)).norm() < 1e-13);
        }
        let curve: Vec<Vec3> = t
            .iter()
            .map(|&x| Vec3::new(x, (3.0 * x).sin(), 0.0))
            .collect();
        let s = NaturalSpline::new(&t, &curve);
        // Away from the ends (where the natural condition differs from the curve's), the
        // error is below h⁴·max|f⁗|·5/384 ≈ 0.07⁴ · 81 · 0.013 ≈ 2.5e-5.
        for k in 30..=70 {
            let x = k as f64 / 100.0;
            assert!((s.at(x).y - (3.0 * x).sin()).abs() < 5e-5, "{x}");
        }
    }

    /// An open profile becomes an even curve: cosine terms only, the profile's ends at v = 0
    /// and v = π, and its Fourier series converges fast (Chebyshev).
    #[test]
    fn a_profile_closes_evenly() {
        // The graph of z = sin(2x) over x ∈ [−1, 1] in the plane y = 0, listed right to left.
        let line: Vec<Vec3> = (0..=200)
            .rev()
            .map(|i| {
                let x = -1.0 + 2.0 * i as f64 / 200.0;
                Vec3::new(x, 0.0, (2.0 * x).sin())
            })
            .collect();
        let s = from_polyline(&line, &frame(), 0.0, 128, FileFrame::default()).unwrap();
        assert!((s.points[0] - line[200]).norm() < 1e-12);
        assert!((s.points[64] - line[0]).norm() < 1e-12);
        for k in 1..64 {
            assert!((s.points[k] - s.points[128 - k]).norm() < 1e-12);
        }
        let (_, cos, sin) = fourier(&s.points, 63);
        assert!(sin.iter().all(|b| b.norm() < 1e-12));
        // The parameter is x here (a graph over e₁, up to the length share), so the curve is
        // nearly (−cos v, 0, sin(−2 cos v)): coefficients fall like Bessel functions.
        assert!(cos[20].norm() < 1e-6, "{:?}", cos[20]);
    }
}
