//! A hole's patch as triangles: concentric rings of the unit disk, zipped together.
//!
//! Ring 0 is the loop itself (the mesh's own vertices, not copies), less the tips of teeth
//! that lean back ([`clip_teeth`]). The first step `1/J` makes the rings' spacing in space about
//! the height of an equilateral triangle on the loop's mean edge, from the ribbon's mean
//! magnitude; ring 1 lies at `r_1 = 1 − 1/J`, or deeper where the loop zigzags inwards by more
//! than that ([`first_ring`]) or the first band still folds (half steps, at most three). The
//! steps then grow by the grading per ring up to the mesh's median edge (in space), the last
//! ones spread evenly down to the centre; a ring of step `δ` at radius `r` has
//! `round(S r (1/J)/δ)` equally spaced points (at least 3; every other ring turned by half a
//! step), so the triangles stay about equilateral, and the centre closes the last ring with a
//! fan. The triangles run counterclockwise in the disk, so they face like the
//! patch's normal `X_r × X_θ` and like the mesh around the hole.
//!
//! Between two rings each step takes the triangle that faces like the patch (if only one of the
//! two candidates does) or advances to the point next in angle; a triangle whose normal still opposes
//! the patch's normals at its corners (or that has no area) is counted as folded, and the fill
//! then refuses the hole.

use super::hole::HolePatch;
use crate::surface::Surface;
use crate::{Error, Result, Vec3, TAU};
use std::collections::HashMap;

/// The most points one hole's fill may add.
pub const MAX_POINTS: usize = 4_000_000;

/// The fill's new points and its triangles (mesh indices: the loop's own, then `base + i` for
/// new point `i`).
pub(crate) struct Tessellation {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    /// Triangles that do not face like the patch (or have no area).
    pub folded: usize,
}

