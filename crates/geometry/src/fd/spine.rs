//! The spine of a finite-difference surface: the mean of its interpolant over `v`.

use super::FdSurface;
use crate::surface::Spine;
use crate::Vec3;

/// The cubic Hermite basis on `[0, 1]` (value at 0, slope at 0, value at 1, slope at 1) and its
/// `order`-th derivative in `t`.
fn hermite(t: f64, order: usize) -> [f64; 4] {
    let (t2, t3) = (t * t, t * t * t);
    match order {
        0 => [
            2.0 * t3 - 3.0 * t2 + 1.0,
            t3 - 2.0 * t2 + t,
            -2.0 * t3 + 3.0 * t2,
            t3 - t2,
        ],
        1 => [
            6.0 * t2 - 6.0 * t,
            3.0 * t2 - 4.0 * t + 1.0,
            -6.0 * t2 + 6.0 * t,
            3.0 * t2 - 2.0 * t,
        ],
        2 => [
            12.0 * t - 6.0,
            6.0 * t - 4.0,
            -12.0 * t + 6.0,
            6.0 * t - 2.0,
        ],
        3 => [12.0, 6.0, -12.0, 6.0],
        _ => [0.0; 4],
    }
}

impl FdSurface {
    /// The means over `v` of node row `i`'s values and `u`-slopes: the exact means of the
    /// row's cubic splines in `v`. On a periodic grid a Hermite cubic integrates to
    /// `h Σ y_j` over the period (the slope terms `h²(s_j − s_{j+1})/12` telescope away), so the
    /// mean is the mean of the node values; on an open grid the end slopes leave
    /// `h²(s_0 − s_n)/12` beside the trapezoidal sum.
    fn row_means(&self, i: usize) -> [Vec3; 2] {
        let s = &self.spline;
        let row = &s.data[i * s.mv..(i + 1) * s.mv];
        let mut out = [Vec3::zeros(); 2];
        for (k, o) in out.iter_mut().enumerate() {
            if s.periodic {
                *o = row.iter().map(|n| n[k]).sum::<Vec3>() / s.mv as f64;
            } else {
                let n = s.mv - 1;
                let inner: Vec3 = row[1..n].iter().map(|d| d[k]).sum();
                let trapezoid = (inner + (row[0][k] + row[n][k]) * 0.5) * s.hv;
                let ends = (row[0][2 + k] - row[n][2 + k]) * (s.hv * s.hv / 12.0);
                *o = (trapezoid + ends) / (n as f64 * s.hv);
            }
        }
        out
    }
}

/// `A₀(u)`: the mean over the `v` domain of the bicubic interpolant `X(u, v)` and its
/// u-derivatives, exactly (the interpolant is linear in its node data, so the mean is the cubic
/// Hermite spline in `u` through the row means of the node values and `u`-slopes). On a grid
/// periodic in `v` this is the discrete analogue of the Bloor–Wilson `A₀(u)`: the mean of every
/// grid row, joined by the same not-a-knot spline in `u` as the surface. `u` is clamped to
/// `[0, 1]` as in [`crate::surface::Surface::partials`]; derivatives above the third vanish.
impl Spine for FdSurface {
    fn spine(&self, u: f64, order: usize) -> Vec3 {
        let s = &self.spline;
        let fu = (u.clamp(0.0, 1.0) / s.hu).max(0.0);
        let i = (fu.floor() as usize).min(s.nu - 1);
        let t = fu - i as f64;
        let b = hermite(t, order);
        let [y0, s0] = self.row_means(i);
        let [y1, s1] = self.row_means(i + 1);
        let x = y0 * b[0] + s0 * (b[1] * s.hu) + y1 * b[2] + s1 * (b[3] * s.hu);
        x / s.hu.powi(order as i32)
    }
}
