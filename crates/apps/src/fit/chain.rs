//! A chain of biharmonic patches fitted by least squares to a sequence of sections.
//!
//! The input is an ordered list of *stations*: periodic curves sampled at `S` equal steps of
//! `v` (sections of the mesh, or a pole: one point repeated). Some stations become the
//! patches' end curves (the *nodes*; the first and last always are); every other station is
//! data for the least squares.
//!
//! - **Modes.** Each station's Fourier coefficients are taken up to `S/2 − 1`. At every
//!   station away from the poles, the modes in the upper half of that range estimate the noise
//!   (no smooth section has them): `ν² =` the mean of `|aₘ|² + |bₘ|²` there. A mode is signal
//!   where its amplitude exceeds `3ν` (for noise alone, a chance below 10⁻⁸). The chain keeps
//!   the smallest `M` for which, at every such station, the signal modes beyond `M` add up to at
//!   most the budget: a bound on what the truncation moves the curve. The noise itself is not
//!   followed, however many modes that would take.
//! - **Parameters.** The stations get the cumulative root-mean-square distance between
//!   consecutive ones (chord length); a patch between nodes `a < b` gives station `j` the
//!   parameter `u_j = (s_j − s_a)/(s_b − s_a)`.
//! - **Patches** ([`Joint`]). *Hermite* (the tube mode): each patch has the positions of its
//!   two nodes and the derivative curves there, each derivative curve shared by the two patches
//!   at its node (G1); the derivative curves are the unknowns. *Four positions* (the sheet mode,
//!   book §4.5–4.6): each patch has four position curves at `u = 0, 1/3, 2/3, 1`, the nodes' at
//!   the ends (shared, G0) and two inside, which are the unknowns. Either way the patch is linear
//!   in its curves mode by mode ([`super::basis`]), so the unknowns are the least-squares
//!   solution, mode by mode, of `Xₙ(u_j) = data_j,ₙ` over the stations between the nodes.
//! - **Errors.** A patch's error is the largest distance, along the mesh's normal at the sample
//!   (from differences of neighbouring samples and stations), between a station's samples and
//!   the fitted patch at `u_j`: a slide of the parameters along the surface is no error of the
//!   shape.
//! - **Nodes.** Patches whose error exceeds the target are split at their middle station until
//!   every patch meets it (or has no room left); then nodes whose removal keeps every patch
//!   within the target are removed, smallest neighbouring error first.

use super::basis::{position_weights, weights};
use super::section::fourier;
use crate::spec::{
    ConditionSpec, CurveKind, CurveRef, CurveSpec, DesignSpec, OperatorSpec, PatchSpec, V3,
};
use crate::{Vec3, TAU};
use pdeshape_geometry::linalg::band::BandMatrix;
use std::collections::BTreeMap;

/// A curve's Fourier coefficients: `[a₀, a₁, b₁, a₂, b₂, …]`.
pub type Series = Vec<Vec3>;

/// How a chain's patches are built and joined (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Joint {
    /// Positions at the nodes and one shared derivative curve per node: G1 (the tube mode).
    Hermite,
    /// Four position curves per patch at `u = 0, 1/3, 2/3, 1`, the ends shared: G0 (the sheet
    /// mode, book §4.5).
    FourPoints,
}

/// The inner knots of a [`Joint::FourPoints`] patch.
pub(crate) const INNER_KNOTS: [f64; 2] = [1.0 / 3.0, 2.0 / 3.0];

/// Patches keep at least two stations inside.
const MIN_SPAN: usize = 3;

/// One station: `S` samples of a periodic curve at `v_k = 2πk/S`, or a pole.
#[derive(Clone, Debug)]
pub struct Station {
    /// The `S` samples, `v_k = 2πk/S`; a pole repeats its point `S` times.
    pub points: Vec<Vec3>,
    /// True for a pole (one point repeated).
    pub pole: bool,
    /// The name of the part the station belongs to (templates; empty otherwise).
    pub part: String,
}

impl Station {
    /// A pole at `p`: `samples` copies of it.
    pub fn at_pole(p: Vec3, samples: usize, part: &str) -> Self {
        Station {
            points: vec![p; samples],
            pole: true,
            part: part.to_string(),
        }
    }
}

