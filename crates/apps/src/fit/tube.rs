//! The tube mode: a closed tube-like or star-shaped body as a chain of biharmonic patches
//! along its main axis, closed by poles at both ends; or a tube open at one or both ends (a vase,
//! a pipe), whose boundary loops across the axis are its end stations ([`fit_open_tube`]).
//!
//! 1. **Axis.** The principal axis of largest variance of the triangles (area-weighted
//!    centroids); `e₁` is the second principal axis, `e₂ = axis × e₁`.
//! 2. **Fine sections.** `N` planes at heights `h_j = h_min + (h_max − h_min)(1 − cos πt_j)/2`,
//!    `t_j = j/(N + 1)` (denser towards the ends, where a round end's radius grows like
//!    `√(h − h_min)`), each cut into one periodic curve sampled at `S` angles
//!    ([`super::section`]). The extreme vertices along the axis are the poles.
//! 3. **Patches.** The poles and the sections are the stations of a Hermite chain
//!    ([`super::chain`]): positions at the nodes, one derivative curve per node shared by the
//!    two patches there (G1), fitted by least squares; nodes by splitting and merging until
//!    every patch meets the target.
//! 4. **Smoothing parameter.** A patch's mode `n` is `(α + βu)e^{anu} + (γ + δu)e^{−anu}`
//!    over `u ∈ [0, 1]` whatever the patch's length, so with a large `a` the higher modes bend
//!    within every patch however short, and no number of patches makes them follow a section
//!    whose shape changes slowly. The fit tries `a = 1, 1/2, 1/4` (or the one given) and keeps
//!    the one that needs the fewest patches.

use super::chain::{Chain, Joint, Station};
use super::mesh::InputMesh;
use super::options::{Fit, FitMode, FitOptions};
use super::section::{AxisFrame, Section, Slicer};
use crate::spec::{DesignSpec, SolverSpec};
use crate::{Error, Result, Vec3};
use nalgebra::{Matrix3, SymmetricEigen};
use rayon::prelude::*;

/// The smoothing parameters tried by the tube mode.
pub const TUBE_A: [f64; 3] = [1.0, 0.5, 0.25];

/// Share of the target left to the Fourier truncation of the sections.
pub(crate) const MODES_SHARE: f64 = 0.25;
/// Share of the target the patches' sample errors must meet.
pub(crate) const SAMPLE_SHARE: f64 = 0.4;
/// Share of the target spent on dropping trailing terms of the written curves.
pub(crate) const TRIM_SHARE: f64 = 0.05;
/// Coefficients are written to about this fraction of the diagonal.
pub(crate) const QUANTUM: f64 = 1e-7;

/// Fits a closed mesh (see the module documentation).
pub fn fit_tube(mesh: &InputMesh, opts: &FitOptions) -> Result<Fit> {
    opts.check()?;
    mesh.require_closed()?;
    let diag = mesh.diagonal();
    if !(diag.is_finite() && diag > 0.0) {
        return Err(Error::invalid("the mesh has no extent"));
    }
    fit_along(mesh, opts, principal_frame(mesh), [None, None])
}

/// The open ends of a tube: each boundary loop of `mesh` lying across the tube's axis (its heights
/// within `tol` of each other) at one end of the mesh (within `tol` of the lowest or the highest
/// vertex), as `(height, loop points)`, lower end first (`None` for an end closed by a pole).
type Ends = [Option<(f64, Vec<Vec3>)>; 2];

