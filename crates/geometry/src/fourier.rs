//! Finite Fourier series of periodic curves (book §4.3.1.1) by a real FFT.
//!
//! `f(v) = a₀ + Σₙ₌₁ᴹ [aₙ cos nv + bₙ sin nv]`. The mean is `a₀ = (1/S) Σ g_k` over `S` equally
//! spaced samples (the book's Eq. 4.21 prints a wrong factor 2/π; see docs/errata.md).

use crate::check::{finite3, finite_points};
use crate::curve::{Curve, Domain};
use crate::{Error, Result, Vec3, TAU};

/// Largest number of modes [`FourierSeries::from_curve`] accepts.
pub const MAX_MODES: usize = 1 << 20;
/// Largest number of samples [`FourierSeries::from_curve`] accepts.
pub const MAX_SAMPLES: usize = 1 << 24;

/// `a0 + Σ_{n=1}^{M} [cos[n-1]·cos(nv) + sin[n-1]·sin(nv)]`.
#[derive(Clone, Debug, PartialEq)]
pub struct FourierSeries {
    /// The mean `a₀`.
    pub a0: Vec3,
    /// `aₙ` for `n = 1 … M`: `cos[n − 1]` multiplies `cos nv`.
    pub cos: Vec<Vec3>,
    /// `bₙ` for `n = 1 … M`: `sin[n − 1]` multiplies `sin nv` (as long as `cos`).
    pub sin: Vec<Vec3>,
}

impl FourierSeries {
    /// The series `a0 + Σ cos[n-1]·cos(nv) + sin[n-1]·sin(nv)`; the shorter of `cos` and `sin`
    /// is padded with zeros. Every coefficient must be finite; errors are placed as in the
    /// design file's `fourier` table: `a0[c]`, `cos[n][c]`, `sin[n][c]`.
    pub fn new(a0: Vec3, mut cos: Vec<Vec3>, mut sin: Vec<Vec3>) -> Result<Self> {
        finite3(&a0, "a0")?;
        finite_points(&cos, "cos")?;
        finite_points(&sin, "sin")?;
        let m = cos.len().max(sin.len());
        cos.resize(m, Vec3::zeros());
        sin.resize(m, Vec3::zeros());
        Ok(FourierSeries { a0, cos, sin })
    }

    /// Number of modes `M`.
    pub fn modes(&self) -> usize {
        self.cos.len()
    }

    /// Coefficients of a periodic curve up to `modes`, from `samples ≥ 2·modes + 1` equally spaced
    /// samples and a real FFT. Uses the curve's exact series ([`Curve::fourier`]) when it has one.
    /// Fails (naming the parameter) if the curve is not periodic or a sample is not finite, or if
    /// `modes > MAX_MODES` or `samples > MAX_SAMPLES`.
    ///
    /// With `g_k = C(v_k)`, `v_k = 2πk/S` and the discrete transform `G_n = Σ_k g_k e^{−i n v_k}`
    /// (the integrals of Eqs. 4.21–4.23 by the trapezoidal rule): `a₀ = G₀/S` (the mean), `aₙ = (2/S) Re Gₙ`,
    /// `bₙ = −(2/S) Im Gₙ`. `samples = 0` picks `S = max(64, 8·modes)` rounded up to a power of
    /// two. Modes above `S/2` alias, so the result is exact only for curves whose series ends
    /// below `S − modes`.
    pub fn from_curve(curve: &dyn Curve, modes: usize, samples: usize) -> Result<Self> {
        if modes > MAX_MODES {
            return Err(Error::invalid(format!(
                "modes = {modes} is too large (at most {MAX_MODES})"
            )));
        }
        if samples > MAX_SAMPLES {
            return Err(Error::invalid(format!(
                "samples = {samples} is too large (at most {MAX_SAMPLES})"
            )));
        }
        if let Some(exact) = curve.fourier() {
            return Ok(exact.truncated(modes));
        }
        if let Domain::Interval(a, b) = curve.domain() {
            return Err(Error::invalid(format!(
                "the curve lives on the interval [{a}, {b}]; a Fourier series needs a periodic curve"
            )));
        }
        let s = if samples == 0 {
            (8 * modes).max(64).next_power_of_two()
        } else {
            samples
        };
        if s < 2 * modes + 1 {
            return Err(Error::invalid(format!(
                "samples = {s}: {modes} modes need at least 2·modes + 1 = {} samples",
                2 * modes + 1
            )));
        }
        let mut values = Vec::with_capacity(s);
        for k in 0..s {
            let v = TAU * k as f64 / s as f64;
            let p = curve.point(v);
            if !p.iter().all(|c| c.is_finite()) {
                return Err(Error::invalid(format!(
                    "the curve is not finite at v = {v}: ({}, {}, {})",
                    p.x, p.y, p.z
                )));
            }
            values.push(p);
        }
        let mut planner = realfft::RealFftPlanner::<f64>::new();
        let r2c = planner.plan_fft_forward(s);
        let mut input = r2c.make_input_vec();
        let mut spectrum = r2c.make_output_vec();
        let mut out = FourierSeries {
            a0: Vec3::zeros(),
            cos: vec![Vec3::zeros(); modes],
            sin: vec![Vec3::zeros(); modes],
        };
        let scale = 2.0 / s as f64;
        for c in 0..3 {
            for (x, p) in input.iter_mut().zip(&values) {
                *x = p[c];
            }
            r2c.process(&mut input, &mut spectrum)
                .map_err(|e| Error::invalid(format!("FFT of {s} samples failed: {e}")))?;
            out.a0[c] = spectrum[0].re / s as f64;
            for (n, g) in spectrum.iter().enumerate().skip(1).take(modes) {
                out.cos[n - 1][c] = scale * g.re;
                out.sin[n - 1][c] = -scale * g.im;
            }
        }
        Ok(out)
    }

