//! Quadratic shell meshes of a design's surfaces (CalculiX `S8R` quadrilaterals, `S6`
//! triangles where a cell has collapsed to a triangle at a pole), with the edges that patches
//! share merged into one set of nodes.
//!
//! Each surface is sampled on a grid twice as fine as the element grid: `(2nu + 1) × 2nv` points
//! for a periodic `v` (`2nv + 1` otherwise). The even rows and columns are the elements' corners,
//! the odd ones their mid-side nodes, so every node lies on the exact surface. The vertices are
//! welded and the patches turned to agree by [`crate::mesh::weld_mapped`] (the same rules as
//! every mesh the crate writes). A cell with one side collapsed to a point (the fans at a pole)
//! becomes a six-node triangle; a cell with two collapsed sides is dropped.
//!
//! Why `S8R`: on the closed forms of the tests (cylinders, sphere) the eight-node quadrilateral
//! with reduced integration reaches the membrane stresses within a fraction of a percent on
//! meshes where the six-node triangle (two per cell) is still several percent off; the grids of
//! PDE patches are quadrilateral anyway, and only poles need triangles.

use crate::mesh::{self, GridMesh, Samples, WeldOptions};
use crate::surface::Surface;
use crate::{Error, Result};

/// Largest number of nodes a shell model may have (the solver's memory and time grow faster
/// than linearly; a cup needs a few thousand).
pub const MAX_NODES: usize = 200_000;

/// A boundary edge of one patch, in its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The row `u = start` of the patch's `u` range.
    U0,
    /// The row `u = end`.
    U1,
}

/// A quadratic shell element: corners counter-clockwise seen from the normal side, then the
/// mid-side nodes of edges 1–2, 2–3, … (CalculiX's order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Element {
    /// Six-node triangle (`S6`).
    Tri([u32; 6]),
    /// Eight-node quadrilateral (`S8R`).
    Quad([u32; 8]),
}

impl Element {
    /// The nodes, corners first.
    pub fn nodes(&self) -> &[u32] {
        match self {
            Element::Tri(n) => n,
            Element::Quad(n) => n,
        }
    }

    /// Number of corners.
    pub fn corners(&self) -> usize {
        match self {
            Element::Tri(_) => 3,
            Element::Quad(_) => 4,
        }
    }
}

/// A conforming mesh of six-node triangles on the surfaces of a design.
#[derive(Clone, Debug, PartialEq)]
pub struct ShellMesh {
    /// Node positions (full precision, on the surfaces).
    pub nodes: Vec<[f64; 3]>,
    /// Unit surface normals at the nodes (oriented with the elements).
    pub normals: Vec<[f64; 3]>,
    /// `(patch, u, v)` of each node (the first patch that produced it).
    pub params: Vec<(usize, f64, f64)>,
    /// Elements, 0-based node indices in CalculiX's order.
    pub elements: Vec<Element>,
    /// The patch of each element.
    pub element_patch: Vec<usize>,
    /// Per patch, its `u = start` and `u = end` rows as node indices in `v` order: corner,
    /// mid-side, corner, … (for a periodic `v` the first node is not repeated at the end).
    rows: Vec<[Vec<u32>; 2]>,
    /// Per patch, whether `v` is periodic.
    periodic: Vec<bool>,
    /// Per patch, the node at each point of the sampling grid (for [`ShellMesh::interpolate`]).
    grids: Vec<NodeGrid>,
}

/// The sampling grid of one patch: `u` (rows), `v` (columns, no repeated seam when periodic)
/// and the node at each point, `u32::MAX` where none (cell centres, dropped cells).
#[derive(Clone, Debug, PartialEq)]
struct NodeGrid {
    u: Vec<f64>,
    v: Vec<f64>,
    periodic: bool,
    node: Vec<u32>,
}

/// The cell `c` of a sampling axis `t` (corners at even indices) holding `x`, and the local
/// coordinate `ξ ∈ [−1, 1]` in it; `period` closes a periodic axis (its last cell ends at
/// `t[0] + period`).
fn cell_of(t: &[f64], x: f64, period: Option<f64>) -> (usize, f64) {
    let n = t.len();
    let (cells, end) = match period {
        Some(p) => (n / 2, t[0] + p),
        None => ((n - 1) / 2, t[n - 1]),
    };
    let x = match period {
        Some(p) => t[0] + (x - t[0]).rem_euclid(p),
        None => x.clamp(t[0], end),
    };
    let corner = |c: usize| if 2 * c >= n { end } else { t[2 * c] };
    let mut c = 0;
    while c + 1 < cells && x >= corner(c + 1) {
        c += 1;
    }
    let (a, b) = (corner(c), corner(c + 1));
    let xi = if b > a {
        2.0 * (x - a) / (b - a) - 1.0
    } else {
        0.0
    };
    (c, xi.clamp(-1.0, 1.0))
}

