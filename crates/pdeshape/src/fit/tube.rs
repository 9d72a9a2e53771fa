//! The automatic mode: a closed tube-like or star-shaped body as a chain of biharmonic patches
//! along its main axis, closed by poles at both ends.
//!
//! 1. **Axis.** The principal axis of largest variance of the triangles (area-weighted
//!    centroids); `e₁` is the second principal axis, `e₂ = axis × e₁`.
//! 2. **Fine sections.** `N` planes at heights `h_j = h_min + (h_max − h_min)(1 − cos πt_j)/2`,
//!    `t_j = j/(N + 1)` (denser towards the ends, where a round end's radius grows like
//!    `√(h − h_min)`), each cut into one periodic curve sampled at `S` angles
//!    ([`super::section`]). The extreme vertices along the axis are the poles.
//! 3. **Modes.** The smallest `M` whose truncated Fourier series meets every fine section to a
//!    quarter of the target.
//! 4. **Patches.** Some fine sections are the patches' position curves (nodes); the poles are
//!    the first and last nodes. Patch `p` runs from node `p` (`u = 0`) to node `p + 1`
//!    (`u = 1`) with the biharmonic operator and four conditions: the two positions and the
//!    derivative curves `D_p`, `D_{p+1}`, each shared by the two patches at its node (so
//!    neighbours meet with one tangent plane: G1). The fine sections between two nodes get the
//!    `u` of their cumulative root-mean-square distance from section to section (a chord-length
//!    parameter), and the `D`s are the least-squares solution, mode by mode, of
//!    `Xₙ(u_j) = data_j,ₙ` over all fine sections ([`super::basis::weights`]).
//!    A patch's error is the largest distance, along the mesh's normal there (from differences
//!    of neighbouring samples and sections), between a fine section's samples and the fitted
//!    curve at its `u`: a slide of the parameters along the surface is no error of the shape.
//! 5. **Adaptive refinement.** Patches whose largest sample error exceeds the target are split
//!    at their middle fine section until every patch meets it; then nodes whose removal keeps
//!    every patch within the target are merged away, smallest error first.

use super::basis::weights;
use super::mesh::TriMesh;
use super::section::{fourier, Frame, Section, Slicer};
use crate::spec::{
    ConditionSpec, CurveKind, CurveRef, CurveSpec, DesignSpec, OperatorSpec, PatchSpec, SolverSpec,
    V3,
};
use crate::{Error, Result, Vec3, TAU};
use nalgebra::{DMatrix, Matrix3, SymmetricEigen};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Options of the automatic mode.
#[derive(Clone, Debug, PartialEq)]
pub struct TubeOptions {
    /// Largest sample error allowed, as a fraction of the mesh's bounding-box diagonal.
    pub target: f64,
    /// Smoothing parameter `a` of the biharmonic operator.
    pub a: f64,
    /// Fine sections `N` (the least-squares data and the candidate nodes).
    pub sections: usize,
    /// Samples `S` per section (a power of two).
    pub samples: usize,
    /// Most Fourier modes per curve.
    pub max_modes: usize,
    /// A fixed number of patches (the nodes spread evenly over the fine sections), instead of
    /// the adaptive choice.
    pub patches: Option<usize>,
}

impl Default for TubeOptions {
    fn default() -> Self {
        TubeOptions {
            target: 1e-3,
            a: 1.0,
            sections: 96,
            samples: 128,
            max_modes: 32,
            patches: None,
        }
    }
}

/// What the automatic mode made.
#[derive(Clone, Debug)]
pub struct TubeFit {
    /// The fitted design (Fourier position and derivative curves, a point at each pole).
    pub spec: DesignSpec,
    pub frame: Frame,
    /// Fine sections used (some near the poles may be dropped, see [`TubeFit::dropped`]).
    pub sections: usize,
    /// Fine sections next to the poles left out because they were degenerate.
    pub dropped: usize,
    /// Fourier modes of the curves.
    pub modes: usize,
    pub patches: usize,
    /// Largest distance, along the mesh's normal, between a fine section's samples and the
    /// fitted patch at its `u`, relative to the diagonal.
    pub sample_error: f64,
}

