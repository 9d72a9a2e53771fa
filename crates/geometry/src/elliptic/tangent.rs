//! Tangent solves: the derivatives of a solved patch along directions of its condition curves,
//! all directions as one block of right-hand sides.
//!
//! The solution is linear in its condition curves (each mode's coefficients are the mode
//! system's inverse applied to the curves' Fourier coefficients, the remainder is linear in the
//! curves' leftovers), so the derivative of the patch along curve derivatives `Ċ_i` is the
//! patch solved from `Ċ_i` with the same operator and the same condition places. For a batch of
//! `K` directions each mode's system is set up once (its basis, matrix and equilibration, the
//! same [`super::solve_mode`] the patch was solved with) and solved with the `6K` columns of all
//! directions at once; the remainder's cardinal functions are solved once for the batch.

use super::{assemble, condition_series, solve_mode, Condition, PdePatch, SolveOptions};
use crate::curve::{Curve, Domain, SharedCurve};
use crate::fourier::FourierSeries;
use crate::{Error, Result, Vec3};
use nalgebra::DMatrix;
use std::sync::Arc;

/// The periodic curve `Σ c_j C_j(v)`: a derivative of condition curves, such as
/// `(C(p + h) − C(p))/h` of curves affine in a parameter `p`.
#[derive(Debug)]
pub struct TangentCurve {
    parts: Vec<(f64, SharedCurve)>,
}

/// The curve `Σ c_j C_j` of `parts` (periodic curves).
pub fn combination(parts: Vec<(f64, SharedCurve)>) -> SharedCurve {
    Arc::new(TangentCurve { parts })
}

impl Curve for TangentCurve {
    fn domain(&self) -> Domain {
        Domain::Periodic
    }

    fn jet(&self, t: f64, out: &mut [Vec3]) {
        out.iter_mut().for_each(|o| *o = Vec3::zeros());
        let mut buf = [Vec3::zeros(); crate::curve::MAX_ORDER + 1];
        let part = &mut buf[..out.len()];
        for (c, curve) in &self.parts {
            curve.jet(t, part);
            for (o, p) in out.iter_mut().zip(part.iter()) {
                *o += *c * p;
            }
        }
    }

    /// The combination of the parts' exact series, when every part with a non-zero
    /// coefficient has one.
    fn fourier(&self) -> Option<FourierSeries> {
        let series: Vec<(f64, FourierSeries)> = self
            .parts
            .iter()
            .filter(|(c, _)| *c != 0.0)
            .map(|(c, curve)| curve.fourier().map(|f| (*c, f)))
            .collect::<Option<_>>()?;
        let m = series.iter().map(|(_, f)| f.modes()).max().unwrap_or(0);
        let mut a0 = Vec3::zeros();
        let (mut cos, mut sin) = (vec![Vec3::zeros(); m], vec![Vec3::zeros(); m]);
        for (c, f) in &series {
            a0 += *c * f.a0;
            for (n, (a, b)) in f.cos.iter().zip(&f.sin).enumerate() {
                cos[n] += *c * a;
                sin[n] += *c * b;
            }
        }
        FourierSeries::new(a0, cos, sin).ok()
    }
}

impl PdePatch {
    /// The derivatives of this patch along `K` directions of its condition curves:
    /// `directions[k][i]` is the derivative `Ċ_i` of condition `i`'s curve along direction `k`,
    /// and the result's patch `k` is the solution of the conditions `Ċ_i` at this patch's places
    /// with its operator and `options` (the options it was solved with), so that its partials
    /// are the derivatives of this patch's partials. One set-up and one block solve per mode for
    /// all directions (see the module documentation). Rounding aside, each patch is
    /// [`super::solve`] of its conditions; the a-posteriori check of the conditions is not
    /// repeated (the mode systems are this patch's, which passed it).
    pub fn solve_tangents(
        &self,
        directions: &[Vec<SharedCurve>],
        options: &SolveOptions,
    ) -> Result<Vec<PdePatch>> {
        let operator = self.operator();
        let base = self.conditions();
        let nn = operator.half_order();
        let m = self.modes.len() - 1;
        if options.modes != m {
            return Err(Error::invalid(format!(
                "the patch has {m} modes, the options ask for {}",
                options.modes
            ))
            .at("modes"));
        }
        for (k, d) in directions.iter().enumerate() {
            if d.len() != base.len() {
                return Err(Error::invalid(format!(
                    "direction {k} has {} curves, the patch {} conditions",
                    d.len(),
                    base.len()
                )));
            }
        }
        if directions.is_empty() {
            return Ok(Vec::new());
        }
        let samples = if options.samples == 0 {
            (8 * m).max(64).next_power_of_two()
        } else {
            options.samples
        };
        let (series, exact): (Vec<Vec<FourierSeries>>, Vec<Vec<bool>>) = directions
            .iter()
            .map(|d| {
                d.iter()
                    .enumerate()
                    .map(|(i, c)| {
                        condition_series(&**c, m, samples)
                            .map_err(|e| e.at(&format!("conditions[{i}].curve")))
                    })
                    .collect::<Result<Vec<_>>>()
                    .map(|v| v.into_iter().unzip())
            })
            .collect::<Result<Vec<_>>>()?
            .into_iter()
            .unzip();
        let at: Vec<(f64, usize)> = base.iter().map(|c| (c.u, c.derivative)).collect();
        let kk = directions.len();
        let mut modes: Vec<Vec<super::ModeFn>> =
            (0..kk).map(|_| Vec::with_capacity(m + 1)).collect();
        let mut reports = Vec::with_capacity(m + 2);
        for n in 0..=m {
            let mut rhs = DMatrix::<f64>::zeros(2 * nn, 6 * kk);
            for (k, sk) in series.iter().enumerate() {
                for (i, s) in sk.iter().enumerate() {
                    let (c, sn) = if n == 0 {
                        (s.a0, Vec3::zeros())
                    } else {
                        (s.cos[n - 1], s.sin[n - 1])
                    };
                    for j in 0..3 {
                        rhs[(i, 6 * k + j)] = c[j];
                        rhs[(i, 6 * k + 3 + j)] = sn[j];
                    }
                }
            }
            let (f, report) = solve_mode(operator, n, &at, rhs)?;
            for (k, mk) in modes.iter_mut().enumerate() {
                mk.push(f.columns(6 * k, 6));
            }
            reports.push(report);
        }
        let mut cardinal = None;
        directions
            .iter()
            .zip(series)
            .zip(exact)
            .zip(modes)
            .map(|(((d, s), exact), modes)| {
                let conditions = base
                    .iter()
                    .zip(d)
                    .map(|(c, curve)| Condition {
                        u: c.u,
                        derivative: c.derivative,
                        curve: curve.clone(),
                    })
                    .collect();
                let (patch, _, _) = assemble(
                    operator,
                    conditions,
                    &s,
                    &exact,
                    modes,
                    reports.clone(),
                    options,
                    &at,
                    &mut cardinal,
                )?;
                Ok(patch)
            })
            .collect()
    }
}
