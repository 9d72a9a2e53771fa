//! `[[parametric]]` surfaces: names and domains checked, formulas parsed and differentiated.

use crate::spec::{DomainSpec, ParametricSpec};
use crate::surface::{ParametricSurface, VDomain};
use crate::{Error, Result};

/// The v domain of a spec, checked. `place` is `parametric[i]`.
fn domain(p: &ParametricSpec, place: &str) -> Result<VDomain> {
    match p.domain {
        DomainSpec::Periodic => Ok(VDomain::Periodic),
        DomainSpec::Interval([a, b]) => {
            if a.is_finite() && b.is_finite() && a < b {
                Ok(VDomain::Interval(a, b))
            } else {
                Err(Error::invalid(format!(
                    "must be an interval [v0, v1] with v0 < v1 (got [{a}, {b}])"
                ))
                .at(&format!("{place}.domain")))
            }
        }
    }
}

/// Checks names (non-empty, unique among themselves and against `taken`, the names of the PDE
/// patches), formulas (non-empty) and domains, without parsing the formulas.
pub(crate) fn validate_parametric(specs: &[ParametricSpec], taken: &[String]) -> Result<()> {
    for (i, p) in specs.iter().enumerate() {
        let place = format!("parametric[{i}]");
        if p.name.trim().is_empty() {
            return Err(Error::invalid("must not be empty").at(&format!("{place}.name")));
        }
        if let Some(j) = specs[..i].iter().position(|q| q.name == p.name) {
            return Err(Error::invalid(format!(
                "'{}' is already the name of parametric[{j}]",
                p.name
            ))
            .at(&format!("{place}.name")));
        }
        if taken.contains(&p.name) {
            return Err(
                Error::invalid(format!("'{}' is already the name of a patch", p.name))
                    .at(&format!("{place}.name")),
            );
        }
        for (k, f) in [("x", &p.x), ("y", &p.y), ("z", &p.z)] {
            if f.trim().is_empty() {
                return Err(Error::invalid("is empty").at(&format!("{place}.{k}")));
            }
        }
        domain(p, &place)?;
    }
    Ok(())
}

/// Builds the surface of `parametric[i]` (parsing and differentiating the formulas; errors at
/// `parametric[i].x`).
pub(crate) fn build_parametric(p: &ParametricSpec, i: usize) -> Result<ParametricSurface> {
    let place = format!("parametric[{i}]");
    let d = domain(p, &place)?;
    ParametricSurface::new(&p.x, &p.y, &p.z, d).map_err(|e| e.at(&place))
}
