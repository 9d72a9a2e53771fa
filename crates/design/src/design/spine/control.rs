//! The Bézier control form of the spine `A₀`: its control points, its Hermite data and the
//! new spine a `[[spine]]` entry asks for.

use crate::elliptic::PdePatch;
use crate::spec::SpineSpec;
use crate::{Error, Result, Vec3};

/// The Bézier control points `P_0 … P_d` (`d = 2N − 1`) of a patch's spine `A₀` on `[0, 1]`.
///
/// For the cubic spine of a biharmonic patch they come from the end values and speeds,
/// `[A₀(0), A₀(0) + A₀'(0)/3, A₀(1) − A₀'(1)/3, A₀(1)]` (the Hermite form of Eq. 5.4 with the
/// corrected Eqs. 5.5–5.8 of `docs/errata.md`); for other degrees by collocation at the `d + 1`
/// Chebyshev–Lobatto points of `[0, 1]` (LU with full pivoting). The collocation matrix of the
/// Bernstein basis grows ill-conditioned with the degree (about 10 for `d = 3`, 10⁴ for
/// `d = 11`): beyond `N ≈ 10` the control points carry correspondingly fewer digits.
pub fn spine_control_points(patch: &PdePatch) -> Vec<Vec3> {
    let d = patch.conditions().len().max(2) - 1;
    if d == 3 {
        let [p0, p1, d0, d1] = spine_hermite_of(patch);
        return vec![p0, p0 + d0 / 3.0, p1 - d1 / 3.0, p1];
    }
    let nodes: Vec<f64> = (0..=d)
        .map(|i| 0.5 * (1.0 - (std::f64::consts::PI * i as f64 / d as f64).cos()))
        .collect();
    let m = nalgebra::DMatrix::from_fn(d + 1, d + 1, |i, j| bernstein(d, j, nodes[i]));
    let rhs = nalgebra::DMatrix::from_fn(d + 1, 3, |i, c| patch.spine(nodes[i], 0)[c]);
    let sol = m.full_piv_lu().solve(&rhs).unwrap_or(rhs);
    (0..=d)
        .map(|i| Vec3::new(sol[(i, 0)], sol[(i, 1)], sol[(i, 2)]))
        .collect()
}

/// `[p0, p1, d0, d1]`: the spine's end positions and end speeds (its Hermite form, Eq. 5.4).
pub fn spine_hermite_of(patch: &PdePatch) -> [Vec3; 4] {
    [
        patch.spine(0.0, 0),
        patch.spine(1.0, 0),
        patch.spine(0.0, 1),
        patch.spine(1.0, 1),
    ]
}

fn bernstein(d: usize, j: usize, t: f64) -> f64 {
    let binom = (0..j).fold(1.0, |b, i| b * (d - i) as f64 / (i + 1) as f64);
    binom * t.powi(j as i32) * (1.0 - t).powi((d - j) as i32)
}

/// The control points of the new spine a `[[spine]]` table asks for, from the solved patch's
/// own; errors are placed inside the table (`control`, `moves[1].index`, `hermite`).
pub fn spine_target(patch: &PdePatch, spec: &SpineSpec) -> Result<Vec<Vec3>> {
    let solved = spine_control_points(patch);
    let n = solved.len();
    let v3 = |v: &[f64; 3]| Vec3::new(v[0], v[1], v[2]);
    let given = spec.control.is_some() as usize
        + !spec.moves.is_empty() as usize
        + spec.hermite.is_some() as usize;
    if given > 1 || (given == 0 && spec.wave.is_none()) {
        return Err(Error::invalid(format!(
            "give exactly one of `control`, `moves` and `hermite`, or a `wave` (got {given})"
        )));
    }
    if let Some(control) = &spec.control {
        if control.len() != n {
            return Err(Error::invalid(format!(
                "the spine of this patch has degree {} and needs {n} control points (got {})",
                n - 1,
                control.len()
            ))
            .at("control"));
        }
        return Ok(control.iter().map(v3).collect());
    }
    if let Some(h) = &spec.hermite {
        if n != 4 {
            return Err(Error::invalid(format!(
                "a Hermite spine is cubic; the spine of this patch has degree {}: give `control`",
                n - 1
            ))
            .at("hermite"));
        }
        let (p0, p1, d0, d1) = (v3(&h.p0), v3(&h.p1), v3(&h.d0), v3(&h.d1));
        return Ok(vec![p0, p0 + d0 / 3.0, p1 - d1 / 3.0, p1]);
    }
    let mut control = solved;
    for (i, m) in spec.moves.iter().enumerate() {
        let slot = control.get_mut(m.index).ok_or_else(|| {
            Error::invalid(format!(
                "control point {} does not exist (the spine has {n})",
                m.index
            ))
            .at(&format!("moves[{i}].index"))
        })?;
        *slot += v3(&m.by);
    }
    Ok(control)
}