/// The least-squares problem over the stations.
pub struct Chain {
    stations: Vec<Station>,
    /// Truncated coefficients of every station.
    data: Vec<Series>,
    modes: usize,
    joint: Joint,
    /// Cumulative chord parameter of each station.
    s: Vec<f64>,
    /// Unit normals of the mesh at the stations' samples (zero where they degenerate).
    normals: Vec<Vec<Vec3>>,
    /// `(cos mv_k, sin mv_k)` for sample `k`, mode `m` at `k·modes + m − 1`.
    trig: Vec<(f64, f64)>,
    /// Stations that must be nodes (the ends, and the junctions of a template's parts).
    forced: Vec<bool>,
}

/// The solved unknown curves and each patch's largest error.
pub struct Solved {
    /// The smoothing parameter `a` of the biharmonic patches.
    pub a: f64,
    /// Hermite: the derivative curve at each node. Four points: the two inner curves of each
    /// patch, patch by patch.
    pub curves: Vec<Series>,
    /// Each patch's largest error (distance along the mesh's normal, design units), one per patch.
    pub errors: Vec<f64>,
}

impl Chain {
    /// Builds the problem; `forced` lists the stations that must be nodes besides the ends.
    /// Modes: at most `max_modes`, truncation budget `budget` (absolute).
    pub fn new(
        stations: Vec<Station>,
        forced: &[usize],
        joint: Joint,
        max_modes: usize,
        budget: f64,
    ) -> Self {
        let n = stations.len();
        let samples = stations[0].points.len();
        let full_modes = samples / 2 - 1;
        let full: Vec<Series> = stations
            .iter()
            .map(|st| {
                let (a0, c, sn) = fourier(&st.points, full_modes);
                let mut out = vec![a0];
                for k in 0..full_modes {
                    out.push(c[k]);
                    out.push(sn[k]);
                }
                out
            })
            .collect();
        // Stations next to a pole cut the few triangles of the pole's fan, whose corners no
        // short series follows; they are left out of the choice of modes (the least squares
        // still sees them).
        let skip = n / 12;
        let near_pole = |j: usize| {
            (0..n).any(|p| stations[p].pole && (p as isize - j as isize).unsigned_abs() <= skip)
        };
        let inner: Vec<usize> = (0..n)
            .filter(|&j| !stations[j].pole && !near_pole(j))
            .collect();
        let modes = choose_modes(&full, &inner, max_modes.clamp(1, full_modes), budget);
        let data: Vec<Series> = full
            .into_iter()
            .map(|mut c| {
                c.truncate(2 * modes + 1);
                c
            })
            .collect();
        let rms = |a: &[Vec3], b: &[Vec3]| -> f64 {
            let sum: f64 = a.iter().zip(b).map(|(p, q)| (p - q).norm_squared()).sum();
            (sum / a.len() as f64).sqrt()
        };
        let mut s = vec![0.0];
        for j in 1..n {
            let d = rms(&stations[j - 1].points, &stations[j].points);
            s.push(s[j - 1] + d.max(1e-300));
        }
        let normals = (0..n)
            .map(|j| {
                let pts = &stations[j].points;
                let below = &stations[j.saturating_sub(1)].points;
                let above = &stations[(j + 1).min(n - 1)].points;
                (0..samples)
                    .map(|k| {
                        let mut tv = pts[(k + 1) % samples] - pts[(k + samples - 1) % samples];
                        if tv.norm() <= 1e-12 * (pts[(k + 1) % samples] - pts[k]).norm() {
                            // The fold of an even (sheet) curve: one-sided.
                            tv = pts[(k + 1) % samples] - pts[k];
                        }
                        let nv = (above[k] - below[k]).cross(&tv);
                        let len = nv.norm();
                        if len > 0.0 && len.is_finite() {
                            nv / len
                        } else {
                            Vec3::zeros()
                        }
                    })
                    .collect()
            })
            .collect();
        let trig = (0..samples)
            .flat_map(|k| {
                let v = TAU * k as f64 / samples as f64;
                (1..=modes).map(move |m| ((m as f64 * v).cos(), (m as f64 * v).sin()))
            })
            .collect();
        let mut is_forced = vec![false; n];
        is_forced[0] = true;
        is_forced[n - 1] = true;
        for &f in forced {
            if f < n {
                is_forced[f] = true;
            }
        }
        Chain {
            stations,
            data,
            modes,
            joint,
            s,
            normals,
            trig,
            forced: is_forced,
        }
    }