    /// The series cut (or zero-padded) to `modes`.
    pub fn truncated(&self, modes: usize) -> Self {
        let mut cos = self.cos.clone();
        let mut sin = self.sin.clone();
        cos.resize(modes, Vec3::zeros());
        sin.resize(modes, Vec3::zeros());
        FourierSeries {
            a0: self.a0,
            cos,
            sin,
        }
    }

    /// `max_k |C(v_k) − f(v_k)|` over `samples` equally spaced parameters `v_k = 2πk/samples`
    /// (`samples = 0` counts as 1).
    pub fn reconstruction_error(&self, curve: &dyn Curve, samples: usize) -> f64 {
        let s = samples.max(1);
        (0..s)
            .map(|k| {
                let v = TAU * k as f64 / s as f64;
                (curve.point(v) - self.point(v)).norm()
            })
            .fold(0.0, f64::max)
    }
}

/// `sup_θ |a cos θ + b sin θ|`: the largest singular value of the 3 × 2 matrix `[a b]`, the
/// root of the larger eigenvalue `(p + q)/2 + (((p − q)/2)² + r²)^{1/2}` of its Gram matrix
/// `[[p, r], [r, q]]` (`p = |a|²`, `q = |b|²`, `r = a·b`); at most `(p + q)^{1/2}`, which is
/// returned if rounding ever puts the eigenvalue above it.
pub fn mode_size(a: &Vec3, b: &Vec3) -> f64 {
    let (p, q, r) = (a.norm_squared(), b.norm_squared(), a.dot(b));
    let top = 0.5 * (p + q) + (0.25 * (p - q) * (p - q) + r * r).sqrt();
    let cap = (p + q).sqrt();
    if top.is_finite() {
        top.sqrt().min(cap)
    } else {
        a.norm().hypot(b.norm())
    }
}

