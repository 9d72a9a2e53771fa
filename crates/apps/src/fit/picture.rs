//! The mesh and its fit side by side, each coloured by its distance to the other, the fit's
//! layout edges drawn over it.

use super::measure::{InnerLattice, PointDistances};
use super::mesh::InputMesh;
use crate::mesh::GridMesh;
use crate::render::{
    default_view, diverging_colors, encode_png, render_rgb_colored_with_bar, write_caption,
    BarLayout, ColorBar, Polyline, RenderOptions,
};
use crate::spec::DesignSpec;
use crate::{Result, Vec3};

/// A PNG picture: the mesh on the left (each vertex coloured by its distance to the fit), the
/// fitted surfaces on the right (each sample coloured by its distance to the mesh), on the
/// cool–warm scale from 0 (blue) through `scale / 2` (grey) to `scale` (the tolerance, in the
/// mesh's units) and beyond (red); captioned "mesh" and "fit", with the scale's colour bar
/// labelled in the mesh's units on the right; `edges` (in the mesh's coordinates, see
/// [`layout_edges`]) drawn over the fit as dark lines.
pub fn picture(
    mesh: &InputMesh,
    distances: &PointDistances,
    edges: &[Vec<Vec3>],
    scale: f64,
    options: &RenderOptions,
) -> Result<Vec<u8>> {
    let rgb = picture_rgb(mesh, distances, edges, scale, options)?;
    encode_png(options.width, options.height, &rgb)
}

/// The pixels of [`picture`] (`3 · width · height` bytes, sRGB).
fn picture_rgb(
    mesh: &InputMesh,
    distances: &PointDistances,
    edges: &[Vec<Vec3>],
    scale: f64,
    options: &RenderOptions,
) -> Result<Vec<u8>> {
    let view = options.view.unwrap_or_else(default_view).normalize();
    let up = options.up.normalize();
    // Screen right for an eye along `view` looking back at the object.
    let mut right = (-view).cross(&up);
    if right.norm() < 1e-9 {
        right = Vec3::x();
    }
    let right = right.normalize();
    let (lo, hi) = mesh.bounds();
    let width = (hi - lo).iter().cloned().fold(0.0, f64::max);
    let shift = right * (1.2 * width);
    let f = |p: Vec3| [p.x as f32, p.y as f32, p.z as f32];
    let scale = if scale > 0.0 && scale.is_finite() {
        scale
    } else {
        1.0
    };
    let mut meshes = Vec::with_capacity(mesh.triangles.len() + distances.grids.len());
    let mut colors = Vec::with_capacity(meshes.capacity());
    let lattices = distances.samples.lattices(mesh);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = mesh.corners(t);
        let n = (b - a).cross(&(c - a));
        let n = if n.norm() > 0.0 { n.normalize() } else { up };
        let corners = tri.map(|i| distances.mesh[i as usize]);
        let (side, nodes, d) = triangle_grid(
            [a, b, c],
            corners,
            lattices.get(t).copied(),
            &distances.inner,
        );
        let params: Vec<f64> = (0..side).map(|i| i as f64 / (side - 1) as f64).collect();
        meshes.push(GridMesh {
            nu: side,
            nv: side,
            periodic_v: false,
            u: params.clone(),
            v: params,
            normals: vec![f(n); d.len()],
            positions: nodes.into_iter().map(f).collect(),
        });
        colors.push(diverging_colors(&d, 0.0, scale));
    }
    for (g, d) in distances.grids.iter().zip(&distances.fit) {
        meshes.push(GridMesh {
            nu: g.nu,
            nv: g.nv,
            periodic_v: g.periodic_v,
            u: g.u.clone(),
            v: g.v.clone(),
            positions: g
                .positions
                .iter()
                .map(|p| f(Vec3::new(p[0], p[1], p[2]) + shift))
                .collect(),
            normals: g
                .normals
                .iter()
                .map(|n| [n[0] as f32, n[1] as f32, n[2] as f32])
                .collect(),
        });
        colors.push(diverging_colors(d, 0.0, scale));
    }
    let options = RenderOptions {
        view: Some(view),
        ..options.clone()
    };
    let bar = ColorBar {
        title: "distance".into(),
        lo: 0.0,
        hi: scale,
        note: "in the mesh's units; the top is the tolerance".into(),
    };
    let lines: Vec<Polyline> = edges
        .iter()
        .filter(|e| e.len() >= 2)
        .map(|e| Polyline {
            points: e.iter().map(|p| p + shift).collect(),
            color: [35, 35, 35],
            width: 1.5,
            closed: false,
        })
        .collect();
    let mut rgb = render_rgb_colored_with_bar(&meshes, &colors, &lines, &options, &bar)?;
    // The two objects share the picture's left part, the mesh on its left half.
    let layout = BarLayout::new(options.width, options.height);
    let half = layout.panel_x as i64 / 2;
    let top = (4 * layout.scale) as i64;
    for (centre, text) in [(half / 2, "mesh"), (half + half / 2, "fit and its layout")] {
        write_caption(&mut rgb, options.width, options.height, centre, top, text);
    }
    Ok(rgb)
}

