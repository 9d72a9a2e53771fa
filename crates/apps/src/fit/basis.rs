//! The biharmonic patch as a linear function of its four boundary curves, mode by mode.
//!
//! For `(∂²/∂u² + a²∂²/∂v²)² X = 0` and curves that are Fourier series, mode `n` of the solution
//! solves `(d²/du² − a²n²)² Xₙ = 0` (book Eqs. 4.10–4.14): a cubic for `n = 0`, and
//! `(α + βu) e^{anu} + (γ + δu) e^{−anu}` for `n ≥ 1`. Given `Xₙ(0) = P₀`, `Xₙ'(0) = D₀`,
//! `Xₙ(1) = P₁`, `Xₙ'(1) = D₁`, the value at `u` is `w₀P₀ + w₁D₀ + w₂P₁ + w₃D₁` with the
//! weights returned by [`weights`]. The exponentials are taken in the bounded form
//! `e^{an(u−1)}`, `e^{−anu}` so no basis function exceeds 1 on `[0, 1]`.

use nalgebra::{Matrix4, Vector4};

/// Weights `[w₀, w₁, w₂, w₃]` of `(P₀, D₀, P₁, D₁)` in mode `n` of the biharmonic patch with
/// smoothing parameter `a`, at `u`.
pub fn weights(n: usize, a: f64, u: f64) -> [f64; 4] {
    if n == 0 {
        // Cubic Hermite basis.
        let (u2, u3) = (u * u, u * u * u);
        return [
            2.0 * u3 - 3.0 * u2 + 1.0,
            u3 - 2.0 * u2 + u,
            -2.0 * u3 + 3.0 * u2,
            u3 - u2,
        ];
    }
    let k = a * n as f64;
    let phi = |u: f64| -> (Vector4<f64>, Vector4<f64>) {
        let (ep, em) = ((k * (u - 1.0)).exp(), (-k * u).exp());
        (
            Vector4::new(ep, u * ep, em, u * em),
            Vector4::new(k * ep, (1.0 + k * u) * ep, -k * em, (1.0 - k * u) * em),
        )
    };
    let (v0, d0) = phi(0.0);
    let (v1, d1) = phi(1.0);
    // Rows: the four conditions applied to the four basis functions.
    let m = Matrix4::from_rows(&[
        v0.transpose(),
        d0.transpose(),
        v1.transpose(),
        d1.transpose(),
    ]);
    let (vu, _) = phi(u);
    // X(u) = φ(u)ᵀ c with M c = b, so the weights are M⁻ᵀ φ(u).
    match m.transpose().lu().solve(&vu) {
        Some(w) => [w[0], w[1], w[2], w[3]],
        None => [f64::NAN; 4],
    }
}

