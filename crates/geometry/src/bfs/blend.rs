//! Blending surfaces (seed 004 §6): a discrete PDE spline on `[0, 1]²` whose edges `y = 0` and
//! `y = 1` join two primary surfaces with tangent continuity.

use super::{BfsSurface, Energy, Partition, SplineSystem};
use crate::surface::{Partials, Surface};
use crate::{Error, Result, Vec3};

/// Where the blend meets a primary surface `S`: the blend's edge parameter `x ∈ [0, 1]` maps to
/// the straight line `p(x) = from + x (to − from)` in `S`'s `(u, v)` plane, and the blend's
/// cross derivative is `S`'s derivative along `cross` there. The edge's nodal values are then
/// `σ = S(p)`, `σ_x = DS·T`, `σ_y = DS·N`, `σ_xy = D²S[T, N]` with `T = to − from`, `N = cross`:
/// every BFS degree of freedom on the edge is set from `S` (σ_y = DS·N makes the join C¹ in the
/// parameters when `N` points out of `S`'s domain, as the blend continues `S`).
#[derive(Clone, Copy)]
pub struct Join<'a> {
    /// The primary surface `S`.
    pub surface: &'a dyn Surface,
    /// Start `(u, v)` of the join line in `S`'s parameter plane, at the blend's `x = 0`.
    pub from: [f64; 2],
    /// End `(u, v)` of the join line, at the blend's `x = 1`; must differ from `from`.
    pub to: [f64; 2],
    /// The direction `N` in `S`'s `(u, v)` plane that the blend's `y` derivative follows; not
    /// parallel to `to − from`.
    pub cross: [f64; 2],
}

/// A blend between two primary surfaces, with optional data points (the paper's `A`, `β`).
pub struct BlendProblem<'a> {
    /// The join of the edge `y = 0`.
    pub start: Join<'a>,
    /// The join of the edge `y = 1`.
    pub end: Join<'a>,
    /// Elements in `x` (along the joins).
    pub nx: usize,
    /// Elements in `y` (across, from the `start` join to the `end` join).
    pub ny: usize,
    /// Identify the edges `x = 0` and `x = 1` (a closed tube; both joins must be closed lines).
    pub periodic: bool,
    /// The energy `(v, v)_L` of Eq. 6 (its Euler–Lagrange operator is the PDE the blend solves).
    pub energy: Energy,
    /// The weight `ε > 0` of the energy against the data points in Eq. 6 (finite).
    pub epsilon: f64,
    /// Data sites `a_i` in `[0, 1]²` (the paper's `A`).
    pub sites: Vec<[f64; 2]>,
    /// The points `β_i` the blend should pass near, one per site.
    pub values: Vec<Vec3>,
}

/// The mismatch along one join, sampled densely along the edge (not only at the nodes).
#[derive(Clone, Debug, PartialEq)]
pub struct JoinReport {
    /// G0: `max |σ(x, y_edge) − S(p(x))|`.
    pub g0: f64,
    /// G1: the largest angle (radians) between the unit normals of the blend and of `S`, up to
    /// orientation.
    pub g1: f64,
    /// C¹: `max |σ_y(x, y_edge) − DS·N|`.
    pub cross: f64,
    /// Number of samples along the edge.
    pub samples: usize,
}

/// The blend's report: both joins, the distance to every data point, and, for a blend between
/// closed lines that is not periodic, the gap between its edges `x = 0` and `x = 1`.
#[derive(Clone, Debug, PartialEq)]
pub struct BlendReport {
    /// Mismatch along the join `y = 0`.
    pub start: JoinReport,
    /// Mismatch along the join `y = 1`.
    pub end: JoinReport,
    /// Distance `|σ(a_i) − β_i|` from the blend to each data point, in the order of `sites`.
    pub point_distances: Vec<f64>,
    /// For a blend between closed joins that is not periodic: the largest distance between its
    /// edges `x = 0` and `x = 1`; `None` otherwise.
    pub seam_gap: Option<f64>,
}

/// A solved blend.
pub struct Blend {
    /// The blend on `[0, 1]²` (`y = 0` on the `start` join, `y = 1` on the `end` join).
    pub surface: BfsSurface,
    /// How closely it meets the joins and the data points.
    pub report: BlendReport,
}

/// The nodal values `(σ, σ_x, σ_y, σ_xy)` at edge parameter `x` of a join.
fn join_dofs(j: &Join, x: f64) -> [Vec3; 4] {
    let t = [j.to[0] - j.from[0], j.to[1] - j.from[1]];
    let n = j.cross;
    let q = j
        .surface
        .partials(j.from[0] + x * t[0], j.from[1] + x * t[1]);
    [
        q.x,
        q.xu * t[0] + q.xv * t[1],
        q.xu * n[0] + q.xv * n[1],
        q.xuu * (t[0] * n[0]) + q.xuv * (t[0] * n[1] + t[1] * n[0]) + q.xvv * (t[1] * n[1]),
    ]
}

fn check_join(j: &Join, place: &str) -> Result<()> {
    for (name, p) in [("from", j.from), ("to", j.to), ("cross", j.cross)] {
        if !p.iter().all(|x| x.is_finite()) {
            return Err(Error::invalid(format!("must be finite (got {p:?})"))
                .at(&format!("{place}.{name}")));
        }
    }
    if j.from == j.to {
        return Err(
            Error::invalid("the join line has zero length (from = to)").at(&format!("{place}.to"))
        );
    }
    let t = [j.to[0] - j.from[0], j.to[1] - j.from[1]];
    if (t[0] * j.cross[1] - t[1] * j.cross[0]).abs()
        <= 1e-12 * (t[0].hypot(t[1]) * j.cross[0].hypot(j.cross[1]))
    {
        return Err(Error::invalid(format!(
            "the cross direction {:?} must not be parallel to the join line (to − from = {t:?})",
            j.cross
        ))
        .at(&format!("{place}.cross")));
    }
    Ok(())
}

