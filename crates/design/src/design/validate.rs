//! Validation of a [`DesignSpec`] without building anything: numbers finite and in range, curve
//! references known and acyclic, operators, condition counts and orders, solver options, the
//! output grid; and the plan of a design's PDE patches.

use crate::elliptic::{Operator, SolveOptions};
#[cfg(doc)]
use crate::mesh::grid_parameters;
use crate::mesh::MAX_VERTICES;
use crate::spec::*;
use crate::{Error, Result, Vec3};
use std::collections::{BTreeMap, HashMap};

/// Default grid rows when neither the caller nor `[output]` gives `nu`.
pub const DEFAULT_NU: usize = 64;
/// Default grid columns when neither the caller nor `[output]` gives `nv`.
pub const DEFAULT_NV: usize = 128;
/// Most Fourier modes the design file may ask for.
const MAX_MODES: usize = 256;
/// Most FFT samples per curve the design file may ask for.
const MAX_SAMPLES: usize = 1 << 16;

pub(crate) fn curve_place(name: &str) -> String {
    format!("curves.{}", key_path(name))
}

pub(crate) use crate::check::num;
use crate::check::{finite, positive};

/// `crate::check::finite3` of a file's `[x, y, z]`.
fn finite3(v: &V3, place: &str) -> Result<()> {
    crate::check::finite3(&Vec3::from(*v), place)
}

/// `crate::check::nonzero_vector` of a file's `[x, y, z]`.
fn nonzero_vector(v: &V3, place: &str) -> Result<()> {
    crate::check::nonzero_vector(&Vec3::from(*v), place)
}

/// The kind name as written in the file.
pub(crate) fn kind_name(kind: &CurveKind) -> &'static str {
    match kind {
        CurveKind::Circle { .. } => "circle",
        CurveKind::Ellipse { .. } => "ellipse",
        CurveKind::Point { .. } => "point",
        CurveKind::BSpline { .. } => "bspline",
        CurveKind::Bezier { .. } => "bezier",
        CurveKind::Hermite { .. } => "hermite",
        CurveKind::Fourier { .. } => "fourier",
        CurveKind::Samples { .. } => "samples",
        CurveKind::Formula { .. } => "formula",
        CurveKind::Derivative { .. } => "derivative",
        CurveKind::Local { .. } => "local",
        CurveKind::OnPatch { .. } => "on_patch",
        CurveKind::TangentField { .. } => "tangent_field",
    }
}

/// Checks an operator's parameters and builds it. `place` is where it came from (`operator`).
pub(crate) fn build_operator(spec: &OperatorSpec, place: &str) -> Result<Operator> {
    check_operator_values(spec, place)?;
    match spec {
        OperatorSpec::Polyharmonic { order, a } => Operator::polyharmonic(*order, *a),
        OperatorSpec::SixthOrder { a, b, c, d } => Operator::sixth_order(*a, *b, *c, *d),
        OperatorSpec::General { coefficients } => Operator::general(coefficients.clone()),
    }
    .map_err(|e| e.at(place))
}

/// The half order `N` of an operator spec (checked later by [`build_operator`]).
pub(crate) fn half_order(spec: &OperatorSpec) -> usize {
    match spec {
        OperatorSpec::Polyharmonic { order, .. } => *order,
        OperatorSpec::SixthOrder { .. } => 3,
        OperatorSpec::General { coefficients } => coefficients.len().saturating_sub(1),
    }
}

pub(crate) fn check_solver(s: &SolverSpec) -> Result<SolveOptions> {
    if !(1..=MAX_MODES).contains(&s.modes) {
        return Err(Error::invalid(format!(
            "must be between 1 and {MAX_MODES} (got {})",
            s.modes
        ))
        .at("solver.modes"));
    }
    if s.samples != 0 && !(2 * s.modes + 1..=MAX_SAMPLES).contains(&s.samples) {
        return Err(Error::invalid(format!(
            "must be 0 (automatic) or between 2·modes + 1 = {} and {MAX_SAMPLES} (got {})",
            2 * s.modes + 1,
            s.samples
        ))
        .at("solver.samples"));
    }
    Ok(SolveOptions {
        modes: s.modes,
        remainder: s.remainder,
        samples: s.samples,
    })
}

