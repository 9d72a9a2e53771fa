//! `WeldTopology`: what a weld found that depends only on which vertices joined, and the welding
//! of later grids of the same shapes on it (animation frames).

use super::bounds::diagonal;
use super::join::{join, GridTopology, Joined};
use super::merge::merge;
use super::orient::{signed_volume_about, Group};
use super::{part_names, WeldOptions, Welded};
use crate::mesh::{GridMesh, Part, TriMesh};
use rayon::prelude::*;
use std::collections::HashMap;

/// What welding a set of grids found that depends only on which vertices it joined: the
/// welded triangles of every grid, which grids meet along which edges (their relative
/// orientation), which groups of grids are closed and the rims of the open ones. Grids whose
/// vertices join alike (an animation's frames) are welded again with [`WeldTopology::weld`]
/// without building the edge maps again; the result equals [`weld_mapped`]'s bit for bit.
#[derive(Clone, Debug, PartialEq)]
pub struct WeldTopology {
    pub(super) options: WeldOptions,
    pub(super) names: Vec<String>,
    /// The grids' shapes `(nu, nv)`.
    pub(super) shapes: Vec<(usize, usize)>,
    pub(super) source: Vec<Vec<u32>>,
    pub(super) vertices: usize,
    /// Per grid, its triangles re-indexed (before any turn), without the collapsed ones.
    pub(super) tris: Vec<Vec<[u32; 3]>>,
    /// Per grid, its group's root and its orientation relative to it.
    pub(super) relative: Vec<(usize, bool)>,
    /// The groups whose orientation is decided by a volume, in the order weld visits them.
    pub(super) groups: Vec<Group>,
}

impl WeldTopology {
    /// Welds `grids` (as [`weld_mapped`]) and keeps what the welding found.
    pub fn new(grids: &[GridMesh], names: &[&str], options: WeldOptions) -> (Self, Welded) {
        let Joined {
            diag,
            positions,
            source,
            rows,
            relative,
            groups,
            ..
        } = join(grids, options);
        // Triangles per patch, re-indexed, without the ones welding collapsed.
        let tris: Vec<Vec<[u32; 3]>> = grids
            .iter()
            .zip(&source)
            .zip(&rows)
            .map(|((g, map), rows)| GridTopology::new(g, map, rows).triangles())
            .collect();
        let topology = WeldTopology {
            options,
            names: part_names(grids.len(), names),
            shapes: grids.iter().map(|g| (g.nu, g.nv)).collect(),
            vertices: positions.len(),
            source,
            tris,
            relative,
            groups,
        };
        let welded = topology.finish(grids, positions, diag);
        (topology, welded)
    }

    /// Welds grids of the same shapes as the first; `None` when their vertices join otherwise
    /// (a curve became a point, two patches met or parted), where [`weld_mapped`] must be
    /// called again. The result equals `weld_mapped(grids, …)` bit for bit.
    pub fn weld(&self, grids: &[GridMesh]) -> Option<Welded> {
        // The first frame's vertex map, checked rather than rebuilt (see `weld_frame`);
        // where the check fails, the merge decides.
        if let Some(w) = self.weld_gathered(grids) {
            return Some(w);
        }
        let same_shapes = grids.len() == self.shapes.len()
            && grids
                .iter()
                .zip(&self.shapes)
                .all(|(g, &(nu, nv))| g.nu == nu && g.nv == nv && g.positions.len() == nu * nv);
        if !same_shapes {
            return None;
        }
        let diag = diagonal(grids);
        let (positions, source) = merge(grids, self.options, diag);
        if source != self.source || positions.len() != self.vertices {
            return None;
        }
        Some(self.finish(grids, positions, diag))
    }

    /// Whether group `g` is turned over at these positions ([`Group::turned_over`], the members'
    /// volumes summed over their triangles).
    pub(super) fn turns_over(&self, g: &Group, positions: &[[f32; 3]], diag: f64) -> bool {
        let apex = g.apex(positions);
        let volumes = g
            .members
            .iter()
            .map(|&k| signed_volume_about(positions, &self.tris[k], apex));
        g.turned_over(&self.relative, volumes, diag)
    }

    /// Orients the groups by their volumes at these positions, then the normals.
    pub(super) fn finish(&self, grids: &[GridMesh], positions: Vec<[f32; 3]>, diag: f64) -> Welded {
        let mut group_flip: HashMap<usize, bool> = HashMap::new();
        for g in &self.groups {
            group_flip.insert(g.root, self.turns_over(g, &positions, diag));
        }
        let flipped: Vec<bool> = self
            .relative
            .iter()
            .map(|&(root, rel)| rel ^ group_flip.get(&root).copied().unwrap_or(false))
            .collect();

        // The triangles, each patch turned as decided (patches in parallel blocks).
        let total: usize = self.tris.iter().map(Vec::len).sum();
        let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(total);
        let mut parts = Vec::with_capacity(self.tris.len());
        {
            let mut rest = &mut triangles.spare_capacity_mut()[..total];
            let mut blocks = Vec::new();
            let mut start = 0;
            for (k, ts) in self.tris.iter().enumerate() {
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(ts.len());
                rest = tail;
                for (src, dst) in ts.chunks(1 << 15).zip(head.chunks_mut(1 << 15)) {
                    blocks.push((flipped[k], src, dst));
                }
                parts.push(Part {
                    name: self.names[k].clone(),
                    triangles: start..start + ts.len(),
                });
                start += ts.len();
            }
            blocks.into_par_iter().for_each(|(flip, src, dst)| {
                for (&[a, b, c], d) in src.iter().zip(dst) {
                    d.write(if flip { [a, c, b] } else { [a, b, c] });
                }
            });
        }
        // SAFETY: the blocks tile the first `total` elements, each written in full.
        unsafe { triangles.set_len(total) };

        let normals = super::normals::vertex_normals(grids, &self.source, &positions, &flipped);
        Welded {
            mesh: TriMesh {
                positions,
                normals,
                uv: Vec::new(),
                triangles,
                parts,
            },
            source: self.source.clone(),
            flipped,
        }
    }
}

/// A slice written by several threads at distinct indices.
pub(super) struct SharedSlice<T>(pub(super) *mut T, pub(super) usize);

// SAFETY: the pointer is only used through `write`, whose callers write distinct indices.
unsafe impl<T: Send> Sync for SharedSlice<T> {}

impl<T> SharedSlice<T> {
    /// Writes element `i`.
    ///
    /// # Safety
    /// No other thread reads or writes element `i` meanwhile.
    pub(super) unsafe fn write(&self, i: usize, x: T) {
        assert!(i < self.1, "index {i} within {}", self.1);
        // SAFETY: in bounds (checked); exclusive by the caller's promise.
        unsafe { *self.0.add(i) = x };
    }
}
