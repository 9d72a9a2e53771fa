//! The tensor-product cubic spline through the grid nodes, stored in bicubic Hermite form: at every
//! node the value `X`, the slopes `X_u`, `X_v` and the twist `X_uv` of the spline. Along `u` the
//! spline has the not-a-knot end conditions; along `v` it is periodic (closed grids) or
//! not-a-knot. The interpolant is C² and reproduces cubics in each variable, so between the nodes
//! it adds an O(h⁴) interpolation error to the O(h²) error of the difference scheme.

use crate::curve::hermite::hermite_basis;
use crate::surface::Partials;
use crate::Vec3;

/// Slopes `s_i` of the cubic spline through `y_0 … y_n` on a uniform grid of step `h`, with the
/// not-a-knot conditions (third derivative continuous at `x_1` and `x_{n−1}`). Needs `n ≥ 3`.
///
/// Interior rows are the C² conditions `s_{i−1} + 4 s_i + s_{i+1} = 3 (y_{i+1} − y_{i−1}) / h`.
/// Continuity of `p'''` at `x_1` (on `[x_i, x_{i+1}]`, `p''' = 6 (s_i + s_{i+1} − 2Δ_i) / h²` with
/// `Δ_i = (y_{i+1} − y_i) / h`) gives `s_0 − s_2 = 2 (Δ_0 − Δ_1)`; adding the row of `x_1` makes
/// it tridiagonal: `s_0 + 2 s_1 = (5Δ_0 + Δ_1) / 2`, and symmetrically at the other end.
pub(crate) fn not_a_knot_slopes(y: &[Vec3], h: f64) -> Vec<Vec3> {
    let m = y.len();
    debug_assert!(m >= 4);
    let d: Vec<Vec3> = y.windows(2).map(|w| (w[1] - w[0]) / h).collect();
    // Tridiagonal rows (lower, diag, upper, rhs).
    let mut lo = vec![1.0; m];
    let mut di = vec![4.0; m];
    let mut up = vec![1.0; m];
    let mut r: Vec<Vec3> = (0..m)
        .map(|i| {
            if i == 0 || i == m - 1 {
                Vec3::zeros()
            } else {
                (d[i - 1] + d[i]) * 3.0
            }
        })
        .collect();
    (lo[0], di[0], up[0]) = (0.0, 1.0, 2.0);
    r[0] = (d[0] * 5.0 + d[1]) * 0.5;
    (lo[m - 1], di[m - 1], up[m - 1]) = (2.0, 1.0, 0.0);
    r[m - 1] = (d[m - 3] + d[m - 2] * 5.0) * 0.5;
    thomas(&lo, &mut di, &up, &mut r);
    r
}

/// Solves a tridiagonal system in place (no pivoting: the systems here are diagonally dominant
/// after the first elimination step).
fn thomas(lo: &[f64], di: &mut [f64], up: &[f64], r: &mut [Vec3]) {
    let m = di.len();
    for i in 1..m {
        let w = lo[i] / di[i - 1];
        di[i] -= w * up[i - 1];
        let prev = r[i - 1];
        r[i] -= prev * w;
    }
    r[m - 1] /= di[m - 1];
    for i in (0..m - 1).rev() {
        let next = r[i + 1];
        r[i] = (r[i] - next * up[i]) / di[i];
    }
}