/// Solves the blend: fixes every degree of freedom of the nodes on `y = 0` and `y = 1` from the
/// primary surfaces ([`Join`]), leaves the rest free, and minimises Eq. 6 with `f = 0`.
pub fn blend(problem: &BlendProblem) -> Result<Blend> {
    check_join(&problem.start, "start")?;
    check_join(&problem.end, "end")?;
    if problem.sites.len() != problem.values.len() {
        return Err(Error::invalid(format!(
            "{} data sites but {} values",
            problem.sites.len(),
            problem.values.len()
        ))
        .at("points"));
    }
    let partition = Partition::uniform(problem.nx, problem.ny, problem.periodic)?;
    let (nx, ny) = (problem.nx, problem.ny);
    let ndofs = partition.dofs();
    let mut fixed = vec![false; ndofs];
    let mut values = vec![Vec3::zeros(); ndofs];
    for (join, j, place) in [(&problem.start, 0, "start"), (&problem.end, ny, "end")] {
        for i in 0..partition.node_columns() {
            let x = partition.xs()[i];
            let d = join_dofs(join, x);
            for (k, v) in d.iter().enumerate() {
                if !v.iter().all(|c| c.is_finite()) {
                    return Err(Error::invalid(format!(
                        "the primary surface is not finite (or its derivatives are not) at x = {x} of the join"
                    ))
                    .at(place));
                }
                fixed[partition.dof(i, j, k)] = true;
                values[partition.dof(i, j, k)] = *v;
            }
        }
        if problem.periodic {
            let (a, b) = (join_dofs(join, 0.0), join_dofs(join, 1.0));
            let scale = a.iter().chain(&b).map(|v| v.norm()).fold(1.0, f64::max);
            let names = [
                "position",
                "x-derivative",
                "cross derivative",
                "mixed derivative",
            ];
            for k in 0..4 {
                let gap = (a[k] - b[k]).norm();
                if gap.is_nan() || gap > 1e-9 * scale {
                    return Err(Error::invalid(format!(
                        "a periodic blend needs closed joins, but the {} of the {place} join differs by {gap:.3e} between x = 0 and x = 1",
                        names[k]
                    ))
                    .at("periodic"));
                }
            }
        }
    }
    let system = SplineSystem::new(partition, &fixed)?;
    let factor = system.factor(&problem.energy, problem.epsilon, &problem.sites)?;
    let surface = factor.solve(&problem.values, &values, None)?;
    let samples = (64 * nx).max(1024) + 1;
    let start = join_report(&surface, &problem.start, 0.0, samples);
    let end = join_report(&surface, &problem.end, 1.0, samples);
    let point_distances = problem
        .sites
        .iter()
        .zip(&problem.values)
        .map(|(s, v)| (surface.evaluate(s[0], s[1]).x - v).norm())
        .collect();
    let closed = |j: &Join| {
        let (a, b) = (join_dofs(j, 0.0)[0], join_dofs(j, 1.0)[0]);
        (a - b).norm() <= 1e-9 * a.norm().max(b.norm()).max(1.0)
    };
    let seam_gap = if !problem.periodic && closed(&problem.start) && closed(&problem.end) {
        Some(
            (0..samples)
                .map(|k| {
                    let y = k as f64 / (samples - 1) as f64;
                    (surface.evaluate(0.0, y).x - surface.evaluate(1.0, y).x).norm()
                })
                .fold(0.0, nan_max),
        )
    } else {
        None
    };
    Ok(Blend {
        surface,
        report: BlendReport {
            start,
            end,
            point_distances,
            seam_gap,
        },
    })
}

fn nan_max(a: f64, b: f64) -> f64 {
    if b.is_nan() || b > a {
        b
    } else {
        a
    }
}

/// Angle between the normal lines of two surfaces at a point (0 where either has no normal):
/// `atan2(|a × b|, |a · b|)`, accurate for tiny angles.
fn normal_angle(p: &Partials, q: &Partials) -> f64 {
    match (p.normal_or_none(), q.normal_or_none()) {
        (Some(a), Some(b)) => a.cross(&b).norm().atan2(a.dot(&b).abs()),
        _ => 0.0,
    }
}

fn join_report(s: &BfsSurface, j: &Join, y: f64, samples: usize) -> JoinReport {
    let (mut g0, mut g1, mut cross) = (0.0f64, 0.0f64, 0.0f64);
    for k in 0..samples {
        let x = k as f64 / (samples - 1) as f64;
        let b: Partials = s.evaluate(x, y);
        let d = join_dofs(j, x);
        g0 = nan_max(g0, (b.x - d[0]).norm());
        cross = nan_max(cross, (b.xv - d[2]).norm());
        let t = [j.to[0] - j.from[0], j.to[1] - j.from[1]];
        let q = j
            .surface
            .partials(j.from[0] + x * t[0], j.from[1] + x * t[1]);
        g1 = nan_max(g1, normal_angle(&b, &q));
    }
    JoinReport {
        g0,
        g1,
        cross,
        samples,
    }
}
