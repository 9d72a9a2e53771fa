//! How far a fitted design is from its mesh, and how much smaller it is.
//!
//! - **Where.** A fit is measured to a tolerance: both surfaces are measured densely enough
//!   that no point of either is much farther than its measured points say. The mesh at its
//!   vertices and, inside triangles longer than a quarter of the tolerance, on a grid of that
//!   spacing ([`MeshSamples`]: a fit can pass through every vertex of a mesh of long CAD
//!   triangles and stand off their faces); the fit on each patch's `nu × nv` grid, refined
//!   where neighbouring samples are more than half the tolerance apart ([`sample_within`]: a
//!   tube's patch spans the mesh). Every point of the mesh is then within `0.27 ×` the
//!   tolerance of a measured one, and every point of the fit within about `0.35 ×`: the
//!   distances being 1-Lipschitz, a measured Hausdorff distance `H` bounds the true one by
//!   `H + 0.35 × tolerance` (the figures are for the measured points, a lower bound).
//! - **Fit to mesh.** Each sample's distance to the mesh is its exact point-to-triangle
//!   distance, the nearest triangle found through an R-tree (`rstar`): a grid's first sample
//!   by a nearest-neighbour search, each next one among the triangles no farther than the
//!   last one's closest triangle.
//! - **Mesh to fit.** Every vertex used by a triangle, and every [`MeshSamples`] point, is
//!   taken to the nearest triangle of the same grids (an R-tree of tiles of the grids' quads,
//!   then the quads of the nearest tiles: a [`GridIndex`]), and from that triangle's `(u, v)`
//!   the closest point of the
//!   patch is found by Newton's method ([`ClosestPointIndex::refine`]): the distance to a point
//!   of the surface itself, not to its tessellation. Where pieces meet, their grids share the
//!   boundary's samples: every piece whose grid comes as near is refined, and the least
//!   distance kept (which piece a search met first decided it before).
//! - A design of several components' fits is measured from the components' own measures
//!   ([`measure_components`]): the other components are searched only near their boxes.
//! - The two-sided **Hausdorff** distance is the larger of the two maxima; the **RMS** distance
//!   is `√((rms₁² + rms₂²)/2)` of the two directions' root mean squares. Both are also given
//!   relative to the mesh's bounding-box diagonal.
//! - **Compression**: the mesh's binary size (`f32` vertices and `u32` triangle indices) over the
//!   design's compact size: every number of the design (curve coefficients, condition
//!   parameters, operator) as an 8-byte `f64`. The design file's size in bytes is given beside.

use super::mesh::InputMesh;
use crate::design::{DesignSurface, SolvedDesign};
use crate::mesh::{self, Samples};
use crate::spec::{write_design, DesignSpec};
use crate::surface::{ClosestOptions, ClosestPointIndex};
use crate::{Error, Result, Vec3};
use rayon::prelude::*;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{Envelope, PointDistance, RTree, RTreeObject, AABB};

/// A triangle in an R-tree, with what it came from.
#[derive(Clone, Debug)]
struct Tri {
    corners: [Vec3; 3],
    /// Index of the triangle (mesh) or `(patch, grid index of the first corner, …)`.
    id: usize,
    /// The corners' bounding box, kept: the tree's searches ask for it at every leaf they
    /// look at (recomputing it was a tenth of a fit's time).
    bounds: AABB<[f64; 3]>,
}

impl Tri {
    fn new(corners: [Vec3; 3], id: usize) -> Tri {
        let [a, b, c] = corners;
        let lo = a.inf(&b).inf(&c);
        let hi = a.sup(&b).sup(&c);
        Tri {
            corners,
            id,
            bounds: AABB::from_corners([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]),
        }
    }
}

impl RTreeObject for Tri {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        self.bounds
    }
}

impl PointDistance for Tri {
    fn distance_2(&self, p: &[f64; 3]) -> f64 {
        let p = Vec3::new(p[0], p[1], p[2]);
        (closest_on_triangle(p, &self.corners).0 - p).norm_squared()
    }
}

/// The closest point of triangle `[a, b, c]` to `p`, and its barycentric coordinates
/// `(β, γ)` (the point is `a + β(b − a) + γ(c − a)`): the Voronoi regions of the vertices, then
/// of the edges, then the face.
pub(crate) fn closest_on_triangle(p: Vec3, t: &[Vec3; 3]) -> (Vec3, f64, f64) {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(&ap), ac.dot(&ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, 0.0, 0.0);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(&bp), ac.dot(&bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, 1.0, 0.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let w = d1 / (d1 - d3);
        return (a + ab * w, w, 0.0);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(&cp), ac.dot(&cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, 0.0, 1.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + ac * w, 0.0, w);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, 1.0 - w, w);
    }
    let denom = va + vb + vc;
    if denom.abs() < 1e-300 {
        // A degenerate (zero-area) triangle: the nearest of its corners.
        let best = [a, b, c]
            .into_iter()
            .enumerate()
            .min_by(|x, y| (x.1 - p).norm().total_cmp(&(y.1 - p).norm()))
            .map_or((a, 0.0, 0.0), |(k, q)| match k {
                0 => (q, 0.0, 0.0),
                1 => (q, 1.0, 0.0),
                _ => (q, 0.0, 1.0),
            });
        return best;
    }
    let (v, w) = (vb / denom, vc / denom);
    (a + ab * v + ac * w, v, w)
}

/// Exact point-to-mesh distances through an R-tree of the mesh's triangles.
pub struct MeshDistance {
    tree: RTree<Tri>,
}

impl MeshDistance {
    /// Indexes every triangle of `mesh`.
    pub fn new(mesh: &InputMesh) -> Self {
        let tris = (0..mesh.triangles.len())
            .map(|t| Tri::new(mesh.corners(t), t))
            .collect();
        MeshDistance {
            tree: RTree::bulk_load(tris),
        }
    }

    /// The distance from `p` to the mesh, the closest point and its triangle.
    pub fn closest(&self, p: Vec3) -> Option<(f64, Vec3, usize)> {
        let t = self.tree.nearest_neighbor(&[p.x, p.y, p.z])?;
        let (q, _, _) = closest_on_triangle(p, &t.corners);
        Some(((q - p).norm(), q, t.id))
    }

    /// [`Self::closest`] given a triangle `near` (its corners) to start from: the distance to
    /// it bounds the search ([`Self::closest_within`]) to the box of that half-width about
    /// `p`, which holds the closest point (for points along a sampled surface, the last
    /// point's triangle is a close bound, and the box search needs no heap).
    pub fn closest_from(&self, p: Vec3, near: &[Vec3; 3]) -> Option<(f64, Vec3, usize)> {
        let (q, _, _) = closest_on_triangle(p, near);
        let r = (q - p).norm() * (1.0 + 1e-12);
        if !r.is_finite() {
            return self.closest(p);
        }
        self.closest_within(p, r).or_else(|| self.closest(p))
    }

    /// The closest point of the mesh to `p` if it is no farther than `reach`. The triangles whose
    /// boxes meet the box of half-width `reach` about `p` hold it; they are few when `reach`
    /// is short (a point of one component asking another that it nears only here and
    /// there), and the nearest-neighbour search takes over when they are not.
    pub fn closest_within(&self, p: Vec3, reach: f64) -> Option<(f64, Vec3, usize)> {
        const FEW: usize = 32;
        if !reach.is_finite() {
            return self.closest(p);
        }
        let r = reach;
        let bounds = AABB::from_corners([p.x - r, p.y - r, p.z - r], [p.x + r, p.y + r, p.z + r]);
        let mut best: Option<(f64, Vec3, usize)> = None;
        for (k, t) in self
            .tree
            .locate_in_envelope_intersecting(&bounds)
            .enumerate()
        {
            if k == FEW {
                return self.closest(p).filter(|c| c.0 <= reach);
            }
            let (q, _, _) = closest_on_triangle(p, &t.corners);
            let d = (q - p).norm();
            if best.is_none_or(|b| d < b.0) {
                best = Some((d, q, t.id));
            }
        }
        best.filter(|c| c.0 <= reach)
    }
}

