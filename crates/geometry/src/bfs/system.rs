//! Sparse assembly of the discrete PDE spline (seed 004 §5) with the fixed degrees of freedom
//! eliminated, and its Cholesky factorisation (faer) with the symbolic analysis kept.

use super::element::{element_matrix, shape_values, shape_w, GAUSS4};
use super::{BfsSurface, Energy, Partition};
use crate::{Error, Result, Vec3};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Mat, Side};
use std::collections::HashMap;

const NONE: u32 = u32::MAX;

/// The pattern and symbolic Cholesky analysis of the reduced system `C_ff` for one partition and
/// one set of fixed degrees of freedom. The pattern couples every pair of free degrees of freedom
/// of a common element, which covers `εR` and every `AᵀA` whatever the data points, so one
/// analysis serves any data, ε, energy and prescribed values.
pub struct SplineSystem {
    partition: Partition,
    fixed: Vec<bool>,
    /// Reduced index of each global degree of freedom, `NONE` if fixed.
    free: Vec<u32>,
    nfree: usize,
    /// Global degrees of freedom of every element (row-major in `(i, j)`: `e = j·nx + i`).
    elem_dofs: Vec<[u32; 16]>,
    pattern: SymbolicSparseColMat<usize>,
    /// Per element, `16 × 16` positions in the lower-triangle values (`NONE`: not stored there).
    scatter: Vec<u32>,
    symbolic: SymbolicLlt<usize>,
}

/// A data site located in its element: the element and the 16 shape-function values there.
#[derive(Clone, Debug)]
struct Site {
    elem: usize,
    phi: [f64; 16],
}

/// A numeric factorisation of `C_ff = (AᵀA + εR)_ff` for fixed data sites, ε and energy; solves
/// for any data values, prescribed values and load.
pub struct SplineFactor<'s> {
    system: &'s SplineSystem,
    epsilon: f64,
    sites: Vec<Site>,
    /// Index of each element's matrix in `matrices`.
    elem_matrix: Vec<usize>,
    matrices: Vec<[[f64; 16]; 16]>,
    llt: Llt<usize, f64>,
}

