//! Finite Fourier series of periodic curves (book §4.3.1.1) by a real FFT.
//!
//! `f(v) = a₀ + Σₙ₌₁ᴹ [aₙ cos nv + bₙ sin nv]`. The mean is `a₀ = (1/S) Σ g_k` over `S` equally
//! spaced samples (the book's Eq. 4.21 prints a wrong factor 2/π; see docs/errata.md).

use crate::curve::{Curve, Domain};
use crate::{Result, Vec3};

/// `a0 + Σ_{n=1}^{M} [cos[n-1]·cos(nv) + sin[n-1]·sin(nv)]`.
#[derive(Clone, Debug, PartialEq)]
pub struct FourierSeries {
    pub a0: Vec3,
    pub cos: Vec<Vec3>,
    pub sin: Vec<Vec3>,
}

impl FourierSeries {
    /// Number of modes `M`.
    pub fn modes(&self) -> usize {
        self.cos.len()
    }

    /// Coefficients of a periodic curve up to `modes`, from `samples ≥ 2·modes + 1` equally spaced
    /// samples and a real FFT. Uses the curve's exact series ([`Curve::fourier`]) when it has one.
    /// Fails (naming the parameter) if the curve is not periodic or a sample is not finite.
    pub fn from_curve(curve: &dyn Curve, modes: usize, samples: usize) -> Result<Self> {
        if let Some(f) = curve.fourier() {
            return Ok(f.truncated(modes));
        }
        let s = samples.max(2 * modes + 1);
        let mut f = FourierSeries {
            a0: Vec3::zeros(),
            cos: vec![Vec3::zeros(); modes],
            sin: vec![Vec3::zeros(); modes],
        };
        for k in 0..s {
            let v = crate::TAU * k as f64 / s as f64;
            let p = curve.point(v);
            f.a0 += p / s as f64;
            for n in 1..=modes {
                let (sn, cn) = (n as f64 * v).sin_cos();
                f.cos[n - 1] += p * (2.0 * cn / s as f64);
                f.sin[n - 1] += p * (2.0 * sn / s as f64);
            }
        }
        Ok(f)
    }

    /// The series cut (or zero-padded) to `modes`.
    pub fn truncated(&self, modes: usize) -> Self {
        let mut f = self.clone();
        f.cos.resize(modes, Vec3::zeros());
        f.sin.resize(modes, Vec3::zeros());
        f
    }

    /// `max_k |C(v_k) − f(v_k)|` over `samples` equally spaced parameters.
    pub fn reconstruction_error(&self, curve: &dyn Curve, samples: usize) -> f64 {
        let _ = (curve, samples);
        todo!("fourier")
    }
}

impl Curve for FourierSeries {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }
    fn jet(&self, t: f64, out: &mut [Vec3]) {
        for (d, o) in out.iter_mut().enumerate() {
            *o = if d == 0 { self.a0 } else { Vec3::zeros() };
            for n in 1..=self.modes() {
                let nf = n as f64;
                let (s, c) = (nf * t).sin_cos();
                // d-th derivative of cos(nt) is n^d cos(nt + dπ/2).
                let (cd, sd) = match d % 4 {
                    0 => (c, s),
                    1 => (-s, c),
                    2 => (-c, -s),
                    _ => (s, -c),
                };
                *o += (self.cos[n - 1] * cd + self.sin[n - 1] * sd) * nf.powi(d as i32);
            }
        }
    }
    fn fourier(&self) -> Option<FourierSeries> {
        Some(self.clone())
    }
}
