//! Tessellation of surfaces on `nu × nv` grids, triangle meshes and the weld of a design's grids
//! into one (the writers of mesh and sample formats are `mesh_write`).
//!
//! Grids are u-major: vertex `(i, j)` sits at index `i·nv + j`, with `u_i = i/(nu−1)` (evenly
//! spaced over the surface's [`Surface::u_range`], `[0, 1]` for nearly all surfaces) and, for a
//! periodic `v`, `v_j = 2πj/nv` (no repeated seam column: faces wrap from column `nv−1` to 0).

#[cfg(any(test, feature = "test-support"))]
pub mod test_grids;
mod trimesh;
pub mod weld;

pub use trimesh::{Part, TriMesh};
pub use weld::{
    report, weld, weld_mapped, FrameWeld, MeshReport, WeldOptions, WeldTopology, Welded,
};

use crate::surface::{Interval, RowBuf, Surface, VDomain};
use crate::{Error, Result, TAU};
use rayon::prelude::*;
use std::mem::MaybeUninit;

/// The axis that points up in a written file. Designs are modelled `+Z` up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Up {
    /// As designed (the default for OBJ, STL and PLY).
    #[default]
    Z,
    /// Turned so that the design's `+Z` becomes `+Y`: `(x, y, z) → (x, z, −y)` (a rotation, so
    /// orientation and volume are kept). glTF is always written this way.
    Y,
}

impl Up {
    /// `+Z` or `+Y`.
    pub fn label(self) -> &'static str {
        match self {
            Up::Z => "+Z",
            Up::Y => "+Y",
        }
    }
}

/// Largest number of grid vertices we agree to allocate (per patch).
pub const MAX_VERTICES: usize = 1 << 26;

/// A tessellated grid. `GridMesh` (f32, for meshes and pictures) and `Samples` (f64, for numbers)
/// are the two precisions.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid<T> {
    /// Number of rows (values of `u`), at least 2 for a filled grid.
    pub nu: usize,
    /// Number of columns (values of `v`).
    pub nv: usize,
    /// Faces wrap from the last column to the first.
    pub periodic_v: bool,
    /// Parameter values of the rows (`nu` of them).
    pub u: Vec<f64>,
    /// Parameter values of the columns (`nv` of them).
    pub v: Vec<f64>,
    /// `X(u_i, v_j)` at index [`Grid::index`]`(i, j) = i·nv + j` (row-major).
    pub positions: Vec<[T; 3]>,
    /// Unit normals `X_u × X_v / |X_u × X_v|` from the surface's exact derivatives (the limit
    /// normal at a pole, zero where none exists; see [`crate::surface::Partials::normal`]),
    /// indexed as `positions`.
    pub normals: Vec<[T; 3]>,
}

/// Mesh precision: what every mesh format stores.
pub type GridMesh = Grid<f32>;
/// Full precision samples (CSV).
pub type Samples = Grid<f64>;

impl<T> Grid<T> {
    /// A grid of no vertices, to be filled by [`evaluate_grid_into`].
    pub(crate) fn empty() -> Self {
        Grid {
            nu: 0,
            nv: 0,
            periodic_v: false,
            u: Vec::new(),
            v: Vec::new(),
            positions: Vec::new(),
            normals: Vec::new(),
        }
    }

    /// Index of vertex `(i, j)`.
    pub fn index(&self, i: usize, j: usize) -> usize {
        i * self.nv + j
    }

    /// Quads `(i,j), (i+1,j), (i+1,j+1), (i,j+1)`, counter-clockwise seen from the side the
    /// normals `X_u × X_v` point to.
    pub fn quads(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        let cols = if self.periodic_v {
            self.nv
        } else {
            self.nv.saturating_sub(1)
        };
        let nv = self.nv;
        (0..self.nu.saturating_sub(1)).flat_map(move |i| {
            (0..cols).map(move |j| {
                let j1 = (j + 1) % nv;
                [
                    (i * nv + j) as u32,
                    ((i + 1) * nv + j) as u32,
                    ((i + 1) * nv + j1) as u32,
                    (i * nv + j1) as u32,
                ]
            })
        })
    }

    /// The quads split into two triangles each.
    pub fn triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.quads().flat_map(|[a, b, c, d]| [[a, b, c], [a, c, d]])
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.nu * self.nv
    }

    /// True for an empty grid.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Grid parameters for a surface: `u_i = i/(nu−1)`; `v_j = 2πj/nv` if periodic, else evenly
