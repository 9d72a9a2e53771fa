//! Jets of order 1 to 3 in the two domain coordinates `(x, y)`: a value with its gradient,
//! Hessian and third partials, carried through sums, products, quotients and compositions by
//! the chain rule. The transfinite interpolant and the correction basis are built from them, so
//! every partial the patch reports is exact up to rounding (no finite differences); the third
//! partials feed the energy of order 3 (`∫ |∇ L X|²`). The order is a compile-time parameter:
//! `Jet<O>` and `VJet<O>` carry the partials up to order `O` (`Jet` alone is `Jet<2>`); the
//! higher ones stay zero and cost nothing, so the evaluations that need only second partials
//! (surface partials, orders 1 and 2) pay nothing for the third, and those that need positions
//! and normals alone (rows of a tessellation, `Jet<1>`) nothing for the second.

use crate::Vec3;
use std::ops::{Add, Mul, Sub};

/// A scalar `f(x, y)` to third order: `v = f`, `d = (f_x, f_y)`, `h = (f_xx, f_xy, f_yy)`,
/// `t = (f_xxx, f_xxy, f_xyy, f_yyy)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Jet<const O: usize = 2> {
    pub(crate) v: f64,
    pub(crate) d: [f64; 2],
    pub(crate) h: [f64; 3],
    pub(crate) t: [f64; 4],
}

impl<const O: usize> Jet<O> {
    /// The constant `c`.
    #[inline(always)]
    pub(crate) fn constant(c: f64) -> Jet<O> {
        Jet {
            v: c,
            ..Jet::default()
        }
    }

    /// The affine function `c + g · (x, y)` evaluated where it equals `c`.
    #[inline(always)]
    pub(crate) fn affine(c: f64, g: [f64; 2]) -> Jet<O> {
        Jet {
            v: c,
            d: g,
            h: [0.0; 3],
            t: [0.0; 4],
        }
    }

    /// `f(self)` for a function of one variable given by `f`, `f'`, `f''`, `f'''` at `self.v`
    /// (Faà di Bruno: `(f∘g)_ijk = f''' g_i g_j g_k + f'' (g_ij g_k + g_ik g_j + g_jk g_i) +
    /// f' g_ijk`).
    #[inline(always)]
    pub(crate) fn compose(self, f: [f64; 4]) -> Jet<O> {
        let [f0, f1, f2, f3] = f;
        let [gx, gy] = self.d;
        let [gxx, gxy, gyy] = self.h;
        Jet {
            v: f0,
            d: [f1 * gx, f1 * gy],
            h: if O >= 2 {
                [
                    f2 * gx * gx + f1 * gxx,
                    f2 * gx * gy + f1 * gxy,
                    f2 * gy * gy + f1 * gyy,
                ]
            } else {
                [0.0; 3]
            },
            t: if O >= 3 {
                [
                    f3 * gx * gx * gx + 3.0 * f2 * gxx * gx + f1 * self.t[0],
                    f3 * gx * gx * gy + f2 * (gxx * gy + 2.0 * gxy * gx) + f1 * self.t[1],
                    f3 * gx * gy * gy + f2 * (gyy * gx + 2.0 * gxy * gy) + f1 * self.t[2],
                    f3 * gy * gy * gy + 3.0 * f2 * gyy * gy + f1 * self.t[3],
                ]
            } else {
                [0.0; 4]
            },
        }
    }

    /// `1 / self` (the caller keeps `self.v` away from zero).
    #[inline(always)]
    pub(crate) fn recip(self) -> Jet<O> {
        let r = 1.0 / self.v;
        let r2 = r * r;
        self.compose([r, -r2, 2.0 * r2 * r, -6.0 * r2 * r2])
    }

    /// `self / other`.
    #[inline(always)]
    pub(crate) fn div(self, other: Jet<O>) -> Jet<O> {
        self * other.recip()
    }