    /// The Fourier modes `M` kept.
    pub fn modes(&self) -> usize {
        self.modes
    }

    /// Number of stations.
    pub fn len(&self) -> usize {
        self.stations.len()
    }

    /// True for a chain without stations.
    pub fn is_empty(&self) -> bool {
        self.stations.is_empty()
    }

    /// `patches` patches with nodes spread evenly over the stations (the forced ones kept).
    pub fn even_nodes(&self, patches: usize) -> Option<Vec<usize>> {
        let last = self.len() - 1;
        if patches == 0 || MIN_SPAN * patches > last {
            return None;
        }
        let mut nodes: Vec<usize> = (0..=patches)
            .map(|k| (k as f64 * last as f64 / patches as f64).round() as usize)
            .chain((0..=last).filter(|&j| self.forced[j]))
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        Some(nodes)
    }

    /// The largest number of patches [`Chain::even_nodes`] accepts.
    pub fn max_patches(&self) -> usize {
        (self.len() - 1) / MIN_SPAN
    }

    /// Nodes chosen by splitting and merging (module documentation), for smoothing
    /// parameter `a` and target `tol` (absolute).
    pub fn adaptive_nodes(&self, a: f64, tol: f64) -> Vec<usize> {
        let mut nodes: Vec<usize> = (0..self.len()).filter(|&j| self.forced[j]).collect();
        loop {
            let solved = self.solve(&nodes, a);
            let mut next = vec![nodes[0]];
            let mut split = false;
            for p in 0..nodes.len() - 1 {
                let (x, y) = (nodes[p], nodes[p + 1]);
                if solved.errors[p] > tol && y - x >= 2 * MIN_SPAN {
                    next.push((x + y) / 2);
                    split = true;
                }
                next.push(y);
            }
            nodes = next;
            if !split {
                break;
            }
        }
        // Merge: try removing interior nodes, the one with the smallest neighbouring errors
        // first; keep a removal if every patch still meets the target.
        let mut solved = self.solve(&nodes, a);
        let mut blocked = self.forced.clone();
        loop {
            let candidate =
                (1..nodes.len() - 1)
                    .filter(|&k| !blocked[nodes[k]])
                    .min_by(|&i, &j| {
                        let e = |k: usize| solved.errors[k - 1].max(solved.errors[k]);
                        e(i).total_cmp(&e(j))
                    });
            let Some(k) = candidate else { break };
            let mut trial = nodes.clone();
            trial.remove(k);
            let t = self.solve(&trial, a);
            // The merged patch meets the target, and no other patch gets worse than the
            // target or than it was (a patch with no room to split may miss it).
            let others = (0..t.errors.len()).filter(|&i| i != k - 1).all(|i| {
                let was = solved.errors[if i < k - 1 { i } else { i + 1 }];
                t.errors[i] <= tol.max(was)
            });
            if t.errors[k - 1] <= tol && others {
                nodes = trial;
                solved = t;
            } else {
                blocked[nodes[k]] = true;
            }
        }
        nodes
    }

    /// Rows of the least squares: `(patch, station, u)` for every station strictly inside a
    /// patch.
    fn rows(&self, nodes: &[usize]) -> Vec<(usize, usize, f64)> {
        let mut rows = Vec::new();
        for p in 0..nodes.len() - 1 {
            let (a, b) = (nodes[p], nodes[p + 1]);
            for j in a + 1..b {
                rows.push((p, j, (self.s[j] - self.s[a]) / (self.s[b] - self.s[a])));
            }
        }
        rows
    }

    /// The chord length of patch `p`, to four significant digits (as written in the design):
    /// the patch's `X_u` at a node is this times the node's derivative curve, the derivative
    /// with respect to the chord parameter `s`, which both patches at the node share.
    fn length(&self, nodes: &[usize], p: usize) -> f64 {
        let l = self.s[nodes[p + 1]] - self.s[nodes[p]];
        significant(l, 4)
    }

    /// The coefficient indices of mode `n`: `[0]`, or `[2n − 1, 2n]`.
    fn columns(n: usize) -> std::ops::RangeInclusive<usize> {
        if n == 0 {
            0..=0
        } else {
            2 * n - 1..=2 * n
        }
    }

