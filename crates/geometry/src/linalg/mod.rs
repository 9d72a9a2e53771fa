//! Linear algebra the solvers share: banded LU factorisations (`band`: the dynamic-curve scheme's
//! pentadiagonal systems, the periodic finite-difference solver's per-mode systems) and dense
//! decompositions with iteration caps (`decomp`: SVD, symmetric and general eigenvalues).

pub mod band;
pub(crate) mod decomp;