/// Checks an `nu × nv` grid of a periodic surface against the limits of [`grid_parameters`]
/// (`nu ≥ 2`, `nv ≥ 3`, at most [`MAX_VERTICES`] vertices) with the same messages, without
/// allocating anything. The place of the error is `nu`, `nv` or `nu × nv`.
pub fn check_grid(nu: usize, nv: usize) -> Result<()> {
    if nu < 2 {
        return Err(Error::invalid(format!("must be at least 2 (got {nu})")).at("nu"));
    }
    if nv < 3 {
        return Err(Error::invalid(format!("must be at least 3 (got {nv})")).at("nv"));
    }
    if nu.checked_mul(nv).is_none_or(|n| n > MAX_VERTICES) {
        return Err(Error::invalid(format!(
            "a {nu} × {nv} grid has more than {MAX_VERTICES} vertices; refusing to allocate it"
        ))
        .at("nu × nv"));
    }
    Ok(())
}

/// The output grid `(nu, nv)` of the design's `[output]` table (defaults 64 × 128), checked
/// with [`check_grid`].
pub(crate) fn output_grid(o: &OutputSpec) -> Result<(usize, usize)> {
    let nu = o.nu.unwrap_or(DEFAULT_NU);
    let nv = o.nv.unwrap_or(DEFAULT_NV);
    check_grid(nu, nv).map_err(|e| match e.place() {
        "nu" | "nv" => e.at("output"),
        _ => e,
    })?;
    Ok((nu, nv))
}

/// Checks the numbers of one curve table (everything that does not need the curve built).
pub(crate) fn check_curve(c: &CurveSpec, place: &str) -> Result<()> {
    let at = |e: Error| e.at(place);
    // The values of each kind are checked by the curve's constructor when it is built (with
    // the place inside the curve's table); here only what needs the file's keys.
    match &c.kind {
        CurveKind::Ellipse {
            axis1,
            axis2,
            rx,
            ry,
            normal,
            ..
        } => match (axis1, axis2, rx, ry) {
            (Some(_), Some(_), None, None) if normal.is_some() => {
                return Err(at(Error::invalid(
                    "is only used with rx and ry (the axes already fix the plane)",
                )
                .at("normal")))
            }
            (Some(_), Some(_), None, None) | (None, None, Some(_), Some(_)) => {}
            _ => {
                return Err(at(Error::invalid(
                    "give either axis1 and axis2, or rx and ry (with an optional normal)",
                )))
            }
        },
        CurveKind::Derivative {
            position,
            direction,
            scale,
        } => {
            finite(*scale, "scale").map_err(at)?;
            if *scale == 0.0 {
                return Err(at(Error::invalid("must not be 0").at("scale")));
            }
            for (name, r) in [("position", position), ("direction", direction)] {
                if let CurveRef::Inline(inner) = r {
                    check_curve(inner, &format!("{place}.{name}"))?;
                }
            }
        }
        CurveKind::Local {
            curve: CurveRef::Inline(inner),
            ..
        } => {
            check_curve(inner, &format!("{place}.curve"))?;
        }
        _ => {}
    }
    for (i, step) in c.transform.iter().enumerate() {
        let p = format!("{place}.transform[{i}]");
        match step {
            TransformStep::Translate(d) => {
                finite3(d, &format!("{p}.translate"))?;
            }
            TransformStep::Rotate { axis, angle, about } => {
                nonzero_vector(axis, &format!("{p}.rotate.axis"))?;
                finite(*angle, &format!("{p}.rotate.angle"))?;
                finite3(about, &format!("{p}.rotate.about"))?;
            }
            TransformStep::Scale { factor, about } => {
                finite(*factor, &format!("{p}.scale.factor"))?;
                if *factor == 0.0 {
                    return Err(Error::invalid("must not be 0").at(&format!("{p}.scale.factor")));
                }
                finite3(about, &format!("{p}.scale.about"))?;
            }
            TransformStep::Dilate { factors, about } => {
                finite3(factors, &format!("{p}.dilate.factors"))?;
                if let Some(i) = factors.iter().position(|f| *f == 0.0) {
                    return Err(
                        Error::invalid("must not be 0").at(&format!("{p}.dilate.factors[{i}]"))
                    );
                }
                finite3(about, &format!("{p}.dilate.about"))?;
            }
        }
    }
    finite(c.v_origin, &format!("{place}.v_origin"))?;
    Ok(())
}