impl Curve for FourierSeries {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    /// `f⁽ᵏ⁾(v) = Σ nᵏ [aₙ cos(nv + kπ/2) + bₙ sin(nv + kπ/2)]`, with `cos nv`, `sin nv` from the
    /// angle-addition recurrence.
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        let v = crate::curve::reduce_periodic(t);
        for o in out.iter_mut() {
            *o = Vec3::zeros();
        }
        if out.is_empty() {
            return;
        }
        out[0] = self.a0;
        let (s1, c1) = v.sin_cos();
        let (mut s, mut c) = (s1, c1);
        for (i, (a, b)) in self.cos.iter().zip(&self.sin).enumerate() {
            let n = (i + 1) as f64;
            if i > 0 && i % 16 == 0 {
                // Refresh the recurrence now and then to keep its rounding at a few ε.
                (s, c) = (n * v).sin_cos();
            }
            let mut nk = 1.0;
            for (k, o) in out.iter_mut().enumerate() {
                let (ck, sk) = match k % 4 {
                    0 => (c, s),
                    1 => (-s, c),
                    2 => (-c, -s),
                    _ => (s, -c),
                };
                *o += (a * ck + b * sk) * nk;
                nk *= n;
            }
            (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
        }
    }
    fn fourier(&self) -> Option<FourierSeries> {
        Some(self.clone())
    }
    /// `|aₙ cos θ + bₙ sin θ| ≤ σₙ`, the largest singular value of `[aₙ bₙ]` ([`mode_size`]),
    /// so `|f⁽ᵏ⁾| ≤ [k = 0] |a₀| + Σ nᵏ σₙ` everywhere (attained by an ellipse).
    fn derivative_bounds(&self, t0: f64, t1: f64, out: &mut [f64]) -> bool {
        if t0.partial_cmp(&t1) != Some(std::cmp::Ordering::Less) {
            return false;
        }
        for (k, o) in out.iter_mut().enumerate() {
            let mut sum = if k == 0 { self.a0.norm() } else { 0.0 };
            for (i, (a, b)) in self.cos.iter().zip(&self.sin).enumerate() {
                sum += ((i + 1) as f64).powi(k as i32) * mode_size(a, b);
            }
            *o = sum * (1.0 + crate::curve::BOUND_ROUNDING);
        }
        out.iter().all(|o| o.is_finite())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::curve::BSpline;

    /// A curve given by a closure, without an exact series (forces sampling).
    struct Sampled<F: Fn(f64) -> Vec3 + Send + Sync>(F, Domain);
    impl<F: Fn(f64) -> Vec3 + Send + Sync> std::fmt::Debug for Sampled<F> {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "Sampled")
        }
    }
    impl<F: Fn(f64) -> Vec3 + Send + Sync> Curve for Sampled<F> {
        fn domain(&self) -> Domain {
            self.1
        }
        fn jet(&self, t: f64, out: &mut [Vec3]) {
            out[0] = (self.0)(t);
            for o in out.iter_mut().skip(1) {
                *o = Vec3::new(f64::NAN, f64::NAN, f64::NAN);
            }
        }
    }

    fn trig() -> FourierSeries {
        FourierSeries {
            a0: Vec3::new(0.5, -1.0, 2.0),
            cos: vec![
                Vec3::new(1.0, 0.0, 0.3),
                Vec3::new(0.0, 0.25, -0.1),
                Vec3::zeros(),
                Vec3::new(0.01, 0.02, 0.03),
            ],
            sin: vec![
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(-0.2, 0.0, 0.05),
                Vec3::new(0.1, 0.1, 0.1),
                Vec3::new(0.0, -0.04, 0.0),
            ],
        }
    }

    fn direct(f: &FourierSeries, v: f64) -> Vec3 {
        let mut p = f.a0;
        for n in 1..=f.modes() {
            let x = n as f64 * v;
            p += f.cos[n - 1] * x.cos() + f.sin[n - 1] * x.sin();
        }
        p
    }

    #[test]
    fn trig_polynomial_is_recovered() {
        let f = trig();
        let curve = Sampled(|v| direct(&trig(), v), Domain::Periodic);
        for (modes, samples) in [(4, 9), (4, 16), (6, 0), (10, 37)] {
            let g = FourierSeries::from_curve(&curve, modes, samples).unwrap();
            assert_eq!(g.modes(), modes);
            let want = f.truncated(modes);
            assert!((g.a0 - want.a0).norm() < 1e-15, "a0 {:?}", g.a0);
            for n in 0..modes {
                assert!((g.cos[n] - want.cos[n]).norm() < 2e-15, "cos {n}");
                assert!((g.sin[n] - want.sin[n]).norm() < 2e-15, "sin {n}");
            }
        }
        // Truncating below the content.
        let g = FourierSeries::from_curve(&curve, 2, 64).unwrap();
        let want = f.truncated(2);
        assert_eq!(g.modes(), 2);
        assert!((g.a0 - f.a0).norm() < 1e-15);
        for n in 0..2 {
            assert!((g.cos[n] - want.cos[n]).norm() < 2e-15, "cos {n}");
            assert!((g.sin[n] - want.sin[n]).norm() < 2e-15, "sin {n}");
        }
    }

    #[test]
    fn formula_curves_are_analysed_by_sampling() {
        let f = crate::curve::Formula::new(
            "1 + cos(v) - 0.25*sin(3*v)",
            "2*sin(v) + cos(v)^2",
            "0.5",
            Domain::Periodic,
        )
        .unwrap();
        assert!(f.fourier().is_none());
        let g = FourierSeries::from_curve(&f, 4, 0).unwrap();
        // cos² v = 1/2 + cos(2v)/2.
        let want = FourierSeries {
            a0: Vec3::new(1.0, 0.5, 0.5),
            cos: vec![
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 0.5, 0.0),
                Vec3::zeros(),
                Vec3::zeros(),
            ],
            sin: vec![
                Vec3::new(0.0, 2.0, 0.0),
                Vec3::zeros(),
                Vec3::new(-0.25, 0.0, 0.0),
                Vec3::zeros(),
            ],
        };
        assert!((g.a0 - want.a0).norm() < 1e-15);
        for n in 0..4 {
            assert!(
                (g.cos[n] - want.cos[n]).norm() < 2e-15,
                "cos {n}: {:?}",
                g.cos[n]
            );
            assert!(
                (g.sin[n] - want.sin[n]).norm() < 2e-15,
                "sin {n}: {:?}",
                g.sin[n]
            );
        }
        assert!(g.reconstruction_error(&f, 100) < 1e-14);
    }

    #[test]
    fn fft_matches_direct_sums() {
        let ctrl: Vec<Vec3> = (0..7)
            .map(|i| {
                let x = i as f64;
                Vec3::new(x.cos() * 2.0, (2.0 * x).sin(), 0.1 * x * x)
            })
            .collect();
        let s = BSpline::periodic(3, ctrl, None).unwrap();
        let (m, n_s) = (12, 50);
        let f = FourierSeries::from_curve(&s, m, n_s).unwrap();
        let pts: Vec<Vec3> = (0..n_s)
            .map(|k| s.point(TAU * k as f64 / n_s as f64))
            .collect();
        let size = pts.iter().map(|p| p.norm()).fold(0.0, f64::max);
        let mean = pts.iter().sum::<Vec3>() / n_s as f64;
        assert!((f.a0 - mean).norm() < 1e-15 * size * 8.0);
        for n in 1..=m {
            let (mut a, mut b) = (Vec3::zeros(), Vec3::zeros());
            for (k, p) in pts.iter().enumerate() {
                let x = n as f64 * TAU * k as f64 / n_s as f64;
                a += p * x.cos();
                b += p * x.sin();
            }
            a *= 2.0 / n_s as f64;
            b *= 2.0 / n_s as f64;
            // Both are sums of S terms of size ≤ |C|: rounding ~ ε·√S·|C| each.
            let tol = 16.0 * f64::EPSILON * size;
            assert!(
                (f.cos[n - 1] - a).norm() < tol,
                "a_{n}: {:?} vs {a:?}",
                f.cos[n - 1]
            );
            assert!((f.sin[n - 1] - b).norm() < tol, "b_{n}");
        }
    }

    #[test]
    fn reconstruction_error_falls_with_modes() {
        let ctrl: Vec<Vec3> = (0..9)
            .map(|i| {
                let x = i as f64 * TAU / 9.0;
                Vec3::new(
                    x.cos() * (1.0 + 0.3 * (3.0 * x).cos()),
                    x.sin(),
                    0.2 * (2.0 * x).sin(),
                )
            })
            .collect();
        let s = BSpline::periodic(5, ctrl, None).unwrap();
        let errs: Vec<f64> = [4usize, 8, 16, 32]
            .iter()
            .map(|&m| {
                FourierSeries::from_curve(&s, m, 0)
                    .unwrap()
                    .reconstruction_error(&s, 1000)
            })
            .collect();
        // A C⁴ quintic spline: |coefficients| ~ n⁻⁶, so the max error falls like M⁻⁵ once past
        // the control-polygon scale; require at least a factor 8 per doubling.
        for w in errs.windows(2) {
            assert!(w[1] < w[0] / 8.0, "{errs:?}");
        }
        assert!(errs[3] < 1e-5, "{errs:?}");
    }

    #[test]
    fn jet_is_exact() {
        let f = trig();
        for &v in &[0.0, 0.7, 3.0, -2.0, 40.0] {
            let mut out = [Vec3::zeros(); 9];
            f.jet(v, &mut out);
            for (k, o) in out.iter().enumerate() {
                let mut want = if k == 0 { f.a0 } else { Vec3::zeros() };
                for n in 1..=f.modes() {
                    let nf = n as f64;
                    let x = nf * v + k as f64 * std::f64::consts::FRAC_PI_2;
                    want += (f.cos[n - 1] * x.cos() + f.sin[n - 1] * x.sin()) * nf.powi(k as i32);
                }
                // Rounding of the phase n·v (|v| up to 40) and of the recurrence.
                let tol = 1e-13 * 4f64.powi(k as i32) * (1.0 + v.abs());
                assert!((o - want).norm() < tol, "k {k} v {v}: {o:?} vs {want:?}");
            }
        }
        // Long series: recurrence stays accurate.
        let long = FourierSeries {
            a0: Vec3::zeros(),
            cos: (1..=200)
                .map(|n| Vec3::new(1.0 / (n * n) as f64, 0.0, 0.0))
                .collect(),
            sin: (1..=200)
                .map(|n| Vec3::new(0.0, 1.0 / (n * n) as f64, 0.0))
                .collect(),
        };
        let v = 1.234;
        let want = direct(&long, v);
        assert!((long.point(v) - want).norm() < 1e-14);
    }

    #[test]
    fn errors() {
        let open = Sampled(|v| Vec3::new(v, 0.0, 0.0), Domain::Interval(0.0, 1.0));
        assert!(FourierSeries::from_curve(&open, 3, 16).is_err());
        let c = Sampled(|v| Vec3::new(v.cos(), 0.0, 0.0), Domain::Periodic);
        let e = FourierSeries::from_curve(&c, 8, 16)
            .unwrap_err()
            .to_string();
        assert!(e.contains("samples = 16"), "{e}");
        let nan = Sampled(
            |v| Vec3::new(if v > 3.0 { f64::NAN } else { 0.0 }, 0.0, 0.0),
            Domain::Periodic,
        );
        let e = FourierSeries::from_curve(&nan, 2, 8)
            .unwrap_err()
            .to_string();
        assert!(e.contains("v = 3.14159"), "{e}");
        assert!(FourierSeries::from_curve(&c, usize::MAX, 0).is_err());
        assert!(FourierSeries::from_curve(&c, 3, usize::MAX).is_err());
        let inf = Sampled(|_| Vec3::new(0.0, f64::INFINITY, 0.0), Domain::Periodic);
        assert!(FourierSeries::from_curve(&inf, 2, 8).is_err());
        // The exact path ignores samples.
        let e = crate::curve::Ellipse::circle(Vec3::zeros(), 1.0, Vec3::z()).unwrap();
        let f = FourierSeries::from_curve(&e, 3, 0).unwrap();
        assert_eq!(f.modes(), 3);
        assert_eq!(f.cos[0], e.axis1);
        assert_eq!(f.cos[2], Vec3::zeros());
    }

    #[test]
    fn new_pads_and_refuses_non_finite_coefficients() {
        let f = FourierSeries::new(Vec3::x(), vec![Vec3::y()], vec![]).unwrap();
        assert_eq!(f.sin, vec![Vec3::zeros()]);
        assert_eq!(f.modes(), 1);
        let bad = Vec3::new(0.0, f64::INFINITY, 0.0);
        let e = |a0, cos, sin| FourierSeries::new(a0, cos, sin).unwrap_err().to_string();
        assert_eq!(e(bad, vec![], vec![]), "a0[1]: must be finite (got inf)");
        assert_eq!(
            e(Vec3::x(), vec![Vec3::x(), bad], vec![]),
            "cos[1][1]: must be finite (got inf)"
        );
        assert_eq!(
            e(Vec3::x(), vec![], vec![bad]),
            "sin[0][1]: must be finite (got inf)"
        );
    }
}

