//! Constant-coefficient elliptic operators `L = Σ_{k=0}^{N} c_k ∂u^{2N−2k} ∂v^{2k}` and the
//! characteristic roots of their Fourier-mode equations.
//!
//! For the mode `cos nv` (or `sin nv`), `∂v^{2k}` acts as `(−n²)^k`, so `X = f(u) cos nv` solves
//! `L X = 0` iff `Σ_k c_k (−n²)^k f^{(2N−2k)}(u) = 0`. With `f = e^{ru}` and `r² = n² σ` the
//! characteristic equation becomes `q(σ) = Σ_k c_k (−1)^k σ^{N−k} = 0`, independent of `n`: the
//! roots of mode `n` are `r = ±n s_j` with `s_j = √σ_j`. The operator is elliptic iff no `σ_j`
//! lies on `(−∞, 0]` (its symbol `Σ c_k ξ^{2N−2k} η^{2k}` then has no real zero), which also makes
//! `Re s_j > 0`: every mode splits into `N` solutions decaying away from `u = 0` and `N` decaying
//! away from `u = 1`.

use crate::{Error, Result};
use nalgebra::{Complex, DMatrix};

/// Largest `N` accepted (the book's Klein bottle uses `N = 20`).
pub const MAX_HALF_ORDER: usize = 20;

/// A distinct characteristic root `s` (with `Re s > 0`) of multiplicity `m`. Complex roots stand
/// for the conjugate pair `s, s̄`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootGroup {
    /// The root `s`, `Re s > 0`; for a conjugate pair the member with `Im s > 0`.
    pub s: Complex<f64>,
    /// Its multiplicity `m ≥ 1`.
    pub multiplicity: usize,
}

impl RootGroup {
    /// True for a conjugate pair (`Im s ≠ 0`).
    pub fn is_complex(&self) -> bool {
        self.s.im != 0.0
    }
}

/// A constant-coefficient operator `Σ_{k=0}^{N} c_k ∂u^{2N−2k} ∂v^{2k}` of order `2N`.
#[derive(Clone, Debug, PartialEq)]
pub struct Operator {
    coefficients: Vec<f64>,
    roots: Vec<RootGroup>,
    polyharmonic: Option<f64>,
}

fn check_finite(name: &str, x: f64) -> Result<()> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(format!("must be finite (got {x})")).at(name))
    }
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

impl Operator {
    /// `(∂²/∂u² + a² ∂²/∂v²)^N` for `N = 1…20` and `a > 0`: Laplace (`N = 1`, Eq. 4.1 with
    /// `a = 1`), biharmonic (Eq. 4.10), and the general form of Eq. 4.35. Its characteristic roots
    /// are exactly `±an`, each of multiplicity `N`.
    pub fn polyharmonic(n: usize, a: f64) -> Result<Self> {
        if n == 0 || n > MAX_HALF_ORDER {
            return Err(Error::invalid(format!(
                "must be between 1 and {MAX_HALF_ORDER} (got {n})"
            ))
            .at("order"));
        }
        check_finite("a", a)?;
        if a <= 0.0 {
            return Err(Error::invalid(format!("must be positive (got {a})")).at("a"));
        }
        let coefficients = (0..=n)
            .map(|k| binomial(n, k) * a.powi(2 * k as i32))
            .collect();
        let roots = vec![RootGroup {
            s: Complex::new(a, 0.0),
            multiplicity: n,
        }];
        Ok(Operator {
            coefficients,
            roots,
            polyharmonic: Some(a),
        })
    }

    /// `a ∂u⁶ + b ∂u⁴∂v² + c ∂u²∂v⁴ + d ∂v⁶` (Eq. 4.54), with the shape parameters `a, b, c, d`.
    pub fn sixth_order(a: f64, b: f64, c: f64, d: f64) -> Result<Self> {
        Self::general(vec![a, b, c, d])
    }

