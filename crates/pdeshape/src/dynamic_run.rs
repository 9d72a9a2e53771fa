//! A `[dynamic]` section run to its end, with what `pdeshape curve` reports of it: the final
//! curve, the errors of the end conditions at the final time, the errors against the exact
//! solutions a design gives, the bending energy; for an interpolation the data points' nodes
//! and distances. One function for every shell (the CLI's `curve`, Python's `dynamic()`), and
//! one memory check before a run ([`check_memory`]).

use crate::design::{BuiltDynamic, DynamicPlan};
use crate::dynamic::{bending_energy, end_slopes, l2_norm, Observer};
use crate::{Result, Vec3};
use std::time::Instant;

/// The outcome of [`run`].
#[derive(Clone, Debug)]
pub struct DynamicOutcome {
    /// Coordinates per point (1 to 3).
    pub dim: usize,
    /// The final curve at the nodes `u_j = j/J`, `j = 0 … J`.
    pub nodes: Vec<Vec3>,
    /// Wall time of the solve, seconds.
    pub seconds: f64,
    /// What the run reports, by kind of run.
    pub kind: OutcomeKind,
}

/// What a general run or an interpolation reports.
#[derive(Clone, Debug)]
pub enum OutcomeKind {
    /// A general run of the scheme.
    Run(RunReport),
    /// An interpolating curve.
    Interpolate(InterpolationReport),
}

/// A general run of the scheme.
#[derive(Clone, Debug)]
pub struct RunReport {
    /// `J`.
    pub intervals: usize,
    /// `L`, the time steps.
    pub steps: usize,
    /// `T`.
    pub t_end: f64,
    /// Per component, the errors at `T` of the start and end positions and of the start and
    /// end slopes (one-sided second-order differences of the nodes).
    pub end_errors: Vec<[f64; 4]>,
    /// Per component with an exact solution `x(u, t)`: the discrete L2 norm (`h Σ d_j²`)^½ and
    /// the largest absolute value of `d_j = x_j − x(u_j, T)`.
    pub exact_errors: Vec<Option<(f64, f64)>>,
    /// The final curve's bending energy.
    pub bending_energy: f64,
}

/// An interpolating curve (seed 000, §4).
#[derive(Clone, Debug)]
pub struct InterpolationReport {
    /// `J`.
    pub intervals: usize,
    /// The interior data points `p_1 … p_{n−1}`.
    pub points: Vec<Vec3>,
    /// The node parameter `u_i` of each point.
    pub params: Vec<f64>,
    /// The curve's distance `|p_i − C(u_i)|` from each point.
    pub distances: Vec<f64>,
    /// Time steps taken.
    pub steps: usize,
    /// The time step.
    pub dt: f64,
    /// Force updates made.
    pub updates: usize,
    /// Distance tolerance, relative to `size`.
    pub tolerance: f64,
    /// The data's size: the largest extent of the bounding box of the points and the ends.
    pub size: f64,
    /// Distances of the curve's start, end, start tangent and end tangent from the given ones.
    pub end_errors: [f64; 4],
    /// The final curve's bending energy.
    pub bending_energy: f64,
    /// The curve's given start and end points.
    pub ends: [Vec3; 2],
}