impl ShellMesh {
    /// Meshes `surfaces` with `nu × nv` element grid cells per patch (`nu` rows of cells along
    /// `u`, `nv` around `v`), two triangles per cell.
    pub fn new(surfaces: &[&dyn Surface], names: &[&str], nu: usize, nv: usize) -> Result<Self> {
        if nu < 1 || nv < 2 {
            return Err(Error::invalid(format!(
                "a shell mesh needs at least 1 × 2 cells per patch (got {nu} × {nv})"
            )));
        }
        let rows_f = 2 * nu + 1;
        let estimate = surfaces.len() * rows_f * (2 * nv + 1);
        if estimate > MAX_NODES {
            return Err(Error::invalid(format!(
                "a shell mesh of {nu} × {nv} cells on {} patches has about {estimate} nodes, \
                 above the limit of {MAX_NODES}",
                surfaces.len()
            )));
        }
        let mut samples: Vec<Samples> = Vec::with_capacity(surfaces.len());
        for s in surfaces {
            let periodic = matches!(s.v_domain(), crate::surface::VDomain::Periodic);
            let cols_f = if periodic { 2 * nv } else { 2 * nv + 1 };
            let g = mesh::sample(*s, rows_f, cols_f)?;
            if let Some(k) = g
                .positions
                .iter()
                .position(|p| p.iter().any(|x| !x.is_finite()))
            {
                let _ = k;
                return Err(Error::invalid(
                    "the surface is not finite somewhere on the shell mesh",
                ));
            }
            samples.push(g);
        }
        let grids: Vec<GridMesh> = samples
            .iter()
            .map(|g| GridMesh {
                nu: g.nu,
                nv: g.nv,
                periodic_v: g.periodic_v,
                u: g.u.clone(),
                v: g.v.clone(),
                positions: g.positions.iter().map(|p| p.map(|x| x as f32)).collect(),
                normals: g.normals.iter().map(|p| p.map(|x| x as f32)).collect(),
            })
            .collect();
        let welded = mesh::weld_mapped(&grids, names, WeldOptions { join_patches: true });

        // Welded vertex → node, numbered in order of first use by an element.
        let nw = welded.mesh.positions.len();
        let mut node_of = vec![u32::MAX; nw];
        let mut nodes = Vec::new();
        let mut normals = Vec::new();
        let mut params = Vec::new();
        let mut normal_sum = Vec::new();
        let mut elements = Vec::new();
        let mut element_patch = Vec::new();
        for (k, g) in samples.iter().enumerate() {
            let map = &welded.source[k];
            let (nuf, nvf) = (g.nu, g.nv);
            let at = |i: usize, j: usize| i * nvf + (j % nvf);
            let cols = if g.periodic_v { nvf / 2 } else { (nvf - 1) / 2 };
            let sign = if welded.flipped[k] { -1.0 } else { 1.0 };
            for ci in 0..(nuf - 1) / 2 {
                for cj in 0..cols {
                    let (i, j) = (2 * ci, 2 * cj);
                    // Grid indices of the cell's corners a, b, c, d and mid-side nodes.
                    let q = [
                        at(i, j),
                        at(i + 2, j),
                        at(i + 2, j + 2),
                        at(i, j + 2),
                        at(i + 1, j),
                        at(i + 2, j + 1),
                        at(i + 1, j + 2),
                        at(i, j + 1),
                    ];
                    let w = q.map(|x| map[x]);
                    let collapsed: Vec<usize> =
                        (0..4).filter(|&e| w[e] == w[(e + 1) % 4]).collect();
                    // Grid indices of the element's nodes in CalculiX order.
                    let grid_nodes: Vec<usize> = match collapsed.as_slice() {
                        [] => q.to_vec(),
                        [e] => {
                            // Drop corner e+1 (equal to corner e) and the collapsed side's mid.
                            let keep: Vec<usize> = (0..4).filter(|&c| c != (e + 1) % 4).collect();
                            let mids: Vec<usize> = keep
                                .iter()
                                .map(|&c| {
                                    let next =
                                        keep[(keep.iter().position(|&x| x == c).unwrap() + 1) % 3];
                                    // The mid of side c→next: side c when next is c+1, else the
                                    // side after the collapsed one.
                                    if next == (c + 1) % 4 {
                                        4 + c
                                    } else {
                                        4 + (c + 1) % 4
                                    }
                                })
                                .collect();
                            keep.iter().chain(&mids).map(|&x| q[x]).collect()
                        }
                        _ => continue,
                    };
                    let mut e: Vec<u32> = Vec::with_capacity(8);
                    for &gi in &grid_nodes {
                        let wi = map[gi];
                        let n = &mut node_of[wi as usize];
                        if *n == u32::MAX {
                            *n = nodes.len() as u32;
                            nodes.push(g.positions[gi]);
                            params.push((k, g.u[gi / nvf], g.v[gi % nvf]));
                            normal_sum.push([0.0f64; 3]);
                        }
                        let nn = g.normals[gi];
                        for c in 0..3 {
                            normal_sum[*n as usize][c] += sign * nn[c];
                        }
                        e.push(*n);
                    }
                    if welded.flipped[k] {
                        // Corners reversed after the first; mid-side nodes reversed.
                        let nc = e.len() / 2;
                        e[1..nc].reverse();
                        e[nc..].reverse();
                    }
                    elements.push(if e.len() == 8 {
                        Element::Quad(e.try_into().unwrap())
                    } else {
                        Element::Tri(e.try_into().unwrap())
                    });
                    element_patch.push(k);
                }
            }
        }
        for s in &normal_sum {
            let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
            normals.push(if len > 0.0 {
                s.map(|x| x / len)
            } else {
                [0.0; 3]
            });
        }
        if elements.is_empty() {
            return Err(Error::invalid(
                "the shell mesh has no element of positive size",
            ));
        }
        let mut rows = Vec::new();
        let mut periodic = Vec::new();
        let mut grids = Vec::new();
        for (k, g) in samples.iter().enumerate() {
            let map = &welded.source[k];
            grids.push(NodeGrid {
                u: g.u.clone(),
                v: g.v.clone(),
                periodic: g.periodic_v,
                node: map.iter().map(|&w| node_of[w as usize]).collect(),
            });
            let row = |i: usize| -> Vec<u32> {
                (0..g.nv)
                    .map(|j| node_of[map[i * g.nv + j] as usize])
                    .collect()
            };
            rows.push([row(0), row(g.nu - 1)]);
            periodic.push(g.periodic_v);
        }
        Ok(ShellMesh {
            nodes,
            normals,
            params,
            elements,
            element_patch,
            rows,
            periodic,
            grids,
        })
    }

