//! Knot vectors: the one validator of every B-spline in the crate (curves, surfaces, the
//! B-spline PDE engine), span search, the Cox–de Boor basis with derivatives (generic over
//! [`Scalar`], so exact in rationals), blossoms, knot insertion (Boehm) and degree elevation of
//! one B-spline direction.

use crate::scalar::Scalar;
use crate::{Error, Result};

/// What a knot vector must satisfy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum KnotRule {
    /// The full knot vector of an open spline of degree `degree` with `count` control points:
    /// `count + degree + 1` finite, non-decreasing values (with `count: None`, as many control
    /// points as the knots make, `len − degree − 1`, at least `degree + 1`), a non-empty domain
    /// `[t_degree, t_count]`, no value repeated more than `degree + 1` times and none strictly
    /// inside the domain more than `degree` times (the spline would break apart there).
    Open { degree: usize, count: Option<usize> },
    /// The `count + 1` finite, strictly increasing breakpoints of a periodic spline of degree
    /// `degree` with `count` control points.
    Breakpoints { degree: usize, count: usize },
}

/// The first thing wrong with a knot vector under a [`KnotRule`], with the values it names
/// already written out (`Scalar::to_text`). Turned into an [`Error`] by
/// [`KnotFault::at_place`] (design-file wording) or [`KnotFault::named`] (library wording).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct KnotFault {
    rule: KnotRule,
    len: usize,
    kind: FaultKind,
}

#[derive(Clone, Debug, PartialEq)]
enum FaultKind {
    /// The length is not the one the rule asks for.
    Count { want: usize },
    /// Fewer than `2(degree + 1)` knots where the control-point count follows from the knots.
    TooFew,
    /// Value `at` is NaN or infinite.
    NotFinite { at: usize, value: String },
    /// Value `at` is below (breakpoints: not above) the one before it.
    Decreasing {
        at: usize,
        value: String,
        prev: String,
    },
    /// `t_degree ≥ t_count`.
    EmptyDomain { a: String, b: String },
    /// The run of values equal to value `at` is `mult` long, more than allowed.
    Repeated {
        at: usize,
        value: String,
        mult: usize,
        interior: bool,
    },
}

impl KnotRule {
    fn degree(self) -> usize {
        match self {
            KnotRule::Open { degree, .. } | KnotRule::Breakpoints { degree, .. } => degree,
        }
    }

    /// The control-point count the knots are for (`None` if they are too few to make one).
    fn count(self, len: usize) -> Option<usize> {
        match self {
            KnotRule::Open { count: Some(n), .. } | KnotRule::Breakpoints { count: n, .. } => {
                Some(n)
            }
            KnotRule::Open {
                degree,
                count: None,
            } => len.checked_sub(degree + 1).filter(|&n| n > degree),
        }
    }

    /// The first fault of `knots`, in this order: length, finiteness (all values), order (all
    /// values), then for open knot vectors the domain and the multiplicities.
    pub(crate) fn check<T: Scalar>(self, knots: &[T]) -> Result<(), KnotFault> {
        let len = knots.len();
        let fault = |kind| KnotFault {
            rule: self,
            len,
            kind,
        };
        let p = self.degree();
        let Some(n) = self.count(len) else {
            return Err(fault(FaultKind::TooFew));
        };
        let (want, strict) = match self {
            KnotRule::Open { .. } => (n + p + 1, false),
            KnotRule::Breakpoints { .. } => (n + 1, true),
        };
        if len != want {
            return Err(fault(FaultKind::Count { want }));
        }
        if let Some(at) = knots.iter().position(|k| !k.is_finite()) {
            let value = knots[at].to_text();
            return Err(fault(FaultKind::NotFinite { at, value }));
        }
        for at in 1..len {
            let (k, prev) = (&knots[at], &knots[at - 1]);
            if if strict { k <= prev } else { k < prev } {
                let (value, prev) = (k.to_text(), prev.to_text());
                return Err(fault(FaultKind::Decreasing { at, value, prev }));
            }
        }
        if strict {
            return Ok(());
        }
        let (a, b) = (&knots[p], &knots[n]);
        if a >= b {
            let (a, b) = (a.to_text(), b.to_text());
            return Err(fault(FaultKind::EmptyDomain { a, b }));
        }
        let mut i = 0;
        while i < len {
            let j = (i..len).take_while(|&j| knots[j] == knots[i]).count() + i - 1;
            let mult = j - i + 1;
            let interior = &knots[i] > a && &knots[i] < b;
            if mult > if interior { p } else { p + 1 } {
                let value = knots[i].to_text();
                return Err(fault(FaultKind::Repeated {
                    at: i,
                    value,
                    mult,
                    interior,
                }));
            }
            i = j + 1;
        }
        Ok(())
    }
}

