//! `SpineEdited`: the patch with its spine replaced, as a `Surface` (points, exact partials, row
//! evaluators) and a `Spine`.

use super::frames::{
    angular, min_rotation, new_jet, old_jet, reflect, skew, unit_tangent, Jet, SolvedFrames,
    SolvedSpine, FRAME_STEPS, MIN_SPEED,
};
use super::series::RotationSeries;
use super::wave::Wave;
use crate::curve::{Bezier, Curve};
use crate::elliptic::PdePatch;
use crate::spec::SpineCarry;
use crate::surface::{Partials, PartialsRows, RowBuf, RowEvaluator, Spine, Surface, VDomain};
use crate::{Error, Result, Vec3};
use nalgebra::Matrix3;
use std::sync::Arc;

/// A PDE patch whose spine was replaced: `X̃ = Ã₀ + D` or `Ã₀ + R D` (see the module's text).
#[derive(Debug)]
pub struct SpineEdited {
    pub(super) base: Arc<PdePatch>,
    pub(super) spine: Bezier,
    /// A lateral wave added to the Bézier spine.
    pub(super) wave: Option<Wave>,
    pub(super) carry: SpineCarry,
    /// What this edit shares with the other edits of the same solved patch.
    solved: Arc<SolvedSpine>,
    /// The solved spine's frames (frame mode only).
    pub(super) old_frames: Option<Arc<SolvedFrames>>,
    /// `(F̃(u_k), Ã₀(u_k))` at `u_k = k / FRAME_STEPS` (frame mode only).
    frames: Vec<(Matrix3<f64>, Vec3)>,
    /// The rotation `R = F̃ Fᵀ` as one Chebyshev series (frame mode, when it settles): the
    /// surface's rotation, see [`RotationSeries`].
    pub(super) series: Option<RotationSeries>,
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
    pub(super) fn stepped_rotation(
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
