//! What a fill is measured by: the mesh's vertex normals (angle-weighted, from the triangles
//! around a vertex) and the discrete normal jump across the loop.

use crate::Vec3;

/// The unit normal at every vertex: the sum of the unit normals of its triangles, each
/// weighted by the triangle's angle at the vertex (Thürmer and Wüthrich); zero for a vertex of
/// no triangle.
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut out = vec![Vec3::zeros(); positions.len()];
    for t in triangles {
        let p = t.map(|i| positions[i as usize]);
        let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
        let len = n.norm();
        if len == 0.0 || !len.is_finite() {
            continue;
        }
        let n = n / len;
        for j in 0..3 {
            let (a, b) = (p[(j + 1) % 3] - p[j], p[(j + 2) % 3] - p[j]);
            let angle = a.cross(&b).norm().atan2(a.dot(&b));
            out[t[j] as usize] += n * angle;
        }
    }
    for n in &mut out {
        let len = n.norm();
        if len > 0.0 {
            *n /= len;
        }
    }
    out
}

/// The normal jump at `vertices`: per vertex, the angle (radians) between the area-weighted
/// normal of the triangles of `one` at the vertex and that of the triangles of `other` (the
/// measure of the hole-filling peers: the fill against the mesh, or the removed triangles
/// against the rest for the mesh's own jump). Returns the largest and the root mean square;
/// vertices missing from either side are skipped.
pub fn normal_jump(
    positions: &[Vec3],
    one: &[[u32; 3]],
    other: &[[u32; 3]],
    vertices: &[u32],
) -> (f64, f64) {
    let mut slot = std::collections::HashMap::with_capacity(vertices.len());
    for (k, &v) in vertices.iter().enumerate() {
        slot.insert(v, k);
    }
    let sum = |tris: &[[u32; 3]]| {
        let mut acc = vec![Vec3::zeros(); vertices.len()];
        for t in tris {
            let p = t.map(|i| positions[i as usize]);
            let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
            for &v in t {
                if let Some(&k) = slot.get(&v) {
                    acc[k] += n;
                }
            }
        }
        acc
    };
    let (a, b) = (sum(one), sum(other));
    let (mut worst, mut sq, mut count) = (0.0f64, 0.0, 0usize);
    for (x, y) in a.iter().zip(&b) {
        if x.norm() == 0.0 || y.norm() == 0.0 {
            continue;
        }
        let angle = x.cross(y).norm().atan2(x.dot(y));
        worst = worst.max(angle);
        sq += angle * angle;
        count += 1;
    }
    (
        worst,
        if count > 0 {
            (sq / count as f64).sqrt()
        } else {
            0.0
        },
    )
}