/// The closest triangle of a set of sample grids (their [`Samples::triangles`]) to a point:
/// the grids by their boxes' distance, nearest first, and in each grid the quads whose box is
/// nearer than the best triangle so far. A fit's grids hold millions of triangles and are
/// asked for only as many points as the mesh has vertices: indexing the grids, not their
/// triangles, keeps the index as small as the fit's pieces.
pub(crate) struct GridIndex<'a> {
    grids: &'a [Samples],
    /// The grids' tiles of at most [`TILE`] × [`TILE`] quads: their bounding boxes (a
    /// box's distance a lower bound of the distance to any of its triangles) and their
    /// indices in `tiles`.
    tree: RTree<GeomWithData<Rectangle<[f64; 3]>, usize>>,
    tiles: Vec<Tile>,
}

/// Quads of a grid: rows `rows` and columns `cols` of grid `grid`'s [`Samples::quads`].
#[derive(Clone, Debug)]
struct Tile {
    grid: usize,
    rows: std::ops::Range<usize>,
    cols: std::ops::Range<usize>,
}

/// The side of a [`GridIndex`]'s tiles, in quads: a large grid (a tube's patch spans the
/// mesh) is searched a few tiles at a time, not quad by quad.
const TILE: usize = 2;

/// The closest grid triangle to a point: its grid, its corners' indices in the grid, the
/// point's barycentric coordinates `(β, γ)` in it and its distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct GridPoint {
    pub grid: usize,
    pub corners: [u32; 3],
    pub beta: f64,
    pub gamma: f64,
    pub distance: f64,
}

impl<'a> GridIndex<'a> {
    pub(crate) fn new(grids: &'a [Samples]) -> GridIndex<'a> {
        let mut tiles = Vec::new();
        for (grid, g) in grids.iter().enumerate() {
            let (rows, cols) = quad_shape(g);
            for i in (0..rows).step_by(TILE) {
                for j in (0..cols).step_by(TILE) {
                    tiles.push(Tile {
                        grid,
                        rows: i..(i + TILE).min(rows),
                        cols: j..(j + TILE).min(cols),
                    });
                }
            }
        }
        let boxes = tiles
            .iter()
            .enumerate()
            .map(|(k, t)| {
                let g = &grids[t.grid];
                let corners = (t.rows.start..=t.rows.end).flat_map(|i| {
                    (t.cols.start..=t.cols.end).map(move |j| g.positions[i * g.nv + j % g.nv])
                });
                let bounds = AABB::from_points(corners.collect::<Vec<_>>().iter());
                GeomWithData::new(Rectangle::from_aabb(bounds), k)
            })
            .collect();
        GridIndex {
            grids,
            tree: RTree::bulk_load(boxes),
            tiles,
        }
    }

    /// The closest triangle of each grid that comes within [`TIE`] of the closest of all,
    /// nearest first (none without grids, or where no distance is finite): where pieces
    /// meet, their grids share the boundary's samples, and a point whose nearest grid point
    /// lies there is as near to either piece (which one a search meets first is an accident
    /// of its order).
    pub(crate) fn nearest_per_grid(&self, p: Vec3) -> Vec<GridPoint> {
        let at = [p.x, p.y, p.z];
        let reach = |best: Option<f64>| best.map_or(f64::INFINITY, |d| d * (1.0 + TIE));
        let mut best: Option<f64> = None;
        // Each grid's closest triangle so far.
        let mut found: Vec<GridPoint> = Vec::new();
        for (b, d2) in self.tree.nearest_neighbor_iter_with_distance_2(&at) {
            let r = reach(best);
            if d2 > r * r {
                break;
            }
            let tile = &self.tiles[b.data];
            let g = &self.grids[tile.grid];
            let slot = found.iter().position(|x| x.grid == tile.grid);
            let mut own: Option<GridPoint> = slot.map(|k| found[k]);
            let nv = g.nv;
            for i in tile.rows.clone() {
                for j in tile.cols.clone() {
                    let j1 = (j + 1) % nv;
                    let q = [i * nv + j, (i + 1) * nv + j, (i + 1) * nv + j1, i * nv + j1]
                        .map(|k| k as u32);
                    let corners = q.map(|i| g.positions[i as usize]);
                    let quad = AABB::from_points(corners.iter());
                    let r = reach(best).min(own.map_or(f64::INFINITY, |x| x.distance));
                    if quad.distance_2(&at) > r * r {
                        continue;
                    }
                    let [a, b1, c, d] = q;
                    for t in [[a, b1, c], [a, c, d]] {
                        let tri = t.map(|i| Vec3::from(g.positions[i as usize]));
                        let (x, beta, gamma) = closest_on_triangle(p, &tri);
                        let distance = (x - p).norm();
                        if distance.is_finite() && own.is_none_or(|y| distance < y.distance) {
                            own = Some(GridPoint {
                                grid: tile.grid,
                                corners: t,
                                beta,
                                gamma,
                                distance,
                            });
                        }
                    }
                }
            }
            if let Some(x) = own {
                if best.is_none_or(|d| x.distance < d) {
                    best = Some(x.distance);
                }
                match slot {
                    Some(k) => found[k] = x,
                    None => found.push(x),
                }
            }
        }
        let r = reach(best);
        found.retain(|x| x.distance <= r);
        found.sort_by(|a, b| a.distance.total_cmp(&b.distance).then(a.grid.cmp(&b.grid)));
        found
    }
}

/// The rows and columns of a grid's [`Samples::quads`].
fn quad_shape(g: &Samples) -> (usize, usize) {
    let cols = if g.periodic_v {
        g.nv
    } else {
        g.nv.saturating_sub(1)
    };
    (g.nu.saturating_sub(1), cols)
}

/// Grid triangles within this fraction of the nearest one's distance are as near
/// ([`GridIndex::nearest_per_grid`]).
const TIE: f64 = 1e-9;

/// Largest and root-mean-square distance over a set of points.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Distances {
    /// Number of points measured.
    pub points: usize,
    /// Largest distance (0 for no points).
    pub max: f64,
    /// Root-mean-square distance.
    pub rms: f64,
}

impl Distances {
    /// The largest and root-mean-square of `d`.
    pub(crate) fn of(d: &[f64]) -> Self {
        let n = d.len().max(1) as f64;
        Distances {
            points: d.len(),
            max: d.iter().cloned().fold(0.0, f64::max),
            rms: (d.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
        }
    }
}

/// The measures of a fit (module documentation).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Measures {
    /// The diagonal of the mesh's bounding box.
    pub diagonal: f64,
    /// From the mesh to the fitted surfaces: the root mean square and count over its
    /// vertices, the largest over them and the [`MeshSamples`] of its long triangles.
    pub mesh_to_fit: Distances,
    /// From samples of the fitted surfaces to the mesh.
    pub fit_to_mesh: Distances,
    /// Two-sided Hausdorff distance: the larger of the two directions' maxima.
    pub hausdorff: f64,
    /// `√((rms₁² + rms₂²)/2)` of the two directions' root-mean-square distances.
    pub rms: f64,
    /// `hausdorff / diagonal`.
    pub hausdorff_relative: f64,
    /// `rms / diagonal`.
    pub rms_relative: f64,
    /// Triangles of the mesh.
    pub mesh_triangles: usize,
    /// Vertices of the mesh (used by a triangle or not).
    pub mesh_vertices: usize,
    /// `12·V + 12·T` bytes.
    pub mesh_bytes: usize,
    /// Numbers in the design.
    pub design_numbers: usize,
    /// `8 × design_numbers`.
    pub design_bytes: usize,
    /// Bytes of the design file as written.
    pub toml_bytes: usize,
    /// `mesh_bytes / design_bytes`.
    pub ratio: f64,
    /// `mesh_bytes / toml_bytes`.
    pub toml_ratio: f64,
}

