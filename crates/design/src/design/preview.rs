//! Meshes while one control point is dragged. A surface that depends affinely on the point `P`
//! (a PDE patch, an n-sided patch whose sides carry their own ribbons: each is the solution of a
//! linear problem whose data are linear in `P`) is, at every vertex of a grid,
//! `X(P₀ + Δ) = X(P₀) + Σ_c Δ_c ∂X/∂P_c`, and so are its partials `X_u`, `X_v`. The slopes are
//! found from three solves with `P` moved along the axes (exact up to rounding for an affine
//! surface, whatever the step), so each frame of a drag costs a multiply-add per vertex instead
//! of an evaluation of the surface.
//!
//! Affinity is found, not assumed. When the model is made, a fourth solve at a step off the axes
//! must agree with the prediction at every vertex; on every frame the surface actually solved
//! for that frame is evaluated at [`PROBES`] vertices spread over the grid and must agree with
//! the prediction there. Both to [`AGREEMENT`] of the surface's extent (and of its partials'),
//! below the single precision the meshes are stored in; a surface
//! that fails is tessellated as usual for the rest of the drag. Normals come from the predicted
//! partials as [`crate::surface::RowEvaluator`]s compute them; where `X_u × X_v` degenerates (a
//! pole), from the surface's own [`Surface::partials`].

use crate::mesh::{grid_parameters_in, GridMesh};
use crate::spec::{CurveKind, DesignSpec, V3};
use crate::surface::{first_order_normal, Surface};
use crate::Vec3;
use rayon::prelude::*;

/// Vertices of each predicted mesh checked against the surface on every frame.
pub(super) const PROBES: usize = 32;

/// Largest disagreement between prediction and surface allowed, relative to the largest value
/// of the quantity (position, `X_u`, `X_v`) over the grid: 2⁻²⁷, a sixteenth of the single
/// precision's epsilon, so a predicted mesh differs from a tessellated one by at most a unit in
/// the last place of its `f32` numbers. Exact arithmetic would allow 0; what it must allow is
/// the surfaces' own evaluation error, which is not always near the double precision's: at a
/// corner of an n-sided patch the partials are limits taken 1e-7 inside, where the blends'
/// 0/0 leaves them good to about 1e-9.
pub(super) const AGREEMENT: f64 = 1.0 / (1u64 << 27) as f64;

/// Most vertices a model keeps, over all its surfaces: 288 bytes each (`X`, `X_u`, `X_v` and
/// their three slopes), so at most 72 MiB. A drag on a larger grid is tessellated as usual.
pub(super) const MAX_MODEL_VERTICES: usize = 1 << 18;

/// The drag in progress: one control point moved by consecutive edits.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct DragKey {
    pub(super) curve: String,
    pub(super) index: usize,
}

#[derive(Default)]
pub(super) struct Drag {
    /// The point being dragged.
    pub(super) key: Option<DragKey>,
    /// An edit of it was applied since the last meshes.
    pending: bool,
    /// The grid of the last meshes after an edit, and how many edits in a row were followed by
    /// meshes on it.
    grid: (usize, usize),
    frames: usize,
    /// The model made for it on `grid`, if one was tried (`None` inside: it could not be made).
    pub(super) model: Option<Option<Model>>,
    /// Meshes given by models so far.
    pub(super) predicted: usize,
}

impl Drag {
    /// Notes an applied edit: `Some(key)` for a move of a control point, `None` otherwise.
    pub(super) fn note(&mut self, key: Option<DragKey>) {
        if key.is_none() || key != self.key {
            *self = Drag {
                key,
                predicted: self.predicted,
                ..Drag::default()
            };
        }
        self.pending = self.key.is_some();
    }

    /// Notes meshes asked for on `grid`; true when a model should be made now: the same point
    /// was moved at least twice in a row with meshes on this grid after each (a drag, not a
    /// single edit, nor the full grid after a drag's coarse frames) and none was tried yet.
    pub(super) fn frame(&mut self, grid: (usize, usize)) -> bool {
        if self.pending {
            self.pending = false;
            if grid == self.grid {
                self.frames += 1;
            } else {
                (self.grid, self.frames, self.model) = (grid, 1, None);
            }
        }
        self.frames >= 2 && self.model.is_none() && grid == self.grid
    }
}

/// The affine model of every surface that depends on the dragged point, on one grid.
pub(super) struct Model {
    pub(super) grid: (usize, usize),
    /// The control point at which the bases were taken.
    pub(super) origin: Vec3,
    /// `(surface index, its model)`; surfaces not affine in the point are absent.
    pub(super) surfaces: Vec<(usize, AffineGrid)>,
}