/// Names of the curves a curve refers to, with the place of each reference.
pub(crate) fn references<'a>(c: &'a CurveSpec, place: &str, out: &mut Vec<(&'a str, String)>) {
    if let CurveKind::TangentField { curve, .. } = &c.kind {
        out.push((curve.as_str(), format!("{place}.curve")));
    }
    if let CurveKind::Local { curve, .. } = &c.kind {
        match curve {
            CurveRef::Name(n) => out.push((n.as_str(), format!("{place}.curve"))),
            CurveRef::Inline(inner) => references(inner, &format!("{place}.curve"), out),
        }
    }
    if let CurveKind::Derivative {
        position,
        direction,
        ..
    } = &c.kind
    {
        for (name, r) in [("position", position), ("direction", direction)] {
            match r {
                CurveRef::Name(n) => out.push((n.as_str(), format!("{place}.{name}"))),
                CurveRef::Inline(inner) => references(inner, &format!("{place}.{name}"), out),
            }
        }
    }
}

/// The names [`references`] lists for `c`, in the same order, without their places (which are
/// formatted only when an error names one).
pub(crate) fn reference_names<'a>(c: &'a CurveSpec, out: &mut Vec<&'a str>) {
    if let CurveKind::TangentField { curve, .. } = &c.kind {
        out.push(curve.as_str());
    }
    if let CurveKind::Local { curve, .. } = &c.kind {
        match curve {
            CurveRef::Name(n) => out.push(n.as_str()),
            CurveRef::Inline(inner) => reference_names(inner, out),
        }
    }
    if let CurveKind::Derivative {
        position,
        direction,
        ..
    } = &c.kind
    {
        for r in [position, direction] {
            match r {
                CurveRef::Name(n) => out.push(n.as_str()),
                CurveRef::Inline(inner) => reference_names(inner, out),
            }
        }
    }
}

pub(crate) fn unknown_curve(
    name: &str,
    curves: &BTreeMap<String, CurveSpec>,
    place: &str,
) -> Error {
    use crate::spec::words::user_text;
    /// Names listed at most; more are counted.
    const LISTED: usize = 20;
    let mut known: Vec<String> = curves.keys().take(LISTED).map(|k| user_text(k)).collect();
    if curves.len() > LISTED {
        known.push(format!("and {} more", curves.len() - LISTED));
    }
    let known = if known.is_empty() {
        "no curves are defined".to_string()
    } else {
        format!("known: {}", known.join(", "))
    };
    let guess = match crate::spec::suggest::nearest(name, curves.keys().map(String::as_str)) {
        Some(n) => format!("did you mean '{}'? ", user_text(n)),
        None => String::new(),
    };
    Error::invalid(format!(
        "unknown curve '{}' ({guess}{known})",
        user_text(name)
    ))
    .at(place)
}

