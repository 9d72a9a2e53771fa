//! Index sets of the multivariate Bézier patches and dual bases, and the small integer
//! functions they need, over the crate's [`Scalar`] (`f64` or exact [`BigRational`]).

pub use crate::scalar::Scalar;
use num_rational::BigRational;

/// The exact rational equal to a finite `f64` (every finite float is a dyadic rational); `None`
/// for NaN and infinities.
pub fn rational_from_f64(x: f64) -> Option<BigRational> {
    <BigRational as Scalar>::from_f64(x)
}

/// `n!/(n−k)! = n (n−1) ⋯ (n−k+1)` (1 for `k = 0`; requires `k ≤ n`).
pub(crate) fn falling<T: Scalar>(n: usize, k: usize) -> T {
    let mut f = T::one();
    for x in n + 1 - k..=n {
        f = f * T::int(x as i64);
    }
    f
}

/// The binomial coefficient `C(n, k)` by Pascal's rule (exact in `f64` up to 2⁵³).
pub(crate) fn binomial<T: Scalar>(n: usize, k: usize) -> T {
    if k > n {
        return T::zero();
    }
    let k = k.min(n - k);
    let mut row = vec![T::zero(); k + 1];
    row[0] = T::one();
    for i in 1..=n {
        for j in (1..=k.min(i)).rev() {
            row[j] = row[j].clone() + row[j - 1].clone();
        }
    }
    row[k].clone()
}

/// A finite, downward-closed set of multi-indices `α ∈ Z₊ᵐ` in lexicographic order: the box
/// `{α ≤ d}` or the simplex `{|α| ≤ n}`. Values attached to the set are stored in this order,
/// `dim` coordinates per index.
#[derive(Clone, Debug, PartialEq)]
pub struct IndexSet {
    m: usize,
    /// Per axis, the largest index any member has there.
    extent: Vec<usize>,
    indices: Vec<Vec<usize>>,
    /// Dense lookup on the bounding box: position in `indices`, or `usize::MAX`.
    lookup: Vec<usize>,
}

/// Most variables `m` accepted for an index set.
pub const MAX_VARS: usize = 32;

/// Largest bounding box accepted for an index set (entries).
pub const MAX_INDEX_BOX: usize = 1 << 22;

impl IndexSet {
    /// The box `{α : α ≤ d}` (`(d_1+1)⋯(d_m+1)` members), `m = d.len() ≥ 1`.
    pub fn boxed(d: &[usize]) -> crate::Result<Self> {
        Self::build(d.to_vec(), |_| true)
    }

    /// The simplex `{α ∈ Z₊ᵐ : |α| ≤ n}` (`C(n+m, m)` members), `m ≥ 1`.
    pub fn simplex(m: usize, n: usize) -> crate::Result<Self> {
        if m > MAX_VARS {
            return Err(crate::Error::invalid(format!(
                "m = {m}: at most {MAX_VARS} variables"
            )));
        }
        Self::build(vec![n; m], |a: &[usize]| a.iter().sum::<usize>() <= n)
    }

    fn build(extent: Vec<usize>, keep: impl Fn(&[usize]) -> bool) -> crate::Result<Self> {
        let m = extent.len();
        if m > MAX_VARS {
            return Err(crate::Error::invalid(format!(
                "m = {m}: at most {MAX_VARS} variables"
            )));
        }
        if m == 0 {
            return Err(crate::Error::invalid(
                "the number of variables m must be at least 1",
            ));
        }
        let mut total: usize = 1;
        for (j, &d) in extent.iter().enumerate() {
            total = d
                .checked_add(1)
                .and_then(|e| total.checked_mul(e))
                .filter(|&t| t <= MAX_INDEX_BOX)
                .ok_or_else(|| {
                    crate::Error::invalid(format!(
                        "degree[{j}] = {d}: the index box would exceed {MAX_INDEX_BOX} entries"
                    ))
                })?;
        }
        let mut indices = Vec::new();
        let mut lookup = vec![usize::MAX; total];
        let mut a = vec![0usize; m];
        for (flat, slot) in lookup.iter_mut().enumerate() {
            // flat → α, last axis fastest.
            let mut r = flat;
            for j in (0..m).rev() {
                a[j] = r % (extent[j] + 1);
                r /= extent[j] + 1;
            }
            if keep(&a) {
                *slot = indices.len();
                indices.push(a.clone());
            }
        }
        Ok(IndexSet {
            m,
            extent,
            indices,
            lookup,
        })
    }

    /// Number of variables `m`.
    pub fn vars(&self) -> usize {
        self.m
    }
    /// Number of members.
    pub fn len(&self) -> usize {
        self.indices.len()
    }
    /// Never true (every set holds `0`); present for the usual pairing with `len`.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }
    /// The members in storage order.
    pub fn indices(&self) -> &[Vec<usize>] {
        &self.indices
    }
    /// Position of `α` in storage order, if it is a member.
    pub fn position(&self, alpha: &[usize]) -> Option<usize> {
        if alpha.len() != self.m {
            return None;
        }
        let mut flat = 0usize;
        for (a, e) in alpha.iter().zip(&self.extent) {
            if a > e {
                return None;
            }
            flat = flat * (e + 1) + a;
        }
        let p = self.lookup[flat];
        (p != usize::MAX).then_some(p)
    }
}
