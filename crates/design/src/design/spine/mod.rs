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
use crate::spec::{SpineCarry, SpineSpec};
use crate::surface::Surface;
use crate::{Error, Result, Vec3};
use std::sync::Arc;

mod bounds;
mod control;
mod frames;
mod series;
mod surface;
mod wave;
pub use control::{spine_control_points, spine_hermite_of, spine_target};
pub use surface::SpineEdited;
pub use wave::Wave;

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
            let name = |p: &Option<String>| {
                p.as_deref()
                    .map_or("(none)".to_string(), crate::spec::words::user_text)
            };
            return Err(Error::invalid(format!(
                "the spine table names the patch '{}', the edit '{}'",
                name(&s.patch),
                name(patch)
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
    use super::frames::{new_jet, old_jet};
    use super::*;
    use crate::design::solve_design;
    use crate::spec::parse_design;
    use nalgebra::Matrix3;

    /// The rotation's Chebyshev series stays within `10⁻¹¹` of the stepped frames it was fitted
    /// to and orthogonal to that order, on the bent tube (its largest turn) and a fish.
    #[test]
    fn the_series_follows_the_stepped_frames() {
        let fish = include_str!("../../../../../examples/anim/fish.toml");
        for spec in [
            parse_design(include_str!("../../../../../examples/spine_bend.toml")).unwrap(),
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