impl KnotFault {
    /// The design-file wording: a short message at the place of the offending value, relative
    /// to the knot vector `name` (`knots: needs 9 non-decreasing knots for 5 control points of
    /// degree 3 (got 8)`, `knots[2]: must be increasing (got 1 after 2)`).
    pub(crate) fn at_place(&self, name: &str) -> Error {
        let (p, len) = (self.rule.degree(), self.len);
        let n = self.rule.count(len).unwrap_or(0);
        let what = match self.rule {
            KnotRule::Open { .. } => "non-decreasing knots",
            KnotRule::Breakpoints { .. } => "increasing breakpoints",
        };
        let at = |i: usize| format!("{name}[{i}]");
        match &self.kind {
            FaultKind::Count { want } => Error::invalid(format!(
                "needs {want} {what} for {n} control points of degree {p} (got {len})"
            ))
            .at(name),
            FaultKind::TooFew => Error::invalid(format!(
                "degree {p} needs at least {} {what} (got {len})",
                2 * (p + 1)
            ))
            .at(name),
            FaultKind::NotFinite { at: i, value } => {
                Error::invalid(format!("must be finite (got {value})")).at(&at(*i))
            }
            FaultKind::Decreasing { at: i, value, prev } => Error::invalid(format!(
                "must be {} (got {value} after {prev})",
                match self.rule {
                    KnotRule::Open { .. } => "non-decreasing",
                    KnotRule::Breakpoints { .. } => "increasing",
                }
            ))
            .at(&at(*i)),
            FaultKind::EmptyDomain { a, b } => Error::invalid(format!(
                "the domain [{name}[{p}], {name}[{n}]] = [{a}, {b}] is empty"
            ))
            .at(name),
            FaultKind::Repeated {
                at: i,
                value,
                mult,
                interior,
            } => Error::invalid(format!("{value} {}", self.repeated(*mult, *interior))).at(&at(*i)),
        }
    }

    /// `is repeated 4 times; at most 3 allowed inside the domain (…)`.
    fn repeated(&self, mult: usize, interior: bool) -> String {
        let p = self.rule.degree();
        if interior {
            format!(
                "is repeated {mult} times; at most {p} allowed inside the domain (the spline \
                 would break apart there)"
            )
        } else {
            format!(
                "is repeated {mult} times; at most {} allowed at or outside the ends of the domain",
                p + 1
            )
        }
    }

    /// The library wording: the message names the values (`knots_v[5] = 0.25 is smaller than
    /// knots_v[4] = 0.5; knots must not decrease`); the place is `name`.
    pub(crate) fn named(&self, name: &str) -> Error {
        let (p, len) = (self.rule.degree(), self.len);
        let n = self.rule.count(len).unwrap_or(0);
        let msg = match &self.kind {
            FaultKind::Count { want } => match self.rule {
                KnotRule::Open { .. } => format!(
                    "expected control count + degree + 1 = {n} + {p} + 1 = {want} values, got {len}"
                ),
                KnotRule::Breakpoints { .. } => {
                    format!("expected control count + 1 = {want} values, got {len}")
                }
            },
            FaultKind::TooFew => format!(
                "degree {p} needs at least 2·({p} + 1) knots ({p} + 1 control points), got {len}"
            ),
            FaultKind::NotFinite { at, value } => format!("{name}[{at}] = {value} is not finite"),
            FaultKind::Decreasing { at, value, prev } => match self.rule {
                KnotRule::Open { .. } => format!(
                    "{name}[{at}] = {value} is smaller than {name}[{}] = {prev}; knots must not \
                     decrease",
                    at - 1
                ),
                KnotRule::Breakpoints { .. } => format!(
                    "{name}[{at}] = {value} is not larger than {name}[{}] = {prev}; breakpoints \
                     must increase strictly",
                    at - 1
                ),
            },
            // Worded alike: the message names the knots either way.
            FaultKind::EmptyDomain { .. } => return self.at_place(name),
            FaultKind::Repeated {
                at,
                value,
                mult,
                interior,
            } => format!("{name}[{at}] = {value} {}", self.repeated(*mult, *interior)),
        };
        Error::invalid(msg).at(name)
    }
}

