//! The correction space of an n-sided patch: `φ_ab(x, y) = w(x, y) · P_a(x) P_b(y)`, `a + b ≤
//! p`, with Legendre polynomials `P_a` and the weight `w = Π_i (d_i / ρ)^{m_i}` (`d_i` the
//! distance to side `i`, `ρ` the inradius, `m_i` the number of conditions side `i` carries).
//! Every `φ` vanishes with its first `m_i − 1` cross-boundary derivatives on side `i`, so
//! adding any combination of them to the boundary interpolant leaves the positions and ribbons
//! exactly as they were: the boundary is met by construction, not by the solve.

use super::domain::Polygon;
use super::jet::Jet;

/// Legendre `P_0 … P_p` at `x` with three derivatives.
fn legendre(p: usize, x: f64) -> Vec<[f64; 4]> {
    let mut out = vec![[1.0, 0.0, 0.0, 0.0]];
    if p >= 1 {
        out.push([x, 1.0, 0.0, 0.0]);
    }
    for k in 1..p {
        let kf = k as f64;
        let [a0, a1, a2, a3] = out[k];
        let [b0, b1, b2, b3] = out[k - 1];
        // (k + 1) P_{k+1} = (2k + 1) x P_k − k P_{k−1}, differentiated three times
        // ((x P)^(j) = x P^(j) + j P^(j−1)).
        let c = 2.0 * kf + 1.0;
        let k1 = kf + 1.0;
        let c0 = (c * x * a0 - kf * b0) / k1;
        let c1 = (c * (a0 + x * a1) - kf * b1) / k1;
        let c2 = (c * (2.0 * a1 + x * a2) - kf * b2) / k1;
        let c3 = (c * (3.0 * a2 + x * a3) - kf * b3) / k1;
        out.push([c0, c1, c2, c3]);
    }
    out
}

/// The weighted Legendre basis of one polygon, side multiplicities and degree.
#[derive(Clone, Debug)]
pub(crate) struct Basis {
    pub(crate) degree: usize,
    pub(crate) multiplicity: Vec<usize>,
    inradius: f64,
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
    pub(crate) fn weight<const T: bool>(&self, poly: &Polygon, p: [f64; 2]) -> Jet<T> {
        let mut w = Jet::constant(1.0);
        for (i, &m) in self.multiplicity.iter().enumerate() {
            let d = poly.distance_jet(i, p).scale(1.0 / self.inradius);
            for _ in 0..m {
                w = w * d;
            }
        }
        w
    }

    /// Every basis function at `p`, in the order `(a, b)` by total degree, then `a`.
    pub(crate) fn eval<const T: bool>(&self, poly: &Polygon, p: [f64; 2], out: &mut Vec<Jet<T>>) {
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
