//! The correction space of an n-sided patch: `φ_ab(x, y) = w(x, y) · P_a(x) P_b(y)`, `a + b ≤
//! p`, with Legendre polynomials `P_a` and the weight `w = Π_i (d_i / ρ)^{m_i}` (`d_i` the
//! distance to side `i`, `ρ` the inradius, `m_i` the number of conditions side `i` carries).
//! Every `φ` vanishes with its first `m_i − 1` cross-boundary derivatives on side `i`, so
//! adding any combination of them to the boundary interpolant leaves the positions and ribbons
//! exactly as they were: the boundary is met by construction, not by the solve.

use super::domain::Polygon;
use super::jet::{Jet, VJet};
use crate::Vec3;

/// The largest degree of the correction polynomials.
pub(crate) const MAX_DEGREE: usize = 24;

/// Legendre `P_0 … P_p` at `x` with three derivatives.
fn legendre(p: usize, x: f64) -> Vec<[f64; 4]> {
    legendre_array::<3>(p, x)[..=p].to_vec()
}

/// The coefficients `((2k + 1)/(k + 1), k/(k + 1))` of the three-term recurrence, `k <
/// MAX_DEGREE`, as a table: a step of the recurrence then costs no division.
const RECURRENCE: [[f64; 2]; MAX_DEGREE] = {
    let mut t = [[0.0; 2]; MAX_DEGREE];
    let mut k = 0;
    while k < MAX_DEGREE {
        let kf = k as f64;
        t[k] = [(2.0 * kf + 1.0) / (kf + 1.0), kf / (kf + 1.0)];
        k += 1;
    }
    t
};

/// Legendre `P_0 … P_p` (`p ≤ MAX_DEGREE`) at `x` with `D ≤ 3` derivatives, on the stack; the
/// entries above `p` and the derivatives above `D` are zero.
fn legendre_array<const D: usize>(p: usize, x: f64) -> [[f64; 4]; MAX_DEGREE + 1] {
    let mut out = [[0.0; 4]; MAX_DEGREE + 1];
    out[0][0] = 1.0;
    if p >= 1 {
        out[1][0] = x;
        if D >= 1 {
            out[1][1] = 1.0;
        }
    }
    for k in 1..p {
        // P_{k+1} = ((2k + 1) x P_k − k P_{k−1}) / (k + 1), differentiated j times
        // ((x P)^(j) = x P^(j) + j P^(j−1)).
        let [alpha, beta] = RECURRENCE[k];
        let (a, b) = (out[k], out[k - 1]);
        let mut c = [alpha * x * a[0] - beta * b[0], 0.0, 0.0, 0.0];
        for j in 1..=D.min(3) {
            c[j] = alpha * (j as f64 * a[j - 1] + x * a[j]) - beta * b[j];
        }
        out[k + 1] = c;
    }
    out
}

/// The weighted Legendre basis of one polygon, side multiplicities and degree.
#[derive(Clone, Debug)]
pub(crate) struct Basis {
    pub(crate) degree: usize,
    pub(crate) multiplicity: Vec<usize>,
    pub(crate) inradius: f64,
}

impl Basis {
    pub(crate) fn new(poly: &Polygon, multiplicity: Vec<usize>, degree: usize) -> Basis {
        Basis {
            degree,
            multiplicity,
            inradius: (std::f64::consts::PI / poly.n as f64).cos(),
        }
    }

    /// The number of basis functions, `(p + 1)(p + 2)/2`.
    pub(crate) fn len(&self) -> usize {
        (self.degree + 1) * (self.degree + 2) / 2
    }

    /// The polynomial degree of the weight, `Σ m_i`.
    pub(crate) fn weight_degree(&self) -> usize {
        self.multiplicity.iter().sum()
    }

    /// The weight `w` at `p`.
    pub(crate) fn weight<const O: usize>(&self, poly: &Polygon, p: [f64; 2]) -> Jet<O> {
        let mut w = Jet::constant(1.0);
        for (i, &m) in self.multiplicity.iter().enumerate() {
            let d = poly.distance_jet(i, p).scale(1.0 / self.inradius);
            for _ in 0..m {
                w = w * d;
            }
        }
        w
    }

    /// The coefficients `c_ab` of [`Basis::eval`]'s order (by total degree, then `a`) in the
    /// order [`Basis::combine`] takes them: by `a`, then `b = 0 … p − a`.
    pub(crate) fn by_a(&self, c: &[Vec3]) -> Vec<Vec3> {
        let deg = self.degree;
        let mut out = Vec::with_capacity(c.len());
        for a in 0..=deg {
            for b in 0..=deg - a {
                let t = a + b;
                out.push(c[t * (t + 1) / 2 + a]);
            }
        }
        out
    }

