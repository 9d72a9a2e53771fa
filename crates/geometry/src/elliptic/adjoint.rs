//! The adjoint of a quadrature over a patch's partials: linear functionals of the tangents of a
//! patch, gathered once over the nodes and applied to each tangent's mode coefficients.
//!
//! A linear functional of a surface's partials at a tensor grid of nodes `(u_a, v_b)`,
//! `ℓ[T] = Σ_ab G_ab · (T, T_u, T_v, T_uu, T_uv, T_vv)(u_a, v_b)` (the weights `G_ab`, 18 numbers
//! per node and functional, include the quadrature weights), is for a PDE patch
//! `T = Σ_n Σ_j ψ_nj(u) (a_nj cos nv + b_nj sin nv) + Σ_i w_i(u) Δ_i(v)` linear in its mode
//! coefficients `a_nj, b_nj` and its remainder's `Δ_i(v_b)`:
//!
//! ```text
//! ℓ[T] = Σ_n Σ_j a_nj · α_nj + b_nj · β_nj + Σ_i Σ_b Σ_{k≤2} Δ_i^{(k)}(v_b) · ρ_ibk
//! α_nj = Σ_a ψ_nj(u_a) (C_x − n² C_vv − n S_v) + ψ'_nj(u_a) (C_u − n S_uv) + ψ''_nj(u_a) C_uu
//! β_nj = Σ_a ψ_nj(u_a) (S_x − n² S_vv + n C_v) + ψ'_nj(u_a) (S_u + n C_uv) + ψ''_nj(u_a) S_uu
//! ```
//!
//! with `C_q = Σ_b G_ab,q cos n v_b`, `S_q = Σ_b G_ab,q sin n v_b` per row `a`, and
//! `ρ_ib0 = Σ_a w_i G_x + w_i' G_u + w_i'' G_uu`, `ρ_ib1 = Σ_a w_i G_v + w_i' G_uv`,
//! `ρ_ib2 = Σ_a w_i G_vv`. The tangents of one patch share its mode bases and cardinal
//! functions (the same operator and condition places), so the weights `α, β, ρ` are gathered in
//! one pass over the nodes whatever the number of tangents, and each tangent costs a dot
//! product of its coefficients (and, with a remainder, its `Δ_i` at the `v` nodes).
//!
//! A tangent may also carry `s · u X_u` of the patch `X` itself (the derivative along the
//! smoothing parameter, [`PdePatch::smoothing_tangent_curves`]): the same sums with the basis
//! `u ψ'` (derivatives `ψ' + u ψ''`, `2ψ'' + u ψ'''`) and cardinal functions `u w_i'`, applied
//! to `X`'s own coefficients.

use super::{ModeFn, PdePatch};
use crate::{Error, Result, Vec3};
use rayon::prelude::*;

/// Numbers per node and functional: `X, X_u, X_v, X_uu, X_uv, X_vv` (x, y, z each).
pub const NODE_WEIGHTS: usize = 18;

/// The offsets of the six partials in a node's 18 weights.
const X: usize = 0;
const XU: usize = 3;
const XV: usize = 6;
const XUU: usize = 9;
const XUV: usize = 12;
const XVV: usize = 15;

/// A partial of a surface whose node weights a functional uses
/// ([`PdePatch::quadrature_adjoint_using`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Partial {
    /// `X`.
    X,
    /// `X_u`.
    Xu,
    /// `X_v`.
    Xv,
    /// `X_uu`.
    Xuu,
    /// `X_uv`.
    Xuv,
    /// `X_vv`.
    Xvv,
}

impl Partial {
    /// All six, in the order of a node's weights.
    pub const ALL: [Partial; 6] = [
        Partial::X,
        Partial::Xu,
        Partial::Xv,
        Partial::Xuu,
        Partial::Xuv,
        Partial::Xvv,
    ];

    /// The offset of the partial's three weights among a node's 18.
    fn offset(self) -> usize {
        match self {
            Partial::X => X,
            Partial::Xu => XU,
            Partial::Xv => XV,
            Partial::Xuu => XUU,
            Partial::Xuv => XUV,
            Partial::Xvv => XVV,
        }
    }
}

/// A tangent of a patch for [`PdePatch::quadrature_adjoint`]: `patch + stretch · u X_u` with `X`
/// the patch the adjoint is gathered on.
#[derive(Clone, Copy)]
pub struct AdjointTangent<'a> {
    /// The tangent patch (solved with the same operator and condition places).
    pub patch: &'a PdePatch,
    /// The factor of `u X_u` (0 for a direction of the condition curves).
    pub stretch: f64,
}

