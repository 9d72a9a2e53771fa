//! The merge of the weld candidates: the boundary vertices (end rows, collapsed rows, end
//! columns) that coincide within the tolerance join, the others keep numbers of their own.

use super::hash::CellHasher;
use super::{WeldOptions, WELD_TOLERANCE};
use crate::mesh::GridMesh;
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::BuildHasherDefault;

/// True for the rows whose every vertex may coincide with another: the two end rows and the
/// rows collapsed to one point. The end columns of a non-periodic grid are the other weld
/// candidates ([`GridTopology::explicit`]).
pub(super) fn candidate_rows(g: &GridMesh) -> Vec<bool> {
    let (nu, nv) = (g.nu, g.nv);
    (0..nu)
        .map(|i| {
            let row = &g.positions[i * nv..(i + 1) * nv];
            i == 0 || i + 1 == nu || row.iter().all(|p| p == &row[0])
        })
        .collect()
}

/// Joins the boundary vertices that coincide: the welded positions (first copy) and the welded
/// vertex of every grid vertex.
pub(super) fn merge(
    grids: &[GridMesh],
    options: WeldOptions,
    diag: f64,
) -> (Vec<[f32; 3]>, Vec<Vec<u32>>) {
    let m = merge_rows(grids, options, diag);
    (m.positions, m.source)
}

/// What [`merge_rows`] finds.
pub(super) struct Merged {
    /// The welded positions (each vertex's first copy).
    pub(super) positions: Vec<[f32; 3]>,
    /// Each grid's welded vertex of every grid vertex.
    pub(super) source: Vec<Vec<u32>>,
    /// Each grid's [`candidate_rows`].
    pub(super) rows: Vec<Vec<bool>>,
    /// Each grid's welded number of each row's first new vertex, and one past its last row's:
    /// grid `k`'s own vertices (the ones it adds) are `starts[k][0]..starts[k][nu]`.
    pub(super) starts: Vec<Vec<usize>>,
}

/// [`merge`], also returning each grid's [`candidate_rows`] and where its rows' new vertices
/// start.
///
/// Welded vertices are numbered in the order of the grids' vertices, a new number for every
/// vertex that is not a candidate or finds no earlier candidate within the tolerance. Only the
/// candidates are visited one by one (in that order, looking through the cells around them);
/// the others take consecutive numbers, so every row's new vertices form one range of welded
/// numbers, and the rows are then filled in parallel.
pub(super) fn merge_rows(grids: &[GridMesh], options: WeldOptions, diag: f64) -> Merged {
    let tol = if diag.is_finite() && diag > 0.0 {
        WELD_TOLERANCE * diag
    } else {
        f64::MIN_POSITIVE
    };
    let tol2 = tol * tol;
    let cell = |p: [f32; 3]| p.map(|x| (x as f64 / tol).floor() as i64);

    // Candidates' cells: their welded vertex and its position (the first copy's).
    type Buckets = HashMap<([i64; 3], usize), Vec<(u32, [f32; 3])>, BuildHasherDefault<CellHasher>>;
    let mut buckets: Buckets = HashMap::default();
    let mut next = 0usize;
    let mut visit = |p: [f32; 3], group: usize, next: &mut usize| -> u32 {
        let c = cell(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let key = ([c[0] + dx, c[1] + dy, c[2] + dz], group);
                    if let Some(list) = buckets.get(&key) {
                        for &(w, q) in list {
                            let d2: f64 = (0..3).map(|a| (p[a] as f64 - q[a] as f64).powi(2)).sum();
                            if d2 <= tol2 {
                                return w;
                            }
                        }
                    }
                }
            }
        }
        let w = *next as u32;
        *next += 1;
        buckets.entry((c, group)).or_default().push((w, p));
        w
    };
    let mut sources: Vec<Vec<u32>> = Vec::with_capacity(grids.len());
    let mut all_rows = Vec::with_capacity(grids.len());
    // Per grid, the welded number of each row's first new vertex (and one past the last row).
    let mut starts: Vec<Vec<usize>> = Vec::with_capacity(grids.len());
    for (k, g) in grids.iter().enumerate() {
        let group = if options.join_patches { 0 } else { k };
        let (nu, nv) = (g.nu, g.nv);
        let rows = candidate_rows(g);
        // Zeroed pages are faulted in where they are first written: the candidates here, the
        // rest in parallel below.
        let mut map = vec![0u32; nu * nv];
        crate::mesh::advise_huge_pages(&mut map);
        let mut start = Vec::with_capacity(nu + 1);
        for (i, &whole) in rows.iter().enumerate() {
            start.push(next);
            let row = i * nv;
            if whole {
                for j in 0..nv {
                    map[row + j] = visit(g.positions[row + j], group, &mut next);
                }
            } else if g.periodic_v {
                next += nv;
            } else if nv > 0 {
                map[row] = visit(g.positions[row], group, &mut next);
                if nv > 1 {
                    next += nv - 2;
                    map[row + nv - 1] = visit(g.positions[row + nv - 1], group, &mut next);
                }
            }
        }
        start.push(next);
        sources.push(map);
        all_rows.push(rows);
        starts.push(start);
    }

    // Every row's new vertices are the welded numbers start[i]..start[i + 1]: the row's
    // non-candidates in order, and each candidate whose number is at least start[i].
    let mut positions: Vec<[f32; 3]> = Vec::with_capacity(next);
    crate::mesh::advise_huge_pages(positions.spare_capacity_mut());
    {
        let mut rest = &mut positions.spare_capacity_mut()[..next];
        let mut tasks = Vec::new();
        for (k, (g, map)) in grids.iter().zip(sources.iter_mut()).enumerate() {
            let nv = g.nv.max(1);
            for (i, src) in map.chunks_mut(nv).enumerate() {
                let len = starts[k][i + 1] - starts[k][i];
                let (head, tail) = std::mem::take(&mut rest).split_at_mut(len);
                rest = tail;
                tasks.push((g, &all_rows[k], i, starts[k][i], src, head));
            }
        }
        tasks
            .into_par_iter()
            .with_min_len(8)
            .for_each(|(g, rows, i, start, src, out)| {
                let nv = src.len();
                let row = &g.positions[i * g.nv..i * g.nv + nv];
                if !rows[i] {
                    // Non-candidates, numbered after the first column if it was new.
                    let (first, lo, hi) = if g.periodic_v {
                        (start, 0, nv)
                    } else {
                        let first = start + (src[0] as usize == start) as usize;
                        (first, 1, nv.saturating_sub(1).max(1))
                    };
                    for (j, s) in src.iter_mut().enumerate().take(hi).skip(lo) {
                        *s = (first + j - lo) as u32;
                    }
                }
                // New vertices take increasing numbers along the row; a candidate joined to an
                // earlier vertex (of this row or before) has a smaller one.
                let mut expect = start;
                for (s, p) in src.iter().zip(row) {
                    if *s as usize == expect {
                        out[expect - start].write(*p);
                        expect += 1;
                    }
                }
                assert_eq!(
                    expect - start,
                    out.len(),
                    "every new vertex of the row written"
                );
            });
    }
    // SAFETY: the welded numbers 0..next are the union of the rows' ranges start[i]..start[i+1],
    // and each row wrote every number of its range (checked by the assertion above).
    unsafe { positions.set_len(next) };
    Merged {
        positions,
        source: sources,
        rows: all_rows,
        starts,
    }
}
