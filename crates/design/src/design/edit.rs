//! Edits of a design, as values: what a designer does to a design after the first solve (move a
//! control point, transform a curve, change `a`, the order or the modes, add or remove curves,
//! conditions and patches). An edit applies to a [`DesignSpec`] and returns the edit that undoes
//! it; [`super::CompiledDesign::apply`] re-solves only what it touched. Edits serialise (JSON or
//! TOML) so a server, an undo stack and the optimiser can share them.

use crate::spec::{
    ConditionSpec, CurveKind, CurveSpec, DesignSpec, OperatorSpec, PatchSpec, SolverSpec,
    TransformStep, TrimCurveSpec, TrimSpec, V3,
};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};

/// A patch of a design: `None` for the single patch of a design with top-level `conditions`,
/// else the name of one of its `[[patches]]`.
pub type PatchRef = Option<String>;

/// One edit of a design.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "edit", rename_all = "snake_case", deny_unknown_fields)]
pub enum Edit {
    /// Sets the named curve to `curve` (adding it if there is none), or removes it (`None`).
    SetCurve {
        /// The curve's name in `[curves]`.
        name: String,
        /// The new table; `None` removes the curve.
        curve: Option<CurveSpec>,
    },
    /// Moves control point `index` of a B-spline, Bézier or closed-samples curve to `point`.
    MoveControlPoint {
        /// The curve's name in `[curves]`.
        name: String,
        /// 0-based index into the curve's `control` (B-spline, Bézier) or `points` (samples).
        index: usize,
        /// The point's new position `[x, y, z]`, in the curve's own coordinates (before its
        /// `transform`).
        point: V3,
    },
    /// Appends an affine step to a curve's transform (§6.1).
    Transform {
        /// The curve's name in `[curves]`.
        name: String,
        /// The step appended after the curve's existing ones.
        step: TransformStep,
    },
    /// Sets the operator of a patch (`patch`) or of the design (`patch` left out; `operator`
    /// left out removes an override or the design's operator).
    SetOperator {
        /// The patch whose `operator` is set; `None` (the default) sets the design's.
        #[serde(default)]
        patch: PatchRef,
        /// The new operator; `None` removes it (a patch then uses the design's, the design the
        /// default polyharmonic operator of order 2, `a = 1`).
        operator: Option<OperatorSpec>,
    },
    /// Sets the smoothing parameter `a` of a polyharmonic operator (the patch's own if it has
    /// one, else the design's).
    SetSmoothing {
        /// The patch (`None`, the default: the design's operator).
        #[serde(default)]
        patch: PatchRef,
        /// The new smoothing parameter `a` (`> 0`; checked when the design is compiled). A
        /// missing operator becomes the default polyharmonic one first; any other kind of
        /// operator is an error.
        a: f64,
    },
    /// Sets the half order `N` of a polyharmonic operator (the patch's own if it has one, else
    /// the design's).
    SetOrder {
        /// The patch (`None`, the default: the design's operator).
        #[serde(default)]
        patch: PatchRef,
        /// The new `N` (the PDE has order `2N`, so each affected patch needs `2N` conditions;
        /// checked when the design is compiled). Only a polyharmonic operator has one.
        order: usize,
    },
    /// Sets the number of Fourier modes of the analytic solver.
    SetModes {
        /// The new number of modes (`[solver] modes`; 1 to 256, checked when the design is
        /// compiled). Its undo is a [`Edit::SetSolver`].
        modes: usize,
    },
    /// Replaces the solver options.
    SetSolver {
        /// The whole new `[solver]` table.
        solver: SolverSpec,
    },
    /// Replaces condition `index` of a patch.
    SetCondition {
        /// The patch (`None`, the default: the top-level `conditions`).
        #[serde(default)]
        patch: PatchRef,
        /// 0-based index of an existing condition.
        index: usize,
        /// The replacement.
        condition: ConditionSpec,
    },
    /// Inserts a condition at `index` of a patch's conditions.
    InsertCondition {
        /// The patch (`None`, the default: the top-level `conditions`).
        #[serde(default)]
        patch: PatchRef,
        /// 0-based place of the new condition, at most the number of conditions (that
        /// number appends).
        index: usize,
        /// The condition inserted.
        condition: ConditionSpec,
    },
    /// Removes condition `index` of a patch.
    RemoveCondition {
        /// The patch (`None`, the default: the top-level `conditions`).
        #[serde(default)]
        patch: PatchRef,
        /// 0-based index of an existing condition.
        index: usize,
    },
    /// Inserts a patch at `index` of `[[patches]]`.
    InsertPatch {
        /// 0-based place in `[[patches]]`, at most their number (that number appends); the
        /// design must have `[[patches]]` already.
        index: usize,
        /// The patch inserted.
        patch: PatchSpec,
    },
    /// Removes the named patch.
    RemovePatch {
        /// The patch's `name`.
        name: String,
    },
    /// Sets the `[[spine]]` edit of a patch (§5.3): replaces its table, adds one, or removes
    /// it (`None`).
    SetSpine {
        /// The patch (`None`, the default: the single patch of a design with top-level
        /// `conditions`).
        #[serde(default)]
        patch: PatchRef,
        /// The new `[[spine]]` table of the patch (its own `patch` must name the same patch);
        /// `None` removes it.
        spine: Option<crate::spec::SpineSpec>,
    },
    /// Replaces every `[[spine]]` table (the undo of a removed one keeps the order).
    SetSpines {
        /// The new `[[spine]]` list, in order.
        spines: Vec<crate::spec::SpineSpec>,
    },
    /// A local edit of the named curve between `from` and `to` (§6.2): the curve becomes a
    /// `local` curve around its old table, so everything that refers to it follows.
    LocalEdit {
        /// The curve's name in `[curves]`.
        name: String,
        /// Start of the edited interval of `v`.
        from: f64,
        /// End of the edited interval of `v` (below `from`: across `v = 0` on a periodic
        /// curve).
        to: f64,
        /// The handle's parameter (`None`, the default: the middle of the interval).
        #[serde(default)]
        at: Option<f64>,
        /// Move of the handle from `C(from)` towards `C(to)` (default 0), in length units.
        #[serde(default)]
        along: f64,
        /// Move of the handle in the plane of `C(from)`, `C(to)` and the handle, towards the
        /// handle (default 0).
        #[serde(default)]
        across: f64,
        /// Move of the handle perpendicular to that plane (default 0).
        #[serde(default)]
        normal: f64,
    },
    /// Replaces `[[trims]]` entry `index`.
    SetTrim {
        /// 0-based index of an existing `[[trims]]` entry.
        index: usize,
        /// The replacement entry.
        trim: TrimSpec,
    },
    /// Inserts a `[[trims]]` entry at `index`.
    InsertTrim {
        /// 0-based place in `[[trims]]`, at most their number (that number appends).
        index: usize,
        /// The entry inserted.
        trim: TrimSpec,
    },
    /// Removes `[[trims]]` entry `index`.
    RemoveTrim {
        /// 0-based index of an existing `[[trims]]` entry.
        index: usize,
    },
    /// Moves trim curve `curve` of `[[trims]]` entry `index` by `offset = [Δu, Δv]` in the
    /// surface's parameter plane (the hole slides over the surface, §5.2.1).
    MoveTrimCurve {
        /// 0-based index of the `[[trims]]` entry.
        index: usize,
        /// 0-based index of the curve in the entry's `curves`.
        curve: usize,
        /// `[Δu, Δv]`, added to a circle's or ellipse's `center`, or to every point of a
        /// polyline or B-spline.
        offset: [f64; 2],
    },
    /// Moves the `(u, v)` curve of the `on_patch` curve `name` by `offset = [Δu, Δv]` in its
    /// patch's parameter plane: the attached patch's end slides over the host, and the host's
    /// hole with it (§5.2.1, Fig. 5.11).
    MoveAttachment {
        /// The name of an `on_patch` curve in `[curves]`.
        name: String,
        /// `[Δu, Δv]`, added to the `path`'s centre (circle, ellipse) or to every one of its
        /// points (polyline, B-spline).
        offset: [f64; 2],
    },
    /// Sets the value of the `[[parameters]]` entry `name` (§6.1, §6.4, §7.5; `None`: its
    /// neutral value, the design as written), checked against its bounds: only the curves
    /// and patches the parameter drives are re-solved.
    SetParameter {
        /// The parameter's `name`.
        name: String,
        /// The new value, within `[min, max]` (angles in radians); `None` (the default): the
        /// neutral value. The undo carries the previous `value` as written.
        #[serde(default)]
        value: Option<f64>,
    },
}

