//! Meshes with holes for the hole-filling tests and benches: graded, jittered meshes of the unit
//! sphere with geodesic discs removed (the kind `bench/peers/hole_cases.py` writes for the
//! peers), and a jittered planar grid with a round hole.

use pdeshape::fit::InputMesh;
use pdeshape::Vec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A closed mesh and the triangles removed from it.
#[derive(Clone, Debug)]
pub struct Holed {
    /// The mesh with its holes (every vertex kept, so indices match `whole`).
    pub mesh: InputMesh,
    /// The closed mesh before the holes were cut (the same vertices).
    pub whole: Vec<[u32; 3]>,
    /// The removed triangles.
    pub removed: Vec<[u32; 3]>,
}

/// The geodesic disc's radius of every hole (radians), as in `hole_cases.py`.
pub const RHO: f64 = 0.5;

/// The hole's centre of the peers' cases, `(0.3, −0.2, 0.93)/|·|`.
pub fn peer_centre() -> Vec3 {
    Vec3::new(0.3, -0.2, 0.93).normalize()
}

/// A graded mesh of the unit sphere about `centre`: rings of constant geodesic distance `d`
/// from it, `(√3/2) h` apart, each of `round(2π sin d / h)` equally spaced vertices at a random
/// phase, with target edge `h(d) = min(0.04, h_b + 0.25 |d − ρ|)` (finest at the rim of the
/// hole to come); consecutive rings zipped into triangles (counterclockwise seen from outside);
/// then every vertex moved in its tangent plane by a random step of at most `jitter · h` (the
/// peers' cases: 0.25) and projected back onto the sphere.
pub fn graded_sphere(centre: Vec3, hb: f64, jitter: f64, seed: u64) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let size = |d: f64| (hb + 0.25 * (d - RHO).abs()).min(0.04);
    let step = 3f64.sqrt() / 2.0;
    let mut inner = vec![RHO - step * hb / 2.0];
    loop {
        let d = *inner.last().unwrap();
        let h = size(d - step * size(d) / 2.0);
        if d - step * h < 0.6 * h {
            break;
        }
        inner.push(d - step * h);
    }
    let mut outer = vec![RHO + step * hb / 2.0];
    loop {
        let d = *outer.last().unwrap();
        let h = size(d + step * size(d) / 2.0);
        if std::f64::consts::PI - (d + step * h) < 0.6 * h {
            break;
        }
        outer.push(d + step * h);
    }
    inner.reverse();
    let radii: Vec<f64> = inner.into_iter().chain(outer).collect();
    let e1 = centre.cross(&Vec3::new(0.0, 0.0, 1.0));
    let e1 = if e1.norm() < 1e-6 {
        centre.cross(&Vec3::new(1.0, 0.0, 0.0)).normalize()
    } else {
        e1.normalize()
    };
    let e2 = centre.cross(&e1);
    let at = |d: f64, phi: f64| centre * d.cos() + (e1 * phi.cos() + e2 * phi.sin()) * d.sin();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut pos = vec![centre];
    let mut hs = vec![size(0.0)];
    let mut rings: Vec<(Vec<u32>, Vec<f64>)> = Vec::new();
    let tau = std::f64::consts::TAU;
    for &d in &radii {
        let h = size(d);
        let n = ((tau * d.sin() / h).round() as usize).max(6);
        let phase = rng.gen_range(0.0..tau);
        let idx: Vec<u32> = (0..n).map(|k| (pos.len() + k) as u32).collect();
        let ang: Vec<f64> = (0..n).map(|k| phase + tau * k as f64 / n as f64).collect();
        for &a in &ang {
            pos.push(at(d, a));
            hs.push(h);
        }
        rings.push((idx, ang));
    }
    let south = pos.len() as u32;
    pos.push(-centre);
    hs.push(size(std::f64::consts::PI));
    let mut tris = Vec::new();
    let first = &rings[0].0;
    for k in 0..first.len() {
        tris.push([0, first[k], first[(k + 1) % first.len()]]);
    }
    for w in rings.windows(2) {
        zipper(&w[0], &w[1], &mut tris);
    }
    let last = &rings[rings.len() - 1].0;
    for k in 0..last.len() {
        tris.push([last[k], south, last[(k + 1) % last.len()]]);
    }
    for (p, h) in pos.iter_mut().zip(&hs) {
        let helper = if p.z.abs() < 0.9 {
            Vec3::new(0.0, 0.0, 1.0)
        } else {
            Vec3::new(1.0, 0.0, 0.0)
        };
        let t1 = p.cross(&helper).normalize();
        let t2 = p.cross(&t1);
        let r = jitter * h * rng.gen_range(0.0f64..1.0).sqrt();
        let a = rng.gen_range(0.0..tau);
        *p = (*p + t1 * (r * a.cos()) + t2 * (r * a.sin())).normalize();
    }
    (pos, tris)
}

