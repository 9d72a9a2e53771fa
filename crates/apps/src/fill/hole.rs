//! One hole's patch: the polyharmonic disk patch ([`DiskPatch`]) whose boundary samples are the
//! loop's vertices, in order, at equally spaced angles, and whose ribbon is taken from the
//! mesh's vertex normals.
//!
//! # Boundary
//!
//! Vertex `k` of a loop of `S` vertices sits at `θ_k = 2πk/S`, and the boundary samples are the
//! loop's polyline, `OVERSAMPLE` equally spaced points per edge: the patch passes through every
//! vertex exactly (the vertices are FFT nodes) and follows the mesh's boundary edges between
//! them (a polyline's series converges uniformly, without the overshoot a series through the
//! vertices alone has when the loop zigzags along the mesh's edges). Angles by index rather
//! than by arc length make the parametrisation follow the mesh's spacing: a long boundary edge
//! spans as much angle as a short one, so the rings of the tessellation near the loop have the
//! loop's spacing. The zigzag lives in the high modes, and a mode `m` decays inwards like
//! `r^m`: within a few rings it is gone.
//!
//! # Ribbon (G1)
//!
//! `D_k` at the vertices, linear along each edge, lies in the mesh's tangent plane (`N_k` the
//! mesh's angle-weighted normal at the vertex) and points out of the hole. Its first choice is
//! `D_k = T_k × N_k`, with `T_k` the central difference `(P_{k+1} − P_{k−1}) S/(4π)` (the
//! polyline's mean tangent per unit of `θ`): square to the loop and as long as its tangent, the
//! conformal choice (a circle gives the flat disc, any planar loop a planar fill). For long or
//! bent holes the conformal map crowds and the fill can fold; the fill then tries the harmonic
//! and the radial ribbons ([`RibbonChoice`]). The patch's tangent at a vertex is
//! the mean of its two edges, `T_k`, so its normal is `N_k` made orthogonal to `T_k`: it leaves
//! the mesh's normal by the angle at which the loop leaves the mesh's tangent plane there, the
//! loop's own discretisation (reported as the G1 angle).

use super::curvature::form;
use super::{Continuity, Neighbours};
use crate::{Error, Result, Vec3, TAU};
use pdeshape_geometry::disk::{DiskData, DiskPatch, RingPoint};

/// The magnitude and direction of the ribbon `D` in the mesh's tangent plane (G1, G2): the
/// fill tries them in this order and keeps the first whose tessellation does not fold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RibbonChoice {
    /// `T_k × N_k`: square to the loop, as long as its tangent (the disc's conformal map).
    Conformal,
    /// The harmonic fill's derivative `∂X/∂r` just inside the loop, turned into the mesh's
    /// tangent plane (its length kept): for a planar loop the biharmonic fill is then close to
    /// the harmonic one, which maps the disc one-to-one onto any convex region.
    Harmonic,
    /// `P_k − C` (from the loop's centroid), turned into the tangent plane (its length kept):
    /// an affine image of the disc is reproduced (an ellipse by its angles).
    Radial,
}

impl RibbonChoice {
    /// Every choice, in the order the fill tries them.
    pub const ALL: [RibbonChoice; 3] = [
        RibbonChoice::Conformal,
        RibbonChoice::Harmonic,
        RibbonChoice::Radial,
    ];

    /// The choice's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            RibbonChoice::Conformal => "conformal",
            RibbonChoice::Harmonic => "harmonic",
            RibbonChoice::Radial => "radial",
        }
    }
}

/// Boundary samples per edge of the loop.
const OVERSAMPLE: usize = 8;

/// A hole's solved patch.
pub(crate) struct HolePatch {
    pub patch: DiskPatch,
    /// The loop's vertices (mesh indices), vertex `k` at angle `2πk/S`.
    pub vertices: Vec<u32>,
    /// The patch at the loop's vertices: `X`, `X_r`, `X_θ`.
    pub boundary: Vec<RingPoint>,
    /// The largest angle (radians) between the patch's tangent plane and the mesh's (its vertex
    /// normal) at the loop's vertices.
    pub g1_angle: f64,
}

