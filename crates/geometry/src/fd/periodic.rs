//! The periodic problem by a real FFT in `v` and one banded solve per mode in `u`.
//!
//! Every equation of [`PeriodicProblem`]'s system is the same at every node column `j` (the
//! stencil of `L_h^N` at interior rows, the derivative conditions at the boundary and ghost rows,
//! which do not reach across columns), so the matrix is block circulant in `j`. The discrete
//! Fourier transform in `j` splits it: with `X_{i,j} = (1/M) Σ_m X̂_{i,m} e^{2πi mj/M}`, the
//! stencil entry `c(du, dv)` becomes `c(du, dv) e^{2πi m dv/M}`, and because every stencil is
//! symmetric in `dv` (`c(du, dv) = c(du, −dv)`) the mode's matrix is the real banded matrix
//! `A_m[i, i + du] = Σ_dv c(du, dv) cos(2π m dv / M)`. Each mode `m = 0 … M/2` is then one real
//! banded system in `u` (bandwidth `N` in the interior, up to `N + 1` in the boundary rows) with
//! six right-hand sides (real and imaginary parts of the three components); modes `m` and `M − m`
//! have the same matrix, which the real FFT exploits. The result is the sparse solver's discrete
//! solution, up to rounding (`fd::tests::fft_periodic_solver_equals_the_sparse_one`).
//!
//! Cost for `R = nu + 2N − 1` rows and `M` columns: `3R` real FFTs of length `M` each way
//! (`O(R M log M)`) and `M/2 + 1` banded factorisations of `O(R N²)`: a few milliseconds for
//! 256 × 256, where the sparse LU of the same system takes hundreds.

use super::{data, derivative_stencil, second_difference_power, source, stencil, PeriodicProblem};
use crate::linalg::band::BandMatrix;
use crate::{Error, Result, Vec3, TAU};
use realfft::num_complex::Complex64;
use realfft::RealFftPlanner;

/// The node values `(nu + 1) × nv` (row-major) of the discrete solution.
pub(super) fn solve_modes(p: &PeriodicProblem<'_>) -> Result<Vec<Vec3>> {
    let n = p.order;
    let (nu, mv) = (p.nu, p.nv);
    let g = n - 1;
    let rows = nu + 1 + 2 * g;
    let hu = 1.0 / nu as f64;
    let hv = TAU / mv as f64;
    let st = stencil(n, p.a, hu, hv);
    let scale = hu.powi(2 * n as i32);
    let wide = n == 3;

    // Right-hand sides, row by row (in the sparse solver's order, so that the first non-finite
    // datum reported is the same), component-major within a row: rhs[(r * 3 + c) * mv + j].
    let mut rhs = vec![0.0; rows * 3 * mv];
    let (gi, nui) = (g as isize, nu as isize);
    for (r, i) in (-gi..=nui + gi).enumerate() {
        let u = i as f64 * hu;
        for j in 0..mv {
            let v = j as f64 * hv;
            let val = if (1..nui).contains(&i) {
                source(p.source, u, v)? * scale
            } else {
                let (k, edges, place) = if i <= 0 {
                    ((-i) as usize, &p.start, "start")
                } else {
                    ((i - nui) as usize, &p.end, "end")
                };
                data(edges[k], v, place, k, "v")? * hu.powi(k as i32)
            };
            for c in 0..3 {
                rhs[(r * 3 + c) * mv + j] = val[c];
            }
        }
    }

    // The equations of each row as (column offset, coefficient per mode).
    // Interior rows: the symbol of the stencil in v, per u offset.
    let mut du_offsets: Vec<isize> = st.iter().map(|e| e.0).collect();
    du_offsets.sort_unstable();
    du_offsets.dedup();
    // The symbol of `δ²_v` is `σ_m = −4 sin²(π m / M)`, so that of `h_u^{2N} L_h^N` at u offset
    // `du` is `Σ_k C(N, k) r^k σ_m^k [δ²ᵘ^{N−k}](du)`, `r = (a h_u / h_v)²`: no cancellation,
    // where summing `c(du, dv) cos(2π m dv / M)` would cancel to `O(h²)` for small `m`.
    let r2 = (p.a * hu / hv).powi(2);
    let symbol = |du: isize, m: usize| -> f64 {
        let sigma = -4.0 * (std::f64::consts::PI * m as f64 / mv as f64).sin().powi(2);
        let mut binom = 1.0;
        let mut total = 0.0;
        for k in 0..=n {
            if k > 0 {
                binom = binom * (n + 1 - k) as f64 / k as f64;
            }
            let mu = (n - k) as isize;
            if du.abs() <= mu {
                let cu = second_difference_power(n - k)[(du + mu) as usize];
                total += binom * (r2 * sigma).powi(k as i32) * cu;
            }
        }
        total
    };
    // Boundary and ghost rows: the derivative condition centred on the boundary node.
    let boundary_row = |i: isize| -> Vec<(isize, f64)> {
        let (b, k) = if i <= 0 {
            (0, (-i) as usize)
        } else {
            (nui, (i - nui) as usize)
        };
        if k == 0 {
            vec![(b, 1.0)]
        } else {
            derivative_stencil(k, wide)
                .iter()
                .map(|&(s, c)| (b + s, c))
                .collect()
        }
    };
    // Bandwidths of the rows (row r is node i = r − g).
    let (mut kl, mut ku) = (0usize, 0usize);
    for i in -gi..=nui + gi {
        let cols: Vec<isize> = if (1..nui).contains(&i) {
            du_offsets.iter().map(|d| i + d).collect()
        } else {
            boundary_row(i).iter().map(|e| e.0).collect()
        };
        for c in cols {
            if c < i {
                kl = kl.max((i - c) as usize);
            } else {
                ku = ku.max((c - i) as usize);
            }
        }
    }

    // The banded matrix of every mode, factorised once.
    let modes = mv / 2 + 1;
    let mut factors = Vec::with_capacity(modes);
    for m in 0..modes {
        let mut a = BandMatrix::zeros(rows, kl, ku);
        let sym: Vec<(isize, f64)> = du_offsets.iter().map(|&d| (d, symbol(d, m))).collect();
        for (r, i) in (-gi..=nui + gi).enumerate() {
            if (1..nui).contains(&i) {
                for &(d, c) in &sym {
                    a.set(r, (i + d + gi) as usize, c);
                }
            } else {
                for (col, c) in boundary_row(i) {
                    a.set(r, (col + gi) as usize, c);
                }
            }
        }
        a.factorize().map_err(|_| {
            Error::invalid(format!(
                "the difference system is singular (Fourier mode {m} in v)"
            ))
        })?;
        factors.push(a);
    }
    let modal = Modal::new(mv, rows, factors);

    // Solve, then one step of iterative refinement: the residual of the whole system in working
    // precision, solved again with the same factors (the transforms' rounding is amplified by
    // the mode systems' condition numbers; the refinement brings the solution back to the
    // accuracy of a backward-stable solve of the assembled system).
    let mut x = rhs.clone();
    modal.solve_in_place(&mut x)?;
    let mut res = rhs;
    for (r, i) in (-gi..=nui + gi).enumerate() {
        let row_terms: Vec<(isize, isize, f64)> = if (1..nui).contains(&i) {
            st.clone()
        } else {
            boundary_row(i)
                .into_iter()
                .map(|(col, c)| (col - i, 0, c))
                .collect()
        };
        for c in 0..3 {
            let out = &mut res[(r * 3 + c) * mv..(r * 3 + c + 1) * mv];
            for &(du, dv, w) in &row_terms {
                let rr = (r as isize + du) as usize;
                let line = &x[(rr * 3 + c) * mv..(rr * 3 + c + 1) * mv];
                let shift = dv.rem_euclid(mv as isize) as usize;
                for (j, o) in out.iter_mut().enumerate() {
                    let mut jj = j + shift;
                    if jj >= mv {
                        jj -= mv;
                    }
                    *o -= w * line[jj];
                }
            }
        }
    }
    modal.solve_in_place(&mut res)?;
    let mut nodes = vec![Vec3::zeros(); (nu + 1) * mv];
    for i in 0..=nu {
        let r = i + g;
        for (j, node) in nodes[i * mv..(i + 1) * mv].iter_mut().enumerate() {
            for c in 0..3 {
                let k = (r * 3 + c) * mv + j;
                node[c] = x[k] + res[k];
            }
        }
    }
    if nodes.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(Error::invalid(
            "the difference system gave a non-finite solution (singular system)",
        ));
    }
    Ok(nodes)
}