impl Measures {
    /// The measures with the sizes of the design `spec` (its numbers, its TOML's bytes and
    /// their ratios to the mesh's), which the searches leave at 0: writing a large design's
    /// TOML costs as much as a tenth of measuring it, and a fit's rounds need only the
    /// distances of all but the round they report.
    pub(crate) fn sized(self, spec: &DesignSpec) -> Result<Measures> {
        Ok(self.with_sizes(design_sizes(spec)?))
    }

    /// [`Measures::sized`] given [`design_sizes`].
    pub(crate) fn with_sizes(mut self, (toml_bytes, numbers): (usize, usize)) -> Measures {
        self.design_numbers = numbers;
        self.design_bytes = 8 * self.design_numbers;
        self.ratio = self.mesh_bytes as f64 / self.design_bytes.max(1) as f64;
        self.with_toml_bytes(toml_bytes)
    }

    /// The measures with the TOML's size as it is written (`bytes`: the design with what the
    /// writer adds, such as its title), and its ratio to the mesh's.
    pub fn with_toml_bytes(mut self, bytes: usize) -> Measures {
        self.toml_bytes = bytes;
        self.toml_ratio = self.mesh_bytes as f64 / bytes.max(1) as f64;
        self
    }

    /// What `pdeshape fit` prints of a fit (after the mesh's name): the verdict first (whether
    /// the Hausdorff distance is within `tolerance`, a fraction of the diagonal), then the
    /// distances as percentages of the diagonal and in the mesh's units, the patches, and the
    /// sizes (with the packed size of [`super::pack`]); numbers with
    /// [`crate::number::DIGITS`] significant digits.
    pub fn summary(&self, fitted: &super::Fit, tolerance: f64) -> String {
        use crate::number::{sig, DIGITS};
        let n = |x: f64| sig(x, DIGITS);
        let mode = fitted.mode.name();
        let verdict = if self.hausdorff_relative <= tolerance {
            "within"
        } else {
            "beyond"
        };
        format!(
            "Hausdorff {}% of the diagonal ({verdict} the tolerance {}%), RMS {}%; \
             {} triangles → {} patches ({mode} mode, {} modes, a = {}); {} bytes → {} bytes of \
             coefficients (ratio {}), {} bytes of TOML (ratio {}), {}",
            n(100.0 * self.hausdorff_relative),
            n(100.0 * tolerance),
            n(100.0 * self.rms_relative),
            self.mesh_triangles,
            fitted.patches,
            fitted.modes,
            n(fitted.a),
            self.mesh_bytes,
            self.design_bytes,
            n(self.ratio),
            self.toml_bytes,
            n(self.toml_ratio),
            super::pack(&fitted.spec, self.diagonal, tolerance).map_or_else(
                |e| format!("no packed size ({})", e.message()),
                |p| format!("{} bytes packed ({})", p.bytes, p.describe())
            )
        )
    }
}

/// Points inside a mesh's long triangles, measured to a fit beside its vertices: a fit can
/// pass near every vertex of a mesh of long thin triangles (a CAD mesh, a coarse cylinder)
/// and still stand off its faces between them.
///
/// Every edge longer than the spacing `h` gets `⌈L/h⌉ − 1` points evenly along it, and every
/// triangle whose longest edge `L` exceeds `h` the interior points `a + (i/k)(b − a) +
/// (j/k)(c − a)` (`i, j ≥ 1`, `i + j < k`) of its `k = ⌈L/h⌉` subdivision. With the
/// vertices, every point of the mesh is within `1.08 h` of a measured point: within `h/√3` of
/// a point of its triangle's subdivision (the covering radius of a triangle whose sides are at
/// most `h`), which is measured, a vertex, or on an edge within `h/2` of the edge's points.
/// The distance to the fit being 1-Lipschitz, the largest measured distance is at most `1.08 h`
/// short of the largest over the whole mesh. A mesh of short triangles has none.
#[derive(Clone, Debug, Default)]
pub struct MeshSamples {
    /// The points.
    pub points: Vec<Vec3>,
    /// The triangle each point is on (an edge's points: the edge's first triangle); empty in
    /// a measure composed of components' ([`measure_components`]), whose points are then
    /// all measured when passed to [`measure`] again.
    pub triangles: Vec<u32>,
    /// The spacing `h` used (after [`MeshSamples::MAX_POINTS`]).
    pub spacing: f64,
}

impl MeshSamples {
    /// The most points taken: a mesh whose long triangles would need more at the spacing asked
    /// gets a spacing as much larger as makes this many (about a third of a second to
    /// measure on two cores, each round of a fit).
    pub const MAX_POINTS: usize = 60_000;

    /// The spacing as a share of the tolerance: a fit measured within the tolerance is within
    /// `1.27 ×` it everywhere on the mesh.
    pub const TOLERANCE_SHARE: f64 = 0.25;

    /// The points of `mesh` for a fit to `tolerance` (a fraction of its diagonal): spacing
    /// [`Self::TOLERANCE_SHARE`] of the tolerance.
    pub fn for_tolerance(mesh: &InputMesh, tolerance: f64) -> MeshSamples {
        MeshSamples::new(mesh, Self::TOLERANCE_SHARE * tolerance * mesh.diagonal())
    }

    /// The points of `mesh` at spacing `spacing` (a length; none for a spacing that is not a
    /// positive number), at most [`Self::MAX_POINTS`].
    pub fn new(mesh: &InputMesh, spacing: f64) -> MeshSamples {
        if !(spacing > 0.0 && spacing.is_finite()) {
            return MeshSamples::default();
        }
        let mut edges: Vec<(u32, u32)> = mesh
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |j| (t[j].min(t[(j + 1) % 3]), t[j].max(t[(j + 1) % 3]))))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let length =
            |(a, b): (u32, u32)| (mesh.positions[a as usize] - mesh.positions[b as usize]).norm();
        // The count at spacing `h`, and a larger spacing until it is within the bound.
        let count = |h: f64| -> usize {
            let inner: usize = (0..mesh.triangles.len())
                .map(|t| InnerLattice::count(divisions(longest_side(mesh, t), h)))
                .sum();
            let along: usize = edges
                .iter()
                .map(|&e| divisions(length(e), h).saturating_sub(1))
                .sum();
            inner + along
        };
        let mut h = spacing;
        loop {
            let n = count(h);
            if n <= Self::MAX_POINTS {
                break;
            }
            h *= (n as f64 / Self::MAX_POINTS as f64).sqrt() * 1.01;
        }
        let mut samples = MeshSamples {
            spacing: h,
            ..MeshSamples::default()
        };
        let mut first = std::collections::HashMap::with_capacity(edges.len());
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for j in 0..3 {
                let (a, b) = (tri[j], tri[(j + 1) % 3]);
                first.entry((a.min(b), a.max(b))).or_insert(t as u32);
            }
        }
        for (a, b) in edges {
            let t = first[&(a, b)];
            let k = divisions(length((a, b)), h);
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            for i in 1..k {
                samples.points.push(pa + (pb - pa) * (i as f64 / k as f64));
                samples.triangles.push(t);
            }
        }
        for t in 0..mesh.triangles.len() {
            let k = divisions(longest_side(mesh, t), h);
            let [a, b, c] = mesh.corners(t);
            for i in 1..k {
                for j in 1..k - i {
                    let (x, y) = (i as f64 / k as f64, j as f64 / k as f64);
                    samples.points.push(a + (b - a) * x + (c - a) * y);
                    samples.triangles.push(t as u32);
                }
            }
        }
        samples
    }
}

