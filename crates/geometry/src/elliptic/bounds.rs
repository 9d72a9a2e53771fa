//! Bounds of the mode functions' u-derivatives over the whole patch `u ∈ [0, 1]`, the input of
//! certified error bounds (`cad`: spline approximations whose deviation holds everywhere).
//!
//! - Chebyshev basis: a column is `Σ_m c_m T_m(x)`, `x = 2u − 1`, so its `d`-th u-derivative is
//!   `2^d Σ_m c^{(d)}_m T_m(x)` with the differentiated series `c^{(d)}`, and `|T_m| ≤ 1` on
//!   `[−1, 1]`: the sum of the coefficients' sizes bounds it (Euclidean sizes of the `(x, y, z)`
//!   coefficient vectors for a vector-valued column).
//! - Layer basis: `|Σ_k c_k ψ_k^{(d)}| ≤ Σ_k |c_k| sup|ψ_k^{(d)}|` with the bounds of
//!   `LayerBasis::derivative_sups`.
//!
//! Both are exact statements about the stored series; the only other error is rounding in
//! evaluating them (the Chebyshev tails are continued to rounding level when the basis is built).

use super::basis::{cheb_diff, Basis};
use super::{ModeFn, PdePatch};

/// `Σ_{n ≥ first} nᵏ (αₙ² + βₙ²)^{1/2}` for the mode bounds `[αₙ, βₙ]`
/// ([`PdePatch::mode_derivative_bounds`]): with `|a cos nv + b sin nv| ≤ (|a|² + |b|²)^{1/2}`,
/// a bound of `sup|∂_v^k|` of the modes from `first` on (`first = 1`: without the spine).
pub fn mode_sum(bounds: &[[f64; 2]], k: usize, first: usize) -> f64 {
    bounds
        .iter()
        .enumerate()
        .skip(first)
        .map(|(n, [a, b])| (n as f64).powi(k as i32) * a.hypot(*b))
        .sum()
}

impl ModeFn {
    /// A bound of `sup_{u ∈ [0, 1]} |g^{(d)}(u)|` for the vector `g` of columns
    /// `first .. first + 3` (zero if the function has fewer columns).
    fn sup_bound(&self, d: usize, first: usize) -> f64 {
        if first + 3 > self.ncols() {
            return 0.0;
        }
        self.sup_bound_of(d, &[first, first + 1, first + 2])
    }

    /// A bound of `sup_{u ∈ [0, 1]} |g^{(d)}(u)|` for the vector `g` of the given columns (one
    /// column: a scalar function), each coefficient's size the Euclidean norm over the columns.
    fn sup_bound_of(&self, d: usize, cols: &[usize]) -> f64 {
        let norm = |x: &mut dyn Iterator<Item = f64>| x.map(|a| a * a).sum::<f64>().sqrt();
        match &self.basis {
            Basis::Chebyshev { series, .. } => {
                let len = series.iter().map(Vec::len).max().unwrap_or(0);
                let diffed: Vec<Vec<f64>> = cols
                    .iter()
                    .map(|&c| {
                        let mut s = vec![0.0; len];
                        for (k, sk) in series.iter().enumerate() {
                            let w = self.coef[(k, c)];
                            for (a, b) in s.iter_mut().zip(sk) {
                                *a += w * b;
                            }
                        }
                        for _ in 0..d {
                            s = cheb_diff(&s);
                        }
                        s
                    })
                    .collect();
                let m = diffed.iter().map(Vec::len).max().unwrap_or(0);
                let sum: f64 = (0..m)
                    .map(|j| norm(&mut diffed.iter().map(|c| c.get(j).copied().unwrap_or(0.0))))
                    .sum();
                sum * 2f64.powi(d as i32)
            }
            Basis::Layers(_) => {
                let sups = self.basis.layer_derivative_sups(d).unwrap_or_default();
                sups.iter()
                    .enumerate()
                    .map(|(k, s)| norm(&mut cols.iter().map(|&c| self.coef[(k, c)])) * s)
                    .sum()
            }
        }
    }
}

impl PdePatch {
    /// For every mode `n = 0 … M`, bounds `[a, b]` of `sup_{u ∈ [0, 1]} |Aₙ^{(d)}(u)|` and
    /// `|Bₙ^{(d)}(u)|` (Euclidean norms of the vectors), from the stored series (module docs).
    /// `None` when the spectral remainder is active: its `v`-dependence comes from the condition
    /// curves themselves, which carry no derivative bounds.
    pub fn mode_derivative_bounds(&self, d: usize) -> Option<Vec<[f64; 2]>> {
        if self.remainder.is_some() {
            return None;
        }
        Some(self.fourier_mode_bounds(d))
    }