    /// The unknown curves for the given nodes, mode by mode, and each patch's largest error.
    pub fn solve(&self, nodes: &[usize], a: f64) -> Solved {
        let width = 2 * self.modes + 1;
        let rows = self.rows(nodes);
        let unknowns = match self.joint {
            Joint::Hermite => nodes.len(),
            Joint::FourPoints => 2 * (nodes.len() - 1),
        };
        let mut curves = vec![vec![Vec3::zeros(); width]; unknowns];
        // Each row touches two neighbouring unknowns (`p, p + 1`, or `2p, 2p + 1`), so the normal
        // matrix is tridiagonal: assembled and solved in the band, O(rows + unknowns) a mode.
        for n in 0..=self.modes {
            let cols: Vec<usize> = Self::columns(n).collect();
            let width_rhs = 3 * cols.len();
            let mut diag = vec![0.0; unknowns];
            let mut upper = vec![0.0; unknowns];
            let mut b = vec![0.0; unknowns * width_rhs];
            for &(p, j, u) in &rows {
                let (pa, pb) = (&self.data[nodes[p]], &self.data[nodes[p + 1]]);
                let (k, m0, m1, w0, w3) = match self.joint {
                    Joint::Hermite => {
                        let w = weights(n, a, u);
                        let l = self.length(nodes, p);
                        (p, w[1] * l, w[3] * l, w[0], w[2])
                    }
                    Joint::FourPoints => {
                        let w =
                            position_weights(n, a, [0.0, INNER_KNOTS[0], INNER_KNOTS[1], 1.0], u);
                        (2 * p, w[1], w[2], w[0], w[3])
                    }
                };
                diag[k] += m0 * m0;
                diag[k + 1] += m1 * m1;
                upper[k] += m0 * m1;
                for (q, &c) in cols.iter().enumerate() {
                    let target = self.data[j][c] - pa[c] * w0 - pb[c] * w3;
                    for d in 0..3 {
                        b[k * width_rhs + 3 * q + d] += m0 * target[d];
                        b[(k + 1) * width_rhs + 3 * q + d] += m1 * target[d];
                    }
                }
            }
            // Tikhonov damping far below the data's scale keeps an unknown without data
            // determined.
            let trace = diag.iter().sum::<f64>().max(1e-300);
            let mut normal = BandMatrix::zeros(unknowns, 1, 1);
            for k in 0..unknowns {
                normal.set(k, k, diag[k] + 1e-12 * trace / unknowns as f64);
                if k + 1 < unknowns {
                    normal.set(k, k + 1, upper[k]);
                    normal.set(k + 1, k, upper[k]);
                }
            }
            let solvable = normal.factorize().is_ok();
            let mut column = vec![0.0; unknowns];
            for r in 0..width_rhs {
                if solvable {
                    for k in 0..unknowns {
                        column[k] = b[k * width_rhs + r];
                    }
                    normal.solve_in_place(&mut column);
                }
                for (k, curve) in curves.iter_mut().enumerate() {
                    let (q, d) = (r / 3, r % 3);
                    curve[cols[q]][d] = if solvable { column[k] } else { 0.0 };
                }
            }
        }
        let mut solved = Solved {
            a,
            curves,
            errors: vec![0.0; nodes.len() - 1],
        };
        for &(p, j, u) in &rows {
            let c = self.patch_curve(nodes, &solved, p, u);
            let e = self.error(j, &c);
            solved.errors[p] = solved.errors[p].max(e);
        }
        solved
    }

    /// The coefficients of patch `p`'s curve at `u`.
    fn patch_curve(&self, nodes: &[usize], solved: &Solved, p: usize, u: f64) -> Series {
        let width = 2 * self.modes + 1;
        let (pa, pb) = (&self.data[nodes[p]], &self.data[nodes[p + 1]]);
        let mut c = vec![Vec3::zeros(); width];
        for n in 0..=self.modes {
            for i in Self::columns(n) {
                c[i] = match self.joint {
                    Joint::Hermite => {
                        let w = weights(n, solved.a, u);
                        let l = self.length(nodes, p);
                        pa[i] * w[0]
                            + solved.curves[p][i] * (w[1] * l)
                            + pb[i] * w[2]
                            + solved.curves[p + 1][i] * (w[3] * l)
                    }
                    Joint::FourPoints => {
                        let w = position_weights(
                            n,
                            solved.a,
                            [0.0, INNER_KNOTS[0], INNER_KNOTS[1], 1.0],
                            u,
                        );
                        pa[i] * w[0]
                            + solved.curves[2 * p][i] * w[1]
                            + solved.curves[2 * p + 1][i] * w[2]
                            + pb[i] * w[3]
                    }
                };
            }
        }
        c
    }

