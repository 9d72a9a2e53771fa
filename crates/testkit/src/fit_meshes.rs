//! Test meshes made independently of the fitting code: closed bodies swept ring by ring, with a
//! different number of vertices on every ring, random angular offsets and spacings, rings joined
//! by a zipper triangulation, and noise added to every vertex. Used by `pdeshape`'s `fit` tests
//! and the `fit_bench` profiling tool.

use pdeshape::fit::InputMesh;
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
) -> InputMesh {
    sweep_with(
        x,
        |s| (std::f64::consts::PI * s).sin().max(0.15),
        rings,
        around,
        noise,
        seed,
    )
}

/// [`sweep`] with the share of `around` vertices on the ring at `s` given by `density(s)`
/// (`sweep` takes `max(sin πs, 0.15)`, for bodies round like a sphere).
pub fn sweep_with(
    x: impl Fn(f64, f64) -> Vec3,
    density: impl Fn(f64) -> f64,
    rings: usize,
    around: usize,
    noise: f64,
    seed: u64,
) -> InputMesh {
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
        let scale = density(si);
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
    InputMesh::new(positions, triangles).unwrap()
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

/// The half-width of the relief sheet at height `y` (`|y| ≤ RELIEF_HALF_HEIGHT`): narrower at
/// the chin and the forehead, like the outline of a face.
pub fn relief_half_width(y: f64) -> f64 {
    1.0 - 0.25 * (y / RELIEF_HALF_HEIGHT).powi(2)
}

/// Half the height of the relief sheet.
pub const RELIEF_HALF_HEIGHT: f64 = 1.3;

/// A face-like relief (book §4.6, Fig. 4.6): a dome with a nose, eye sockets, a brow ridge,
/// lips and a chin, as heights over the `(x, y)` plane (the face looks towards +z, up is +y).
pub fn relief(x: f64, y: f64) -> f64 {
    let g = |dx: f64, sx: f64, dy: f64, sy: f64| (-(dx / sx).powi(2) - (dy / sy).powi(2)).exp();
    0.45 * (1.0 - 0.35 * x * x - 0.15 * y * y) + 0.22 * g(x, 0.16, y + 0.05, 0.38)
        - 0.07 * (g(x - 0.42, 0.2, y - 0.3, 0.13) + g(x + 0.42, 0.2, y - 0.3, 0.13))
        + 0.05 * g(x, 0.6, y - 0.55, 0.08)
        + 0.035 * g(x, 0.3, y + 0.6, 0.07)
        + 0.06 * g(x, 0.35, y + 1.05, 0.2)
}

/// An open sheet over the relief: `rows + 1` rows across the face (the first and last exactly
/// at `y = ∓RELIEF_HALF_HEIGHT`, the others jittered), each with a random count of about
/// `across` vertices at jittered places between its two ends on the outline, consecutive rows
/// joined by a zipper triangulation; noise as in [`sweep`]. The mesh is tilted (a rotation about
/// (1, 2, 0) by 0.3 rad) so no coordinate axis lines up with the sheet.
pub fn relief_sheet(rows: usize, across: usize, noise: f64, seed: u64) -> InputMesh {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let hh = RELIEF_HALF_HEIGHT;
    let mut ys: Vec<f64> = (0..=rows)
        .map(|i| {
            let jitter = if i == 0 || i == rows {
                0.0
            } else {
                rng.gen_range(-0.3..0.3)
            };
            -hh + 2.0 * hh * (i as f64 + jitter) / rows as f64
        })
        .collect();
    ys.sort_by(f64::total_cmp);
    let mut positions = Vec::new();
    // Each row: (x / half-width, vertex) from left to right.
    let mut row_ix: Vec<Vec<(f64, u32)>> = Vec::new();
    for &y in &ys {
        let n = ((across as f64 * rng.gen_range(0.8..1.2)) as usize).max(4);
        let w = relief_half_width(y);
        let mut row = Vec::with_capacity(n);
        for j in 0..n {
            let jitter = if j == 0 || j + 1 == n {
                0.0
            } else {
                rng.gen_range(-0.3..0.3)
            };
            let t = -1.0 + 2.0 * (j as f64 + jitter) / (n - 1) as f64;
            row.push((t, positions.len() as u32));
            positions.push(Vec3::new(w * t, y, relief(w * t, y)));
        }
        row.sort_by(|a, b| a.0.total_cmp(&b.0));
        row_ix.push(row);
    }
    let mut triangles = Vec::new();
    for w in row_ix.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let (mut i, mut j) = (0usize, 0usize);
        while i + 1 < a.len() || j + 1 < b.len() {
            if j + 1 == b.len() || (i + 1 < a.len() && a[i + 1].0 <= b[j + 1].0) {
                triangles.push([a[i].1, a[i + 1].1, b[j].1]);
                i += 1;
            } else {
                triangles.push([a[i].1, b[j + 1].1, b[j].1]);
                j += 1;
            }
        }
    }
    let k = Vec3::new(1.0, 2.0, 0.0).normalize();
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    for p in positions.iter_mut() {
        let q = *p;
        *p = q * c + k.cross(&q) * s + k * k.dot(&q) * (1.0 - c);
        *p += Vec3::new(
            rng.gen_range(-noise..=noise),
            rng.gen_range(-noise..=noise),
            rng.gen_range(-noise..=noise),
        );
    }
    InputMesh::new(positions, triangles).unwrap()
}

