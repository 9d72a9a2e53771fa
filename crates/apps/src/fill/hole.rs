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

use super::curvature::Form;
use super::Continuity;
use crate::{Error, Result, Vec3, TAU};
use pdeshape_geometry::disk::{polyline, DiskData, DiskPatch, RingPoint};

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
    /// The order in which the pieces of a split hole try them: the chord's ends are corners,
    /// where the conformal ribbon's magnitude (the loop's speed) is too large for the map
    /// inside and the fill bulges; the harmonic fill's derivative vanishes towards them.
    pub const PIECES: [RibbonChoice; 3] = [
        RibbonChoice::Harmonic,
        RibbonChoice::Conformal,
        RibbonChoice::Radial,
    ];

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
pub(crate) const OVERSAMPLE: usize = 8;

/// A patch's boundary data at the loop's vertices.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct VertexData {
    /// The positions.
    pub points: Vec<Vec3>,
    /// The ribbon `∂X/∂r` (G1, G2).
    pub derivatives: Option<Vec<Vec3>>,
    /// `∂²X/∂r²` (G2).
    pub second: Option<Vec<Vec3>>,
}

/// A hole's solved patch.
pub(crate) struct HolePatch {
    pub patch: DiskPatch,
    /// The data it was solved from, at the loop's vertices (the samples between them are the
    /// polyline's, [`OVERSAMPLE`] per edge).
    pub data: VertexData,
    /// The harmonic patch of the loop's normals (its "position" is a direction): the way the
    /// fill should face inside; a patch normal against it is a fold of the disk's map onto
    /// the surface (the patch's normal turns with the fold, so the triangles' check against it
    /// cannot see one).
    pub reference: DiskPatch,
    /// The loop's vertices (mesh indices), vertex `k` at angle `2πk/S`.
    pub vertices: Vec<u32>,
    /// The patch at the loop's vertices: `X`, `X_r`, `X_θ`.
    pub boundary: Vec<RingPoint>,
    /// The largest angle (radians) between the patch's tangent plane and the mesh's (its vertex
    /// normal) at the loop's vertices.
    pub g1_angle: f64,
}

/// Builds and solves the patch of the hole `loop_vertices` (in the fill's direction):
/// `positions` and `vertex_normals` hold the mesh's vertices and any chord points of a split
/// hole; `form_at` gives a vertex's second fundamental form (G2 only).
pub(crate) fn build(
    positions: &[Vec3],
    vertex_normals: &[Vec3],
    form_at: &dyn Fn(u32) -> Option<Form>,
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
        polyline(&(0..s).map(f).collect::<Vec<_>>(), OVERSAMPLE)
    };
    let pf = fine(&|k| p[k]);
    let data = DiskData {
        positions: &pf,
        derivatives: None,
        second: None,
    };
    // The loop's normals carried inside (harmonic): which way the fill should face.
    let nf = fine(&|k| normals[k]);
    let reference = DiskPatch::solve(
        1,
        &DiskData {
            positions: &nf,
            derivatives: None,
            second: None,
        },
    )?;
    if continuity == Continuity::G0 {
        let patch = DiskPatch::solve(1, &data)?;
        let data = VertexData {
            points: p,
            derivatives: None,
            second: None,
        };
        return Ok(finish(patch, data, loop_vertices, &normals, reference));
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
        RibbonChoice::Harmonic => {
            // Kept within 60° of the square to the loop (a corner's harmonic derivative can
            // run along the loop, where it says nothing about the tangent plane).
            let h = in_plane(k, harm[k].xr);
            let c = conformal(k);
            let u = c / c.norm().max(f64::MIN_POSITIVE);
            let o = h.dot(&u);
            if o >= 0.5 * h.norm() {
                h
            } else {
                u * o.max(0.1 * c.norm())
            }
        }
        RibbonChoice::Radial => in_plane(k, p[k] - centre),
    };
    let d: Vec<Vec3> = (0..s).map(d_at).collect();
    let df = fine(&|k| d[k]);
    let g1 = DiskPatch::solve(
        2,
        &DiskData {
            derivatives: Some(&df),
            ..data
        },
    )?;
    if continuity == Continuity::G1 {
        let data = VertexData {
            points: p,
            derivatives: Some(d),
            second: None,
        };
        return Ok(finish(g1, data, loop_vertices, &normals, reference));
    }
    // G2: ∂²X/∂r² is normal, II(D, D) N with the mesh's fitted form (its tangential part, a
    // matter of parametrisation, is left to be zero: the flat disc's).
    let mut e = Vec::with_capacity(s);
    for (k, &v) in loop_vertices.iter().enumerate() {
        let f = form_at(v).ok_or_else(|| {
            Error::invalid(format!(
                "vertex {} has too few neighbours to fit its curvature (G2)",
                v + 1
            ))
        })?;
        e.push(f.normal() * f.at(d[k]));
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
    let data = VertexData {
        points: p,
        derivatives: Some(d),
        second: Some(e),
    };
    Ok(finish(g2, data, loop_vertices, &normals, reference))
}

/// The hole's patch with its boundary values and G1 angle.
fn finish(
    patch: DiskPatch,
    data: VertexData,
    loop_vertices: &[u32],
    normals: &[Vec3],
    reference: DiskPatch,
) -> HolePatch {
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
        data,
        reference,
        vertices: loop_vertices.to_vec(),
        boundary,
        g1_angle,
    }
}