    /// The largest distance along the normals between station `j`'s samples and the curve
    /// `c`.
    fn error(&self, j: usize, c: &Series) -> f64 {
        let pts = &self.stations[j].points;
        let normals = &self.normals[j];
        let mut worst: f64 = 0.0;
        for (k, q) in pts.iter().enumerate() {
            let mut x = c[0];
            for m in 1..=self.modes {
                let (cs, sn) = self.trig[k * self.modes + m - 1];
                x += c[2 * m - 1] * cs + c[2 * m] * sn;
            }
            let e = x - q;
            let n = normals[k];
            let d = if n == Vec3::zeros() {
                e.norm()
            } else {
                e.dot(&n).abs()
            };
            worst = worst.max(d);
        }
        worst
    }

    /// The design of the chain (module documentation of [`super`] for the names): curves named
    /// `{prefix}p00, {prefix}p01, …` (positions in order along the chain) and, for Hermite
    /// chains, `{prefix}d00, …` (the derivative curves at the nodes); patches named after the
    /// part of their first inner station (or `patch`) and numbered within it. Coefficients are
    /// rounded to about `quantum`; trailing terms of each curve whose norms add up to at most
    /// `trim` (absolute, scaled for derivative curves by their largest weight) are dropped.
    pub fn design_into(
        &self,
        nodes: &[usize],
        solved: &Solved,
        prefix: &str,
        quantum: f64,
        trim: f64,
        out: &mut DesignSpec,
    ) {
        // Positions to `quantum`; derivative curves, which the patches scale by their chord
        // lengths, to `quantum` over the longest chord (the same absolute rounding of the
        // surface, and the same digits for the same shape at any size).
        let longest = (0..nodes.len().saturating_sub(1))
            .map(|p| self.length(nodes, p))
            .fold(0.0, f64::max);
        let slope_quantum = quantum / longest.max(1e-300);
        let digits = |q: f64| (-q.log10()).ceil().clamp(0.0, 17.0) as usize;
        let round = |x: f64, digits: usize| -> f64 {
            let r: f64 = format!("{x:.digits$}").parse().unwrap_or(x);
            if r == 0.0 {
                0.0
            } else {
                r
            }
        };
        let v3 = |p: Vec3, q: f64| -> V3 {
            let d = digits(q);
            [round(p.x, d), round(p.y, d), round(p.z, d)]
        };
        let series = |c: &Series, budget: f64, quantum: f64| -> CurveKind {
            let mut cos: Vec<Vec3> = (1..=self.modes).map(|m| c[2 * m - 1]).collect();
            let mut sin: Vec<Vec3> = (1..=self.modes).map(|m| c[2 * m]).collect();
            // Drop trailing terms, the smaller list's last first, while the budget lasts;
            // terms below the rounding always go.
            let mut left = budget;
            loop {
                let lc = cos.last().map_or(f64::INFINITY, |x| x.norm());
                let ls = sin.last().map_or(f64::INFINITY, |x| x.norm());
                let (len, is_cos) = if lc <= ls { (lc, true) } else { (ls, false) };
                if !len.is_finite() {
                    break;
                }
                if len < 0.5 * quantum {
                    // Rounds to zero anyway.
                } else if len <= left {
                    left -= len;
                } else {
                    break;
                }
                if is_cos {
                    cos.pop();
                } else {
                    sin.pop();
                }
            }
            CurveKind::Fourier {
                a0: v3(c[0], quantum),
                cos: cos.into_iter().map(|x| v3(x, quantum)).collect(),
                sin: sin.into_iter().map(|x| v3(x, quantum)).collect(),
            }
        };
        let curve = |kind| CurveSpec {
            kind,
            transform: Vec::new(),
            v_origin: 0.0,
            arc_length: false,
        };
        let position = |i: usize| -> CurveKind {
            if self.stations[i].pole {
                CurveKind::Point {
                    at: v3(self.data[i][0], quantum),
                }
            } else {
                series(&self.data[i], 0.0, quantum)
            }
        };
        let cond = |u: f64, derivative: usize, curve: CurveRef| ConditionSpec {
            u,
            derivative,
            curve,
        };
        let name_p = |k: usize| format!("{prefix}p{k:02}");
        let name_d = |k: usize| format!("{prefix}d{k:02}");
        let last = nodes.len() - 1;
        let mut counts: BTreeMap<String, usize> = BTreeMap::new();
        let mut patch_name = |p: usize| -> String {
            // The first station inside the patch: a junction node belongs to the part before.
            let part = &self.stations[(nodes[p] + 1).min(nodes[p + 1])].part;
            let base = if part.is_empty() { "patch" } else { part };
            let k = counts.entry(base.to_string()).or_insert(0);
            *k += 1;
            format!("{base}{:02}", *k)
        };
        let patches = out.patches.get_or_insert_with(Vec::new);
        match self.joint {
            Joint::Hermite => {
                // A derivative curve moves a patch of chord length L by at most L·4/27 times
                // its size (the largest Hermite weight of a slope, u(1 − u)², at u = 1/3).
                let slope_budget = 0.5 * trim * 27.0 / 4.0 / longest.max(1e-300);
                for (k, &i) in nodes.iter().enumerate() {
                    out.curves.insert(name_p(k), curve(position(i)));
                    out.curves.insert(
                        name_d(k),
                        curve(series(&solved.curves[k], slope_budget, slope_quantum)),
                    );
                }
                let origin = format!("{prefix}origin");
                out.curves
                    .insert(origin.clone(), curve(CurveKind::Point { at: [0.0; 3] }));
                // X_u at a node is the patch's chord length times the node's derivative curve.
                let slope = |k: usize, l: f64| {
                    CurveRef::Inline(Box::new(curve(CurveKind::Derivative {
                        position: CurveRef::Name(origin.clone()),
                        direction: CurveRef::Name(name_d(k)),
                        scale: l,
                    })))
                };
                for p in 0..last {
                    let l = self.length(nodes, p);
                    patches.push(PatchSpec {
                        name: patch_name(p),
                        operator: None,
                        conditions: vec![
                            cond(0.0, 0, CurveRef::Name(name_p(p))),
                            cond(0.0, 1, slope(p, l)),
                            cond(1.0, 0, CurveRef::Name(name_p(p + 1))),
                            cond(1.0, 1, slope(p + 1, l)),
                        ],
                    });
                }
            }
            Joint::FourPoints => {
                for p in 0..last {
                    if p == 0 {
                        out.curves.insert(name_p(0), curve(position(nodes[0])));
                    }
                    // The Lagrange-like weights of the inner curves stay below about 1.3 for
                    // the a·n used; half the budget each.
                    for q in 0..2 {
                        out.curves.insert(
                            name_p(3 * p + 1 + q),
                            curve(series(&solved.curves[2 * p + q], 0.5 * trim / 1.3, quantum)),
                        );
                    }
                    out.curves
                        .insert(name_p(3 * p + 3), curve(position(nodes[p + 1])));
                    patches.push(PatchSpec {
                        name: patch_name(p),
                        operator: None,
                        conditions: vec![
                            cond(0.0, 0, CurveRef::Name(name_p(3 * p))),
                            cond(INNER_KNOTS[0], 0, CurveRef::Name(name_p(3 * p + 1))),
                            cond(INNER_KNOTS[1], 0, CurveRef::Name(name_p(3 * p + 2))),
                            cond(1.0, 0, CurveRef::Name(name_p(3 * p + 3))),
                        ],
                    });
                }
            }
        }
        let op = OperatorSpec::Polyharmonic {
            order: 2,
            a: solved.a,
        };
        match &out.operator {
            None => out.operator = Some(op),
            Some(o) if *o == op => {}
            Some(_) => {
                let n = patches.len();
                for p in &mut patches[n - last..] {
                    p.operator = Some(op.clone());
                }
            }
        }
        out.solver.modes = out.solver.modes.max(self.modes);
    }
}