/// Tessellates `hole` (module documentation).
pub(crate) fn tessellate(
    hole: &HolePatch,
    mesh_positions: &[Vec3],
    base: u32,
    grading: f64,
    max_edge: f64,
) -> Result<Tessellation> {
    let s = hole.vertices.len();
    let mean = |f: &dyn Fn(usize) -> f64| (0..s).map(f).sum::<f64>() / s as f64;
    let edge = mean(&|k| {
        (mesh_positions[hole.vertices[(k + 1) % s] as usize]
            - mesh_positions[hole.vertices[k] as usize])
            .norm()
    });
    // The radial speed: the ribbon's for G1, the tangent's over the angle for G0 (a circle's).
    let speed = mean(&|k| {
        let b = &hole.boundary[k];
        if hole.patch.order() >= 2 {
            b.xr.norm()
        } else {
            b.xt.norm()
        }
    });
    let rings = (speed / (edge * 3f64.sqrt() / 2.0)).round().max(1.0);
    let dr = 1.0 / rings;
    let largest = (dr * max_edge / edge).max(dr);
    let count = |r: f64, step: f64| ((s as f64 * r * dr / step).round() as usize).max(3);
    // The points the graded rings will have (the first ring may yet move deeper, by at most
    // one and a half steps: fewer points).
    let total = if rings > 1.0 {
        steps(1.0 - dr, dr, grading, largest)
            .iter()
            .map(|&(r, step)| count(r, step))
            .sum::<usize>()
            + count(1.0 - dr, dr)
            + 1
    } else {
        1
    };
    if total > MAX_POINTS {
        return Err(Error::invalid(format!(
            "the fill would need about {total} points (at most {MAX_POINTS}): the hole is too \
             large for the mesh's spacing"
        )));
    }
    // The loop: the mesh's vertices, the patch's normals.
    let mut outer = Ring {
        index: hole.vertices.clone(),
        angle: (0..s).map(|k| TAU * k as f64 / s as f64).collect(),
        x: hole
            .vertices
            .iter()
            .map(|&v| mesh_positions[v as usize])
            .collect(),
        normal: hole
            .boundary
            .iter()
            .map(|b| unit(b.xr.cross(&b.xt)))
            .collect(),
        against: 0,
    };
    let mut positions: Vec<Vec3> = Vec::with_capacity(total);
    let mut triangles = Vec::with_capacity(2 * total + s);
    let mut folded = 0;
    // A ring at radius r whose points are `step` apart along the radius: as many as keep the
    // triangles about equilateral.
    let ring = |r: f64, phase: f64, first: usize, step: f64| {
        let count = count(r, step);
        let pts = hole.patch.ring(r, count, phase);
        // Points where the patch's normal turns against the loop's normals carried inside.
        let reference = hole.reference.ring(r, count, phase);
        let against = pts
            .iter()
            .zip(&reference)
            .filter(|(p, q)| p.xr.cross(&p.xt).dot(&q.x) <= 0.0)
            .count();
        Ring {
            index: (0..count).map(|l| (first + l) as u32).collect(),
            angle: (0..count)
                .map(|l| TAU * (l as f64 + phase) / count as f64)
                .collect(),
            x: pts.iter().map(|p| p.x).collect(),
            normal: pts.iter().map(|p| unit(p.xr.cross(&p.xt))).collect(),
            against,
        }
    };
    if rings > 1.0 {
        // The patch's forward direction along the loop: N × ∂X/∂r.
        let forward: Vec<Vec3> = hole
            .boundary
            .iter()
            .zip(&outer.normal)
            .map(|(b, n)| n.cross(&b.xr))
            .collect();
        outer = clip_teeth(outer, &forward, &mut triangles);
        // The first band, with its ring taken deeper by half steps while the band folds.
        let mut r1 = first_ring(hole, mesh_positions, dr);
        for attempt in 0.. {
            let mut inner = ring(r1, 0.5, base as usize, dr);
            let mut band = Vec::with_capacity(outer.index.len() + inner.index.len());
            let mut f = zip(&outer, &inner, &mut band);
            if f > 0 {
                f = nudge(hole, &outer, &mut inner, &band, r1, dr);
            }
            if f == 0 || attempt == 3 || r1 - 0.5 * dr < 0.5 {
                positions.extend_from_slice(&inner.x);
                triangles.extend(band);
                folded += f + inner.against;
                outer = inner;
                break;
            }
            r1 -= 0.5 * dr;
        }
        for (j, (r, step)) in steps(r1, dr, grading, largest).into_iter().enumerate() {
            let phase = if j % 2 == 0 { 0.0 } else { 0.5 };
            let inner = ring(r, phase, base as usize + positions.len(), step);
            positions.extend_from_slice(&inner.x);
            folded += inner.against + zip(&outer, &inner, &mut triangles);
            outer = inner;
        }
    }
    let centre = hole.patch.partials(0.0, 0.0);
    let (cx, cn) = (centre.x, centre.normal());
    if cn.dot(&hole.reference.partials(0.0, 0.0).x) <= 0.0 {
        folded += 1;
    }

    let c = base + positions.len() as u32;
    positions.push(cx);
    let m = outer.index.len();
    for l in 0..m {
        let (a, b) = (l, (l + 1) % m);
        triangles.push([c, outer.index[a], outer.index[b]]);
        if !faces(
            [cx, outer.x[a], outer.x[b]],
            cn + outer.normal[a] + outer.normal[b],
        ) {
            folded += 1;
        }
    }
    Ok(Tessellation {
        positions,
        triangles,
        folded,
    })
}

/// The rings inside the first, at `r1`: `(radius, step)` with the step from the ring outside
/// it, growing by `grading` per ring from `dr` up to `largest`, the last ones spread evenly so
/// the innermost ring is a step from the centre.
fn steps(r1: f64, dr: f64, grading: f64, largest: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let (mut r, mut step) = (r1, dr);
    loop {
        step = (step * (1.0 + grading)).min(largest);
        let left = (r / step).round().max(1.0);
        step = r / left;
        if left <= 1.0 {
            return out;
        }
        r -= step;
        out.push((r, step));
    }
}

/// The radius of the first ring inside the loop: `1 − dr`, or deeper (by half steps, at most
/// three) until every loop vertex lies outside it, along the patch's outward derivative, by at
/// least half its mean edge. A loop that zigzags along the mesh's edges reaches inwards by up to
/// an edge; the ring must clear it for the band between them to be triangulated unfolded.
fn first_ring(hole: &HolePatch, mesh_positions: &[Vec3], dr: f64) -> f64 {
    let s = hole.vertices.len();
    let p = |k: usize| mesh_positions[hole.vertices[k % s] as usize];
    let mut r = 1.0 - dr;
    for _ in 0..6 {
        let ring = hole.patch.ring(r, s, 0.0);
        let clear = (0..s).all(|k| {
            let e = 0.5 * ((p(k + 1) - p(k)).norm() + (p(k) - p(k + s - 1)).norm());
            (p(k) - ring[k].x).dot(&unit(hole.boundary[k].xr)) >= 0.5 * e
        });
        if clear || r - 0.5 * dr < 0.5 * dr.max(0.5) {
            break;
        }
        r -= 0.5 * dr;
    }
    r
}

