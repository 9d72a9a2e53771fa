//! The piecewise-bicubic spline as a [`Surface`], and its Bézier and B-spline control nets.

use super::element::hermite_1d;
use super::Partition;
use crate::surface::{Partials, Surface, VDomain};
use crate::Vec3;

/// A C¹ piecewise-bicubic function `σ_h : [0, 1]² → R³` of the BFS space: its partition and the
/// four nodal values `σ, σ_x, σ_y, σ_xy` of every node. As a [`Surface`], `u = x` and `v = y`
/// (`v` on `[0, 1]`), and the partials are the exact derivatives of the element's bicubic.
#[derive(Clone, Debug, PartialEq)]
pub struct BfsSurface {
    partition: Partition,
    coef: Vec<Vec3>,
}

// Closest points by the general search (no closed form).
impl crate::surface::SurfaceNearest for BfsSurface {}

/// One element's bicubic in Bézier form: `σ(x, y) = Σ_{i,j} B_i(s) B_j(t) control[i][j]` with
/// `s = (x − x0)/(x1 − x0)`, `t = (y − y0)/(y1 − y0)` and the cubic Bernstein polynomials `B`.
#[derive(Clone, Debug, PartialEq)]
pub struct BezierPatch {
    /// The element's extent `[x0, x1]` in `x`.
    pub x: [f64; 2],
    /// The element's extent `[y0, y1]` in `y`.
    pub y: [f64; 2],
    /// The 4 × 4 Bézier control points, `control[i][j]` with `i` along `x`.
    pub control: [[Vec3; 4]; 4],
}

/// The whole spline as one bicubic tensor B-spline: clamped knot vectors with every interior
/// breakpoint doubled (C¹ across it), `control[i][j]` with `i` along `x`.
#[derive(Clone, Debug, PartialEq)]
pub struct BSplineNet {
    /// Knot vector in `x`: the partition's breakpoints, the ends four times and every interior one
    /// twice.
    pub knots_x: Vec<f64>,
    /// Knot vector in `y`, built like `knots_x`.
    pub knots_y: Vec<f64>,
    /// Control points, `control[i][j]` with `i` along `x`: `2 nx + 2` rows of `2 ny + 2`.
    pub control: Vec<Vec<Vec3>>,
}

/// Cubic Hermite data `(p₀, h d₀, p₁, h d₁)` to Bézier points `b₀ … b₃`.
const HERMITE_TO_BEZIER: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [1.0, 1.0 / 3.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, -1.0 / 3.0],
    [0.0, 0.0, 1.0, 0.0],
];

impl BfsSurface {
    /// The spline with nodal coefficients `coef` (length [`Partition::dofs`], global order
    /// `4·node + k`).
    ///
    /// # Panics
    /// If `coef` has the wrong length.
    pub fn new(partition: Partition, coef: Vec<Vec3>) -> Self {
        assert_eq!(coef.len(), partition.dofs(), "one coefficient per dof");
        BfsSurface { partition, coef }
    }

    /// The partition.
    pub fn partition(&self) -> &Partition {
        &self.partition
    }

    /// The nodal coefficients.
    pub fn coefficients(&self) -> &[Vec3] {
        &self.coef
    }

    /// `σ` and its exact partials up to second order at `(x, y)` (outside `Ω`: the nearest
    /// element's bicubic).
    pub fn evaluate(&self, x: f64, y: f64) -> Partials {
        let p = &self.partition;
        let (i, j) = p.locate(x, y);
        let (x0, y0) = (p.xs()[i], p.ys()[j]);
        let (hx, hy) = (p.xs()[i + 1] - x0, p.ys()[j + 1] - y0);
        let gx = hermite_1d((x - x0) / hx, hx);
        let gy = hermite_1d((y - y0) / hy, hy);
        let dofs = p.element_dofs(i, j);
        let mut out = [Vec3::zeros(); 6];
        for b in 0..2 {
            for a in 0..2 {
                for q in 0..2 {
                    for pp in 0..2 {
                        let c = self.coef[dofs[4 * (a + 2 * b) + pp + 2 * q]];
                        let (ix, iy) = (2 * a + pp, 2 * b + q);
                        for (m, &(rx, ry)) in super::element::W_ORDERS.iter().enumerate() {
                            out[m] += c * (gx[rx][ix] * gy[ry][iy]);
                        }
                    }
                }
            }
        }
        Partials {
            x: out[0],
            xu: out[1],
            xv: out[2],
            xuu: out[3],
            xuv: out[4],
            xvv: out[5],
        }
    }

