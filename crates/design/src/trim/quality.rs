//! Mesh quality of triangles: angles, aspect ratios, orientation.

/// Quality figures of a set of triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshQuality {
    /// Number of triangles measured.
    pub triangles: usize,
    /// Smallest interior angle, degrees.
    pub min_angle_deg: f64,
    /// Largest aspect ratio `l_max (l_a + l_b + l_c) / (4√3 A)` (1 for an equilateral triangle).
    pub max_aspect: f64,
    /// Mean aspect ratio.
    pub mean_aspect: f64,
    /// Triangles of zero or negative area (clockwise in the plane for 2D points; for 3D points,
    /// those whose normal points against `reference`, see [`quality`]).
    pub inverted: usize,
}

/// The quality of `triangles` over `points`. With `reference` (one unit normal per vertex), a
/// triangle counts as inverted when its normal `(b − a) × (c − a)` has a non-positive dot
/// product with the mean of its vertices' reference normals; without it, when the `z` component
/// of that normal is non-positive (points in a plane, `z = 0`).
pub fn quality(
    points: &[[f64; 3]],
    triangles: &[[u32; 3]],
    reference: Option<&[[f64; 3]]>,
) -> MeshQuality {
    let mut q = MeshQuality {
        triangles: triangles.len(),
        min_angle_deg: 180.0,
        max_aspect: 0.0,
        mean_aspect: 0.0,
        inverted: 0,
    };
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    for t in triangles {
        let [a, b, c] = t.map(|i| points[i as usize]);
        let n = cross(sub(b, a), sub(c, a));
        let area = 0.5 * dot(n, n).sqrt();
        let up = match reference {
            Some(r) => {
                let [x, y, z] = t.map(|i| r[i as usize]);
                dot(
                    n,
                    [x[0] + y[0] + z[0], x[1] + y[1] + z[1], x[2] + y[2] + z[2]],
                )
            }
            None => n[2],
        };
        if up.is_nan() || up <= 0.0 {
            q.inverted += 1;
        }
        let e = [sub(b, a), sub(c, b), sub(a, c)];
        let l = e.map(|v| dot(v, v).sqrt());
        for k in 0..3 {
            // Angle at the vertex between edges k and k+2 (reversed).
            let (x, y) = (e[k], e[(k + 2) % 3]);
            let cosine = -dot(x, y) / (l[k] * l[(k + 2) % 3]);
            let angle = cosine.clamp(-1.0, 1.0).acos().to_degrees();
            if angle.is_nan() || angle < q.min_angle_deg {
                q.min_angle_deg = angle;
            }
        }
        let aspect = l[0].max(l[1]).max(l[2]) * (l[0] + l[1] + l[2]) / (4.0 * 3f64.sqrt() * area);
        if aspect.is_nan() || aspect > q.max_aspect {
            q.max_aspect = aspect;
        }
        q.mean_aspect += aspect;
    }
    if !triangles.is_empty() {
        q.mean_aspect /= triangles.len() as f64;
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equilateral_and_right_triangles() {
        let h = 3f64.sqrt() / 2.0;
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, h, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let q = quality(&p, &[[0, 1, 2]], None);
        assert!((q.min_angle_deg - 60.0).abs() < 1e-9);
        assert!((q.max_aspect - 1.0).abs() < 1e-12);
        assert_eq!(q.inverted, 0);
        let q = quality(&p, &[[0, 1, 3]], None);
        assert!((q.min_angle_deg - 45.0).abs() < 1e-9);
        // l_max = √2, perimeter 2 + √2, area ½.
        let want = 2f64.sqrt() * (2.0 + 2f64.sqrt()) / (2.0 * 3f64.sqrt());
        assert!((q.max_aspect - want).abs() < 1e-12);
        assert_eq!(quality(&p, &[[0, 3, 1]], None).inverted, 1);
    }
}