/// Where the loop runs backwards (an edge that makes more than 75° with the patch's forward
/// direction about it: a tooth of the mesh's edges leaning back), clips the ear at the
/// tooth's tip, the triangle of it and its two neighbours on the loop, if that triangle faces
/// like the patch; repeats until no such edge is left or none can be clipped. Returns the loop
/// without the clipped tips; the ears go to `out`. No zipper can join a backward edge to the
/// ring inside without turning a triangle over; an ear closes it along the loop instead.
fn clip_teeth(mut ring: Ring, forward: &[Vec3], out: &mut Vec<[u32; 3]>) -> Ring {
    let mut fwd = forward.to_vec();
    let cos_limit = (75f64).to_radians().cos();
    loop {
        let n = ring.index.len();
        if n <= 3 {
            return ring;
        }
        // The forward direction averaged over nine vertices about the edge: a zigzag's own
        // vertices disagree about it.
        let backward = |i: usize| {
            let e = ring.x[(i + 1) % n] - ring.x[i];
            let f: Vec3 = (0..10).map(|d| fwd[(i + n + d - 4) % n]).sum();
            e.dot(&f) < cos_limit * e.norm() * f.norm()
        };
        let ear = |k: usize| {
            let (a, b, c) = ((k + n - 1) % n, k, (k + 1) % n);
            faces(
                [ring.x[a], ring.x[b], ring.x[c]],
                ring.normal[a] + ring.normal[b] + ring.normal[c],
            )
        };
        let mut clipped = Vec::new();
        let mut i = 0;
        while i < n {
            if backward(i) {
                // The tip is the edge's end farther out along the patch's outward direction.
                let out_dir = |k: usize| fwd[k].cross(&ring.normal[k]);
                let (a, b) = (i, (i + 1) % n);
                let (tip, other) = if (ring.x[a] - ring.x[b]).dot(&(out_dir(a) + out_dir(b))) > 0.0
                {
                    (a, b)
                } else {
                    (b, a)
                };
                // The tip's ear, the other end's, or a neighbour's (which may let the tip's
                // be clipped in the next round).
                let beyond = |k: usize, from: usize| {
                    if (k + 1) % n == from {
                        (k + n - 1) % n
                    } else {
                        (k + 1) % n
                    }
                };
                let candidates = [tip, other, beyond(tip, other), beyond(other, tip)];
                if let Some(k) = candidates.into_iter().find(|&k| ear(k)) {
                    if clipped.last() != Some(&k) && !clipped.contains(&((k + 1) % n)) {
                        clipped.push(k);
                        i += 1;
                    }
                }
            }
            i += 1;
        }
        clipped.sort_unstable();
        clipped.dedup();
        // Never two neighbours at once (each ear needs its neighbours on the loop).
        let mut keep = vec![true; n];
        let mut any = false;
        for &k in &clipped {
            let (a, c) = ((k + n - 1) % n, (k + 1) % n);
            if keep[a] && keep[c] && keep[k] {
                out.push([ring.index[a], ring.index[k], ring.index[c]]);
                keep[k] = false;
                any = true;
            }
        }
        if !any {
            return ring;
        }
        let pick = |v: &mut Vec<Vec3>| {
            let mut k = 0;
            v.retain(|_| {
                k += 1;
                keep[k - 1]
            });
        };
        pick(&mut ring.x);
        pick(&mut ring.normal);
        pick(&mut fwd);
        let mut k = 0;
        ring.index.retain(|_| {
            k += 1;
            keep[k - 1]
        });
        let mut k = 0;
        ring.angle.retain(|_| {
            k += 1;
            keep[k - 1]
        });
    }
}