/// Fits a closed mesh (see the module documentation).
pub fn fit_tube(mesh: &TriMesh, opts: &TubeOptions) -> Result<TubeFit> {
    if !(opts.target > 0.0 && opts.target.is_finite()) {
        return Err(
            Error::invalid(format!("must be a positive number (got {})", opts.target))
                .at("tolerance"),
        );
    }
    if opts.sections < 8 || opts.sections > 4096 {
        return Err(Error::invalid(format!(
            "must be between 8 and 4096 (got {})",
            opts.sections
        ))
        .at("sections"));
    }
    mesh.require_closed()?;
    let diag = mesh.diagonal();
    if diag <= 0.0 {
        return Err(Error::invalid("the mesh has no extent"));
    }
    let tol = opts.target * diag;
    let frame = principal_frame(mesh);
    let slicer = Slicer::new(mesh, frame);
    let (lo, hi) = mesh
        .triangles
        .iter()
        .flatten()
        .map(|&i| (i, frame.height(&mesh.positions[i as usize])))
        .fold(
            ((0u32, f64::INFINITY), (0u32, f64::NEG_INFINITY)),
            |(lo, hi), (i, h)| {
                (
                    if h < lo.1 { (i, h) } else { lo },
                    if h > hi.1 { (i, h) } else { hi },
                )
            },
        );
    let (hmin, hmax) = (lo.1, hi.1);
    let n = opts.sections;
    let heights: Vec<f64> = (1..=n)
        .map(|j| {
            let t = j as f64 / (n + 1) as f64;
            hmin + (hmax - hmin) * 0.5 * (1.0 - (std::f64::consts::PI * t).cos())
        })
        .collect();
    let cut: Vec<Result<Section>> = heights
        .par_iter()
        .map(|&h| slicer.section(h, opts.samples))
        .collect();
    // Degenerate sections right next to a pole (a handful of triangles) are left out.
    const EDGE: usize = 3;
    let mut sections = Vec::with_capacity(n);
    let mut dropped = 0;
    for (j, s) in cut.into_iter().enumerate() {
        match s {
            Ok(s) => sections.push(s),
            Err(_) if j < EDGE || j + EDGE >= n => dropped += 1,
            Err(e) => return Err(e),
        }
    }
    if sections.len() < 4 {
        return Err(Error::invalid("fewer than four usable sections"));
    }
    let poles = [mesh.positions[lo.0 as usize], mesh.positions[hi.0 as usize]];
    let (data, modes) = section_series(&sections, opts.max_modes, 0.25 * tol);
    let chain = Chain::new(&sections, data, poles, modes, opts.a);
    let nodes = match opts.patches {
        Some(p) => chain.even_nodes(p)?,
        None => chain.adaptive_nodes(0.4 * tol),
    };
    let solved = chain.solve(&nodes);
    let sample_error = solved.errors.iter().cloned().fold(0.0, f64::max) / diag;
    let spec = chain.design(&nodes, &solved, 1e-7 * diag);
    Ok(TubeFit {
        spec,
        frame,
        sections: sections.len(),
        dropped,
        modes,
        patches: nodes.len() - 1,
        sample_error,
    })
}

/// The principal axes of the triangles' area-weighted centroids.
fn principal_frame(mesh: &TriMesh) -> Frame {
    let mut weight = 0.0;
    let mut mean = Vec3::zeros();
    let tris: Vec<(f64, Vec3)> = (0..mesh.triangles.len())
        .map(|t| {
            let [a, b, c] = mesh.corners(t);
            (0.5 * (b - a).cross(&(c - a)).norm(), (a + b + c) / 3.0)
        })
        .collect();
    for (w, c) in &tris {
        weight += w;
        mean += c * *w;
    }
    let mean = if weight > 0.0 { mean / weight } else { mean };
    let mut cov = Matrix3::zeros();
    for (w, c) in &tris {
        let d = c - mean;
        cov += d * d.transpose() * *w;
    }
    let eig = SymmetricEigen::new(cov);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
    let pick = |k: usize| -> Vec3 {
        let v: Vec3 = eig.eigenvectors.column(order[k]).into();
        // A deterministic sign: the largest component positive.
        let m = (0..3)
            .max_by(|&i, &j| v[i].abs().total_cmp(&v[j].abs()))
            .unwrap_or(0);
        if v[m] < 0.0 {
            -v
        } else {
            v
        }
    };
    let axis = pick(0).normalize();
    let e1 = (pick(1) - axis * pick(1).dot(&axis)).normalize();
    let e2 = axis.cross(&e1);
    Frame {
        origin: mean,
        e1,
        e2,
        axis,
    }
}

/// A curve's Fourier coefficients: `[a₀, a₁, b₁, a₂, b₂, …]`.
type Series = Vec<Vec3>;