fn no_trim(index: usize, len: usize) -> Error {
    Error::invalid(format!("the design has {len} [[trims]] entries")).at(&format!("trims[{index}]"))
}

fn no_patch(name: &str) -> Error {
    Error::invalid(format!("the design has no patch named '{name}'")).at("patch")
}

/// The conditions of a patch.
fn conditions<'a>(
    spec: &'a mut DesignSpec,
    patch: &PatchRef,
) -> Result<&'a mut Vec<ConditionSpec>> {
    match patch {
        None => spec.conditions.as_mut().ok_or_else(|| {
            Error::invalid("the design has no top-level conditions: name a patch").at("patch")
        }),
        Some(name) => spec
            .patches
            .iter_mut()
            .flatten()
            .find(|p| &p.name == name)
            .map(|p| &mut p.conditions)
            .ok_or_else(|| no_patch(name)),
    }
}

/// The operator slot an edit of `patch` changes: the patch's own if it has one, else the
/// design's.
fn operator_slot<'a>(
    spec: &'a mut DesignSpec,
    patch: &PatchRef,
) -> Result<&'a mut Option<OperatorSpec>> {
    match patch {
        None => Ok(&mut spec.operator),
        Some(name) => {
            let p = spec
                .patches
                .iter_mut()
                .flatten()
                .find(|p| &p.name == name)
                .ok_or_else(|| no_patch(name))?;
            if p.operator.is_some() {
                Ok(&mut p.operator)
            } else {
                Ok(&mut spec.operator)
            }
        }
    }
}

