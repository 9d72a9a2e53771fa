//! The sheet mode: an open surface such as a face scan (book §4.6, Figs. 4.6–4.8) as a chain
//! of biharmonic patches through profile curves cut by parallel planes.
//!
//! 1. **AxisFrame.** The principal axes of the triangles: the axis of largest variance runs along
//!    the sheet (the planes are across it), `e₁`, the second, across it, and `e₂` is near the
//!    sheet's normal.
//! 2. **Profiles.** `N` planes at equal steps of height, each cutting the sheet in one open
//!    polyline between two boundary edges; each becomes, through a cubic spline, an even
//!    periodic curve ([`super::profile`]: the profile there and back, a cosine series). The
//!    sheet's two ends are not plane sections: they are the arcs of the mesh's boundary beyond
//!    the first and the last plane, between the boundary edges where those planes' profiles
//!    end, so the fit reaches the mesh's own edge however ragged; they are interpolated
//!    linearly, not by a spline, which would overshoot at their corners
//!    ([`super::profile::from_edge_arc`]). Planes right next to an end
//!    that cut the sheet in several pieces (grazing a ragged end) are left out.
//! 3. **Patches.** The profiles are the stations of a chain whose patches have four position
//!    curves at `u = 0, 1/3, 2/3, 1` (book §4.5; the profiles "grouped in fours" of §4.6): the
//!    ends are profiles of the sheet, shared by neighbouring patches (G0), and the two inside
//!    are fitted by least squares to the profiles between ([`super::chain`]). A mode's four
//!    positions pin it at `u = 1/3` and `2/3`; with `a·n` of a few units or more the mode
//!    swings far between them (the weights grow like `e^{an/3}`), so `a` is chosen with
//!    `a·M ≤ 2` for the `M` modes of the curves: the fit tries `a·M = 2, 1, 1/2`.
//!
//! The patches cover the sheet for `0 ≤ v ≤ π` and again, over the same points, for
//! `π ≤ v ≤ 2π`.

use super::chain::{Chain, Joint, Station};
use super::mesh::InputMesh;
use super::options::{Fit, FitMode, FitOptions};
use super::section::{AxisFrame, Piece, Slicer};
use super::tube::{fit_one_chain, principal_frame, ChainFit, MODES_SHARE};
use crate::{Error, Result, Vec3};
use rayon::prelude::*;

/// The values of `a·M` tried by the sheet mode.
pub const SHEET_AM: [f64; 3] = [2.0, 1.0, 0.5];