    /// `self` times the constant `c`.
    #[inline(always)]
    pub(crate) fn scale(self, c: f64) -> Jet<O> {
        Jet {
            v: self.v * c,
            d: [self.d[0] * c, self.d[1] * c],
            h: if O >= 2 {
                [self.h[0] * c, self.h[1] * c, self.h[2] * c]
            } else {
                [0.0; 3]
            },
            t: if O >= 3 {
                [self.t[0] * c, self.t[1] * c, self.t[2] * c, self.t[3] * c]
            } else {
                [0.0; 4]
            },
        }
    }
}

impl<const O: usize> Add for Jet<O> {
    type Output = Jet<O>;
    #[inline(always)]
    fn add(self, o: Jet<O>) -> Jet<O> {
        Jet {
            v: self.v + o.v,
            d: [self.d[0] + o.d[0], self.d[1] + o.d[1]],
            h: if O >= 2 {
                [self.h[0] + o.h[0], self.h[1] + o.h[1], self.h[2] + o.h[2]]
            } else {
                [0.0; 3]
            },
            t: if O >= 3 {
                [
                    self.t[0] + o.t[0],
                    self.t[1] + o.t[1],
                    self.t[2] + o.t[2],
                    self.t[3] + o.t[3],
                ]
            } else {
                self.t
            },
        }
    }
}

impl<const O: usize> Sub for Jet<O> {
    type Output = Jet<O>;
    #[inline(always)]
    fn sub(self, o: Jet<O>) -> Jet<O> {
        self + o.scale(-1.0)
    }
}

impl<const O: usize> Mul for Jet<O> {
    type Output = Jet<O>;
    #[inline(always)]
    fn mul(self, o: Jet<O>) -> Jet<O> {
        let (a, b) = (self, o);
        Jet {
            v: a.v * b.v,
            d: [a.v * b.d[0] + b.v * a.d[0], a.v * b.d[1] + b.v * a.d[1]],
            h: if O >= 2 {
                [
                    a.v * b.h[0] + 2.0 * a.d[0] * b.d[0] + b.v * a.h[0],
                    a.v * b.h[1] + a.d[0] * b.d[1] + a.d[1] * b.d[0] + b.v * a.h[1],
                    a.v * b.h[2] + 2.0 * a.d[1] * b.d[1] + b.v * a.h[2],
                ]
            } else {
                [0.0; 3]
            },
            // Leibniz: every split of the three derivatives between the factors.
            t: if O >= 3 {
                [
                    a.v * b.t[0] + 3.0 * (a.d[0] * b.h[0] + a.h[0] * b.d[0]) + a.t[0] * b.v,
                    a.v * b.t[1]
                        + 2.0 * (a.d[0] * b.h[1] + a.h[1] * b.d[0])
                        + a.d[1] * b.h[0]
                        + a.h[0] * b.d[1]
                        + a.t[1] * b.v,
                    a.v * b.t[2]
                        + 2.0 * (a.d[1] * b.h[1] + a.h[1] * b.d[1])
                        + a.d[0] * b.h[2]
                        + a.h[2] * b.d[0]
                        + a.t[2] * b.v,
                    a.v * b.t[3] + 3.0 * (a.d[1] * b.h[2] + a.h[2] * b.d[1]) + a.t[3] * b.v,
                ]
            } else {
                [0.0; 4]
            },
        }
    }
}

/// A point-valued `X(x, y)` to third order: `v = X`, `d = (X_x, X_y)`,
/// `h = (X_xx, X_xy, X_yy)`, `t = (X_xxx, X_xxy, X_xyy, X_yyy)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct VJet<const O: usize = 2> {
    pub(crate) v: Vec3,
    pub(crate) d: [Vec3; 2],
    pub(crate) h: [Vec3; 3],
    pub(crate) t: [Vec3; 4],
}

impl<const O: usize> Default for VJet<O> {
    #[inline(always)]
    fn default() -> Self {
        VJet {
            v: Vec3::zeros(),
            d: [Vec3::zeros(); 2],
            h: [Vec3::zeros(); 3],
            t: [Vec3::zeros(); 4],
        }
    }
}