/// What one pass gathers: the offsets of each part in one flat accumulator.
struct Layout {
    outputs: usize,
    /// The basis functions per mode (`2N`).
    len: usize,
    /// The modes gathered (with the tangents' patches' coefficients).
    live: Vec<usize>,
    /// The modes gathered in the stretched basis (`X`'s own non-zero modes), when a tangent
    /// has a stretch.
    stretched: Vec<usize>,
    /// The remainder's weights are gathered (some tangent has a remainder), with the cardinal
    /// functions of that tangent.
    remainder: Option<usize>,
    /// The stretched remainder's weights (a tangent has a stretch and `X` a remainder).
    stretched_remainder: bool,
    conditions: usize,
    nv: usize,
    /// The offsets of the used partials' weights among a node's 18 (all six unless the
    /// functionals use fewer).
    used: Vec<usize>,
    /// The distinct modes of `live` and `stretched`, ascending: each one's cosine and sine
    /// sums of a row are made once.
    distinct: Vec<usize>,
}

impl Layout {
    fn mode_block(&self) -> usize {
        self.outputs * self.len * 6
    }
    fn remainder_block(&self) -> usize {
        self.conditions * self.nv * 3 * self.outputs * 3
    }
    fn stretched_at(&self) -> usize {
        self.live.len() * self.mode_block()
    }
    fn remainder_at(&self) -> usize {
        self.stretched_at() + self.stretched.len() * self.mode_block()
    }
    fn stretched_remainder_at(&self) -> usize {
        self.remainder_at()
            + if self.remainder.is_some() {
                self.remainder_block()
            } else {
                0
            }
    }
    fn total(&self) -> usize {
        self.stretched_remainder_at()
            + if self.stretched_remainder {
                self.remainder_block()
            } else {
                0
            }
    }
}

/// The basis functions of a mode and their first three u-derivatives at `u` (the third only
/// when `third`): `out[d][j]`.
fn basis_at(mode: &ModeFn, u: f64, third: bool, out: &mut [Vec<f64>; 4]) {
    let [b0, b1, b2, b3] = out;
    mode.basis
        .eval012(u, [&mut b0[..], &mut b1[..], &mut b2[..]]);
    if third {
        mode.basis.eval(u, 3, b3);
    }
}

/// Adds `f_d(u)`-weighted row sums into a mode's block `w[(o·len + j)·6 + c]`: `phi[d][j]` are
/// the basis function `j`'s values and derivatives at the row, `p[o][d]`, `q[o][d]` the row's
/// cosine and sine combinations (see the module documentation).
#[allow(clippy::needless_range_loop)] // j indexes three basis rows and the block
fn add_mode(w: &mut [f64], phi: [&[f64]; 3], p: &[[Vec3; 3]], q: &[[Vec3; 3]], len: usize) {
    for (o, (p, q)) in p.iter().zip(q).enumerate() {
        for j in 0..len {
            let (f0, f1, f2) = (phi[0][j], phi[1][j], phi[2][j]);
            let a = p[0] * f0 + p[1] * f1 + p[2] * f2;
            let b = q[0] * f0 + q[1] * f1 + q[2] * f2;
            let at = (o * len + j) * 6;
            for k in 0..3 {
                w[at + k] += a[k];
                w[at + 3 + k] += b[k];
            }
        }
    }
}

/// Adds a row's remainder weights `ρ` into `r[((i·nv + b)·3 + k)·outputs + o]` (Vec3 as three
/// numbers): `card[d][i]` the cardinal functions' values and derivatives at the row, `g` the
/// row's node weights `[b][o][18]`.
fn add_remainder(r: &mut [f64], card: [&[f64]; 3], g: &[f64], lay: &Layout, active: &[bool]) {
    let (nv, outputs) = (lay.nv, lay.outputs);
    for (i, _) in active.iter().enumerate().filter(|(_, a)| **a) {
        let (w0, w1, w2) = (card[0][i], card[1][i], card[2][i]);
        for b in 0..nv {
            for o in 0..outputs {
                let gq = &g[(b * outputs + o) * NODE_WEIGHTS..][..NODE_WEIGHTS];
                let at = ((i * nv + b) * 3) * outputs * 3 + o * 3;
                let step = outputs * 3;
                for c in 0..3 {
                    r[at + c] += w0 * gq[X + c] + w1 * gq[XU + c] + w2 * gq[XUU + c];
                    r[at + step + c] += w0 * gq[XV + c] + w1 * gq[XUV + c];
                    r[at + 2 * step + c] += w0 * gq[XVV + c];
                }
            }
        }
    }
}