/// Checks a knot vector for `count` control points of degree `p` ([`KnotRule::Open`]); errors
/// in the library wording at the place `name` (`knots_u`).
pub(crate) fn check_knots<T: Scalar>(
    name: &str,
    p: usize,
    count: usize,
    knots: &[T],
) -> Result<()> {
    KnotRule::Open {
        degree: p,
        count: Some(count),
    }
    .check(knots)
    .map_err(|f| f.named(name))
}

/// The span `s` (`p ≤ s < count`, `t_s < t_{s+1}`) whose polynomial piece evaluates `t`: the
/// last non-empty span with `t_s ≤ t`, the first one for `t` before the domain (or NaN). At the
/// domain's end `t = t_count` this is the last non-empty span.
pub(crate) fn find_span<T: Scalar>(knots: &[T], p: usize, count: usize, t: &T) -> usize {
    let first = (p..count).find(|&s| knots[s] < knots[s + 1]).unwrap_or(p);
    if !matches!(
        t.partial_cmp(&knots[first + 1]),
        Some(std::cmp::Ordering::Greater | std::cmp::Ordering::Equal)
    ) {
        return first;
    }
    // Largest s in [p, count) with knots[s] <= t.
    let (mut lo, mut hi) = (p, count);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if &knots[mid] <= t {
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
/// polynomial pieces of span `s` are extended. Exact in exact arithmetic.
///
/// The values come from the Cox–de Boor recursion
/// `N_{i,d} = (t − t_i)/(t_{i+d} − t_i) N_{i,d−1} + (t_{i+d+1} − t)/(t_{i+d+1} − t_{i+1}) N_{i+1,d−1}`
/// started from `N_{s,0} = 1` (terms with a zero denominator vanish). Derivatives use
/// `N'_{i,d} = d (N_{i,d−1}/(t_{i+d} − t_i) − N_{i+1,d−1}/(t_{i+d+1} − t_{i+1}))` unrolled:
/// `N⁽ᵏ⁾_{i,p} = p!/(p−k)! Σ_{j=0}^{k} c_j N_{i+j,p−k}` with
/// `c⁽ᵏ⁾_j = (c⁽ᵏ⁻¹⁾_j − c⁽ᵏ⁻¹⁾_{j−1}) / (t_{i+j+p−k+1} − t_{i+j})`. Orders above `p` are zero.
pub fn basis_derivatives<T: Scalar>(
    knots: &[T],
    p: usize,
    s: usize,
    t: &T,
    order: usize,
    out: &mut [T],
) {
    let w = p + 1;
    let zero = T::zero();
    debug_assert!(out.len() >= (order + 1) * w);
    // table[d][r] = N_{s−d+r, d}(t), r = 0..=d, stored in a (p+1)×(p+1) square.
    let mut table = vec![zero.clone(); w * w];
    table[0] = T::one();
    for d in 1..=p {
        for r in 0..=d {
            let i = s + r - d;
            let mut v = zero.clone();
            if r >= 1 {
                let den = knots[i + d].clone() - knots[i].clone();
                if den > zero {
                    v = v
                        + (t.clone() - knots[i].clone()) / den * table[(d - 1) * w + r - 1].clone();
                }
            }
            if r < d {
                let den = knots[i + d + 1].clone() - knots[i + 1].clone();
                if den > zero {
                    v = v
                        + (knots[i + d + 1].clone() - t.clone()) / den
                            * table[(d - 1) * w + r].clone();
                }
            }
            table[d * w + r] = v;
        }
    }
    out[..w].clone_from_slice(&table[p * w..p * w + w]);
    let mut c = vec![zero.clone(); w + 1];
    let mut prev = vec![zero.clone(); w + 1];
    for k in 1..=order {
        let row = &mut out[k * w..(k + 1) * w];
        if k > p {
            row.fill(zero.clone());
            continue;
        }
        let q = p - k;
        // p!/(p−k)!
        let factor = (q + 1..=p).fold(T::one(), |f, x| f * T::int(x as i64));
        for (r, o) in row.iter_mut().enumerate() {
            let i = s + r - p;
            prev[..=k].fill(zero.clone());
            prev[0] = T::one();
            for kk in 1..=k {
                let qq = p - kk;
                for j in 0..=kk {
                    let a = if j < kk {
                        prev[j].clone()
                    } else {
                        zero.clone()
                    };
                    let b = if j >= 1 {
                        prev[j - 1].clone()
                    } else {
                        zero.clone()
                    };
                    let den = knots[i + j + qq + 1].clone() - knots[i + j].clone();
                    c[j] = if den > zero {
                        (a - b) / den
                    } else {
                        zero.clone()
                    };
                }
                prev[..=kk].clone_from_slice(&c[..=kk]);
            }
            // Σ_j c_j N_{i+j, q}; N_{i+j,q} sits at table[q][r + j − k] when 0 ≤ r+j−k ≤ q.
            let mut v = zero.clone();
            for (j, cj) in prev[..=k].iter().enumerate() {
                if r + j >= k && r + j - k <= q {
                    v = v + cj.clone() * table[q * w + r + j - k].clone();
                }
            }
            *o = factor.clone() * v;
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
        let s = find_span(knots, p, count, &mid);
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
/// for `k = 0..=order`. The knot vector is checked as by [`super::BSplineSurface::new`]. Works in
/// any [`Scalar`]: in exact rationals the values are exact.
pub fn bspline_basis<T: Scalar>(
    knots: &[T],
    p: usize,
    t: T,
    order: usize,
) -> Result<(usize, Vec<T>)> {
    KnotRule::Open {
        degree: p,
        count: None,
    }
    .check(knots)
    .map_err(|f| f.named("knots"))?;
    let n = knots.len() - p - 1;
    let len = order
        .checked_add(1)
        .and_then(|o| o.checked_mul(p + 1))
        .filter(|&l| l <= 1 << 24)
        .ok_or_else(|| Error::invalid(format!("order = {order} is too large")))?;
    let s = find_span(knots, p, n, &t);
    let mut out = vec![T::zero(); len];
    basis_derivatives(knots, p, s, &t, order, &mut out);
    Ok((s, out))
}

/// The B-spline `N_{i,p}(t)` by the recursive definition, independent of the evaluators: the
/// reference the tests check them against. `b` is the end of the domain, where the last
/// non-empty degree-0 function is taken as closed.
#[cfg(test)]
pub(crate) fn cox_de_boor(knots: &[f64], i: usize, p: usize, t: f64, b: f64) -> f64 {
    if p == 0 {
        let (lo, hi) = (knots[i], knots[i + 1]);
        let inside = if t == b {
            lo < hi && hi == b
        } else {
            lo <= t && t < hi
        };
        return if inside { 1.0 } else { 0.0 };
    }
    let mut v = 0.0;
    let d1 = knots[i + p] - knots[i];
    if d1 > 0.0 {
        v += (t - knots[i]) / d1 * cox_de_boor(knots, i, p - 1, t, b);
    }
    let d2 = knots[i + p + 1] - knots[i + 1];
    if d2 > 0.0 {
        v += (knots[i + p + 1] - t) / d2 * cox_de_boor(knots, i + 1, p - 1, t, b);
    }
    v
}