/// A mesh triangle `a, b, c` as a square grid for the renderer, with the distance at each
/// node. A triangle whose inner points were measured (`lattice`, their distances in `inner`)
/// is drawn on their lattice: node `(i, j)` of the `(k + 1) × (k + 1)` grid is the inner point
/// `a + (b − a)·j/k + (c − a)·i/k`, coloured by its distance, so a miss inside a long triangle
/// shows where it is. The nodes on the triangle's sides (and past `b–c`, `i + j > k`) are
/// moved to the nearer corner of their side and take its distance (`corners`): the strips
/// along the sides become fans of the corners (quads with two nodes alike, flat ones past
/// `b–c`), so the triangle's sides have no nodes between its corners and meet the
/// neighbouring triangles without T-junctions (whose cracks let the far side show through).
/// Any other triangle is one quad `a, b, c, c`, coloured by its corners. Row `i` runs towards
/// `c` and column `j` towards `b`, so the grid faces the way the triangle does. Returns the
/// grid's side (at least 2), its nodes row by row, and the distances at them.
fn triangle_grid(
    [a, b, c]: [Vec3; 3],
    corners: [f64; 3],
    lattice: Option<InnerLattice>,
    inner: &[f64],
) -> (usize, Vec<Vec3>, Vec<f64>) {
    let measured = lattice.filter(|l| {
        l.k >= 3
            && l.index(l.k - 2, 1) < inner.len()
            && (1..l.k).all(|i| (1..l.k - i).all(|j| inner[l.index(i, j)].is_finite()))
    });
    let k = measured.map_or(1, |l| l.k);
    let n = k + 1;
    let at = |i: usize| i as f64 / k as f64;
    let mut nodes = Vec::with_capacity(n * n);
    let mut values = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            // The corner a side node goes to: along `a–b` by `j`, `a–c` by `i`, `b–c` by
            // the share of `i` in `i + j`.
            let corner = if i + j >= k {
                Some(if 2 * i < i + j { 1 } else { 2 })
            } else if i == 0 {
                Some(if 2 * j < k { 0 } else { 1 })
            } else if j == 0 {
                Some(if 2 * i < k { 0 } else { 2 })
            } else {
                None
            };
            if let (None, Some(l)) = (corner, measured) {
                nodes.push(a + (b - a) * at(j) + (c - a) * at(i));
                values.push(inner[l.index(j, i)]);
            } else {
                // Every node of the one-quad grid (`k = 1`) is a corner.
                let q = corner.unwrap_or(0);
                nodes.push([a, b, c][q]);
                values.push(corners[q]);
            }
        }
    }
    (n, nodes, values)
}

/// Segments per patchwork edge in [`layout_edges`].
const EDGE_SEGMENTS: usize = 24;

