//! Knot vectors: validation, span search, the Cox–de Boor basis with derivatives, blossoms,
//! knot insertion (Boehm) and degree elevation of one B-spline direction.

use crate::{Error, Result};

/// Checks a knot vector for `count` control points of degree `p`: `count + p + 1` finite,
/// non-decreasing values, a non-empty domain `[t_p, t_count]`, no value repeated more than
/// `p + 1` times and none strictly inside the domain more than `p` times. `name` prefixes the
/// messages (`knots_u`).
pub(crate) fn check_knots(name: &str, p: usize, count: usize, knots: &[f64]) -> Result<()> {
    if knots.len() != count + p + 1 {
        return Err(Error::invalid(format!(
            "{name}: expected control count + degree + 1 = {} + {p} + 1 = {} values, got {}",
            count,
            count + p + 1,
            knots.len()
        )));
    }
    for (i, k) in knots.iter().enumerate() {
        if !k.is_finite() {
            return Err(Error::invalid(format!("{name}[{i}] = {k} is not finite")));
        }
        if i > 0 && *k < knots[i - 1] {
            return Err(Error::invalid(format!(
                "{name}[{i}] = {k} is smaller than {name}[{}] = {}; knots must not decrease",
                i - 1,
                knots[i - 1]
            )));
        }
    }
    let (a, b) = (knots[p], knots[count]);
    if a >= b {
        return Err(Error::invalid(format!(
            "{name}: the domain [{name}[{p}], {name}[{count}]] = [{a}, {b}] is empty"
        )));
    }
    let mut i = 0;
    while i < knots.len() {
        let mut j = i;
        while j + 1 < knots.len() && knots[j + 1] == knots[i] {
            j += 1;
        }
        let mult = j - i + 1;
        let interior = knots[i] > a && knots[i] < b;
        let max = if interior { p } else { p + 1 };
        if mult > max {
            return Err(Error::invalid(format!(
                "{name}[{i}] = {} is repeated {mult} times; at most {max} allowed {}",
                knots[i],
                if interior {
                    "inside the domain (the surface would break apart)"
                } else {
                    "at or outside the ends of the domain"
                }
            )));
        }
        i = j + 1;
    }
    Ok(())
}

