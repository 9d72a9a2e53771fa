//! How far a fitted design is from its mesh, and how much smaller it is.
//!
//! - **Fit to mesh.** Every patch is sampled on a `nu × nv` grid (exact surface points); each
//!   sample's distance to the mesh is its exact point-to-triangle distance, the nearest triangle
//!   found through an R-tree (`rstar`).
//! - **Mesh to fit.** Every vertex used by a triangle is taken to the nearest triangle of the
//!   same grids (an R-tree again), and from that triangle's `(u, v)` the closest point of the
//!   patch is found by Newton's method ([`ClosestPointIndex::refine`]): the distance to a point
//!   of the surface itself, not to its tessellation.
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
use crate::{Result, Vec3};
use rayon::prelude::*;
use rstar::{PointDistance, RTree, RTreeObject, AABB};

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
}

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
    /// From the mesh's vertices to the fitted surfaces.
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

/// Per-point distances, kept for pictures.
#[derive(Clone, Debug)]
pub struct PointDistances {
    /// Distance of each mesh vertex to the fit (`NaN` for vertices no triangle uses).
    pub mesh: Vec<f64>,
    /// The fitted surfaces' sample grids, one per surface.
    pub grids: Vec<Samples>,
    /// The distance of each sample to the mesh: `fit[k][i]` for vertex `i` of `grids[k]`.
    pub fit: Vec<Vec<f64>>,
}

impl PointDistances {
    /// The point, in the mesh's coordinates, farthest from the other surface (a mesh vertex
    /// or a sample of the fit), and its distance.
    pub fn worst(&self, mesh: &InputMesh) -> (Vec3, f64) {
        let mut best = (Vec3::zeros(), f64::NEG_INFINITY);
        for (p, &x) in mesh.positions.iter().zip(&self.mesh) {
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
/// `nu × nv` grid.
pub fn measure(
    mesh: &InputMesh,
    spec: &DesignSpec,
    solved: &SolvedDesign,
    nu: usize,
    nv: usize,
) -> Result<(Measures, PointDistances)> {
    measure_surfaces(mesh, spec, &solved.surfaces, (nu, nv), None)
}

/// [`measure`] of `surfaces`, the surfaces of `spec` as solved (in the design's order): a
/// design whose patchworks were solved one by one need not be solved again to be measured.
/// `sampled`, when given, is their `nu × nv` sample grids, already taken (by a measure of the
/// same surfaces against another mesh).
pub(crate) fn measure_surfaces(
    mesh: &InputMesh,
    spec: &DesignSpec,
    surfaces: &[DesignSurface],
    (nu, nv): (usize, usize),
    sampled: Option<Vec<Samples>>,
) -> Result<(Measures, PointDistances)> {
    let grids: Vec<Samples> = match sampled {
        Some(g) if g.len() == surfaces.len() => g,
        _ => surfaces
            .par_iter()
            .map(|s| mesh::sample(s.surface(), nu, nv))
            .collect::<Result<_>>()?,
    };
    // Fit to mesh.
    let index = MeshDistance::new(mesh);
    // In parallel over the grids (a fit has thousands of pieces of 100 samples each).
    let fit: Vec<Vec<f64>> = grids
        .par_iter()
        .map(|g| {
            g.positions
                .iter()
                .map(|p| {
                    index
                        .closest(Vec3::new(p[0], p[1], p[2]))
                        .map_or(f64::NAN, |c| c.0)
                })
                .collect()
        })
        .collect();
    // Mesh to fit: the grids' triangles, then Newton on the surface.
    let mut tris = Vec::new();
    for (k, g) in grids.iter().enumerate() {
        for t in g.triangles() {
            let corners = t.map(|i| {
                let p = g.positions[i as usize];
                Vec3::new(p[0], p[1], p[2])
            });
            tris.push((k, t, corners));
        }
    }
    let tree = RTree::bulk_load(
        tris.iter()
            .enumerate()
            .map(|(id, (_, _, corners))| Tri::new(*corners, id))
            .collect(),
    );
    // Only Newton runs from a grid triangle's `(u, v)` are asked of these indices
    // (`refine`), never a search over the surface, so their own sample grids are the
    // smallest allowed (the default 16 × 32 evaluations per patch were most of the time
    // of measuring a fit of hundreds of n-sided pieces).
    let opts = ClosestOptions {
        samples_u: 2,
        samples_v: 3,
        ..ClosestOptions::default()
    };
    let indices: Vec<ClosestPointIndex<'_, dyn crate::surface::Surface>> = surfaces
        .iter()
        .map(|s| ClosestPointIndex::new(s.surface(), &opts))
        .collect();
    let mut used = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    let mesh_d: Vec<f64> = mesh
        .positions
        .par_iter()
        .zip(used.par_iter())
        .map(|(p, &u)| {
            if !u {
                return f64::NAN;
            }
            let Some(t) = tree.nearest_neighbor(&[p.x, p.y, p.z]) else {
                return f64::NAN;
            };
            let (q, b, c) = closest_on_triangle(*p, &t.corners);
            let flat = (q - p).norm();
            let (k, idx, _) = &tris[t.id];
            let g = &grids[*k];
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
            // The refined point and the starting point lie on the surface: the nearer bounds
            // the true distance from above. (Newton from the start can leave for a farther
            // local minimum where `X_v` vanishes: at the folds `v = 0, π` of a sheet's even
            // curves, which it takes for poles.) Without either, the distance to the grid's
            // triangle stands in.
            let start = indices[*k].surface().point(u, v).metric_distance(p);
            let refined = indices[*k]
                .refine(*p, u, v)
                .map_or(f64::INFINITY, |r| r.distance);
            let best = refined.min(start);
            if best.is_finite() {
                best
            } else {
                flat
            }
        })
        .collect();
    let used_d: Vec<f64> = mesh_d.iter().cloned().filter(|d| !d.is_nan()).collect();
    let all_fit: Vec<f64> = fit.iter().flatten().cloned().collect();
    let mesh_to_fit = Distances::of(&used_d);
    let fit_to_mesh = Distances::of(&all_fit);
    let diagonal = mesh.diagonal();
    let hausdorff = mesh_to_fit.max.max(fit_to_mesh.max);
    let rms = (0.5 * (mesh_to_fit.rms.powi(2) + fit_to_mesh.rms.powi(2))).sqrt();
    let toml_bytes = write_design(spec)?.len();
    let design_numbers = count_numbers(spec);
    let mesh_bytes = mesh.binary_size();
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
        mesh_bytes,
        design_numbers,
        design_bytes: 8 * design_numbers,
        toml_bytes,
        ratio: mesh_bytes as f64 / (8 * design_numbers).max(1) as f64,
        toml_ratio: mesh_bytes as f64 / toml_bytes.max(1) as f64,
    };
    Ok((
        measures,
        PointDistances {
            mesh: mesh_d,
            grids,
            fit,
        },
    ))
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
}
