//! `Wave`: the lateral wave `w(u) d` of fish locomotion added to a new spine (§8.1.3.2), its
//! derivatives and their bounds.

use crate::spec::{SpineWave, WaveKind, MAX_WAVE_TERMS};
use crate::{Error, Result, Vec3};

/// A checked spine wave (§8.1.3.2): `w(u) d`, see [`SpineWave`].
#[derive(Clone, Debug, PartialEq)]
pub struct Wave {
    kind: WaveKind,
    amplitude: Vec<f64>,
    alpha: f64,
    /// `2π ω time`.
    angle: f64,
    phase: f64,
    pub(super) direction: Vec3,
}

impl Wave {
    /// Checks a `wave` table (errors placed inside it: `wave.amplitude`, `wave.direction`).
    pub fn new(spec: &SpineWave) -> Result<Wave> {
        let n = spec.amplitude.len();
        if n == 0 || n > MAX_WAVE_TERMS {
            return Err(Error::invalid(format!(
                "give 1 to {MAX_WAVE_TERMS} coefficients of Ω(u) = a₀ + a₁u + … (got {n})"
            ))
            .at("wave.amplitude"));
        }
        let d = Vec3::new(spec.direction[0], spec.direction[1], spec.direction[2]);
        let len = d.norm();
        if !(len.is_finite() && len > 0.0) {
            return Err(Error::invalid("must be a non-zero vector").at("wave.direction"));
        }
        let angle = 2.0 * std::f64::consts::PI * spec.omega * spec.time;
        if !angle.is_finite() {
            return Err(
                Error::invalid(format!("2π·omega·time must be finite (got {angle})"))
                    .at("wave.omega"),
            );
        }
        Ok(Wave {
            kind: spec.kind,
            amplitude: spec.amplitude.clone(),
            alpha: spec.alpha,
            angle,
            phase: spec.phase,
            direction: d / len,
        })
    }

    /// `dᵏw/duᵏ` at `u` for `k = order` (Leibniz's rule on `Ω(u) g(u)`).
    pub fn derivative(&self, u: f64, order: usize) -> f64 {
        // dʲΩ/duʲ by Horner on the differentiated coefficients.
        let omega = |j: usize| -> f64 {
            let mut acc = 0.0;
            for (i, &a) in self.amplitude.iter().enumerate().skip(j).rev() {
                let falling = ((i + 1 - j)..=i).fold(1.0, |f, m| f * m as f64);
                acc = acc * u + a * falling;
            }
            acc
        };
        // dᵐ/duᵐ of sin(αu + c) is αᵐ sin(αu + c + mπ/2).
        let (arg, factor) = match self.kind {
            WaveKind::Travelling => (self.alpha * u - self.angle + self.phase, 1.0),
            WaveKind::Standing => (
                self.alpha * u + self.phase + std::f64::consts::FRAC_PI_2,
                self.angle.sin(),
            ),
        };
        let (s, c) = arg.sin_cos();
        let g = |m: usize| -> f64 {
            let turn = [s, c, -s, -c][m % 4];
            factor * self.alpha.powi(m as i32) * turn
        };
        let mut binom = 1.0;
        let mut sum = 0.0;
        for j in 0..=order {
            if j > 0 {
                binom = binom * (order + 1 - j) as f64 / j as f64;
            }
            if j < self.amplitude.len() {
                sum += binom * omega(j) * g(order - j);
            }
        }
        sum
    }

    /// A bound of `sup_{u ∈ [0, 1]} |dᵏw/duᵏ|`: Leibniz's rule with `|Ω⁽ʲ⁾| ≤ Σ_i |a_i| i!/(i − j)!`
    /// (`|u| ≤ 1`) and `|g⁽ᵐ⁾| ≤ |factor| αᵐ`.
    pub fn bound(&self, order: usize) -> f64 {
        let factor = match self.kind {
            WaveKind::Travelling => 1.0,
            WaveKind::Standing => self.angle.sin().abs(),
        };
        let omega = |j: usize| -> f64 {
            self.amplitude
                .iter()
                .enumerate()
                .skip(j)
                .map(|(i, a)| a.abs() * ((i + 1 - j)..=i).fold(1.0, |f, m| f * m as f64))
                .sum()
        };
        let mut binom = 1.0;
        let mut sum = 0.0;
        for j in 0..=order {
            if j > 0 {
                binom = binom * (order + 1 - j) as f64 / j as f64;
            }
            sum += binom * omega(j) * factor * self.alpha.abs().powi((order - j) as i32);
        }
        sum * (1.0 + 1e-12)
    }

    /// The lateral displacement `w(u)` along the unit direction.
    pub fn displacement(&self, u: f64) -> f64 {
        self.derivative(u, 0)
    }

    /// The unit direction of the displacement.
    pub fn direction(&self) -> Vec3 {
        self.direction
    }
}