    /// The nodal field `values` (one per node) at the point `(u, v)` of `patch`: the eight-node
    /// serendipity interpolation of the element grid cell holding it (the `S8R` shape
    /// functions), or the mean of the cell's nodes where some are missing (a cell collapsed at a
    /// pole). `NaN` for an unknown patch.
    pub fn interpolate(&self, values: &[f64], patch: usize, u: f64, v: f64) -> f64 {
        let Some(g) = self.grids.get(patch) else {
            return f64::NAN;
        };
        let nv = g.v.len();
        let (ci, xi) = cell_of(&g.u, u, None);
        let (cj, eta) = cell_of(&g.v, v, g.periodic.then_some(crate::TAU));
        // (row offset, column offset, ξ_i, η_i) of the eight nodes.
        const NODES: [(usize, usize, f64, f64); 8] = [
            (0, 0, -1.0, -1.0),
            (2, 0, 1.0, -1.0),
            (2, 2, 1.0, 1.0),
            (0, 2, -1.0, 1.0),
            (1, 0, 0.0, -1.0),
            (2, 1, 1.0, 0.0),
            (1, 2, 0.0, 1.0),
            (0, 1, -1.0, 0.0),
        ];
        let mut sum = 0.0;
        let (mut mean, mut count) = (0.0, 0usize);
        let mut complete = true;
        for (di, dj, a, b) in NODES {
            let (i, j) = (2 * ci + di, (2 * cj + dj) % nv);
            let n = g.node[i * nv + j];
            let Some(&f) = values.get(n as usize) else {
                complete = false;
                continue;
            };
            mean += f;
            count += 1;
            let shape = if a == 0.0 {
                0.5 * (1.0 - xi * xi) * (1.0 + eta * b)
            } else if b == 0.0 {
                0.5 * (1.0 + xi * a) * (1.0 - eta * eta)
            } else {
                0.25 * (1.0 + xi * a) * (1.0 + eta * b) * (xi * a + eta * b - 1.0)
            };
            sum += shape * f;
        }
        if complete {
            sum
        } else if count > 0 {
            mean / count as f64
        } else {
            f64::NAN
        }
    }

