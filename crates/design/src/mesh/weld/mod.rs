//! The patches of a design as one welded, consistently oriented triangle mesh.
//!
//! A design's grids repeat points: a pole row collapses to one point, the seam of a surface that
//! closes on itself appears twice (the `[blend]` surface's first and last columns), and two
//! patches that share a position curve both carry its points. [`weld`] joins every such pair of
//! boundary vertices (rows `0` and `nu−1`, the end columns of a non-periodic grid, and any row
//! that collapsed to one point) that lie within `10⁻⁶` of the design's bounding-box diagonal of
//! each other, drops the triangles that welding left with two equal corners (the pole fans keep
//! one vertex per pole), and orients the result:
//!
//! * patches that share an edge are turned to agree along it (a patch is flipped as a whole);
//! * a closed group of patches (every edge shared by two triangles) is turned outward: its
//!   signed volume is positive;
//! * an open group that encloses a volume once its boundary is closed by a cone from the
//!   centroid of its boundary vertices (a cup, a glass: [`OPEN_VOLUME_FRACTION`]) is turned so
//!   that this capped volume is positive, the normals pointing away from the inside;
//! * any other open group (a sheet) keeps the side its first patch's normals `X_u × X_v` point
//!   to.
//!
//! Only boundary vertices are welded, so the interior of a self-intersecting surface (the Klein
//! bottle) is never stitched to itself. Vertex normals are the exact surface normals (the
//! normalised mean of the welded copies, after the flips), except where that mean vanishes or
//! points against the triangles around the vertex, where the mean of their facet normals is
//! taken; texture coordinates are dropped, since a welded vertex has several.

use super::{GridMesh, Part, TriMesh};
use rayon::prelude::*;

mod bounds;
mod frame;
mod hash;
mod join;
mod merge;
mod normals;
mod orient;
mod plan;
mod report;
mod topology;
pub(crate) use bounds::bounding_box;
pub use bounds::{box_union, BoundingBox, EMPTY_BOX};
pub use frame::FrameWeld;
use hash::CellHasher;
use join::{join, GridTopology, Joined};
use merge::candidate_rows;
pub use orient::facet_cross;
use orient::{flipped_of, turned};
pub use plan::{Plan, PlanPart};
#[cfg(test)]
pub(crate) use report::is_closed;
pub use report::{closed_given, edge_bits, report, MeshReport};
use topology::SharedSlice;
pub use topology::WeldTopology;
#[cfg(test)]
use {
    bounds::diagonal,
    merge::merge,
    orient::{signed_volume_of, Group, Parity},
    std::collections::HashMap,
};

/// Relative weld tolerance: a fraction of the bounding-box diagonal (far above `f32` rounding of
/// the same point, far below any grid spacing).
pub const WELD_TOLERANCE: f64 = 1e-6;

/// An open group of patches is turned to a positive capped volume only when that volume exceeds
/// this fraction of the cube of the bounding-box diagonal; below it the group is a sheet and
/// keeps the side of its first patch.
pub const OPEN_VOLUME_FRACTION: f64 = 1e-3;

/// How [`weld`] joins the patches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WeldOptions {
    /// Join patches that share an edge into one connected mesh (the default). When false, every
    /// patch is welded (poles, seams) and oriented on its own and shares no vertex with another.
    pub join_patches: bool,
}

impl Default for WeldOptions {
    fn default() -> Self {
        WeldOptions { join_patches: true }
    }
}

/// The grids of a design welded into one oriented [`TriMesh`] with one part per grid, named
/// `names[k]` (or `patch<k>` where `names` is short). See the module documentation.
pub fn weld(grids: &[GridMesh], names: &[&str], options: WeldOptions) -> TriMesh {
    weld_mapped(grids, names, options).mesh
}

/// A welded mesh with the way back to its grids.
#[derive(Clone, Debug, PartialEq)]
pub struct Welded {
    /// The mesh [`weld`] returns.
    pub mesh: TriMesh,
    /// `source[k][i]`: the welded vertex of vertex `i` of grid `k`.
    pub source: Vec<Vec<u32>>,
    /// True for the grids whose triangles were turned over (`X_v × X_u` orientation).
    pub flipped: Vec<bool>,
}

/// [`weld`], also returning each grid vertex's welded vertex and each grid's turn (for meshes
/// built on the same vertices with other elements, such as quadratic shell elements).
///
/// The mesh equals [`WeldTopology::new`]'s bit for bit, built without keeping a topology: the
/// groups' volumes are summed over each grid's triangles as its layout gives them (members in
/// parallel, each in the order of its triangles) while the triangles are written once, in
/// place, then turned where a grid is.
pub fn weld_mapped(grids: &[GridMesh], names: &[&str], options: WeldOptions) -> Welded {
    let Joined {
        diag,
        positions,
        source,
        rows,
        relative,
        groups,
        ..
    } = join(grids, options);
    let topo: Vec<GridTopology> = grids
        .iter()
        .zip(&source)
        .zip(&rows)
        .map(|((g, map), rows)| GridTopology::new(g, map, rows))
        .collect();
    // The kept triangles of every quad row, and of every grid.
    let counts: Vec<Vec<usize>> = topo.par_iter().map(GridTopology::kept_per_row).collect();
    let lens: Vec<usize> = counts.iter().map(|c| c.iter().sum()).collect();
    let total: usize = lens.iter().sum();
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(total);
    super::advise_huge_pages(triangles.spare_capacity_mut());
    let (turns, ()) = rayon::join(
        || {
            groups
                .par_iter()
                .map(|g| {
                    (
                        g.root,
                        g.turned_over_soon(&topo, &positions, &relative, diag),
                    )
                })
                .collect::<Vec<(usize, bool)>>()
        },
        || {
            let mut rest = &mut triangles.spare_capacity_mut()[..total];
            let mut jobs = Vec::with_capacity(topo.len());
            for ((t, c), &len) in topo.iter().zip(&counts).zip(&lens) {
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
                rest = tail;
                jobs.push((t, c, head));
            }
            jobs.into_par_iter()
                .for_each(|(t, c, dst)| t.triangles_into(c, dst));
        },
    );
    // SAFETY: the grids' slices tile the first `total` elements, each written in full by
    // `triangles_into`.
    unsafe { triangles.set_len(total) };
    let flipped = flipped_of(&relative, &turns);
    let names = part_names(grids.len(), names);
    let mut parts = Vec::with_capacity(grids.len());
    let mut rest = triangles.as_mut_slice();
    let mut start = 0;
    for (k, &len) in lens.iter().enumerate() {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
        rest = tail;
        if flipped[k] {
            head.par_chunks_mut(1 << 15)
                .for_each(|ts| ts.iter_mut().for_each(|t| t.swap(1, 2)));
        }
        parts.push(Part {
            name: names[k].clone(),
            triangles: start..start + len,
        });
        start += len;
    }
    let normals = normals::vertex_normals(grids, &source, &positions, &flipped);
    Welded {
        mesh: TriMesh {
            positions,
            normals,
            uv: Vec::new(),
            triangles,
            parts,
        },
        source,
        flipped,
    }
}

/// Part names: `names[k]`, or `patch<k>` where `names` is short.
fn part_names(grids: usize, names: &[&str]) -> Vec<String> {
    (0..grids)
        .map(|k| {
            names
                .get(k)
                .map(|s| s.to_string())
                .unwrap_or_else(|| format!("patch{k}"))
        })
        .collect()
}

#[cfg(test)]
mod tests;