/// Every reference exists and the references between named curves have no cycle.
fn check_references(curves: &BTreeMap<String, CurveSpec>) -> Result<()> {
    for (name, c) in curves {
        let mut refs = Vec::new();
        references(c, &curve_place(name), &mut refs);
        for (r, place) in refs {
            if !curves.contains_key(r) {
                return Err(unknown_curve(r, curves, &place));
            }
        }
    }
    // Depth-first search with colours: 1 = on the stack, 2 = done.
    fn visit<'a>(
        name: &'a str,
        curves: &'a BTreeMap<String, CurveSpec>,
        colour: &mut HashMap<&'a str, u8>,
        stack: &mut Vec<&'a str>,
    ) -> Result<()> {
        match colour.get(name) {
            Some(2) => return Ok(()),
            Some(1) => {
                let start = stack.iter().position(|s| *s == name).unwrap_or(0);
                let mut cycle: Vec<&str> = stack[start..].to_vec();
                cycle.push(name);
                return Err(Error::invalid(format!(
                    "curves refer to each other in a cycle: {}",
                    cycle.join(" → ")
                ))
                .at(&curve_place(name)));
            }
            _ => {}
        }
        colour.insert(name, 1);
        stack.push(name);
        let mut refs = Vec::new();
        if let Some(c) = curves.get(name) {
            references(c, "", &mut refs);
        }
        for (r, _) in refs {
            if let Some((k, _)) = curves.get_key_value(r) {
                visit(k.as_str(), curves, colour, stack)?;
            }
        }
        stack.pop();
        colour.insert(name, 2);
        Ok(())
    }
    let mut colour = HashMap::new();
    for name in curves.keys() {
        visit(name, curves, &mut colour, &mut Vec::new())?;
    }
    Ok(())
}

/// Whether a curve spec describes a periodic curve (closed on [0, 2π)).
fn is_periodic(c: &CurveSpec, curves: &BTreeMap<String, CurveSpec>, depth: usize) -> bool {
    if depth > curves.len() + 8 {
        return false;
    }
    match &c.kind {
        CurveKind::Circle { .. }
        | CurveKind::Ellipse { .. }
        | CurveKind::Point { .. }
        | CurveKind::Fourier { .. }
        | CurveKind::Samples { .. }
        | CurveKind::OnPatch { .. }
        | CurveKind::TangentField { .. } => true,
        CurveKind::BSpline { periodic, .. } => *periodic,
        CurveKind::Bezier { .. } | CurveKind::Hermite { .. } => false,
        CurveKind::Formula { domain, .. } => *domain == DomainSpec::Periodic,
        CurveKind::Local { curve, .. } => match curve {
            CurveRef::Name(n) => curves
                .get(n)
                .is_some_and(|p| is_periodic(p, curves, depth + 1)),
            CurveRef::Inline(p) => is_periodic(p, curves, depth + 1),
        },
        CurveKind::Derivative { position, .. } => match position {
            CurveRef::Name(n) => curves
                .get(n)
                .is_some_and(|p| is_periodic(p, curves, depth + 1)),
            CurveRef::Inline(p) => is_periodic(p, curves, depth + 1),
        },
    }
}

fn derivative_words(d: usize) -> String {
    match d {
        0 => "the position".to_string(),
        1 => "the first u-derivative".to_string(),
        2 => "the second u-derivative".to_string(),
        3 => "the third u-derivative".to_string(),
        _ => format!("the u-derivative of order {d}"),
    }
}