/// The frame of a tube open at one or both ends and its [`Ends`]: the axis runs through the
/// centroids of two boundary loops, or square to the plane of one (towards the mesh); `e₁` is
/// the mesh's second principal axis made square to it. `None` when the mesh has no boundary,
/// more than two loops, or a loop that is not an end across the axis.
pub(crate) fn open_ends(mesh: &InputMesh, tol: f64) -> Option<(AxisFrame, Ends)> {
    let loops = mesh.boundary_loops().ok()?;
    if loops.is_empty() || loops.len() > 2 {
        return None;
    }
    let rings: Vec<Vec<Vec3>> = loops
        .iter()
        .map(|l| l.iter().map(|&i| mesh.positions[i as usize]).collect())
        .collect();
    let mean = |r: &[Vec3]| r.iter().fold(Vec3::zeros(), |a, p| a + p) / r.len() as f64;
    let centres: Vec<Vec3> = rings.iter().map(|r| mean(r)).collect();
    let principal = principal_frame(mesh);
    let axis = if rings.len() == 2 {
        centres[1] - centres[0]
    } else {
        let c = centres[0];
        let cov = rings[0]
            .iter()
            .fold(Matrix3::zeros(), |m, p| m + (p - c) * (p - c).transpose());
        let eig = SymmetricEigen::new(cov);
        let k = (0..3)
            .min_by(|&i, &j| eig.eigenvalues[i].total_cmp(&eig.eigenvalues[j]))
            .unwrap_or(0);
        let n: Vec3 = eig.eigenvectors.column(k).into();
        if n.dot(&(principal.origin - c)) < 0.0 {
            -n
        } else {
            n
        }
    };
    if axis.norm().is_nan() || axis.norm() <= 0.0 {
        return None;
    }
    let axis = axis.normalize();
    let mut e1 = principal.e1 - axis * principal.e1.dot(&axis);
    if e1.norm() < 1e-6 {
        e1 = principal.axis - axis * principal.axis.dot(&axis);
    }
    let e1 = e1.normalize();
    let frame = AxisFrame {
        origin: principal.origin,
        e1,
        e2: axis.cross(&e1),
        axis,
    };
    let (lo, hi) = extremes(mesh, &frame);
    let (hmin, hmax) = (frame.height(&lo), frame.height(&hi));
    let mut ends: Ends = [None, None];
    for points in rings {
        let (a, b) = points
            .iter()
            .map(|p| frame.height(p))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), h| {
                (a.min(h), b.max(h))
            });
        if b - a > tol {
            return None;
        }
        let h = 0.5 * (a + b);
        let end = if (h - hmin).abs() <= tol {
            0
        } else if (hmax - h).abs() <= tol {
            1
        } else {
            return None;
        };
        if ends[end].is_some() {
            return None;
        }
        ends[end] = Some((h, points));
    }
    Some((frame, ends))
}

/// Fits a tube open at one or both ends of its main axis (a vase, a pipe, a cup without its
/// bottom): as [`fit_tube`], with each open end's boundary loop as the first or last station
/// instead of a pole. Fails unless [`open_ends`] finds the ends.
pub fn fit_open_tube(mesh: &InputMesh, opts: &FitOptions) -> Result<Fit> {
    opts.check()?;
    mesh.require_single()?;
    let diag = mesh.diagonal();
    if !(diag.is_finite() && diag > 0.0) {
        return Err(Error::invalid("the mesh has no extent"));
    }
    let tol = opts.target * diag;
    let (frame, ends) = open_ends(mesh, tol).ok_or_else(|| {
        Error::invalid(
            "the mesh's boundary is not one or two loops across its main axis at its ends",
        )
    })?;
    fit_along(mesh, opts, frame, ends)
}

