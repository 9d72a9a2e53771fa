//! Orientation: the parity union–find of the patches' relative turns, the groups a volume turns
//! over (closed, or open and capped by a cone from the rim's centroid) and the signed volumes
//! behind that choice.

use super::join::GridTopology;
use super::OPEN_VOLUME_FRACTION;
use rayon::prelude::*;

/// Union–find with the parity of a patch's orientation relative to its group's root.
pub(super) struct Parity {
    parent: Vec<usize>,
    flip: Vec<bool>,
    pub(super) conflict: Vec<bool>,
}

impl Parity {
    pub(super) fn new(n: usize) -> Self {
        Parity {
            parent: (0..n).collect(),
            flip: vec![false; n],
            conflict: vec![false; n],
        }
    }

    /// Root of `a` and the parity of `a` relative to it.
    pub(super) fn find(&mut self, a: usize) -> (usize, bool) {
        let mut parity = false;
        let mut x = a;
        while self.parent[x] != x {
            parity ^= self.flip[x];
            x = self.parent[x];
        }
        (x, parity)
    }

    /// Records that `a` and `b` must differ in orientation by `differ`.
    pub(super) fn join(&mut self, a: usize, b: usize, differ: bool) {
        let (ra, pa) = self.find(a);
        let (rb, pb) = self.find(b);
        if ra == rb {
            if pa ^ pb != differ {
                self.conflict[ra] = true;
            }
            return;
        }
        // Attach the larger index's root under the smaller's, so a group's root is its first
        // patch.
        let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        self.parent[hi] = lo;
        self.flip[hi] = pa ^ pb ^ differ;
        if self.conflict[hi] {
            self.conflict[lo] = true;
        }
    }
}

/// Each grid's turn: its orientation relative to its group's root, and the root's `turns`
/// (the groups a volume turned over).
pub(super) fn flipped_of(relative: &[(usize, bool)], turns: &[(usize, bool)]) -> Vec<bool> {
    relative
        .iter()
        .map(|&(root, rel)| rel ^ turns.iter().any(|&(r, turn)| r == root && turn))
        .collect()
}

#[derive(Clone, Debug, PartialEq)]
pub(super) struct Group {
    pub(super) root: usize,
    pub(super) members: Vec<usize>,
    pub(super) closed: bool,
    /// The first vertex of every rim edge (used once), in the order of the triangles.
    pub(super) rim: Vec<u32>,
}

impl Group {
    /// Where the cones closing an open group meet: the centroid of its rim (the origin for a
    /// closed group, whose volume does not depend on it).
    pub(super) fn apex(&self, positions: &[[f32; 3]]) -> [f64; 3] {
        if self.closed {
            return [0.0; 3];
        }
        let mut sum = [0.0f64; 3];
        for &a in &self.rim {
            let p = positions[a as usize];
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
        }
        sum.map(|x| x / self.rim.len().max(1) as f64)
    }

    /// Whether the group is turned over, given the signed volumes of its members' triangles
    /// (as the grids have them, before any turn) about [`Group::apex`], in member order: a
    /// closed group whose enclosed volume is negative, or an open one whose volume closed by a
    /// cone from the centroid of its rim (what `analyze` calls the capped volume) is negative
    /// and not next to nothing (a sheet keeps its first patch's side).
    pub(super) fn turned_over(
        &self,
        relative: &[(usize, bool)],
        volumes: impl IntoIterator<Item = f64>,
        diag: f64,
    ) -> bool {
        let mut volume = 0.0f64;
        for (&k, v) in self.members.iter().zip(volumes) {
            let sign = if relative[k].1 { -1.0 } else { 1.0 };
            volume += sign * v;
        }
        let encloses = self.closed || volume.abs() > OPEN_VOLUME_FRACTION * diag.powi(3);
        encloses && volume < 0.0
    }

