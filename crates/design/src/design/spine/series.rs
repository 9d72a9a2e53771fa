//! The rotation of a frame-carried spine edit as one Chebyshev series.
//!
//! The rotation-minimising frames of the old and the new spine come from the double-reflection
//! method on [`super::frames`]'s steps (accurate to about `10⁻¹³`). The edited surface uses
//! `R(u) = F̃(u) F(u)ᵀ` through its Chebyshev interpolant on `u ∈ [0, 1]` (`x = 2u − 1`): the
//! frames sampled at the `n + 1` Chebyshev–Lobatto points, `n` doubled from 64 until the
//! coefficients of the last quarter are below `10⁻¹²` of the largest (the rotation of a smooth
//! spine is analytic, so they fall geometrically until the frames' own error). The series
//! *defines* the surface's rotation from then on: its value and its derivatives are those of
//! one polynomial, so the surface's partials are exact derivatives of its points, and
//! `‖R⁽ᵏ⁾(u)‖₂ ≤ 2ᵏ Σ_m ‖c_m⁽ᵏ⁾‖₂` (`|T_m| ≤ 1`, `c⁽ᵏ⁾` the `k`-times differentiated
//! series in `x`) bounds every derivative over the patch, which the certified CAD export
//! needs. Trailing coefficients below `10⁻¹⁴` of the largest
//! (the frames' rounding) are dropped, so that a rotation that does not turn stays constant
//! instead of carrying amplified noise in its derivatives. `R` is orthogonal to about `10⁻¹²`.

use nalgebra::Matrix3;

/// The first number of Chebyshev intervals tried (enough for the smooth spines of practice).
const START: usize = 64;
/// The most intervals tried before the rotation is left to the frames themselves.
const MAX_INTERVALS: usize = 1024;
/// The size of the last quarter of the coefficients, relative to the largest, that ends the
/// doubling.
const TAIL: f64 = 1e-12;
/// Coefficients below this fraction of the largest are rounding of the sampled frames (about
/// `10⁻¹³`) and are dropped from the end of the series.
const NOISE: f64 = 1e-14;
/// Derivatives kept (the certified bound needs the fourth).
const ORDERS: usize = 5;

/// `R` and its first four `u`-derivatives as Chebyshev series in `x = 2u − 1`.
#[derive(Clone, Debug)]
pub(crate) struct RotationSeries {
    series: [Vec<Matrix3<f64>>; ORDERS],
}

/// `Σ a_m T_m` differentiated in `x` (the recurrence `b_{m−1} = b_{m+1} + 2m a_m`, `b_0`
/// halved).
fn differentiated(a: &[Matrix3<f64>]) -> Vec<Matrix3<f64>> {
    let m = a.len();
    if m <= 1 {
        return vec![Matrix3::zeros()];
    }
    let mut b = vec![Matrix3::zeros(); m + 1];
    for k in (1..m).rev() {
        b[k - 1] = b[k + 1] + a[k] * (2.0 * k as f64);
    }
    b[0] /= 2.0;
    b.truncate(m - 1);
    b
}

/// The coefficients of the interpolant of the values at the `n + 1` Chebyshev–Lobatto points
/// `x_j = cos(πj/n)`: a type-I cosine transform, entry by entry through the real FFT of the
/// even extension (`Re Y_m = f_0 + (−1)ᵐ f_n + 2 Σ_{0<j<n} f_j cos(πmj/n)`).
fn coefficients(values: &[Matrix3<f64>]) -> Option<Vec<Matrix3<f64>>> {
    let n = values.len() - 1;
    let fft = realfft::RealFftPlanner::<f64>::new().plan_fft_forward(2 * n);
    let (mut input, mut spectrum) = (fft.make_input_vec(), fft.make_output_vec());
    let mut out = vec![Matrix3::zeros(); n + 1];
    for e in 0..9 {
        for (j, v) in values.iter().enumerate() {
            input[j] = v[e];
            if j > 0 && j < n {
                input[2 * n - j] = v[e];
            }
        }
        fft.process(&mut input, &mut spectrum).ok()?;
        for (m, (o, y)) in out.iter_mut().zip(&spectrum).enumerate() {
            let end = if m == 0 || m == n { 0.5 } else { 1.0 };
            o[e] = y.re * end / n as f64;
        }
    }
    Some(out)
}

/// `u` of the Lobatto point `j` of `n`.
fn lobatto(j: usize, n: usize) -> f64 {
    0.5 * (1.0 + (std::f64::consts::PI * j as f64 / n as f64).cos())
}