#[cfg(test)]
mod bound_tests {
    use super::*;
    use crate::curve::testutil::check_bounds;

    /// The bounds hold on random intervals, and over a whole period they are within
    /// `(2N)^{1/2}` of the sampled maximum, `N` the number of non-zero terms: the maximum is at
    /// least the root mean square `(Σ n²ᵏ (|aₙ|² + |bₙ|²)/2)^{1/2}` (Parseval), and
    /// `Σ nᵏ σₙ ≤ Σ nᵏ (|aₙ|² + |bₙ|²)^{1/2} ≤ N^{1/2} (Σ n²ᵏ (|aₙ|² + |bₙ|²))^{1/2}`
    /// (Cauchy–Schwarz).
    #[test]
    fn bounds_hold_and_are_within_the_rms_factor() {
        let f = FourierSeries {
            a0: Vec3::new(0.1, 0.0, 0.5),
            cos: vec![
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 0.2, 0.1),
                Vec3::new(0.05, 0.0, 0.0),
            ],
            sin: vec![
                Vec3::new(0.0, 0.9, 0.0),
                Vec3::new(0.1, 0.0, 0.0),
                Vec3::new(0.0, 0.0, 0.08),
            ],
        };
        check_bounds(&f, 11, 40, 2.0);
        let mut b = [0.0; 5];
        assert!(f.derivative_bounds(0.0, TAU, &mut b));
        for (k, bk) in b.iter().enumerate() {
            let seen = (0..4000)
                .map(|i| f.derivative(TAU * i as f64 / 4000.0, k).norm())
                .fold(0.0, f64::max);
            let n: f64 = if k == 0 { 4.0 } else { 3.0 };
            eprintln!("fourier k = {k}: bound {bk}, sampled {seen}");
            assert!(seen <= *bk * (1.0 + 1e-12));
            assert!(*bk <= (2.0 * n).sqrt() * seen, "{k}: {bk} vs {seen}");
        }
    }
}