/// `X`, `X_u`, `X_v` at every vertex of a grid and their derivatives by the three coordinates of
/// the control point.
pub(super) struct AffineGrid {
    /// `[X, X_u, X_v]` at `P₀`, row-major like the mesh.
    base: Vec<[Vec3; 3]>,
    /// `∂/∂P_c` of `[X, X_u, X_v]`, `c = x, y, z`.
    slope: Vec<[[Vec3; 3]; 3]>,
    /// The largest `|X|`, `|X_u|`, `|X_v|` over the grid: the scales of [`AGREEMENT`].
    scale: [f64; 3],
    /// The grid's parameters: a surface whose grid has others is not predicted.
    us: Vec<f64>,
    vs: Vec<f64>,
}

/// `[X, X_u, X_v]` of `surface` at every `(u, v)` of the grid, rows in parallel.
pub(super) fn jets(surface: &dyn Surface, us: &[f64], vs: &[f64]) -> Vec<[Vec3; 3]> {
    let nv = vs.len();
    let mut out = vec![[Vec3::zeros(); 3]; us.len() * nv];
    let rows = surface.first_partials_rows(vs);
    let rows = &*rows;
    out.par_chunks_mut(nv)
        .zip(us.par_iter())
        .for_each(|(row, &u)| rows.eval_row(u, row));
    out
}

fn largest(values: &[[Vec3; 3]]) -> [f64; 3] {
    let mut s = [0.0f64; 3];
    for v in values {
        for q in 0..3 {
            s[q] = s[q].max(v[q].amax());
        }
    }
    s
}

impl AffineGrid {
    /// The model from the surface at `P₀` (`base`), at `P₀ + h e_c` (`axes[c]`), checked
    /// against the surface at `P₀ + check_step` (`check`), all on the grid `(us, vs)`. `None`
    /// if they are not affine.
    pub(super) fn new(
        (us, vs): (Vec<f64>, Vec<f64>),
        base: Vec<[Vec3; 3]>,
        axes: [Vec<[Vec3; 3]>; 3],
        h: f64,
        check: (&[[Vec3; 3]], Vec3),
    ) -> Option<AffineGrid> {
        let slope: Vec<[[Vec3; 3]; 3]> = (0..base.len())
            .map(|i| [0, 1, 2].map(|c| [0, 1, 2].map(|q| (axes[c][i][q] - base[i][q]) / h)))
            .collect();
        let mut scale = largest(&base);
        for a in &axes {
            let s = largest(a);
            for q in 0..3 {
                scale[q] = scale[q].max(s[q]);
            }
        }
        let model = AffineGrid {
            base,
            slope,
            scale,
            us,
            vs,
        };
        let (values, step) = check;
        let all: Vec<usize> = (0..values.len()).collect();
        model.agrees(step, &all, |i| values[i]).then_some(model)
    }

    /// `[X, X_u, X_v]` predicted at vertex `i` for the point moved by `d` from `P₀`.
    #[inline]
    fn at(&self, i: usize, d: Vec3) -> [Vec3; 3] {
        let (b, s) = (&self.base[i], &self.slope[i]);
        [0, 1, 2].map(|q| b[q] + s[0][q] * d.x + s[1][q] * d.y + s[2][q] * d.z)
    }

    /// True if the prediction at `d` agrees with `actual` at the vertices `at`.
    fn agrees(&self, d: Vec3, at: &[usize], actual: impl Fn(usize) -> [Vec3; 3]) -> bool {
        at.iter().all(|&i| {
            let (p, a) = (self.at(i, d), actual(i));
            (0..3).all(|q| (p[q] - a[q]).amax() <= AGREEMENT * self.scale[q])
        })
    }

    /// True if `surface` (the one solved for the point moved by `d`) has the model's grid
    /// parameters and agrees with the prediction at [`PROBES`] vertices.
    pub(super) fn probe(&self, surface: &dyn Surface, d: Vec3) -> bool {
        let (nu, nv) = (self.us.len(), self.vs.len());
        match grid_parameters_in(surface.u_range(), surface.v_domain(), nu, nv) {
            Ok((us, vs)) if us == self.us && vs == self.vs => {}
            _ => return false,
        }
        let (us, vs) = (&self.us, &self.vs);
        let n = self.base.len();
        // Spread over the grid: a stride prime to most grid sizes, the corners included.
        let mut at: Vec<usize> = (0..PROBES).map(|k| (k * 7919) % n).collect();
        at.extend([0, nv - 1, n - nv, n - 1]);
        self.agrees(d, &at, |i| surface.first_partials(us[i / nv], vs[i % nv]))
    }

