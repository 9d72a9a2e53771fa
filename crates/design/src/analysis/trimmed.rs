//! Integrals over a trimmed parameter domain ([`crate::trim::ParamMesh`]): area and the
//! divergence-theorem volume share of what remains of a surface after its holes are cut.

use super::Integrals;
use crate::design::SolvedDesign;
use crate::surface::Surface;
use crate::trim::ParamMesh;
use rayon::prelude::*;

/// Radon's 7-point rule on a triangle (exact for polynomials of degree 5): barycentric points
/// and weights summing to 1.
fn radon7() -> [([f64; 3], f64); 7] {
    let s = 15f64.sqrt();
    let (a1, a2) = ((6.0 - s) / 21.0, (6.0 + s) / 21.0);
    let (w1, w2) = ((155.0 - s) / 1200.0, (155.0 + s) / 1200.0);
    let c = 1.0 / 3.0;
    [
        ([c, c, c], 9.0 / 40.0),
        ([a1, a1, 1.0 - 2.0 * a1], w1),
        ([a1, 1.0 - 2.0 * a1, a1], w1),
        ([1.0 - 2.0 * a1, a1, a1], w1),
        ([a2, a2, 1.0 - 2.0 * a2], w2),
        ([a2, 1.0 - 2.0 * a2, a2], w2),
        ([1.0 - 2.0 * a2, a2, a2], w2),
    ]
}

/// `A = ∫ dA` and `V = (1/3) ∫ X·n dA` over the triangles of `pm` in `(u, v)` (each mapped
/// exactly through the surface, with the exact area element `|X_u × X_v|`, by Radon's degree-5
/// rule on each parameter triangle). The domain's boundary along a trim is the polygon of the
/// mesh's trim vertices, so the result converges like the chords: `O(h²)` in the grid spacing.
/// The curvature integrals are left at zero.
pub fn integrate_trimmed(s: &dyn Surface, pm: &ParamMesh) -> Integrals {
    let rule = radon7();
    let periodic = s.v_domain().is_periodic();
    const CHUNK: usize = 4096;
    let sums: Vec<(f64, f64)> = (0..pm.triangles.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let (mut area, mut volume) = (0.0, 0.0);
            for k in c * CHUNK..((c + 1) * CHUNK).min(pm.triangles.len()) {
                let [a, b, c] = pm.triangle_uv(k, periodic);
                let jac =
                    ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs() * 0.5;
                for (l, w) in rule {
                    let u = l[0] * a[0] + l[1] * b[0] + l[2] * c[0];
                    let v = l[0] * a[1] + l[1] * b[1] + l[2] * c[1];
                    let p = s.partials(u, v);
                    let n = p.xu.cross(&p.xv);
                    area += w * jac * n.norm();
                    volume += w * jac * p.x.dot(&n) / 3.0;
                }
            }
            (area, volume)
        })
        .collect();
    // Summed in a fixed order: the result does not depend on the thread count.
    let mut out = Integrals::default();
    for (a, v) in sums {
        out.area += a;
        out.volume += v;
    }
    out
}

/// The area and volume share of what remains of one trimmed surface of a design.
#[derive(Clone, Debug, PartialEq)]
pub struct TrimmedIntegrals {
    /// The surface's name.
    pub name: String,
    /// The area that remains, by [`integrate_trimmed`] on the finer of the two grids.
    pub area: f64,
    /// The remainder's share `(1/3)∫X·n dA` of the enclosed volume on the finer grid, with the
    /// design's outward normal (the orientation passed in), as the untrimmed patches' volumes
    /// are reported.
    pub volume: f64,
    /// The change of the area between the two grids (the error of the coarser; the finer's is
    /// about a quarter of it, the chords converging at second order).
    pub area_change: f64,
    /// The two grids `[nu, nv]`.
    pub grids: [[usize; 2]; 2],
}

/// [`integrate_trimmed`] of every trimmed surface of a design on the `nu × nv` grid and on the
/// grid twice as fine (`(2nu − 1) × 2nv`), reporting the finer. `orientation` is, per surface,
/// `+1` if the design's outward normal is `X_u × X_v` and `−1` if it is the reverse
/// ([`super::DesignIntegrals::orientation`]); the volume share is turned by it.
pub fn integrate_trimmed_design(
    d: &SolvedDesign,
    nu: usize,
    nv: usize,
    orientation: &[f64],
) -> crate::Result<Vec<TrimmedIntegrals>> {
    let (nu2, nv2) = (2 * nu - 1, 2 * nv);
    let coarse = d.param_meshes(nu, nv)?;
    let fine = d.param_meshes(nu2, nv2)?;
    let mut out = Vec::new();
    for (k, (c, f)) in coarse.iter().zip(&fine).enumerate() {
        let (Some(c), Some(f)) = (c, f) else {
            continue;
        };
        let s = d.surfaces[k].surface();
        let (ic, i_f) = (integrate_trimmed(s, c), integrate_trimmed(s, f));
        let sign = orientation.get(k).copied().unwrap_or(1.0);
        out.push(TrimmedIntegrals {
            name: d.surfaces[k].name.clone(),
            area: i_f.area,
            volume: sign * i_f.volume,
            area_change: (i_f.area - ic.area).abs(),
            grids: [[nu, nv], [nu2, nv2]],
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radon_rule_is_exact_to_degree_five() {
        // ∫ x^i y^j over the unit triangle = i! j! / (i + j + 2)!.
        let fact = |n: u32| (1..=n).map(f64::from).product::<f64>();
        for i in 0..=5u32 {
            for j in 0..=5 - i {
                let exact = fact(i) * fact(j) / fact(i + j + 2);
                let got: f64 = radon7()
                    .iter()
                    .map(|(l, w)| 0.5 * w * l[1].powi(i as i32) * l[2].powi(j as i32))
                    .sum();
                assert!((got - exact).abs() < 1e-15, "x^{i} y^{j}: {got} vs {exact}");
            }
        }
    }
}
