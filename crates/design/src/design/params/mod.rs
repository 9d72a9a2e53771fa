//! Design parameters (`[[parameters]]`): named, bounded values that act on the design's curves
//! and operators. The book's parameters on a curve (§6.1): the position parameter `X₁` (the
//! curve's point at `v₁` dragged, the curve following), the angling parameter `θ` (the curve
//! turned about a line through `X₁`), the scaling parameter `s = |X₁X₂|` (the curve resized
//! about `X₁`), and the `v = 0` point (§6.4, `v_origin`); and those of §7.5: translation,
//! rotation and dilation about the curve's centroid (`c_kT_i`, `c_kR_i`, `c_kD_i`), the
//! control-point offsets `c_T` and the smoothing parameter `a`.
//!
//! A parameter acts by editing the design as a file would: transform steps appended to the
//! driven curves, `v_origin` or `a` replaced, control points moved. [`resolve_parameters`] turns
//! a design with parameters into the design without them that [`super::compile`] solves; the
//! optimiser (`optimize::Parameters`) drives the same entries by name, so there is one
//! mechanism. A parameter at its neutral value leaves the design exactly as written.
//!
//! Order: the §7.5 kinds act first, grouped per curve as the optimiser's names always did
//! (dilation, rotations about x, y, z, translation, all about the centroid of the curve as
//! written); then the §6.1 and §6.4 kinds act in the order they are written, each on the curves
//! as the ones before it left them (so `X₁` is found on the curve as already moved).

use crate::spec::DesignSpec;
use crate::{Error, Result};
use std::borrow::Cow;

mod book;
mod kind;
mod read;
mod resolve;
pub use book::{book_names, design_a, parse_book_name, poly_a, top_level_used, BookEdits};
pub use kind::{DesignParameter, ParamKind};
use resolve::run;

/// The `[[parameters]]` of a design, read and checked, with their neutral values; the design
/// they do not change (its curves and operators as written) is `spec`.
pub fn design_parameters(spec: &DesignSpec) -> Result<Vec<DesignParameter>> {
    run(spec).map(|(_, list)| list)
}

/// The design with the values of its `[[parameters]]` applied and the table emptied (borrowed
/// when it has none): what [`super::compile`] solves. Errors name their place
/// (`parameters[2].v2`, …).
pub fn resolve_parameters(spec: &DesignSpec) -> Result<Cow<'_, DesignSpec>> {
    if spec.parameters.is_empty() {
        return Ok(Cow::Borrowed(spec));
    }
    run(spec).map(|(s, _)| Cow::Owned(s))
}

/// Sets the value of the parameter `name` (`None`: back to its neutral value, i.e. no `value`
/// key), checked against its bounds; returns the old value. Errors name the parameter.
pub fn set_parameter(spec: &mut DesignSpec, name: &str, value: Option<f64>) -> Result<Option<f64>> {
    let Some((i, p)) = spec
        .parameters
        .iter_mut()
        .enumerate()
        .find(|(_, p)| p.name == name)
    else {
        let names: Vec<&str> = spec.parameters.iter().map(|p| p.name.as_str()).collect();
        return Err(Error::invalid(format!(
            "the design has no parameter named '{name}' (known: {})",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        ))
        .at("parameters"));
    };
    if let Some(v) = value {
        if !(v.is_finite() && p.min <= v && v <= p.max) {
            return Err(Error::invalid(format!(
                "the value {v} of '{name}' lies outside [min, max] = [{}, {}]",
                p.min, p.max
            ))
            .at(&format!("parameters[{i}].value")));
        }
    }
    Ok(std::mem::replace(&mut p.value, value))
}