/// Moves the inner ring's points of the band's turned-over triangles deeper along their own
/// radius (to `r − dr/4`, `r − dr/2`, `r − 3dr/4`: still points of the patch) until all the
/// band's triangles at the point face like the patch; returns how many triangles of the band
/// are still turned over.
fn nudge(
    hole: &HolePatch,
    outer: &Ring,
    inner: &mut Ring,
    band: &[[u32; 3]],
    r: f64,
    dr: f64,
) -> usize {
    let first = inner.index[0];
    let mut at: HashMap<u32, (Vec3, Vec3)> = HashMap::with_capacity(outer.index.len());
    for (k, &v) in outer.index.iter().enumerate() {
        at.insert(v, (outer.x[k], outer.normal[k]));
    }
    let get = |v: u32, inner: &Ring| -> (Vec3, Vec3) {
        if v >= first && ((v - first) as usize) < inner.index.len() {
            let l = (v - first) as usize;
            (inner.x[l], inner.normal[l])
        } else {
            at[&v]
        }
    };
    let ok = |t: &[u32; 3], inner: &Ring| {
        let [(p, n), (q, m), (s, o)] = t.map(|v| get(v, inner));
        faces([p, q, s], n + m + o)
    };
    let bad: Vec<usize> = (0..band.len()).filter(|&k| !ok(&band[k], inner)).collect();
    for k in bad {
        for &v in &band[k] {
            if v < first {
                continue;
            }
            let l = (v - first) as usize;
            let around: Vec<&[u32; 3]> = band.iter().filter(|t| t.contains(&v)).collect();
            if around.iter().all(|t| ok(t, inner)) {
                continue;
            }
            let keep = (inner.x[l], inner.normal[l]);
            let mut fixed = false;
            for step in 1..=3 {
                let q = hole
                    .patch
                    .partials(r - 0.25 * step as f64 * dr, inner.angle[l]);
                inner.x[l] = q.x;
                inner.normal[l] = unit(q.xu.cross(&q.xv));
                if around.iter().all(|t| ok(t, inner)) {
                    fixed = true;
                    break;
                }
            }
            if !fixed {
                (inner.x[l], inner.normal[l]) = keep;
            }
        }
    }
    band.iter().filter(|t| !ok(t, inner)).count()
}

/// `v / |v|`, or `v` if it is zero.
fn unit(v: Vec3) -> Vec3 {
    let n = v.norm();
    if n > 0.0 {
        v / n
    } else {
        v
    }
}

/// True if the triangle `p` (in order) faces along `normal` (and has an area).
fn faces(p: [Vec3; 3], normal: Vec3) -> bool {
    (p[1] - p[0]).cross(&(p[2] - p[0])).dot(&normal) > 0.0
}

/// One ring: its points (mesh indices), their angles (increasing, in `[0, 2π)`), positions and
/// the patch's unit normals there.
struct Ring {
    index: Vec<u32>,
    angle: Vec<f64>,
    x: Vec<Vec3>,
    normal: Vec<Vec3>,
    /// Points whose patch normal turns against the loop's normals carried inside.
    against: usize,
}

/// The triangles between ring `a` (outer) and ring `b` (inner), counterclockwise in the disk;
/// returns how many of them do not face like the patch.
///
/// From `b`'s point nearest `a`'s first in angle, each step adds the triangle that advances
/// along one ring to the point next in angle, or along the other if only that one faces like
/// the patch and the rings' fronts stay within a step and a half of each other. Triangles still
/// turned over (a loop zigzagging along the mesh's edges, with an edge almost in line with a
/// point of the next ring) are then mended by flipping their diagonals ([`repair`]).
fn zip(a: &Ring, b: &Ring, out: &mut Vec<[u32; 3]>) -> usize {
    let first = out.len();
    let folded = zip_by_angle(a, b, out);
    if folded == 0 {
        return 0;
    }
    let mut at = HashMap::with_capacity(a.index.len() + b.index.len());
    for ring in [a, b] {
        for (k, &v) in ring.index.iter().enumerate() {
            at.insert(v, (ring.x[k], ring.normal[k]));
        }
    }
    repair(&mut out[first..], &at)
}

