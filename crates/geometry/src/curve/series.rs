//! Truncated power series (Taylor coefficients `a_k`, `f(x₀ + ε) = Σ a_k ε^k`) for composing
//! exact derivatives: products, square roots, reciprocals and composition.

use crate::Vec3;

/// Longest series used: orders `0..=MAX_ORDER`.
pub(crate) const LEN: usize = super::MAX_ORDER + 1;

/// A scalar series truncated after `LEN` terms.
pub(crate) type Series = [f64; LEN];

/// `c = a·b` (first `n` coefficients).
pub(crate) fn mul(a: &Series, b: &Series, n: usize) -> Series {
    let mut c = [0.0; LEN];
    for k in 0..n {
        c[k] = (0..=k).map(|i| a[i] * b[k - i]).sum();
    }
    c
}

/// `√a` for `a₀ > 0`: `s₀ = √a₀`, `s_k = (a_k − Σ_{i=1}^{k−1} s_i s_{k−i}) / (2 s₀)`.
pub(crate) fn sqrt(a: &Series, n: usize) -> Series {
    let mut s = [0.0; LEN];
    s[0] = a[0].sqrt();
    for k in 1..n {
        let cross: f64 = (1..k).map(|i| s[i] * s[k - i]).sum();
        s[k] = (a[k] - cross) / (2.0 * s[0]);
    }
    s
}

/// `1/a` for `a₀ ≠ 0`: `r₀ = 1/a₀`, `r_k = −(Σ_{i=1}^{k} a_i r_{k−i}) / a₀`.
pub(crate) fn recip(a: &Series, n: usize) -> Series {
    let mut r = [0.0; LEN];
    r[0] = 1.0 / a[0];
    for k in 1..n {
        let s: f64 = (1..=k).map(|i| a[i] * r[k - i]).sum();
        r[k] = -s * r[0];
    }
    r
}

/// `f(g(ε))` for a series `g` with `g₀ = 0` (Horner in `g`).
pub(crate) fn compose(f: &Series, g: &Series, n: usize) -> Series {
    debug_assert!(g[0] == 0.0);
    let mut acc = [0.0; LEN];
    for j in (0..n).rev() {
        acc = mul(&acc, g, n);
        acc[0] += f[j];
    }
    acc
}

/// `F(g(ε))` for vector coefficients `F` and a scalar series `g` with `g₀ = 0`.
pub(crate) fn compose_vec(f: &[Vec3], g: &Series, n: usize) -> [Vec3; LEN] {
    let mut acc = [Vec3::zeros(); LEN];
    for j in (0..n.min(f.len())).rev() {
        let mut next = [Vec3::zeros(); LEN];
        for k in 0..n {
            next[k] = (1..=k).fold(Vec3::zeros(), |s, i| s + acc[k - i] * g[i]);
        }
        next[0] += f[j];
        acc = next;
    }
    acc
}

/// `k!` as a float.
pub(crate) fn factorial(k: usize) -> f64 {
    (1..=k).fold(1.0, |p, m| p * m as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exp_series(x0: f64) -> Series {
        let mut s = [0.0; LEN];
        for (k, c) in s.iter_mut().enumerate() {
            *c = x0.exp() / factorial(k);
        }
        s
    }

    #[test]
    fn sqrt_recip_compose_match_closed_forms() {
        // exp(x)² = exp(2x); √exp(x) = exp(x/2); 1/exp(x) = exp(−x).
        let e = exp_series(0.3);
        let sq = sqrt(&e, LEN);
        let rc = recip(&e, LEN);
        let pr = mul(&e, &e, LEN);
        for k in 0..LEN {
            let f = factorial(k);
            let want_sqrt = (0.15f64).exp() * 0.5f64.powi(k as i32) / f;
            let want_rec = (-0.3f64).exp() * (-1.0f64).powi(k as i32) / f;
            let want_sq = (0.6f64).exp() * 2.0f64.powi(k as i32) / f;
            // Each recursion step adds a few roundings: 16k ε relative.
            let tol = 16.0 * (k + 1) as f64 * f64::EPSILON;
            // The square-root recursion cancels: a_k − Σ s_i s_{k−i} = 2 s₀ s_k is much smaller
            // than its terms; scale the bound by that condition number.
            let cond = (e[k] + (1..k).map(|i| (sq[i] * sq[k - i]).abs()).sum::<f64>())
                / (2.0 * sq[0] * sq[k]).abs();
            assert!(
                (sq[k] - want_sqrt).abs() <= tol * cond * want_sqrt.abs(),
                "sqrt {k}: {} {want_sqrt}",
                sq[k]
            );
            assert!(
                (rc[k] - want_rec).abs() <= tol * want_rec.abs(),
                "recip {k}"
            );
            assert!((pr[k] - want_sq).abs() <= tol * want_sq.abs(), "mul {k}");
        }
        // exp(sin ε): coefficients 1, 1, 1/2, 0, −1/8, −1/15, −1/240, 1/90, 31/5760.
        let mut sin = [0.0; LEN];
        for (k, c) in sin.iter_mut().enumerate() {
            if k % 2 == 1 {
                *c = if k % 4 == 1 { 1.0 } else { -1.0 } / factorial(k);
            }
        }
        let ex = exp_series(0.0);
        let c = compose(&ex, &sin, LEN);
        let want = [
            1.0,
            1.0,
            0.5,
            0.0,
            -1.0 / 8.0,
            -1.0 / 15.0,
            -1.0 / 240.0,
            1.0 / 90.0,
            31.0 / 5760.0,
        ];
        for k in 0..LEN {
            assert!(
                (c[k] - want[k]).abs() <= 4e-16,
                "k = {k}: {} vs {}",
                c[k],
                want[k]
            );
        }
        let fv: Vec<Vec3> = ex.iter().map(|&a| Vec3::new(a, 2.0 * a, 0.0)).collect();
        let cv = compose_vec(&fv, &sin, LEN);
        for k in 0..LEN {
            assert!((cv[k].x - want[k]).abs() <= 4e-16);
            assert!((cv[k].y - 2.0 * want[k]).abs() <= 8e-16);
        }
    }
}