/// `Σ_i Σ_b Σ_k Δ_i^{(k)}(v_b) · ρ_ibk` for `outputs` functionals, with `Δ` of `patch`.
fn apply_remainder(r: &[f64], patch: &PdePatch, vs: &[f64], outputs: usize, out: &mut [f64]) {
    let Some(rem) = &patch.remainder else {
        return;
    };
    let nv = vs.len();
    let conditions = patch.conditions();
    for i in (0..conditions.len()).filter(|&i| rem.active[i]) {
        for (b, &v) in vs.iter().enumerate() {
            let d = rem.delta(conditions, i, v, 2);
            for (k, dk) in d.iter().enumerate() {
                let at = ((i * nv + b) * 3 + k) * outputs * 3;
                for (o, out) in out.iter_mut().enumerate() {
                    let w = &r[at + o * 3..at + o * 3 + 3];
                    *out += w[0] * dk.x + w[1] * dk.y + w[2] * dk.z;
                }
            }
        }
    }
}

/// `Σ_j Σ_c w[(o·len + j)·6 + c] · coef[(j, c)]` for every functional `o`.
fn apply_mode(w: &[f64], mode: &ModeFn, outputs: usize, len: usize, out: &mut [f64]) {
    for (o, out) in out.iter_mut().enumerate().take(outputs) {
        let mut s = 0.0;
        for j in 0..len {
            for c in 0..6 {
                s += w[(o * len + j) * 6 + c] * mode.coef[(j, c)];
            }
        }
        *out += s;
    }
}

impl PdePatch {
    /// `outputs` linear functionals of the partials of each tangent in `tangents`, gathered
    /// once over the nodes `us × vs` (see the module documentation): `weights(a, row)` writes
    /// the weights of row `u_a` into `row[(b·outputs + o)·18 + q]` (`q` over `X, X_u, X_v, X_uu,
    /// X_uv, X_vv`, x, y, z each; the quadrature weights included). The result's `[k][o]` is
    /// functional `o` of tangent `k`, equal to the sum over the nodes of the weights times the
    /// tangent's partials up to the rounding of the sums.
    ///
    /// Every tangent must be a solution with this patch's operator and condition places (such
    /// as [`PdePatch::solve_tangents`]' patches), so it shares this patch's mode bases and the
    /// remainder's cardinal functions.
    pub fn quadrature_adjoint(
        &self,
        us: &[f64],
        vs: &[f64],
        outputs: usize,
        weights: &(dyn Fn(usize, &mut [f64]) + Sync),
        tangents: &[AdjointTangent],
    ) -> Result<Vec<Vec<f64>>> {
        self.quadrature_adjoint_using(us, vs, outputs, &Partial::ALL, weights, tangents)
    }