/// Checks one patch's conditions: count, u, derivative orders, duplicates, curve references and
/// periodicity. `place` is `conditions` or `patches[i].conditions`.
fn check_conditions(
    conds: &[ConditionSpec],
    n: usize,
    curves: &BTreeMap<String, CurveSpec>,
    place: &str,
    op_words: &str,
) -> Result<()> {
    for (i, c) in conds.iter().enumerate() {
        let p = format!("{place}[{i}]");
        finite(c.u, &format!("{p}.u"))?;
        if !(0.0..=1.0).contains(&c.u) {
            return Err(
                Error::invalid(format!("must lie in [0, 1] (got {})", num(c.u)))
                    .at(&format!("{p}.u")),
            );
        }
        if c.derivative >= 2 * n {
            return Err(Error::invalid(format!(
                "must be below the PDE's order {} (got {})",
                2 * n,
                c.derivative
            ))
            .at(&format!("{p}.derivative")));
        }
        let (spec, periodic) = match &c.curve {
            CurveRef::Name(name) => {
                let Some(spec) = curves.get(name) else {
                    return Err(unknown_curve(name, curves, &format!("{p}.curve")));
                };
                (spec, is_periodic(spec, curves, 0))
            }
            CurveRef::Inline(spec) => {
                check_curve(spec, &format!("{p}.curve"))?;
                let mut refs = Vec::new();
                references(spec, &format!("{p}.curve"), &mut refs);
                for (r, rp) in refs {
                    if !curves.contains_key(r) {
                        return Err(unknown_curve(r, curves, &rp));
                    }
                }
                (&**spec, is_periodic(spec, curves, 0))
            }
        };
        if !periodic {
            return Err(Error::invalid(format!(
                "a condition curve must be periodic (closed, v in [0, 2π)); this {} curve is open",
                kind_name(&spec.kind)
            ))
            .at(&format!("{p}.curve")));
        }
        for (j, earlier) in conds[..i].iter().enumerate() {
            if earlier.u == c.u && earlier.derivative == c.derivative {
                return Err(Error::invalid(format!(
                    "prescribes {} at u = {} like {place}[{j}]",
                    derivative_words(c.derivative),
                    num(c.u)
                ))
                .at(&p));
            }
        }
    }
    if conds.len() != 2 * n {
        return Err(Error::invalid(format!(
            "{op_words} needs {} conditions, got {}",
            2 * n,
            conds.len()
        ))
        .at(place));
    }
    Ok(())
}

fn operator_words(spec: &OperatorSpec) -> String {
    match spec {
        OperatorSpec::Polyharmonic { order, .. } => {
            format!("a polyharmonic operator of order {order}")
        }
        OperatorSpec::SixthOrder { .. } => "a sixth-order operator".to_string(),
        OperatorSpec::General { coefficients } => format!(
            "a general operator of order {}",
            2 * coefficients.len().saturating_sub(1)
        ),
    }
}

/// One patch after validation, before solving.
pub(crate) struct PatchPlan<'a> {
    pub name: String,
    /// Where the conditions are: `conditions` or `patches[i].conditions`.
    pub place: String,
    pub operator: &'a OperatorSpec,
    pub operator_place: String,
    pub conditions: &'a [ConditionSpec],
}

/// The PDE patches of a design (none for a design of other parts only).
pub(crate) fn plan(spec: &DesignSpec) -> Result<Vec<PatchPlan<'_>>> {
    static DEFAULT_OP: OperatorSpec = OperatorSpec::Polyharmonic { order: 2, a: 1.0 };
    let top_op = spec.operator.as_ref().unwrap_or(&DEFAULT_OP);
    match (&spec.conditions, &spec.patches) {
        (Some(_), Some(_)) => Err(Error::invalid(
            "a design has either top-level conditions (one patch) or [[patches]], not both",
        )
        .at("conditions")),
        (None, None)
            if !spec.parametric.is_empty()
                || !spec.nurbs.is_empty()
                || !spec.nsided.is_empty()
                || !spec.network.is_empty()
                || !spec.patchwork.is_empty()
                || !spec.disk.is_empty()
                || spec.dynamic.is_some()
                || spec.blend.is_some()
                || spec.spline.is_some() =>
        {
            Ok(Vec::new())
        }
        (None, None) => Err(Error::invalid(
            "the design has no conditions: give `conditions = [...]` or [[patches]]",
        )),
        (Some(conds), None) => Ok(vec![PatchPlan {
            name: spec.title.clone().unwrap_or_else(|| "surface".to_string()),
            place: "conditions".to_string(),
            operator: top_op,
            operator_place: "operator".to_string(),
            conditions: conds,
        }]),
        (None, Some(patches)) => {
            if patches.is_empty() {
                return Err(Error::invalid("needs at least one patch").at("patches"));
            }
            let mut out = Vec::new();
            for (i, p) in patches.iter().enumerate() {
                if p.name.trim().is_empty() {
                    return Err(
                        Error::invalid("must not be empty").at(&format!("patches[{i}].name"))
                    );
                }
                if let Some(j) = patches[..i].iter().position(|q| q.name == p.name) {
                    return Err(Error::invalid(format!(
                        "'{}' is already the name of patches[{j}]",
                        p.name
                    ))
                    .at(&format!("patches[{i}].name")));
                }
                let (operator, operator_place) = match &p.operator {
                    Some(op) => (op, format!("patches[{i}].operator")),
                    None => (top_op, "operator".to_string()),
                };
                out.push(PatchPlan {
                    name: p.name.clone(),
                    place: format!("patches[{i}].conditions"),
                    operator,
                    operator_place,
                    conditions: &p.conditions,
                });
            }
            Ok(out)
        }
    }
}