impl SplineSystem {
    /// Analyses the system for `partition` with the global degrees of freedom flagged in `fixed`
    /// (length [`Partition::dofs`]) prescribed. Fails if every degree of freedom is fixed.
    pub fn new(partition: Partition, fixed: &[bool]) -> Result<Self> {
        let ndofs = partition.dofs();
        if fixed.len() != ndofs {
            return Err(Error::invalid(format!(
                "{} fixed-dof flags for a space of {ndofs} degrees of freedom",
                fixed.len()
            )));
        }
        let mut free = vec![NONE; ndofs];
        let mut nfree = 0usize;
        for (d, &f) in fixed.iter().enumerate() {
            if !f {
                free[d] = nfree as u32;
                nfree += 1;
            }
        }
        if nfree == 0 {
            return Err(Error::invalid(
                "every degree of freedom is fixed: nothing to solve for",
            ));
        }
        let (nx, ny) = (partition.nx(), partition.ny());
        let mut elem_dofs = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                elem_dofs.push(partition.element_dofs(i, j).map(|d| d as u32));
            }
        }
        // Lower-triangle pattern: for every column c the rows r ≥ c sharing an element.
        let mut cols: Vec<Vec<u32>> = vec![Vec::new(); nfree];
        for dofs in &elem_dofs {
            for &a in dofs {
                let ra = free[a as usize];
                if ra == NONE {
                    continue;
                }
                for &b in dofs {
                    let rb = free[b as usize];
                    if rb != NONE && rb >= ra {
                        cols[ra as usize].push(rb);
                    }
                }
            }
        }
        let mut col_ptr = Vec::with_capacity(nfree + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0usize);
        for c in &mut cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend(c.iter().map(|&r| r as usize));
            col_ptr.push(row_idx.len());
        }
        drop(cols);
        let mut scatter = vec![NONE; elem_dofs.len() * 256];
        for (e, dofs) in elem_dofs.iter().enumerate() {
            for (l, &a) in dofs.iter().enumerate() {
                let ra = free[a as usize];
                if ra == NONE {
                    continue;
                }
                for (l2, &b) in dofs.iter().enumerate() {
                    let rb = free[b as usize];
                    // Entry (row ra, column rb) of the lower triangle: ra ≥ rb.
                    if rb == NONE || ra < rb {
                        continue;
                    }
                    let (lo, hi) = (col_ptr[rb as usize], col_ptr[rb as usize + 1]);
                    let k = row_idx[lo..hi]
                        .binary_search(&(ra as usize))
                        .map_err(|_| Error::invalid("internal: sparsity pattern incomplete"))?;
                    scatter[e * 256 + 16 * l + l2] = (lo + k) as u32;
                }
            }
        }
        if row_idx.len() >= NONE as usize {
            return Err(Error::invalid(format!(
                "the system has {} non-zeros, beyond the supported size",
                row_idx.len()
            )));
        }
        let pattern = SymbolicSparseColMat::new_checked(nfree, nfree, col_ptr, None, row_idx);
        let symbolic = SymbolicLlt::try_new(pattern.as_ref(), Side::Lower)
            .map_err(|e| Error::invalid(format!("sparse analysis failed: {e:?}")))?;
        Ok(SplineSystem {
            partition,
            fixed: fixed.to_vec(),
            free,
            nfree,
            elem_dofs,
            pattern,
            scatter,
            symbolic,
        })
    }

    /// The partition.
    pub fn partition(&self) -> &Partition {
        &self.partition
    }

    /// Number of free (unknown) degrees of freedom.
    pub fn free_dofs(&self) -> usize {
        self.nfree
    }

    /// Stored non-zeros of the lower triangle of `C_ff`.
    pub fn nonzeros(&self) -> usize {
        self.pattern.row_idx().len()
    }

    /// Factorises `C_ff = (AᵀA + εR)_ff` for the data sites `sites` (points of `Ω`, the paper's
    /// `A`), the weight `ε > 0` and the energy, reusing the symbolic analysis. Fails (as not
    /// unique) when the fixed degrees of freedom and the sites do not determine an affine
    /// function (the kernel of a pure second-order energy: the paper's `P₁`-unisolvence).
    pub fn factor(
        &self,
        energy: &Energy,
        epsilon: f64,
        sites: &[[f64; 2]],
    ) -> Result<SplineFactor<'_>> {
        if !(epsilon.is_finite() && epsilon > 0.0) {
            return Err(
                Error::invalid(format!("must be positive and finite (got {epsilon})"))
                    .at("epsilon"),
            );
        }
        let p = &self.partition;
        let mut located = Vec::with_capacity(sites.len());
        for (k, s) in sites.iter().enumerate() {
            let [x, y] = *s;
            if !((0.0..=1.0).contains(&x) && (0.0..=1.0).contains(&y)) {
                return Err(Error::invalid(format!(
                    "the site ({x}, {y}) lies outside Ω = [0, 1]²"
                ))
                .at(&format!("points[{k}]")));
            }
            let (i, j) = p.locate(x, y);
            let (x0, y0) = (p.xs()[i], p.ys()[j]);
            let (hx, hy) = (p.xs()[i + 1] - x0, p.ys()[j + 1] - y0);
            located.push(Site {
                elem: j * p.nx() + i,
                phi: shape_values((x - x0) / hx, (y - y0) / hy, hx, hy),
            });
        }
        if energy.is_pure_second_order() {
            self.check_unisolvent(sites)?;
        }
        // Element matrices, one per distinct element size.
        let mut cache: HashMap<(u64, u64), usize> = HashMap::new();
        let mut matrices = Vec::new();
        let mut elem_matrix = Vec::with_capacity(p.elements());
        for j in 0..p.ny() {
            let hy = p.ys()[j + 1] - p.ys()[j];
            for i in 0..p.nx() {
                let hx = p.xs()[i + 1] - p.xs()[i];
                let key = (hx.to_bits(), hy.to_bits());
                let idx = *cache.entry(key).or_insert_with(|| {
                    matrices.push(element_matrix(energy, hx, hy));
                    matrices.len() - 1
                });
                elem_matrix.push(idx);
            }
        }
        let mut vals = vec![0.0f64; self.nonzeros()];
        for (e, &mi) in elem_matrix.iter().enumerate() {
            let k = &matrices[mi];
            let sc = &self.scatter[e * 256..(e + 1) * 256];
            for l in 0..16 {
                for l2 in 0..16 {
                    let pos = sc[16 * l + l2];
                    if pos != NONE {
                        vals[pos as usize] += epsilon * k[l][l2];
                    }
                }
            }
        }
        for s in &located {
            let sc = &self.scatter[s.elem * 256..(s.elem + 1) * 256];
            for l in 0..16 {
                for l2 in 0..16 {
                    let pos = sc[16 * l + l2];
                    if pos != NONE {
                        vals[pos as usize] += s.phi[l] * s.phi[l2];
                    }
                }
            }
        }
        let mat = SparseColMatRef::new(self.pattern.as_ref(), &vals);
        let llt =
            Llt::try_new_with_symbolic(self.symbolic.clone(), mat, Side::Lower).map_err(|_| {
                Error::not_unique(
                    "the system (AᵀA + εR) restricted to the free degrees of freedom is not \
                     positive definite",
                )
            })?;
        Ok(SplineFactor {
            system: self,
            epsilon,
            sites: located,
            elem_matrix,
            matrices,
            llt,
        })
    }

    /// The paper's condition "A ∪ B contains a P₁-unisolvent subset", for the degrees of freedom
    /// actually fixed: the affine functions `c₀ + c₁x + c₂y` vanishing at the sites and on every
    /// fixed degree of freedom must be zero. Checked on the 3 × 3 Gram matrix of the
    /// (normalised) conditions.
    fn check_unisolvent(&self, sites: &[[f64; 2]]) -> Result<()> {
        let p = &self.partition;
        let mut gram = nalgebra::Matrix3::<f64>::zeros();
        let mut add = |r: nalgebra::Vector3<f64>| {
            let n = r.norm();
            if n > 0.0 {
                let r = r / n;
                gram += r * r.transpose();
            }
        };
        for &[x, y] in sites {
            add(nalgebra::Vector3::new(1.0, x, y));
        }
        for j in 0..=p.ny() {
            for i in 0..p.node_columns() {
                let (x, y) = (p.xs()[i], p.ys()[j]);
                for (k, row) in [
                    nalgebra::Vector3::new(1.0, x, y),
                    nalgebra::Vector3::new(0.0, 1.0, 0.0),
                    nalgebra::Vector3::new(0.0, 0.0, 1.0),
                ]
                .into_iter()
                .enumerate()
                {
                    if self.fixed[p.dof(i, j, k)] {
                        add(row);
                    }
                }
            }
        }
        let ev = gram.symmetric_eigenvalues();
        if ev.min() <= 1e-10 * ev.amax().max(1.0) {
            return Err(Error::not_unique(
                "the data points and the fixed degrees of freedom do not determine an affine \
                 function (the energy vanishes on affine functions): give at least three \
                 non-collinear points or fix boundary values",
            ));
        }
        Ok(())
    }
}

