//! The parameter domain of an n-sided patch: the regular n-gon with circumradius 1, its sides'
//! distance functions, a quadrature rule over it, and its splitting into four-sided pieces.
//!
//! Vertex `V_k = (cos θ_k, sin θ_k)` with `θ_k = −π/2 − π/n + 2πk/n`, so side 0 (from `V_0` to
//! `V_1`) lies at the bottom, parallel to `x`, and the sides run counterclockwise. For `n = 4`
//! the domain is the square `[−r, r]²`, `r = 1/√2`.

use super::jet::Jet;

/// The regular n-gon.
#[derive(Clone, Debug)]
pub(crate) struct Polygon {
    pub(crate) n: usize,
    /// Vertices, counterclockwise; side `i` runs from `verts[i]` to `verts[i + 1]`.
    pub(crate) verts: Vec<[f64; 2]>,
    /// Inward unit normal of each side.
    normals: Vec<[f64; 2]>,
    /// The length of every side, `2 sin(π/n)`.
    pub(crate) side: f64,
    /// The distance from a vertex to the line of the side two steps away (the second side
    /// through neither of its two sides' far ends), `d_{i+1}(V_i) = d_{i−2}(V_i)`.
    pub(crate) reach: f64,
}

impl Polygon {
    pub(crate) fn new(n: usize) -> Polygon {
        use std::f64::consts::PI;
        let nf = n as f64;
        let verts: Vec<[f64; 2]> = (0..n)
            .map(|k| {
                let t = -PI / 2.0 - PI / nf + 2.0 * PI * k as f64 / nf;
                let (s, c) = t.sin_cos();
                [c, s]
            })
            .collect();
        // For the square, snap to the exact ±1/√2 so the sides are exactly axis-parallel.
        let verts = if n == 4 {
            let r = std::f64::consts::FRAC_1_SQRT_2;
            vec![[-r, -r], [r, -r], [r, r], [-r, r]]
        } else {
            verts
        };
        let normals = (0..n)
            .map(|i| {
                let (a, b) = (verts[i], verts[(i + 1) % n]);
                let (tx, ty) = (b[0] - a[0], b[1] - a[1]);
                let l = tx.hypot(ty);
                [-ty / l, tx / l]
            })
            .collect();
        let mut p = Polygon {
            n,
            verts,
            normals,
            side: 2.0 * (PI / nf).sin(),
            reach: 0.0,
        };
        p.reach = p.distance(1, p.verts[0]);
        if n == 4 {
            p.side = 2.0 * std::f64::consts::FRAC_1_SQRT_2;
        }
        p
    }

    /// Signed distance from `p` to the line of side `i` (positive inside).
    pub(crate) fn distance(&self, i: usize, p: [f64; 2]) -> f64 {
        let (v, nrm) = (self.verts[i], self.normals[i]);
        (p[0] - v[0]) * nrm[0] + (p[1] - v[1]) * nrm[1]
    }

    /// [`Polygon::distance`] as a jet.
    pub(crate) fn distance_jet<const O: usize>(&self, i: usize, p: [f64; 2]) -> Jet<O> {
        Jet::affine(self.distance(i, p), self.normals[i])
    }

    /// The point at parameter `s ∈ [0, 1]` of side `i`.
    pub(crate) fn side_point(&self, i: usize, s: f64) -> [f64; 2] {
        let (a, b) = (self.verts[i], self.verts[(i + 1) % self.n]);
        [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]
    }

    /// The inward unit normal of side `i`.
    pub(crate) fn normal(&self, i: usize) -> [f64; 2] {
        self.normals[i]
    }

    /// The index of the vertex within `tol` of `p`, if any (asked at every evaluation: the
    /// squared distances, no `hypot`).
    pub(crate) fn vertex_near(&self, p: [f64; 2], tol: f64) -> Option<usize> {
        let tol2 = tol * tol;
        self.verts.iter().position(|v| {
            let (dx, dy) = (v[0] - p[0], v[1] - p[1]);
            dx * dx + dy * dy <= tol2
        })
    }

    /// A rule `(point, weight)` integrating polynomials of degree `≤ 2 nq − 2` exactly over the
    /// polygon: the fan of triangles from the centre, each mapped from the square by the
    /// collapsed (Duffy) map with `nq × nq` Gauss–Legendre points.
    pub(crate) fn quadrature(&self, nq: usize) -> Vec<([f64; 2], f64)> {
        let (x, w) = crate::quadrature::gauss_legendre(nq);
        let x: Vec<f64> = x.iter().map(|t| 0.5 * (t + 1.0)).collect();
        let w: Vec<f64> = w.iter().map(|t| 0.5 * t).collect();
        let mut out = Vec::with_capacity(self.n * nq * nq);
        for k in 0..self.n {
            let (b, c) = (self.verts[k], self.verts[(k + 1) % self.n]);
            // p = ξ (B + η (C − B)) from the centre A = 0; Jacobian ξ |det(B, C − B)|.
            let det = (b[0] * (c[1] - b[1]) - b[1] * (c[0] - b[0])).abs();
            for (xi, wi) in x.iter().zip(&w) {
                for (eta, wj) in x.iter().zip(&w) {
                    let p = [
                        xi * (b[0] + eta * (c[0] - b[0])),
                        xi * (b[1] + eta * (c[1] - b[1])),
                    ];
                    out.push((p, wi * wj * xi * det));
                }
            }
        }
        out
    }

