//! Trimmed surfaces of a frame (§5.2, §5.2.1): a surface with holes (from `[[trims]]` or from
//! attachments) is drawn as the library's re-meshed triangle mesh, not as its grid. The
//! re-meshed parameter domain (`trim::trim_domain`) depends only on the trim curves, the method,
//! the grid and the surface's parameter domain, so it is kept while they stay the same (a spine
//! drag of a trimmed patch re-uses it); the positions are gathered from the surface's grid mesh
//! (which the compiled design re-tessellates only when the surface changed) and the vertices on
//! the trim curves evaluated exactly (`trim::to_trimesh`).

use pdeshape::design::{SolvedDesign, SurfaceKind, SurfaceTrim};
use pdeshape::mesh::{GridMesh, TriMesh};
use pdeshape::surface::ParameterDomain;
use pdeshape::trim::{to_trimesh, trim_domain, ParamMesh, TrimCurve, TrimMethod};

/// What a re-meshed domain was made from.
#[derive(Clone, Debug, PartialEq)]
struct Key {
    curves: Vec<TrimCurve>,
    method: TrimMethod,
    grid: (usize, usize),
    domain: ParameterDomain,
}

/// The triangle mesh of one trimmed surface and the parameter mesh it was made from.
pub(super) struct Trimmed {
    key: Key,
    pub param: ParamMesh,
    pub mesh: TriMesh,
}

/// The trimmed meshes of the last frame, one slot per surface (`None`: drawn as its grid).
#[derive(Default)]
pub(super) struct TrimmedMeshes {
    slots: Vec<Option<Trimmed>>,
    /// Parameter meshes re-made (not reused) since the session started: for tests.
    pub remeshed: usize,
}

/// A trimmed surface of a solved design: what its mesh is made from.
pub(super) struct Job {
    k: usize,
    surface: SurfaceKind,
    name: String,
    trim: SurfaceTrim,
}

/// The trimmed surfaces of `solved` (their objects shared, not copied).
pub(super) fn jobs(solved: &SolvedDesign) -> Vec<Job> {
    solved
        .trims
        .iter()
        .map(|t| Job {
            k: t.surface,
            surface: solved.surfaces[t.surface].kind.clone(),
            name: solved.surfaces[t.surface].name.clone(),
            trim: t.clone(),
        })
        .collect()
}

impl TrimmedMeshes {
    /// Re-makes the trimmed meshes of the surfaces `jobs` on the grid meshes `grids` (of every
    /// surface, made on `grid`). On an error (holes that cannot be cut on this grid) nothing
    /// is kept.
    pub(super) fn update(
        &mut self,
        jobs: &[Job],
        grids: &[GridMesh],
        grid: (usize, usize),
    ) -> pdeshape::Result<()> {
        let mut old = std::mem::take(&mut self.slots);
        let mut slots: Vec<Option<Trimmed>> = (0..grids.len()).map(|_| None).collect();
        for job in jobs {
            let surface = job.surface.surface();
            let key = Key {
                curves: job.trim.curves.clone(),
                method: job.trim.method,
                grid,
                domain: surface.parameter_domain(),
            };
            // A kept parameter mesh of the same key, from any slot (surfaces may be renumbered).
            let kept = old
                .iter_mut()
                .find(|o| o.as_ref().is_some_and(|o| o.key == key))
                .and_then(Option::take);
            let param = match kept {
                Some(k) => k.param,
                None => {
                    self.remeshed += 1;
                    trim_domain(key.domain, grid.0, grid.1, &key.curves, key.method)
                        .map_err(|e| e.at(&job.trim.place))?
                }
            };
            let mesh = to_trimesh(surface, &grids[job.k], &param, &job.name);
            slots[job.k] = Some(Trimmed { key, param, mesh });
        }
        self.slots = slots;
        Ok(())
    }

    /// The trimmed mesh of surface `k`, if it has holes.
    pub(super) fn get(&self, k: usize) -> Option<&Trimmed> {
        self.slots.get(k).and_then(Option::as_ref)
    }

    pub(super) fn clear(&mut self) {
        self.slots.clear();
    }
}

/// Per-vertex colours of a trimmed mesh from its grid's colours: a grid vertex keeps its own,
/// a vertex on a trim curve takes that of the grid vertex nearest in `(u, v)` (within one cell).
pub(super) fn colors(t: &Trimmed, grid: &GridMesh, grid_colors: &[[u8; 3]]) -> Vec<[u8; 3]> {
    let nearest = |values: &[f64], x: f64| -> usize {
        let k = values.partition_point(|&y| y < x);
        if k == 0 {
            0
        } else if k >= values.len() {
            values.len() - 1
        } else if x - values[k - 1] <= values[k] - x {
            k - 1
        } else {
            k
        }
    };
    let nv = grid.nv;
    let g = t.param.grid_source.len();
    let mut out: Vec<[u8; 3]> = t.param.grid_source[..]
        .iter()
        .map(|&s| grid_colors[s as usize])
        .collect();
    let period = pdeshape::TAU;
    out.extend(t.param.uv[g..].iter().map(|&[u, v]| {
        let v = if grid.periodic_v {
            v.rem_euclid(period)
        } else {
            v
        };
        let i = nearest(&grid.u, u);
        let mut j = nearest(&grid.v, v);
        // Past the last column of a periodic grid the first one is nearer.
        if grid.periodic_v && j + 1 == nv && v - grid.v[j] > period - v {
            j = 0;
        }
        grid_colors[i * nv + j]
    }));
    out
}
