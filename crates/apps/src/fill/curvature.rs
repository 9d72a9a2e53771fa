//! The mesh's second fundamental form at a vertex, for G2 fills: a least-squares quadric
//! height field over the vertex's two rings of neighbours, in the frame of its normal.

use crate::Vec3;
use nalgebra::{Matrix3, Matrix5, Vector5};

/// The second fundamental form at one vertex, with respect to its unit normal `n`: for a
/// tangent vector `w`, `II(w, w) = w · (h w)` with `h` the height field's Hessian.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Form {
    n: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// Hessian entries `h_11`, `h_12`, `h_22`.
    h: [f64; 3],
}

impl Form {
    /// `II(w, w)`: the normal component of the acceleration of a curve with velocity `w`.
    pub(crate) fn at(&self, w: Vec3) -> f64 {
        let (a, b) = (w.dot(&self.e1), w.dot(&self.e2));
        self.h[0] * a * a + 2.0 * self.h[1] * a * b + self.h[2] * b * b
    }

    /// The form as a symmetric tensor of space: `II(w, w) = wᵀ M w` for tangent `w`.
    pub(crate) fn tensor(&self) -> Matrix3<f64> {
        let (a, b) = (self.e1, self.e2);
        a * a.transpose() * self.h[0]
            + (a * b.transpose() + b * a.transpose()) * self.h[1]
            + b * b.transpose() * self.h[2]
    }

    /// The form of the tensor `m` restricted to the plane square to the unit `normal`.
    pub(crate) fn from_tensor(normal: Vec3, m: &Matrix3<f64>) -> Form {
        let (e1, e2) = frame(normal);
        let h = |x: &Vec3, y: &Vec3| x.dot(&(m * y));
        Form {
            n: normal,
            e1,
            e2,
            h: [h(&e1, &e1), h(&e1, &e2), h(&e2, &e2)],
        }
    }

    /// The unit normal the form refers to.
    pub(crate) fn normal(&self) -> Vec3 {
        self.n
    }
}

/// The form at `vertex`, from `z = d x + e y + (h11 x² + 2 h12 xy + h22 y²)/2` fitted to the
/// heights of the vertex's one- and two-ring neighbours (`rings`: for each vertex, its
/// neighbours) above the tangent plane of `normal`, weighted by `1/|p|²` so nearer neighbours
/// count more. The linear terms absorb an error in the normal. `None` with fewer than five
/// neighbours or a singular fit.
pub(crate) fn form(
    positions: &[Vec3],
    rings: &dyn Fn(u32) -> Vec<u32>,
    vertex: u32,
    normal: Vec3,
) -> Option<Form> {
    let o = positions[vertex as usize];
    let (e1, e2) = frame(normal);
    let mut near: Vec<u32> = Vec::new();
    for v in rings(vertex) {
        near.push(v);
        near.extend(rings(v));
    }
    near.sort_unstable();
    near.dedup();
    near.retain(|&v| v != vertex);
    if near.len() < 5 {
        return None;
    }
    let mut ata = Matrix5::<f64>::zeros();
    let mut atb = Vector5::<f64>::zeros();
    for &v in &near {
        let d = positions[v as usize] - o;
        let (x, y, z) = (d.dot(&e1), d.dot(&e2), d.dot(&normal));
        let w = 1.0 / (x * x + y * y).max(f64::MIN_POSITIVE);
        let row = Vector5::new(x, y, 0.5 * x * x, x * y, 0.5 * y * y);
        ata += row * row.transpose() * w;
        atb += row * (z * w);
    }
    let c = ata.cholesky()?.solve(&atb);
    c.iter().all(|v| v.is_finite()).then_some(Form {
        n: normal,
        e1,
        e2,
        h: [c[2], c[3], c[4]],
    })
}

/// Two unit vectors square to the unit `normal` and to each other.
fn frame(normal: Vec3) -> (Vec3, Vec3) {
    let helper = if normal.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let e1 = normal.cross(&helper).normalize();
    (e1, normal.cross(&e1))
}