/// Runs a built `[dynamic]` section (`design::build_dynamic`), calling `observer` after every
/// level (with the nodes every `frames_every`-th level), and measures the result. Errors are
/// placed at `dynamic`.
pub fn run(built: &BuiltDynamic, observer: &mut Observer<'_>) -> Result<DynamicOutcome> {
    let every = built.frames_every;
    let start = Instant::now();
    match &built.plan {
        DynamicPlan::Run(r) => {
            let dim = r.curve.components.len();
            let values = r
                .curve
                .solve_observed(r.grid, r.positivity, every, observer)
                .map_err(|e| e.at("dynamic"))?;
            let seconds = start.elapsed().as_secs_f64();
            let t_end = r.grid.t_end;
            let jn = r.grid.intervals;
            let nodes: Vec<Vec3> = (0..=jn)
                .map(|j| {
                    let mut p = Vec3::zeros();
                    for (c, v) in values.iter().enumerate() {
                        p[c] = v[j];
                    }
                    p
                })
                .collect();
            let (s0, s1) = end_slopes(&nodes);
            let mut end_errors = Vec::new();
            let mut exact_errors = Vec::new();
            for (c, comp) in r.curve.components.iter().enumerate() {
                end_errors.push([
                    (nodes[0][c] - (comp.start)(t_end)).abs(),
                    (nodes[jn][c] - (comp.end)(t_end)).abs(),
                    (s0[c] - (comp.start_slope)(t_end)).abs(),
                    (s1[c] - (comp.end_slope)(t_end)).abs(),
                ]);
                exact_errors.push(r.exact[c].as_ref().map(|ex| {
                    let h = r.grid.h();
                    let diff: Vec<f64> = values[c]
                        .iter()
                        .enumerate()
                        .map(|(j, x)| x - ex.eval(&[j as f64 * h, t_end]))
                        .collect();
                    let max = diff.iter().fold(0.0f64, |m, d| m.max(d.abs()));
                    (l2_norm(&diff, h), max)
                }));
            }
            let energy = bending_energy(&nodes);
            Ok(DynamicOutcome {
                dim,
                nodes,
                seconds,
                kind: OutcomeKind::Run(RunReport {
                    intervals: jn,
                    steps: r.grid.steps,
                    t_end,
                    end_errors,
                    exact_errors,
                    bending_energy: energy,
                }),
            })
        }
        DynamicPlan::Interpolate { problem, dim } => {
            let result = problem
                .solve_observed(every, observer)
                .map_err(|e| e.at("dynamic"))?;
            let seconds = start.elapsed().as_secs_f64();
            let size = {
                let mut all = vec![problem.start, problem.end];
                all.extend(problem.points.iter().copied());
                let (mut lo, mut hi) = (all[0], all[0]);
                for p in &all {
                    lo = lo.inf(p);
                    hi = hi.sup(p);
                }
                (hi - lo).amax()
            };
            let nodes = result.nodes;
            let jn = nodes.len() - 1;
            let (s0, s1) = end_slopes(&nodes);
            let end_errors = [
                (nodes[0] - problem.start).norm(),
                (nodes[jn] - problem.end).norm(),
                (s0 - problem.start_tangent).norm(),
                (s1 - problem.end_tangent).norm(),
            ];
            Ok(DynamicOutcome {
                dim: *dim,
                nodes,
                seconds,
                kind: OutcomeKind::Interpolate(InterpolationReport {
                    intervals: problem.intervals,
                    points: problem.points.clone(),
                    params: result.params,
                    distances: result.distances,
                    steps: result.steps,
                    dt: problem.dt,
                    updates: result.updates,
                    tolerance: problem.tolerance,
                    size,
                    end_errors,
                    bending_energy: result.bending_energy,
                    ends: [problem.start, problem.end],
                }),
            })
        }
    }
}

/// Coordinates per point of a built run (1 to 3).
pub fn dimension(built: &BuiltDynamic) -> usize {
    match &built.plan {
        DynamicPlan::Run(r) => r.curve.components.len(),
        DynamicPlan::Interpolate { dim, .. } => *dim,
    }
}

/// How many frames [`run`] hands its observer at most: the first and the last level and every
/// `frames_every`-th level between.
pub fn frame_count(built: &BuiltDynamic) -> usize {
    let steps = match &built.plan {
        DynamicPlan::Run(r) => r.grid.steps,
        DynamicPlan::Interpolate { problem, .. } => problem.max_steps,
    };
    match built.frames_every {
        0 => 2,
        every => (steps / every).saturating_add(2),
    }
}

/// Refuses, before anything is allocated, a run of `built` whose storage together with `held`
/// frames of the curve kept at once exceeds the memory budget ([`crate::memory`]), placed at
/// `dynamic.intervals`. `held` counts every frame a caller keeps, at least the one the observer
/// is handed and the last (2); `held_for` names in the message what keeps more (such as
/// `--picture`).
pub fn check_memory(built: &BuiltDynamic, held: usize, held_for: Option<&str>) -> Result<()> {
    let dim = dimension(built);
    let intervals = match &built.plan {
        DynamicPlan::Run(r) => r.grid.intervals,
        DynamicPlan::Interpolate { problem, .. } => problem.intervals,
    };
    crate::memory::check(
        crate::memory::dynamic_run(intervals as u64, dim.max(1) as u64, held as u64),
        &format!(
            "a run on {intervals} intervals ({dim} component{}, {held} frames held{})",
            if dim == 1 { "" } else { "s" },
            held_for.map(|f| format!(" for {f}")).unwrap_or_default()
        ),
        "dynamic.intervals",
    )
}

/// A number in reports: six decimals without trailing zeros between 1e-3 and 1e6 (and 0),
/// three significant digits in exponent form otherwise.
pub(crate) fn format_number(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) {
        format!("{x:.6}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{x:.3e}")
    }
}

impl DynamicOutcome {
    /// The final curve's bending energy.
    pub fn bending_energy(&self) -> f64 {
        match &self.kind {
            OutcomeKind::Run(r) => r.bending_energy,
            OutcomeKind::Interpolate(r) => r.bending_energy,
        }
    }

