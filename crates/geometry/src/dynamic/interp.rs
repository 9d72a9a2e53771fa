//! Interpolating dynamic PDE curves (paper §4): a Hermite initial curve through the end points with
//! the end tangents, pulled through interior points by attraction forces
//! `F(u, t) = k Σ_i (p_i − C(u_i, t)) g(u, u_i, ε)`.
//!
//! The paper's forces alone leave the settled curve away from the points (the steady state
//! balances the force against the bending stiffness, so a misfit always remains). This module
//! removes the misfit by updating the forces from it: the force of point `i` is
//! `k (p_i + q_i − C(u_i, t)) g(u, u_i, ε)`, and each time the damped curve has settled (largest
//! nodal speed below a threshold) the offsets are updated, `q_i ← q_i + (p_i − C(u_i))`. At the
//! steady state the misfit `e` obeys `e ← (I + M)^{−1} e`, where `M` (the static response at the
//! points to unit offsets, times `k`) is positive definite, so the misfit decreases geometrically;
//! the run stops when every distance is below the tolerance.
//!
//! Damping: with the paper's `A = 0` the curve oscillates for ever, so [`Interpolation::damping`]
//! defaults to 2 (the lowest bending mode of `D = 0.01` has `ω₁ ≈ 4.73² √D ≈ 2.2`). The averaged
//! scheme does not damp stiff high-frequency modes (a mode with `ωΔt ≫ 1` loses only a factor
//! `≈ 1 − 2A/(ω²Δt)` per step); here they are hardly excited, because the Hermite initial curve
//! already meets the end conditions and the kernel forces are C², so the speed criterion is met
//! without any filtering. Convergence of the offsets is linear: on the §4 data with the
//! paper's `k = 500`, `ε = 0.01` the first settled misfit is about 11 units, the first updates
//! roughly halve it, and the slowest mode then shrinks by only about 8 % per update (19 updates
//! reach 1e-3 of the data size; tighter tolerances need many more, a larger `k` speeds this up).
//!
//! The parameters `u_i` start from the chord length of the data polygon, rounded to grid nodes so
//! that `C(u_i, t)` is a nodal value of the scheme and the reported distances are exact for the
//! discrete curve. [`ParamMode`] chooses whether they stay fixed or follow the paper's
//! definition (Eq. 10: `u_p` is the parameter of the point of the curve closest to `p`), taken
//! as the closest grid node `u_j`, `2 ≤ j ≤ J − 2`, of the current curve, either after every
//! time step or only when the curve has settled and the forces are updated. The offsets `q_i`
//! belong to the point, not to the node, and are kept when its node changes.

use super::{constant, constant_field, scalar, Component, Scheme, TimeGrid};
use crate::{Error, Result, Vec3};

/// The C² bump `g(u, u_p, ε)` of §4: zero outside `(u_p − ε, u_p + ε)`, symmetric about `u_p`,
/// `g(u_p) = 1`, piecewise cubic on sixths of the support.
pub fn kernel(u: f64, up: f64, eps: f64) -> f64 {
    let r = (u - up) / eps;
    let a = r.abs();
    // Symmetric: evaluate the left half at −|r|; s = (u − u_p + ε)/ε = 1 − |r|.
    if a >= 1.0 {
        0.0
    } else if a > 2.0 / 3.0 {
        let s = 1.0 - a;
        4.5 * s * s * s
    } else if a > 1.0 / 3.0 {
        let s = 1.0 - a;
        let q = s - 1.0 / 3.0;
        4.5 * (s * s * s - 3.0 * q * q * q)
    } else {
        1.0 - 4.5 * a * a * a
    }
}

/// How the parameters `u_i` of the interior points are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamMode {
    /// Chord length of the data polygon, fixed for the whole run.
    Fixed,
    /// The closest node of the current curve, re-chosen after every time step.
    ClosestEachStep,
    /// The closest node of the current curve, re-chosen each time the curve has settled (before
    /// the forces are updated from the misfit).
    ClosestEachUpdate,
}