impl<const O: usize> VJet<O> {
    /// `C(s(x, y))` for a curve given by `C`, `C'`, `C''`, `C'''` at `s.v` (the chain rule of
    /// [`Jet::compose`]).
    #[inline(always)]
    pub(crate) fn compose(s: Jet<O>, c: [Vec3; 4]) -> VJet<O> {
        let [gx, gy] = s.d;
        let [gxx, gxy, gyy] = s.h;
        VJet {
            v: c[0],
            d: [c[1] * gx, c[1] * gy],
            h: if O >= 2 {
                [
                    c[2] * (gx * gx) + c[1] * gxx,
                    c[2] * (gx * gy) + c[1] * gxy,
                    c[2] * (gy * gy) + c[1] * gyy,
                ]
            } else {
                [Vec3::zeros(); 3]
            },
            t: if O >= 3 {
                [
                    c[3] * (gx * gx * gx) + c[2] * (3.0 * gxx * gx) + c[1] * s.t[0],
                    c[3] * (gx * gx * gy) + c[2] * (gxx * gy + 2.0 * gxy * gx) + c[1] * s.t[1],
                    c[3] * (gx * gy * gy) + c[2] * (gyy * gx + 2.0 * gxy * gy) + c[1] * s.t[2],
                    c[3] * (gy * gy * gy) + c[2] * (3.0 * gyy * gy) + c[1] * s.t[3],
                ]
            } else {
                [Vec3::zeros(); 4]
            },
        }
    }

    /// `self · f` for a scalar jet `f` (Leibniz, as [`Jet`]'s product).
    #[inline(always)]
    pub(crate) fn times(&self, f: Jet<O>) -> VJet<O> {
        let a = self;
        VJet {
            v: a.v * f.v,
            d: [a.v * f.d[0] + a.d[0] * f.v, a.v * f.d[1] + a.d[1] * f.v],
            h: if O >= 2 {
                [
                    a.v * f.h[0] + a.d[0] * (2.0 * f.d[0]) + a.h[0] * f.v,
                    a.v * f.h[1] + a.d[0] * f.d[1] + a.d[1] * f.d[0] + a.h[1] * f.v,
                    a.v * f.h[2] + a.d[1] * (2.0 * f.d[1]) + a.h[2] * f.v,
                ]
            } else {
                [Vec3::zeros(); 3]
            },
            t: if O >= 3 {
                [
                    a.v * f.t[0] + (a.d[0] * f.h[0] + a.h[0] * f.d[0]) * 3.0 + a.t[0] * f.v,
                    a.v * f.t[1]
                        + (a.d[0] * f.h[1] + a.h[1] * f.d[0]) * 2.0
                        + a.d[1] * f.h[0]
                        + a.h[0] * f.d[1]
                        + a.t[1] * f.v,
                    a.v * f.t[2]
                        + (a.d[1] * f.h[1] + a.h[1] * f.d[1]) * 2.0
                        + a.d[0] * f.h[2]
                        + a.h[2] * f.d[0]
                        + a.t[2] * f.v,
                    a.v * f.t[3] + (a.d[1] * f.h[2] + a.h[2] * f.d[1]) * 3.0 + a.t[3] * f.v,
                ]
            } else {
                [Vec3::zeros(); 4]
            },
        }
    }
}