impl SplineFactor<'_> {
    /// The system this factorisation belongs to.
    pub fn system(&self) -> &SplineSystem {
        self.system
    }

    /// Solves Theorem 5's variational problem for the data values `beta` (one per site, the
    /// paper's `β`), the prescribed values `dof_values` of the fixed degrees of freedom (length
    /// [`Partition::dofs`]; entries of free degrees of freedom are ignored) and the load `f` of
    /// `(f, v)_0` (none: `f = 0`). The three coordinates share the factorisation. The load
    /// integrals use the 4 × 4 Gauss rule per element.
    pub fn solve(
        &self,
        beta: &[Vec3],
        dof_values: &[Vec3],
        load: Option<&(dyn Fn(f64, f64) -> Vec3 + Sync)>,
    ) -> Result<BfsSurface> {
        let sys = self.system;
        let p = &sys.partition;
        if beta.len() != self.sites.len() {
            return Err(Error::invalid(format!(
                "{} data values for {} data points",
                beta.len(),
                self.sites.len()
            )));
        }
        if dof_values.len() != p.dofs() {
            return Err(Error::invalid(format!(
                "{} prescribed values for a space of {} degrees of freedom",
                dof_values.len(),
                p.dofs()
            )));
        }
        for (d, v) in dof_values.iter().enumerate() {
            if sys.fixed[d] && !v.iter().all(|x| x.is_finite()) {
                return Err(Error::invalid(format!(
                    "the prescribed value of degree of freedom {d} is not finite: {v:?}"
                )));
            }
        }
        for (k, b) in beta.iter().enumerate() {
            if !b.iter().all(|x| x.is_finite()) {
                return Err(
                    Error::invalid(format!("is not finite: {b:?}")).at(&format!("points[{k}]"))
                );
            }
        }
        let mut rhs = Mat::<f64>::zeros(sys.nfree, 3);
        let eps = self.epsilon;
        // −ε R_fc y
        for (e, dofs) in sys.elem_dofs.iter().enumerate() {
            let k = &self.matrices[self.elem_matrix[e]];
            for l in 0..16 {
                let ra = sys.free[dofs[l] as usize];
                if ra == NONE {
                    continue;
                }
                let mut acc = Vec3::zeros();
                for l2 in 0..16 {
                    let d = dofs[l2] as usize;
                    if sys.free[d] == NONE {
                        acc += k[l][l2] * dof_values[d];
                    }
                }
                for c in 0..3 {
                    rhs[(ra as usize, c)] -= eps * acc[c];
                }
            }
        }
        // Aᵀ (β − A_c y)
        for (s, b) in self.sites.iter().zip(beta) {
            let dofs = &sys.elem_dofs[s.elem];
            let mut resid = *b;
            for l in 0..16 {
                let d = dofs[l] as usize;
                if sys.free[d] == NONE {
                    resid -= s.phi[l] * dof_values[d];
                }
            }
            for l in 0..16 {
                let ra = sys.free[dofs[l] as usize];
                if ra != NONE {
                    for c in 0..3 {
                        rhs[(ra as usize, c)] += s.phi[l] * resid[c];
                    }
                }
            }
        }
        // ε (f, ω_i)_0
        if let Some(f) = load {
            for j in 0..p.ny() {
                let (y0, hy) = (p.ys()[j], p.ys()[j + 1] - p.ys()[j]);
                for i in 0..p.nx() {
                    let (x0, hx) = (p.xs()[i], p.xs()[i + 1] - p.xs()[i]);
                    let dofs = &sys.elem_dofs[j * p.nx() + i];
                    for &(t, wt) in &GAUSS4 {
                        for &(s, ws) in &GAUSS4 {
                            let fv = f(x0 + s * hx, y0 + t * hy) * (ws * wt * hx * hy * eps);
                            if !fv.iter().all(|x| x.is_finite()) {
                                return Err(Error::invalid(format!(
                                    "the load is not finite at ({}, {})",
                                    x0 + s * hx,
                                    y0 + t * hy
                                )));
                            }
                            let w = shape_w(s, t, hx, hy);
                            for l in 0..16 {
                                let ra = sys.free[dofs[l] as usize];
                                if ra != NONE {
                                    for c in 0..3 {
                                        rhs[(ra as usize, c)] += w[l][0] * fv[c];
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        self.llt.solve_in_place(rhs.as_mut());
        let mut coef = Vec::with_capacity(p.dofs());
        for (d, v) in dof_values.iter().enumerate() {
            let r = sys.free[d];
            coef.push(if r == NONE {
                *v
            } else {
                let r = r as usize;
                Vec3::new(rhs[(r, 0)], rhs[(r, 1)], rhs[(r, 2)])
            });
        }
        if coef.iter().any(|c| !c.iter().all(|x| x.is_finite())) {
            return Err(Error::not_unique(
                "the spline's coefficients are not finite (the system is numerically singular)",
            ));
        }
        Ok(BfsSurface::new(p.clone(), coef))
    }
}