    /// Element `(i, j)` in Bézier form (exact conversion of the Hermite data).
    pub fn bezier_patch(&self, i: usize, j: usize) -> BezierPatch {
        let p = &self.partition;
        let (hx, hy) = (p.xs()[i + 1] - p.xs()[i], p.ys()[j + 1] - p.ys()[j]);
        let dofs = p.element_dofs(i, j);
        // g[α][β], α = 2a + p, β = 2b + q: hxᵖ hy^q ∂xᵖ∂y^q σ at corner (a, b).
        let mut g = [[Vec3::zeros(); 4]; 4];
        for b in 0..2 {
            for a in 0..2 {
                for q in 0..2 {
                    for pp in 0..2 {
                        let c = self.coef[dofs[4 * (a + 2 * b) + pp + 2 * q]];
                        g[2 * a + pp][2 * b + q] = c * (hx.powi(pp as i32) * hy.powi(q as i32));
                    }
                }
            }
        }
        let m = &HERMITE_TO_BEZIER;
        let mut control = [[Vec3::zeros(); 4]; 4];
        for (ci, row) in control.iter_mut().enumerate() {
            for (cj, cell) in row.iter_mut().enumerate() {
                let mut acc = Vec3::zeros();
                for al in 0..4 {
                    for be in 0..4 {
                        let w = m[ci][al] * m[cj][be];
                        if w != 0.0 {
                            acc += g[al][be] * w;
                        }
                    }
                }
                *cell = acc;
            }
        }
        BezierPatch {
            x: [p.xs()[i], p.xs()[i + 1]],
            y: [p.ys()[j], p.ys()[j + 1]],
            control,
        }
    }

    /// Every element in Bézier form, row-major (`e = j·nx + i`).
    pub fn bezier_patches(&self) -> Vec<BezierPatch> {
        let p = &self.partition;
        let mut out = Vec::with_capacity(p.elements());
        for j in 0..p.ny() {
            for i in 0..p.nx() {
                out.push(self.bezier_patch(i, j));
            }
        }
        out
    }

    /// The spline as one C¹ bicubic B-spline with double interior knots: its control points are
    /// the inner Bézier points `b₁, b₂` of every element span plus the two end points (the
    /// Bézier junction points are the C¹ combinations of their neighbours).
    pub fn bspline(&self) -> BSplineNet {
        let p = &self.partition;
        let knots = |b: &[f64]| {
            let n = b.len() - 1;
            let mut k = vec![b[0]; 4];
            for &t in &b[1..n] {
                k.push(t);
                k.push(t);
            }
            k.extend([b[n]; 4]);
            k
        };
        // Control index I → (element, Bézier index).
        let map = |idx: usize, n: usize| {
            if idx == 0 {
                (0, 0)
            } else if idx == 2 * n + 1 {
                (n - 1, 3)
            } else {
                ((idx - 1) / 2, 1 + (idx - 1) % 2)
            }
        };
        let patches = self.bezier_patches();
        let (nx, ny) = (p.nx(), p.ny());
        let control = (0..2 * nx + 2)
            .map(|ci| {
                let (ei, bi) = map(ci, nx);
                (0..2 * ny + 2)
                    .map(|cj| {
                        let (ej, bj) = map(cj, ny);
                        patches[ej * nx + ei].control[bi][bj]
                    })
                    .collect()
            })
            .collect();
        BSplineNet {
            knots_x: knots(p.xs()),
            knots_y: knots(p.ys()),
            control,
        }
    }

    /// The control nets as JSON: `{"parameters": …, "bezier": [{x, y, control}], "bspline":
    /// {degree, knots_x, knots_y, control}}`, every control point `[X, Y, Z]`, `control[i][j]`
    /// with `i` along `x`.
    pub fn control_net_json(&self) -> String {
        let v3 = |v: &Vec3| serde_json::json!([v.x, v.y, v.z]);
        let bezier: Vec<_> = self
            .bezier_patches()
            .iter()
            .map(|b| {
                serde_json::json!({
                    "x": b.x,
                    "y": b.y,
                    "control": b.control.iter().map(|r| r.iter().map(v3).collect::<Vec<_>>()).collect::<Vec<_>>(),
                })
            })
            .collect();
        let bs = self.bspline();
        let value = serde_json::json!({
            "parameters": "x = u and y = v on [0, 1]²; control[i][j] with i along x",
            "elements": [self.partition.nx(), self.partition.ny()],
            "periodic_x": self.partition.periodic_x(),
            "bezier": bezier,
            "bspline": {
                "degree": 3,
                "knots_x": bs.knots_x,
                "knots_y": bs.knots_y,
                "control": bs.control.iter().map(|r| r.iter().map(v3).collect::<Vec<_>>()).collect::<Vec<_>>(),
            }
        });
        let mut s = serde_json::to_string_pretty(&value).unwrap_or_default();
        s.push('\n');
        s
    }
}

impl Surface for BfsSurface {
    fn v_domain(&self) -> VDomain {
        VDomain::Interval(0.0, 1.0)
    }
    /// Closed in `u = x` when the partition is periodic in `x` (a tube).
    fn u_periodic(&self) -> bool {
        self.partition.periodic_x()
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        self.evaluate(u, v)
    }
}