    /// Number of patches.
    pub fn patches(&self) -> usize {
        self.rows.len()
    }

    /// The distinct nodes of a patch's edge (a pole gives one node).
    pub fn edge_nodes(&self, patch: usize, side: Side) -> Vec<u32> {
        let row = &self.rows[patch][side as usize];
        let mut out: Vec<u32> = Vec::with_capacity(row.len());
        for &n in row {
            if n != u32::MAX && !out.contains(&n) {
                out.push(n);
            }
        }
        out
    }

    /// The quadratic segments `[corner, mid, corner]` along a patch's edge (none at a pole).
    pub fn edge_segments(&self, patch: usize, side: Side) -> Vec<[u32; 3]> {
        let row = &self.rows[patch][side as usize];
        let n = row.len();
        let count = if self.periodic[patch] {
            n / 2
        } else {
            (n - 1) / 2
        };
        (0..count)
            .map(|s| [row[2 * s], row[2 * s + 1], row[(2 * s + 2) % n]])
            .filter(|[a, _, c]| a != c && !row.is_empty())
            .filter(|seg| seg.iter().all(|&x| x != u32::MAX))
            .collect()
    }

    /// Total length of a patch's edge (3-point Gauss on each quadratic segment).
    pub fn edge_length(&self, patch: usize, side: Side) -> f64 {
        self.edge_segments(patch, side)
            .iter()
            .map(|s| segment_weights(&self.nodes, *s).iter().sum::<f64>())
            .sum()
    }
}

/// `∫ N_i |x'(ξ)| dξ` over a quadratic segment `[a, m, b]`, `ξ ∈ [−1, 1]`: the consistent nodal
/// shares of a unit line load (their sum is the segment's length).
pub(crate) fn segment_weights(nodes: &[[f64; 3]], s: [u32; 3]) -> [f64; 3] {
    let [a, m, b] = s.map(|i| nodes[i as usize]);
    let g = (0.6f64).sqrt();
    let pts = [(-g, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g, 5.0 / 9.0)];
    let mut w = [0.0; 3];
    for (xi, wt) in pts {
        // N_a = ξ(ξ−1)/2, N_m = 1−ξ², N_b = ξ(ξ+1)/2.
        let n = [xi * (xi - 1.0) / 2.0, 1.0 - xi * xi, xi * (xi + 1.0) / 2.0];
        let dn = [xi - 0.5, -2.0 * xi, xi + 0.5];
        let mut d = [0.0; 3];
        for c in 0..3 {
            d[c] = dn[0] * a[c] + dn[1] * m[c] + dn[2] * b[c];
        }
        let j = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        for i in 0..3 {
            w[i] += wt * n[i] * j;
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::UnitCylinder as Cylinder;

    #[test]
    fn interpolation_reproduces_the_serendipity_space() {
        let m = ShellMesh::new(&[&Cylinder], &["c"], 3, 8).unwrap();
        // A field in the span of the 8-node shape functions in every cell: quadratic in u,
        // times a function that is linear in v inside each cell is not periodic, so take v
        // within the first seven cells (the eighth wraps to v = 0) and u²v, uv² terms.
        let f =
            |u: f64, v: f64| 1.0 + 2.0 * u - 3.0 * u * u + 0.5 * v + 0.25 * u * v * v - u * u * v;
        let values: Vec<f64> = m.params.iter().map(|&(_, u, v)| f(u, v)).collect();
        let cell = crate::TAU / 8.0;
        for (u, v) in [
            (0.1, 0.2),
            (0.5, 1.0),
            (0.77, 3.3),
            (1.0, 7.0 * cell - 1e-9),
            (0.0, 0.0),
        ] {
            let got = m.interpolate(&values, 0, u, v);
            assert!(
                (got - f(u, v)).abs() < 1e-12,
                "({u}, {v}): {got} vs {}",
                f(u, v)
            );
        }
        // At the nodes the field itself, across the seam too.
        for (k, &(_, u, v)) in m.params.iter().enumerate() {
            assert!((m.interpolate(&values, 0, u, v) - values[k]).abs() < 1e-12);
        }
        // A periodic v: v + 2π is v.
        assert!((m.interpolate(&values, 0, 0.3, 0.4 + crate::TAU) - f(0.3, 0.4)).abs() < 1e-12);
        assert!(m.interpolate(&values, 1, 0.3, 0.4).is_nan());
    }
}
