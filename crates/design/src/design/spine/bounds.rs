//! The derivative bounds of a `SpineEdited` patch that the certified CAD export uses: the base's
//! mode bounds, the rotation's Chebyshev series and the new spine's hodographs.

use super::SpineEdited;
use crate::curve::Curve;
use crate::elliptic::mode_sum;
use crate::spec::SpineCarry;

impl SpineEdited {
    /// Bounds over the whole patch of `|∂_u⁴X̃|`, `|∂_v⁴X̃|`, `|∂_u∂_v⁴X̃|` and `|X̃|` for
    /// `X̃ = Ã₀ + R D` (`D = X − A₀` the base's modes `n ≥ 1`, `R = I` when translating):
    /// `∂_u⁴X̃ = Ã₀⁗ + Σ_j C(4, j) R⁽ʲ⁾ ∂_u^{4−j}D`, `∂_v⁴X̃ = R ∂_v⁴D`,
    /// `∂_u∂_v⁴X̃ = R' ∂_v⁴D + R ∂_u∂_v⁴D`, with `|∂_u^d ∂_v^k D| ≤ Σ_{n≥1} nᵏ (αₙ² + βₙ²)^{1/2}`
    /// (the base's mode bounds), `‖R⁽ʲ⁾‖` from its Chebyshev series ([`RotationSeries`]) and
    /// `|Ã₀⁽ᵏ⁾|` from the Bézier curve's hodographs plus the wave's bound. `None` when the base
    /// has an active spectral remainder or the frames have no settled series (the CAD export
    /// then samples the patch).
    pub fn derivative_sums(&self) -> Option<[f64; 4]> {
        let modes: Vec<Vec<[f64; 2]>> = (0..=4)
            .map(|d| self.base.mode_derivative_bounds(d))
            .collect::<Option<_>>()?;
        let radial = |d: usize, k: usize| mode_sum(&modes[d], k, 1);
        let r: [f64; 5] = match (self.carry, &self.series) {
            (SpineCarry::Translate, _) => [1.0, 0.0, 0.0, 0.0, 0.0],
            (SpineCarry::Frame, Some(s)) => std::array::from_fn(|k| s.bound(k)),
            (SpineCarry::Frame, None) => return None,
        };
        let mut spine = [0.0; 5];
        if !self.spine.derivative_bounds(0.0, 1.0, &mut spine) {
            return None;
        }
        if let Some(w) = &self.wave {
            for (k, x) in spine.iter_mut().enumerate() {
                *x += w.bound(k);
            }
        }
        const BINOMIAL: [f64; 5] = [1.0, 4.0, 6.0, 4.0, 1.0];
        let mu4 = spine[4]
            + (0..5)
                .map(|j| BINOMIAL[j] * r[j] * radial(4 - j, 0))
                .sum::<f64>();
        let mv4 = r[0] * radial(0, 4);
        let mu1v4 = r[1] * radial(0, 4) + r[0] * radial(1, 4);
        let size = spine[0] + r[0] * radial(0, 0);
        let sums = [mu4, mv4, mu1v4, size];
        sums.iter().all(|x| x.is_finite()).then_some(sums)
    }
}
