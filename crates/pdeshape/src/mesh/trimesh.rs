//! Indexed triangle meshes: the general form of a tessellation, for what a rectangular grid cannot
//! describe (trimmed patches, welded designs). A [`GridMesh`] converts to one without loss.

use super::GridMesh;
use std::ops::Range;

/// A named group of consecutive triangles (a design's patch).
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    pub name: String,
    pub triangles: Range<usize>,
}

/// An indexed triangle mesh in mesh precision. Triangles are counter-clockwise seen from the side
/// the normals point to. `uv` is empty or has one `(u, v)` parameter pair per vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uv: Vec<[f32; 2]>,
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
        if let Some((k, t)) = self
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&i| i as usize >= n))
        {
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
