//! The designer's gestures as library edits: a dragged spine handle becomes a `[[spine]]` table
//! (`Edit::SetSpine`, §5.3) with the patch's current Bézier control points and the one moved;
//! a dragged local-edit handle becomes `Edit::LocalEdit` (§6.2) — the drag's later positions
//! re-state the same local curve around the curve as it was when the drag began, so a drag is
//! one local edit, not a local edit of a local edit.

use super::error::ApiError;
use pdeshape::curve::LocalFrame;
use pdeshape::design::{Edit, PatchRef, SolvedDesign};
use pdeshape::spec::{CurveSpec, DesignSpec, SpineCarry, SpineSpec, V3};
use pdeshape::Vec3;
use serde::Deserialize;

fn edit_error(e: &pdeshape::Error) -> ApiError {
    ApiError::unprocessable(crate::common::message_of(e), e.place())
}

/// The surface a patch reference names: a `[[patches]]` name, or the single patch of a design
/// with top-level conditions.
fn surface_index(
    spec: &DesignSpec,
    solved: &SolvedDesign,
    patch: &PatchRef,
) -> Result<usize, ApiError> {
    match patch {
        Some(name) => solved
            .surfaces
            .iter()
            .position(|s| &s.name == name && s.place.starts_with("patches["))
            .ok_or_else(|| {
                ApiError::unprocessable(format!("the design has no patch named '{name}'"), "patch")
            }),
        None if spec.conditions.is_some() => solved
            .surfaces
            .iter()
            .position(|s| s.place == "conditions")
            .ok_or_else(|| ApiError::unprocessable("the design's patch did not solve", "patch")),
        None => Err(ApiError::unprocessable(
            "the design has [[patches]]: name the patch",
            "patch",
        )),
    }
}

/// A request to move spine control point `index` of `patch` to `point`, and/or to set how the
/// sections follow the spine (`carry`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SpineRequest {
    #[serde(default)]
    pub patch: PatchRef,
    #[serde(default)]
    pub index: Option<usize>,
    #[serde(default)]
    pub point: Option<V3>,
    #[serde(default)]
    pub carry: Option<SpineCarry>,
    #[serde(default)]
    pub group: Option<u64>,
}

/// The `Edit::SetSpine` of a spine request: the patch's current spine control points (the
/// edited ones, else the solved spine's Bézier form), point `index` moved to `point`; a wave
/// and the carry of an existing `[[spine]]` table are kept unless `carry` is given.
pub(super) fn spine_edit(
    spec: &DesignSpec,
    solved: &SolvedDesign,
    r: &SpineRequest,
) -> Result<Edit, ApiError> {
    let k = surface_index(spec, solved, &r.patch)?;
    let report = solved.surfaces[k].spine_report().ok_or_else(|| {
        ApiError::unprocessable(
            format!(
                "'{}' is a {}: only analytic PDE patches have a spine to edit (§5.3)",
                solved.surfaces[k].name,
                solved.surfaces[k].kind.word()
            ),
            "patch",
        )
    })?;
    let mut control: Vec<Vec3> = match report.edited {
        Some((_, c)) => c,
        None => report.solved,
    };
    match (r.index, r.point) {
        (Some(i), Some(p)) => {
            let n = control.len();
            let slot = control.get_mut(i).ok_or_else(|| {
                ApiError::unprocessable(
                    format!("spine control point {i} does not exist (the spine has {n})"),
                    "index",
                )
            })?;
            if p.iter().any(|x| !x.is_finite()) {
                return Err(ApiError::bad_request("must be finite", "point"));
            }
            *slot = Vec3::new(p[0], p[1], p[2]);
        }
        (None, None) if r.carry.is_some() => {}
        (None, None) => {
            return Err(ApiError::bad_request(
                "give index and point (a moved control point) or carry",
                "index",
            ))
        }
        (None, Some(_)) => {
            return Err(ApiError::bad_request(
                "give the index of the point",
                "index",
            ))
        }
        (Some(_), None) => {
            return Err(ApiError::bad_request("give the point's new place", "point"))
        }
    }
    let old = spec.spine.iter().find(|s| s.patch == r.patch);
    let spine = SpineSpec {
        patch: r.patch.clone(),
        carry: r
            .carry
            .or(old.map(|s| s.carry))
            .unwrap_or(SpineCarry::Frame),
        control: Some(control.iter().map(|p| [p.x, p.y, p.z]).collect()),
        moves: Vec::new(),
        hermite: None,
        wave: old.and_then(|s| s.wave.clone()),
    };
    Ok(Edit::SetSpine {
        patch: r.patch.clone(),
        spine: Some(spine),
    })
}