/// Fits an open mesh (see the module documentation).
pub fn fit_sheet(mesh: &InputMesh, opts: &FitOptions) -> Result<Fit> {
    opts.check()?;
    mesh.require_open()?;
    let diag = mesh.diagonal();
    if !(diag.is_finite() && diag > 0.0) {
        return Err(Error::invalid("the mesh has no extent"));
    }
    let tol = opts.target * diag;
    let frame = principal_frame(mesh);
    let slicer = Slicer::new(mesh, frame, opts.file);
    let (hmin, hmax) = mesh
        .triangles
        .iter()
        .flatten()
        .map(|&i| frame.height(&mesh.positions[i as usize]))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(x), h.max(x))
        });
    let n = opts.sections;
    let heights: Vec<f64> = (1..=n)
        .map(|j| hmin + (hmax - hmin) * j as f64 / (n + 1) as f64)
        .collect();
    let cut: Vec<Result<Piece>> = heights
        .par_iter()
        .map(|&h| slicer.open_piece(h, None))
        .collect();
    // Planes next to an end that graze it (several pieces, or none) are left out.
    let edge = (n / 16).max(2);
    let mut pieces = Vec::with_capacity(n);
    let mut dropped = 0;
    for (j, p) in cut.into_iter().enumerate() {
        match p {
            Ok(p) => pieces.push((heights[j], p)),
            Err(_) if j < edge || j + edge >= n => dropped += 1,
            Err(e) => return Err(e),
        }
    }
    if pieces.len() < 4 {
        return Err(Error::invalid("fewer than four usable profiles"));
    }
    let boundary = mesh.boundary_loops()?;
    if boundary.len() != 1 {
        return Err(Error::invalid(format!(
            "the sheet has {} boundary loops (holes): the sheet mode fits sheets with one \
             outline",
            boundary.len()
        )));
    }
    let outline = &boundary[0];
    let station = |points: &[Vec3], h: f64, edge: bool| -> Result<Station> {
        let s = if edge {
            super::profile::from_edge_arc(points, &frame, h, opts.samples, opts.file)?
        } else {
            super::profile::from_polyline(points, &frame, h, opts.samples, opts.file)?
        };
        Ok(Station {
            points: s.points,
            pole: false,
            part: String::new(),
        })
    };
    let first = &pieces[0].1;
    let last = &pieces[pieces.len() - 1].1;
    let mut stations = vec![station(
        &end_arc(mesh, outline, first, &frame, true)?,
        hmin,
        true,
    )?];
    for (h, p) in &pieces {
        stations.push(station(&p.points, *h, false)?);
    }
    stations.push(station(
        &end_arc(mesh, outline, last, &frame, false)?,
        hmax,
        true,
    )?);
    let sections = pieces.len();
    let chain = Chain::new(
        stations,
        &[],
        Joint::FourPoints,
        opts.max_modes,
        MODES_SHARE * tol,
    );
    let candidates: Vec<f64> = match opts.a {
        Some(a) => vec![a],
        None => SHEET_AM
            .iter()
            .map(|am| super::chain::significant(am / chain.modes() as f64, 3))
            .collect(),
    };
    let what = ChainFit {
        mode: FitMode::Sheet,
        frame,
        sections,
        dropped,
        stations: "profiles",
    };
    fit_one_chain(&chain, &candidates, tol, diag, opts, what)
}

/// The arc of the boundary loop `outline` beyond the open piece `piece` (below it if `below`,
/// else above), from the piece's first point to its last through the boundary's vertices.
pub(crate) fn end_arc(
    mesh: &InputMesh,
    outline: &[u32],
    piece: &Piece,
    frame: &AxisFrame,
    below: bool,
) -> Result<Vec<Vec3>> {
    let len = outline.len();
    let find = |e: (u32, u32)| -> Option<usize> {
        (0..len).find(|&i| {
            let (a, b) = (outline[i], outline[(i + 1) % len]);
            (a.min(b), a.max(b)) == e
        })
    };
    let ends = (piece.keys.first().copied(), piece.keys.last().copied());
    let (Some(i), Some(k)) = (ends.0.and_then(find), ends.1.and_then(find)) else {
        return Err(Error::invalid(
            "a profile of the sheet does not end on its outline",
        ));
    };
    if i == k {
        return Err(Error::invalid(
            "a profile of the sheet starts and ends on the same boundary edge",
        ));
    }
    let at = |j: usize| mesh.positions[outline[j % len] as usize];
    // Forward from edge i to edge k: outline[i + 1 ..= k]; backward: outline[i, i − 1, …, k + 1].
    let forward: Vec<Vec3> = (1..=(k + len - i) % len).map(|d| at(i + d)).collect();
    let backward: Vec<Vec3> = (0..(i + len - k) % len).map(|d| at(i + len - d)).collect();
    let score = |arc: &[Vec3]| -> f64 {
        let hs = arc.iter().map(|p| frame.height(p));
        if below {
            hs.fold(f64::NEG_INFINITY, f64::max)
        } else {
            -hs.fold(f64::INFINITY, f64::min)
        }
    };
    let arc = if score(&forward) <= score(&backward) {
        forward
    } else {
        backward
    };
    let mut line = vec![piece.points[0]];
    line.extend(arc);
    line.push(piece.points[piece.points.len() - 1]);
    Ok(line)
}