/// The pieces a length is cut into at spacing `h` (each at most `h` long).
fn divisions(length: f64, h: f64) -> usize {
    (length / h).ceil().min(1e6) as usize
}

/// Where a triangle's inner points are among [`MeshSamples`]' points: its sides divided in
/// `k`, the points `a + (b − a)·i/k + (c − a)·j/k` (`a, b, c` its corners) for `i, j ≥ 1`,
/// `i + j < k`, by `i` then `j`, from index `start`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InnerLattice {
    /// The divisions of the triangle's sides.
    pub k: usize,
    /// The index of its first inner point.
    pub start: usize,
}

impl InnerLattice {
    /// The index of the inner point `(i, j)` (`i, j ≥ 1`, `i + j < k`).
    pub fn index(&self, i: usize, j: usize) -> usize {
        self.start + (i - 1) * (self.k - 1) - (i - 1) * i / 2 + (j - 1)
    }

    /// The number of inner points.
    fn count(k: usize) -> usize {
        (k.saturating_sub(1) * k.saturating_sub(2)) / 2
    }
}

impl MeshSamples {
    /// Each triangle's [`InnerLattice`] (the edges' points come first, then the triangles'
    /// inner points in the triangles' order); empty for samples composed of components'
    /// (without their triangles) or not of `mesh`.
    pub fn lattices(&self, mesh: &InputMesh) -> Vec<InnerLattice> {
        if self.triangles.len() != self.points.len() || self.spacing.is_nan() || self.spacing <= 0.0
        {
            return Vec::new();
        }
        let ks: Vec<usize> = (0..mesh.triangles.len())
            .map(|t| divisions(longest_side(mesh, t), self.spacing))
            .collect();
        let inner: usize = ks.iter().map(|&k| InnerLattice::count(k)).sum();
        let Some(mut start) = self.points.len().checked_sub(inner) else {
            return Vec::new();
        };
        ks.into_iter()
            .map(|k| {
                let l = InnerLattice { k, start };
                start += InnerLattice::count(k);
                l
            })
            .collect()
    }
}

/// The longest side of triangle `t` of `mesh`.
fn longest_side(mesh: &InputMesh, t: usize) -> f64 {
    let [a, b, c] = mesh.corners(t);
    (b - a).norm().max((c - b).norm()).max((a - c).norm())
}

/// Per-point distances, kept for pictures.
#[derive(Clone, Debug)]
pub struct PointDistances {
    /// Distance of each mesh vertex to the fit (`NaN` for vertices no triangle uses).
    pub mesh: Vec<f64>,
    /// The points measured inside the mesh's long triangles.
    pub samples: MeshSamples,
    /// The distance of each of `samples`' points to the fit; `NaN` for one not measured, on a
    /// triangle that cannot reach the Hausdorff distance (see [`measure_surfaces`]).
    pub inner: Vec<f64>,
    /// The fitted surfaces' sample grids, one per surface.
    pub grids: Vec<Samples>,
    /// The distance of each sample to the mesh: `fit[k][i]` for vertex `i` of `grids[k]`.
    pub fit: Vec<Vec<f64>>,
}

impl PointDistances {
    /// The point, in the mesh's coordinates, farthest from the other surface (a point of the
    /// mesh or a sample of the fit), and its distance.
    pub fn worst(&self, mesh: &InputMesh) -> (Vec3, f64) {
        let mut best = (Vec3::zeros(), f64::NEG_INFINITY);
        let points = mesh.positions.iter().zip(&self.mesh);
        for (p, &x) in points.chain(self.samples.points.iter().zip(&self.inner)) {
            if x > best.1 {
                best = (*p, x);
            }
        }
        for (g, dist) in self.grids.iter().zip(&self.fit) {
            for (p, &x) in g.positions.iter().zip(dist) {
                if x > best.1 {
                    best = (Vec3::new(p[0], p[1], p[2]), x);
                }
            }
        }
        best
    }
}

/// Measures `solved` (the design `spec`, solved) against `mesh`, sampling each surface on an
/// `nu × nv` grid and the mesh at its vertices and at `samples`.
pub fn measure(
    mesh: &InputMesh,
    spec: &DesignSpec,
    solved: &SolvedDesign,
    (nu, nv): (usize, usize),
    samples: &MeshSamples,
) -> Result<(Measures, PointDistances)> {
    let index = MeshDistance::new(mesh);
    let (m, d) = measure_surfaces(mesh, &index, samples, &solved.surfaces, (nu, nv))?;
    Ok((m.sized(spec)?, d))
}

/// [`measure`] of `surfaces`, the surfaces of a design as solved (in the design's order): a
/// design whose patchworks were solved one by one need not be solved again to be measured.
/// The design's sizes are left to [`Measures::sized`]; `index` is `mesh`'s (a fit's rounds
/// measure against the same mesh).
pub(crate) fn measure_surfaces(
    mesh: &InputMesh,
    index: &MeshDistance,
    samples: &MeshSamples,
    surfaces: &[DesignSurface],
    (nu, nv): (usize, usize),
) -> Result<(Measures, PointDistances)> {
    let grids = sample_within(surfaces, (nu, nv), FIT_SPACING * samples.spacing)?;
    // Fit to mesh, in parallel over the grids (a fit has thousands of pieces of 100 samples
    // each), beside the index of the fit for the mesh's vertices.
    let fit_to_mesh = || -> Vec<Vec<f64>> {
        grids
            .par_iter()
            .map(|g| {
                let mut near: Option<[Vec3; 3]> = None;
                g.positions
                    .iter()
                    .map(|p| {
                        let p = Vec3::from(*p);
                        let found = match &near {
                            Some(t) => index.closest_from(p, t),
                            None => index.closest(p),
                        };
                        if let Some((_, _, t)) = found {
                            near = Some(mesh.corners(t));
                        }
                        found.map_or(f64::NAN, |c| c.0)
                    })
                    .collect()
            })
            .collect()
    };
    let (fit, to_fit) = rayon::join(fit_to_mesh, || ToFit::new(surfaces, &grids));
    let used = mesh.used_vertices();
    let mesh_d: Vec<f64> = mesh
        .positions
        .par_iter()
        .zip(used.par_iter())
        .map(|(p, &u)| if u { to_fit.distance(*p) } else { f64::NAN })
        .collect();
    // A triangle whose corners' distances plus its reach (any of its points is within
    // `L/√3` of a corner, `L` its longest side) stay within the largest distance of a vertex
    // cannot raise the mesh's largest distance: its samples are left unmeasured. On a fine
    // mesh of a smooth shape that is nearly every triangle.
    let lower = mesh_d
        .iter()
        .filter(|x| x.is_finite())
        .fold(0.0, |a: f64, &x| a.max(x));
    let open: Vec<bool> = mesh
        .triangles
        .par_iter()
        .enumerate()
        .map(|(t, tri)| {
            let corner = tri
                .iter()
                .map(|&i| mesh_d[i as usize])
                .fold(0.0, |a: f64, x| {
                    if x.is_finite() {
                        a.max(x)
                    } else {
                        f64::INFINITY
                    }
                });
            corner + longest_side(mesh, t) / 3f64.sqrt() > lower
        })
        .collect();
    let inner: Vec<f64> = samples
        .points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let t = samples.triangles.get(i).map_or(usize::MAX, |&t| t as usize);
            if open.get(t).copied().unwrap_or(true) {
                to_fit.distance(*p)
            } else {
                f64::NAN
            }
        })
        .collect();
    Ok(summarise(
        mesh,
        mesh_d,
        (samples.clone(), inner),
        grids,
        fit,
    ))
}

