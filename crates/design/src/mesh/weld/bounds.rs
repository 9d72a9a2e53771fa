//! Bounding boxes of vertices (`bounding_box`, `box_union`) and the grids' diagonal that scales
//! the weld tolerance.

use crate::mesh::GridMesh;
use rayon::prelude::*;

/// A box `(lo, hi)` with sides along the axes.
pub type BoundingBox = ([f32; 3], [f32; 3]);

/// The box around nothing: the identity of [`box_union`].
pub const EMPTY_BOX: BoundingBox = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);

/// The smallest box around two boxes (by comparisons, as [`bounding_box`]).
pub fn box_union(a: BoundingBox, b: BoundingBox) -> BoundingBox {
    (
        [0, 1, 2].map(|c| if b.0[c] < a.0[c] { b.0[c] } else { a.0[c] }),
        [0, 1, 2].map(|c| if b.1[c] > a.1[c] { b.1[c] } else { a.1[c] }),
    )
}

/// The smallest box `(lo, hi)` around `points`, by comparisons: a NaN coordinate is passed
/// over (as `f32::min` passes it over), and which sign a zero extreme keeps is not specified.
/// Eight points at a time in 24 lanes, which the compiler turns into vector compares.
pub(crate) fn bounding_box(points: &[[f32; 3]]) -> BoundingBox {
    let flat = points.as_flattened();
    let mut lo = [f32::INFINITY; 24];
    let mut hi = [f32::NEG_INFINITY; 24];
    let mut blocks = flat.chunks_exact(24);
    for b in &mut blocks {
        for k in 0..24 {
            lo[k] = if b[k] < lo[k] { b[k] } else { lo[k] };
            hi[k] = if b[k] > hi[k] { b[k] } else { hi[k] };
        }
    }
    for (k, &x) in blocks.remainder().iter().enumerate() {
        lo[k] = if x < lo[k] { x } else { lo[k] };
        hi[k] = if x > hi[k] { x } else { hi[k] };
    }
    let (mut l, mut h) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for k in 0..24 {
        let c = k % 3;
        l[c] = if lo[k] < l[c] { lo[k] } else { l[c] };
        h[c] = if hi[k] > h[c] { hi[k] } else { h[c] };
    }
    (l, h)
}

/// Bounding-box diagonal of every grid vertex (blocks in parallel: minima and maxima do not
/// depend on the order).
pub(super) fn diagonal(grids: &[GridMesh]) -> f64 {
    let empty = || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let (lo, hi) = grids
        .par_iter()
        .flat_map(|g| g.positions.par_chunks(1 << 14))
        .map(|block| {
            // In f32 (the extremes convert exactly); the sign of a zero does not change the
            // diagonal.
            let (lo, hi) = bounding_box(block);
            (lo.map(f64::from), hi.map(f64::from))
        })
        .reduce(empty, |(a, b), (c, d)| {
            (
                [a[0].min(c[0]), a[1].min(c[1]), a[2].min(c[2])],
                [b[0].max(d[0]), b[1].max(d[1]), b[2].max(d[2])],
            )
        });
    (0..3).map(|c| (hi[c] - lo[c]).powi(2)).sum::<f64>().sqrt()
}
