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
        let _ = (curve, modes, samples);
        todo!("fourier")
    }

    /// The series cut (or zero-padded) to `modes`.
    pub fn truncated(&self, modes: usize) -> Self {
        let _ = modes;
        todo!("fourier")
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
    fn jet(&self, _t: f64, _out: &mut [Vec3]) {
        todo!("fourier")
    }
    fn fourier(&self) -> Option<FourierSeries> {
        Some(self.clone())
    }
}
