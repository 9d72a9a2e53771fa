//! Majorant series: bounds of the derivatives of a composition `F(u(s), v(s))` from bounds of
//! the derivatives of `F` and of `u`, `v` (Faà di Bruno with absolute values).
//!
//! A [`Majorant`] is a power series `Σ_{k≤4} c_k s^k` with non-negative coefficients, truncated
//! after order [`ORDER`]` = 4`. A series `a(s)` is *majorised* by `A(s)` (`a ≪ A`) if
//! `|a_k| ≤ A_k` for every `k ≤ 4` (`|·|` the Euclidean norm for vector coefficients).
//! Sums and products keep the relation: `a ≪ A`, `b ≪ B` give `a + b ≪ A + B` and
//! `a b ≪ A B` (each coefficient of the product is a finite sum of products, and the triangle
//! inequality and `|x y| ≤ |x| |y|` hold term by term; the coefficients of order `≤ 4` of a
//! product depend only on those of its factors, so truncation commutes with both).
//!
//! **The composition bound.** Let `F` be `C⁴` near `(u(σ), v(σ))`, `u`, `v` `C⁴` near `σ`.
//! The Taylor coefficients of order `≤ 4` of `s ↦ F(u(σ + s), v(σ + s))` are those of the
//! formal composition `Σ_{a+b≤4} ∂_u^a ∂_v^b F / (a! b!) · û(s)^a v̂(s)^b`, with
//! `û(s) = Σ_{1≤k≤4} u^{(k)}(σ) s^k / k!` (the chain rule, written as a coefficient identity;
//! `û` has no constant term, so only `a + b ≤ 4` reaches order 4). If `|∂_u^a ∂_v^b F| ≤ M_ab`,
//! `|u^{(k)}| ≤ U_k`, `|v^{(k)}| ≤ V_k` at the points concerned, then `û ≪ Û = Σ U_k s^k/k!`,
//! `v̂ ≪ V̂`, and by the rules above the composition is majorised by
//! `Σ M_ab/(a! b!) Û^a V̂^b` ([`Majorant::compose2`]). Its coefficient `c_k` times `k!` bounds
//! `|d^k/ds^k F(u, v)|` at `σ`; with the `M`, `U`, `V` bounds valid over a whole interval of
//! `σ`, it bounds the derivative over that interval. One variable ([`Majorant::compose1`]) is
//! the case `b = 0`.
//!
//! **Rounding.** Every operation is a sum of products of non-negative numbers, each rounded
//! with a relative error of at most `2⁻⁵³`; the few hundred operations of an order-4
//! composition stay far below the factor `1 + 10⁻¹²` that [`Majorant::derivative`] applies.

/// The highest order kept.
pub const ORDER: usize = 4;

/// `k!` for `k ≤ 4`.
const FACTORIAL: [f64; ORDER + 1] = [1.0, 1.0, 2.0, 6.0, 24.0];

/// The relative allowance for the rounding of a composition.
const ROUNDING: f64 = 1e-12;

/// A truncated power series `Σ_{k≤4} c_k s^k` with non-negative coefficients.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Majorant(pub [f64; ORDER + 1]);

impl Majorant {
    /// The zero series.
    pub fn zero() -> Majorant {
        Majorant([0.0; ORDER + 1])
    }

    /// The constant `c` (`|c|` taken).
    pub fn constant(c: f64) -> Majorant {
        let mut m = Majorant::zero();
        m.0[0] = c.abs();
        m
    }

    /// `Σ_{k≥1} B_k s^k / k!` from bounds `B_k` of the `k`-th derivatives (`bounds[k]`,
    /// `k = 1..=4`; missing or negative entries are taken as `0`/`|B_k|`; `bounds[0]` is
    /// ignored): the majorant of the increment `u(σ + s) − u(σ)`.
    pub fn increment(bounds: &[f64]) -> Majorant {
        let mut m = Majorant::zero();
        for (k, (c, f)) in m.0.iter_mut().zip(FACTORIAL).enumerate().skip(1) {
            *c = bounds.get(k).map_or(0.0, |b| b.abs()) / f;
        }
        m
    }

    /// The coefficient-wise sum.
    pub fn add(&self, other: &Majorant) -> Majorant {
        let mut m = *self;
        for (a, b) in m.0.iter_mut().zip(&other.0) {
            *a += b;
        }
        m
    }

    /// The series times `|c|`.
    pub fn scale(&self, c: f64) -> Majorant {
        Majorant(self.0.map(|x| x * c.abs()))
    }