/// spaced over the interval including both ends. Refuses `nu < 2`, `nv < 3` (periodic) or
/// `nv < 2`, and grids over [`MAX_VERTICES`], before allocating anything.
pub fn grid_parameters(domain: VDomain, nu: usize, nv: usize) -> Result<(Vec<f64>, Vec<f64>)> {
    grid_parameters_in(Interval::UNIT, domain, nu, nv)
}

/// [`grid_parameters`] with `u` over `u_range`: `u_i = u₀ + (u₁ − u₀)·i/(nu−1)` with the last
/// exactly `u₁` (for `[0, 1]` these are the numbers of [`grid_parameters`], bit for bit). Also
/// refuses a `u` range that is not finite with start < end.
pub fn grid_parameters_in(
    u_range: Interval,
    domain: VDomain,
    nu: usize,
    nv: usize,
) -> Result<(Vec<f64>, Vec<f64>)> {
    if !u_range.is_valid() {
        return Err(Error::invalid(format!(
            "the u range [{}, {}] must be finite with start < end",
            u_range.start, u_range.end
        ))
        .at("u range"));
    }
    if nu < 2 {
        return Err(Error::invalid(format!("must be at least 2 (got {nu})")).at("nu"));
    }
    let min_nv = if domain == VDomain::Periodic { 3 } else { 2 };
    if nv < min_nv {
        return Err(Error::invalid(format!("must be at least {min_nv} (got {nv})")).at("nv"));
    }
    if nu.checked_mul(nv).is_none_or(|n| n > MAX_VERTICES) {
        return Err(Error::invalid(format!(
            "a {nu} × {nv} grid has more than {MAX_VERTICES} vertices; refusing to allocate it"
        ))
        .at("nu × nv"));
    }
    crate::memory::check_items(
        (nu * nv) as u64,
        crate::memory::BYTES_PER_GRID_VERTEX,
        &format!("a {nu} × {nv} grid"),
        "nu × nv",
    )?;
    let (a, b) = (u_range.start, u_range.end);
    let us = (0..nu)
        .map(|i| {
            if i + 1 == nu {
                b
            } else {
                a + (b - a) * i as f64 / (nu - 1) as f64
            }
        })
        .collect();
    let vs = match domain {
        VDomain::Periodic => (0..nv).map(|j| TAU * j as f64 / nv as f64).collect(),
        VDomain::Interval(a, b) => (0..nv)
            .map(|j| a + (b - a) * j as f64 / (nv - 1) as f64)
            .collect(),
    };
    Ok((us, vs))
}