/// The samples of `surfaces` on `nu × nv` grids, each refined where neighbouring samples are
/// farther apart than `spacing` (a length; a surface spanning much of the mesh, such as a
/// tube's patch, bulges between coarse samples unseen): each direction by the ratio of its
/// longest step to the spacing, at most [`MAX_REFINE`] times, and the spacing as much larger
/// as keeps each refined grid within [`MAX_SURFACE_SAMPLES`] samples (or its coarse count,
/// when that is more).
fn sample_within(
    surfaces: &[DesignSurface],
    (nu, nv): (usize, usize),
    spacing: f64,
) -> Result<Vec<Samples>> {
    let coarse: Vec<Samples> = surfaces
        .par_iter()
        .map(|s| mesh::sample(s.surface(), nu, nv))
        .collect::<Result<_>>()?;
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Ok(coarse);
    }
    let steps: Vec<(f64, f64)> = coarse.par_iter().map(longest_steps).collect();
    // The refined grid's intervals in each direction (a periodic `v` has as many as
    // samples), and its sample count.
    let shape = |g: &Samples, (along_u, along_v): (f64, f64), h: f64| -> (usize, usize) {
        let finer = |intervals: usize, step: f64| -> usize {
            if step.is_finite() {
                let ratio = (step / h).clamp(1.0, MAX_REFINE as f64);
                (intervals as f64 * ratio).ceil() as usize
            } else {
                intervals
            }
        };
        let iv = if g.periodic_v { g.nv } else { g.nv - 1 };
        let (fu, fv) = (finer(g.nu - 1, along_u), finer(iv, along_v));
        (fu + 1, if g.periodic_v { fv } else { fv + 1 })
    };
    coarse
        .into_par_iter()
        .zip(steps.par_iter())
        .zip(surfaces.par_iter())
        .map(|((g, &s), surface)| {
            // Each surface on its own (a design's measure and its components' agree).
            let bound = MAX_SURFACE_SAMPLES.max(g.positions.len());
            let mut h = spacing;
            let mut shape_at = shape(&g, s, h);
            while shape_at.0 * shape_at.1 > bound {
                h *= (shape_at.0 as f64 * shape_at.1 as f64 / bound as f64).sqrt() * 1.01;
                shape_at = shape(&g, s, h);
            }
            if shape_at == (g.nu, g.nv) {
                Ok(g)
            } else {
                mesh::sample(surface.surface(), shape_at.0, shape_at.1)
            }
        })
        .collect()
}

/// The longest step between neighbouring samples of `g` along `u` and along `v` (across
/// the seam of a periodic `v`).
fn longest_steps(g: &Samples) -> (f64, f64) {
    let at = |i: usize, j: usize| Vec3::from(g.positions[i * g.nv + j]);
    let (mut along_u, mut along_v) = (0.0f64, 0.0f64);
    for i in 0..g.nu {
        for j in 0..g.nv {
            if i + 1 < g.nu {
                along_u = along_u.max((at(i + 1, j) - at(i, j)).norm());
            }
            if j + 1 < g.nv || g.periodic_v {
                along_v = along_v.max((at(i, (j + 1) % g.nv) - at(i, j)).norm());
            }
        }
    }
    (along_u, along_v)
}

/// The most samples [`sample_within`] refines one surface's grid to (a tube's patch from
/// 48 × 96 to about 2 × 2 times as many; a general fit's 10 × 10 pieces are never refined
/// that far).
const MAX_SURFACE_SAMPLES: usize = 16_384;

/// A fit's samples may be this many times the mesh's spacing apart ([`sample_within`]):
/// a point of the fit is within about `1/√2` of that of a sample (a grid cell's
/// half-diagonal), `0.35 ×` the tolerance at [`MeshSamples::TOLERANCE_SHARE`], where the
/// mesh's own points are within `0.27 ×` of it (a surface evaluation costs as much as a
/// mesh point's search, and a fit has more samples than the mesh has points).
const FIT_SPACING: f64 = 2.0;

/// The most a surface's measuring grid is refined in each direction ([`sample_within`]).
const MAX_REFINE: usize = 8;

/// Distances from points to a fit's surfaces: the closest triangle of their sample grids (a
/// [`GridIndex`]), then Newton on that triangle's surface from its `(u, v)`.
struct ToFit<'a> {
    grids: &'a [Samples],
    pieces: GridIndex<'a>,
    indices: Vec<ClosestPointIndex<'a, dyn crate::surface::Surface + 'a>>,
}

impl<'a> ToFit<'a> {
    /// `grids[k]` samples `surfaces[k]`.
    fn new(surfaces: &'a [DesignSurface], grids: &'a [Samples]) -> ToFit<'a> {
        // Only Newton runs from a grid triangle's `(u, v)` are asked of these indices
        // (`refine`), never a search over the surface, so their own sample grids are the
        // smallest allowed (the default 16 × 32 evaluations per patch were most of the time
        // of measuring a fit of hundreds of n-sided pieces).
        let opts = ClosestOptions {
            samples_u: 2,
            samples_v: 3,
            ..ClosestOptions::default()
        };
        ToFit {
            grids,
            pieces: GridIndex::new(grids),
            indices: surfaces
                .par_iter()
                .map(|s| ClosestPointIndex::new(s.surface(), &opts))
                .collect(),
        }
    }

    /// The distance from `p` to the fit (`NaN` without grids or a finite distance): the
    /// least over the pieces whose grids come nearest ([`GridIndex::nearest_per_grid`]).
    fn distance(&self, p: Vec3) -> f64 {
        self.pieces
            .nearest_per_grid(p)
            .iter()
            .map(|near| self.refine(p, near))
            .fold(f64::NAN, f64::min)
    }

    /// The distance from `p` to the piece of `near`, by Newton from `near`'s `(u, v)`.
    fn refine(&self, p: Vec3, near: &GridPoint) -> f64 {
        let (k, idx, b, c) = (near.grid, near.corners, near.beta, near.gamma);
        let flat = near.distance;
        let g = &self.grids[k];
        let uv = |i: u32| {
            let i = i as usize;
            (g.u[i / g.nv], g.v[i % g.nv])
        };
        let (u0, v0) = uv(idx[0]);
        let (u1, mut v1) = uv(idx[1]);
        let (u2, mut v2) = uv(idx[2]);
        // Unwrap the periodic seam.
        if g.periodic_v {
            let period = crate::TAU;
            for v in [&mut v1, &mut v2] {
                if *v - v0 > 0.5 * period {
                    *v -= period;
                } else if v0 - *v > 0.5 * period {
                    *v += period;
                }
            }
        }
        let u = u0 + b * (u1 - u0) + c * (u2 - u0);
        let v = v0 + b * (v1 - v0) + c * (v2 - v0);
        // The refined point and the starting point lie on the surface: the nearer bounds the
        // true distance from above. (Newton from the start can leave for a farther local
        // minimum where `X_v` vanishes: at the folds `v = 0, π` of a sheet's even curves,
        // which it takes for poles.) Without either, the distance to the grid's triangle
        // stands in.
        let start = self.indices[k].surface().point(u, v).metric_distance(&p);
        let refined = self.indices[k]
            .refine(p, u, v)
            .map_or(f64::INFINITY, |r| r.distance);
        let best = refined.min(start);
        if best.is_finite() {
            best
        } else {
            flat
        }
    }
}