    /// [`PdePatch::quadrature_adjoint`] of functionals that weigh only the partials `uses`
    /// (such as `X` and `X_v` on a boundary row): the sums over the nodes skip the others, and
    /// their weights are taken as zero whatever `weights` writes into their places.
    pub fn quadrature_adjoint_using(
        &self,
        us: &[f64],
        vs: &[f64],
        outputs: usize,
        uses: &[Partial],
        weights: &(dyn Fn(usize, &mut [f64]) + Sync),
        tangents: &[AdjointTangent],
    ) -> Result<Vec<Vec<f64>>> {
        let nm = self.modes.len();
        let len = self.modes[0].basis.len();
        for (k, t) in tangents.iter().enumerate() {
            let p = t.patch;
            let same = p.modes.len() == nm
                && p.conditions().len() == self.conditions().len()
                && p.modes.iter().zip(&self.modes).all(|(a, b)| {
                    a.basis.kind() == b.basis.kind() && a.basis.len() == b.basis.len()
                });
            if !same {
                return Err(Error::invalid(format!(
                    "tangent {k} is not solved with the patch's modes and bases"
                )));
            }
        }
        let live: Vec<usize> = (0..nm)
            .filter(|&n| tangents.iter().any(|t| !t.patch.modes[n].zero))
            .collect();
        let stretch = tangents.iter().any(|t| t.stretch != 0.0);
        let stretched: Vec<usize> = if stretch {
            (0..nm).filter(|&n| !self.modes[n].zero).collect()
        } else {
            Vec::new()
        };
        let remainder = tangents.iter().position(|t| t.patch.remainder.is_some());
        let lay = Layout {
            outputs,
            len,
            live,
            stretched,
            remainder,
            stretched_remainder: stretch && self.remainder.is_some(),
            conditions: self.conditions().len(),
            nv: vs.len(),
            used: Partial::ALL
                .iter()
                .filter(|p| uses.contains(p))
                .map(|p| p.offset())
                .collect(),
            distinct: Vec::new(),
        };
        let mut lay = lay;
        lay.distinct = (0..nm)
            .filter(|n| lay.live.contains(n) || lay.stretched.contains(n))
            .collect();
        // The cardinal functions of the tangents' remainder (all the same), and every
        // condition that is active in some tangent.
        let cardinal = lay
            .remainder
            .and_then(|k| tangents[k].patch.remainder.as_ref());
        let active: Vec<bool> = (0..lay.conditions)
            .map(|i| {
                tangents
                    .iter()
                    .any(|t| t.patch.remainder.as_ref().is_some_and(|r| r.active[i]))
            })
            .collect();
        let total = lay.total();
        let block = vs.len() * outputs * NODE_WEIGHTS;
        // trig[b·D + d] = (cos n v_b, sin n v_b) of the distinct modes `n = lay.distinct[d]`.
        let trig: Vec<(f64, f64)> = vs
            .iter()
            .flat_map(|&v| {
                lay.distinct.iter().map(move |&n| {
                    let (s, c) = (n as f64 * v).sin_cos();
                    (c, s)
                })
            })
            .collect();
        // Each row's sums, then their total in row order: the same bits whatever the number
        // of threads.
        let rows: Vec<Vec<f64>> = (0..us.len())
            .into_par_iter()
            .map_init(
                || {
                    Scratch::new(
                        total,
                        block,
                        outputs,
                        len,
                        lay.conditions,
                        lay.distinct.len(),
                    )
                },
                |s, a| {
                    s.acc.fill(0.0);
                    s.row(a, us[a], weights, &lay, self, cardinal, &active, &trig);
                    s.acc.clone()
                },
            )
            .collect();
        let mut acc = vec![0.0; total];
        for r in &rows {
            acc.iter_mut().zip(r).for_each(|(x, y)| *x += y);
        }
        let mb = lay.mode_block();
        let mut base_part = vec![0.0; outputs];
        if stretch {
            for (k, &n) in lay.stretched.iter().enumerate() {
                let w = &acc[lay.stretched_at() + k * mb..][..mb];
                apply_mode(w, &self.modes[n], outputs, len, &mut base_part);
            }
            if lay.stretched_remainder {
                let r = &acc[lay.stretched_remainder_at()..][..lay.remainder_block()];
                apply_remainder(r, self, vs, outputs, &mut base_part);
            }
        }
        Ok(tangents
            .iter()
            .map(|t| {
                let mut out = vec![0.0; outputs];
                for (k, &n) in lay.live.iter().enumerate() {
                    if !t.patch.modes[n].zero {
                        apply_mode(
                            &acc[k * mb..][..mb],
                            &t.patch.modes[n],
                            outputs,
                            len,
                            &mut out,
                        );
                    }
                }
                if lay.remainder.is_some() {
                    let r = &acc[lay.remainder_at()..][..lay.remainder_block()];
                    apply_remainder(r, t.patch, vs, outputs, &mut out);
                }
                for (o, b) in out.iter_mut().zip(&base_part) {
                    *o += t.stretch * b;
                }
                out
            })
            .collect())
    }
}

/// The cosine and sine sums of a row's weights `g` (`[b][o][18]`) for `modes` modes whose
/// `(cos, sin)` at node `b` are `trig[b·modes + d]`: `cs[d·outputs + o][q] = Σ_b g · cos`, each
/// sum in node order, over all 18 weights (`ALL`) or those of the partials at the offsets
/// `used` only (the others left as they are).
///
/// Each sum runs over the nodes in a register of its own (nine weights at a time), not
/// through memory node by node; the terms and their order are those of the plain loop, so the
/// sums are the same bits.
fn v_sums<const ALL: bool>(
    g: &[f64],
    trig: &[(f64, f64)],
    modes: usize,
    outputs: usize,
    used: &[usize],
    cs: &mut [[f64; NODE_WEIGHTS]],
    sn: &mut [[f64; NODE_WEIGHTS]],
) {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor supports the feature the function was compiled for.
        return unsafe { v_sums_avx2::<ALL>(g, trig, modes, outputs, used, cs, sn) };
    }
    v_sums_generic::<ALL>(g, trig, modes, outputs, used, cs, sn)
}

