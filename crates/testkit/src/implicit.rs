//! Closed meshes of implicit surfaces by marching tetrahedra, independent of the fitting code:
//! a torus (genus 1), a double torus (genus 2), a body with limbs and a mug with a handle; and
//! an open mesh cut from one of them.
//!
//! Each cube of a regular grid is split into six tetrahedra around its main diagonal (the
//! Kuhn split, the same in every cube, so neighbouring cubes' faces match); in each
//! tetrahedron the zero set of the linearly interpolated function is a triangle or a quad (two
//! triangles), with vertices on the tetrahedron's edges shared through the grid edge they lie
//! on, so the mesh is watertight and edge-manifold. Triangles face the positive side (outward
//! for a function negative inside).

use pdeshape::fit::InputMesh;
use pdeshape::Vec3;
use std::collections::HashMap;

/// The zero set of `f` (negative inside) in the box `[lo, hi]` on a grid of `n` cells along
/// its longest side.
pub fn marching_tetrahedra(f: &dyn Fn(Vec3) -> f64, lo: Vec3, hi: Vec3, n: usize) -> InputMesh {
    let size = hi - lo;
    let h = size.max() / n as f64;
    let dims = [
        (size.x / h).ceil() as usize + 1,
        (size.y / h).ceil() as usize + 1,
        (size.z / h).ceil() as usize + 1,
    ];
    let id = |i: usize, j: usize, k: usize| (i * (dims[1] + 1) + j) * (dims[2] + 1) + k;
    let point = |i: usize, j: usize, k: usize| lo + Vec3::new(i as f64, j as f64, k as f64) * h;
    let mut values = vec![0.0; (dims[0] + 1) * (dims[1] + 1) * (dims[2] + 1)];
    for i in 0..=dims[0] {
        for j in 0..=dims[1] {
            for k in 0..=dims[2] {
                let v = f(point(i, j, k));
                // No grid point on the surface: the mesh stays manifold.
                values[id(i, j, k)] = if v == 0.0 { 1e-12 } else { v };
            }
        }
    }
    let corners = [
        [0, 0, 0],
        [1, 0, 0],
        [0, 1, 0],
        [1, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [0, 1, 1],
        [1, 1, 1],
    ];
    // The six tetrahedra around the diagonal 0–7.
    let tets = [
        [0, 1, 3, 7],
        [0, 3, 2, 7],
        [0, 2, 6, 7],
        [0, 6, 4, 7],
        [0, 4, 5, 7],
        [0, 5, 1, 7],
    ];
    let mut positions: Vec<Vec3> = Vec::new();
    let mut on_edge: HashMap<(usize, usize), u32> = HashMap::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for i in 0..dims[0] {
        for j in 0..dims[1] {
            for k in 0..dims[2] {
                let ids: Vec<usize> = corners
                    .iter()
                    .map(|c| id(i + c[0], j + c[1], k + c[2]))
                    .collect();
                let pts: Vec<Vec3> = corners
                    .iter()
                    .map(|c| point(i + c[0], j + c[1], k + c[2]))
                    .collect();
                for t in &tets {
                    let g = t.map(|c| ids[c]);
                    let p = t.map(|c| pts[c]);
                    let v = g.map(|x| values[x]);
                    let inside: Vec<usize> = (0..4).filter(|&a| v[a] < 0.0).collect();
                    if inside.is_empty() || inside.len() == 4 {
                        continue;
                    }
                    let outside: Vec<usize> = (0..4).filter(|&a| v[a] >= 0.0).collect();
                    let mut vertex = |a: usize, b: usize| -> u32 {
                        let key = (g[a].min(g[b]), g[a].max(g[b]));
                        *on_edge.entry(key).or_insert_with(|| {
                            let s = v[a] / (v[a] - v[b]);
                            positions.push(p[a] + (p[b] - p[a]) * s);
                            (positions.len() - 1) as u32
                        })
                    };
                    let mut loop_: Vec<u32> = Vec::new();
                    if inside.len() == 2 {
                        let (a, b) = (inside[0], inside[1]);
                        let (c, d) = (outside[0], outside[1]);
                        loop_.extend([vertex(a, c), vertex(a, d), vertex(b, d), vertex(b, c)]);
                    } else {
                        let (one, rest) = if inside.len() == 1 {
                            (inside[0], &outside)
                        } else {
                            (outside[0], &inside)
                        };
                        loop_.extend(rest.iter().map(|&r| vertex(one, r)));
                    }
                    // Outward: from the inside corners towards the outside ones.
                    let centre = |s: &[usize]| {
                        s.iter().map(|&a| p[a]).fold(Vec3::zeros(), |x, y| x + y) / s.len() as f64
                    };
                    let out_dir = centre(&outside) - centre(&inside);
                    let q = |x: u32| positions[x as usize];
                    let tris = if loop_.len() == 4 {
                        vec![
                            [loop_[0], loop_[1], loop_[2]],
                            [loop_[0], loop_[2], loop_[3]],
                        ]
                    } else {
                        vec![[loop_[0], loop_[1], loop_[2]]]
                    };
                    for mut tri in tris {
                        let n = (q(tri[1]) - q(tri[0])).cross(&(q(tri[2]) - q(tri[0])));
                        if n.dot(&out_dir) < 0.0 {
                            tri.swap(1, 2);
                        }
                        if tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2] {
                            triangles.push(tri);
                        }
                    }
                }
            }
        }
    }
    InputMesh {
        positions,
        triangles,
    }
}