/// Which slot [`operator_slot`] picks, as a patch reference for the undo edit.
fn slot_ref(spec: &DesignSpec, patch: &PatchRef) -> PatchRef {
    patch.as_ref().and_then(|name| {
        spec.patches
            .iter()
            .flatten()
            .find(|p| &p.name == name && p.operator.is_some())
            .map(|p| p.name.clone())
    })
}

fn curve_mut<'a>(spec: &'a mut DesignSpec, name: &str) -> Result<&'a mut CurveSpec> {
    spec.curves
        .get_mut(name)
        .ok_or_else(|| Error::invalid(format!("the design has no curve named '{name}'")).at("name"))
}

fn index_error(index: usize, len: usize, what: &str) -> Error {
    Error::invalid(format!("{what} {index} does not exist (there are {len})")).at("index")
}

/// Changes the polyharmonic operator of a patch (its own if it has one, else the design's,
/// the default operator if there is none) with `change(order, a)`; returns the undo edit.
/// `key` names what changes, for the error on another kind of operator.
fn set_polyharmonic(
    spec: &mut DesignSpec,
    patch: &PatchRef,
    key: &str,
    change: impl FnOnce(&mut usize, &mut f64),
) -> Result<Edit> {
    let undo_ref = slot_ref(spec, patch);
    let slot = operator_slot(spec, patch)?;
    let old = slot.clone();
    match slot.get_or_insert_with(OperatorSpec::default) {
        OperatorSpec::Polyharmonic { order, a } => change(order, a),
        _ => {
            return Err(Error::invalid(format!(
                "only the polyharmonic operator has `{key}` to set"
            ))
            .at(key))
        }
    }
    Ok(Edit::SetOperator {
        patch: undo_ref,
        operator: old,
    })
}