/// [`v_sums_generic`] compiled for AVX2 (four sums per instruction; no fused multiply–adds, so
/// the same bits).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn v_sums_avx2<const ALL: bool>(
    g: &[f64],
    trig: &[(f64, f64)],
    modes: usize,
    outputs: usize,
    used: &[usize],
    cs: &mut [[f64; NODE_WEIGHTS]],
    sn: &mut [[f64; NODE_WEIGHTS]],
) {
    v_sums_generic::<ALL>(g, trig, modes, outputs, used, cs, sn)
}

/// The sums of `W` consecutive weights from offset `at` of every node's block `o`, for mode
/// `d`, each over the nodes in order.
#[inline(always)]
fn v_sum_run<const W: usize>(
    g: &[f64],
    trig: &[(f64, f64)],
    modes: usize,
    d: usize,
    stride: usize,
    at: usize,
) -> ([f64; W], [f64; W]) {
    let (mut c, mut s) = ([0.0; W], [0.0; W]);
    for (gb, t) in g.chunks_exact(stride).zip(trig.chunks_exact(modes)) {
        let (cb, sb) = t[d];
        let gq: &[f64; W] = gb[at..at + W].try_into().expect("W weights");
        for q in 0..W {
            c[q] += gq[q] * cb;
            s[q] += gq[q] * sb;
        }
    }
    (c, s)
}

#[inline(always)]
fn v_sums_generic<const ALL: bool>(
    g: &[f64],
    trig: &[(f64, f64)],
    modes: usize,
    outputs: usize,
    used: &[usize],
    cs: &mut [[f64; NODE_WEIGHTS]],
    sn: &mut [[f64; NODE_WEIGHTS]],
) {
    if modes == 0 {
        return;
    }
    let stride = outputs * NODE_WEIGHTS;
    for d in 0..modes {
        for o in 0..outputs {
            let (c, s) = (&mut cs[d * outputs + o], &mut sn[d * outputs + o]);
            let base = o * NODE_WEIGHTS;
            if ALL {
                for half in [0, 9] {
                    let (cc, ss) = v_sum_run::<9>(g, trig, modes, d, stride, base + half);
                    c[half..half + 9].copy_from_slice(&cc);
                    s[half..half + 9].copy_from_slice(&ss);
                }
            } else {
                for &p in used {
                    let (cc, ss) = v_sum_run::<3>(g, trig, modes, d, stride, base + p);
                    c[p..p + 3].copy_from_slice(&cc);
                    s[p..p + 3].copy_from_slice(&ss);
                }
            }
        }
    }
}

/// One thread's accumulator and row buffers.
struct Scratch {
    acc: Vec<f64>,
    g: Vec<f64>,
    /// Per distinct mode and functional: the row's cosine and sine sums of the 18 weights,
    /// `cs[d·outputs + o]`.
    cs: Vec<[f64; NODE_WEIGHTS]>,
    sn: Vec<[f64; NODE_WEIGHTS]>,
    phi: [Vec<f64>; 4],
    stretched: [Vec<f64>; 3],
    card: [Vec<f64>; 4],
    card_stretched: [Vec<f64>; 3],
    p: Vec<[Vec3; 3]>,
    q: Vec<[Vec3; 3]>,
}

impl Scratch {
    fn new(
        total: usize,
        block: usize,
        outputs: usize,
        len: usize,
        conditions: usize,
        distinct: usize,
    ) -> Self {
        let v = |n: usize| vec![0.0; n];
        Scratch {
            acc: v(total),
            g: v(block),
            cs: vec![[0.0; NODE_WEIGHTS]; outputs * distinct],
            sn: vec![[0.0; NODE_WEIGHTS]; outputs * distinct],
            phi: [v(len), v(len), v(len), v(len)],
            stretched: [v(len), v(len), v(len)],
            card: [v(conditions), v(conditions), v(conditions), v(conditions)],
            card_stretched: [v(conditions), v(conditions), v(conditions)],
            p: vec![[Vec3::zeros(); 3]; outputs],
            q: vec![[Vec3::zeros(); 3]; outputs],
        }
    }