/// Weights `[w₀, w₁, w₂, w₃]` of four position curves at `u = knots[k]` (distinct, in
/// `[0, 1]`) in mode `n` of the biharmonic patch with smoothing parameter `a`, at `u`: the
/// variant of book §4.5 whose four conditions are all positions. The four functions of a mode
/// (a cubic, or `(α + βu) e^{anu} + (γ + δu) e^{−anu}`) have at most three zeros, so any four
/// distinct `u` determine them.
pub fn position_weights(n: usize, a: f64, knots: [f64; 4], u: f64) -> [f64; 4] {
    let k = a * n as f64;
    let phi = |u: f64| -> Vector4<f64> {
        if n == 0 {
            // Centred powers keep the system well conditioned.
            let x = u - 0.5;
            Vector4::new(1.0, x, x * x, x * x * x)
        } else {
            let (ep, em) = ((k * (u - 1.0)).exp(), (-k * u).exp());
            Vector4::new(ep, u * ep, em, u * em)
        }
    };
    let m = Matrix4::from_rows(&knots.map(|t| phi(t).transpose()));
    match m.transpose().lu().solve(&phi(u)) {
        Some(w) => [w[0], w[1], w[2], w[3]],
        None => [f64::NAN; 4],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_meet_the_conditions_and_solve_the_mode_equation() {
        for n in [0, 1, 2, 5, 20] {
            for a in [0.5, 1.0, 3.0] {
                let at = |u| weights(n, a, u);
                // Interpolation at the ends.
                let w0 = at(0.0);
                let w1 = at(1.0);
                for k in 0..4 {
                    let e0 = if k == 0 { 1.0 } else { 0.0 };
                    let e1 = if k == 2 { 1.0 } else { 0.0 };
                    assert!((w0[k] - e0).abs() < 1e-12, "{n} {a} {k}");
                    assert!((w1[k] - e1).abs() < 1e-12, "{n} {a} {k}");
                }
                // Derivatives at the ends by central differences centred on the ends themselves
                // (the basis is analytic past [0, 1]): error h²·|w'''|/6 ≤ h²(an)³, 2e-5 at
                // an = 60, plus rounding 1e-16/h.
                let h = 1e-5;
                let d = |u: f64, k: usize| (at(u + h)[k] - at(u - h)[k]) / (2.0 * h);
                for k in 0..4 {
                    let e0 = if k == 1 { 1.0 } else { 0.0 };
                    let e1 = if k == 3 { 1.0 } else { 0.0 };
                    assert!(
                        (d(0.0, k) - e0).abs() < 1e-4 * (1.0 + a * n as f64),
                        "{n} {a} {k}"
                    );
                    assert!(
                        (d(1.0, k) - e1).abs() < 1e-4 * (1.0 + a * n as f64),
                        "{n} {a} {k}"
                    );
                }
                // The mode equation (D² − k²)² w = 0 in the interior, by finite differences
                // with step 1e-2: the fourth difference's error is O(h²)·w⁽⁶⁾.
                let kk = a * n as f64;
                let h = 1e-2;
                for u in [0.3, 0.5, 0.7] {
                    for k in 0..4 {
                        let f = |x: f64| at(x)[k];
                        let d2 = (f(u + h) - 2.0 * f(u) + f(u - h)) / (h * h);
                        let d4 = (f(u + 2.0 * h) - 4.0 * f(u + h) + 6.0 * f(u) - 4.0 * f(u - h)
                            + f(u - 2.0 * h))
                            / h.powi(4);
                        let r = d4 - 2.0 * kk * kk * d2 + kk.powi(4) * f(u);
                        let scale = 1.0 + kk.powi(4) * f(u).abs() + kk.powi(6) * h * h;
                        assert!(r.abs() < 1e-2 * scale, "{n} {a} {u} {k}: {r}");
                    }
                }
            }
        }
    }

    #[test]
    fn position_weights_interpolate_and_reproduce_the_mode_solutions() {
        let knots = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0];
        // The range the sheet mode uses: a·n up to a few (beyond, a mode's weights grow like
        // e^{an/3} between the knots).
        for n in [0, 1, 3, 12, 40] {
            for a in [0.05, 0.1, 0.3] {
                if a * n as f64 > 4.0 {
                    continue;
                }
                for (i, &t) in knots.iter().enumerate() {
                    let w = position_weights(n, a, knots, t);
                    for (k, wk) in w.iter().enumerate() {
                        let e = if k == i { 1.0 } else { 0.0 };
                        assert!((wk - e).abs() < 1e-9, "{n} {a} {i} {k}: {wk}");
                    }
                }
                // The weights reproduce every solution of the mode's equation
                // (D² − k²)² X = 0 from its values at the knots: cosh, sinh and u·cosh, u·sinh
                // of k(u − 1/2) (polynomials up to u³ for n = 0).
                let kk = a * n as f64;
                let solutions: [&dyn Fn(f64) -> f64; 4] = if n == 0 {
                    [&|_| 1.0, &|u| u, &|u| u * u, &|u| u * u * u]
                } else {
                    [
                        &|u| (kk * (u - 0.5)).cosh(),
                        &|u| (kk * (u - 0.5)).sinh(),
                        &|u| u * (kk * (u - 0.5)).cosh(),
                        &|u| u * (kk * (u - 0.5)).sinh(),
                    ]
                };
                for u in [0.05, 0.2, 0.5, 0.8, 0.97] {
                    let w = position_weights(n, a, knots, u);
                    for f in solutions {
                        let x: f64 = knots.iter().zip(w).map(|(&t, wk)| wk * f(t)).sum();
                        assert!((x - f(u)).abs() < 1e-9, "{n} {a} {u}: {x} vs {}", f(u));
                    }
                }
            }
        }
    }
}