/// Slopes of the periodic cubic spline through `y_0 … y_{m−1}` (`y_m = y_0`) of step `h`: the
/// circulant system `s_{i−1} + 4 s_i + s_{i+1} = 3 (y_{i+1} − y_{i−1}) / h`, solved by the
/// Sherman–Morrison formula around a tridiagonal solve.
pub(crate) fn periodic_slopes(y: &[Vec3], h: f64) -> Vec<Vec3> {
    let m = y.len();
    debug_assert!(m >= 3);
    let rhs: Vec<Vec3> = (0..m)
        .map(|i| (y[(i + 1) % m] - y[(i + m - 1) % m]) * (3.0 / h))
        .collect();
    // A = T + w zᵀ with w = (γ, 0, …, 0, 1)ᵀ, z = (1, 0, …, 0, 1/γ)ᵀ, γ = −4.
    let gamma = -4.0;
    let lo = vec![1.0; m];
    let up = vec![1.0; m];
    let mut di = vec![4.0; m];
    di[0] -= gamma;
    di[m - 1] -= 1.0 / gamma;
    let mut x = rhs;
    let mut di1 = di.clone();
    thomas(&lo, &mut di1, &up, &mut x);
    // Solve T q = w with a scalar right-hand side (use the x component of Vec3).
    let mut q: Vec<Vec3> = vec![Vec3::zeros(); m];
    q[0].x = gamma;
    q[m - 1].x = 1.0;
    thomas(&lo, &mut di, &up, &mut q);
    let zq = q[0].x + q[m - 1].x / gamma;
    let zx = x[0] + x[m - 1] / gamma;
    let f = zx / (1.0 + zq);
    for (xi, qi) in x.iter_mut().zip(&q) {
        *xi -= f * qi.x;
    }
    x
}

/// The bicubic spline through `(nu + 1) × mv` nodes on `[0, 1] × [v0, v0 + mv·hv)` (periodic) or
/// `[0, 1] × [v0, v0 + (mv − 1)·hv]`.
#[derive(Clone, Debug)]
pub(crate) struct NodeSpline {
    pub nu: usize,
    /// Nodes per row (columns).
    pub mv: usize,
    pub periodic: bool,
    pub hu: f64,
    pub v0: f64,
    pub hv: f64,
    /// Per node (row-major, `i * mv + j`): `[X, X_u, X_v, X_uv]`.
    pub data: Vec<[Vec3; 4]>,
}

impl NodeSpline {
    /// Fits the spline to the node values `x[i * mv + j]`.
    pub(super) fn new(
        x: Vec<Vec3>,
        nu: usize,
        mv: usize,
        periodic: bool,
        v0: f64,
        hv: f64,
    ) -> Self {
        let hu = 1.0 / nu as f64;
        let rows = nu + 1;
        let mut data = vec![[Vec3::zeros(); 4]; rows * mv];
        let vslopes = |y: &[Vec3]| {
            if periodic {
                periodic_slopes(y, hv)
            } else {
                not_a_knot_slopes(y, hv)
            }
        };
        let mut col = vec![Vec3::zeros(); rows];
        for j in 0..mv {
            for i in 0..rows {
                col[i] = x[i * mv + j];
            }
            let s = not_a_knot_slopes(&col, hu);
            for i in 0..rows {
                data[i * mv + j][0] = col[i];
                data[i * mv + j][1] = s[i];
            }
        }
        let mut row = vec![Vec3::zeros(); mv];
        for i in 0..rows {
            for k in [0, 1] {
                for j in 0..mv {
                    row[j] = data[i * mv + j][k];
                }
                let s = vslopes(&row);
                for j in 0..mv {
                    data[i * mv + j][2 + k] = s[j];
                }
            }
        }
        NodeSpline {
            nu,
            mv,
            periodic,
            hu,
            v0,
            hv,
            data,
        }
    }