/// The interpolation problem of §4 and the parameters of the dynamics.
#[derive(Debug, Clone)]
pub struct Interpolation {
    /// Start point `p_0`.
    pub start: Vec3,
    /// End point `p_n`.
    pub end: Vec3,
    /// Start tangent `p_0'` (derivative with respect to `u ∈ [0, 1]`).
    pub start_tangent: Vec3,
    /// End tangent `p_n'` (derivative with respect to `u ∈ [0, 1]`).
    pub end_tangent: Vec3,
    /// Interior points `p_1 … p_{n−1}`.
    pub points: Vec<Vec3>,
    /// Bending stiffness `D` (paper: 0.01).
    pub stiffness: f64,
    /// Tension `B` (paper: 0).
    pub tension: f64,
    /// Damping `A` (the paper's 0 never settles).
    pub damping: f64,
    /// Force constant `k` (paper: 500).
    pub k: f64,
    /// Kernel half-width `ε` (paper: 0.01).
    pub eps: f64,
    /// Distance tolerance relative to the data size (largest extent of the points' bounding box).
    pub tolerance: f64,
    /// Grid intervals `J`.
    pub intervals: usize,
    /// Time step `Δt`.
    pub dt: f64,
    /// Settled when the largest nodal speed is below `speed · size`.
    pub speed: f64,
    /// Largest number of steps.
    pub max_steps: usize,
    /// How the parameters `u_i` are chosen.
    pub params: ParamMode,
}

impl Interpolation {
    /// The §4 data with the paper's `D, B, k, ε`, plus damping and the grid of this module.
    pub fn paper_example() -> Self {
        Interpolation {
            start: Vec3::new(0.0, 0.0, 0.0),
            end: Vec3::new(300.0, 0.0, 0.0),
            start_tangent: Vec3::new(28.0, 65.0, 0.0),
            end_tangent: Vec3::new(55.0, -37.0, 0.0),
            points: vec![
                Vec3::new(100.0, 60.0, 0.0),
                Vec3::new(150.0, 70.0, 0.0),
                Vec3::new(200.0, 60.0, 0.0),
            ],
            stiffness: 0.01,
            tension: 0.0,
            damping: 2.0,
            k: 500.0,
            eps: 0.01,
            tolerance: 1e-3,
            intervals: 200,
            dt: 0.01,
            speed: 1e-4,
            max_steps: 200_000,
            params: ParamMode::Fixed,
        }
    }
}

/// The settled interpolating curve.
#[derive(Debug, Clone)]
pub struct Interpolated {
    /// Nodal points `C(u_j)`, `u_j = j/J`.
    pub nodes: Vec<Vec3>,
    /// Parameters `u_i` of the interior points (grid nodes).
    pub params: Vec<f64>,
    /// Distances `|p_i − C(u_i)|`.
    pub distances: Vec<f64>,
    /// Time steps taken.
    pub steps: usize,
    /// Force updates made (one each time the curve settled with a misfit above the tolerance).
    pub updates: usize,
    /// Discrete bending energy `Σ |δ²C_j|² h` (fairness).
    pub bending_energy: f64,
}

impl Interpolated {
    /// The settled curve as a core curve: the clamped C² cubic spline through the nodes with the
    /// end tangents of the problem (usable as a boundary curve of a surface).
    pub fn to_curve(&self, problem: &Interpolation) -> Result<super::spline::NodalCurve> {
        super::spline::NodalCurve::new(
            self.nodes.clone(),
            problem.start_tangent,
            problem.end_tangent,
        )
    }
}