    /// The product, truncated after order 4.
    pub fn mul(&self, other: &Majorant) -> Majorant {
        let mut m = Majorant::zero();
        for i in 0..=ORDER {
            for j in 0..=ORDER - i {
                m.0[i + j] += self.0[i] * other.0[j];
            }
        }
        m
    }

    /// The `n`-th power, truncated after order 4 (`1` for `n = 0`).
    pub fn pow(&self, n: usize) -> Majorant {
        let mut m = Majorant::constant(1.0);
        for _ in 0..n {
            m = m.mul(self);
        }
        m
    }

    /// `Σ_{a≤4} M_a / a! · u^a` (`m[a]` bounds `|F^{(a)}|`, missing entries `0`); `u` the
    /// majorant of an increment (no constant term).
    pub fn compose1(m: &[f64], u: &Majorant) -> Majorant {
        let mut out = Majorant::zero();
        let mut power = Majorant::constant(1.0);
        for (a, &ma) in m.iter().enumerate().take(ORDER + 1) {
            out = out.add(&power.scale(ma / FACTORIAL[a]));
            power = power.mul(u);
        }
        out
    }

    /// `Σ_{a+b≤4} M_ab / (a! b!) · u^a v^b` (`m[a][b]` bounds `|∂_u^a ∂_v^b F|`); `u`, `v` the
    /// majorants of increments (no constant term).
    pub fn compose2(m: &[[f64; ORDER + 1]; ORDER + 1], u: &Majorant, v: &Majorant) -> Majorant {
        let mut out = Majorant::zero();
        let mut ua = Majorant::constant(1.0);
        for (a, row) in m.iter().enumerate() {
            let mut vb = Majorant::constant(1.0);
            for (b, &mab) in row.iter().enumerate().take(ORDER + 1 - a) {
                out = out.add(&ua.mul(&vb).scale(mab / (FACTORIAL[a] * FACTORIAL[b])));
                vb = vb.mul(v);
            }
            ua = ua.mul(u);
        }
        out
    }