/// The measures of a fit from its points' distances, with them: `mesh_d` of the mesh's
/// vertices (`NaN` for those no triangle uses), `inner` of its samples, `fit` of the samples
/// of `grids`; the design's sizes are left to [`Measures::sized`].
fn summarise(
    mesh: &InputMesh,
    mesh_d: Vec<f64>,
    (samples, inner): (MeshSamples, Vec<f64>),
    grids: Vec<Samples>,
    fit: Vec<Vec<f64>>,
) -> (Measures, PointDistances) {
    let used_d: Vec<f64> = mesh_d.iter().cloned().filter(|d| !d.is_nan()).collect();
    let all_fit: Vec<f64> = fit.iter().flatten().cloned().collect();
    // The samples inside triangles are measured only where they may exceed the vertices
    // (a biased few): they count towards the largest distance, not the mean.
    let inner_max = inner
        .iter()
        .filter(|x| x.is_finite())
        .fold(0.0, |a: f64, &x| a.max(x));
    let mut mesh_to_fit = Distances::of(&used_d);
    mesh_to_fit.max = mesh_to_fit.max.max(inner_max);
    let fit_to_mesh = Distances::of(&all_fit);
    let diagonal = mesh.diagonal();
    let hausdorff = mesh_to_fit.max.max(fit_to_mesh.max);
    let rms = (0.5 * (mesh_to_fit.rms.powi(2) + fit_to_mesh.rms.powi(2))).sqrt();
    let measures = Measures {
        diagonal,
        mesh_to_fit,
        fit_to_mesh,
        hausdorff,
        rms,
        hausdorff_relative: hausdorff / diagonal,
        rms_relative: rms / diagonal,
        mesh_triangles: mesh.triangles.len(),
        mesh_vertices: mesh.positions.len(),
        mesh_bytes: mesh.binary_size(),
        design_numbers: 0,
        design_bytes: 0,
        toml_bytes: 0,
        ratio: 0.0,
        toml_ratio: 0.0,
    };
    let distances = PointDistances {
        mesh: mesh_d,
        samples,
        inner,
        grids,
        fit,
    };
    (measures, distances)
}

/// A component of a mesh and its fit as measured against that component alone, for
/// [`measure_components`].
pub(crate) struct PartMeasure<'a> {
    /// The component.
    pub mesh: &'a InputMesh,
    /// The whole mesh's index of each of the component's vertices.
    pub vertices: &'a [u32],
    /// The component's surfaces among the design's and their measure against the component
    /// ([`measure_surfaces`]'s, its grids those of the surfaces); `None` for a component left
    /// out of the design.
    pub fitted: Option<(std::ops::Range<usize>, PointDistances)>,
}

/// [`measure_surfaces`] of a design made of components' fits, against the whole mesh, from
/// the components' own measures (`parts`: every component of the mesh). A point's distance
/// to the whole is the least of its distance to its own component and to the others, and
/// the others are searched only where they come within the own distance: a sample whose ball
/// of that radius meets another component's bounding box is searched in that component too,
/// and a mesh vertex whose ball meets the box of another component's grids is measured on
/// the whole fit. The samples' distances are those a measure of the whole finds; so are the
/// vertices', but where another component's piece would bulge out of its grid's box to
/// within the own distance (the whole's search would then run Newton on it too), where the
/// own distance, the distance to a point of the fit, stands. Only the few points near two
/// components cost more than their own measures did.
pub(crate) fn measure_components(
    mesh: &InputMesh,
    surfaces: &[DesignSurface],
    parts: Vec<PartMeasure<'_>>,
    spacing: f64,
) -> Result<(Measures, PointDistances)> {
    let mut owner: Vec<Option<(usize, usize)>> = vec![None; mesh.positions.len()];
    for (k, part) in parts.iter().enumerate() {
        for (l, &i) in part.vertices.iter().enumerate() {
            if let Some(o) = owner.get_mut(i as usize) {
                *o = Some((k, l));
            }
        }
    }
    let boxes: Vec<Option<AABB<[f64; 3]>>> = parts
        .iter()
        .map(|part| {
            let (lo, hi) = part.mesh.bounds();
            (!part.mesh.triangles.is_empty()).then(|| AABB::from_corners(lo.into(), hi.into()))
        })
        .collect();
    // A component's index is built when a point first comes within its box.
    let meshes: Vec<&InputMesh> = parts.iter().map(|p| p.mesh).collect();
    let indices: Vec<std::sync::OnceLock<MeshDistance>> =
        meshes.iter().map(|_| std::sync::OnceLock::new()).collect();
    // The design's grids and their samples' own distances, in the design's order.
    let mut grids: Vec<Samples> = Vec::with_capacity(surfaces.len());
    let mut fit: Vec<Vec<f64>> = Vec::with_capacity(surfaces.len());
    let mut grid_owner: Vec<usize> = Vec::with_capacity(surfaces.len());
    let mut own: Vec<Option<(std::ops::Range<usize>, Vec<f64>)>> = Vec::with_capacity(parts.len());
    // The components' samples, each with its component and own distance.
    let mut samples = MeshSamples {
        spacing,
        ..MeshSamples::default()
    };
    let mut sample_own: Vec<(usize, f64)> = Vec::new();
    for (k, part) in parts.into_iter().enumerate() {
        let Some((range, mut d)) = part.fitted else {
            // Measured on the whole fit, as its vertices are.
            let mut left_out = MeshSamples::new(part.mesh, spacing);
            sample_own.extend(left_out.points.iter().map(|_| (k, f64::INFINITY)));
            samples.points.append(&mut left_out.points);
            own.push(None);
            continue;
        };
        if range.start != grids.len() || range.len() != d.grids.len() {
            return Err(Error::invalid(
                "the components' surfaces are not in the design's order",
            ));
        }
        grid_owner.extend(std::iter::repeat_n(k, d.grids.len()));
        grids.append(&mut d.grids);
        fit.append(&mut d.fit);
        own.push(Some((range, d.mesh)));
        samples.points.append(&mut d.samples.points);
        samples.spacing = samples.spacing.max(d.samples.spacing);
        sample_own.extend(d.inner.iter().map(|&x| (k, x)));
    }
    if grids.len() != surfaces.len() {
        return Err(Error::invalid(
            "the components' surfaces are not the design's",
        ));
    }
    // Fit to mesh.
    fit.par_iter_mut()
        .zip(grids.par_iter())
        .zip(grid_owner.par_iter())
        .for_each(|((dist, g), &k)| {
            for (x, p) in dist.iter_mut().zip(&g.positions) {
                let reach = if x.is_finite() { *x } else { f64::INFINITY };
                for (j, (b, index)) in boxes.iter().zip(&indices).enumerate() {
                    let near = b.is_some_and(|b| b.distance_2(p) <= reach * reach);
                    if j != k && near {
                        let index = index.get_or_init(|| MeshDistance::new(meshes[j]));
                        if let Some((d, _, _)) = index.closest_within(Vec3::from(*p), reach) {
                            if x.is_nan() || d < *x {
                                *x = d;
                            }
                        }
                    }
                }
            }
        });
    // Mesh to fit.
    let grid_boxes: Vec<Option<AABB<[f64; 3]>>> = own
        .iter()
        .map(|o| {
            o.as_ref().and_then(|(range, _)| {
                grids[range.clone()]
                    .iter()
                    .filter(|g| !g.positions.is_empty())
                    .map(|g| AABB::from_points(&g.positions))
                    .reduce(|a, b| a.merged(&b))
            })
        })
        .collect();
    let used = mesh.used_vertices();
    // A point's own distance `d` to its component `k`'s fit, where no other component's
    // grids come within it.
    let clear_of_others = |p: &Vec3, k: usize, d: f64| -> Option<f64> {
        let at = [p.x, p.y, p.z];
        let clear = grid_boxes
            .iter()
            .enumerate()
            .all(|(j, b)| j == k || b.is_none_or(|b| b.distance_2(&at) > d * d));
        (d.is_finite() && clear).then_some(d)
    };
    let own_distance = |p: &Vec3, o: &Option<(usize, usize)>| -> Option<f64> {
        let (k, l) = (*o)?;
        clear_of_others(p, k, own[k].as_ref()?.1[l])
    };
    let mesh_d: Vec<Option<f64>> = mesh
        .positions
        .par_iter()
        .zip(used.par_iter())
        .zip(owner.par_iter())
        .map(|((p, &u), o)| {
            if u {
                own_distance(p, o)
            } else {
                Some(f64::NAN)
            }
        })
        .collect();
    let inner: Vec<Option<f64>> = samples
        .points
        .par_iter()
        .zip(sample_own.par_iter())
        .map(|(p, &(k, d))| {
            // One its component's measure left unmeasured stays so (the whole's distance is
            // no larger than the component's own); a left-out component's are measured.
            if d.is_nan() {
                Some(f64::NAN)
            } else {
                clear_of_others(p, k, d)
            }
        })
        .collect();
    let to_fit =
        (mesh_d.iter().chain(&inner).any(Option::is_none)).then(|| ToFit::new(surfaces, &grids));
    let whole = |points: &[Vec3], own: &[Option<f64>]| -> Vec<f64> {
        points
            .par_iter()
            .zip(own.par_iter())
            .map(|(p, d)| match (d, &to_fit) {
                (Some(d), _) => *d,
                (None, Some(t)) => t.distance(*p),
                (None, None) => f64::NAN,
            })
            .collect()
    };
    let mesh_d = whole(&mesh.positions, &mesh_d);
    let inner = whole(&samples.points, &inner);
    Ok(summarise(mesh, mesh_d, (samples, inner), grids, fit))
}