fn torus_sdf(p: Vec3, big: f64, small: f64) -> f64 {
    let q = (p.x * p.x + p.y * p.y).sqrt() - big;
    (q * q + p.z * p.z).sqrt() - small
}

fn smooth_min(a: f64, b: f64, k: f64) -> f64 {
    let h = (0.5 + 0.5 * (b - a) / k).clamp(0.0, 1.0);
    b + (a - b) * h - k * h * (1.0 - h)
}

fn capsule(p: Vec3, a: Vec3, b: Vec3, r: f64) -> f64 {
    let (pa, ba) = (p - a, b - a);
    let h = (pa.dot(&ba) / ba.dot(&ba)).clamp(0.0, 1.0);
    (pa - ba * h).norm() - r
}

/// A torus, major radius 1, minor radius 0.35, about z (genus 1), on a grid of `n` cells.
pub fn torus(n: usize) -> InputMesh {
    marching_tetrahedra(
        &|p| torus_sdf(p, 1.0, 0.35),
        Vec3::new(-1.5, -1.5, -0.5),
        Vec3::new(1.5, 1.5, 0.5),
        n,
    )
}

/// Two tori side by side along x, blended where they overlap (genus 2).
pub fn double_torus(n: usize) -> InputMesh {
    marching_tetrahedra(
        &|p| {
            let a = torus_sdf(p - Vec3::new(-0.85, 0.0, 0.0), 1.0, 0.3);
            let b = torus_sdf(p - Vec3::new(0.85, 0.0, 0.0), 1.0, 0.3);
            smooth_min(a, b, 0.15)
        },
        Vec3::new(-2.3, -1.45, -0.5),
        Vec3::new(2.3, 1.45, 0.5),
        n,
    )
}

/// A round body with four limbs and a head, blended (genus 0, not star-shaped along any
/// axis).
pub fn limbs(n: usize) -> InputMesh {
    marching_tetrahedra(
        &|p| {
            let body = capsule(p, Vec3::new(-0.6, 0.0, 0.0), Vec3::new(0.6, 0.0, 0.0), 0.45);
            let mut d = body;
            for (x, y) in [(-0.5, -0.4), (-0.5, 0.4), (0.5, -0.4), (0.5, 0.4)] {
                let leg = capsule(
                    p,
                    Vec3::new(x, y * 0.5, -0.2),
                    Vec3::new(x * 1.1, y, -1.2),
                    0.16,
                );
                d = smooth_min(d, leg, 0.12);
            }
            let head = capsule(p, Vec3::new(0.8, 0.0, 0.2), Vec3::new(1.2, 0.0, 0.6), 0.28);
            smooth_min(d, head, 0.12)
        },
        Vec3::new(-1.3, -1.0, -1.5),
        Vec3::new(1.6, 1.0, 1.0),
        n,
    )
}

/// A mug: a cup (a cylinder of radius 1 and height 2 with a hollow of radius 0.75 open at the
/// top, its edges rounded to 0.15) with a handle (half a torus) on its side (genus 1).
pub fn mug(n: usize) -> InputMesh {
    marching_tetrahedra(
        &|p| {
            let r = (p.x * p.x + p.y * p.y).sqrt();
            let round = 0.15;
            // Outer cylinder, rounded.
            let dx = r - (1.0 - round);
            let dz = p.z.abs() - (1.0 - round);
            let outer =
                dx.max(dz).min(0.0) + Vec3::new(dx.max(0.0), dz.max(0.0), 0.0).norm() - round;
            // The hollow: from z = −0.8 up, radius 0.75.
            let hx = r - 0.75 + round;
            let hz = (p.z - 0.6).abs() - 1.4 + round;
            let hollow =
                hx.max(hz).min(0.0) + Vec3::new(hx.max(0.0), hz.max(0.0), 0.0).norm() - round;
            let cup = outer.max(-hollow);
            let q = p - Vec3::new(1.0, 0.0, 0.0);
            // The half of the handle's ring outside the wall (the rest would cross the hollow).
            let handle = torus_sdf(Vec3::new(q.x, q.z, q.y), 0.6, 0.14).max(0.9 - r);
            smooth_min(cup, handle, 0.08)
        },
        Vec3::new(-1.2, -1.2, -1.2),
        Vec3::new(1.9, 1.2, 1.2),
        n,
    )
}

/// The half of the [`torus`] with `y > 0`: an open mesh with two boundary loops.
pub fn half_torus(n: usize) -> InputMesh {
    let full = torus(n);
    let triangles: Vec<[u32; 3]> = full
        .triangles
        .iter()
        .filter(|t| t.iter().map(|&i| full.positions[i as usize].y).sum::<f64>() > 0.0)
        .copied()
        .collect();
    // Keep only the vertices used, renumbered.
    let mut index = vec![u32::MAX; full.positions.len()];
    let mut positions = Vec::new();
    let mut out = Vec::with_capacity(triangles.len());
    for t in &triangles {
        out.push(t.map(|i| {
            if index[i as usize] == u32::MAX {
                index[i as usize] = positions.len() as u32;
                positions.push(full.positions[i as usize]);
            }
            index[i as usize]
        }));
    }
    InputMesh {
        positions,
        triangles: out,
    }
}
