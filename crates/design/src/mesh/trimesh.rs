//! Indexed triangle meshes: the general form of a tessellation, for what a rectangular grid cannot
//! describe (trimmed patches, welded designs). A [`GridMesh`] converts to one without loss.

use super::GridMesh;
use rayon::prelude::*;
use std::ops::Range;

/// A named group of consecutive triangles (a design's patch).
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// The group's name (the patch's name in the design).
    pub name: String,
    /// Indices into [`TriMesh::triangles`] of the group's triangles.
    pub triangles: Range<usize>,
}

/// An indexed triangle mesh in mesh precision. Triangles are counter-clockwise seen from the side
/// the normals point to. `uv` is empty or has one `(u, v)` parameter pair per vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions `[x, y, z]`.
    pub positions: Vec<[f32; 3]>,
    /// Vertex normals (unit, or zero where the surface has none), one per position.
    pub normals: Vec<[f32; 3]>,
    /// Surface parameters `(u, v)`, one per position, or empty.
    pub uv: Vec<[f32; 2]>,
    /// Triangles as three indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Named triangle ranges, in order, covering `triangles` (empty for an unnamed mesh).
    pub parts: Vec<Part>,
}

impl TriMesh {
    /// The grid's vertices, normals, parameters and triangles (two per quad, the diagonal from
    /// `(i, j)` to `(i+1, j+1)`), as one part called `name`.
    pub fn from_grid(grid: &GridMesh, name: &str) -> TriMesh {
        let uv = (0..grid.nu)
            .flat_map(|i| (0..grid.nv).map(move |j| [grid.u[i] as f32, grid.v[j] as f32]))
            .collect();
        let triangles: Vec<[u32; 3]> = grid.triangles().collect();
        let parts = vec![Part {
            name: name.to_string(),
            triangles: 0..triangles.len(),
        }];
        TriMesh {
            positions: grid.positions.clone(),
            normals: grid.normals.clone(),
            uv,
            triangles,
            parts,
        }
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True when the mesh has no vertices.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Appends `other`'s vertices, triangles (re-indexed) and parts. The `uv` channel is kept only
    /// when both meshes have it (or `self` is empty).
    pub fn append(&mut self, other: &TriMesh) {
        let offset = self.positions.len() as u32;
        let first = self.triangles.len();
        if self.is_empty() || (!self.uv.is_empty() && !other.uv.is_empty()) {
            self.uv.extend_from_slice(&other.uv);
        } else {
            self.uv.clear();
        }
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.triangles.extend(
            other
                .triangles
                .iter()
                .map(|t| [t[0] + offset, t[1] + offset, t[2] + offset]),
        );
        self.parts.extend(other.parts.iter().map(|p| Part {
            name: p.name.clone(),
            triangles: p.triangles.start + first..p.triangles.end + first,
        }));
    }

    /// Joins vertices at exactly the same position (a surface's pole: a grid row collapsed to a
    /// point), drops the triangles that collapse with them, and leaves out vertices no triangle
    /// uses. A joined vertex keeps the first one's normal and `uv`. Parts keep their order.
    pub fn join_coincident(&mut self) {
        let mut first: std::collections::HashMap<[u32; 3], u32> =
            std::collections::HashMap::with_capacity(self.positions.len());
        let same: Vec<u32> = self
            .positions
            .iter()
            .enumerate()
            .map(|(k, p)| {
                // −0 and +0 are the same position.
                let key = p.map(|x| (x + 0.0).to_bits());
                *first.entry(key).or_insert(k as u32)
            })
            .collect();
        let kept = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| same[i as usize]);
            (a != b && b != c && a != c).then_some([a, b, c])
        };
        let mut triangles = Vec::with_capacity(self.triangles.len());
        let mut parts = Vec::with_capacity(self.parts.len());
        for part in &self.parts {
            let start = triangles.len();
            triangles.extend(
                self.triangles[part.triangles.clone()]
                    .iter()
                    .filter_map(kept),
            );
            parts.push(Part {
                name: part.name.clone(),
                triangles: start..triangles.len(),
            });
        }
        if self.parts.is_empty() {
            triangles.extend(self.triangles.iter().filter_map(kept));
        }
        // Keep the used vertices, in order: `index[k]` is vertex k's new index.
        let mut used = vec![false; self.positions.len()];
        for &i in triangles.iter().flatten() {
            used[i as usize] = true;
        }
        let mut index = vec![u32::MAX; used.len()];
        for (n, (k, _)) in used.iter().enumerate().filter(|(_, &u)| u).enumerate() {
            index[k] = n as u32;
        }
        fn keep<T: Copy>(v: &[T], used: &[bool]) -> Vec<T> {
            v.iter()
                .zip(used)
                .filter(|(_, &u)| u)
                .map(|(x, _)| *x)
                .collect()
        }
        self.positions = keep(&self.positions, &used);
        self.normals = keep(&self.normals, &used);
        if !self.uv.is_empty() {
            self.uv = keep(&self.uv, &used);
        }
        for t in &mut triangles {
            *t = t.map(|i| index[i as usize]);
        }
        self.triangles = triangles;
        self.parts = parts;
    }

    /// Structural problems, if any: an index out of range, a normal or `uv` channel of the wrong
    /// length, parts that do not cover the triangles in order. Writers check this first.
    pub fn check(&self) -> Result<(), String> {
        let n = self.positions.len();
        if self.normals.len() != n {
            return Err(format!("{} normals for {n} vertices", self.normals.len()));
        }
        if !self.uv.is_empty() && self.uv.len() != n {
            return Err(format!("{} uv pairs for {n} vertices", self.uv.len()));
        }
        // The largest index first (one straight pass), the culprit only when it is too large.
        let largest = self
            .triangles
            .par_chunks(1 << 16)
            .map(|ts| ts.as_flattened().iter().copied().fold(0, u32::max))
            .max();
        let past = |t: &[u32; 3]| t.iter().any(|&i| i as usize >= n);
        if let Some(k) = largest
            .filter(|&m| m as usize >= n)
            .and_then(|_| self.triangles.iter().position(past))
        {
            let t = self.triangles[k];
            return Err(format!("triangle {k} {t:?} indexes past {n} vertices"));
        }
        let mut next = 0;
        for p in &self.parts {
            if p.triangles.start != next || p.triangles.end < p.triangles.start {
                return Err(format!(
                    "part {:?} does not follow the previous part",
                    p.name
                ));
            }
            next = p.triangles.end;
        }
        if !self.parts.is_empty() && next != self.triangles.len() {
            return Err(format!(
                "parts cover {next} of {} triangles",
                self.triangles.len()
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::tessellate;
    use crate::surface::{ParametricSurface, VDomain};

    fn plane(nu: usize, nv: usize) -> GridMesh {
        let s = ParametricSurface::new("u", "v", "0", VDomain::Interval(0.0, 1.0)).unwrap();
        tessellate(&s, nu, nv).unwrap()
    }

    /// A cone `u (cos v, sin v), 1 − u` has a pole at `u = 0`: its row of grid vertices becomes
    /// one vertex, the row's flat triangles go, every other triangle and its area stay.
    #[test]
    fn a_pole_row_becomes_one_vertex_without_flat_triangles() {
        let s = ParametricSurface::new("u*cos(v)", "u*sin(v)", "1 - u", VDomain::Periodic).unwrap();
        let (nu, nv) = (5, 8);
        let mut m = TriMesh::from_grid(&tessellate(&s, nu, nv).unwrap(), "cone");
        let area = |m: &TriMesh| -> f64 {
            m.triangles
                .iter()
                .map(|t| {
                    let p = t.map(|i| m.positions[i as usize].map(f64::from));
                    let (a, b) = (
                        [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]],
                        [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]],
                    );
                    let c = [
                        a[1] * b[2] - a[2] * b[1],
                        a[2] * b[0] - a[0] * b[2],
                        a[0] * b[1] - a[1] * b[0],
                    ];
                    0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
                })
                .sum()
        };
        let before = area(&m);
        let flat = m
            .triangles
            .iter()
            .filter(|t| {
                let p = t.map(|i| m.positions[i as usize]);
                p[0] == p[1] || p[1] == p[2] || p[0] == p[2]
            })
            .count();
        assert_eq!(flat, nv, "one flat triangle per cell of the pole's row");
        m.join_coincident();
        m.check().unwrap();
        assert_eq!(m.len(), (nu - 1) * nv + 1);
        assert_eq!(m.triangles.len(), 2 * (nu - 1) * nv - nv);
        assert_eq!(m.parts[0].triangles, 0..m.triangles.len());
        assert!((area(&m) - before).abs() <= 1e-12 * before);
        for t in &m.triangles {
            assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
        }
    }

    #[test]
    fn grid_conversion_keeps_vertices_and_counter_clockwise_triangles() {
        let g = plane(4, 5);
        let m = TriMesh::from_grid(&g, "sheet");
        assert_eq!(m.len(), 20);
        assert_eq!(m.triangles.len(), 2 * 3 * 4);
        m.check().unwrap();
        assert_eq!(m.uv[7], [g.u[1] as f32, g.v[2] as f32]);
        // Every triangle of the plane z = 0 with normal +z winds counter-clockwise in (x, y).
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let cross = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            assert!(cross > 0.0, "{t:?}");
            assert!(m.normals[t[0] as usize][2] > 0.0);
        }
    }

    #[test]
    fn append_reindexes_and_shifts_parts() {
        let mut m = TriMesh::from_grid(&plane(2, 2), "a");
        m.append(&TriMesh::from_grid(&plane(3, 2), "b"));
        m.check().unwrap();
        assert_eq!(m.len(), 4 + 6);
        assert_eq!(m.parts[1].triangles, 2..6);
        assert_eq!(m.triangles[2], [4, 6, 7]);
        let mut bad = m.clone();
        bad.triangles.push([0, 1, 10]);
        assert!(bad.check().unwrap_err().contains("past 10 vertices"));
    }
}
