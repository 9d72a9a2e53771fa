//! Motion re-targeting (§8.1.2): carrying a time-dependent design's motion onto a separate
//! triangle mesh (a scan of the same object, made independently).
//!
//! Once, at the reference design (the animation at its first time), every mesh vertex `p` is
//! anchored to its closest point `X₀ = X(u, v)` on one of the design's surfaces, and the offset
//! distance `d = |p − X₀|` is kept. In every frame the vertex moves with the surface point it is
//! anchored to: `p' = p + (Xₜ(u, v) − X₀)`. The offset vector `p − X₀` is carried unchanged (a
//! translation, not turned with the normal), so `|p' − Xₜ(u, v)| = d` and the moved mesh lies
//! within `d` of the moved surface at every vertex; where the surface does not move
//! (`Xₜ(u, v) = X₀` bit for bit) the vertex stays where it was, bit for bit.

use super::frames::Keyframes;
use crate::design::SolvedDesign;
use crate::spec::time::TimeSpec;
use crate::surface::{ClosestOptions, ClosestPointIndex};
use crate::{Error, Result, Vec3};
use rayon::prelude::*;

/// Where a mesh vertex is anchored on the reference design.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anchor {
    /// The index of the surface in `SolvedDesign::surfaces`.
    pub surface: usize,
    /// The foot point's parameter `u`.
    pub u: f64,
    /// The foot point's parameter `v`.
    pub v: f64,
    /// `X₀ = X(u, v)` on the reference design.
    pub foot: Vec3,
    /// `|p − X₀|`.
    pub distance: f64,
}

/// Closest-point searches (mesh vertices × design surfaces) a core does a second: about 7.5 µs
/// each (20 000 vertices on the four surfaces of `examples/anim/ventricle.toml` anchored in
/// 0.6 s). A re-targeting that would take more than [`crate::work::MAX_SECONDS`] is refused
/// before the first search (a million vertices there ran past 30 s of CPU).
pub(crate) const SEARCHES_PER_SECOND: f64 = 130_000.0;

/// The closest-point correspondence of a mesh's vertices with a design's surfaces.
#[derive(Clone, Debug)]
pub struct Correspondence {
    /// The surfaces' names (a frame must have the same, in the same order).
    pub surfaces: Vec<String>,
    /// The mesh's vertices as given.
    pub points: Vec<Vec3>,
    /// One anchor per vertex.
    pub anchors: Vec<Anchor>,
}

impl Correspondence {
    /// Anchors every point to its closest point on the surfaces of `reference` (the closest over
    /// all surfaces). Fails if a point is not finite or no foot point is found.
    pub fn new(reference: &SolvedDesign, points: &[Vec3]) -> Result<Correspondence> {
        if reference.surfaces.is_empty() {
            return Err(Error::invalid(
                "the design has no surface to re-target from",
            ));
        }
        // Time is priced like memory: the searches are counted before the first one starts.
        let n = reference.surfaces.len();
        crate::work::check(
            &[crate::work::Work {
                units: points.len() as f64 * n as f64,
                per_second: SEARCHES_PER_SECOND,
            }],
            &format!(
                "re-targeting a mesh of {} vertices to a design of {n} surface{} ({} closest-point searches)",
                points.len(),
                if n == 1 { "" } else { "s" },
                points.len().saturating_mul(n)
            ),
            "decimate the mesh",
            "",
        )?;
        let opts = ClosestOptions::default();
        let indices: Vec<_> = reference
            .surfaces
            .iter()
            .map(|s| ClosestPointIndex::new(s.surface(), &opts))
            .collect();
        let mut anchors = Vec::with_capacity(points.len());
        for (k, &p) in points.iter().enumerate() {
            let mut best: Option<Anchor> = None;
            for (s, index) in indices.iter().enumerate() {
                if let Some(c) = index.closest(p) {
                    if best.is_none_or(|b| c.distance < b.distance) {
                        best = Some(Anchor {
                            surface: s,
                            u: c.u,
                            v: c.v,
                            foot: c.point,
                            distance: c.distance,
                        });
                    }
                }
            }
            let a = best.ok_or_else(|| {
                Error::invalid(format!(
                    "vertex {} ({}, {}, {}): no closest point on the design",
                    k + 1,
                    p.x,
                    p.y,
                    p.z
                ))
            })?;
            anchors.push(a);
        }
        Ok(Correspondence {
            surfaces: reference.surfaces.iter().map(|s| s.name.clone()).collect(),
            points: points.to_vec(),
            anchors,
        })
    }

