//! Rotation-minimising frames of the old and new spines (double reflection on `FRAME_STEPS`
//! steps), the jets they are built from, and what is kept between edits of one solved patch
//! (`SolvedSpine`).

use super::wave::Wave;
use crate::curve::{Bezier, Curve};
use crate::elliptic::PdePatch;
use crate::surface::Partials;
use crate::{Error, Result, Vec3};
use nalgebra::Matrix3;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Steps of the precomputed rotation-minimising frames on `u ∈ [0, 1]`.
pub(super) const FRAME_STEPS: usize = 1024;
/// A spine speed `|A₀'|` below this fraction of the design's size has no tangent direction.
pub(super) const MIN_SPEED: f64 = 1e-9;

/// The solved spine `A₀` at the frame nodes `u_k = k / FRAME_STEPS`: its jets and its
/// rotation-minimising frames `F(u_k)`.
#[derive(Debug)]
pub(crate) struct SolvedFrames {
    pub(super) jets: Vec<Jet>,
    pub(super) frames: Vec<Matrix3<f64>>,
}

/// Grids of at most this many points keep the solved patch's partials between edits.
const KEPT_GRID_POINTS: usize = 1 << 16;

/// What does not change while the spine of one solved patch is edited again and again (a drag
/// in the designer): the solved spine's frames, and the solved patch's partials on the grid
/// last tessellated (for grids up to [`KEPT_GRID_POINTS`] points; kept from the second edit
/// on, so that a single edit, or an animation that re-solves its patch every frame, pays
/// nothing for it).
#[derive(Debug, Default)]
pub(crate) struct SolvedSpine {
    frames: Mutex<Option<Arc<SolvedFrames>>>,
    keep_rows: bool,
    pub(super) rows: Mutex<KeptRows>,
}

/// The solved patch's partials on grid rows: the columns `vs` and one row per `u` (by its bits).
#[derive(Debug, Default)]
pub(super) struct KeptRows {
    vs: Vec<f64>,
    pub(super) rows: HashMap<u64, Arc<[Partials]>>,
}

impl SolvedSpine {
    /// The same solved patch's state for a further edit: rows are kept from now on.
    pub(super) fn again(&self) -> Arc<SolvedSpine> {
        let frames = self.frames.lock().map(|f| f.clone()).unwrap_or_default();
        let rows = if self.keep_rows {
            self.rows
                .lock()
                .map(|r| KeptRows {
                    vs: r.vs.clone(),
                    rows: r.rows.clone(),
                })
                .unwrap_or_default()
        } else {
            KeptRows::default()
        };
        Arc::new(SolvedSpine {
            frames: Mutex::new(frames),
            keep_rows: true,
            rows: Mutex::new(rows),
        })
    }

    /// The solved spine's frames, computed once.
    pub(super) fn frames(&self, base: &PdePatch) -> Result<Arc<SolvedFrames>> {
        let mut slot = self
            .frames
            .lock()
            .map_err(|_| Error::invalid("the spine's frames were poisoned"))?;
        if let Some(f) = slot.as_ref() {
            return Ok(f.clone());
        }
        let tiny = MIN_SPEED * base.scale();
        let mut jets: Vec<Jet> = Vec::with_capacity(FRAME_STEPS + 1);
        let mut frames: Vec<Matrix3<f64>> = Vec::with_capacity(FRAME_STEPS + 1);
        for k in 0..=FRAME_STEPS {
            let u = k as f64 / FRAME_STEPS as f64;
            let j = old_jet(base, u);
            let t = unit_tangent(&j, tiny, u, "solved")?;
            let f = match (frames.last(), jets.last()) {
                (Some(f), Some(p)) => reflect(f, &p[0], &j[0], &t),
                _ => frame_from(&t),
            };
            jets.push(j);
            frames.push(f);
        }
        let f = Arc::new(SolvedFrames { jets, frames });
        *slot = Some(f.clone());
        Ok(f)
    }

    /// Row `u` of the solved patch's partials at the columns `vs`, if it is kept.
    pub(super) fn kept_row(&self, vs: &[f64], u: f64) -> Option<Arc<[Partials]>> {
        if !self.keep_rows {
            return None;
        }
        let kept = self.rows.lock().ok()?;
        (kept.vs == vs).then(|| kept.rows.get(&u.to_bits()).cloned())?
    }

    /// Keeps row `u` (grids up to [`KEPT_GRID_POINTS`] points).
    pub(super) fn keep_row(&self, vs: &[f64], u: f64, row: &[Partials]) {
        if !self.keep_rows {
            return;
        }
        if let Ok(mut kept) = self.rows.lock() {
            if kept.vs != vs {
                kept.vs = vs.to_vec();
                kept.rows.clear();
            }
            if (kept.rows.len() + 1) * vs.len() <= KEPT_GRID_POINTS {
                kept.rows.insert(u.to_bits(), row.into());
            }
        }
    }
}