    /// `Σ_ab c_ab φ_ab` at `p` to order `O ≤ 2`, for coefficients `c` ordered by
    /// [`Basis::by_a`]: `w · Q` with `Q = Σ_a P_a(x) S_a(y)`, `S_a = Σ_b c_ab P_b(y)`. Each
    /// coefficient costs one multiply-add per partial of `S_a`, not a jet product per
    /// function, and nothing is allocated: the sum every evaluation of the patch makes.
    pub(crate) fn combine<const O: usize>(
        &self,
        poly: &Polygon,
        p: [f64; 2],
        c: &[Vec3],
    ) -> VJet<O> {
        debug_assert!(O <= 2 && c.len() == self.len());
        let deg = self.degree;
        let lx = legendre_array::<O>(deg, p[0]);
        let ly = legendre_array::<O>(deg, p[1]);
        let z = Vec3::zeros();
        let mut q = VJet::<O>::default();
        let mut rest = c;
        for (a, fx) in lx.iter().enumerate().take(deg + 1) {
            // S_a and its first two derivatives in y.
            let (mut s0, mut s1, mut s2) = (z, z, z);
            let (column, tail) = rest.split_at(deg + 1 - a);
            rest = tail;
            for (ck, fy) in column.iter().zip(&ly) {
                let ck = *ck;
                s0 += ck * fy[0];
                if O >= 1 {
                    s1 += ck * fy[1];
                }
                if O >= 2 {
                    s2 += ck * fy[2];
                }
            }
            q.v += s0 * fx[0];
            if O >= 1 {
                q.d[0] += s0 * fx[1];
                q.d[1] += s1 * fx[0];
            }
            if O >= 2 {
                q.h[0] += s0 * fx[2];
                q.h[1] += s1 * fx[1];
                q.h[2] += s2 * fx[0];
            }
        }
        q.times(self.weight::<O>(poly, p))
    }

    /// Every basis function at `p`, in the order `(a, b)` by total degree, then `a`.
    pub(crate) fn eval<const O: usize>(&self, poly: &Polygon, p: [f64; 2], out: &mut Vec<Jet<O>>) {
        out.clear();
        let w = self.weight(poly, p);
        let lx = legendre(self.degree, p[0]);
        let ly = legendre(self.degree, p[1]);
        for total in 0..=self.degree {
            for (a, fx) in lx.iter().enumerate().take(total + 1) {
                let (fx, fy) = (*fx, ly[total - a]);
                let q = Jet {
                    v: fx[0] * fy[0],
                    d: [fx[1] * fy[0], fx[0] * fy[1]],
                    h: [fx[2] * fy[0], fx[1] * fy[1], fx[0] * fy[2]],
                    t: [fx[3] * fy[0], fx[2] * fy[1], fx[1] * fy[2], fx[0] * fy[3]],
                };
                out.push(w * q);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legendre_matches_closed_forms() {
        let x: f64 = 0.37;
        let l = legendre(4, x);
        let p4 = (35.0 * x.powi(4) - 30.0 * x * x + 3.0) / 8.0;
        let d4 = (140.0 * x.powi(3) - 60.0 * x) / 8.0;
        let dd4 = (420.0 * x * x - 60.0) / 8.0;
        assert!((l[4][0] - p4).abs() < 1e-15);
        assert!((l[4][1] - d4).abs() < 1e-14);
        assert!((l[4][2] - dd4).abs() < 1e-13);
        let ddd4 = 840.0 * x / 8.0;
        assert!((l[4][3] - ddd4).abs() < 1e-12);
    }

    /// On a side of multiplicity 2 every function and its gradient vanish; on a side of
    /// multiplicity 1 the function vanishes and its cross derivative does not.
    #[test]
    fn the_basis_vanishes_to_the_sides_multiplicity() {
        let poly = Polygon::new(5);
        let basis = Basis::new(&poly, vec![2, 2, 1, 2, 2], 4);
        let mut out: Vec<Jet> = Vec::new();
        for side in 0..5 {
            basis.eval(&poly, poly.side_point(side, 0.37), &mut out);
            let nrm = poly.normal(side);
            let mut cross_max: f64 = 0.0;
            for phi in &out {
                assert!(phi.v.abs() < 1e-15);
                let cross = phi.d[0] * nrm[0] + phi.d[1] * nrm[1];
                cross_max = cross_max.max(cross.abs());
            }
            if side == 2 {
                assert!(cross_max > 1e-3);
            } else {
                assert!(cross_max < 1e-14, "side {side}: {cross_max}");
            }
        }
    }

    /// On a side of multiplicity 3 (G2) the second cross derivative vanishes too; on one of
    /// multiplicity 2 it does not.
    #[test]
    fn a_g2_side_keeps_the_second_cross_derivative() {
        let poly = Polygon::new(4);
        let basis = Basis::new(&poly, vec![3, 2, 3, 1], 5);
        let mut out: Vec<Jet> = Vec::new();
        for side in 0..4 {
            basis.eval(&poly, poly.side_point(side, 0.61), &mut out);
            let g = poly.normal(side);
            let mut second: f64 = 0.0;
            for phi in &out {
                let cross = phi.d[0] * g[0] + phi.d[1] * g[1];
                if side != 3 {
                    assert!(cross.abs() < 1e-14, "side {side}");
                }
                let nn =
                    phi.h[0] * g[0] * g[0] + 2.0 * phi.h[1] * g[0] * g[1] + phi.h[2] * g[1] * g[1];
                second = second.max(nn.abs());
            }
            match side {
                0 | 2 => assert!(second < 1e-13, "side {side}: {second}"),
                _ => assert!(second > 1e-3, "side {side}: {second}"),
            }
        }
    }
}