/// The frame of a local edit of the curve `name` as the design stands.
pub(super) fn local_frame(
    solved: &SolvedDesign,
    name: &str,
    from: f64,
    to: f64,
    at: Option<f64>,
) -> Result<LocalFrame, ApiError> {
    let c = solved
        .curves
        .iter()
        .find(|c| c.name == name)
        .ok_or_else(|| {
            ApiError::unprocessable(format!("the design has no curve named '{name}'"), "name")
        })?;
    LocalFrame::new(&*c.curve, from, to, at).map_err(|e| edit_error(&e))
}

/// A local edit of the curve `name` between `from` and `to`, the handle at `at` moved by
/// `[along, across, normal]` in the frame of [`local_frame`].
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub(super) struct LocalRequest {
    pub name: String,
    pub from: f64,
    pub to: f64,
    #[serde(default)]
    pub at: Option<f64>,
    #[serde(default)]
    pub along: f64,
    #[serde(default)]
    pub across: f64,
    #[serde(default)]
    pub normal: f64,
    #[serde(default)]
    pub group: Option<u64>,
}

impl LocalRequest {
    fn edit(&self) -> Edit {
        Edit::LocalEdit {
            name: self.name.clone(),
            from: self.from,
            to: self.to,
            at: self.at,
            along: self.along,
            across: self.across,
            normal: self.normal,
        }
    }
}

/// The local drag under way: its group, the curve and the curve's table when it began.
pub(super) struct LocalDrag {
    group: u64,
    name: String,
    base: CurveSpec,
}

/// The edit of a local-edit request: `Edit::LocalEdit` when a drag begins (or without a
/// group); later positions of the same drag set the curve to the local edit of the table the
/// drag began from (the library's `Edit::LocalEdit` applied to that table). Returns the edit and
/// the drag state to keep once it applied.
pub(super) fn local_edit(
    spec: &DesignSpec,
    under_way: Option<&LocalDrag>,
    r: &LocalRequest,
) -> Result<(Edit, Option<LocalDrag>), ApiError> {
    let current = spec.curves.get(&r.name).ok_or_else(|| {
        ApiError::unprocessable(
            format!("the design has no curve named '{}'", r.name),
            "name",
        )
    })?;
    let Some(group) = r.group else {
        return Ok((r.edit(), None));
    };
    let base = match under_way {
        Some(d) if d.group == group && d.name == r.name => d.base.clone(),
        _ => {
            let drag = LocalDrag {
                group,
                name: r.name.clone(),
                base: current.clone(),
            };
            return Ok((r.edit(), Some(drag)));
        }
    };
    let mut scratch = DesignSpec {
        curves: [(r.name.clone(), base.clone())].into_iter().collect(),
        ..DesignSpec::default()
    };
    r.edit().apply(&mut scratch).map_err(|e| edit_error(&e))?;
    let curve = scratch.curves.remove(&r.name);
    let drag = LocalDrag {
        group,
        name: r.name.clone(),
        base,
    };
    Ok((
        Edit::SetCurve {
            name: r.name.clone(),
            curve,
        },
        Some(drag),
    ))
}

/// The JSON of a local frame for the page.
pub(super) fn frame_json(f: &LocalFrame) -> serde_json::Value {
    let p = |v: &Vec3| [v.x, v.y, v.z];
    serde_json::json!({
        "from": f.from(), "to": f.to(), "at": f.at(),
        "x1": p(&f.x1), "x2": p(&f.x2), "x3": p(&f.x3), "e1": p(&f.e1),
        "e2": f.plane.map(|(e2, _)| p(&e2)),
        "e3": f.plane.map(|(_, e3)| p(&e3)),
    })
}