/// Validates a design's PDE patches without building any curve: numbers finite and in range,
/// curve references known and acyclic, the operator's parameters, condition counts (`2N`),
/// `u ∈ [0, 1]`, derivative orders `< 2N`, no two conditions of the same order at the same `u`,
/// condition curves periodic, solver options and the `[output]` grid. The curves' own values
/// are checked by their constructors when they are built.
pub(crate) fn validate_patches(spec: &DesignSpec) -> Result<()> {
    check_solver(&spec.solver)?;
    output_grid(&spec.output)?;
    for (name, c) in &spec.curves {
        check_curve(c, &curve_place(name))?;
    }
    check_references(&spec.curves)?;
    for (i, c) in spec.creases.iter().enumerate() {
        if !spec.curves.contains_key(c) {
            return Err(unknown_curve(c, &spec.curves, &format!("creases[{i}]")));
        }
    }
    super::attach::check_attachment_specs(spec)?;
    super::attach::patch_levels(spec)?;
    let plans = plan(spec)?;
    let names: Vec<String> = plans.iter().map(|p| p.name.clone()).collect();
    super::parametric::validate_parametric(&spec.parametric, &names)?;
    let mut taken = names.clone();
    taken.extend(spec.parametric.iter().map(|p| p.name.clone()));
    super::nurbs::validate_nurbs_names(&spec.nurbs, &taken)?;
    for p in plans {
        check_operator_values(p.operator, &p.operator_place)?;
        check_conditions(
            p.conditions,
            half_order(p.operator),
            &spec.curves,
            &p.place,
            &operator_words(p.operator),
        )?;
    }
    super::fd::check(spec)?;
    Ok(())
}

/// The checks of [`build_operator`] that do not need the operator built.
fn check_operator_values(spec: &OperatorSpec, place: &str) -> Result<()> {
    match spec {
        OperatorSpec::Polyharmonic { order, a } => {
            if !(1..=20).contains(order) {
                return Err(Error::invalid(format!(
                    "must be between 1 and 20 (got {order}); the PDE has order 2·order"
                ))
                .at(&format!("{place}.order")));
            }
            positive(*a, &format!("{place}.a"))
        }
        OperatorSpec::SixthOrder { a, b, c, d } => {
            for (name, x) in [("a", a), ("b", b), ("c", c), ("d", d)] {
                finite(*x, &format!("{place}.{name}"))?;
            }
            Ok(())
        }
        OperatorSpec::General { coefficients } => {
            if !(2..=21).contains(&coefficients.len()) {
                return Err(Error::invalid(format!(
                    "needs between 2 and 21 values [c0, …, cN] (got {})",
                    coefficients.len()
                ))
                .at(&format!("{place}.coefficients")));
            }
            for (i, x) in coefficients.iter().enumerate() {
                finite(*x, &format!("{place}.coefficients[{i}]"))?;
            }
            Ok(())
        }
    }
}

/// A patch as `(conditions place, operator place, operator, conditions)`.
pub(crate) type PatchSpecView = (String, String, OperatorSpec, Vec<ConditionSpec>);

/// The patches of a design, unvalidated.
pub(crate) fn patch_specs(spec: &DesignSpec) -> Result<Vec<PatchSpecView>> {
    Ok(plan(spec)?
        .into_iter()
        .map(|p| {
            (
                p.place,
                p.operator_place,
                p.operator.clone(),
                p.conditions.to_vec(),
            )
        })
        .collect())
}