    /// The spline and its partials up to second order at `(u, v)`.
    pub(super) fn partials(&self, u: f64, v: f64) -> Partials {
        let fu = (u.clamp(0.0, 1.0) / self.hu).max(0.0);
        let i = (fu.floor() as usize).min(self.nu - 1);
        let t = fu - i as f64;
        let cells_v = if self.periodic { self.mv } else { self.mv - 1 };
        let mut fv = (v - self.v0) / self.hv;
        if self.periodic {
            fv = fv.rem_euclid(self.mv as f64);
            if fv >= self.mv as f64 {
                fv = 0.0;
            }
        } else {
            fv = fv.clamp(0.0, cells_v as f64);
        }
        let j = (fv.floor() as usize).min(cells_v - 1);
        let s = fv - j as f64;
        let j1 = if self.periodic && j + 1 == self.mv {
            0
        } else {
            j + 1
        };
        let (hu, hv) = (self.hu, self.hv);
        let bu = hermite_basis(t);
        let bv = hermite_basis(s);
        // Node p of the cell (0: i, 1: i+1) in u and q in v.
        let node = |p: usize, q: usize| &self.data[(i + p) * self.mv + if q == 0 { j } else { j1 }];
        let mut out = [[Vec3::zeros(); 3]; 3];
        for (du, out_du) in out.iter_mut().enumerate() {
            for (dv, o) in out_du.iter_mut().enumerate() {
                if du + dv > 2 {
                    continue;
                }
                let mut acc = Vec3::zeros();
                for p in 0..2 {
                    for q in 0..2 {
                        let n = node(p, q);
                        let (wu0, wu1) = (bu[du][2 * p], bu[du][2 * p + 1] * hu);
                        let (wv0, wv1) = (bv[dv][2 * q], bv[dv][2 * q + 1] * hv);
                        acc += n[0] * (wu0 * wv0)
                            + n[1] * (wu1 * wv0)
                            + n[2] * (wu0 * wv1)
                            + n[3] * (wu1 * wv1);
                    }
                }
                *o = acc / (hu.powi(du as i32) * hv.powi(dv as i32));
            }
        }
        Partials {
            x: out[0][0],
            xu: out[1][0],
            xv: out[0][1],
            xuu: out[2][0],
            xuv: out[1][1],
            xvv: out[0][2],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(u: f64, v: f64) -> Vec3 {
        Vec3::new(
            u * u * u - 2.0 * u * v + v * v * v,
            (u * v).powi(2),
            1.0 - u + 3.0 * v,
        )
    }

    /// Bicubic polynomials are reproduced exactly (not-a-knot in both directions), with all
    /// partials.
    #[test]
    fn reproduces_bicubics() {
        let (nu, mv) = (5, 7);
        let hv = 0.3;
        let x: Vec<Vec3> = (0..=nu)
            .flat_map(|i| (0..mv).map(move |j| f(i as f64 / nu as f64, 0.2 + j as f64 * hv)))
            .collect();
        let s = NodeSpline::new(x, nu, mv, false, 0.2, hv);
        for &(u, v) in &[(0.13, 0.25), (0.5, 1.1), (0.99, 1.9), (0.0, 2.0)] {
            let p = s.partials(u, v);
            let e = 1e-6;
            let fd_u = (f(u + e, v) - f(u - e, v)) / (2.0 * e);
            let fd_v = (f(u, v + e) - f(u, v - e)) / (2.0 * e);
            assert!((p.x - f(u, v)).norm() < 1e-13, "{u} {v}");
            assert!((p.xu - fd_u).norm() < 1e-8);
            assert!((p.xv - fd_v).norm() < 1e-8);
            let exact_uv = Vec3::new(-2.0, 4.0 * u * v, 0.0);
            assert!((p.xuv - exact_uv).norm() < 1e-11);
            let exact_uu = Vec3::new(6.0 * u, 2.0 * v * v, 0.0);
            let exact_vv = Vec3::new(6.0 * v, 2.0 * u * u, 0.0);
            assert!((p.xuu - exact_uu).norm() < 1e-11);
            assert!((p.xvv - exact_vv).norm() < 1e-11);
        }
    }

    /// The periodic spline of a trigonometric polynomial converges at fourth order.
    #[test]
    fn periodic_spline_converges_at_fourth_order() {
        let err = |m: usize| {
            let h = crate::TAU / m as f64;
            let y: Vec<Vec3> = (0..m)
                .map(|j| {
                    let v = j as f64 * h;
                    Vec3::new(v.cos(), (2.0 * v).sin(), 1.0)
                })
                .collect();
            let s = periodic_slopes(&y, h);
            (0..m)
                .map(|j| {
                    let v = j as f64 * h;
                    (s[j] - Vec3::new(-v.sin(), 2.0 * (2.0 * v).cos(), 0.0)).norm()
                })
                .fold(0.0, f64::max)
        };
        let (e1, e2) = (err(32), err(64));
        let order = (e1 / e2).log2();
        assert!(order > 3.8, "order {order} ({e1:e}, {e2:e})");
    }
}