    /// The four-sided piece `k` of the split about the centre, as the bilinear map of its
    /// corners `[V_k, M_k, O, M_{k−1}]` (`M_i` the midpoint of side `i`, `O` the centre):
    /// `(u, v) ↦` the point, `∂/∂u`, `∂/∂v` and `∂²/∂u∂v` (the other second partials vanish).
    /// `v = 0` is the first half of side `k`, `u = 0` the second half of side `k − 1`
    /// (reversed); `u = 1` and `v = 1` are the cuts, shared with the neighbouring pieces.
    pub(crate) fn piece(&self, k: usize, u: f64, v: f64) -> [[f64; 2]; 4] {
        let n = self.n;
        let a = self.verts[k];
        let b = self.side_point(k, 0.5);
        let d = self.side_point((k + n - 1) % n, 0.5);
        let (w00, w10, w11, w01) = ((1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v);
        // The centre is the origin, so its term vanishes; written out so that the cut points
        // of two pieces are the same floats ((1 − t) M + t·0 on both sides).
        let p = [
            w00 * a[0] + w10 * b[0] + w01 * d[0] + w11 * 0.0,
            w00 * a[1] + w10 * b[1] + w01 * d[1] + w11 * 0.0,
        ];
        let pu = [
            -(1.0 - v) * a[0] + (1.0 - v) * b[0] - v * d[0],
            -(1.0 - v) * a[1] + (1.0 - v) * b[1] - v * d[1],
        ];
        let pv = [
            -(1.0 - u) * a[0] - u * b[0] + (1.0 - u) * d[0],
            -(1.0 - u) * a[1] - u * b[1] + (1.0 - u) * d[1],
        ];
        let puv = [a[0] - b[0] - d[0], a[1] - b[1] - d[1]];
        [p, pu, pv, puv]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_integrates_polynomials_over_the_polygon() {
        for n in 3..=8 {
            let poly = Polygon::new(n);
            let rule = poly.quadrature(8);
            let area: f64 = rule.iter().map(|(_, w)| w).sum();
            let exact = 0.5 * n as f64 * (2.0 * std::f64::consts::PI / n as f64).sin();
            assert!((area - exact).abs() < 1e-14, "n = {n}: {area} vs {exact}");
            // ∫ x² + y² over a regular polygon of circumradius 1 (polar moment):
            // (n/12) · sin(2π/n) · (2 + cos(2π/n)) · … — check against the triangle-by-triangle
            // formula: each fan triangle O, B, C contributes |det|/12 · (|B|² + |C|² + B·C).
            let mut want = 0.0;
            for k in 0..n {
                let (b, c) = (poly.verts[k], poly.verts[(k + 1) % n]);
                let det = (b[0] * c[1] - b[1] * c[0]).abs();
                want += det / 12.0
                    * (b[0] * b[0]
                        + b[1] * b[1]
                        + c[0] * c[0]
                        + c[1] * c[1]
                        + b[0] * c[0]
                        + b[1] * c[1]);
            }
            let got: f64 = rule
                .iter()
                .map(|(p, w)| w * (p[0] * p[0] + p[1] * p[1]))
                .sum();
            assert!((got - want).abs() < 1e-14, "n = {n}: {got} vs {want}");
        }
    }

    #[test]
    fn sides_and_distances_agree() {
        for n in 3..=8 {
            let poly = Polygon::new(n);
            for i in 0..n {
                let p = poly.side_point(i, 0.3);
                assert!(poly.distance(i, p).abs() < 1e-15);
                for j in 0..n {
                    assert!(poly.distance(j, p) > -1e-15, "side {j} of {n}");
                }
                let near = poly.distance((i + 1) % n, poly.verts[i]);
                assert!((near - poly.reach).abs() < 1e-14, "n = {n}");
                let far = poly.distance((i + n - 2) % n, poly.verts[i]);
                assert!((far - poly.reach).abs() < 1e-14, "n = {n}");
            }
        }
    }

    #[test]
    fn the_pieces_tile_the_polygon_and_share_their_cuts() {
        for n in 3..=8 {
            let poly = Polygon::new(n);
            for k in 0..n {
                for t in [0.0, 0.25, 0.5, 1.0] {
                    let a = poly.piece(k, 1.0, t)[0];
                    let b = poly.piece((k + 1) % n, t, 1.0)[0];
                    assert_eq!(a, b, "n = {n}, piece {k}, t = {t}");
                }
                assert_eq!(poly.piece(k, 0.0, 0.0)[0], poly.verts[k]);
                let m = poly.piece(k, 1.0, 0.0)[0];
                let want = poly.side_point(k, 0.5);
                assert!((m[0] - want[0]).abs() + (m[1] - want[1]).abs() < 1e-16);
            }
        }
    }
}