    /// Writes the mesh of the surface for the point moved by `d` into `mesh` (whose grid is the
    /// model's); `surface` gives the normal where the predicted partials degenerate.
    pub(super) fn fill(&self, surface: &dyn Surface, d: Vec3, mesh: &mut GridMesh) {
        let nv = mesh.nv;
        let (us, vs) = (&self.us, &self.vs);
        mesh.positions
            .par_chunks_mut(nv)
            .zip(mesh.normals.par_chunks_mut(nv))
            .enumerate()
            .for_each(|(r, (prow, nrow))| {
                for j in 0..nv {
                    let [x, xu, xv] = self.at(r * nv + j, d);
                    let n = first_order_normal(xu, xv)
                        .unwrap_or_else(|| surface.partials(us[r], vs[j]).normal());
                    prow[j] = [x.x as f32, x.y as f32, x.z as f32];
                    nrow[j] = [n.x as f32, n.y as f32, n.z as f32];
                }
            });
    }
}

/// The control points (or sample points) of the curve `key` names.
fn points<'a>(spec: &'a DesignSpec, key: &DragKey) -> Option<&'a [V3]> {
    match &spec.curves.get(&key.curve)?.kind {
        CurveKind::BSpline { control, .. } | CurveKind::Bezier { control } => Some(control),
        CurveKind::Samples { points, .. } => Some(points),
        _ => None,
    }
}

/// The dragged point as the design file has it (in the curve's own coordinates).
pub(super) fn control_point(spec: &DesignSpec, key: &DragKey) -> Option<Vec3> {
    let p = points(spec, key)?.get(key.index)?;
    Some(Vec3::new(p[0], p[1], p[2]))
}

/// The step of the solves that find the slopes: a quarter of the curve's control polygon's
/// extent about the point (a power-of-two fraction: no rounding in the step itself). The
/// slopes' error is the surfaces' evaluation error over `h` (about `ε |X| / h`, and `1e-9 |X| /
/// h` at an n-sided patch's corners), so the step is large, as large as a drag's moves; a step
/// that makes the design invalid leaves the drag without a model.
pub(super) fn step(spec: &DesignSpec, key: &DragKey) -> Option<f64> {
    let all = points(spec, key)?;
    let p = control_point(spec, key)?;
    let extent = all
        .iter()
        .map(|q| (Vec3::new(q[0], q[1], q[2]) - p).amax())
        .fold(0.0f64, f64::max);
    let h = if extent > 0.0 && extent.is_finite() {
        extent / 4.0
    } else {
        0.25
    };
    h.is_finite().then_some(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[X, X_u, X_v]` at four vertices for the point moved by `d`.
    fn values(f: &impl Fn(usize, Vec3) -> [Vec3; 3], d: Vec3) -> Vec<[Vec3; 3]> {
        (0..4).map(|i| f(i, d)).collect()
    }

    fn model(f: &impl Fn(usize, Vec3) -> [Vec3; 3], h: f64) -> Option<AffineGrid> {
        let check = Vec3::new(0.5, -0.75, 0.3) * h;
        let axes = [Vec3::x(), Vec3::y(), Vec3::z()].map(|e| values(f, e * h));
        let grid = (vec![0.0, 1.0], vec![0.0, 1.0]);
        AffineGrid::new(
            grid,
            values(f, Vec3::zeros()),
            axes,
            h,
            (&values(f, check), check),
        )
    }

    #[test]
    fn affine_data_make_a_model_and_others_do_not() {
        // Affine in d, with a different matrix at every vertex and in every partial.
        let affine = |i: usize, d: Vec3| {
            let w = 0.3 + i as f64;
            [
                Vec3::new(1.0, 2.0, i as f64) + d * w,
                d * (2.0 * w) + Vec3::new(0.5, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0) + Vec3::new(d.y, -d.x, 3.0 * d.z),
            ]
        };
        let m = model(&affine, 0.25).expect("affine data make a model");
        let all = [0, 1, 2, 3];
        // It predicts any other move, far outside the steps it was made from.
        let d = Vec3::new(-0.4, 0.9, 2.0);
        assert!(m.agrees(d, &all, |i| affine(i, d)));
        // A quadratic term a hundred thousand times smaller than the values is found by the
        // check…
        let quadratic = |i: usize, d: Vec3| {
            let mut v = affine(i, d);
            v[2].y += 1e-5 * d.norm_squared();
            v
        };
        assert!(model(&quadratic, 0.25).is_none());
        // …and by the probes of a model made from affine data.
        assert!(!m.agrees(d, &all, |i| quadratic(i, d)));
    }
}