impl RotationSeries {
    /// The Chebyshev interpolant of `f` on `[0, 1]` (module docs); `None` if the coefficients
    /// have not settled within [`MAX_INTERVALS`] (a spine whose frames turn too fast, or that
    /// are not smooth).
    pub(crate) fn fit(f: &dyn Fn(f64) -> Matrix3<f64>) -> Option<RotationSeries> {
        let mut n = START;
        let mut values: Vec<Matrix3<f64>> = (0..=n).map(|j| f(lobatto(j, n))).collect();
        loop {
            let c = coefficients(&values)?;
            let largest = c.iter().map(|m| m.norm()).fold(0.0, f64::max);
            let tail = c[3 * n / 4..].iter().map(|m| m.norm()).fold(0.0, f64::max);
            if !largest.is_finite() {
                return None;
            }
            if tail <= TAIL * largest {
                // The coefficients after the last one above the frames' noise are dropped:
                // they carry rounding only, which the derivatives would amplify (`m²` each).
                let keep = c
                    .iter()
                    .rposition(|m| m.norm() > NOISE * largest)
                    .map_or(1, |i| i + 1);
                let mut c = c;
                c.truncate(keep);
                let mut series: [Vec<Matrix3<f64>>; ORDERS] = Default::default();
                series[0] = c;
                for k in 1..ORDERS {
                    series[k] = differentiated(&series[k - 1])
                        .into_iter()
                        .map(|m| m * 2.0)
                        .collect();
                }
                return Some(RotationSeries { series });
            }
            if n >= MAX_INTERVALS {
                return None;
            }
            // The points of `n` are the even points of `2n`: only the odd ones are new.
            n *= 2;
            values = (0..=n)
                .map(|j| {
                    if j % 2 == 0 {
                        values[j / 2]
                    } else {
                        f(lobatto(j, n))
                    }
                })
                .collect();
        }
    }

    /// `R⁽ᵏ⁾(u)` (`k < 5`) by Clenshaw's recurrence.
    pub(crate) fn eval(&self, u: f64, k: usize) -> Matrix3<f64> {
        let a = &self.series[k];
        let x = 2.0 * u - 1.0;
        let (mut b1, mut b2) = (Matrix3::zeros(), Matrix3::zeros());
        for c in a.iter().skip(1).rev() {
            let b0 = b1 * (2.0 * x) - b2 + c;
            b2 = b1;
            b1 = b0;
        }
        b1 * x - b2 + a[0]
    }

    /// A bound of `sup_{u ∈ [0, 1]} ‖R⁽ᵏ⁾(u)‖₂` (`k < 5`): the sum of the coefficients'
    /// spectral norms (their largest singular values, with a relative allowance for the
    /// decomposition's rounding).
    pub(crate) fn bound(&self, k: usize) -> f64 {
        self.series[k]
            .iter()
            .map(|m| m.singular_values().max())
            .sum::<f64>()
            * (1.0 + 1e-12)
    }

    /// The number of coefficients.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.series[0].len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotation about a fixed axis by `θ(u) = 2u + u²`: the series reproduces it and its
    /// derivatives (closed forms through `R' = θ' K R`, `K` the axis' skew matrix), and the
    /// bounds hold on a dense sample.
    #[test]
    fn a_known_rotation_and_its_derivatives() {
        let axis = nalgebra::Vector3::new(1.0, 2.0, 2.0) / 3.0;
        let k = Matrix3::new(
            0.0, -axis.z, axis.y, axis.z, 0.0, -axis.x, -axis.y, axis.x, 0.0,
        );
        let rot = |t: f64| Matrix3::identity() + k * t.sin() + k * k * (1.0 - t.cos());
        let theta = |u: f64| [2.0 * u + u * u, 2.0 + 2.0 * u, 2.0, 0.0, 0.0];
        // R(θ(u)): dR/dθ = K R, so with θ⁗ = θ''' = 0: R' = θ'KR, R'' = (θ'' K + θ'² K²) R,
        // R''' = (3θ'θ'' K² + θ'³ K³) R, R⁗ = (3θ''² K² + 6θ'²θ'' K³ + θ'⁴ K⁴) R.
        let exact = |u: f64, d: usize| {
            let t = theta(u);
            let r = rot(t[0]);
            let (k2, k3, k4) = (k * k, k * k * k, k * k * k * k);
            match d {
                0 => r,
                1 => k * r * t[1],
                2 => (k * t[2] + k2 * t[1].powi(2)) * r,
                3 => (k2 * (3.0 * t[1] * t[2]) + k3 * t[1].powi(3)) * r,
                _ => {
                    (k2 * (3.0 * t[2] * t[2]) + k3 * (6.0 * t[1] * t[1] * t[2]) + k4 * t[1].powi(4))
                        * r
                }
            }
        };
        let s = RotationSeries::fit(&|u| rot(theta(u)[0])).unwrap();
        assert!(s.len() <= 65, "{} coefficients", s.len());
        for d in 0..5 {
            let mut worst = 0.0f64;
            let mut err = 0.0f64;
            for i in 0..=400 {
                let u = i as f64 / 400.0;
                let e = exact(u, d);
                worst = worst.max(e.singular_values().max());
                err = err.max((s.eval(u, d) - e).norm() / (1.0 + e.norm()));
            }
            // The interpolant's error grows by about n² per derivative from 1e-15.
            assert!(err < 1e-14 * 4e3f64.powi(d as i32), "d = {d}: {err}");
            assert!(worst <= s.bound(d), "d = {d}: {worst} > {}", s.bound(d));
            eprintln!("d = {d}: bound {} against the sampled {worst}", s.bound(d));
        }
    }

    /// A rotation with a kink has no settled series.
    #[test]
    fn a_kinked_rotation_is_refused() {
        let kinked = |u: f64| {
            let t = (u - 0.4).abs();
            Matrix3::new(t.cos(), -t.sin(), 0.0, t.sin(), t.cos(), 0.0, 0.0, 0.0, 1.0)
        };
        assert!(RotationSeries::fit(&kinked).is_none());
    }
}