/// The chain of a tube along `frame`'s axis between its two ends, each a pole (the extreme
/// vertex) or an open end's loop ([`Ends`]): sections between them, denser towards the poles.
fn fit_along(mesh: &InputMesh, opts: &FitOptions, frame: AxisFrame, ends: Ends) -> Result<Fit> {
    let diag = mesh.diagonal();
    let tol = opts.target * diag;
    let slicer = Slicer::new(mesh, frame, opts.file);
    let (lo, hi) = extremes(mesh, &frame);
    let h0 = ends[0].as_ref().map_or(frame.height(&lo), |e| e.0);
    let h1 = ends[1].as_ref().map_or(frame.height(&hi), |e| e.0);
    let n = opts.sections;
    // Between the ends (an open end's loop is a station itself).
    let heights: Vec<f64> = (1..=n)
        .map(|j| {
            let t = j as f64 / (n + 1) as f64;
            // Denser towards a pole, where a round end's radius grows like `√(h − h_pole)`.
            match (&ends[0], &ends[1]) {
                (Some(_), Some(_)) => h0 + (h1 - h0) * t,
                (Some(_), None) => h0 + (h1 - h0) * (std::f64::consts::FRAC_PI_2 * t).sin(),
                (None, Some(_)) => h0 + (h1 - h0) * (1.0 - (std::f64::consts::FRAC_PI_2 * t).cos()),
                (None, None) => h0 + (h1 - h0) * 0.5 * (1.0 - (std::f64::consts::PI * t).cos()),
            }
        })
        .collect();
    let cut: Vec<Result<Section>> = heights
        .par_iter()
        .map(|&h| slicer.section(h, opts.samples, None))
        .collect();
    const EDGE: usize = 3;
    let end_station = |end: &Option<(f64, Vec<Vec3>)>, pole: Vec3| -> Result<Station> {
        Ok(match end {
            Some((h, ring)) => Station {
                points: Section::from_loop(ring, &frame, *h, opts.samples, opts.file)?.points,
                pole: false,
                part: String::new(),
            },
            None => Station::at_pole(pole, opts.samples, ""),
        })
    };
    let mut stations = vec![end_station(&ends[0], lo)?];
    let mut dropped = 0;
    for (j, s) in cut.into_iter().enumerate() {
        match s {
            Ok(s) => stations.push(Station {
                points: s.points,
                pole: false,
                part: String::new(),
            }),
            Err(_) if (ends[0].is_none() && j < EDGE) || (ends[1].is_none() && j + EDGE >= n) => {
                dropped += 1
            }
            Err(e) => return Err(e),
        }
    }
    stations.push(end_station(&ends[1], hi)?);
    if stations.len() < 6 {
        return Err(Error::invalid("fewer than four usable sections"));
    }
    let sections = stations.iter().filter(|s| !s.pole).count();
    let chain = Chain::new(
        stations,
        &[],
        Joint::Hermite,
        opts.max_modes,
        MODES_SHARE * tol,
    );
    let candidates = opts.a.map_or(TUBE_A.to_vec(), |a| vec![a]);
    let what = ChainFit {
        mode: FitMode::Tube,
        frame,
        sections,
        dropped,
        stations: "sections",
    };
    fit_one_chain(&chain, &candidates, tol, diag, opts, what)
}

/// What a one-chain fit reports besides the chain: its mode, frame and sections, and the word
/// for its stations in messages.
pub(crate) struct ChainFit {
    pub mode: FitMode,
    pub frame: AxisFrame,
    pub sections: usize,
    pub dropped: usize,
    pub stations: &'static str,
}

/// Fits `chain` with the smoothing parameters `candidates` (node choice, least squares) and
/// makes its design: the end of the tube and the sheet modes.
pub(crate) fn fit_one_chain(
    chain: &Chain,
    candidates: &[f64],
    tol: f64,
    diag: f64,
    opts: &FitOptions,
    what: ChainFit,
) -> Result<Fit> {
    let ChainFit {
        mode,
        frame,
        sections,
        dropped,
        stations,
    } = what;
    let (nodes, solved) = chain
        .fit(candidates, SAMPLE_SHARE * tol, opts.patches)
        .ok_or_else(|| {
            Error::invalid(format!(
                "{} patches: between 1 and {} for {sections} {stations}",
                opts.patches.unwrap_or(0),
                chain.max_patches()
            ))
            .at("sections")
        })?;
    let sample_error = solved.errors.iter().cloned().fold(0.0, f64::max) / diag;
    let mut spec = DesignSpec {
        solver: SolverSpec {
            modes: 1,
            ..SolverSpec::default()
        },
        ..DesignSpec::default()
    };
    chain.design_into(
        &nodes,
        &solved,
        "",
        QUANTUM * diag,
        TRIM_SHARE * tol,
        &mut spec,
    );
    Ok(Fit {
        spec,
        mode,
        frame,
        sections,
        dropped,
        modes: chain.modes(),
        patches: nodes.len() - 1,
        a: solved.a,
        sample_error,
        notes: Vec::new(),
    })
}

/// The vertices (used by triangles) of smallest and largest height along the frame's axis.
pub(crate) fn extremes(mesh: &InputMesh, frame: &AxisFrame) -> (Vec3, Vec3) {
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
    (mesh.positions[lo.0 as usize], mesh.positions[hi.0 as usize])
}

/// The principal axes of the triangles' area-weighted centroids: the axis of largest variance,
/// `e₁` the second, `e₂ = axis × e₁`.
pub(crate) fn principal_frame(mesh: &InputMesh) -> AxisFrame {
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
    AxisFrame {
        origin: mean,
        e1,
        e2,
        axis,
    }
}