/// The coefficients of every section up to the smallest `M ≤ max_modes` that meets the samples
/// of every section but the twelfth next to each pole within `tol` (or `max_modes`).
fn section_series(sections: &[Section], max_modes: usize, tol: f64) -> (Vec<Series>, usize) {
    let s = sections[0].points.len();
    let max_modes = max_modes.min(s / 2 - 1).max(1);
    let full: Vec<Series> = sections
        .iter()
        .map(|sec| {
            let (a0, c, sn) = fourier(&sec.points, max_modes);
            let mut out = vec![a0];
            for k in 0..max_modes {
                out.push(c[k]);
                out.push(sn[k]);
            }
            out
        })
        .collect();
    // Residuals after each mode, per section. The sections next to the poles cut the few
    // triangles of a pole's fan, whose corners no short series follows; they are left out of
    // this choice (the least squares still sees them).
    let mut worst = vec![0.0f64; max_modes + 1];
    let skip = sections.len() / 12;
    let inner = skip..sections.len() - skip;
    for (sec, series) in sections[inner.clone()].iter().zip(&full[inner]) {
        let mut r: Vec<Vec3> = sec.points.iter().map(|p| p - series[0]).collect();
        for m in 1..=max_modes {
            for (k, rk) in r.iter_mut().enumerate() {
                let v = TAU * k as f64 / s as f64;
                let x = m as f64 * v;
                *rk -= series[2 * m - 1] * x.cos() + series[2 * m] * x.sin();
            }
            let e = r.iter().map(|x| x.norm()).fold(0.0, f64::max);
            worst[m] = worst[m].max(e);
        }
    }
    let modes = (1..=max_modes)
        .find(|&m| worst[m] <= tol)
        .unwrap_or(max_modes);
    let data = full
        .into_iter()
        .map(|mut c| {
            c.truncate(2 * modes + 1);
            c
        })
        .collect();
    (data, modes)
}

/// The least-squares problem over the fine sections.
struct Chain<'s> {
    sections: &'s [Section],
    /// Coefficients of the fine sections.
    data: Vec<Series>,
    poles: [Vec3; 2],
    modes: usize,
    a: f64,
    /// Cumulative chord parameter: `s[0]` at the first pole, `s[j + 1]` at section `j`,
    /// `s[N + 1]` at the last pole.
    s: Vec<f64>,
    /// Unit normals of the mesh at the sections' samples, from differences of neighbouring
    /// samples and sections (zero where they degenerate).
    normals: Vec<Vec<Vec3>>,
}

/// The solved derivative curves and each patch's largest sample error.
struct Solved {
    /// Coefficients of the derivative curve at each node.
    slopes: Vec<Series>,
    errors: Vec<f64>,
}

impl<'s> Chain<'s> {
    fn new(
        sections: &'s [Section],
        data: Vec<Series>,
        poles: [Vec3; 2],
        modes: usize,
        a: f64,
    ) -> Self {
        let rms = |a: &[Vec3], b: &[Vec3]| -> f64 {
            let sum: f64 = a.iter().zip(b).map(|(p, q)| (p - q).norm_squared()).sum();
            (sum / a.len() as f64).sqrt()
        };
        let sp = sections[0].points.len();
        let first = vec![poles[0]; sp];
        let last = vec![poles[1]; sp];
        let mut s = vec![0.0];
        let mut prev: &[Vec3] = &first;
        for sec in sections {
            let d = rms(prev, &sec.points);
            s.push(s.last().copied().unwrap_or(0.0) + d.max(1e-300));
            prev = &sec.points;
        }
        let d = rms(prev, &last);
        s.push(s.last().copied().unwrap_or(0.0) + d.max(1e-300));
        let nsec = sections.len();
        let normals = (0..nsec)
            .map(|j| {
                let pts = &sections[j].points;
                (0..sp)
                    .map(|k| {
                        let below = if j == 0 {
                            poles[0]
                        } else {
                            sections[j - 1].points[k]
                        };
                        let above = if j + 1 == nsec {
                            poles[1]
                        } else {
                            sections[j + 1].points[k]
                        };
                        let tv = pts[(k + 1) % sp] - pts[(k + sp - 1) % sp];
                        let n = (above - below).cross(&tv);
                        let len = n.norm();
                        if len > 0.0 && len.is_finite() {
                            n / len
                        } else {
                            Vec3::zeros()
                        }
                    })
                    .collect()
            })
            .collect();
        Chain {
            sections,
            data,
            poles,
            modes,
            a,
            s,
            normals,
        }
    }

    /// Number of fine positions including the poles: `N + 2`.
    fn len(&self) -> usize {
        self.sections.len() + 2
    }