    /// [`Group::turned_over`] with the members' volumes summed over their grids' triangles: in
    /// parallel, in any order, when that cannot change the answer; else in the triangles' order.
    ///
    /// Any order of summing `n` terms lands within `γ·Σ|term|` of their exact sum (`γ = n·2⁻⁵³`,
    /// to first order), so two orders differ by at most twice that, and the group's volume (a
    /// sum of the members' with signs) by at most the sum of those plus its own rounding. When
    /// the volume found in parallel is farther than a generous multiple of that from zero and
    /// from the threshold of [`OPEN_VOLUME_FRACTION`], the triangles' order decides alike.
    pub(super) fn turned_over_soon(
        &self,
        topo: &[GridTopology],
        positions: &[[f32; 3]],
        relative: &[(usize, bool)],
        diag: f64,
    ) -> bool {
        let apex = self.apex(positions);
        // (sum, sum of absolute values, terms) of each member, quad rows in parallel.
        let sums: Vec<(f64, f64, usize)> = self
            .members
            .par_iter()
            .map(|&k| {
                let t = &topo[k];
                (0..t.nu.saturating_sub(1))
                    .into_par_iter()
                    .with_min_len(16)
                    .map(|i| {
                        let (mut s, mut a, mut n) = (0.0f64, 0.0f64, 0usize);
                        for j in 0..t.cols {
                            for tri in t.quad(i, j) {
                                if let Some(w) = t.welded(tri) {
                                    let v = volume_term(positions, w, apex);
                                    s += v;
                                    a += v.abs();
                                    n += 1;
                                }
                            }
                        }
                        (s, a, n)
                    })
                    .reduce(|| (0.0, 0.0, 0), |x, y| (x.0 + y.0, x.1 + y.1, x.2 + y.2))
            })
            .collect();
        let mut volume = 0.0f64;
        for (&k, &(v, _, _)) in self.members.iter().zip(&sums) {
            volume += if relative[k].1 { -v } else { v };
        }
        let size: f64 = sums.iter().map(|&(v, a, _)| a + v.abs()).sum();
        let terms: usize = sums.iter().map(|&(_, _, n)| n).sum::<usize>() + sums.len();
        let slack = 8.0 * (terms as f64 + 4.0) * f64::EPSILON * size;
        let threshold = OPEN_VOLUME_FRACTION * diag.powi(3);
        let clear = volume.abs() > slack
            && (self.closed || (volume.abs() - threshold).abs() > slack)
            && slack.is_finite();
        if clear {
            self.turned_over(relative, sums.iter().map(|&(v, _, _)| v), diag)
        } else {
            let exact = self.members.iter().map(|&k| {
                topo[k]
                    .kept()
                    .map(|t| volume_term(positions, t, apex))
                    .sum::<f64>()
            });
            self.turned_over(relative, exact, diag)
        }
    }
}

/// A triangle as written: turned over (`[a, c, b]`) when its patch is.
pub(super) fn turned(t: [u32; 3], flip: bool) -> [u32; 3] {
    if flip {
        [t[0], t[2], t[1]]
    } else {
        t
    }
}

/// `(b − a) × (c − a)` in f64.
pub fn facet_cross(p: &[[f32; 3]], t: [u32; 3]) -> [f64; 3] {
    // Corner by corner rather than through `t.map`, which the compiler does not always inline
    // in this hot loop (the same arithmetic).
    let at = |i: u32| {
        let q = p[i as usize];
        [q[0] as f64, q[1] as f64, q[2] as f64]
    };
    let (a, b, c) = (at(t[0]), at(t[1]), at(t[2]));
    let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ]
}

/// `Σ a · (b × c) / 6` over the triangles: the enclosed volume of a closed, outward mesh.
pub(super) fn signed_volume_of(p: &[[f32; 3]], tris: &[[u32; 3]]) -> f64 {
    signed_volume_about(p, tris, [0.0; 3])
}

/// `Σ (a − o) · ((b − o) × (c − o)) / 6`: the signed volume of the triangles closed by cones to
/// `o` (for a closed mesh, the enclosed volume whatever `o`).
pub(super) fn signed_volume_about(p: &[[f32; 3]], tris: &[[u32; 3]], o: [f64; 3]) -> f64 {
    tris.iter().map(|&t| volume_term(p, t, o)).sum()
}

/// `(a − o) · ((b − o) × (c − o)) / 6` of one triangle.
#[inline(always)]
fn volume_term(p: &[[f32; 3]], t: [u32; 3], o: [f64; 3]) -> f64 {
    let at = |i: u32| {
        let q = p[i as usize];
        [q[0] as f64 - o[0], q[1] as f64 - o[1], q[2] as f64 - o[2]]
    };
    let (a, b, c) = (at(t[0]), at(t[1]), at(t[2]));
    let bc = [
        b[1] * c[2] - b[2] * c[1],
        b[2] * c[0] - b[0] * c[2],
        b[0] * c[1] - b[1] * c[0],
    ];
    (a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2]) / 6.0
}