/// The edges of a fit's layout as polylines: every `[[patchwork]]` edge (its cubic Hermite
/// curve), and for the other patches the borders of their sample grids in `distances` (the
/// sections of a tube or a sheet, and a sheet's sides).
pub fn layout_edges(spec: &DesignSpec, distances: &PointDistances) -> Vec<Vec<Vec3>> {
    let mut out = Vec::new();
    let v3 = |p: [f64; 3]| Vec3::new(p[0], p[1], p[2]);
    for p in &spec.patchwork {
        for e in &p.edges {
            let (Some(&a), Some(&b)) = (p.points.get(e.ends[0]), p.points.get(e.ends[1])) else {
                continue;
            };
            let (a, b) = (v3(a), v3(b));
            let (d0, d1) = (v3(e.tangents[0]), v3(e.tangents[1]));
            out.push(
                (0..=EDGE_SEGMENTS)
                    .map(|k| super::layout::hermite(a, b, d0, d1, k as f64 / EDGE_SEGMENTS as f64))
                    .collect(),
            );
        }
    }
    if !spec.patchwork.is_empty() {
        return out;
    }
    for g in &distances.grids {
        let at = |i: usize, j: usize| v3(g.positions[i * g.nv + j]);
        if g.nu < 2 || g.nv < 2 {
            continue;
        }
        for i in [0, g.nu - 1] {
            let mut row: Vec<Vec3> = (0..g.nv).map(|j| at(i, j)).collect();
            if g.periodic_v {
                row.push(at(i, 0));
            }
            out.push(row);
        }
        if !g.periodic_v {
            for j in [0, g.nv - 1] {
                out.push((0..g.nu).map(|i| at(i, j)).collect());
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::measure::MeshSamples;
    use super::*;
    use crate::mesh::Samples;

    /// A unit square as a mesh of two triangles and as a 5 × 5 sample grid, at distance 0.
    fn square() -> (InputMesh, PointDistances) {
        let mesh = InputMesh::new(
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap();
        let n = 5;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / (n - 1) as f64).collect();
        let grid = Samples {
            nu: n,
            nv: n,
            periodic_v: false,
            u: t.clone(),
            v: t.clone(),
            positions: (0..n * n).map(|k| [t[k / n], t[k % n], 0.0]).collect(),
            normals: vec![[0.0, 0.0, 1.0]; n * n],
        };
        let d = PointDistances {
            mesh: vec![0.0; 4],
            samples: MeshSamples::default(),
            inner: Vec::new(),
            grids: vec![grid],
            fit: vec![vec![0.0; n * n]],
        };
        (mesh, d)
    }

    /// A miss inside a mesh triangle (at 25 of its inner points, its corners at distance
    /// 0) colours the mesh there: red pixels on the mesh's half of the picture, none when
    /// every point is at 0 (before, the triangles were coloured from their corners only).
    #[test]
    fn a_miss_inside_a_triangle_is_drawn_where_it_is() {
        let (mesh, mut d) = square();
        d.samples = MeshSamples::new(&mesh, 0.1);
        let lattices = d.samples.lattices(&mesh);
        assert_eq!(lattices[0].k, 15);
        d.inner = vec![0.0; d.samples.points.len()];
        let options = RenderOptions {
            width: 400,
            height: 200,
            view: Some(Vec3::new(0.0, 0.0, 1.0)),
            up: Vec3::new(0.0, 1.0, 0.0),
        };
        let half = BarLayout::new(options.width, options.height).panel_x / 2;
        let red = |rgb: &[u8]| {
            rgb.chunks(3)
                .enumerate()
                .filter(|(k, p)| {
                    (k % options.width as usize) < half && p[0] > 150 && p[1] < 90 && p[2] < 110
                })
                .count()
        };
        assert_eq!(red(&picture_rgb(&mesh, &d, &[], 1.0, &options).unwrap()), 0);
        let l = lattices[0];
        for i in 3..=7 {
            for j in 3..=7 {
                d.inner[l.index(i, j)] = 3.0;
            }
        }
        let drawn = red(&picture_rgb(&mesh, &d, &[], 1.0, &options).unwrap());
        assert!(drawn > 20, "{drawn}");
    }

    #[test]
    fn the_borders_of_a_grid_are_its_layout_and_are_drawn() {
        let (mesh, d) = square();
        let edges = layout_edges(&DesignSpec::default(), &d);
        // Two rows and two columns of 5 samples.
        assert_eq!(edges.len(), 4);
        assert!(edges.iter().all(|e| e.len() == 5));
        let options = RenderOptions {
            width: 400,
            height: 200,
            view: Some(Vec3::new(0.0, 0.0, 1.0)),
            up: Vec3::new(0.0, 1.0, 0.0),
        };
        let dark = |rgb: &[u8]| rgb.chunks(3).filter(|p| p.iter().all(|&c| c < 60)).count();
        let plain = picture_rgb(&mesh, &d, &[], 1.0, &options).unwrap();
        let drawn = picture_rgb(&mesh, &d, &edges, 1.0, &options).unwrap();
        // The lines add dark pixels (the captions and the bar's text are in both).
        assert!(
            dark(&drawn) > dark(&plain) + 100,
            "{} {}",
            dark(&drawn),
            dark(&plain)
        );
    }
}