/// The bytes of the design's TOML and the count of its numbers.
pub(crate) fn design_sizes(spec: &DesignSpec) -> Result<(usize, usize)> {
    Ok((write_design(spec)?.len(), count_numbers(spec)))
}

/// Every number of a design (its JSON form).
pub(crate) fn count_numbers(spec: &DesignSpec) -> usize {
    fn count(v: &serde_json::Value) -> usize {
        match v {
            serde_json::Value::Number(_) => 1,
            serde_json::Value::Array(a) => a.iter().map(count).sum(),
            serde_json::Value::Object(o) => o.values().map(count).sum(),
            _ => 0,
        }
    }
    serde_json::to_value(spec).map_or(0, |v| count(&v))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Every point of a mesh of long and short triangles is within `1.08 h` of a vertex or a
    /// sample (random points against every measured one); no triangle shorter than `h` has
    /// samples; a spacing too fine for [`MeshSamples::MAX_POINTS`] is widened.
    #[test]
    fn mesh_samples_come_within_their_stated_reach_of_every_point() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        // A strip of long thin triangles, a fan about an obtuse corner and small ones.
        let mut positions: Vec<Vec3> = Vec::new();
        let mut triangles: Vec<[u32; 3]> = Vec::new();
        for k in 0..6 {
            let x = k as f64 * 0.4;
            positions.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 0.2, 3.0, 0.3 * x)]);
        }
        for k in 0..5u32 {
            let (a, b, c, d) = (2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3);
            triangles.extend([[a, c, b], [b, c, d]]);
        }
        let o = positions.len() as u32;
        positions.extend([
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(-2.0, -1.1, 0.5),
            Vec3::new(2.0, -1.1, -0.5),
            Vec3::new(0.0, -1.05, 0.01),
            Vec3::new(0.01, -1.04, 0.0),
        ]);
        triangles.extend([[o, o + 1, o + 2], [o, o + 3, o + 4]]);
        let mesh = InputMesh::new(positions, triangles).unwrap();
        for h in [0.5, 0.1, 0.05] {
            let samples = MeshSamples::new(&mesh, h);
            assert_eq!(samples.spacing, h);
            let measured: Vec<Vec3> = mesh
                .positions
                .iter()
                .chain(&samples.points)
                .cloned()
                .collect();
            // Each triangle's inner points are where its lattice says.
            let lattices = samples.lattices(&mesh);
            assert_eq!(lattices.len(), mesh.triangles.len());
            let mut inner = 0;
            for (t, l) in lattices.iter().enumerate() {
                let [a, b, c] = mesh.corners(t);
                for i in 1..l.k {
                    for j in 1..l.k - i {
                        let (x, y) = (i as f64 / l.k as f64, j as f64 / l.k as f64);
                        let q = a + (b - a) * x + (c - a) * y;
                        assert!((samples.points[l.index(i, j)] - q).norm() < 1e-15);
                        assert_eq!(samples.triangles[l.index(i, j)], t as u32);
                        inner += 1;
                    }
                }
            }
            assert_eq!(lattices[0].start + inner, samples.points.len());
            // Every sample lies on the mesh.
            let index = MeshDistance::new(&mesh);
            for p in &samples.points {
                assert!(index.closest(*p).unwrap().0 < 1e-12);
            }
            for _ in 0..3000 {
                let t = rng.gen_range(0..mesh.triangles.len());
                let (mut x, mut y): (f64, f64) = (rng.gen(), rng.gen());
                if x + y > 1.0 {
                    (x, y) = (1.0 - x, 1.0 - y);
                }
                let [a, b, c] = mesh.corners(t);
                let p = a + (b - a) * x + (c - a) * y;
                let near = measured
                    .iter()
                    .map(|q| (q - p).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(near <= 1.08 * h, "{h}: {near} at {p:?}");
            }
        }
        // The small triangle (sides under 0.06) has none at h = 0.1.
        let small_only = InputMesh::new(mesh.positions.clone(), vec![[12, 15, 16]]).unwrap();
        assert!(MeshSamples::new(&small_only, 0.1).points.is_empty());
        // Too fine a spacing is widened to the bound.
        let fine = MeshSamples::new(&mesh, 1e-4);
        assert!(fine.points.len() <= MeshSamples::MAX_POINTS && fine.spacing > 1e-4);
        assert!(fine.points.len() > MeshSamples::MAX_POINTS / 2);
        assert!(MeshSamples::new(&mesh, 0.0).points.is_empty());
        assert!(MeshSamples::new(&mesh, f64::NAN).points.is_empty());
    }

    #[test]
    fn closest_point_on_a_triangle_agrees_with_dense_sampling() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut r = || Vec3::new(rng.gen(), rng.gen(), rng.gen()) * 2.0 - Vec3::repeat(1.0);
        for _ in 0..200 {
            let t = [r(), r(), r()];
            let p = r() * 1.5;
            let (q, b, c) = closest_on_triangle(p, &t);
            assert!(b >= -1e-12 && c >= -1e-12 && b + c <= 1.0 + 1e-12);
            assert!((t[0] + (t[1] - t[0]) * b + (t[2] - t[0]) * c - q).norm() < 1e-12);
            // No sample of the triangle is closer (up to the sampling's resolution only in the
            // other direction: the exact answer is never beaten).
            let d = (q - p).norm();
            let n = 60;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
                    let s = t[0] + (t[1] - t[0]) * x + (t[2] - t[0]) * y;
                    assert!((s - p).norm() >= d - 1e-12);
                }
            }
        }
    }

    /// Wavy grids, some wrapping in `v`, at random places and sizes.
    fn wavy_grids(rng: &mut rand_chacha::ChaCha8Rng) -> Vec<Samples> {
        (0..12)
            .map(|k| {
                let (nu, nv) = (rng.gen_range(2..9), rng.gen_range(3..9));
                let periodic_v = k % 3 == 0;
                let c = Vec3::new(rng.gen(), rng.gen(), rng.gen()) * 4.0;
                let r: f64 = rng.gen_range(0.2..1.0);
                let positions = (0..nu * nv)
                    .map(|i| {
                        let (a, b) = ((i / nv) as f64, (i % nv) as f64);
                        let t = crate::TAU * b / nv as f64;
                        let bump: f64 = rng.gen_range(-0.05..0.05);
                        let p = c + Vec3::new(r * t.cos(), r * t.sin(), 0.3 * a) * (1.0 + bump);
                        [p.x, p.y, p.z]
                    })
                    .collect();
                Samples {
                    nu,
                    nv,
                    periodic_v,
                    u: (0..nu).map(|i| i as f64).collect(),
                    v: (0..nv).map(|j| j as f64).collect(),
                    positions,
                    normals: vec![[0.0; 3]; nu * nv],
                }
            })
            .collect()
    }

    #[test]
    fn the_grid_index_finds_the_closest_grid_triangle() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let grids = wavy_grids(&mut rng);
        let index = GridIndex::new(&grids);
        for _ in 0..400 {
            let p = Vec3::new(rng.gen(), rng.gen(), rng.gen()) * 6.0 - Vec3::repeat(1.0);
            // Every triangle of every grid, by brute force.
            let mut want = f64::INFINITY;
            for g in &grids {
                for t in g.triangles() {
                    let tri = t.map(|i| Vec3::from(g.positions[i as usize]));
                    want = want.min((closest_on_triangle(p, &tri).0 - p).norm());
                }
            }
            let found = index.nearest_per_grid(p);
            let got = found[0];
            // Every other grid found is as near, to the tie's margin.
            assert!(found.iter().all(|x| x.distance <= want * (1.0 + TIE)));
            assert_eq!(got.distance, want, "at {p:?}");
            // The answer names its triangle and the point in it.
            let g = &grids[got.grid];
            assert!(g.triangles().any(|t| t == got.corners));
            let [a, b, c] = got.corners.map(|i| Vec3::from(g.positions[i as usize]));
            let q = a + (b - a) * got.beta + (c - a) * got.gamma;
            assert!(((q - p).norm() - want).abs() <= 1e-12 * (1.0 + want));
        }
        assert!(GridIndex::new(&[])
            .nearest_per_grid(Vec3::zeros())
            .is_empty());
    }

    /// Two pieces meeting along `x = 1` at a fold (the second rises at half a slope): a point
    /// whose nearest grid point is on the shared edge gets both grids, the first no farther
    /// than the second, each with its own nearest triangle; a point over one piece's middle,
    /// or near the edge but nearer one piece, gets that piece only.
    #[test]
    fn pieces_meeting_at_the_nearest_point_are_both_found() {
        let grid = |x0: f64, slope: f64| {
            let (nu, nv) = (5, 4);
            Samples {
                nu,
                nv,
                periodic_v: false,
                u: (0..nu).map(|i| i as f64 / 4.0).collect(),
                v: (0..nv).map(|j| j as f64 / 3.0).collect(),
                positions: (0..nu * nv)
                    .map(|i| {
                        let (x, y) = ((i / nv) as f64 / 4.0, (i % nv) as f64 / 3.0);
                        [x0 + x, y, slope * x]
                    })
                    .collect(),
                normals: vec![[0.0; 3]; nu * nv],
            }
        };
        // The first runs from x = 0 to 1, the second from 1 to 2: the edge's samples are the
        // same points.
        let grids = [grid(0.0, 0.0), grid(1.0, 0.5)];
        let index = GridIndex::new(&grids);
        let on_edge = index.nearest_per_grid(Vec3::new(1.2, 0.5, -0.5));
        assert_eq!(on_edge.iter().map(|x| x.grid).collect::<Vec<_>>(), [0, 1]);
        let want = (0.2f64 * 0.2 + 0.5 * 0.5).sqrt();
        for x in &on_edge {
            assert!((x.distance - want).abs() < 1e-15, "{x:?}");
        }
        let middle = index.nearest_per_grid(Vec3::new(0.5, 0.5, 1.0));
        assert_eq!(middle.iter().map(|x| x.grid).collect::<Vec<_>>(), [0]);
        let beside = index.nearest_per_grid(Vec3::new(1.001, 0.5, 0.3));
        assert_eq!(beside.iter().map(|x| x.grid).collect::<Vec<_>>(), [1]);
    }

    #[test]
    fn a_search_from_any_triangle_finds_the_closest() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        // A crumpled sheet of 2 × 20 × 20 triangles.
        let n = 21;
        let positions: Vec<Vec3> = (0..n * n)
            .map(|i| {
                let (x, y) = ((i / n) as f64 / 20.0, (i % n) as f64 / 20.0);
                Vec3::new(
                    x,
                    y,
                    0.2 * (7.0 * x).sin() * (5.0 * y).cos() + rng.gen_range(0.0..0.01),
                )
            })
            .collect();
        let mut triangles = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                let k = (i * n + j) as u32;
                triangles.push([k, k + n as u32, k + n as u32 + 1]);
                triangles.push([k, k + n as u32 + 1, k + 1]);
            }
        }
        let mesh = InputMesh::new(positions, triangles).unwrap();
        let index = MeshDistance::new(&mesh);
        for _ in 0..500 {
            let p = Vec3::new(rng.gen(), rng.gen(), rng.gen()) * 1.4 - Vec3::repeat(0.2);
            let want = index.closest(p).unwrap();
            // From a near triangle, a far one and the closest itself.
            let brute = (0..mesh.triangles.len())
                .map(|t| (closest_on_triangle(p, &mesh.corners(t)).0 - p).norm())
                .fold(f64::INFINITY, f64::min);
            assert_eq!(want.0, brute);
            for seed in [rng.gen_range(0..mesh.triangles.len()), 0, want.2] {
                let got = index.closest_from(p, &mesh.corners(seed)).unwrap();
                assert_eq!(got.0, want.0, "at {p:?} from triangle {seed}");
            }
            // Within a reach: the closest when it is nearer, nothing otherwise, from a box
            // of a few triangles or (a long reach) of more than the box search takes.
            for reach in [want.0 * 0.999, want.0 * 1.001, want.0 + 0.3, f64::INFINITY] {
                let got = index.closest_within(p, reach).map(|c| c.0);
                let expect = (want.0 <= reach).then_some(want.0);
                assert_eq!(got, expect, "at {p:?} within {reach}");
            }
        }
    }
}