    /// The sums of row `a` (at `u`) into the accumulator.
    #[allow(clippy::too_many_arguments)]
    fn row(
        &mut self,
        a: usize,
        u: f64,
        weights: &(dyn Fn(usize, &mut [f64]) + Sync),
        lay: &Layout,
        patch: &PdePatch,
        cardinal: Option<&super::patch::Remainder>,
        active: &[bool],
        trig: &[(f64, f64)],
    ) {
        weights(a, &mut self.g);
        if lay.used.len() < 6 {
            // The weights of the partials not used are zero.
            for node in self.g.chunks_exact_mut(NODE_WEIGHTS) {
                for p in Partial::ALL.map(Partial::offset) {
                    if !lay.used.contains(&p) {
                        node[p..p + 3].fill(0.0);
                    }
                }
            }
        }
        let outputs = lay.outputs;
        let mb = lay.mode_block();
        let modes = lay
            .live
            .iter()
            .map(|&n| (n, false))
            .chain(lay.stretched.iter().map(|&n| (n, true)));
        // The row's cosine and sine sums of every functional's weights, all distinct modes in
        // one pass over the nodes (each sum in node order).
        let dd = lay.distinct.len();
        self.cs.fill([0.0; NODE_WEIGHTS]);
        self.sn.fill([0.0; NODE_WEIGHTS]);
        if lay.used.len() == 6 {
            v_sums::<true>(&self.g, trig, dd, outputs, &[], &mut self.cs, &mut self.sn);
        } else {
            v_sums::<false>(
                &self.g,
                trig,
                dd,
                outputs,
                &lay.used,
                &mut self.cs,
                &mut self.sn,
            );
        }
        for (k, (n, stretched)) in modes.enumerate() {
            let d = lay.distinct.partition_point(|&m| m < n);
            let nf = n as f64;
            let v3 = |x: &[f64; NODE_WEIGHTS], q: usize| Vec3::new(x[q], x[q + 1], x[q + 2]);
            for o in 0..outputs {
                let (c, s) = (&self.cs[d * outputs + o], &self.sn[d * outputs + o]);
                self.p[o] = [
                    v3(c, X) - v3(c, XVV) * (nf * nf) - v3(s, XV) * nf,
                    v3(c, XU) - v3(s, XUV) * nf,
                    v3(c, XUU),
                ];
                self.q[o] = [
                    v3(s, X) - v3(s, XVV) * (nf * nf) + v3(c, XV) * nf,
                    v3(s, XU) + v3(c, XUV) * nf,
                    v3(s, XUU),
                ];
            }
            basis_at(&patch.modes[n], u, stretched, &mut self.phi);
            let w = &mut self.acc[k * mb..][..mb];
            if stretched {
                // u ψ' and its two u-derivatives.
                let [f0, f1, f2] = &mut self.stretched;
                for j in 0..lay.len {
                    let [p1, p2, p3] = [self.phi[1][j], self.phi[2][j], self.phi[3][j]];
                    f0[j] = u * p1;
                    f1[j] = p1 + u * p2;
                    f2[j] = 2.0 * p2 + u * p3;
                }
                add_mode(w, [f0, f1, f2], &self.p, &self.q, lay.len);
            } else {
                add_mode(
                    w,
                    [&self.phi[0], &self.phi[1], &self.phi[2]],
                    &self.p,
                    &self.q,
                    lay.len,
                );
            }
        }
        if let Some(r) = cardinal {
            for (d, c) in self.card.iter_mut().take(3).enumerate() {
                r.cardinal.eval(u, d, c);
            }
            let at = lay.remainder_at();
            let card = [&self.card[0][..], &self.card[1][..], &self.card[2][..]];
            add_remainder(
                &mut self.acc[at..at + lay.remainder_block()],
                card,
                &self.g,
                lay,
                active,
            );
        }
        if lay.stretched_remainder {
            if let Some(r) = &patch.remainder {
                for d in 1..4 {
                    r.cardinal.eval(u, d, &mut self.card[d]);
                }
                let [f0, f1, f2] = &mut self.card_stretched;
                for i in 0..lay.conditions {
                    let [w1, w2, w3] = [self.card[1][i], self.card[2][i], self.card[3][i]];
                    f0[i] = u * w1;
                    f1[i] = w1 + u * w2;
                    f2[i] = 2.0 * w2 + u * w3;
                }
                let at = lay.stretched_remainder_at();
                add_remainder(
                    &mut self.acc[at..at + lay.remainder_block()],
                    [f0, f1, f2],
                    &self.g,
                    lay,
                    &r.active,
                );
            }
        }
    }
}