/// The solve of the block-circulant system: forward real FFTs of every line, one banded solve per
/// mode, inverse FFTs.
struct Modal {
    mv: usize,
    rows: usize,
    modes: usize,
    r2c: std::sync::Arc<dyn realfft::RealToComplex<f64>>,
    c2r: std::sync::Arc<dyn realfft::ComplexToReal<f64>>,
    factors: Vec<BandMatrix>,
}

impl Modal {
    fn new(mv: usize, rows: usize, factors: Vec<BandMatrix>) -> Self {
        let mut planner = RealFftPlanner::<f64>::new();
        Modal {
            mv,
            rows,
            modes: mv / 2 + 1,
            r2c: planner.plan_fft_forward(mv),
            c2r: planner.plan_fft_inverse(mv),
            factors,
        }
    }

    /// Replaces the right-hand sides `b[(r * 3 + c) * mv + j]` (row `r`, component `c`, column
    /// `j`) by the solution in the same layout.
    fn solve_in_place(&self, b: &mut [f64]) -> Result<()> {
        let (mv, rows, modes) = (self.mv, self.rows, self.modes);
        let fft_error = |e: realfft::FftError| Error::invalid(format!("FFT of {mv} samples: {e}"));
        let mut spec = vec![Complex64::new(0.0, 0.0); rows * 3 * modes];
        let mut scratch = self.r2c.make_scratch_vec();
        for (line, out) in b.chunks_exact_mut(mv).zip(spec.chunks_exact_mut(modes)) {
            self.r2c
                .process_with_scratch(line, out, &mut scratch)
                .map_err(fft_error)?;
        }
        let mut col = vec![0.0; rows];
        for (m, a) in self.factors.iter().enumerate() {
            for c in 0..3 {
                for part in 0..2 {
                    for (r, x) in col.iter_mut().enumerate() {
                        let z = spec[(r * 3 + c) * modes + m];
                        *x = if part == 0 { z.re } else { z.im };
                    }
                    a.solve_in_place(&mut col);
                    for (r, &x) in col.iter().enumerate() {
                        let z = &mut spec[(r * 3 + c) * modes + m];
                        if part == 0 {
                            z.re = x;
                        } else {
                            z.im = x;
                        }
                    }
                }
            }
        }
        let mut scratch = self.c2r.make_scratch_vec();
        let inv = 1.0 / mv as f64;
        for (coeffs, line) in spec.chunks_exact_mut(modes).zip(b.chunks_exact_mut(mv)) {
            // The mean and (for even M) the Nyquist term of a real sequence are real.
            coeffs[0].im = 0.0;
            if mv % 2 == 0 {
                coeffs[modes - 1].im = 0.0;
            }
            self.c2r
                .process_with_scratch(coeffs, line, &mut scratch)
                .map_err(fft_error)?;
            for y in line.iter_mut() {
                *y *= inv;
            }
        }
        Ok(())
    }
}