/// The share of vertices on a ring of [`u_tube`]: its circumference over the largest, at least
/// 0.15.
pub fn u_tube_density(s: f64) -> f64 {
    ((u_tube(s, 0.0) - u_tube(s, std::f64::consts::PI)).norm() / 0.7).max(0.15)
}

/// A U-shaped tube (a closed body): two legs of length 2 along z at `x = ∓1` joined at the top
/// by a half circle of radius 1 about `(0, 0, 2)`, radius 0.35, hemispherical ends. No plane
/// across one main axis cuts it in single loops: the automatic mode refuses it and a template
/// fits it.
pub fn u_tube(s: f64, phi: f64) -> Vec3 {
    let pi = std::f64::consts::PI;
    let (rho, cap) = (0.35, 0.35);
    let leg = 2.0 + cap;
    let total = 2.0 * leg + pi;
    let l = s * total;
    // The spine point and its unit tangent.
    let (p, t) = if l < leg {
        (Vec3::new(-1.0, 0.0, l - cap), Vec3::z())
    } else if l < leg + pi {
        let a = pi - (l - leg);
        (
            Vec3::new(a.cos(), 0.0, 2.0 + a.sin()),
            Vec3::new(a.sin(), 0.0, -a.cos()),
        )
    } else {
        (Vec3::new(1.0, 0.0, 2.0 - (l - leg - pi)), -Vec3::z())
    };
    let d = l.min(total - l);
    let r = if d < cap {
        (rho * rho - (cap - d).powi(2)).max(0.0).sqrt()
    } else {
        rho
    };
    let b = Vec3::y();
    let n = b.cross(&t);
    p + (n * phi.cos() + b * phi.sin()) * r
}

/// The template that fits [`u_tube`]: three joined parts, the two legs along z and the bend
/// by five planes about its centre, poles at both ends.
pub const U_TUBE_TEMPLATE: &str = r#"
[[parts]]
name = "left"
axis = [0, 0, 1]
origin = [-1, 0, 0]
positions = [0.0, 2.0]
start = "pole"

[[parts]]
name = "bend"
planes = [
  { point = [-1, 0, 2], normal = [0, 0, 1] },
  { point = [-0.70710678, 0, 2.70710678], normal = [0.70710678, 0, 0.70710678] },
  { point = [0, 0, 3], normal = [1, 0, 0] },
  { point = [0.70710678, 0, 2.70710678], normal = [0.70710678, 0, -0.70710678] },
  { point = [1, 0, 2], normal = [0, 0, -1] },
]

[[parts]]
name = "right"
axis = [0, 0, -1]
origin = [1, 0, 0]
positions = [-2.0, 0.0]
end = "pole"
"#;

/// A plate as a CAD program exports it: a 4 × 3 rectangle with corners rounded to `radius`,
/// each corner's arc in `segments` pieces, `thickness` thick, centred at the origin. Its two
/// flat faces are the outline's polygon cut in a zigzag from end to end (every triangle spans
/// the plate, a sliver as long as it is wide), its rim long quads of two triangles each: the
/// vertices are all on the outline, and the faces have none inside them. Closed, oriented
/// outwards, volume `thickness · (12 − (4 − π) radius²)` up to the arcs' chords.
pub fn cad_plate(radius: f64, segments: usize, thickness: f64) -> InputMesh {
    let (w, d) = (4.0, 3.0);
    let mut outline = Vec::new();
    for (k, (cx, cy)) in [
        (w / 2.0 - radius, d / 2.0 - radius),
        (radius - w / 2.0, d / 2.0 - radius),
        (radius - w / 2.0, radius - d / 2.0),
        (w / 2.0 - radius, radius - d / 2.0),
    ]
    .into_iter()
    .enumerate()
    {
        for j in 0..=segments {
            let a = TAU / 4.0 * (k as f64 + j as f64 / segments as f64);
            outline.push((cx + radius * a.cos(), cy + radius * a.sin()));
        }
    }
    let n = outline.len() as u32;
    let h = thickness / 2.0;
    let mut positions: Vec<Vec3> = outline.iter().map(|&(x, y)| Vec3::new(x, y, h)).collect();
    positions.extend(outline.iter().map(|&(x, y)| Vec3::new(x, y, -h)));
    let mut triangles = Vec::new();
    // The zigzag: from both ends of the outline towards its middle, one step at a time.
    let (mut i, mut j) = (0, n - 1);
    while j - i >= 2 {
        let t = if (j - i) % 2 == (n - 1) % 2 {
            i += 1;
            [i - 1, i, j]
        } else {
            j -= 1;
            [i, j, j + 1]
        };
        triangles.push(t);
        triangles.push([n + t[0], n + t[2], n + t[1]]);
    }
    for i in 0..n {
        let k = (i + 1) % n;
        triangles.push([i, n + i, n + k]);
        triangles.push([i, n + k, k]);
    }
    InputMesh::new(positions, triangles).unwrap()
}
