//! Quadrature rules: composite Gauss–Legendre on intervals, the trapezoid rule on periods.

/// Nodes and weights of a rule on some interval: `∫ f ≈ Σ w_i f(x_i)`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Rule {
    pub nodes: Vec<f64>,
    pub weights: Vec<f64>,
}

/// The `n`-point Gauss–Legendre rule on `[−1, 1]` (exact for polynomials of degree `2n − 1`):
/// nodes are the roots of `P_n`, found by Newton's method from Tricomi's estimate
/// `cos(π(i − 1/4)/(n + 1/2))`; weights `2 / ((1 − x²) P_n'(x)²)`.
pub(crate) fn gauss_legendre(n: usize) -> Rule {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pm = if n == 0 { 0.0 } else { p0 };
            dp = n as f64 * (x * pn - pm) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() <= 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        nodes[i] = -x;
        nodes[n - 1 - i] = x;
        weights[i] = w;
        weights[n - 1 - i] = w;
    }
    if n % 2 == 1 {
        nodes[n / 2] = 0.0;
    }
    Rule { nodes, weights }
}

/// `panels` equal panels of `[a, b]`, each with the `order`-point Gauss–Legendre rule.
pub(crate) fn composite_gauss(a: f64, b: f64, panels: usize, order: usize) -> Rule {
    let base = gauss_legendre(order);
    let h = (b - a) / panels as f64;
    let mut nodes = Vec::with_capacity(panels * order);
    let mut weights = Vec::with_capacity(panels * order);
    for p in 0..panels {
        let mid = a + (p as f64 + 0.5) * h;
        for (x, w) in base.nodes.iter().zip(&base.weights) {
            nodes.push(mid + 0.5 * h * x);
            weights.push(0.5 * h * w);
        }
    }
    Rule { nodes, weights }
}

/// The trapezoid rule on a period `[0, 2π)` with `n` equally spaced nodes (exact for
/// trigonometric polynomials of degree `< n`; spectrally accurate for smooth periodic
/// integrands).
pub(crate) fn periodic_trapezoid(n: usize) -> Rule {
    let h = crate::TAU / n as f64;
    Rule {
        // 2πj/n exactly as written, so row evaluators recognise the standard periodic grid.
        nodes: (0..n).map(|j| crate::TAU * j as f64 / n as f64).collect(),
        weights: vec![h; n],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_is_exact_to_degree_2n_minus_1() {
        for n in 1..=12 {
            let r = gauss_legendre(n);
            assert!(
                (r.weights.iter().sum::<f64>() - 2.0).abs() < 1e-14,
                "n = {n}"
            );
            for d in 0..2 * n {
                let exact = if d % 2 == 1 {
                    0.0
                } else {
                    2.0 / (d as f64 + 1.0)
                };
                let got: f64 = r
                    .nodes
                    .iter()
                    .zip(&r.weights)
                    .map(|(x, w)| w * x.powi(d as i32))
                    .sum();
                assert!((got - exact).abs() < 1e-14, "n = {n}, degree {d}: {got}");
            }
            // Degree 2n is not exact: the rule is not accidentally of higher order.
            let got: f64 = r
                .nodes
                .iter()
                .zip(&r.weights)
                .map(|(x, w)| w * x.powi(2 * n as i32))
                .sum();
            assert!(
                (got - 2.0 / (2.0 * n as f64 + 1.0)).abs() > 1e-12,
                "n = {n}"
            );
        }
        // The 8-point rule of the tables: largest node 0.9602898564975363.
        let r = gauss_legendre(8);
        assert!((r.nodes[7] - 0.960_289_856_497_536_3).abs() < 1e-15);
        assert!((r.weights[7] - 0.101_228_536_290_376_26).abs() < 1e-15);
    }

    #[test]
    fn composite_and_periodic_rules() {
        let r = composite_gauss(0.0, 1.0, 4, 8);
        let got: f64 = r
            .nodes
            .iter()
            .zip(&r.weights)
            .map(|(x, w)| w * x.exp())
            .sum();
        // Rounding of a 32-term sum: a few ulps.
        assert!(
            (got - (1f64.exp() - 1.0)).abs() < 4.0 * f64::EPSILON * got,
            "{got}"
        );
        let r = periodic_trapezoid(16);
        // ∫ e^{cos v} dv = 2π I₀(1).
        let got: f64 = r
            .nodes
            .iter()
            .zip(&r.weights)
            .map(|(x, w)| w * x.cos().exp())
            .sum();
        assert!((got - crate::TAU * 1.266_065_877_752_008_4).abs() < 1e-14);
    }
}