    /// `Σ_{k=0}^{N} c_k ∂u^{2N−2k} ∂v^{2k}` from `[c_0, …, c_N]` (`1 ≤ N ≤ 20`). Fails unless the
    /// operator is elliptic: `c_0 ≠ 0`, `c_N ≠ 0` and `Σ c_k t^{N−k}` has no root `t ≥ 0`.
    pub fn general(coefficients: Vec<f64>) -> Result<Self> {
        let n = coefficients.len().saturating_sub(1);
        if n == 0 || n > MAX_HALF_ORDER {
            return Err(Error::invalid(format!(
                "need between 2 and {} coefficients c_0..c_N (got {})",
                MAX_HALF_ORDER + 1,
                coefficients.len()
            ))
            .at("coefficients"));
        }
        for (k, &c) in coefficients.iter().enumerate() {
            check_finite(&format!("coefficients[{k}]"), c)?;
        }
        if coefficients[0] == 0.0 || coefficients[n] == 0.0 {
            return Err(Error::invalid(format!(
                "c_0 (the ∂u^{} term) and c_N (the ∂v^{} term) must be non-zero for an elliptic operator",
                2 * n,
                2 * n
            ))
            .at("coefficients"));
        }
        let roots = characteristic_roots(&coefficients)?;
        Ok(Operator {
            coefficients,
            roots,
            polyharmonic: None,
        })
    }

    /// `N` (the operator has order `2N` and takes `2N` conditions).
    pub fn half_order(&self) -> usize {
        self.coefficients.len() - 1
    }

    /// `[c_0, …, c_N]`.
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }

    /// The distinct roots `s_j` (`Re s_j > 0`) of the characteristic equation in `σ = s²`; the
    /// roots of mode `n` are `±n s_j`.
    pub fn roots(&self) -> &[RootGroup] {
        &self.roots
    }

    /// The smoothing parameter `a` if this is `(∂uu + a²∂vv)^N`.
    pub fn smoothing_parameter(&self) -> Option<f64> {
        self.polyharmonic
    }

    /// The mode equation `f^{(2N)} + Σ_{k≥1} γ_k f^{(2N−2k)} = 0` written in `x = 2u − 1`:
    /// `γ_k = (c_k / c_0) (−n²/4)^k`.
    pub(crate) fn mode_gammas_x(&self, n: usize) -> Vec<f64> {
        let c0 = self.coefficients[0];
        let m = -((n * n) as f64) / 4.0;
        (1..=self.half_order())
            .map(|k| self.coefficients[k] / c0 * m.powi(k as i32))
            .collect()
    }

    /// `max_j |s_j|`: mode `n` varies on the length scale `1/(n·max|s|)` in `u`.
    pub(crate) fn root_scale(&self) -> f64 {
        self.roots.iter().map(|g| g.s.norm()).fold(0.0, f64::max)
    }

    /// A short human-readable description.
    pub fn describe(&self) -> String {
        let n = self.half_order();
        match self.polyharmonic {
            Some(a) => {
                let name = match n {
                    1 => "Laplace".to_string(),
                    2 => "biharmonic".to_string(),
                    3 => "triharmonic".to_string(),
                    _ => format!("polyharmonic N = {n}"),
                };
                format!("(∂uu + a²∂vv)^{n} X = 0 ({name}, order {}, a = {a})", 2 * n)
            }
            None => {
                let terms: Vec<String> = self
                    .coefficients
                    .iter()
                    .enumerate()
                    .map(|(k, c)| format!("{c}·∂u^{}∂v^{}", 2 * n - 2 * k, 2 * k))
                    .collect();
                format!("({}) X = 0 (order {})", terms.join(" + "), 2 * n)
            }
        }
    }
}