/// Triangles between ring `a` (nearer the centre) and ring `b`, both counterclockwise about
/// the centre with increasing angles.
fn zipper(a: &(Vec<u32>, Vec<f64>), b: &(Vec<u32>, Vec<f64>), out: &mut Vec<[u32; 3]>) {
    let tau = std::f64::consts::TAU;
    let (na, nb) = (a.0.len(), b.0.len());
    // B's angles unwrapped about A's first, starting from B's vertex nearest it.
    let wrap = |x: f64| (x + std::f64::consts::PI).rem_euclid(tau) - std::f64::consts::PI;
    let j0 = (0..nb)
        .min_by(|&i, &j| {
            wrap(b.1[i] - a.1[0])
                .abs()
                .total_cmp(&wrap(b.1[j] - a.1[0]).abs())
        })
        .unwrap();
    let bun: Vec<f64> = (0..=nb)
        .map(|j| {
            let base = a.1[0] + wrap(b.1[j0] - a.1[0]);
            base + (b.1[(j0 + j) % nb] - b.1[j0]).rem_euclid(tau) + if j == nb { tau } else { 0.0 }
        })
        .collect();
    let aun: Vec<f64> = (0..=na)
        .map(|i| a.1[0] + (a.1[i % na] - a.1[0]).rem_euclid(tau) + if i == na { tau } else { 0.0 })
        .collect();
    let (mut i, mut j) = (0, 0);
    while i < na || j < nb {
        let (ai, ai1) = (a.0[i % na], a.0[(i + 1) % na]);
        let (bj, bj1) = (b.0[(j0 + j) % nb], b.0[(j0 + j + 1) % nb]);
        if j == nb || (i < na && aun[i + 1] < bun[j + 1]) {
            out.push([ai, bj, ai1]);
            i += 1;
        } else {
            out.push([ai, bj, bj1]);
            j += 1;
        }
    }
}

/// Cuts the geodesic discs of radius [`RHO`] about `centres` out of a closed mesh of the unit
/// sphere: the triangles whose centroid (projected onto the sphere) lies inside one, then, until
/// every hole's boundary is a simple loop, every kept triangle at a vertex the boundary passes
/// twice.
pub fn cut_discs(pos: &[Vec3], tris: &[[u32; 3]], centres: &[Vec3], rho: f64) -> Holed {
    cut_where(pos, tris, |c| {
        let c = c.normalize();
        centres
            .iter()
            .any(|z| c.dot(z).clamp(-1.0, 1.0).acos() < rho)
    })
}