impl<const O: usize> Add for VJet<O> {
    type Output = VJet<O>;
    #[inline(always)]
    fn add(self, o: VJet<O>) -> VJet<O> {
        VJet {
            v: self.v + o.v,
            d: [self.d[0] + o.d[0], self.d[1] + o.d[1]],
            h: if O >= 2 {
                [self.h[0] + o.h[0], self.h[1] + o.h[1], self.h[2] + o.h[2]]
            } else {
                [Vec3::zeros(); 3]
            },
            t: if O >= 3 {
                [
                    self.t[0] + o.t[0],
                    self.t[1] + o.t[1],
                    self.t[2] + o.t[2],
                    self.t[3] + o.t[3],
                ]
            } else {
                self.t
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(x, y) = x² y / (1 + x) at (0.3, −0.7), against closed-form partials.
    #[test]
    fn products_and_quotients_follow_the_chain_rule() {
        let (x0, y0) = (0.3, -0.7);
        let x = Jet::<2>::affine(x0, [1.0, 0.0]);
        let y = Jet::affine(y0, [0.0, 1.0]);
        let f = (x * x * y).div(x + Jet::constant(1.0));
        let q = 1.0 + x0;
        let fx = y0 * (2.0 * x0 * q - x0 * x0) / (q * q);
        let fy = x0 * x0 / q;
        // d/dx of (x² + 2x)/(1 + x)² = 2/(1 + x)³.
        let fxx = y0 * 2.0 / (q * q * q);
        let fxy = (2.0 * x0 * q - x0 * x0) / (q * q);
        let want = [x0 * x0 * y0 / q, fx, fy, fxx, fxy, 0.0];
        let got = [f.v, f.d[0], f.d[1], f.h[0], f.h[1], f.h[2]];
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-14, "{got:?} vs {want:?}");
        }
    }

    /// The third partials of a product, a quotient and a composition against central
    /// differences of the (independently checked) Hessians.
    #[test]
    fn third_partials_are_the_derivatives_of_the_hessian() {
        let f = |x0: f64, y0: f64| {
            let x = Jet::<3>::affine(x0, [1.0, 0.0]);
            let y = Jet::<3>::affine(y0, [0.0, 1.0]);
            let q = (x * x * y).div(x + Jet::constant(1.0) + y * y);
            let e = (x * y).compose([(x0 * y0).exp(); 4]);
            // C(z) = (sin z, z³, e^z) with its three derivatives at z = q.
            let z = q.v;
            let c = [
                Vec3::new(z.sin(), z * z * z, z.exp()),
                Vec3::new(z.cos(), 3.0 * z * z, z.exp()),
                Vec3::new(-z.sin(), 6.0 * z, z.exp()),
                Vec3::new(-z.cos(), 6.0, z.exp()),
            ];
            let mut v = VJet::compose(q, c);
            v = v.times(e);
            (q * e, v)
        };
        let (x0, y0, h) = (0.3, -0.7, 1e-5);
        let (j, v) = f(x0, y0);
        let (jxp, vxp) = f(x0 + h, y0);
        let (jxm, vxm) = f(x0 - h, y0);
        let (jyp, vyp) = f(x0, y0 + h);
        let (jym, vym) = f(x0, y0 - h);
        let dx = |a: f64, b: f64| (a - b) / (2.0 * h);
        let want = [
            dx(jxp.h[0], jxm.h[0]),
            dx(jyp.h[0], jym.h[0]),
            dx(jxp.h[2], jxm.h[2]),
            dx(jyp.h[2], jym.h[2]),
        ];
        let also = [dx(jxp.h[1], jxm.h[1]), dx(jyp.h[1], jym.h[1])];
        for (k, (got, w)) in j.t.iter().zip(&want).enumerate() {
            assert!(
                (got - w).abs() < 1e-7 * (1.0 + w.abs()),
                "{k}: {j:?} vs {want:?}"
            );
        }
        assert!((j.t[1] - also[0]).abs() < 1e-7 * (1.0 + also[0].abs()));
        assert!((j.t[2] - also[1]).abs() < 1e-7 * (1.0 + also[1].abs()));
        let vw = [
            (vxp.h[0] - vxm.h[0]) / (2.0 * h),
            (vyp.h[0] - vym.h[0]) / (2.0 * h),
            (vxp.h[2] - vxm.h[2]) / (2.0 * h),
            (vyp.h[2] - vym.h[2]) / (2.0 * h),
        ];
        for (k, (got, want)) in v.t.iter().zip(&vw).enumerate() {
            assert!((got - want).norm() < 1e-7 * (1.0 + want.norm()), "{k}");
        }
    }
}