/// Builds and solves the patch of the hole `loop_vertices` (in the fill's direction).
pub(crate) fn build<'a>(
    positions: &[Vec3],
    vertex_normals: &[Vec3],
    neighbours: &dyn Fn() -> &'a Neighbours,
    loop_vertices: &[u32],
    continuity: Continuity,
    ribbon: RibbonChoice,
) -> Result<HolePatch> {
    let s = loop_vertices.len();
    let p: Vec<Vec3> = loop_vertices
        .iter()
        .map(|&v| positions[v as usize])
        .collect();
    for k in 0..s {
        if p[k] == p[(k + 1) % s] {
            return Err(Error::invalid(format!(
                "the loop's vertices {} and {} coincide",
                loop_vertices[k] + 1,
                loop_vertices[(k + 1) % s] + 1
            )));
        }
    }
    let normals: Vec<Vec3> = loop_vertices
        .iter()
        .map(|&v| vertex_normals[v as usize])
        .collect();
    // The polyline, OVERSAMPLE points per edge (the loop's vertices among them).
    let fine = |f: &dyn Fn(usize) -> Vec3| -> Vec<Vec3> {
        (0..s * OVERSAMPLE)
            .map(|i| {
                let (k, t) = (i / OVERSAMPLE, (i % OVERSAMPLE) as f64 / OVERSAMPLE as f64);
                f(k) * (1.0 - t) + f((k + 1) % s) * t
            })
            .collect()
    };
    let pf = fine(&|k| p[k]);
    let data = DiskData {
        positions: &pf,
        derivatives: None,
        second: None,
    };
    if continuity == Continuity::G0 {
        let patch = DiskPatch::solve(1, &data)?;
        return Ok(finish(patch, loop_vertices, &normals));
    }
    // The central difference per unit of θ: the polyline's mean tangent at a vertex.
    let scale = s as f64 / (2.0 * TAU);
    let conformal = |k: usize| (p[(k + 1) % s] - p[(k + s - 1) % s]).cross(&normals[k]) * scale;
    // A vector turned into the mesh's tangent plane at vertex k, its length kept.
    let in_plane = |k: usize, v: Vec3| {
        let t = v - normals[k] * normals[k].dot(&v);
        let n = t.norm();
        if n > 0.0 {
            t * (v.norm() / n)
        } else {
            conformal(k)
        }
    };
    let centre = p.iter().sum::<Vec3>() / s as f64;
    // The harmonic fill's derivative, taken a little inside the loop (two steps of the
    // samples: the Poisson kernel there damps the zigzag's modes); only for that ribbon.
    let harm = if ribbon == RibbonChoice::Harmonic {
        DiskPatch::solve(1, &data)?.ring(1.0 - 2.0 * TAU / s as f64, s, 0.0)
    } else {
        Vec::new()
    };
    let d_at = |k: usize| match ribbon {
        RibbonChoice::Conformal => conformal(k),
        RibbonChoice::Harmonic => in_plane(k, harm[k].xr),
        RibbonChoice::Radial => in_plane(k, p[k] - centre),
    };
    let df = fine(&d_at);
    let g1 = DiskPatch::solve(
        2,
        &DiskData {
            derivatives: Some(&df),
            ..data
        },
    )?;
    if continuity == Continuity::G1 {
        return Ok(finish(g1, loop_vertices, &normals));
    }
    // G2: ∂²X/∂r² is normal, II(D, D) N with the mesh's fitted form (its tangential part, a
    // matter of parametrisation, is left to be zero: the flat disc's).
    let table = neighbours();
    let rings = |v: u32| table.of(v).to_vec();
    let mut e = Vec::with_capacity(s);
    for k in 0..s {
        let n = normals[k];
        let f = form(positions, &rings, loop_vertices[k], n).ok_or_else(|| {
            Error::invalid(format!(
                "vertex {} has too few neighbours to fit its curvature (G2)",
                loop_vertices[k] + 1
            ))
        })?;
        let d = d_at(k);
        e.push(f.normal() * f.at(d));
    }
    let ef = fine(&|k| e[k]);
    let g2 = DiskPatch::solve(
        3,
        &DiskData {
            derivatives: Some(&df),
            second: Some(&ef),
            ..data
        },
    )?;
    Ok(finish(g2, loop_vertices, &normals))
}

/// The hole's patch with its boundary values and G1 angle.
fn finish(patch: DiskPatch, loop_vertices: &[u32], normals: &[Vec3]) -> HolePatch {
    let s = loop_vertices.len();
    let boundary = patch.ring(1.0, s, 0.0);
    let g1_angle = boundary
        .iter()
        .zip(normals)
        .map(|(b, n)| {
            let m = b.xr.cross(&b.xt);
            m.cross(n).norm().atan2(m.dot(n).abs())
        })
        .fold(0.0, f64::max);
    HolePatch {
        patch,
        vertices: loop_vertices.to_vec(),
        boundary,
        g1_angle,
    }
}