/// Cuts the triangles whose centroid satisfies `inside` out of a closed mesh, then, until
/// every hole's boundary is a simple loop, every kept triangle at a vertex the boundary passes
/// twice.
pub fn cut_where(pos: &[Vec3], tris: &[[u32; 3]], inside: impl Fn(Vec3) -> bool) -> Holed {
    let mut removed: Vec<bool> = tris
        .iter()
        .map(|t| inside((pos[t[0] as usize] + pos[t[1] as usize] + pos[t[2] as usize]) / 3.0))
        .collect();
    for _ in 0..100 {
        let kept: Vec<[u32; 3]> = tris
            .iter()
            .zip(&removed)
            .filter(|(_, r)| !**r)
            .map(|(t, _)| *t)
            .collect();
        let mut count = std::collections::HashMap::new();
        for t in &kept {
            for j in 0..3 {
                let (a, b) = (t[j], t[(j + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut out = vec![0u32; pos.len()];
        for (&(a, b), &c) in &count {
            if c == 1 {
                out[a as usize] += 1;
                out[b as usize] += 1;
            }
        }
        let pinched: Vec<bool> = out.iter().map(|&c| c > 2).collect();
        if !pinched.iter().any(|&p| p) {
            break;
        }
        for (t, r) in tris.iter().zip(removed.iter_mut()) {
            if t.iter().any(|&v| pinched[v as usize]) {
                *r = true;
            }
        }
    }
    let kept = tris
        .iter()
        .zip(&removed)
        .filter(|(_, r)| !**r)
        .map(|(t, _)| *t)
        .collect();
    let gone = tris
        .iter()
        .zip(&removed)
        .filter(|(_, r)| **r)
        .map(|(t, _)| *t)
        .collect();
    Holed {
        mesh: InputMesh {
            positions: pos.to_vec(),
            triangles: kept,
        },
        whole: tris.to_vec(),
        removed: gone,
    }
}

/// The peers' case: a graded sphere with one hole of about `boundary` vertices about
/// [`peer_centre`] (`h_b = 4π sin ρ / boundary`, the first guess of `hole_cases.py`).
pub fn sphere_hole(boundary: usize, seed: u64) -> Holed {
    let c = peer_centre();
    let hb = 4.0 * std::f64::consts::PI * RHO.sin() / boundary as f64;
    let (p, t) = graded_sphere(c, hb, 0.25, seed);
    cut_discs(&p, &t, &[c], RHO)
}

/// The graded, jittered sphere about the north pole (finest edge `hb` at the geodesic distance
/// [`RHO`] from it, at most 0.04) with the triangles whose centroid `(x, y)` (its upper half
/// only) satisfies `inside` cut out ([`cut_where`]).
pub fn sphere_hole_where(hb: f64, seed: u64, inside: impl Fn(f64, f64) -> bool) -> Holed {
    let (p, t) = graded_sphere(Vec3::new(0.0, 0.0, 1.0), hb, 0.25, seed);
    cut_where(&p, &t, |c| c.z > 0.0 && inside(c.x, c.y))
}

/// A jittered mesh of the open unit cylinder `x² + y² = 1`, `|z| ≤ half`: `around` vertices
/// about it, rows `about` the same spacing apart, every vertex off the two rims moved in its
/// tangent plane by at most 0.2 of the spacing (and back onto the cylinder), two triangles per
/// cell facing outwards; with the triangles whose centroid's angle `atan2(y, x)` and height
/// `z` satisfy `inside` cut out ([`cut_where`]). The two rims are loops too.
pub fn cylinder_hole_where(
    around: usize,
    half: f64,
    seed: u64,
    inside: impl Fn(f64, f64) -> bool,
) -> Holed {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let tau = std::f64::consts::TAU;
    let h = tau / around as f64;
    let rows = ((2.0 * half / h).round() as usize).max(1);
    let dz = 2.0 * half / rows as f64;
    let mut pos = Vec::with_capacity(around * (rows + 1));
    for j in 0..=rows {
        for i in 0..around {
            let (mut a, mut z) = (i as f64 * h, -half + j as f64 * dz);
            if j > 0 && j < rows {
                a += rng.gen_range(-0.2..0.2) * h;
                z += rng.gen_range(-0.2..0.2) * dz;
            }
            pos.push(Vec3::new(a.cos(), a.sin(), z));
        }
    }
    let id = |i: usize, j: usize| (j * around + i % around) as u32;
    let mut tris = Vec::with_capacity(2 * around * rows);
    for j in 0..rows {
        for i in 0..around {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    cut_where(&pos, &tris, |c| inside(c.y.atan2(c.x), c.z))
}

/// A smooth hole: the graded sphere without jitter, cut between its first two rings inside
/// the rim, so the hole's loop is that ring, a circle of equally spaced vertices (about
/// `2π sin ρ / h_b` of them).
pub fn sphere_ring_hole(hb: f64) -> Holed {
    let c = peer_centre();
    let (p, t) = graded_sphere(c, hb, 0.0, 1);
    cut_discs(&p, &t, &[c], RHO - 3f64.sqrt() / 2.0 * hb)
}

/// A jittered grid of `[−1, 1]²` in the plane `z = 0` (`k × k` cells, two triangles each,
/// counterclockwise seen from `+z`) with the triangles whose centroid is within `r` of the
/// origin removed.
pub fn plane_hole(k: usize, r: f64, seed: u64) -> Holed {
    plane_hole_where(k, seed, |x, y| x.hypot(y) < r)
}

/// [`plane_hole`] with the triangles whose centroid `(x, y)` satisfies `inside` removed.
pub fn plane_hole_where(k: usize, seed: u64, inside: impl Fn(f64, f64) -> bool) -> Holed {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let h = 2.0 / k as f64;
    let mut pos = Vec::new();
    for j in 0..=k {
        for i in 0..=k {
            let inner = i > 0 && i < k && j > 0 && j < k;
            let (dx, dy) = if inner {
                (rng.gen_range(-0.2..0.2) * h, rng.gen_range(-0.2..0.2) * h)
            } else {
                (0.0, 0.0)
            };
            pos.push(Vec3::new(
                -1.0 + i as f64 * h + dx,
                -1.0 + j as f64 * h + dy,
                0.0,
            ));
        }
    }
    let id = |i: usize, j: usize| (j * (k + 1) + i) as u32;
    let mut tris = Vec::new();
    for j in 0..k {
        for i in 0..k {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    let (mut kept, mut gone) = (Vec::new(), Vec::new());
    for t in &tris {
        let c = (pos[t[0] as usize] + pos[t[1] as usize] + pos[t[2] as usize]) / 3.0;
        if inside(c.x, c.y) {
            gone.push(*t);
        } else {
            kept.push(*t);
        }
    }
    Holed {
        mesh: InputMesh {
            positions: pos,
            triangles: kept,
        },
        whole: tris,
        removed: gone,
    }
}

/// The grid of `[−1, 1]²` in the plane `z = 0` (`k × k` cells, no jitter) with the cells of
/// `|x|, |y| < r` removed: a square hole whose loop runs along grid lines.
pub fn plane_square_hole(k: usize, r: f64) -> Holed {
    let h = 2.0 / k as f64;
    let mut pos = Vec::new();
    for j in 0..=k {
        for i in 0..=k {
            pos.push(Vec3::new(-1.0 + i as f64 * h, -1.0 + j as f64 * h, 0.0));
        }
    }
    let id = |i: usize, j: usize| (j * (k + 1) + i) as u32;
    let (mut kept, mut gone, mut whole) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..k {
        for i in 0..k {
            let c = [-1.0 + (i as f64 + 0.5) * h, -1.0 + (j as f64 + 0.5) * h];
            let pair = [
                [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
            ];
            whole.extend(pair);
            if c[0].abs() < r && c[1].abs() < r {
                gone.extend(pair);
            } else {
                kept.extend(pair);
            }
        }
    }
    Holed {
        mesh: InputMesh {
            positions: pos,
            triangles: kept,
        },
        whole,
        removed: gone,
    }
}
