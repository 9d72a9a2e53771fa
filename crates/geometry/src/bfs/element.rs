//! The BFS rectangle: bicubic Hermite shape functions in element-local coordinates and the
//! element matrices of an [`Energy`] by Gauss quadrature.

use super::Energy;

/// Gauss–Legendre rule with 4 points on `[0, 1]`: `(node, weight)`, exact for degree ≤ 7.
pub const GAUSS4: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_87, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

/// The cubic Hermite basis of an interval of length `h` at local coordinate `s ∈ [0, 1]`, and
/// its first and second derivatives with respect to the global coordinate:
/// `out[r][2a + p] = dʳ/dxʳ (hᵖ H_{2a+p}(s))`, where `H₀ = 1 − 3s² + 2s³`, `H₁ = s − 2s² + s³`,
/// `H₂ = 3s² − 2s³`, `H₃ = s³ − s²` carry the value (`p = 0`) or the derivative (`p = 1`) at the
/// end `a ∈ {0, 1}`.
pub fn hermite_1d(s: f64, h: f64) -> [[f64; 4]; 3] {
    let s2 = s * s;
    let s3 = s2 * s;
    let val = [
        1.0 - 3.0 * s2 + 2.0 * s3,
        s - 2.0 * s2 + s3,
        3.0 * s2 - 2.0 * s3,
        s3 - s2,
    ];
    let d1 = [
        -6.0 * s + 6.0 * s2,
        1.0 - 4.0 * s + 3.0 * s2,
        6.0 * s - 6.0 * s2,
        3.0 * s2 - 2.0 * s,
    ];
    let d2 = [
        -6.0 + 12.0 * s,
        -4.0 + 6.0 * s,
        6.0 - 12.0 * s,
        6.0 * s - 2.0,
    ];
    let scale = [1.0, h, 1.0, h];
    let mut out = [[0.0; 4]; 3];
    for k in 0..4 {
        out[0][k] = val[k] * scale[k];
        out[1][k] = d1[k] * scale[k] / h;
        out[2][k] = d2[k] * scale[k] / (h * h);
    }
    out
}

/// The derivative orders `(rx, ry)` of `w = (u, u_x, u_y, u_xx, u_xy, u_yy)`.
pub(crate) const W_ORDERS: [(usize, usize); 6] = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];

/// `w` of the 16 local shape functions at local `(s, t)`: `out[ℓ][m]` for the local degree of
/// freedom `ℓ = 4 (a + 2b) + p + 2q` (corner `(a, b)`, derivative `∂xᵖ ∂y^q`).
pub(crate) fn shape_w(s: f64, t: f64, hx: f64, hy: f64) -> [[f64; 6]; 16] {
    let gx = hermite_1d(s, hx);
    let gy = hermite_1d(t, hy);
    let mut out = [[0.0; 6]; 16];
    for b in 0..2 {
        for a in 0..2 {
            for q in 0..2 {
                for p in 0..2 {
                    let l = 4 * (a + 2 * b) + p + 2 * q;
                    for (m, &(rx, ry)) in W_ORDERS.iter().enumerate() {
                        out[l][m] = gx[rx][2 * a + p] * gy[ry][2 * b + q];
                    }
                }
            }
        }
    }
    out
}

/// The 16 local shape functions' values at local `(s, t)`.
pub(crate) fn shape_values(s: f64, t: f64, hx: f64, hy: f64) -> [f64; 16] {
    let gx = hermite_1d(s, hx);
    let gy = hermite_1d(t, hy);
    let mut out = [0.0; 16];
    for b in 0..2 {
        for a in 0..2 {
            for q in 0..2 {
                for p in 0..2 {
                    out[4 * (a + 2 * b) + p + 2 * q] = gx[0][2 * a + p] * gy[0][2 * b + q];
                }
            }
        }
    }
    out
}

/// The element matrix `R_e[ℓ][ℓ'] = ∫_e w_ℓᵀ M w_ℓ'` of the energy on an `hx × hy` rectangle
/// (the element block of the paper's `R = ((ω_i, ω_j)_L)`), by the 4 × 4 Gauss rule in local
/// coordinates: exact, since the integrand has degree at most 6 in each variable.
pub fn element_matrix(energy: &Energy, hx: f64, hy: f64) -> [[f64; 16]; 16] {
    let m = energy.matrix();
    let mut k = [[0.0; 16]; 16];
    for &(t, wt) in &GAUSS4 {
        for &(s, ws) in &GAUSS4 {
            let w = shape_w(s, t, hx, hy);
            let weight = ws * wt * hx * hy;
            // mw[ℓ] = M w_ℓ
            let mut mw = [[0.0; 6]; 16];
            for l in 0..16 {
                for i in 0..6 {
                    let mut acc = 0.0;
                    for j in 0..6 {
                        acc += m[i][j] * w[l][j];
                    }
                    mw[l][i] = acc;
                }
            }
            for l in 0..16 {
                for l2 in l..16 {
                    let mut acc = 0.0;
                    for i in 0..6 {
                        acc += w[l][i] * mw[l2][i];
                    }
                    k[l][l2] += weight * acc;
                }
            }
        }
    }
    for l in 0..16 {
        for l2 in 0..l {
            k[l][l2] = k[l2][l];
        }
    }
    k
}
