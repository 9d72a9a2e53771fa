//! Editing the spine of a PDE patch (book §5.3, Figs. 5.12–5.13).
//!
//! A solved patch is `X(u, v) = A₀(u) + D(u, v)` with the spine `A₀` (the mode-0 solution, a
//! polynomial of degree `2N − 1`: mode 0 of `(∂²/∂u² + a²∂²/∂v²)^N` is `A₀^{(2N)} = 0`) and the
//! radial part `D = Σ Aₙ cos nv + Bₙ sin nv (+ the remainder)`. A spine edit keeps `D` and
//! replaces `A₀` by a new polynomial `Ã₀` given by Bézier control points:
//!
//! * `carry = "translate"` (the book's reading): `X̃ = Ã₀ + D`; every section `v ↦ X(u, v)` is
//!   translated by `Ã₀(u) − A₀(u)`.
//! * `carry = "frame"` (the default): `X̃ = Ã₀ + R(u) D`, with `R(u) = F̃(u) F(u)ᵀ` the rotation
//!   from the rotation-minimising frame `F = [T r s]` of the old spine to that of the new one
//!   (Bishop frames: `F' = [ω]ₓ F`, `ω = T × T'`, no turn about the tangent). A section that
//!   lay across the old spine's tangent lies across the new one's: a bent spine bends the
//!   tube instead of shearing it (translated sections stay parallel to themselves, so a spine
//!   bent by 90° flattens the tube where the spine runs along the old sections). That is why
//!   it is the default; `translate` is the book's method and keeps section planes fixed.
//!
//! The frames come from the double-reflection method (Wang, Jüttler, Zheng, Liu 2008, fourth
//! order) on `FRAME_STEPS` steps of `u` and one further step to any `u` (about 10⁻¹³ of the
//! design's size for smooth spines). The rotation `R` they give is then fitted by one
//! Chebyshev series ([`RotationSeries`], to 10⁻¹²), which is the surface's rotation from then
//! on: `R'` and `R''` are its derivatives, so the partials are exact derivatives of the
//! surface's points, and the series' coefficients bound every derivative
//! ([`SpineEdited::derivative_sums`], the certified CAD export). Only where the series does
//! not settle (frames that are not smooth) does the surface use the stepped frames, with `R'`
//! and `R''` from the frame equation `R' = [ω̃]ₓ R − R [ω]ₓ`.

use super::solved::{DesignSurface, SurfaceKind};
use super::spine_series::RotationSeries;
use crate::curve::{Bezier, Curve};
use crate::elliptic::{mode_sum, PdePatch};
use crate::spec::{SpineCarry, SpineSpec, SpineWave, WaveKind, MAX_WAVE_TERMS};
use crate::surface::{Partials, PartialsRows, RowBuf, RowEvaluator, Spine, Surface, VDomain};
use crate::{Error, Result, Vec3};
use nalgebra::Matrix3;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Steps of the precomputed rotation-minimising frames on `u ∈ [0, 1]`.
const FRAME_STEPS: usize = 1024;
/// A spine speed `|A₀'|` below this fraction of the design's size has no tangent direction.
const MIN_SPEED: f64 = 1e-9;

/// The Bézier control points `P_0 … P_d` (`d = 2N − 1`) of a patch's spine `A₀` on `[0, 1]`.
///
/// For the cubic spine of a biharmonic patch they come from the end values and speeds,
/// `[A₀(0), A₀(0) + A₀'(0)/3, A₀(1) − A₀'(1)/3, A₀(1)]` (the Hermite form of Eq. 5.4 with the
/// corrected Eqs. 5.5–5.8 of `docs/errata.md`); for other degrees by collocation at the `d + 1`
/// Chebyshev–Lobatto points of `[0, 1]` (LU with full pivoting). The collocation matrix of the
/// Bernstein basis grows ill-conditioned with the degree (about 10 for `d = 3`, 10⁴ for
/// `d = 11`): beyond `N ≈ 10` the control points carry correspondingly fewer digits.
pub fn spine_control_points(patch: &PdePatch) -> Vec<Vec3> {
    let d = patch.conditions().len().max(2) - 1;
    if d == 3 {
        let [p0, p1, d0, d1] = spine_hermite_of(patch);
        return vec![p0, p0 + d0 / 3.0, p1 - d1 / 3.0, p1];
    }
    let nodes: Vec<f64> = (0..=d)
        .map(|i| 0.5 * (1.0 - (std::f64::consts::PI * i as f64 / d as f64).cos()))
        .collect();
    let m = nalgebra::DMatrix::from_fn(d + 1, d + 1, |i, j| bernstein(d, j, nodes[i]));
    let rhs = nalgebra::DMatrix::from_fn(d + 1, 3, |i, c| patch.spine(nodes[i], 0)[c]);
    let sol = m.full_piv_lu().solve(&rhs).unwrap_or(rhs);
    (0..=d)
        .map(|i| Vec3::new(sol[(i, 0)], sol[(i, 1)], sol[(i, 2)]))
        .collect()
}