/// Roots of `q(σ) = Σ_k c_k (−1)^k σ^{N−k}` as groups `s = √σ` with multiplicities, checking
/// ellipticity. Eigenvalues of the companion matrix give the roots; clusters (a multiple root
/// splits by about `ε^{1/m}` in floating point) are merged and the merged root is polished by
/// Newton's method on `q^{(m−1)}`, where it is simple.
fn characteristic_roots(c: &[f64]) -> Result<Vec<RootGroup>> {
    let n = c.len() - 1;
    // q(σ) coefficients, highest degree first: p[k] multiplies σ^{N−k}.
    let p: Vec<f64> = c
        .iter()
        .enumerate()
        .map(|(k, &ck)| if k % 2 == 0 { ck } else { -ck })
        .collect();
    let mut companion = DMatrix::<f64>::zeros(n, n);
    for k in 0..n {
        companion[(0, k)] = -p[k + 1] / p[0];
        if k + 1 < n {
            companion[(k + 1, k)] = 1.0;
        }
    }
    let eig: Vec<Complex<f64>> =
        crate::linalg::decomp::complex_eigenvalues(companion).ok_or_else(|| {
            Error::invalid(
                "the roots of the characteristic equation could not be computed (coefficients too \
             large, too small or too far apart)",
            )
            .at("coefficients")
        })?;
    let scale = eig
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);

    // Cluster. An m-fold root spreads into a ring of radius about ε^{1/m} in floating point, so
    // the merge radius grows with N; false merges are undone below by the multiplicity test.
    let radius = (1e-4f64).max(10.0 * f64::EPSILON.powf(1.0 / n as f64)) * scale;
    let mut used = vec![false; n];
    let mut clusters: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        if used[i] {
            continue;
        }
        let mut members = vec![i];
        used[i] = true;
        let mut changed = true;
        while changed {
            changed = false;
            for j in 0..n {
                if !used[j] && members.iter().any(|&k| (eig[j] - eig[k]).norm() <= radius) {
                    members.push(j);
                    used[j] = true;
                    changed = true;
                }
            }
        }
        clusters.push(members);
    }
    let groups: Vec<(Complex<f64>, usize, Vec<usize>)> = clusters
        .into_iter()
        .map(|m| {
            (
                m.iter().map(|&k| eig[k]).sum::<Complex<f64>>() / m.len() as f64,
                m.len(),
                m,
            )
        })
        .collect();

    // Polish each group on the (m−1)-th derivative of q.
    let poly_eval = |coef: &[f64], z: Complex<f64>| {
        coef.iter()
            .fold(Complex::new(0.0, 0.0), |acc, &a| acc * z + a)
    };
    let derivative = |coef: &[f64]| -> Vec<f64> {
        let d = coef.len() - 1;
        coef[..d]
            .iter()
            .enumerate()
            .map(|(k, &a)| a * (d - k) as f64)
            .collect()
    };
    let polish = |mut z: Complex<f64>, m: usize| {
        let mut q = p.clone();
        for _ in 1..m {
            q = derivative(&q);
        }
        let dq = derivative(&q);
        if dq.is_empty() {
            return z;
        }
        for _ in 0..6 {
            let f = poly_eval(&q, z);
            let df = poly_eval(&dq, z);
            if df.norm() == 0.0 {
                break;
            }
            let step = f / df;
            z -= step;
            if step.norm() <= 1e-16 * z.norm() {
                break;
            }
        }
        z
    };
    // A merged cluster must really be a multiple root: q and its first m−1 derivatives vanish
    // there to rounding. Otherwise (distinct but close roots) keep the members apart.
    let abs_poly: Vec<f64> = p.iter().map(|a| a.abs()).collect();
    let is_multiple_root = |z: Complex<f64>, m: usize| {
        let mut q = p.clone();
        let mut qa = abs_poly.clone();
        for _ in 0..m {
            let bound = poly_eval(&qa, Complex::new(z.norm(), 0.0)).re;
            if poly_eval(&q, z).norm() > 1e-9 * bound {
                return false;
            }
            q = derivative(&q);
            qa = derivative(&qa);
        }
        true
    };
    let mut split = Vec::new();
    for (z, m, members) in groups {
        if m > 1 && !is_multiple_root(polish(z, m), m) {
            split.extend(members.iter().map(|&k| (eig[k], 1)));
        } else {
            split.push((z, m));
        }
    }
    let mut result = Vec::new();
    for (z, m) in split {
        let mut z = polish(z, m);
        if !is_multiple_root(z, m) {
            return Err(Error::invalid(format!(
                "cannot resolve the characteristic roots of this operator in double precision (a root near σ = {z:.4} of multiplicity {m}); for (∂uu + a²∂vv)^N use kind = \"polyharmonic\""
            ))
            .at("coefficients"));
        }
        if z.im.abs() <= 1e-10 * z.norm() {
            z.im = 0.0;
        }
        if z.im == 0.0 && z.re <= 0.0 {
            return Err(Error::invalid(format!(
                "the operator is not elliptic: Σ c_k t^(N−k) vanishes at t = {:.6} ≥ 0, so the Fourier modes oscillate in u",
                -z.re
            ))
            .at("coefficients"));
        }
        if z.im < 0.0 {
            // The conjugate stands for the pair.
            continue;
        }
        let s = z.sqrt();
        result.push(RootGroup { s, multiplicity: m });
    }
    result.sort_by(|a, b| {
        a.s.re
            .partial_cmp(&b.s.re)
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    Ok(result)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn total_multiplicity(op: &Operator) -> usize {
        op.roots()
            .iter()
            .map(|g| g.multiplicity * if g.is_complex() { 2 } else { 1 })
            .sum()
    }

    #[test]
    fn polyharmonic_coefficients_are_binomial() {
        let op = Operator::polyharmonic(3, 2.0).unwrap();
        assert_eq!(op.coefficients(), &[1.0, 12.0, 48.0, 64.0]);
        assert_eq!(
            op.roots(),
            &[RootGroup {
                s: Complex::new(2.0, 0.0),
                multiplicity: 3
            }]
        );
    }

    #[test]
    fn general_recovers_repeated_roots_of_a_polyharmonic() {
        // (∂uu + 1.5² ∂vv)^3 written out: the triple root must be found as one group.
        let a: f64 = 1.5;
        let c = vec![1.0, 3.0 * a * a, 3.0 * a.powi(4), a.powi(6)];
        let op = Operator::general(c).unwrap();
        assert_eq!(op.roots().len(), 1);
        assert_eq!(op.roots()[0].multiplicity, 3);
        assert!((op.roots()[0].s - Complex::new(a, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn general_recovers_high_multiplicities() {
        for (nn, a) in [(4usize, 1.0f64), (8, 3.0), (12, 1.0), (20, 3.0)] {
            let c: Vec<f64> = (0..=nn)
                .map(|k| binomial(nn, k) * a.powi(2 * k as i32))
                .collect();
            match Operator::general(c) {
                Ok(op) => {
                    assert_eq!(op.roots().len(), 1, "N={nn} a={a}: {:?}", op.roots());
                    assert_eq!(op.roots()[0].multiplicity, nn);
                    assert!(
                        (op.roots()[0].s - Complex::new(a, 0.0)).norm() < 1e-8 * a,
                        "N={nn}: {:?}",
                        op.roots()
                    );
                }
                // Refusing is acceptable; silently wrong roots are not.
                Err(e) => assert!(e.to_string().contains("polyharmonic"), "{e}"),
            }
        }
    }

    #[test]
    fn sixth_order_with_distinct_and_complex_roots() {
        // Σ c_k t^{3-k} = (t + 1)(t² + t + 1): roots t = −1 and t = (−1 ± i√3)/2 (none ≥ 0).
        let op = Operator::sixth_order(1.0, 2.0, 2.0, 1.0).unwrap();
        assert_eq!(total_multiplicity(&op), 3);
        for g in op.roots() {
            assert!(g.s.re > 0.0);
            // σ = s² must solve q(σ) = σ³ − 2σ² + 2σ − 1 = 0.
            let z = g.s * g.s;
            let q = z * z * z - z * z * 2.0 + z * 2.0 - 1.0;
            assert!(q.norm() < 1e-13, "q(σ) = {q}");
        }
    }

    #[test]
    fn non_elliptic_operators_are_refused() {
        // ∂u² − ∂v²: the wave operator (t − 1 has the root t = 1).
        assert!(Operator::general(vec![1.0, -1.0]).is_err());
        assert!(Operator::general(vec![0.0, 1.0]).is_err());
        assert!(Operator::general(vec![1.0, 0.0]).is_err());
        assert!(Operator::general(vec![1.0, f64::NAN]).is_err());
        assert!(Operator::polyharmonic(2, 0.0).is_err());
        assert!(Operator::polyharmonic(2, -1.0).is_err());
        assert!(Operator::polyharmonic(0, 1.0).is_err());
        assert!(Operator::polyharmonic(21, 1.0).is_err());
        assert!(Operator::polyharmonic(2, f64::INFINITY).is_err());
    }
}