/// The span `s` (`p ≤ s < count`, `t_s < t_{s+1}`) whose polynomial piece evaluates `t`: the
/// last non-empty span with `t_s ≤ t`, the first one for `t` before the domain. At the domain's
/// end `t = t_count` this is the last non-empty span.
pub(crate) fn find_span(knots: &[f64], p: usize, count: usize, t: f64) -> usize {
    let first = (p..count).find(|&s| knots[s] < knots[s + 1]).unwrap_or(p);
    if t.is_nan() || t < knots[first + 1] {
        return first;
    }
    // Largest s in [p, count) with knots[s] <= t.
    let (mut lo, mut hi) = (p, count);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if knots[mid] <= t {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let mut s = lo;
    while s > first && knots[s] >= knots[s + 1] {
        s -= 1;
    }
    s
}

/// Values and derivatives of the `p + 1` B-splines of degree `p` that live on span `s`, at `t`:
/// `out[k·(p+1) + r] = N⁽ᵏ⁾_{s−p+r,p}(t)` for `k = 0..=order`. Outside `[t_s, t_{s+1}]` the
/// polynomial pieces of span `s` are extended.
///
/// The values come from the Cox–de Boor recursion
/// `N_{i,d} = (t − t_i)/(t_{i+d} − t_i) N_{i,d−1} + (t_{i+d+1} − t)/(t_{i+d+1} − t_{i+1}) N_{i+1,d−1}`
/// started from `N_{s,0} = 1` (terms with a zero denominator vanish). Derivatives use
/// `N'_{i,d} = d (N_{i,d−1}/(t_{i+d} − t_i) − N_{i+1,d−1}/(t_{i+d+1} − t_{i+1}))` unrolled:
/// `N⁽ᵏ⁾_{i,p} = p!/(p−k)! Σ_{j=0}^{k} c_j N_{i+j,p−k}` with
/// `c⁽ᵏ⁾_j = (c⁽ᵏ⁻¹⁾_j − c⁽ᵏ⁻¹⁾_{j−1}) / (t_{i+j+p−k+1} − t_{i+j})`. Orders above `p` are zero.
pub(crate) fn basis_derivatives(
    knots: &[f64],
    p: usize,
    s: usize,
    t: f64,
    order: usize,
    out: &mut [f64],
) {
    let w = p + 1;
    debug_assert!(out.len() >= (order + 1) * w);
    // table[d][r] = N_{s−d+r, d}(t), r = 0..=d, stored in a (p+1)×(p+1) square.
    let mut table = vec![0.0; w * w];
    table[0] = 1.0;
    for d in 1..=p {
        for r in 0..=d {
            let i = s + r - d;
            let mut v = 0.0;
            if r >= 1 {
                let den = knots[i + d] - knots[i];
                if den > 0.0 {
                    v += (t - knots[i]) / den * table[(d - 1) * w + r - 1];
                }
            }
            if r < d {
                let den = knots[i + d + 1] - knots[i + 1];
                if den > 0.0 {
                    v += (knots[i + d + 1] - t) / den * table[(d - 1) * w + r];
                }
            }
            table[d * w + r] = v;
        }
    }
    out[..w].copy_from_slice(&table[p * w..p * w + w]);
    let mut c = vec![0.0; w + 1];
    let mut prev = vec![0.0; w + 1];
    for k in 1..=order {
        let row = &mut out[k * w..(k + 1) * w];
        if k > p {
            row.fill(0.0);
            continue;
        }
        let q = p - k;
        // p!/(p−k)!
        let factor: f64 = (q + 1..=p).map(|x| x as f64).product();
        for (r, o) in row.iter_mut().enumerate() {
            let i = s + r - p;
            prev[..=k].fill(0.0);
            prev[0] = 1.0;
            for kk in 1..=k {
                let qq = p - kk;
                for j in 0..=kk {
                    let a = if j < kk { prev[j] } else { 0.0 };
                    let b = if j >= 1 { prev[j - 1] } else { 0.0 };
                    let den = knots[i + j + qq + 1] - knots[i + j];
                    c[j] = if den > 0.0 { (a - b) / den } else { 0.0 };
                }
                prev[..=kk].copy_from_slice(&c[..=kk]);
            }
            // Σ_j c_j N_{i+j, q}; N_{i+j,q} sits at table[q][r + j − k] when 0 ≤ r+j−k ≤ q.
            let mut v = 0.0;
            for (j, cj) in prev[..=k].iter().enumerate() {
                if r + j >= k && r + j - k <= q {
                    v += cj * table[q * w + r + j - k];
                }
            }
            *o = factor * v;
        }
    }
}

/// The blossom `b_s(x_1, …, x_p)` of the polynomial piece on span `s` of the spline with control
/// values `ctrl` (one coordinate array per control point, `dim` coordinates each), by de Boor's
/// algorithm with a different argument at each level:
/// `d⁽ʳ⁾_j = ((t_{j+p+1−r} − x_r) d⁽ʳ⁻¹⁾_{j−1} + (x_r − t_j) d⁽ʳ⁻¹⁾_j) / (t_{j+p+1−r} − t_j)`.
/// With all `x_r = t` this is the value at `t`; `b_s(t_{i+1}, …, t_{i+p})` is the control point
/// `P_i` for every `i` whose B-spline is non-zero on span `s`.
pub(crate) fn blossom(
    knots: &[f64],
    p: usize,
    s: usize,
    ctrl: &[f64],
    dim: usize,
    args: &[f64],
) -> Vec<f64> {
    // local[r] = P_{s−p+r}
    let mut local: Vec<f64> = ctrl[(s - p) * dim..(s + 1) * dim].to_vec();
    for (r, &x) in args.iter().enumerate().take(p) {
        let r = r + 1;
        // Update j from high to low: d_j uses d_{j−1} and d_j of the previous level.
        for jj in (r..=p).rev() {
            let j = s - p + jj;
            let (lo, hi) = (knots[j], knots[j + p + 1 - r]);
            let den = hi - lo;
            let (wa, wb) = if den > 0.0 {
                ((hi - x) / den, (x - lo) / den)
            } else {
                (0.0, 1.0)
            };
            for c in 0..dim {
                local[jj * dim + c] = wa * local[(jj - 1) * dim + c] + wb * local[jj * dim + c];
            }
        }
    }
    local[p * dim..(p + 1) * dim].to_vec()
}

/// Boehm's knot insertion of `t` into one direction: the new control points are
/// `Q_i = α_i P_i + (1 − α_i) P_{i−1}` with `α_i = 1` where `t ≥ t_{i+p}`, `0` where
/// `t ≤ t_i`, else `(t − t_i)/(t_{i+p} − t_i)` (`i = 0..=count`). `ctrl` holds `count` control
/// values of `dim` coordinates each. Returns the new knots and control values.
pub(crate) fn insert_knot(
    name: &str,
    knots: &[f64],
    p: usize,
    count: usize,
    ctrl: &[f64],
    dim: usize,
    t: f64,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let (a, b) = (knots[p], knots[count]);
    if !(t >= a && t <= b) {
        return Err(Error::invalid(format!(
            "{name}: the inserted knot {t} is outside the domain [{a}, {b}]"
        )));
    }
    let pos = knots.partition_point(|&k| k <= t);
    let mut new_knots = knots.to_vec();
    new_knots.insert(pos, t);
    check_knots(name, p, count + 1, &new_knots)
        .map_err(|e| Error::invalid(format!("inserting knot {t}: {e}")))?;
    let mut out = vec![0.0; (count + 1) * dim];
    for i in 0..=count {
        let alpha = if p == 0 {
            if knots[i] <= t && i < count {
                1.0
            } else {
                0.0
            }
        } else if t >= knots[i + p] {
            1.0
        } else if t <= knots[i] {
            0.0
        } else {
            (t - knots[i]) / (knots[i + p] - knots[i])
        };
        for c in 0..dim {
            let pi = if alpha != 0.0 && i < count {
                ctrl[i * dim + c]
            } else {
                0.0
            };
            let pm = if alpha != 1.0 && i >= 1 {
                ctrl[(i - 1) * dim + c]
            } else {
                0.0
            };
            out[i * dim + c] = alpha * pi + (1.0 - alpha) * pm;
        }
    }
    Ok((new_knots, out))
}

/// Degree elevation `p → p + 1` of one direction, exact: every distinct knot value in the domain
/// `[a, b]` gets one more copy (so the continuity at each knot is kept; knots outside the
/// domain are left alone), and the new control points are the blossoms of the elevated pieces,
/// `Q_i = 1/(p+1) Σ_{k=1}^{p+1} b(t'_{i+1}, …, t'_{i+k} omitted, …, t'_{i+p+1})`, evaluated on a
/// non-empty domain span inside the support of the new `N_{i,p+1}`.
pub(crate) fn elevate(
    knots: &[f64],
    p: usize,
    count: usize,
    ctrl: &[f64],
    dim: usize,
) -> (Vec<f64>, Vec<f64>) {
    let (a, b) = (knots[p], knots[count]);
    let mut distinct: Vec<f64> = knots
        .iter()
        .copied()
        .filter(|&k| k >= a && k <= b)
        .collect();
    distinct.dedup();
    let mut new_knots = knots.to_vec();
    for &d in &distinct {
        let pos = new_knots.partition_point(|&k| k <= d);
        new_knots.insert(pos, d);
    }
    let q = p + 1;
    let new_count = new_knots.len() - q - 1;
    let mut out = vec![0.0; new_count * dim];
    let mut args = vec![0.0; p];
    for i in 0..new_count {
        // A non-empty domain span [t'_j, t'_{j+1}] inside the support [t'_i, t'_{i+q+1}].
        let lo = i.max(q);
        let hi = (i + q).min(new_count - 1);
        let j = (lo..=hi)
            .find(|&j| new_knots[j] < new_knots[j + 1])
            .unwrap_or_else(|| {
                if i < q {
                    (q..new_count)
                        .find(|&j| new_knots[j] < new_knots[j + 1])
                        .unwrap_or(q)
                } else {
                    (q..new_count)
                        .rev()
                        .find(|&j| new_knots[j] < new_knots[j + 1])
                        .unwrap_or(q)
                }
            });
        // The original span with the same interval.
        let mid = 0.5 * (new_knots[j] + new_knots[j + 1]);
        let s = find_span(knots, p, count, mid);
        let slot = &mut out[i * dim..(i + 1) * dim];
        for omit in 0..q {
            let mut n = 0;
            for r in 0..q {
                if r != omit {
                    args[n] = new_knots[i + 1 + r];
                    n += 1;
                }
            }
            let v = blossom(knots, p, s, ctrl, dim, &args);
            for c in 0..dim {
                slot[c] += v[c];
            }
        }
        for x in slot.iter_mut() {
            *x /= q as f64;
        }
    }
    (new_knots, out)
}

/// The B-splines of degree `p` on `knots` that are alive at `t`, with derivatives: returns the
/// span `s` (`p ≤ s < n`, `n = knots.len() − p − 1`, the span whose polynomial piece evaluates
/// `t`, as in [`super::BSplineSurface::derivative`]) and `out[k·(p+1) + r] = N⁽ᵏ⁾_{s−p+r,p}(t)`
/// for `k = 0..=order`. The knot vector is checked as by [`super::BSplineSurface::new`].
pub fn bspline_basis(knots: &[f64], p: usize, t: f64, order: usize) -> Result<(usize, Vec<f64>)> {
    if knots.len() / 2 <= p {
        return Err(Error::invalid(format!(
            "knots: degree {p} needs at least 2·({p} + 1) knots, got {}",
            knots.len()
        )));
    }
    let n = knots.len() - p - 1;
    check_knots("knots", p, n, knots)?;
    let len = order
        .checked_add(1)
        .and_then(|o| o.checked_mul(p + 1))
        .filter(|&l| l <= 1 << 24)
        .ok_or_else(|| Error::invalid(format!("order = {order} is too large")))?;
    let s = find_span(knots, p, n, t);
    let mut out = vec![0.0; len];
    basis_derivatives(knots, p, s, t, order, &mut out);
    Ok((s, out))
}