    /// A bound of the `k`-th derivative (`k ≤ 4`) of the majorised function: `k! c_k`, with the
    /// rounding allowance. `+∞` for `k > 4` or a coefficient that is not finite.
    pub fn derivative(&self, k: usize) -> f64 {
        match self.0.get(k) {
            Some(c) if c.is_finite() => c * FACTORIAL[k] * (1.0 + ROUNDING),
            _ => f64::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The largest `|g|` over `n + 1` equal steps of `[a, b]`.
    fn max_on(g: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
        (0..=n)
            .map(|i| g(a + (b - a) * i as f64 / n as f64).abs())
            .fold(0.0, f64::max)
    }

    /// `sin(p(s))`, `p(s) = s³ − 2s² + 3s`, on `s ∈ [0, 1]`: `|sin^{(a)}| ≤ 1`, and
    /// `|p'| ≤ 3`, `|p''| ≤ 4`, `|p'''| = 6`. The fourth derivative in closed form is
    /// compared with the bound: bound ≥ truth, within a factor 6.
    #[test]
    fn sine_of_a_cubic() {
        let p1 = |s: f64| 3.0 * s * s - 4.0 * s + 3.0;
        let p2 = |s: f64| 6.0 * s - 4.0;
        let p3 = 6.0;
        let p = |s: f64| s * s * s - 2.0 * s * s + 3.0 * s;
        // d⁴ sin(p) = sin p (p'^4 − 3p''^2 − 4p'p''') − 6 cos p p'^2 p''   (p⁗ = 0).
        let d4 = |s: f64| {
            let (sn, cs) = p(s).sin_cos();
            sn * (p1(s).powi(4) - 3.0 * p2(s).powi(2) - 4.0 * p1(s) * p3)
                - cs * 6.0 * p1(s).powi(2) * p2(s)
        };
        let truth = max_on(d4, 0.0, 1.0, 20000);
        let u = Majorant::increment(&[0.0, 3.0, 4.0, 6.0, 0.0]);
        let bound = Majorant::compose1(&[1.0; 5], &u).derivative(4);
        eprintln!(
            "sin∘cubic: bound {bound}, truth {truth}, ratio {}",
            bound / truth
        );
        assert!(bound >= truth, "{bound} < {truth}");
        assert!(bound <= 6.0 * truth, "ratio {}", bound / truth);
        // A finite-difference check of the closed form itself.
        let h = 1e-2;
        let s = 0.4;
        let fd = ((p(s + 2.0 * h)).sin() - 4.0 * (p(s + h)).sin() + 6.0 * (p(s)).sin()
            - 4.0 * (p(s - h)).sin()
            + (p(s - 2.0 * h)).sin())
            / h.powi(4);
        assert!(
            (fd - d4(s)).abs() < 1e-2 * (1.0 + d4(s).abs()),
            "{fd} {}",
            d4(s)
        );
    }

    /// `exp(λ s)` through the linear `u = λ s` on `s ∈ [0, 1]`: `|exp^{(a)}| ≤ e^λ` there, and
    /// the bound is exact: `λ⁴ e^λ` (up to the rounding factor).
    #[test]
    fn exponential_of_a_line_is_exact() {
        let lambda = 1.7f64;
        let u = Majorant::increment(&[0.0, lambda]);
        let b = Majorant::compose1(&[lambda.exp(); 5], &u);
        for k in 0..=4 {
            let truth = lambda.powi(k as i32) * lambda.exp();
            assert!(b.derivative(k) >= truth);
            assert!(b.derivative(k) <= truth * (1.0 + 1e-11), "k = {k}");
        }
    }

    /// The quadratic surface `F(u, v) = (u², u v, v²)` along the circle
    /// `(u, v) = (r cos s, r sin s)`: `F(s) = r²(cos², cos sin, sin²)`, whose fourth
    /// derivative is `8 r² (cos 2s, sin 2s, −cos 2s)` (the components are `r²` times
    /// `(1 + cos 2s)/2`, `sin 2s / 2`, `(1 − cos 2s)/2`), of norm `8 r² (1 + cos² 2s)^{1/2}`,
    /// largest (`8√2 r²`) at `s = 0`.
    /// `|F_u| ≤ |(2u, v, 0)| ≤ 2r`, `|F_v| ≤ 2r`, `|F_uu| = 2`, `|F_uv| = 1`, `|F_vv| = 2`,
    /// and `|u^{(k)}|, |v^{(k)}| ≤ r`. Bound ≥ truth, within a factor 8.
    #[test]
    fn quadratic_surface_along_a_circle() {
        let r = 0.8f64;
        let truth = 8.0 * 2f64.sqrt() * r * r;
        // The closed form checked against a fine difference of F.
        let f = |s: f64| {
            let (sn, cs) = s.sin_cos();
            [r * r * cs * cs, r * r * cs * sn, r * r * sn * sn]
        };
        let (s, h) = (0.3f64, 1e-2);
        let mut fd = [0.0; 3];
        for (w, x) in [
            (1.0, 2.0),
            (-4.0, 1.0),
            (6.0, 0.0),
            (-4.0, -1.0),
            (1.0, -2.0),
        ] {
            let y = f(s + x * h);
            for c in 0..3 {
                fd[c] += w * y[c] / h.powi(4);
            }
        }
        let exact = [
            8.0 * r * r * (2.0 * s).cos(),
            8.0 * r * r * (2.0 * s).sin(),
            -8.0 * r * r * (2.0 * s).cos(),
        ];
        for c in 0..3 {
            assert!((fd[c] - exact[c]).abs() < 1e-2, "{fd:?} {exact:?}");
        }
        let mut m = [[0.0; 5]; 5];
        m[0][0] = r * r;
        m[1][0] = 2.0 * r;
        m[0][1] = 2.0 * r;
        m[2][0] = 2.0;
        m[1][1] = 1.0;
        m[0][2] = 2.0;
        let u = Majorant::increment(&[r; 5]);
        let bound = Majorant::compose2(&m, &u, &u).derivative(4);
        eprintln!(
            "quadric on a circle: bound {bound}, truth {truth}, ratio {}",
            bound / truth
        );
        assert!(bound >= truth, "{bound} < {truth}");
        assert!(bound <= 8.0 * truth, "ratio {}", bound / truth);
    }

    #[test]
    fn products_and_powers_truncate() {
        let a = Majorant([1.0, 2.0, 0.0, 0.0, 1.0]);
        let b = a.mul(&a);
        assert_eq!(b.0, [1.0, 4.0, 4.0, 0.0, 2.0]);
        assert_eq!(a.pow(2), b);
        assert_eq!(a.pow(0), Majorant::constant(1.0));
        assert_eq!(
            Majorant([1.0, f64::NAN, 0.0, 0.0, 0.0]).derivative(1),
            f64::INFINITY
        );
        assert_eq!(a.derivative(7), f64::INFINITY);
    }
}