/// `[p0, p1, d0, d1]`: the spine's end positions and end speeds (its Hermite form, Eq. 5.4).
pub fn spine_hermite_of(patch: &PdePatch) -> [Vec3; 4] {
    [
        patch.spine(0.0, 0),
        patch.spine(1.0, 0),
        patch.spine(0.0, 1),
        patch.spine(1.0, 1),
    ]
}

fn bernstein(d: usize, j: usize, t: f64) -> f64 {
    let binom = (0..j).fold(1.0, |b, i| b * (d - i) as f64 / (i + 1) as f64);
    binom * t.powi(j as i32) * (1.0 - t).powi((d - j) as i32)
}

/// The control points of the new spine a `[[spine]]` table asks for, from the solved patch's
/// own; errors are placed inside the table (`control`, `moves[1].index`, `hermite`).
pub fn spine_target(patch: &PdePatch, spec: &SpineSpec) -> Result<Vec<Vec3>> {
    let solved = spine_control_points(patch);
    let n = solved.len();
    let v3 = |v: &[f64; 3]| Vec3::new(v[0], v[1], v[2]);
    let given = spec.control.is_some() as usize
        + !spec.moves.is_empty() as usize
        + spec.hermite.is_some() as usize;
    if given > 1 || (given == 0 && spec.wave.is_none()) {
        return Err(Error::invalid(format!(
            "give exactly one of `control`, `moves` and `hermite`, or a `wave` (got {given})"
        )));
    }
    if let Some(control) = &spec.control {
        if control.len() != n {
            return Err(Error::invalid(format!(
                "the spine of this patch has degree {} and needs {n} control points (got {})",
                n - 1,
                control.len()
            ))
            .at("control"));
        }
        return Ok(control.iter().map(v3).collect());
    }
    if let Some(h) = &spec.hermite {
        if n != 4 {
            return Err(Error::invalid(format!(
                "a Hermite spine is cubic; the spine of this patch has degree {}: give `control`",
                n - 1
            ))
            .at("hermite"));
        }
        let (p0, p1, d0, d1) = (v3(&h.p0), v3(&h.p1), v3(&h.d0), v3(&h.d1));
        return Ok(vec![p0, p0 + d0 / 3.0, p1 - d1 / 3.0, p1]);
    }
    let mut control = solved;
    for (i, m) in spec.moves.iter().enumerate() {
        let slot = control.get_mut(m.index).ok_or_else(|| {
            Error::invalid(format!(
                "control point {} does not exist (the spine has {n})",
                m.index
            ))
            .at(&format!("moves[{i}].index"))
        })?;
        *slot += v3(&m.by);
    }
    Ok(control)
}

/// A PDE patch whose spine was replaced: `X̃ = Ã₀ + D` or `Ã₀ + R D` (see the module's text).
#[derive(Debug)]
pub struct SpineEdited {
    base: Arc<PdePatch>,
    spine: Bezier,
    /// A lateral wave added to the Bézier spine.
    wave: Option<Wave>,
    carry: SpineCarry,
    /// What this edit shares with the other edits of the same solved patch.
    solved: Arc<SolvedSpine>,
    /// The solved spine's frames (frame mode only).
    old_frames: Option<Arc<SolvedFrames>>,
    /// `(F̃(u_k), Ã₀(u_k))` at `u_k = k / FRAME_STEPS` (frame mode only).
    frames: Vec<(Matrix3<f64>, Vec3)>,
    /// The rotation `R = F̃ Fᵀ` as one Chebyshev series (frame mode, when it settles): the
    /// surface's rotation, see [`RotationSeries`].
    series: Option<RotationSeries>,
}

/// The solved spine `A₀` at the frame nodes `u_k = k / FRAME_STEPS`: its jets and its
/// rotation-minimising frames `F(u_k)`.
#[derive(Debug)]
pub(crate) struct SolvedFrames {
    jets: Vec<Jet>,
    frames: Vec<Matrix3<f64>>,
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
    rows: Mutex<KeptRows>,
}

/// The solved patch's partials on grid rows: the columns `vs` and one row per `u` (by its bits).
#[derive(Debug, Default)]
struct KeptRows {
    vs: Vec<f64>,
    rows: HashMap<u64, Arc<[Partials]>>,
}

