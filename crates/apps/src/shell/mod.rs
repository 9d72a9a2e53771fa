//! Thin-shell strength analysis of designs with CalculiX.
//!
//! [`ShellMesh`] meshes a design's surfaces with quadratic shell elements, [`ShellModel`] adds
//! thickness, material, clamped edges and loads and writes the input deck, [`run_ccx`] runs the
//! solver, [`read_frd`] reads its nodal results back, and [`max_shear`] finds the largest shear
//! stress `(σ₁ − σ₃)/2` over the structure (the book's Eq. 7.7).

mod deck;
mod frd;
mod material;
mod mesh;
mod output;
mod run;
mod setup;
mod stress;

pub use deck::{LineLoad, ShellModel};
pub use frd::{read_frd, FrdResults};
pub use material::Material;
pub use mesh::{Element, ShellMesh, Side, MAX_NODES};
pub use output::{csv, vtu};
pub use run::{run_ccx, RunOptions, RunOutput};
pub use setup::{
    LoadSetup, ShellSetup, BOOK_LINE_LOAD, DEFAULT_ELEMENTS, DEFAULT_THICKNESS, MAX_ELEMENTS,
};
pub use stress::{max_shear, principal_stresses, MaxShear};

use crate::{Error, Result};
use std::time::Instant;

/// The result of one analysis, per shell node (in the mesh's node order).
#[derive(Clone, Debug)]
pub struct ShellReport {
    /// Largest shear stress `(σ₁ − σ₃)/2` at each shell node, the largest over the wall's
    /// thickness (inner surface, mid-surface, outer surface) (Pa).
    pub max_shear: Vec<f64>,
    /// The mid-surface stress `[sxx, syy, szz, sxy, syz, szx]` at each node (Pa).
    pub mid_stress: Vec<[f64; 6]>,
    /// Mid-surface displacement at each node (m).
    pub displacement: Vec<[f64; 3]>,
    /// The largest of `max_shear` and the node where it occurs.
    pub peak: MaxShear,
    /// Seconds spent writing the deck.
    pub deck_seconds: f64,
    /// Seconds spent in the solver.
    pub solver_seconds: f64,
    /// Seconds spent reading the results back onto the shell nodes.
    pub read_seconds: f64,
}

/// Writes the deck of `model`, runs CalculiX and reads the stresses back onto the shell nodes.
pub fn analyse(model: &ShellModel, options: &RunOptions) -> Result<ShellReport> {
    if !(model.thickness > 0.0 && model.thickness.is_finite()) {
        return Err(
            Error::invalid(format!("must be positive (got {})", model.thickness)).at("thickness"),
        );
    }
    let t0 = Instant::now();
    let deck = model.deck();
    let deck_seconds = t0.elapsed().as_secs_f64();
    let out = run_ccx(&deck, options)?;
    let t1 = Instant::now();
    let frd = read_frd(&out.frd)?;
    let report = map_to_shell(model, &frd)?;
    Ok(ShellReport {
        deck_seconds,
        solver_seconds: out.seconds,
        read_seconds: t1.elapsed().as_secs_f64(),
        ..report
    })
}

/// CalculiX expands every shell node into nodes on the inner and outer surfaces (and the
/// mid-surface for corner nodes), at `∓t/2` along its normal, and reports results there. Each
/// expanded node goes back to the nearest shell node (at `t/2` or `0`, refused beyond `0.75 t`,
/// which happens only for meshes finer than the wall is thick).
pub fn map_to_shell(model: &ShellModel, frd: &FrdResults) -> Result<ShellReport> {
    use rstar::{primitives::GeomWithData, RTree};
    let m = &model.mesh;
    let tree: RTree<GeomWithData<[f64; 3], usize>> = RTree::bulk_load(
        m.nodes
            .iter()
            .enumerate()
            .map(|(i, p)| GeomWithData::new(*p, i))
            .collect(),
    );
    let n = m.nodes.len();
    let mut max_shear = vec![f64::NEG_INFINITY; n];
    // The mid-surface value: the expanded node on it (corner nodes), else the mean of the two
    // surfaces (mid-side nodes).
    let mut on_mid: Vec<Option<[f64; 6]>> = vec![None; n];
    let mut sum = vec![[0.0; 6]; n];
    let mut count = vec![0usize; n];
    let mut displacement = vec![[0.0; 3]; n];
    let mut disp_count = vec![0usize; n];
    let limit = 0.75 * model.thickness;
    for (id, p) in &frd.nodes {
        let Some(near) = tree.nearest_neighbor(p) else {
            continue;
        };
        let q = near.geom();
        let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
        if d > limit {
            return Err(Error::invalid(format!(
                "result node {id} lies {d:.3e} m from the nearest shell node (more than 0.75 × the \
                 thickness): the mesh is finer than the wall is thick; use fewer elements"
            )));
        }
        let k = near.data;
        if let Some(s) = frd.stresses.get(id) {
            let p = principal_stresses(*s);
            max_shear[k] = max_shear[k].max((p[0] - p[2]) / 2.0);
            if d < 1e-3 * model.thickness {
                on_mid[k] = Some(*s);
            }
            for c in 0..6 {
                sum[k][c] += s[c];
            }
            count[k] += 1;
        }
        if let Some(u) = frd.displacements.get(id) {
            for c in 0..3 {
                displacement[k][c] += u[c];
            }
            disp_count[k] += 1;
        }
    }
    if let Some(k) = (0..n).find(|&k| count[k] == 0) {
        return Err(Error::invalid(format!(
            "the result file has no stress for shell node {}",
            k + 1
        )));
    }
    let mut mid_stress = vec![[0.0; 6]; n];
    for k in 0..n {
        let c = count[k] as f64;
        mid_stress[k] = on_mid[k].unwrap_or(sum[k].map(|x| x / c));
        let c = disp_count[k].max(1) as f64;
        displacement[k] = displacement[k].map(|x| x / c);
    }
    let peak = max_shear
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(node, &value)| MaxShear { value, node })
        .ok_or_else(|| Error::invalid("the shell model has no node"))?;
    Ok(ShellReport {
        max_shear,
        mid_stress,
        displacement,
        peak,
        deck_seconds: 0.0,
        solver_seconds: 0.0,
        read_seconds: 0.0,
    })
}