impl Chain {
    /// Fits the chain for each smoothing parameter of `candidates` and keeps the best: among
    /// those whose patches all meet `tol` (absolute), the fewest patches, then the smallest
    /// error; if none meets it, the smallest error. With `patches`, the nodes are spread
    /// evenly instead of chosen ([`Chain::even_nodes`]); `None` if that many do not fit.
    pub fn fit(
        &self,
        candidates: &[f64],
        tol: f64,
        patches: Option<usize>,
    ) -> Option<(Vec<usize>, Solved)> {
        let mut best: Option<(Vec<usize>, Solved)> = None;
        for &a in candidates {
            let nodes = match patches {
                Some(p) => self.even_nodes(p)?,
                None => self.adaptive_nodes(a, tol),
            };
            let solved = self.solve(&nodes, a);
            let worst = |s: &Solved| s.errors.iter().cloned().fold(0.0, f64::max);
            let better = match &best {
                None => true,
                Some((bn, bs)) => {
                    let (meets, best_meets) = (worst(&solved) <= tol, worst(bs) <= tol);
                    match (meets, best_meets) {
                        (true, false) => true,
                        (false, true) => false,
                        (true, true) => {
                            nodes.len() < bn.len()
                                || (nodes.len() == bn.len() && worst(&solved) < worst(bs))
                        }
                        (false, false) => worst(&solved) < worst(bs),
                    }
                }
            };
            if better {
                best = Some((nodes, solved));
            }
        }
        best
    }
}