impl SolvedSpine {
    /// The same solved patch's state for a further edit: rows are kept from now on.
    fn again(&self) -> Arc<SolvedSpine> {
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
    fn frames(&self, base: &PdePatch) -> Result<Arc<SolvedFrames>> {
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
    fn kept_row(&self, vs: &[f64], u: f64) -> Option<Arc<[Partials]>> {
        if !self.keep_rows {
            return None;
        }
        let kept = self.rows.lock().ok()?;
        (kept.vs == vs).then(|| kept.rows.get(&u.to_bits()).cloned())?
    }

    /// Keeps row `u` (grids up to [`KEPT_GRID_POINTS`] points).
    fn keep_row(&self, vs: &[f64], u: f64, row: &[Partials]) {
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
fn unit_tangent(j: &Jet, tiny: f64, u: f64, which: &str) -> Result<Vec3> {
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
type Jet = [Vec3; 4];

/// A checked spine wave (§8.1.3.2): `w(u) d`, see [`SpineWave`].
#[derive(Clone, Debug, PartialEq)]
pub struct Wave {
    kind: WaveKind,
    amplitude: Vec<f64>,
    alpha: f64,
    /// `2π ω time`.
    angle: f64,
    phase: f64,
    direction: Vec3,
}

impl Wave {
    /// Checks a `wave` table (errors placed inside it: `wave.amplitude`, `wave.direction`).
    pub fn new(spec: &SpineWave) -> Result<Wave> {
        let n = spec.amplitude.len();
        if n == 0 || n > MAX_WAVE_TERMS {
            return Err(Error::invalid(format!(
                "give 1 to {MAX_WAVE_TERMS} coefficients of Ω(u) = a₀ + a₁u + … (got {n})"
            ))
            .at("wave.amplitude"));
        }
        let d = Vec3::new(spec.direction[0], spec.direction[1], spec.direction[2]);
        let len = d.norm();
        if !(len.is_finite() && len > 0.0) {
            return Err(Error::invalid("must be a non-zero vector").at("wave.direction"));
        }
        let angle = 2.0 * std::f64::consts::PI * spec.omega * spec.time;
        if !angle.is_finite() {
            return Err(
                Error::invalid(format!("2π·omega·time must be finite (got {angle})"))
                    .at("wave.omega"),
            );
        }
        Ok(Wave {
            kind: spec.kind,
            amplitude: spec.amplitude.clone(),
            alpha: spec.alpha,
            angle,
            phase: spec.phase,
            direction: d / len,
        })
    }

    /// `dᵏw/duᵏ` at `u` for `k = order` (Leibniz's rule on `Ω(u) g(u)`).
    pub fn derivative(&self, u: f64, order: usize) -> f64 {
        // dʲΩ/duʲ by Horner on the differentiated coefficients.
        let omega = |j: usize| -> f64 {
            let mut acc = 0.0;
            for (i, &a) in self.amplitude.iter().enumerate().skip(j).rev() {
                let falling = ((i + 1 - j)..=i).fold(1.0, |f, m| f * m as f64);
                acc = acc * u + a * falling;
            }
            acc
        };
        // dᵐ/duᵐ of sin(αu + c) is αᵐ sin(αu + c + mπ/2).
        let (arg, factor) = match self.kind {
            WaveKind::Travelling => (self.alpha * u - self.angle + self.phase, 1.0),
            WaveKind::Standing => (
                self.alpha * u + self.phase + std::f64::consts::FRAC_PI_2,
                self.angle.sin(),
            ),
        };
        let (s, c) = arg.sin_cos();
        let g = |m: usize| -> f64 {
            let turn = [s, c, -s, -c][m % 4];
            factor * self.alpha.powi(m as i32) * turn
        };
        let mut binom = 1.0;
        let mut sum = 0.0;
        for j in 0..=order {
            if j > 0 {
                binom = binom * (order + 1 - j) as f64 / j as f64;
            }
            if j < self.amplitude.len() {
                sum += binom * omega(j) * g(order - j);
            }
        }
        sum
    }

    /// A bound of `sup_{u ∈ [0, 1]} |dᵏw/duᵏ|`: Leibniz's rule with `|Ω⁽ʲ⁾| ≤ Σ_i |a_i| i!/(i − j)!`
    /// (`|u| ≤ 1`) and `|g⁽ᵐ⁾| ≤ |factor| αᵐ`.
    pub fn bound(&self, order: usize) -> f64 {
        let factor = match self.kind {
            WaveKind::Travelling => 1.0,
            WaveKind::Standing => self.angle.sin().abs(),
        };
        let omega = |j: usize| -> f64 {
            self.amplitude
                .iter()
                .enumerate()
                .skip(j)
                .map(|(i, a)| a.abs() * ((i + 1 - j)..=i).fold(1.0, |f, m| f * m as f64))
                .sum()
        };
        let mut binom = 1.0;
        let mut sum = 0.0;
        for j in 0..=order {
            if j > 0 {
                binom = binom * (order + 1 - j) as f64 / j as f64;
            }
            sum += binom * omega(j) * factor * self.alpha.abs().powi((order - j) as i32);
        }
        sum * (1.0 + 1e-12)
    }

    /// The lateral displacement `w(u)` along the unit direction.
    pub fn displacement(&self, u: f64) -> f64 {
        self.derivative(u, 0)
    }

    /// The unit direction of the displacement.
    pub fn direction(&self) -> Vec3 {
        self.direction
    }
}

/// The new spine's jet: the Bézier curve's plus the wave's.
fn new_jet(b: &Bezier, wave: &Option<Wave>, u: f64) -> Jet {
    let mut j = bezier_jet(b, u);
    if let Some(w) = wave {
        for (k, jk) in j.iter_mut().enumerate() {
            *jk += w.direction * w.derivative(u, k);
        }
    }
    j
}

fn old_jet(p: &PdePatch, u: f64) -> Jet {
    [p.spine(u, 0), p.spine(u, 1), p.spine(u, 2), p.spine(u, 3)]
}

fn bezier_jet(b: &Bezier, u: f64) -> Jet {
    let mut out = [Vec3::zeros(); 4];
    b.jet(u, &mut out);
    out
}

/// `(T, ω, ω')` of a curve from its jet: `T = A'/|A'|`, `ω = T × T'`, `ω' = T × T''`.
fn angular(j: &Jet) -> (Vec3, Vec3, Vec3) {
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

fn skew(w: &Vec3) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// The rotation taking unit `a` to unit `b` about `a × b` (a half turn about some axis normal
/// to `a` when they are opposite).
fn min_rotation(a: &Vec3, b: &Vec3) -> Matrix3<f64> {
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
fn reflect(f: &Matrix3<f64>, x0: &Vec3, x1: &Vec3, t1: &Vec3) -> Matrix3<f64> {
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

impl SpineEdited {
    /// The patch `base` with its spine replaced by the Bézier curve of `control` (degree
    /// `2N − 1`, as many points as the patch has conditions). In frame mode the old and the
    /// new spine need a tangent everywhere: a spine whose speed falls below 10⁻⁹ of the
    /// design's size at a frame node is refused (use `carry = "translate"`).
    pub fn new(base: Arc<PdePatch>, control: Vec<Vec3>, carry: SpineCarry) -> Result<Self> {
        Self::with_wave(base, control, None, carry)
    }

    /// [`SpineEdited::new`] with a lateral wave added to the new spine (§8.1.3.2).
    pub fn with_wave(
        base: Arc<PdePatch>,
        control: Vec<Vec3>,
        wave: Option<Wave>,
        carry: SpineCarry,
    ) -> Result<Self> {
        Self::sharing(base, control, wave, carry, Arc::default())
    }

    /// [`SpineEdited::with_wave`] for a further edit of the solved patch of `previous`, sharing
    /// what does not change (see [`SolvedSpine`]). The result is the same.
    pub fn after(
        previous: &SpineEdited,
        control: Vec<Vec3>,
        wave: Option<Wave>,
        carry: SpineCarry,
    ) -> Result<Self> {
        Self::sharing(
            previous.base.clone(),
            control,
            wave,
            carry,
            previous.solved.again(),
        )
    }

    fn sharing(
        base: Arc<PdePatch>,
        control: Vec<Vec3>,
        wave: Option<Wave>,
        carry: SpineCarry,
        solved: Arc<SolvedSpine>,
    ) -> Result<Self> {
        let n = base.conditions().len();
        if control.len() != n {
            return Err(Error::invalid(format!(
                "the spine needs {n} control points (got {})",
                control.len()
            ))
            .at("control"));
        }
        let spine = Bezier::new(control)?;
        let mut old_frames = None;
        let mut frames = Vec::new();
        if carry == SpineCarry::Frame {
            let old = solved.frames(&base)?;
            let tiny = MIN_SPEED * base.scale();
            frames.reserve(FRAME_STEPS + 1);
            let mut prev: Option<(Vec3, Matrix3<f64>)> = None;
            for k in 0..=FRAME_STEPS {
                let u = k as f64 / FRAME_STEPS as f64;
                let jn = new_jet(&spine, &wave, u);
                let tn = unit_tangent(&jn, tiny, u, "new")?;
                let f_n = match &prev {
                    None => {
                        let to = old.frames[0].column(0).into();
                        min_rotation(&to, &tn) * old.frames[0]
                    }
                    Some((pn, f_n)) => reflect(f_n, pn, &jn[0], &tn),
                };
                frames.push((f_n, jn[0]));
                prev = Some((jn[0], f_n));
            }
            old_frames = Some(old);
        }
        let mut edited = SpineEdited {
            base,
            spine,
            wave,
            carry,
            solved,
            old_frames,
            frames,
            series: None,
        };
        if let Some(old) = &edited.old_frames {
            let stepped = |u: f64| {
                let jo = old_jet(&edited.base, u);
                let jn = new_jet(&edited.spine, &edited.wave, u);
                edited.stepped_rotation(u, old, &jo, &jn)[0]
            };
            edited.series = RotationSeries::fit(&stepped);
        }
        Ok(edited)
    }

    /// Bounds over the whole patch of `|∂_u⁴X̃|`, `|∂_v⁴X̃|`, `|∂_u∂_v⁴X̃|` and `|X̃|` for
    /// `X̃ = Ã₀ + R D` (`D = X − A₀` the base's modes `n ≥ 1`, `R = I` when translating):
    /// `∂_u⁴X̃ = Ã₀⁗ + Σ_j C(4, j) R⁽ʲ⁾ ∂_u^{4−j}D`, `∂_v⁴X̃ = R ∂_v⁴D`,
    /// `∂_u∂_v⁴X̃ = R' ∂_v⁴D + R ∂_u∂_v⁴D`, with `|∂_u^d ∂_v^k D| ≤ Σ_{n≥1} nᵏ (αₙ² + βₙ²)^{1/2}`
    /// (the base's mode bounds), `‖R⁽ʲ⁾‖` from its Chebyshev series ([`RotationSeries`]) and
    /// `|Ã₀⁽ᵏ⁾|` from the Bézier curve's hodographs plus the wave's bound. `None` when the base
    /// has an active spectral remainder or the frames have no settled series (the CAD export
    /// then samples the patch).
    pub fn derivative_sums(&self) -> Option<[f64; 4]> {
        let modes: Vec<Vec<[f64; 2]>> = (0..=4)
            .map(|d| self.base.mode_derivative_bounds(d))
            .collect::<Option<_>>()?;
        let radial = |d: usize, k: usize| mode_sum(&modes[d], k, 1);
        let r: [f64; 5] = match (self.carry, &self.series) {
            (SpineCarry::Translate, _) => [1.0, 0.0, 0.0, 0.0, 0.0],
            (SpineCarry::Frame, Some(s)) => std::array::from_fn(|k| s.bound(k)),
            (SpineCarry::Frame, None) => return None,
        };
        let mut spine = [0.0; 5];
        if !self.spine.derivative_bounds(0.0, 1.0, &mut spine) {
            return None;
        }
        if let Some(w) = &self.wave {
            for (k, x) in spine.iter_mut().enumerate() {
                *x += w.bound(k);
            }
        }
        const BINOMIAL: [f64; 5] = [1.0, 4.0, 6.0, 4.0, 1.0];
        let mu4 = spine[4]
            + (0..5)
                .map(|j| BINOMIAL[j] * r[j] * radial(4 - j, 0))
                .sum::<f64>();
        let mv4 = r[0] * radial(0, 4);
        let mu1v4 = r[1] * radial(0, 4) + r[0] * radial(1, 4);
        let size = spine[0] + r[0] * radial(0, 0);
        let sums = [mu4, mv4, mu1v4, size];
        sums.iter().all(|x| x.is_finite()).then_some(sums)
    }

    /// The patch before the edit.
    pub fn base(&self) -> &Arc<PdePatch> {
        &self.base
    }

    /// How many rows of the solved patch this edit keeps (see [`SolvedSpine`]).
    #[cfg(test)]
    pub(crate) fn kept_rows(&self) -> usize {
        self.solved.rows.lock().map(|r| r.rows.len()).unwrap_or(0)
    }

    /// The new spine's control points.
    pub fn control(&self) -> &[Vec3] {
        &self.spine.control
    }

    /// The wave added to the new spine, if any.
    pub fn wave(&self) -> Option<&Wave> {
        self.wave.as_ref()
    }

    /// The new spine's point at `u` (the Bézier curve and the wave).
    pub fn point(&self, u: f64) -> Vec3 {
        match &self.wave {
            Some(w) => self.spine.point(u) + w.direction * w.displacement(u),
            None => self.spine.point(u),
        }
    }

    /// How the sections follow the spine.
    pub fn carry(&self) -> SpineCarry {
        self.carry
    }

    /// The unit tangent of the new spine at `u` (zero where it has none).
    pub fn tangent(&self, u: f64) -> Vec3 {
        angular(&new_jet(&self.spine, &self.wave, u)).0
    }

    /// `(R, R', R'')` at `u` (frame mode): the Chebyshev series' where it settled, else
    /// [`SpineEdited::stepped_rotation`].
    fn rotation(&self, u: f64, old: &SolvedFrames, jo: &Jet, jn: &Jet) -> [Matrix3<f64>; 3] {
        match &self.series {
            Some(s) => [s.eval(u, 0), s.eval(u, 1), s.eval(u, 2)],
            None => self.stepped_rotation(u, old, jo, jn),
        }
    }

    /// `(R, R', R'')` at `u` from the frames at the steps and one double-reflection step to
    /// `u` (`R'`, `R''` by the frame equation).
    fn stepped_rotation(
        &self,
        u: f64,
        old: &SolvedFrames,
        jo: &Jet,
        jn: &Jet,
    ) -> [Matrix3<f64>; 3] {
        let k = ((u * FRAME_STEPS as f64).floor().max(0.0) as usize).min(FRAME_STEPS - 1);
        let uk = k as f64 / FRAME_STEPS as f64;
        let (fo, ao) = (&old.frames[k], &old.jets[k][0]);
        let (f_n, an) = &self.frames[k];
        let (to, wo, wo1) = angular(jo);
        let (tn, wn, wn1) = angular(jn);
        let (fo, f_n) = if u == uk || to == Vec3::zeros() || tn == Vec3::zeros() {
            (*fo, *f_n)
        } else {
            (reflect(fo, ao, &jo[0], &to), reflect(f_n, an, &jn[0], &tn))
        };
        let r = f_n * fo.transpose();
        let (so, sn) = (skew(&wo), skew(&wn));
        let r1 = sn * r - r * so;
        let r2 = skew(&wn1) * r + sn * r1 - r1 * so - r * skew(&wo1);
        [r, r1, r2]
    }

    /// The edited partials from the base patch's partials `p` at `u`.
    fn edit(
        &self,
        u: f64,
        p: &Partials,
        jo: &Jet,
        jn: &Jet,
        rot: &Option<[Matrix3<f64>; 3]>,
    ) -> Partials {
        let (d, du, duu) = (p.x - jo[0], p.xu - jo[1], p.xuu - jo[2]);
        match rot {
            None => Partials {
                x: jn[0] + d,
                xu: jn[1] + du,
                xuu: jn[2] + duu,
                ..*p
            },
            Some([r, r1, r2]) => {
                let _ = u;
                Partials {
                    x: jn[0] + r * d,
                    xu: jn[1] + r1 * d + r * du,
                    xuu: jn[2] + r2 * d + r1 * du * 2.0 + r * duu,
                    xv: r * p.xv,
                    xuv: r1 * p.xv + r * p.xuv,
                    xvv: r * p.xvv,
                }
            }
        }
    }

    /// [`SpineEdited::edit`] of `X`, `X_u`, `X_v` and `X_uv` only (by the same expressions),
    /// what a position and its normal need; `X_uu` and `X_vv` are left as in `p`.
    #[inline(always)]
    fn edit_first(
        &self,
        p: &Partials,
        jo: &Jet,
        jn: &Jet,
        rot: &Option<[Matrix3<f64>; 3]>,
    ) -> Partials {
        let (d, du) = (p.x - jo[0], p.xu - jo[1]);
        match rot {
            None => Partials {
                x: jn[0] + d,
                xu: jn[1] + du,
                ..*p
            },
            Some([r, r1, _]) => Partials {
                x: jn[0] + r * d,
                xu: jn[1] + r1 * d + r * du,
                xv: r * p.xv,
                xuv: r1 * p.xv + r * p.xuv,
                ..*p
            },
        }
    }

    /// Everything that depends on `u` only.
    fn row_setup(&self, u: f64) -> (Jet, Jet, Option<[Matrix3<f64>; 3]>) {
        let (jo, jn) = (old_jet(&self.base, u), new_jet(&self.spine, &self.wave, u));
        let rot = self
            .old_frames
            .as_ref()
            .map(|old| self.rotation(u, old, &jo, &jn));
        (jo, jn, rot)
    }
}

impl Spine for SpineEdited {
    /// The new spine `Ã₀(u)`.
    fn spine(&self, u: f64, order: usize) -> Vec3 {
        let b = self.spine.derivative(u, order);
        match &self.wave {
            Some(w) => b + w.direction * w.derivative(u, order),
            None => b,
        }
    }
}

impl Surface for SpineEdited {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }

    fn as_spine(&self) -> Option<&dyn Spine> {
        Some(self)
    }

    fn partials(&self, u: f64, v: f64) -> Partials {
        let (jo, jn, rot) = self.row_setup(u);
        self.edit(u, &self.base.partials(u, v), &jo, &jn, &rot)
    }

    fn row_evaluator<'a>(&'a self, vs: &'a [f64]) -> Box<dyn RowEvaluator + 'a> {
        Box::new(EditedRows {
            surface: self,
            rows: self.base.partials_rows(vs),
            vs,
        })
    }

    fn partials_rows<'a>(&'a self, vs: &'a [f64]) -> Box<dyn PartialsRows + 'a> {
        Box::new(EditedRows {
            surface: self,
            rows: self.base.partials_rows(vs),
            vs,
        })
    }
}

/// Grid rows of an edited patch: the base patch's rows of partials, edited column by column.
struct EditedRows<'a> {
    surface: &'a SpineEdited,
    rows: Box<dyn PartialsRows + 'a>,
    vs: &'a [f64],
}

impl PartialsRows for EditedRows<'_> {
    fn eval_row(&self, u: f64, out: &mut [Partials]) {
        let (jo, jn, rot) = self.surface.row_setup(u);
        let solved = &self.surface.solved;
        match solved.kept_row(self.vs, u) {
            Some(kept) => {
                for (p, k) in out.iter_mut().zip(kept.iter()) {
                    *p = self.surface.edit(u, k, &jo, &jn, &rot);
                }
            }
            None => {
                self.rows.eval_row(u, out);
                solved.keep_row(self.vs, u, out);
                for p in out.iter_mut() {
                    *p = self.surface.edit(u, p, &jo, &jn, &rot);
                }
            }
        }
    }
}

impl RowEvaluator for EditedRows<'_> {
    /// Positions and normals only: the edit of `X`, `X_u`, `X_v` and `X_uv` (what the normal
    /// needs, by the same expressions as [`SpineEdited::edit`], so the same bits) fused with
    /// the normal, straight from the kept row when there is one.
    fn eval_row(&self, u: f64, row: &mut RowBuf) {
        thread_local! {
            static PARTS: std::cell::RefCell<Vec<Partials>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let surface = self.surface;
        let (jo, jn, rot) = surface.row_setup(u);
        let mut write = |base: &[Partials]| {
            for (j, p) in base.iter().enumerate() {
                let e = surface.edit_first(p, &jo, &jn, &rot);
                row.set(j, e.x, e.normal());
            }
        };
        let solved = &surface.solved;
        match solved.kept_row(self.vs, u) {
            Some(kept) => write(&kept),
            None => PARTS.with_borrow_mut(|parts| {
                parts.clear();
                parts.resize(self.vs.len(), Partials::default());
                self.rows.eval_row(u, parts);
                solved.keep_row(self.vs, u, parts);
                write(parts);
            }),
        }
    }
}

/// Replaces the PDE patches that a `[[spine]]` table edits by their edited surfaces. `cache`
/// holds the edits of the last compile with the identity of their base patch, and is replaced
/// by this compile's; an edit whose table and base patch did not change is reused.
pub(crate) fn apply_spines(
    specs: &[SpineSpec],
    surfaces: &mut [DesignSurface],
    single_patch: bool,
    cache: &mut Vec<(SpineSpec, usize, SurfaceKind)>,
) -> Result<()> {
    let mut next = Vec::with_capacity(specs.len());
    for (i, spec) in specs.iter().enumerate() {
        let place = format!("spine[{i}]");
        let index = match (&spec.patch, single_patch) {
            (None, true) => surfaces.first().filter(|s| s.is_patch()).map(|_| 0),
            (None, false) => {
                return Err(Error::invalid("the design has [[patches]]: name the patch").at(&place))
            }
            (Some(name), _) => surfaces
                .iter()
                .position(|s| s.is_patch() && &s.name == name),
        }
        .ok_or_else(|| {
            Error::invalid(format!(
                "the design has no PDE patch named '{}'",
                spec.patch.as_deref().unwrap_or_default()
            ))
            .at(&format!("{place}.patch"))
        })?;
        if specs[..i].iter().any(|s| s.patch == spec.patch) {
            return Err(Error::invalid("this patch's spine is edited twice").at(&place));
        }
        let surface = &mut surfaces[index];
        let base = match &surface.kind {
            SurfaceKind::Pde(p) => p.clone(),
            _ => {
                return Err(Error::invalid(
                    "spine edits need the analytic solver (solver = \"analytic\")",
                )
                .at(&place))
            }
        };
        let base_id = Arc::as_ptr(&base) as usize;
        let kind = match cache.iter().find(|(s, id, _)| s == spec && *id == base_id) {
            Some((_, _, kind)) => kind.clone(),
            None => {
                let control = spine_target(&base, spec).map_err(|e| e.at(&place))?;
                let wave = spec
                    .wave
                    .as_ref()
                    .map(Wave::new)
                    .transpose()
                    .map_err(|e| e.at(&place))?;
                // A further edit of the same solved patch (a drag) shares what it can.
                let previous = cache.iter().find_map(|(_, id, kind)| match kind {
                    SurfaceKind::SpineEdited(e) if *id == base_id => Some(e.clone()),
                    _ => None,
                });
                let edited = match previous {
                    Some(p) => SpineEdited::after(&p, control, wave, spec.carry),
                    None => SpineEdited::with_wave(base, control, wave, spec.carry),
                };
                SurfaceKind::SpineEdited(Arc::new(edited.map_err(|e| e.at(&place))?))
            }
        };
        surface.kind = kind.clone();
        next.push((spec.clone(), base_id, kind));
    }
    *cache = next;
    Ok(())
}

/// A patch's spine as `pdeshape check` reports it.
#[derive(Clone, Debug)]
pub struct SpineReport {
    /// The Bézier control points of the solved spine `A₀`.
    pub solved: Vec<Vec3>,
    /// The edited spine's control points and how the sections follow it, if it was edited.
    pub edited: Option<(SpineCarry, Vec<Vec3>)>,
}

impl DesignSurface {
    /// The spine of an analytic PDE patch in Bézier form, solved and (if edited) as edited.
    pub fn spine_report(&self) -> Option<SpineReport> {
        match &self.kind {
            SurfaceKind::Pde(p) => Some(SpineReport {
                solved: spine_control_points(p),
                edited: None,
            }),
            SurfaceKind::SpineEdited(e) => Some(SpineReport {
                solved: spine_control_points(e.base()),
                edited: Some((e.carry(), e.control().to_vec())),
            }),
            _ => None,
        }
    }
}

impl DesignSurface {
    /// The section `X̃(u, ·)` of a spine-edited patch at `n` equally spaced `v` (`None` for any
    /// other surface): where the edit carried the position curve of a condition at `u`, which
    /// the patch no longer meets (a picture draws this instead of the curve).
    pub(crate) fn edited_section(&self, u: f64, n: usize) -> Option<Vec<Vec3>> {
        let SurfaceKind::SpineEdited(e) = &self.kind else {
            return None;
        };
        Some(
            (0..n)
                .map(|k| Surface::point(&**e, u, crate::TAU * k as f64 / n as f64))
                .collect(),
        )
    }
}

/// [`super::Edit::SetSpine`]: sets, adds or removes the `[[spine]]` table of `patch`; returns
/// the undo edit. A table given with another `patch` than the edit's is refused.
pub(crate) fn set_spine(
    spec: &mut crate::spec::DesignSpec,
    patch: &super::PatchRef,
    spine: &Option<SpineSpec>,
) -> Result<super::Edit> {
    use super::Edit;
    if let Some(s) = spine {
        if &s.patch != patch {
            return Err(Error::invalid(format!(
                "the spine table names the patch {:?}, the edit {:?}",
                s.patch, patch
            ))
            .at("patch"));
        }
    }
    let at = spec.spine.iter().position(|s| &s.patch == patch);
    match (at, spine) {
        (Some(i), Some(s)) => Ok(Edit::SetSpine {
            patch: patch.clone(),
            spine: Some(std::mem::replace(&mut spec.spine[i], s.clone())),
        }),
        (Some(i), None) => {
            let old = spec.spine.clone();
            spec.spine.remove(i);
            Ok(Edit::SetSpines { spines: old })
        }
        (None, Some(s)) => {
            spec.spine.push(s.clone());
            Ok(Edit::SetSpine {
                patch: patch.clone(),
                spine: None,
            })
        }
        (None, None) => Ok(Edit::SetSpine {
            patch: patch.clone(),
            spine: None,
        }),
    }
}

#[cfg(test)]
mod series_tests {
    use super::*;
    use crate::design::solve_design;
    use crate::spec::parse_design;

    /// The rotation's Chebyshev series stays within `10⁻¹¹` of the stepped frames it was fitted
    /// to and orthogonal to that order, on the bent tube (its largest turn) and a fish.
    #[test]
    fn the_series_follows_the_stepped_frames() {
        let fish = include_str!("../../../../examples/anim/fish.toml");
        for spec in [
            parse_design(include_str!("../../../../examples/spine_bend.toml")).unwrap(),
            crate::spec::time::parse_timed(fish)
                .unwrap()
                .at(0.3)
                .unwrap(),
        ] {
            let design = solve_design(&spec).unwrap();
            let SurfaceKind::SpineEdited(s) = &design.surfaces[0].kind else {
                panic!("not a spine edit");
            };
            let (series, old) = (s.series.as_ref().unwrap(), s.old_frames.as_ref().unwrap());
            let mut worst = [0.0f64; 2];
            for i in 0..=997 {
                let u = i as f64 / 997.0;
                let (jo, jn) = (old_jet(&s.base, u), new_jet(&s.spine, &s.wave, u));
                let stepped = s.stepped_rotation(u, old, &jo, &jn)[0];
                let r = series.eval(u, 0);
                worst[0] = worst[0].max((r - stepped).norm());
                worst[1] = worst[1].max((r.transpose() * r - Matrix3::identity()).norm());
            }
            eprintln!("series of {} coefficients, {worst:?}", series.len());
            assert!(worst[0] < 1e-11 && worst[1] < 1e-11, "{worst:?}");
        }
    }
}
