//! Test meshes made independently of the fitting code: closed bodies swept ring by ring, with a
//! different number of vertices on every ring, random angular offsets and spacings, rings joined
//! by a zipper triangulation, and noise added to every vertex.

#![allow(dead_code)]

use pdeshape::fit::TriMesh;
use pdeshape::{Vec3, TAU};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A closed body `X(s, φ)`, `s ∈ [0, 1]` from pole to pole (`X(0, ·)` and `X(1, ·)` single
/// points), `φ ∈ [0, 2π)`: about `rings` rings of about `around` vertices, jittered, plus the
/// poles; isotropic noise of `noise` (uniform in a cube of that half-width) on every vertex.
pub fn sweep(
    x: impl Fn(f64, f64) -> Vec3,
    rings: usize,
    around: usize,
    noise: f64,
    seed: u64,
) -> TriMesh {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // Ring parameters: jittered and sorted.
    let mut s: Vec<f64> = (1..rings)
        .map(|i| (i as f64 + rng.gen_range(-0.3..0.3)) / rings as f64)
        .collect();
    s.sort_by(f64::total_cmp);
    let mut positions = vec![x(0.0, 0.0)];
    let mut ring_ix: Vec<Vec<(f64, u32)>> = Vec::new();
    for &si in &s {
        // Fewer vertices near the poles, and a random count and offset per ring.
        let scale = (std::f64::consts::PI * si).sin().max(0.15);
        let n = ((around as f64 * scale * rng.gen_range(0.8..1.2)) as usize).max(6);
        let offset = rng.gen_range(0.0..TAU);
        let mut ring = Vec::with_capacity(n);
        for j in 0..n {
            let phi =
                (offset + TAU * (j as f64 + rng.gen_range(-0.25..0.25)) / n as f64).rem_euclid(TAU);
            ring.push((phi, positions.len() as u32));
            positions.push(x(si, phi));
        }
        ring.sort_by(|a, b| a.0.total_cmp(&b.0));
        ring_ix.push(ring);
    }
    positions.push(x(1.0, 0.0));
    let top = positions.len() as u32 - 1;
    let mut triangles = Vec::new();
    // Caps: fans, oriented so normals point outwards for a body around +z (φ counter-clockwise).
    let first = &ring_ix[0];
    for j in 0..first.len() {
        triangles.push([0, first[(j + 1) % first.len()].1, first[j].1]);
    }
    let last = &ring_ix[ring_ix.len() - 1];
    for j in 0..last.len() {
        triangles.push([top, last[j].1, last[(j + 1) % last.len()].1]);
    }
    // Zipper between consecutive rings, both sorted by angle from their smallest: advance on
    // the ring whose next vertex comes first.
    for w in ring_ix.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let angle = |r: &[(f64, u32)], k: usize| r[k % r.len()].0 + TAU * (k / r.len()) as f64;
        let (mut i, mut j) = (0usize, 0usize);
        while i < a.len() || j < b.len() {
            let (ai, bj) = (a[i % a.len()].1, b[j % b.len()].1);
            if j == b.len() || (i < a.len() && angle(a, i + 1) <= angle(b, j + 1)) {
                triangles.push([ai, a[(i + 1) % a.len()].1, bj]);
                i += 1;
            } else {
                triangles.push([ai, b[(j + 1) % b.len()].1, bj]);
                j += 1;
            }
        }
    }
    for p in positions.iter_mut() {
        *p += Vec3::new(
            rng.gen_range(-noise..=noise),
            rng.gen_range(-noise..=noise),
            rng.gen_range(-noise..=noise),
        );
    }
    TriMesh::new(positions, triangles).unwrap()
}

/// The vase: a body of revolution about z, height 3, with a belly and a waist.
pub fn vase(s: f64, phi: f64) -> Vec3 {
    let pi = std::f64::consts::PI;
    let r = (pi * s).sin() * (0.8 + 0.3 * (2.0 * pi * 1.25 * s + 1.0).sin());
    let z = 1.5 * (1.0 - (pi * s).cos());
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The unit sphere (Fig. 8.10), its poles on a tilted axis.
pub fn sphere(s: f64, phi: f64) -> Vec3 {
    let pi = std::f64::consts::PI;
    let p = Vec3::new(
        (pi * s).sin() * phi.cos(),
        (pi * s).sin() * phi.sin(),
        -(pi * s).cos(),
    );
    // A rotation about (1, 1, 0) by 0.4 rad, so nothing lines up with the coordinate axes.
    let k = Vec3::new(1.0, 1.0, 0.0).normalize();
    let (c, sn) = (0.4f64.cos(), 0.4f64.sin());
    p * c + k.cross(&p) * sn + k * k.dot(&p) * (1.0 - c)
}

/// A star-shaped blob: `r(θ, φ) = 1 + 0.18 sin 3φ sin²θ + 0.12 cos 2θ`, stretched by 1.4 along z.
pub fn blob(s: f64, phi: f64) -> Vec3 {
    let pi = std::f64::consts::PI;
    let t = pi * s;
    let r = 1.0 + 0.18 * (3.0 * phi).sin() * t.sin().powi(2) + 0.12 * (2.0 * t).cos();
    Vec3::new(
        r * t.sin() * phi.cos(),
        r * t.sin() * phi.sin(),
        -1.4 * r * t.cos(),
    )
}

/// A bent tube: a prolate body (half-length 2, radius 0.5) bent about y on a circle of radius 4
/// (about 57° from end to end).
pub fn bent_tube(s: f64, phi: f64) -> Vec3 {
    let pi = std::f64::consts::PI;
    let rho = 0.5 * (pi * s).sin() * (1.0 + 0.3 * (pi * s).sin());
    let z = -2.0 * (pi * s).cos();
    let (x, y) = (rho * phi.cos(), rho * phi.sin());
    let radius = 4.0;
    let angle = z / radius;
    Vec3::new(
        (radius + x) * angle.cos() - radius,
        y,
        (radius + x) * angle.sin(),
    )
}