    /// [`PdePatch::mode_derivative_bounds`] of the Fourier part `X̃` alone, with or without a
    /// remainder.
    pub fn fourier_mode_bounds(&self, d: usize) -> Vec<[f64; 2]> {
        self.modes
            .iter()
            .map(|m| [m.sup_bound(d, 0), m.sup_bound(d, 3)])
            .collect()
    }

    /// A bound of `sup |∂_u^d ∂_v^k X̃|` of the Fourier part alone (as
    /// [`PdePatch::partial_bound`], with or without a remainder).
    pub fn fourier_partial_bound(&self, d: usize, k: usize) -> f64 {
        mode_sum(&self.fourier_mode_bounds(d), k, 0)
    }

    /// The active terms `w_i(u) Δ_i(v)` of the spectral remainder, `Δ_i = g_i − fitted_i`, with
    /// bounds of `sup_{u ∈ [0, 1]} |w_i^{(d)}|`, `d = 0 ..= 4`, from the cardinal functions'
    /// stored series (as for the modes). Empty without a remainder.
    pub fn remainder_terms(&self) -> Vec<RemainderTerm> {
        let Some(r) = &self.remainder else {
            return Vec::new();
        };
        (0..self.conditions().len())
            .filter(|&i| r.active[i])
            .map(|i| RemainderTerm {
                condition: i,
                curve: self.conditions()[i].curve.clone(),
                fitted: r.fitted[i].clone(),
                w: std::array::from_fn(|d| r.cardinal.sup_bound_of(d, &[i])),
            })
            .collect()
    }
}

/// One active term `w_i(u) Δ_i(v)` of a patch's spectral remainder ([`PdePatch::remainder_terms`]).
#[derive(Clone, Debug)]
pub struct RemainderTerm {
    /// The condition `i`.
    pub condition: usize,
    /// Its curve `g_i`.
    pub curve: crate::curve::SharedCurve,
    /// `fitted_i = ∂ᵈX̃(u_i, ·)` as a Fourier series.
    pub fitted: crate::fourier::FourierSeries,
    /// Bounds of `sup_{u ∈ [0, 1]} |w_i^{(d)}(u)|` for `d = 0 ..= 4`.
    pub w: [f64; 5],
}

impl PdePatch {
    /// A bound of `sup |∂_u^d ∂_v^k X|` over the whole patch (`u ∈ [0, 1]`, every `v`): with
    /// `|a cos nv + b sin nv| ≤ (|a|² + |b|²)^{1/2}`, `Σ_n n^k (αₙ² + βₙ²)^{1/2}` from
    /// [`PdePatch::mode_derivative_bounds`]. `None` when those are.
    pub fn partial_bound(&self, d: usize, k: usize) -> Option<f64> {
        Some(mode_sum(&self.mode_derivative_bounds(d)?, k, 0))
    }
}

impl PdePatch {
    /// The partials `∂_u^a ∂_v^b X̃(u, v)` of the Fourier part for `a + b ≤ order`: `out[a][b]`
    /// (`∂_v^b` of `Aₙ cos nv + Bₙ sin nv` is `nᵇ` times `Aₙ cos(nv + bπ/2) + Bₙ sin(nv + bπ/2)`).
    pub fn fourier_partials_at(&self, u: f64, v: f64, order: usize) -> Vec<Vec<crate::Vec3>> {
        let mut out: Vec<Vec<crate::Vec3>> = (0..=order)
            .map(|a| vec![crate::Vec3::zeros(); order + 1 - a])
            .collect();
        for (a, row) in out.iter_mut().enumerate() {
            for n in 0..self.modes.len() {
                let (an, bn) = self.mode(n, u, a);
                let (s, c) = (n as f64 * v).sin_cos();
                let mut power = 1.0;
                for (b, x) in row.iter_mut().enumerate() {
                    if n == 0 && b > 0 {
                        break;
                    }
                    let term = match b % 4 {
                        0 => an * c + bn * s,
                        1 => bn * c - an * s,
                        2 => -(an * c + bn * s),
                        _ => an * s - bn * c,
                    };
                    *x += term * power;
                    power *= n as f64;
                }
            }
        }
        out
    }

