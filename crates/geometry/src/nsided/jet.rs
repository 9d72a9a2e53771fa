//! Second-order jets in the two domain coordinates `(x, y)`: a value with its gradient and
//! Hessian, carried through sums, products, quotients and compositions by the chain rule. The
//! transfinite interpolant and the correction basis are built from them, so every partial the
//! patch reports is exact up to rounding (no finite differences).

use crate::Vec3;
use std::ops::{Add, Mul, Sub};

/// A scalar `f(x, y)` to second order: `v = f`, `d = (f_x, f_y)`, `h = (f_xx, f_xy, f_yy)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Jet {
    pub(crate) v: f64,
    pub(crate) d: [f64; 2],
    pub(crate) h: [f64; 3],
}

impl Jet {
    /// The constant `c`.
    pub(crate) fn constant(c: f64) -> Jet {
        Jet {
            v: c,
            ..Jet::default()
        }
    }

    /// The affine function `c + g · (x, y)` evaluated where it equals `c`.
    pub(crate) fn affine(c: f64, g: [f64; 2]) -> Jet {
        Jet {
            v: c,
            d: g,
            h: [0.0; 3],
        }
    }

    /// `f(self)` for a function of one variable given by `f`, `f'`, `f''` at `self.v`.
    pub(crate) fn compose(self, f0: f64, f1: f64, f2: f64) -> Jet {
        let [gx, gy] = self.d;
        Jet {
            v: f0,
            d: [f1 * gx, f1 * gy],
            h: [
                f2 * gx * gx + f1 * self.h[0],
                f2 * gx * gy + f1 * self.h[1],
                f2 * gy * gy + f1 * self.h[2],
            ],
        }
    }

    /// `1 / self` (the caller keeps `self.v` away from zero).
    pub(crate) fn recip(self) -> Jet {
        let r = 1.0 / self.v;
        self.compose(r, -r * r, 2.0 * r * r * r)
    }

    /// `self / other`.
    pub(crate) fn div(self, other: Jet) -> Jet {
        self * other.recip()
    }

    /// `self` times the constant `c`.
    pub(crate) fn scale(self, c: f64) -> Jet {
        Jet {
            v: self.v * c,
            d: [self.d[0] * c, self.d[1] * c],
            h: [self.h[0] * c, self.h[1] * c, self.h[2] * c],
        }
    }
}

impl Add for Jet {
    type Output = Jet;
    fn add(self, o: Jet) -> Jet {
        Jet {
            v: self.v + o.v,
            d: [self.d[0] + o.d[0], self.d[1] + o.d[1]],
            h: [self.h[0] + o.h[0], self.h[1] + o.h[1], self.h[2] + o.h[2]],
        }
    }
}

impl Sub for Jet {
    type Output = Jet;
    fn sub(self, o: Jet) -> Jet {
        self + o.scale(-1.0)
    }
}

impl Mul for Jet {
    type Output = Jet;
    fn mul(self, o: Jet) -> Jet {
        let (a, b) = (self, o);
        Jet {
            v: a.v * b.v,
            d: [a.v * b.d[0] + b.v * a.d[0], a.v * b.d[1] + b.v * a.d[1]],
            h: [
                a.v * b.h[0] + 2.0 * a.d[0] * b.d[0] + b.v * a.h[0],
                a.v * b.h[1] + a.d[0] * b.d[1] + a.d[1] * b.d[0] + b.v * a.h[1],
                a.v * b.h[2] + 2.0 * a.d[1] * b.d[1] + b.v * a.h[2],
            ],
        }
    }
}

/// A point-valued `X(x, y)` to second order: `v = X`, `d = (X_x, X_y)`,
/// `h = (X_xx, X_xy, X_yy)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct VJet {
    pub(crate) v: Vec3,
    pub(crate) d: [Vec3; 2],
    pub(crate) h: [Vec3; 3],
}

impl Default for VJet {
    fn default() -> Self {
        VJet {
            v: Vec3::zeros(),
            d: [Vec3::zeros(); 2],
            h: [Vec3::zeros(); 3],
        }
    }
}

impl VJet {
    /// `C(s(x, y))` for a curve given by `C`, `C'`, `C''` at `s.v`.
    pub(crate) fn compose(s: Jet, c: [Vec3; 3]) -> VJet {
        let [gx, gy] = s.d;
        VJet {
            v: c[0],
            d: [c[1] * gx, c[1] * gy],
            h: [
                c[2] * (gx * gx) + c[1] * s.h[0],
                c[2] * (gx * gy) + c[1] * s.h[1],
                c[2] * (gy * gy) + c[1] * s.h[2],
            ],
        }
    }

    /// `self · f` for a scalar jet `f` (product rule).
    pub(crate) fn times(&self, f: Jet) -> VJet {
        let a = self;
        VJet {
            v: a.v * f.v,
            d: [a.v * f.d[0] + a.d[0] * f.v, a.v * f.d[1] + a.d[1] * f.v],
            h: [
                a.v * f.h[0] + a.d[0] * (2.0 * f.d[0]) + a.h[0] * f.v,
                a.v * f.h[1] + a.d[0] * f.d[1] + a.d[1] * f.d[0] + a.h[1] * f.v,
                a.v * f.h[2] + a.d[1] * (2.0 * f.d[1]) + a.h[2] * f.v,
            ],
        }
    }

    /// `self + c · f` for a constant vector `c` and a scalar jet `f`.
    pub(crate) fn add_scaled(&mut self, c: Vec3, f: &Jet) {
        self.v += c * f.v;
        self.d[0] += c * f.d[0];
        self.d[1] += c * f.d[1];
        self.h[0] += c * f.h[0];
        self.h[1] += c * f.h[1];
        self.h[2] += c * f.h[2];
    }
}

impl Add for VJet {
    type Output = VJet;
    fn add(self, o: VJet) -> VJet {
        VJet {
            v: self.v + o.v,
            d: [self.d[0] + o.d[0], self.d[1] + o.d[1]],
            h: [self.h[0] + o.h[0], self.h[1] + o.h[1], self.h[2] + o.h[2]],
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
        let x = Jet::affine(x0, [1.0, 0.0]);
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
}
