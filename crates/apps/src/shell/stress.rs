//! Principal stresses and the largest shear stress (Eq. 7.7).

/// The principal stresses `σ₁ ≥ σ₂ ≥ σ₃` of the symmetric stress
/// `[sxx, syy, szz, sxy, syz, szx]` (closed form of the cubic's three real roots).
pub fn principal_stresses(s: [f64; 6]) -> [f64; 3] {
    let [xx, yy, zz, xy, yz, zx] = s;
    let mean = (xx + yy + zz) / 3.0;
    let off = xy * xy + yz * yz + zx * zx;
    let (a, b, c) = (xx - mean, yy - mean, zz - mean);
    let p2 = (a * a + b * b + c * c + 2.0 * off) / 6.0;
    if p2 <= f64::MIN_POSITIVE {
        return [mean; 3];
    }
    let p = p2.sqrt();
    // det((S − mean I)/p) / 2, clamped into [−1, 1] against rounding.
    let det = a * (b * c - yz * yz) - xy * (xy * c - yz * zx) + zx * (xy * yz - b * zx);
    let r = (det / (2.0 * p * p2)).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let s1 = mean + 2.0 * p * phi.cos();
    let s3 = mean + 2.0 * p * (phi + 2.0 * std::f64::consts::FRAC_PI_3).cos();
    let s2 = 3.0 * mean - s1 - s3;
    [s1, s2, s3]
}

/// The largest shear stress over a set of nodal stresses and where it occurs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaxShear {
    /// `max (σ₁ − σ₃)/2` (Pa).
    pub value: f64,
    /// Index of the node where it occurs.
    pub node: usize,
}

/// `(σ₁ − σ₃)/2` of each stress and the largest of them (`None` for no stress).
pub fn max_shear(stresses: &[[f64; 6]]) -> (Vec<f64>, Option<MaxShear>) {
    let field: Vec<f64> = stresses
        .iter()
        .map(|s| {
            let p = principal_stresses(*s);
            (p[0] - p[2]) / 2.0
        })
        .collect();
    let best = field
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(node, &value)| MaxShear { value, node });
    (field, best)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn principal_stresses_of_known_tensors() {
        // Diagonal, in any order.
        let p = principal_stresses([1.0, -3.0, 2.0, 0.0, 0.0, 0.0]);
        assert!((p[0] - 2.0).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12);
        assert!((p[2] + 3.0).abs() < 1e-12);
        // Pure shear τ in the xy plane: ±τ and 0, largest shear τ.
        let p = principal_stresses([0.0, 0.0, 0.0, 5.0, 0.0, 0.0]);
        assert!((p[0] - 5.0).abs() < 1e-12 && p[1].abs() < 1e-12 && (p[2] + 5.0).abs() < 1e-12);
        // A rotated tensor R diag(4, 1, −2) Rᵀ keeps its eigenvalues.
        let (c, s) = (0.3f64.cos(), 0.3f64.sin());
        let d = [4.0, 1.0, -2.0];
        // Rotation about z by 0.3 then about x by 0.3.
        let rz = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        let rx = [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]];
        let mut r = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                r[i][j] = (0..3).map(|k| rx[i][k] * rz[k][j]).sum();
            }
        }
        let m = |i: usize, j: usize| (0..3).map(|k| r[i][k] * d[k] * r[j][k]).sum::<f64>();
        let p = principal_stresses([m(0, 0), m(1, 1), m(2, 2), m(0, 1), m(1, 2), m(2, 0)]);
        for (a, b) in p.iter().zip(d) {
            assert!((a - b).abs() < 1e-12, "{p:?}");
        }
        let (field, best) = max_shear(&[[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0; 6]]);
        assert!(
            (field[0] - 0.5).abs() < 1e-15 && field[1] == 0.0,
            "{field:?}"
        );
        assert_eq!(best.unwrap().node, 0);
    }
}