    /// [`PdePatch::partial_bound`] for every `a + b ≤ order`: `out[a][b] ≥ sup|∂_u^a ∂_v^b X|`
    /// over `u ∈ [0, 1]` and every `v`. `None` with an active remainder.
    pub fn partial_bounds_table(&self, order: usize) -> Option<Vec<Vec<f64>>> {
        (0..=order)
            .map(|a| {
                let bounds = self.mode_derivative_bounds(a)?;
                Some((0..=order - a).map(|b| mode_sum(&bounds, b, 0)).collect())
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use crate::curve::{Ellipse, SharedCurve};
    use crate::elliptic::{solve, Condition, Operator, SolveOptions};
    use crate::Vec3;
    use std::sync::Arc;

    /// The bounds are upper bounds of the derivatives on a dense sample (both bases: the
    /// biharmonic patch with a = 3 puts mode 3+ in the layer basis).
    #[test]
    fn mode_bounds_hold_on_a_dense_sample() {
        for a in [1.0, 3.0] {
            let op = Operator::polyharmonic(2, a).unwrap();
            let circle = |z: f64, r: f64| -> SharedCurve {
                let (a1, a2) = (Vec3::new(r, 0.0, 0.1), Vec3::new(0.0, 0.8 * r, 0.0));
                Arc::new(Ellipse::new(Vec3::new(0.1, 0.0, z), a1, a2).unwrap())
            };
            let conds = vec![
                Condition {
                    u: 0.0,
                    derivative: 0,
                    curve: circle(0.0, 1.0),
                },
                Condition {
                    u: 0.0,
                    derivative: 1,
                    curve: circle(0.5, 0.3),
                },
                Condition {
                    u: 1.0,
                    derivative: 0,
                    curve: circle(2.0, 0.6),
                },
                Condition {
                    u: 1.0,
                    derivative: 1,
                    curve: circle(1.0, -0.2),
                },
            ];
            let patch = solve(&op, conds, &SolveOptions::default()).unwrap();
            for d in 0..6 {
                let bounds = patch.mode_derivative_bounds(d).unwrap();
                for (n, b) in bounds.iter().enumerate() {
                    let mut worst = [0.0f64; 2];
                    for i in 0..=2000 {
                        let u = i as f64 / 2000.0;
                        let (an, bn) = patch.mode(n, u, d);
                        worst[0] = worst[0].max(an.norm());
                        worst[1] = worst[1].max(bn.norm());
                    }
                    for s in 0..2 {
                        assert!(
                            worst[s] <= b[s] * (1.0 + 1e-12) + 1e-12,
                            "a = {a}, d = {d}, mode {n}: sampled {} above the bound {}",
                            worst[s],
                            b[s]
                        );
                    }
                }
            }
        }
    }

    /// The exact partials at a point agree with the surface's own (orders ≤ 2) and with
    /// central differences of the surface's `X_uu`, `X_uv`, `X_vv` for order 3 (error
    /// `O(h²)` with `h = 10⁻⁴`); the global table bounds them.
    #[test]
    fn partials_at_a_point_are_the_surface_s() {
        use crate::surface::Surface;
        let op = Operator::polyharmonic(2, 1.5).unwrap();
        let circle = |z: f64, r: f64| -> SharedCurve {
            let (a1, a2) = (Vec3::new(r, 0.0, 0.2), Vec3::new(0.1, 0.7 * r, 0.0));
            Arc::new(Ellipse::new(Vec3::new(0.1, 0.3 * z, z), a1, a2).unwrap())
        };
        let conds = [(0.0, 0, circle(0.0, 1.0)), (0.0, 1, circle(0.5, 0.3))]
            .into_iter()
            .chain([(1.0, 0, circle(2.0, 0.6)), (1.0, 1, circle(1.0, -0.2))])
            .map(|(u, derivative, curve)| Condition {
                u,
                derivative,
                curve,
            })
            .collect();
        let patch = solve(&op, conds, &SolveOptions::default()).unwrap();
        let table = patch.partial_bounds_table(6).unwrap();
        let h = 1e-4;
        for (u, v) in [(0.3, 1.1), (0.8, 5.0), (0.05, 3.0)] {
            let at = patch.fourier_partials_at(u, v, 6);
            let p = patch.partials(u, v);
            for (x, y) in [
                (at[0][0], p.x),
                (at[1][0], p.xu),
                (at[0][1], p.xv),
                (at[2][0], p.xuu),
                (at[1][1], p.xuv),
                (at[0][2], p.xvv),
            ] {
                assert!((x - y).norm() <= 1e-12 * (1.0 + y.norm()), "{x} {y}");
            }
            let du = |f: fn(&crate::surface::Partials) -> Vec3| {
                (f(&patch.partials(u + h, v)) - f(&patch.partials(u - h, v))) / (2.0 * h)
            };
            let dv = |f: fn(&crate::surface::Partials) -> Vec3| {
                (f(&patch.partials(u, v + h)) - f(&patch.partials(u, v - h))) / (2.0 * h)
            };
            for (x, y) in [
                (at[3][0], du(|p| p.xuu)),
                (at[2][1], du(|p| p.xuv)),
                (at[1][2], du(|p| p.xvv)),
                (at[0][3], dv(|p| p.xvv)),
            ] {
                assert!((x - y).norm() <= 1e-5 * (1.0 + y.norm()), "{x} {y}");
            }
            for (a, row) in at.iter().enumerate() {
                for (b, x) in row.iter().enumerate() {
                    assert!(x.norm() <= table[a][b] * (1.0 + 1e-12), "({a}, {b})");
                }
            }
        }
    }
}