/// [`zip`] before the repair.
fn zip_by_angle(a: &Ring, b: &Ring, out: &mut Vec<[u32; 3]>) -> usize {
    let (na, nb) = (a.index.len(), b.index.len());
    let pi = std::f64::consts::PI;
    let gap = |x: f64| (x - a.angle[0] + pi).rem_euclid(TAU) - pi;
    let j0 = (0..nb)
        .min_by(|&i, &j| gap(b.angle[i]).abs().total_cmp(&gap(b.angle[j]).abs()))
        .unwrap_or(0);
    let bi = |j: usize| (j0 + j) % nb;
    // Angles unwrapped: a's from a[0], b's from b[j0] (the nearest to it).
    let a_at = |i: usize| {
        a.angle[0]
            + (a.angle[i % na] - a.angle[0]).rem_euclid(TAU)
            + if i >= na { TAU } else { 0.0 }
    };
    let b0 = a.angle[0] + gap(b.angle[j0]);
    let b_at = |j: usize| {
        b0 + (b.angle[bi(j)] - b.angle[j0]).rem_euclid(TAU) + if j >= nb { TAU } else { 0.0 }
    };
    let mut folded = 0;
    let (mut i, mut j) = (0, 0);
    while i < na || j < nb {
        let (ai, ai1, bj, bj1) = (i % na, (i + 1) % na, bi(j), bi(j + 1));
        let along_a = [b.x[bj], a.x[ai], a.x[ai1]];
        let along_b = [b.x[bj], a.x[ai], b.x[bj1]];
        let ok_a = faces(along_a, b.normal[bj] + a.normal[ai] + a.normal[ai1]);
        let ok_b = faces(along_b, b.normal[bj] + a.normal[ai] + b.normal[bj1]);
        let by_angle = a_at(i + 1) < b_at(j + 1);
        // The other choice, if the angle's turns its triangle over and the other's does not,
        // as long as the rings' fronts stay within a step of each other.
        let lag = if by_angle {
            b_at(j + 1) - a_at(i)
        } else {
            a_at(i + 1) - b_at(j)
        };
        let step = TAU / na.min(nb) as f64;
        let (ok_by, ok_other) = if by_angle { (ok_a, ok_b) } else { (ok_b, ok_a) };
        let advance_a = if j == nb {
            true
        } else if i == na {
            false
        } else if !ok_by && ok_other && lag <= 1.5 * step {
            !by_angle
        } else {
            by_angle
        };
        if advance_a {
            out.push([b.index[bj], a.index[ai], a.index[ai1]]);
            folded += usize::from(!ok_a);
            i += 1;
        } else {
            out.push([b.index[bj], a.index[ai], b.index[bj1]]);
            folded += usize::from(!ok_b);
            j += 1;
        }
    }
    folded
}

/// Flips the diagonals (edges shared by two triangles of `band`) of triangles that do not face
/// like the patch, where both new triangles do; returns how many are still turned over.
/// `at` gives each vertex's position and the patch's normal there.
fn repair(band: &mut [[u32; 3]], at: &HashMap<u32, (Vec3, Vec3)>) -> usize {
    let ok = |t: [u32; 3]| {
        let [(p, n), (q, m), (r, o)] = t.map(|v| at[&v]);
        faces([p, q, r], n + m + o)
    };
    for _ in 0..4 {
        let mut owner: HashMap<(u32, u32), usize> = HashMap::with_capacity(band.len() * 3);
        for (k, t) in band.iter().enumerate() {
            for e in 0..3 {
                owner.insert((t[e], t[(e + 1) % 3]), k);
            }
        }
        let mut changed = false;
        for k in 0..band.len() {
            if ok(band[k]) {
                continue;
            }
            for e in 0..3 {
                let t = band[k];
                let (u, v, w) = (t[e], t[(e + 1) % 3], t[(e + 2) % 3]);
                let Some(&l) = owner.get(&(v, u)) else {
                    continue;
                };
                let x = band[l].into_iter().find(|&y| y != u && y != v);
                let Some(x) = x else { continue };
                if band[l] != [v, u, x] && band[l] != [u, x, v] && band[l] != [x, v, u] {
                    continue;
                }
                let (one, two) = ([u, x, w], [x, v, w]);
                if ok(one) && ok(two) {
                    band[k] = one;
                    band[l] = two;
                    for (tri, idx) in [(one, k), (two, l)] {
                        for f in 0..3 {
                            owner.insert((tri[f], tri[(f + 1) % 3]), idx);
                        }
                    }
                    owner.remove(&(u, v));
                    owner.remove(&(v, u));
                    changed = true;
                    break;
                }
            }
        }
        if !changed {
            break;
        }
    }
    band.iter().filter(|&&t| !ok(t)).count()
}