    /// The largest offset distance.
    pub fn max_distance(&self) -> f64 {
        self.anchors.iter().map(|a| a.distance).fold(0.0, f64::max)
    }

    /// The vertices moved with the design `frame`: `p + (Xₜ(u, v) − X₀)`.
    pub fn displaced(&self, frame: &SolvedDesign) -> Result<Vec<Vec3>> {
        let same = frame.surfaces.len() == self.surfaces.len()
            && frame
                .surfaces
                .iter()
                .zip(&self.surfaces)
                .all(|(s, n)| &s.name == n);
        if !same {
            return Err(Error::invalid(
                "the frame's surfaces differ from the reference design's (names or number)",
            ));
        }
        // In parallel; each vertex alone, so the result does not depend on the threads.
        let out = self
            .points
            .par_iter()
            .zip(&self.anchors)
            .map(|(&p, a)| {
                let x = frame.surfaces[a.surface].surface().point(a.u, a.v);
                p + (x - a.foot)
            })
            .collect::<Vec<_>>();
        if let Some(k) = out.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(Error::invalid(format!(
                "vertex {} moved to a non-finite position",
                k + 1
            )));
        }
        Ok(out)
    }
}

/// Unit vertex normals of a triangle mesh (sums of the triangles' area vectors; a vertex with
/// none gets `fallback`).
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]], fallback: Vec3) -> Vec<Vec3> {
    let mut n = vec![Vec3::zeros(); positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let area = (b - a).cross(&(c - a));
        for &i in t {
            n[i as usize] += area;
        }
    }
    n.into_iter()
        .map(|m| {
            let l = m.norm();
            if l > 0.0 && l.is_finite() {
                m / l
            } else {
                fallback
            }
        })
        .collect()
}

/// A re-targeted mesh's frames, collected as [`Keyframes`] for the glTF writer.
pub struct Retarget {
    /// Where each vertex of the mesh is anchored on the reference design.
    pub correspondence: Correspondence,
    /// The frames so far (one per [`Retarget::push`]), with the mesh's triangles.
    pub keys: Keyframes,
}

impl Retarget {
    /// Anchors `points` (with `triangles`) on the reference design.
    pub fn new(
        reference: &SolvedDesign,
        points: &[Vec3],
        triangles: Vec<[u32; 3]>,
        time: &TimeSpec,
    ) -> Result<Retarget> {
        if triangles.is_empty() {
            return Err(Error::invalid("the mesh has no triangle"));
        }
        if let Some(t) = triangles
            .iter()
            .find(|t| t.iter().any(|&i| i as usize >= points.len()))
        {
            return Err(Error::invalid(format!(
                "a triangle {t:?} refers to a vertex beyond the {} given",
                points.len()
            )));
        }
        let correspondence = Correspondence::new(reference, points)?;
        let mut keys = Keyframes::new(time);
        keys.title = reference.title.clone();
        keys.units = reference.units;
        keys.triangles = triangles;
        let r = crate::mesh::report(&crate::mesh::TriMesh {
            positions: points.iter().map(|p| p.map(|c| c as f32).into()).collect(),
            normals: Vec::new(),
            uv: Vec::new(),
            triangles: keys.triangles.clone(),
            parts: Vec::new(),
        });
        keys.closed = r.boundary_edges == 0 && r.nonmanifold_edges == 0;
        Ok(Retarget {
            correspondence,
            keys,
        })
    }

    /// Moves the mesh with the design at time `t` and appends it as a frame; returns the
    /// positions.
    pub fn push(&mut self, t: f64, frame: &SolvedDesign) -> Result<Vec<Vec3>> {
        let p = self.correspondence.displaced(frame)?;
        let n = vertex_normals(&p, &self.keys.triangles, Vec3::z());
        self.keys.times.push(t);
        self.keys
            .positions
            .push(p.iter().map(|q| q.map(|c| c as f32).into()).collect());
        self.keys
            .normals
            .push(n.iter().map(|q| q.map(|c| c as f32).into()).collect());
        Ok(p)
    }
}

#[cfg(test)]
mod tests;