impl Edit {
    /// Applies the edit to `spec` and returns the edit that undoes it. Nothing changes on an
    /// error (a missing curve, patch or index). The edited design is checked when it is
    /// compiled.
    pub fn apply(&self, spec: &mut DesignSpec) -> Result<Edit> {
        match self {
            Edit::SetCurve { name, curve } => {
                let old = match curve {
                    Some(c) => spec.curves.insert(name.clone(), c.clone()),
                    None => spec.curves.remove(name),
                };
                Ok(Edit::SetCurve {
                    name: name.clone(),
                    curve: old,
                })
            }
            Edit::MoveControlPoint { name, index, point } => {
                let c = curve_mut(spec, name)?;
                let points = match &mut c.kind {
                    CurveKind::BSpline { control, .. } | CurveKind::Bezier { control } => control,
                    CurveKind::Samples { points, .. } => points,
                    _ => {
                        return Err(Error::invalid(
                            "only B-spline, Bézier and samples curves have control points",
                        )
                        .at("name"))
                    }
                };
                let len = points.len();
                let slot = points
                    .get_mut(*index)
                    .ok_or_else(|| index_error(*index, len, "control point"))?;
                let old = std::mem::replace(slot, *point);
                Ok(Edit::MoveControlPoint {
                    name: name.clone(),
                    index: *index,
                    point: old,
                })
            }
            Edit::Transform { name, step } => {
                let c = curve_mut(spec, name)?;
                let old = c.clone();
                c.transform.push(step.clone());
                Ok(Edit::SetCurve {
                    name: name.clone(),
                    curve: Some(old),
                })
            }
            Edit::SetOperator { patch, operator } => {
                let slot = match patch {
                    None => &mut spec.operator,
                    Some(name) => {
                        &mut spec
                            .patches
                            .iter_mut()
                            .flatten()
                            .find(|p| &p.name == name)
                            .ok_or_else(|| no_patch(name))?
                            .operator
                    }
                };
                let old = std::mem::replace(slot, operator.clone());
                Ok(Edit::SetOperator {
                    patch: patch.clone(),
                    operator: old,
                })
            }
            Edit::SetSmoothing { patch, a } => {
                set_polyharmonic(spec, patch, "a", |_, value| *value = *a)
            }
            Edit::SetOrder { patch, order } => {
                set_polyharmonic(spec, patch, "order", |value, _| *value = *order)
            }
            Edit::SetModes { modes } => {
                let old = spec.solver.clone();
                spec.solver.modes = *modes;
                Ok(Edit::SetSolver { solver: old })
            }
            Edit::SetSolver { solver } => Ok(Edit::SetSolver {
                solver: std::mem::replace(&mut spec.solver, solver.clone()),
            }),
            Edit::SetCondition {
                patch,
                index,
                condition,
            } => {
                let conds = conditions(spec, patch)?;
                let len = conds.len();
                let slot = conds
                    .get_mut(*index)
                    .ok_or_else(|| index_error(*index, len, "condition"))?;
                let old = std::mem::replace(slot, condition.clone());
                Ok(Edit::SetCondition {
                    patch: patch.clone(),
                    index: *index,
                    condition: old,
                })
            }
            Edit::InsertCondition {
                patch,
                index,
                condition,
            } => {
                let conds = conditions(spec, patch)?;
                if *index > conds.len() {
                    return Err(index_error(*index, conds.len(), "condition"));
                }
                conds.insert(*index, condition.clone());
                Ok(Edit::RemoveCondition {
                    patch: patch.clone(),
                    index: *index,
                })
            }
            Edit::RemoveCondition { patch, index } => {
                let conds = conditions(spec, patch)?;
                if *index >= conds.len() {
                    return Err(index_error(*index, conds.len(), "condition"));
                }
                let old = conds.remove(*index);
                Ok(Edit::InsertCondition {
                    patch: patch.clone(),
                    index: *index,
                    condition: old,
                })
            }
            Edit::InsertPatch { index, patch } => {
                let patches = spec.patches.as_mut().ok_or_else(|| {
                    Error::invalid("the design has no [[patches]] to insert into").at("index")
                })?;
                if *index > patches.len() {
                    return Err(index_error(*index, patches.len(), "patch"));
                }
                patches.insert(*index, patch.clone());
                Ok(Edit::RemovePatch {
                    name: patch.name.clone(),
                })
            }
            Edit::RemovePatch { name } => {
                let patches = spec.patches.as_mut().ok_or_else(|| no_patch(name))?;
                let index = patches
                    .iter()
                    .position(|p| &p.name == name)
                    .ok_or_else(|| no_patch(name))?;
                let old = patches.remove(index);
                Ok(Edit::InsertPatch { index, patch: old })
            }
            Edit::SetSpine { patch, spine } => super::spine::set_spine(spec, patch, spine),
            Edit::LocalEdit {
                name,
                from,
                to,
                at,
                along,
                across,
                normal,
            } => {
                let c = curve_mut(spec, name)?;
                let old = c.clone();
                *c = CurveSpec {
                    kind: CurveKind::Local {
                        curve: crate::spec::CurveRef::Inline(Box::new(old.clone())),
                        from: *from,
                        to: *to,
                        at: *at,
                        along: *along,
                        across: *across,
                        normal: *normal,
                    },
                    transform: Vec::new(),
                    v_origin: 0.0,
                    arc_length: false,
                };
                Ok(Edit::SetCurve {
                    name: name.clone(),
                    curve: Some(old),
                })
            }
            Edit::SetSpines { spines } => Ok(Edit::SetSpines {
                spines: std::mem::replace(&mut spec.spine, spines.clone()),
            }),
            Edit::SetTrim { index, trim } => {
                let len = spec.trims.len();
                let slot = spec
                    .trims
                    .get_mut(*index)
                    .ok_or_else(|| no_trim(*index, len))?;
                let old = std::mem::replace(slot, trim.clone());
                Ok(Edit::SetTrim {
                    index: *index,
                    trim: old,
                })
            }
            Edit::InsertTrim { index, trim } => {
                if *index > spec.trims.len() {
                    return Err(no_trim(*index, spec.trims.len()));
                }
                spec.trims.insert(*index, trim.clone());
                Ok(Edit::RemoveTrim { index: *index })
            }
            Edit::RemoveTrim { index } => {
                if *index >= spec.trims.len() {
                    return Err(no_trim(*index, spec.trims.len()));
                }
                let old = spec.trims.remove(*index);
                Ok(Edit::InsertTrim {
                    index: *index,
                    trim: old,
                })
            }
            Edit::MoveTrimCurve {
                index,
                curve,
                offset,
            } => {
                let len = spec.trims.len();
                let t = spec
                    .trims
                    .get_mut(*index)
                    .ok_or_else(|| no_trim(*index, len))?;
                let old = t.clone();
                let n = t.curves.len();
                let c = t.curves.get_mut(*curve).ok_or_else(|| {
                    Error::invalid(format!("the entry has {n} curves"))
                        .at(&format!("trims[{index}].curves[{curve}]"))
                })?;
                let shift = |p: &mut [f64; 2]| {
                    p[0] += offset[0];
                    p[1] += offset[1];
                };
                match c {
                    TrimCurveSpec::Circle { center, .. }
                    | TrimCurveSpec::Ellipse { center, .. } => shift(center),
                    TrimCurveSpec::Polyline { points } | TrimCurveSpec::Bspline { points, .. } => {
                        points.iter_mut().for_each(shift)
                    }
                }
                Ok(Edit::SetTrim {
                    index: *index,
                    trim: old,
                })
            }
            Edit::MoveAttachment { name, offset } => {
                let c = spec.curves.get_mut(name).ok_or_else(|| {
                    Error::invalid(format!("the design has no curve named '{name}'")).at("name")
                })?;
                let old = c.clone();
                let CurveKind::OnPatch { path, .. } = &mut c.kind else {
                    return Err(Error::invalid(format!(
                        "'{name}' is not an on_patch curve (a curve on a patch)"
                    ))
                    .at("name"));
                };
                let shift = |p: &mut [f64; 2]| {
                    p[0] += offset[0];
                    p[1] += offset[1];
                };
                match path {
                    TrimCurveSpec::Circle { center, .. }
                    | TrimCurveSpec::Ellipse { center, .. } => shift(center),
                    TrimCurveSpec::Polyline { points } | TrimCurveSpec::Bspline { points, .. } => {
                        points.iter_mut().for_each(shift)
                    }
                }
                Ok(Edit::SetCurve {
                    name: name.clone(),
                    curve: Some(old),
                })
            }
            Edit::SetParameter { name, value } => {
                let old = super::params::set_parameter(spec, name, *value)?;
                Ok(Edit::SetParameter {
                    name: name.clone(),
                    value: old,
                })
            }
        }
    }
}