/// `x` to `digits` significant digits.
pub(crate) fn significant(x: f64, digits: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let e = x.abs().log10().floor() as i32 - digits + 1;
    let q = 10f64.powi(e);
    let r = (x / q).round() * q;
    // Through its decimal text, so the value is the one a design file holds.
    format!("{r:.*e}", (digits - 1) as usize)
        .parse()
        .unwrap_or(r)
}

/// The smallest `M ≤ max_modes` whose neglected signal modes add up to at most `budget` at
/// every station of `inner` (module documentation).
fn choose_modes(full: &[Series], inner: &[usize], max_modes: usize, budget: f64) -> usize {
    let full_modes = (full[0].len() - 1) / 2;
    let band = full_modes.div_ceil(2)..=full_modes;
    let mut modes = 1;
    for &j in inner {
        let c = &full[j];
        let amp = |m: usize| (c[2 * m - 1].norm_squared() + c[2 * m].norm_squared()).sqrt();
        let noise = (band.clone().map(|m| amp(m).powi(2)).sum::<f64>()
            / band.clone().count().max(1) as f64)
            .sqrt();
        let signal: Vec<f64> = (1..=full_modes)
            .map(|m| if amp(m) > 3.0 * noise { amp(m) } else { 0.0 })
            .collect();
        // tail[M] = Σ_{m > M} signal.
        let mut tail = 0.0;
        let mut need = 1;
        for m in (1..=full_modes).rev() {
            tail += signal[m - 1];
            if tail > budget {
                need = m;
                break;
            }
        }
        modes = modes.max(need.min(max_modes));
    }
    modes
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(radius: f64, z: f64, wobble: f64, noise: &mut impl FnMut() -> f64) -> Station {
        let points = (0..64)
            .map(|k| {
                let v = TAU * k as f64 / 64.0;
                let r = radius * (1.0 + wobble * (3.0 * v).cos());
                Vec3::new(r * v.cos(), r * v.sin(), z) + Vec3::new(noise(), noise(), noise())
            })
            .collect();
        Station {
            points,
            pole: false,
            part: String::new(),
        }
    }

    /// Noise alone does not raise the number of modes; a three-lobed section needs four.
    #[test]
    fn modes_follow_the_signal_not_the_noise() {
        let mut seed = 1u64;
        let mut noise = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-3
        };
        let round: Vec<Station> = (0..20)
            .map(|j| ring(1.0 + 0.01 * j as f64, j as f64 * 0.1, 0.0, &mut noise))
            .collect();
        let chain = Chain::new(round, &[], Joint::Hermite, 24, 1e-3);
        assert_eq!(chain.modes(), 1);
        let lobed: Vec<Station> = (0..20)
            .map(|j| ring(1.0, j as f64 * 0.1, 0.1, &mut noise))
            .collect();
        let chain = Chain::new(lobed, &[], Joint::Hermite, 24, 1e-3);
        // r cos v with r = 1 + 0.1 cos 3v has modes 1, 2 and 4.
        assert_eq!(chain.modes(), 4);
    }
}