impl Interpolation {
    /// Checks the parameters (positive `stiffness, k, eps, tolerance, dt, speed`, non-negative
    /// `tension, damping`, at least one interior point, `J ≥ 5`).
    pub fn validate(&self) -> Result<()> {
        let pos = [
            ("stiffness", self.stiffness),
            ("k", self.k),
            ("eps", self.eps),
            ("tolerance", self.tolerance),
            ("dt", self.dt),
            ("speed", self.speed),
        ];
        for (name, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(format!("{name} = {v}; must be > 0")).at(name));
            }
        }
        for (name, v) in [("tension", self.tension), ("damping", self.damping)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(format!("{name} = {v}; must be >= 0")).at(name));
            }
        }
        if self.points.is_empty() {
            return Err(Error::invalid("no interior points").at("points"));
        }
        if self.intervals < 5 {
            return Err(Error::invalid(format!(
                "J = {} intervals; at least 5 are needed",
                self.intervals
            ))
            .at("intervals"));
        }
        Ok(())
    }

    /// Runs the damped dynamics with misfit-updated forces until every interior point is within
    /// `tolerance · size` (see the module documentation). Fails, naming the distances, if
    /// `max_steps` is reached first.
    pub fn solve(&self) -> Result<Interpolated> {
        self.solve_observed(0, &mut |_, _, _| {})
    }

    /// As [`Interpolation::solve`], calling `observer(n, t_n, nodes)` after every level `n`
    /// (from 0); `nodes` (the points `C(u_j, t_n)`) is given at `n = 0`, at every `every`-th
    /// level and at the last level, `None` otherwise.
    pub fn solve_observed(
        &self,
        every: usize,
        observer: &mut super::Observer<'_>,
    ) -> Result<Interpolated> {
        self.validate()?;
        let jn = self.intervals;
        let h = 1.0 / jn as f64;
        // Data size and chord-length parameters.
        let mut all = vec![self.start];
        all.extend(self.points.iter().copied());
        all.push(self.end);
        let (mut lo, mut hi) = (all[0], all[0]);
        for p in &all {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let size = (hi - lo).amax();
        if !(size.is_finite() && size > 0.0) {
            return Err(Error::invalid(format!("data size {size}")).at("points"));
        }
        let chords: Vec<f64> = all.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
        let total: f64 = chords.iter().sum();
        let mut acc = 0.0;
        let mut idx = Vec::new();
        for c in &chords[..chords.len() - 1] {
            acc += c;
            let j = ((acc / total) * jn as f64).round() as usize;
            idx.push(j.clamp(2, jn - 2));
        }
        let weight_row = |j0: usize| -> Vec<f64> {
            let up = j0 as f64 * h;
            (0..=jn)
                .map(|j| kernel(j as f64 * h, up, self.eps))
                .collect()
        };
        let mut weights: Vec<Vec<f64>> = idx.iter().map(|&j| weight_row(j)).collect();
        let hermite =
            crate::curve::Hermite::new(self.start, self.end, self.start_tangent, self.end_tangent);
        use crate::curve::Curve;
        let comps: Vec<Component> = (0..3)
            .map(|c| {
                let hm = hermite.clone();
                Component {
                    a: constant_field(self.damping),
                    b: constant_field(self.tension),
                    d: constant_field(self.stiffness),
                    f: constant_field(0.0),
                    start: constant(self.start[c]),
                    end: constant(self.end[c]),
                    start_slope: constant(self.start_tangent[c]),
                    end_slope: constant(self.end_tangent[c]),
                    position: scalar(move |u| hm.point(u)[c]),
                    velocity: constant(0.0),
                }
            })
            .collect();
        let grid = TimeGrid {
            intervals: jn,
            steps: self.max_steps.max(1),
            t_end: self.dt * self.max_steps.max(1) as f64,
        };
        let mut schemes = comps
            .iter()
            .map(|c| Scheme::new(c, grid))
            .collect::<Result<Vec<_>>>()?;
        let tol = self.tolerance * size;
        let mut offsets = vec![Vec3::zeros(); self.points.len()];
        let mut force = vec![0.0; jn + 1];
        let mut updates = 0;
        let at = |s: &[Scheme], j: usize| {
            Vec3::new(s[0].values()[j], s[1].values()[j], s[2].values()[j])
        };
        // Re-chooses every point's node as the closest node of the current curve.
        let reselect = |s: &[Scheme], idx: &mut Vec<usize>, weights: &mut Vec<Vec<f64>>| {
            for (i, p) in self.points.iter().enumerate() {
                let best = (2..=jn - 2)
                    .min_by(|&a, &b| {
                        (p - at(s, a))
                            .norm_squared()
                            .total_cmp(&(p - at(s, b)).norm_squared())
                    })
                    .unwrap_or(idx[i]);
                if best != idx[i] {
                    idx[i] = best;
                    weights[i] = weight_row(best);
                }
            }
        };
        if self.params != ParamMode::Fixed {
            reselect(&schemes, &mut idx, &mut weights);
        }
        {
            let prev: Vec<Vec3> = (0..=jn)
                .map(|j| {
                    Vec3::new(
                        schemes[0].previous()[j],
                        schemes[1].previous()[j],
                        schemes[2].previous()[j],
                    )
                })
                .collect();
            observer(0, 0.0, Some(&prev));
        }
        let frame = |s: &[Scheme]| -> Vec<Vec3> { (0..=jn).map(|j| at(s, j)).collect() };
        loop {
            if schemes[0].finished() {
                let d: Vec<f64> = self
                    .points
                    .iter()
                    .zip(&idx)
                    .map(|(p, &j)| (p - at(&schemes, j)).norm())
                    .collect();
                return Err(Error::invalid(format!(
                    "not within {tol} after {} steps: distances {d:?}",
                    self.max_steps
                )));
            }
            // Forces from the current misfit.
            let targets: Vec<Vec3> = self
                .points
                .iter()
                .zip(&offsets)
                .zip(&idx)
                .map(|((p, q), &j)| (p + q - at(&schemes, j)) * self.k)
                .collect();
            for (c, s) in schemes.iter_mut().enumerate() {
                force.iter_mut().for_each(|v| *v = 0.0);
                for (t, w) in targets.iter().zip(&weights) {
                    for (fj, wj) in force.iter_mut().zip(w) {
                        *fj += t[c] * wj;
                    }
                }
                s.step_with_force(Some(&force))?;
            }
            if self.params == ParamMode::ClosestEachStep {
                reselect(&schemes, &mut idx, &mut weights);
            }
            let speed = schemes
                .iter()
                .flat_map(|s| {
                    s.values()
                        .iter()
                        .zip(s.previous())
                        .map(|(a, b)| (a - b).abs())
                })
                .fold(0.0, f64::max)
                / self.dt;
            let n = schemes[0].level();
            let t = schemes[0].time();
            let settled = speed < self.speed * size;
            if settled && self.params == ParamMode::ClosestEachUpdate {
                reselect(&schemes, &mut idx, &mut weights);
            }
            let misfit_now: Vec<f64> = if settled {
                self.points
                    .iter()
                    .zip(&idx)
                    .map(|(p, &j)| (p - at(&schemes, j)).norm())
                    .collect()
            } else {
                Vec::new()
            };
            let done = settled && misfit_now.iter().all(|d| *d < tol);
            if done || (every > 0 && n.is_multiple_of(every)) {
                observer(n, t, Some(&frame(&schemes)));
            } else {
                observer(n, t, None);
            }
            if settled {
                let misfit: Vec<Vec3> = self
                    .points
                    .iter()
                    .zip(&idx)
                    .map(|(p, &j)| p - at(&schemes, j))
                    .collect();
                let worst = misfit.iter().map(|m| m.norm()).fold(0.0, f64::max);
                if worst < tol {
                    let nodes: Vec<Vec3> = (0..=jn).map(|j| at(&schemes, j)).collect();
                    let bending_energy = (1..jn)
                        .map(|j| {
                            ((nodes[j + 1] - nodes[j] * 2.0 + nodes[j - 1]) / (h * h))
                                .norm_squared()
                        })
                        .sum::<f64>()
                        * h;
                    return Ok(Interpolated {
                        distances: misfit.iter().map(|m| m.norm()).collect(),
                        params: idx.iter().map(|&j| j as f64 * h).collect(),
                        steps: schemes[0].level(),
                        updates,
                        bending_energy,
                        nodes,
                    });
                }
                for (q, m) in offsets.iter_mut().zip(&misfit) {
                    *q += m;
                }
                updates += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The printed piecewise form, written out literally (independent of `kernel`).
    fn printed(u: f64, up: f64, e: f64) -> f64 {
        let s = (u - up + e) / e;
        let r = (u - up) / e;
        let w = (u - up - e) / e;
        if u < up - e {
            0.0
        } else if u < up - 2.0 * e / 3.0 {
            4.5 * s.powi(3)
        } else if u < up - e / 3.0 {
            4.5 * (s.powi(3) - 3.0 * (s - 1.0 / 3.0).powi(3))
        } else if u < up {
            1.0 + 4.5 * r.powi(3)
        } else if u < up + e / 3.0 {
            1.0 - 4.5 * r.powi(3)
        } else if u < up + 2.0 * e / 3.0 {
            -4.5 * (w.powi(3) - 3.0 * (w + 1.0 / 3.0).powi(3))
        } else if u < up + e {
            -4.5 * w.powi(3)
        } else {
            0.0
        }
    }

    #[test]
    fn kernel_is_the_printed_c2_bump() {
        let (up, e) = (0.4, 0.03);
        assert_eq!(kernel(up, up, e), 1.0);
        for i in 0..=2000 {
            let u = up - 1.2 * e + 2.4 * e * i as f64 / 2000.0;
            let k = kernel(u, up, e);
            assert!((k - printed(u, up, e)).abs() < 1e-13, "u = {u}");
            assert!(
                (k - kernel(2.0 * up - u, up, e)).abs() < 1e-14,
                "symmetry at {u}"
            );
        }
        // C²: value, first and second derivatives of the printed pieces agree across every
        // breakpoint u_p + mε/3. One-sided differences with step δ = 10⁻⁶ε: the slope estimates
        // (second order) are accurate to ~1e-9/ε, the curvature estimates (first order) to
        // δ·g‴ + rounding ≈ 1/ε²; a genuine jump would be of order 1/ε (slope) or 27/ε²
        // (curvature), the scales of the cubic pieces.
        let d = 1e-6 * e;
        for m in [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0] {
            let b = up + m * e / 3.0;
            let left = |k: i32| printed(b - k as f64 * d, up, e);
            let right = |k: i32| printed(b + k as f64 * d, up, e);
            // Points 2δ apart: the values differ by at most 2δ·max|g'| = 2δ·1.5/ε = 3e-6.
            assert!((left(1) - right(1)).abs() < 1e-5, "value at {m}");
            let slope_l = (3.0 * left(1) - 4.0 * left(2) + left(3)) / (2.0 * d);
            let slope_r = (-3.0 * right(1) + 4.0 * right(2) - right(3)) / (2.0 * d);
            assert!(
                (slope_l - slope_r).abs() < 1e-3 / e,
                "slope at {m}: {slope_l} {slope_r}"
            );
            let curv_l = (left(1) - 2.0 * left(2) + left(3)) / (d * d);
            let curv_r = (right(1) - 2.0 * right(2) + right(3)) / (d * d);
            assert!(
                (curv_l - curv_r).abs() < 1.0 / (e * e),
                "curvature at {m}: {curv_l} {curv_r}"
            );
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        let mut p = Interpolation::paper_example();
        p.intervals = 3;
        assert!(p.solve().unwrap_err().to_string().contains("intervals"));
        let mut p = Interpolation::paper_example();
        p.eps = -1.0;
        assert!(p.solve().unwrap_err().to_string().contains("eps"));
        let mut p = Interpolation::paper_example();
        p.damping = 0.0;
        p.max_steps = 2000;
        // Undamped, the curve never settles: the run ends with an error naming the distances.
        assert!(p.solve().unwrap_err().to_string().contains("distances"));
    }

    #[test]
    fn paper_example_passes_through_the_points() {
        let problem = Interpolation::paper_example();
        let r = problem.solve().unwrap();
        eprintln!(
            "steps {}, updates {}, params {:?}, distances {:?}, bending energy {:.6e}",
            r.steps, r.updates, r.params, r.distances, r.bending_energy
        );
        let tol = problem.tolerance * 300.0;
        for d in &r.distances {
            assert!(*d < tol, "distance {d}");
        }
        let n = r.nodes.len() - 1;
        assert_eq!(r.nodes[0], problem.start);
        assert_eq!(r.nodes[n], problem.end);
        // End tangents through the third-order one-sided differences the scheme imposes
        // (to rounding: nodal values ~300, divided by 6h = 0.03).
        let h = 1.0 / n as f64;
        let t0 = (r.nodes[1] * 18.0 - r.nodes[0] * 11.0 - r.nodes[2] * 9.0 + r.nodes[3] * 2.0)
            / (6.0 * h);
        let t1 = (r.nodes[n] * 11.0 - r.nodes[n - 1] * 18.0 + r.nodes[n - 2] * 9.0
            - r.nodes[n - 3] * 2.0)
            / (6.0 * h);
        assert!((t0 - problem.start_tangent).amax() < 1e-10, "{t0:?}");
        assert!((t1 - problem.end_tangent).amax() < 1e-10, "{t1:?}");
        // The core curve passes through the points at their parameters.
        use crate::curve::Curve;
        let curve = r.to_curve(&problem).unwrap();
        for ((p, u), d) in problem.points.iter().zip(&r.params).zip(&r.distances) {
            assert!(((curve.point(*u) - p).norm() - d).abs() < 1e-9);
        }
    }

    /// `u_p` as the closest point of the current curve (Eq. 10), re-chosen after every step or
    /// at every force update: the run still ends within the tolerance, the reported node is the
    /// closest node of the final curve, and no point of the final core curve (sampled finely) is
    /// closer to `p_i` than the reported distance by more than the spline's deviation between
    /// nodes.
    #[test]
    fn closest_point_parameters() {
        use crate::curve::Curve;
        for mode in [ParamMode::ClosestEachStep, ParamMode::ClosestEachUpdate] {
            let mut problem = Interpolation::paper_example();
            problem.params = mode;
            let r = problem.solve().unwrap();
            eprintln!(
                "{mode:?}: steps {}, updates {}, params {:?}, distances {:?}",
                r.steps, r.updates, r.params, r.distances
            );
            let n = r.nodes.len() - 1;
            let tol = problem.tolerance * 300.0;
            let curve = r.to_curve(&problem).unwrap();
            for ((p, u), d) in problem.points.iter().zip(&r.params).zip(&r.distances) {
                assert!(*d < tol, "{mode:?}: distance {d}");
                let j = (u * n as f64).round() as usize;
                assert!(((r.nodes[j] - p).norm() - d).abs() < 1e-12);
                for (k, q) in r.nodes.iter().enumerate().take(n - 1).skip(2) {
                    assert!(
                        (q - p).norm() >= *d,
                        "{mode:?}: node {k} is closer than {j}"
                    );
                }
                // The spline through the nodes: nowhere much closer than the node (a curve
                // passing within d of p cannot come closer than 0).
                let closest = (0..=20 * n)
                    .map(|i| (curve.point(i as f64 / (20 * n) as f64) - p).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(closest <= *d + 1e-12 && closest >= 0.0);
            }
        }
    }
}