    /// Position coefficients at fine position `i` (0 and `N + 1` are the poles).
    fn position(&self, i: usize) -> Series {
        let width = 2 * self.modes + 1;
        if i == 0 || i + 1 == self.len() {
            let mut c = vec![Vec3::zeros(); width];
            c[0] = self.poles[if i == 0 { 0 } else { 1 }];
            c
        } else {
            self.data[i - 1].clone()
        }
    }

    fn even_nodes(&self, patches: usize) -> Result<Vec<usize>> {
        let last = self.len() - 1;
        if patches == 0 || 3 * patches > last {
            return Err(Error::invalid(format!(
                "{patches} patches: between 1 and {} for {} sections",
                last / 3,
                self.sections.len()
            ))
            .at("sections"));
        }
        let mut nodes: Vec<usize> = (0..=patches)
            .map(|k| (k as f64 * last as f64 / patches as f64).round() as usize)
            .collect();
        nodes.dedup();
        Ok(nodes)
    }

    /// Nodes chosen by splitting and merging (module documentation).
    fn adaptive_nodes(&self, tol: f64) -> Vec<usize> {
        let last = self.len() - 1;
        // Patches keep at least two fine sections inside.
        const MIN_SPAN: usize = 3;
        let mut nodes = vec![0, last / 4, last / 2, 3 * last / 4, last];
        nodes.dedup();
        loop {
            let solved = self.solve(&nodes);
            let mut next = vec![nodes[0]];
            let mut split = false;
            for p in 0..nodes.len() - 1 {
                let (a, b) = (nodes[p], nodes[p + 1]);
                if solved.errors[p] > tol && b - a >= 2 * MIN_SPAN {
                    next.push((a + b) / 2);
                    split = true;
                }
                next.push(b);
            }
            nodes = next;
            if !split {
                break;
            }
        }
        // Merge: try removing interior nodes, the one with the smallest neighbouring errors
        // first; keep a removal if every patch still meets the target.
        let mut solved = self.solve(&nodes);
        let mut blocked = vec![false; last + 1];
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
            let t = self.solve(&trial);
            if t.errors.iter().all(|&e| e <= tol) {
                nodes = trial;
                solved = t;
            } else {
                blocked[nodes[k]] = true;
            }
        }
        nodes
    }

    /// The least-squares derivative curves for the given nodes (fine positions), mode by mode,
    /// and each patch's largest sample error.
    fn solve(&self, nodes: &[usize]) -> Solved {
        let width = 2 * self.modes + 1;
        let unknowns = nodes.len();
        let positions: Vec<Series> = nodes.iter().map(|&i| self.position(i)).collect();
        // Rows: (patch, fine position j strictly inside, u_j).
        let mut rows = Vec::new();
        for p in 0..nodes.len() - 1 {
            let (a, b) = (nodes[p], nodes[p + 1]);
            for j in a + 1..b {
                let u = (self.s[j] - self.s[a]) / (self.s[b] - self.s[a]);
                rows.push((p, j, u));
            }
        }
        let mut slopes = vec![vec![Vec3::zeros(); width]; unknowns];
        for n in 0..=self.modes {
            let w: Vec<[f64; 4]> = rows.iter().map(|r| weights(n, self.a, r.2)).collect();
            let cols: Vec<usize> = if n == 0 {
                vec![0]
            } else {
                vec![2 * n - 1, 2 * n]
            };
            let mut m = DMatrix::<f64>::zeros(rows.len(), unknowns);
            let mut rhs = DMatrix::<f64>::zeros(rows.len(), 3 * cols.len());
            for (r, (&(p, j, _), w)) in rows.iter().zip(&w).enumerate() {
                m[(r, p)] = w[1];
                m[(r, p + 1)] = w[3];
                for (q, &c) in cols.iter().enumerate() {
                    let target =
                        self.position(j)[c] - positions[p][c] * w[0] - positions[p + 1][c] * w[2];
                    for d in 0..3 {
                        rhs[(r, 3 * q + d)] = target[d];
                    }
                }
            }
            // Tikhonov damping far below the data's scale keeps a node without data (a
            // patch with no fine section inside) determined.
            let mut normal = m.transpose() * &m;
            let trace = normal.trace().max(1e-300);
            for k in 0..unknowns {
                normal[(k, k)] += 1e-12 * trace / unknowns as f64;
            }
            let b = m.transpose() * rhs;
            let x = normal
                .clone()
                .cholesky()
                .map(|ch| ch.solve(&b))
                .unwrap_or_else(|| DMatrix::zeros(unknowns, 3 * cols.len()));
            for (k, slope) in slopes.iter_mut().enumerate() {
                for (q, &c) in cols.iter().enumerate() {
                    slope[c] = Vec3::new(x[(k, 3 * q)], x[(k, 3 * q + 1)], x[(k, 3 * q + 2)]);
                }
            }
        }
        // Errors: the fitted curve at each fine section against its samples.
        let sp = self.sections[0].points.len();
        let trig: Vec<(f64, f64)> = (0..sp)
            .flat_map(|k| {
                let v = TAU * k as f64 / sp as f64;
                (1..=self.modes).map(move |m| ((m as f64 * v).cos(), (m as f64 * v).sin()))
            })
            .collect();
        let mut errors = vec![0.0f64; nodes.len() - 1];
        for &(p, j, u) in &rows {
            let mut c = vec![Vec3::zeros(); width];
            for n in 0..=self.modes {
                let w = weights(n, self.a, u);
                let idx: &[usize] = if n == 0 { &[0] } else { &[2 * n - 1, 2 * n] };
                for &i in idx {
                    c[i] = positions[p][i] * w[0]
                        + slopes[p][i] * w[1]
                        + positions[p + 1][i] * w[2]
                        + slopes[p + 1][i] * w[3];
                }
            }
            let pts = &self.sections[j - 1].points;
            let normals = &self.normals[j - 1];
            for (k, q) in pts.iter().enumerate() {
                let mut x = c[0];
                for m in 1..=self.modes {
                    let (cs, sn) = trig[k * self.modes + m - 1];
                    x += c[2 * m - 1] * cs + c[2 * m] * sn;
                }
                // The distance across the surface: a shift of the parameters along it is no
                // error of the shape.
                let e = x - q;
                let n = normals[k];
                let d = if n == Vec3::zeros() {
                    e.norm()
                } else {
                    e.dot(&n).abs()
                };
                errors[p] = errors[p].max(d);
            }
        }
        Solved { slopes, errors }
    }

    /// The design: a point curve at each pole, Fourier position curves at the other nodes, a
    /// Fourier derivative curve at every node, one biharmonic patch between consecutive nodes.
    /// Coefficients are rounded to multiples of about `quantum` and trailing modes below it are
    /// dropped.
    fn design(&self, nodes: &[usize], solved: &Solved, quantum: f64) -> DesignSpec {
        let digits = (-quantum.log10()).ceil().clamp(0.0, 17.0) as usize;
        let round = |x: f64| -> f64 {
            let r: f64 = format!("{x:.digits$}").parse().unwrap_or(x);
            if r == 0.0 {
                0.0
            } else {
                r
            }
        };
        let v3 = |p: Vec3| -> V3 { [round(p.x), round(p.y), round(p.z)] };
        let series = |c: &Series| -> CurveKind {
            let mut modes = self.modes;
            while modes > 0 && c[2 * modes - 1].amax() < quantum && c[2 * modes].amax() < quantum {
                modes -= 1;
            }
            CurveKind::Fourier {
                a0: v3(c[0]),
                cos: (1..=modes).map(|m| v3(c[2 * m - 1])).collect(),
                sin: (1..=modes).map(|m| v3(c[2 * m])).collect(),
            }
        };
        let curve = |kind| CurveSpec {
            kind,
            transform: Vec::new(),
            v_origin: 0.0,
            arc_length: false,
        };
        let last = nodes.len() - 1;
        let mut curves = BTreeMap::new();
        let name_p = |k: usize| format!("p{k:02}");
        let name_d = |k: usize| format!("d{k:02}");
        for (k, &i) in nodes.iter().enumerate() {
            let kind = if k == 0 || k == last {
                CurveKind::Point {
                    at: v3(self.position(i)[0]),
                }
            } else {
                series(&self.position(i))
            };
            curves.insert(name_p(k), curve(kind));
            curves.insert(name_d(k), curve(series(&solved.slopes[k])));
        }
        let cond = |u: f64, derivative: usize, name: String| ConditionSpec {
            u,
            derivative,
            curve: CurveRef::Name(name),
        };
        let patches = (0..last)
            .map(|p| PatchSpec {
                name: format!("patch{:02}", p + 1),
                operator: None,
                conditions: vec![
                    cond(0.0, 0, name_p(p)),
                    cond(0.0, 1, name_d(p)),
                    cond(1.0, 0, name_p(p + 1)),
                    cond(1.0, 1, name_d(p + 1)),
                ],
            })
            .collect();
        DesignSpec {
            title: None,
            operator: Some(OperatorSpec::Polyharmonic {
                order: 2,
                a: self.a,
            }),
            solver: SolverSpec {
                modes: self.modes.max(1),
                ..SolverSpec::default()
            },
            curves,
            patches: Some(patches),
            ..DesignSpec::default()
        }
    }
}