/// Scalar types a grid can store.
pub trait GridScalar: Copy + Send + Sync + Default + 'static {
    /// `x` in this precision (rounded to nearest for `f32`).
    fn from_f64(x: f64) -> Self;
    /// Neither infinite nor NaN.
    fn is_finite(self) -> bool;
}
impl GridScalar for f32 {
    fn from_f64(x: f64) -> Self {
        x as f32
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}
impl GridScalar for f64 {
    fn from_f64(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

/// Evaluates positions and unit normals (from exact derivatives) on an `nu × nv` grid, rows in
/// parallel. `tessellate` gives an f32 mesh, `sample` full precision.
pub fn evaluate_grid<T: GridScalar>(
    surface: &dyn Surface,
    nu: usize,
    nv: usize,
) -> Result<Grid<T>> {
    let mut grid = Grid::empty();
    evaluate_grid_into(surface, nu, nv, &mut grid)?;
    Ok(grid)
}

/// [`evaluate_grid`] into an existing grid, reusing its buffers: re-solving while a curve is
/// dragged then writes into memory that is already mapped. On error the grid is left empty.
pub fn evaluate_grid_into<T: GridScalar>(
    surface: &dyn Surface,
    nu: usize,
    nv: usize,
    grid: &mut Grid<T>,
) -> Result<()> {
    evaluate_grid_checked(surface, nu, nv, grid).map(|_| ())
}

/// [`evaluate_grid_into`], also telling whether every position and normal it stored is finite
/// (found as the values are stored, so that a caller refusing non-finite grids need not read
/// them again).
pub(crate) fn evaluate_grid_checked<T: GridScalar>(
    surface: &dyn Surface,
    nu: usize,
    nv: usize,
    grid: &mut Grid<T>,
) -> Result<bool> {
    grid.positions.clear();
    grid.normals.clear();
    (grid.nu, grid.nv) = (0, 0);
    let domain = surface.v_domain();
    let (us, vs) = grid_parameters_in(surface.u_range(), domain, nu, nv)?;
    let n = nu * nv;
    let positions = &mut grid.positions;
    let normals = &mut grid.normals;
    positions.reserve(n);
    normals.reserve(n);
    advise_huge_pages(positions.spare_capacity_mut());
    advise_huge_pages(normals.spare_capacity_mut());
    let finite = std::sync::atomic::AtomicBool::new(true);
    {
        let rows = surface.row_evaluator(&vs);
        let rows = &*rows;
        let finite = &finite;
        // Each row is written exactly once by the thread that evaluates it, straight into the
        // uninitialised buffers: the first touch of every page happens in parallel, and nothing
        // is zero-filled first.
        let pos_rows = positions.spare_capacity_mut()[..n].par_chunks_mut(nv);
        let nrm_rows = normals.spare_capacity_mut()[..n].par_chunks_mut(nv);
        pos_rows
            .zip(nrm_rows)
            .zip(us.par_iter())
            .with_min_len(4)
            .for_each_init(
                || RowBuf::new(nv),
                |row, ((prow, nrow), &u)| {
                    rows.eval_row(u, row);
                    if !store_row(row, prow, nrow) {
                        finite.store(false, std::sync::atomic::Ordering::Relaxed);
                    }
                },
            );
    }
    // SAFETY: the loop above wrote all `n = nu·nv` elements of both buffers: every row chunk of
    // `nv` elements is visited once and written in full.
    unsafe {
        positions.set_len(n);
        normals.set_len(n);
    }
    (grid.nu, grid.nv, grid.periodic_v, grid.u, grid.v) =
        (nu, nv, domain == VDomain::Periodic, us, vs);
    Ok(finite.into_inner())
}

/// Asks the kernel to back the 2 MiB-aligned part of a large, not yet touched buffer with
/// transparent huge pages, where the system allows it (`madvise` mode): a fresh 1024 × 1024 mesh
/// then costs a dozen page faults instead of six thousand. Only a hint; without effect elsewhere.
pub fn advise_huge_pages<T>(buf: &mut [T]) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = buf.as_mut_ptr() as usize;
        let end = start + std::mem::size_of_val(buf);
        let first = start.next_multiple_of(HUGE);
        let last = end / HUGE * HUGE;
        if last >= first + 2 * HUGE {
            // SAFETY: the range lies inside `buf`, which this function borrows mutably;
            // MADV_HUGEPAGE changes only how the pages are backed, never their contents.
            unsafe {
                libc::madvise(
                    first as *mut libc::c_void,
                    last - first,
                    libc::MADV_HUGEPAGE,
                );
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = buf;
}

/// Interleaves a row into the output buffers (converting to `T`); true when every value stored
/// is finite.
#[inline(always)]
fn store_row_generic<T: GridScalar>(
    row: &RowBuf,
    prow: &mut [MaybeUninit<[T; 3]>],
    nrow: &mut [MaybeUninit<[T; 3]>],
) -> bool {
    let mut finite = true;
    for (j, (p, n)) in prow.iter_mut().zip(nrow.iter_mut()).enumerate() {
        let q = [
            T::from_f64(row.x[j]),
            T::from_f64(row.y[j]),
            T::from_f64(row.z[j]),
        ];
        let m = [
            T::from_f64(row.nx[j]),
            T::from_f64(row.ny[j]),
            T::from_f64(row.nz[j]),
        ];
        // Without short cuts, so that the loop stays one straight pass.
        finite &= q[0].is_finite()
            & q[1].is_finite()
            & q[2].is_finite()
            & m[0].is_finite()
            & m[1].is_finite()
            & m[2].is_finite();
        p.write(q);
        n.write(m);
    }
    finite
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn store_row_avx2<T: GridScalar>(
    row: &RowBuf,
    prow: &mut [MaybeUninit<[T; 3]>],
    nrow: &mut [MaybeUninit<[T; 3]>],
) -> bool {
    store_row_generic(row, prow, nrow)
}

/// [`store_row_generic`], compiled for AVX2 where the processor has it.
fn store_row<T: GridScalar>(
    row: &RowBuf,
    prow: &mut [MaybeUninit<[T; 3]>],
    nrow: &mut [MaybeUninit<[T; 3]>],
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor supports the features the function was compiled for.
        return unsafe { store_row_avx2(row, prow, nrow) };
    }
    store_row_generic(row, prow, nrow)
}

/// The index of the first element of `data` for which `bad` holds: blocks in parallel, each
/// looked through in one straight pass (no per-element synchronisation), then the first bad
/// block element by element.
pub fn first_bad<T: Sync>(data: &[T], bad: impl Fn(&T) -> bool + Sync) -> Option<usize> {
    const BLOCK: usize = 1 << 14;
    let block = data
        .par_chunks(BLOCK)
        .position_first(|c| c.iter().fold(false, |any, x| any | bad(x)))?;
    let start = block * BLOCK;
    data[start..].iter().position(bad).map(|k| start + k)
}

/// f32 mesh of a surface on an `nu × nv` grid.
pub fn tessellate(surface: &dyn Surface, nu: usize, nv: usize) -> Result<GridMesh> {
    evaluate_grid(surface, nu, nv)
}

/// [`tessellate`] into an existing mesh, reusing its buffers (the interactive case).
pub fn tessellate_into(
    surface: &dyn Surface,
    nu: usize,
    nv: usize,
    mesh: &mut GridMesh,
) -> Result<()> {
    evaluate_grid_into(surface, nu, nv, mesh)
}

/// Full-precision samples of a surface on an `nu × nv` grid.
pub fn sample(surface: &dyn Surface, nu: usize, nv: usize) -> Result<Samples> {
    evaluate_grid(surface, nu, nv)
}

/// [`evaluate_grid`] and whether every stored value is finite ([`evaluate_grid_checked`]).
pub(crate) fn evaluate_grid_finite<T: GridScalar>(
    surface: &dyn Surface,
    nu: usize,
    nv: usize,
) -> Result<(Grid<T>, bool)> {
    let mut grid = Grid::empty();
    let finite = evaluate_grid_checked(surface, nu, nv, &mut grid)?;
    Ok((grid, finite))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{Partials, UnitCylinder as Cylinder};

    #[test]
    fn grids_follow_the_conventions_and_reuse_buffers() {
        let mesh = tessellate(&Cylinder, 3, 8).unwrap();
        assert_eq!((mesh.nu, mesh.nv, mesh.periodic_v), (3, 8, true));
        assert_eq!(mesh.u, vec![0.0, 0.5, 1.0]);
        assert_eq!(mesh.v[2], TAU * 2.0 / 8.0);
        // u-major, v_j = 2πj/nv without a repeated seam column; outward normals X_u × X_v.
        let p = mesh.positions[mesh.index(1, 2)];
        assert!((p[0] as f64 - (TAU / 4.0).cos()).abs() < 1e-7 && (p[2] - 0.5).abs() < 1e-7);
        let n = mesh.normals[mesh.index(1, 0)];
        assert!((n[0] + 1.0).abs() < 1e-7, "{n:?}");
        assert_eq!(mesh.quads().count(), 2 * 8);
        // Re-tessellating into the mesh gives the same values in the same memory.
        let mut again = mesh.clone();
        again.positions.reserve(64);
        let ptr = again.positions.as_ptr();
        tessellate_into(&Cylinder, 3, 8, &mut again).unwrap();
        assert_eq!(again, mesh);
        assert_eq!(again.positions.as_ptr(), ptr);
        // A refused grid leaves it empty, not stale.
        assert!(tessellate_into(&Cylinder, 1, 8, &mut again).is_err());
        assert!(again.is_empty() && again.positions.is_empty());
    }

    /// The cylinder `(cos v, sin v, u)` on `u ∈ [−1, 2]`.
    struct Tall;

    impl Surface for Tall {
        fn v_domain(&self) -> VDomain {
            VDomain::Periodic
        }
        fn u_range(&self) -> Interval {
            Interval::new(-1.0, 2.0)
        }
        fn partials(&self, u: f64, v: f64) -> Partials {
            Cylinder.partials(u, v)
        }
    }

    #[test]
    fn grids_honour_the_u_range() {
        // On [0, 1] the numbers are those of i/(nu − 1), bit for bit.
        for nu in [2usize, 3, 7, 10, 33, 100, 1000, 1025] {
            let (us, _) = grid_parameters(VDomain::Periodic, nu, 4).unwrap();
            let old: Vec<f64> = (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect();
            assert!(us.iter().zip(&old).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        let mesh = sample(&Tall, 4, 8).unwrap();
        assert_eq!(mesh.u, vec![-1.0, 0.0, 1.0, 2.0]);
        for i in 0..4 {
            assert_eq!(mesh.positions[mesh.index(i, 0)], [1.0, 0.0, mesh.u[i]]);
        }
        let bad = grid_parameters_in(Interval::new(1.0, f64::NAN), VDomain::Periodic, 4, 8);
        assert_eq!(
            bad.unwrap_err().to_string(),
            "u range: the u range [1, NaN] must be finite with start < end"
        );
    }
}