    /// The report `pdeshape curve` prints (before its "wrote" lines).
    pub fn report(&self) -> String {
        let fmt = format_number;
        let dim = self.dim;
        let mut report = String::new();
        match &self.kind {
            OutcomeKind::Run(r) => {
                report.push_str(&format!(
                    "dynamic curve: {dim} component{}, J = {}, L = {}, T = {}\n",
                    if dim == 1 { "" } else { "s" },
                    r.intervals,
                    r.steps,
                    fmt(r.t_end)
                ));
                report.push_str(&format!(
                    "steps: {} to t = {} in {} s\n",
                    r.steps,
                    fmt(r.t_end),
                    fmt(self.seconds)
                ));
                let names = ["x", "y", "z"];
                for (c, errs) in r.end_errors.iter().enumerate() {
                    report.push_str(&format!(
                        "end conditions {} at T: start {}, end {}, start slope {}, end slope {}\n",
                        names[c],
                        fmt(errs[0]),
                        fmt(errs[1]),
                        fmt(errs[2]),
                        fmt(errs[3])
                    ));
                    if let Some((l2, max)) = r.exact_errors[c] {
                        report.push_str(&format!(
                            "exact {}: L2 error {}, max error {}\n",
                            names[c],
                            fmt(l2),
                            fmt(max)
                        ));
                    }
                }
                report.push_str(&format!("bending energy: {}\n", fmt(r.bending_energy)));
            }
            OutcomeKind::Interpolate(r) => {
                report.push_str(&format!(
                    "interpolating curve: {} points, J = {}, {} steps (t = {}), {} force updates, {} s\n",
                    r.points.len(),
                    r.intervals,
                    r.steps,
                    fmt(r.steps as f64 * r.dt),
                    r.updates,
                    fmt(self.seconds)
                ));
                for (i, ((p, u), d)) in r.points.iter().zip(&r.params).zip(&r.distances).enumerate()
                {
                    let coords: Vec<String> = p.iter().take(dim).map(|x| fmt(*x)).collect();
                    report.push_str(&format!(
                        "point {i} ({}): u = {}, distance {}\n",
                        coords.join(", "),
                        fmt(*u),
                        fmt(*d)
                    ));
                }
                report.push_str(&format!(
                    "tolerance: {} ({} of the data size {})\n",
                    fmt(r.tolerance * r.size),
                    fmt(r.tolerance),
                    fmt(r.size)
                ));
                report.push_str(&format!(
                    "end conditions: start {}, end {}, start tangent {}, end tangent {}\n",
                    fmt(r.end_errors[0]),
                    fmt(r.end_errors[1]),
                    fmt(r.end_errors[2]),
                    fmt(r.end_errors[3])
                ));
                report.push_str(&format!("bending energy: {}\n", fmt(r.bending_energy)));
            }
        }
        report
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::parse_design;

    /// Liu et al. §3.3 (`examples/dynamic_section33.toml`), exact solution
    /// `x(u, t) = (1 + e^{−t}) sin(πu)`: the run's L2 and max errors are those of the nodes
    /// against the closed form at `T`, small, and fall by about 4 when `h` and `Δt` halve
    /// (second order).
    #[test]
    fn error_norms_against_the_closed_form() {
        let path = format!(
            "{}/../../examples/dynamic_section33.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let text = std::fs::read_to_string(path).unwrap();
        let errors = |text: &str| {
            let spec = parse_design(text).unwrap();
            let built = crate::design::build_dynamic(spec.dynamic.as_ref().unwrap()).unwrap();
            let mut frames = 0;
            let out = run(&built, &mut |_, _, nodes: Option<&[Vec3]>| {
                frames += usize::from(nodes.is_some());
            })
            .unwrap();
            assert!(frames > 0);
            let OutcomeKind::Run(r) = &out.kind else {
                panic!("not a run")
            };
            let jn = r.intervals;
            let h = 1.0 / jn as f64;
            let exact = |u: f64| (1.0 + (-r.t_end).exp()) * (std::f64::consts::PI * u).sin();
            let d: Vec<f64> = (0..=jn)
                .map(|j| out.nodes[j].x - exact(j as f64 * h))
                .collect();
            let l2 = (h * d.iter().map(|x| x * x).sum::<f64>()).sqrt();
            let max = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let (rl2, rmax) = r.exact_errors[0].unwrap();
            assert!((rl2 - l2).abs() <= 1e-12 * l2.max(1e-300), "{rl2} {l2}");
            assert_eq!(rmax, max);
            assert_eq!(r.end_errors.len(), 1);
            assert!(r.end_errors[0][0] < 1e-12 && r.end_errors[0][1] < 1e-12);
            (l2, max)
        };
        let (l2, max) = errors(&text);
        assert!(l2 < 2e-3 && max < 3e-3, "{l2} {max}");
        let finer = text
            .replace("intervals = 30", "intervals = 60")
            .replace("steps = 450", "steps = 900")
            .replace("frames_every = 45", "frames_every = 90");
        let (l2_fine, _) = errors(&finer);
        let ratio = l2 / l2_fine;
        assert!(
            (3.0..5.5).contains(&ratio),
            "ratio {ratio}: {l2} → {l2_fine}"
        );
    }

    /// The report's lines are those `pdeshape curve` prints.
    #[test]
    fn numbers_in_reports() {
        assert_eq!(format_number(0.0), "0");
        assert_eq!(format_number(15.0), "15");
        assert_eq!(format_number(0.001166), "0.001166");
        assert_eq!(format_number(8.882e-16), "8.882e-16");
    }
}