/// The unit tangent of a spine's jet at `u`, or the refusal of a spine without one.
pub(super) fn unit_tangent(j: &Jet, tiny: f64, u: f64, which: &str) -> Result<Vec3> {
    let speed = j[1].norm();
    if speed.is_nan() || speed <= tiny {
        return Err(Error::invalid(format!(
            "the {which} spine has no tangent at u = {u} (speed {speed:.3e}): the sections \
             cannot turn with it; use carry = \"translate\""
        ))
        .at("carry"));
    }
    Ok(j[1] / speed)
}

/// `A` and its first three derivatives at `u`.
pub(super) type Jet = [Vec3; 4];

/// The new spine's jet: the Bézier curve's plus the wave's.
pub(super) fn new_jet(b: &Bezier, wave: &Option<Wave>, u: f64) -> Jet {
    let mut j = bezier_jet(b, u);
    if let Some(w) = wave {
        for (k, jk) in j.iter_mut().enumerate() {
            *jk += w.direction * w.derivative(u, k);
        }
    }
    j
}

pub(super) fn old_jet(p: &PdePatch, u: f64) -> Jet {
    [p.spine(u, 0), p.spine(u, 1), p.spine(u, 2), p.spine(u, 3)]
}

fn bezier_jet(b: &Bezier, u: f64) -> Jet {
    let mut out = [Vec3::zeros(); 4];
    b.jet(u, &mut out);
    out
}

/// `(T, ω, ω')` of a curve from its jet: `T = A'/|A'|`, `ω = T × T'`, `ω' = T × T''`.
pub(super) fn angular(j: &Jet) -> (Vec3, Vec3, Vec3) {
    let g = j[1].norm();
    if g == 0.0 {
        return (Vec3::zeros(), Vec3::zeros(), Vec3::zeros());
    }
    let t = j[1] / g;
    let g1 = t.dot(&j[2]);
    let t1 = (j[2] - t * g1) / g;
    let g2 = t1.dot(&j[2]) + t.dot(&j[3]);
    let t2 = (j[3] - t1 * (2.0 * g1) - t * g2) / g;
    (t, t.cross(&t1), t.cross(&t2))
}

pub(super) fn skew(w: &Vec3) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// The rotation taking unit `a` to unit `b` about `a × b` (a half turn about some axis normal
/// to `a` when they are opposite).
pub(super) fn min_rotation(a: &Vec3, b: &Vec3) -> Matrix3<f64> {
    let c = a.dot(b);
    let axis = a.cross(b);
    let s = axis.norm();
    if s < 1e-12 {
        if c > 0.0 {
            return Matrix3::identity();
        }
        let helper = if a.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        let k = a.cross(&helper).normalize();
        return Matrix3::identity() * -1.0 + k * k.transpose() * 2.0;
    }
    let k = axis / s;
    Matrix3::identity() * c + skew(&k) * s + k * k.transpose() * (1.0 - c)
}

/// A frame `[T r s]` with first column `t`.
fn frame_from(t: &Vec3) -> Matrix3<f64> {
    let helper = if t.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let r = (helper - t * t.dot(&helper)).normalize();
    let s = t.cross(&r);
    Matrix3::from_columns(&[*t, r, s])
}

/// One double-reflection step of a frame `f` (columns `T, r, s`) from the point `x0` to `x1`
/// with the unit tangent `t1` there.
pub(super) fn reflect(f: &Matrix3<f64>, x0: &Vec3, x1: &Vec3, t1: &Vec3) -> Matrix3<f64> {
    let (t0, r0): (Vec3, Vec3) = (f.column(0).into(), f.column(1).into());
    let v1 = x1 - x0;
    let c1 = v1.dot(&v1);
    let (rl, tl) = if c1 > 0.0 {
        (
            r0 - v1 * (2.0 / c1 * v1.dot(&r0)),
            t0 - v1 * (2.0 / c1 * v1.dot(&t0)),
        )
    } else {
        (r0, t0)
    };
    let v2 = t1 - tl;
    let c2 = v2.dot(&v2);
    let r1 = if c2 > 0.0 {
        rl - v2 * (2.0 / c2 * v2.dot(&rl))
    } else {
        rl
    };
    // Re-orthonormalise against rounding drift.
    let r1 = (r1 - t1 * t1.dot(&r1)).normalize();
    Matrix3::from_columns(&[*t1, r1, t1.cross(&r1)])
}
