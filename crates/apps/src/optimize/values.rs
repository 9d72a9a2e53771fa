//! Parameter values applied to a design by name, each checked against what the design itself
//! declares: the `[[parameters]]` entries' bounds, the `[optimize]` parameters' bounds, and for
//! any other name in the book's notation what its kind admits. (Python's
//! `Design.with_params`.)

use crate::design::{design_a, parse_book_name, set_parameter, BookEdits, ParamKind};
use crate::spec::{CurveKind, DesignSpec};
use crate::Error;

/// A refused parameter value: the index of the pair in the list given to [`apply_values`] and
/// why (the message names the parameter where it is not obvious from the index).
#[derive(Debug)]
pub struct ValueError {
    /// Index of the refused pair in the list given to [`apply_values`].
    pub index: usize,
    /// Why it was refused.
    pub error: Error,
}

impl std::fmt::Display for ValueError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.error)
    }
}

impl std::error::Error for ValueError {}

/// `base` with the parameter values `values` (`(name, value)`, each name once) applied:
///
/// - a name declared in `[optimize]` with `min` and `max` must lie within them;
/// - a `[[parameters]]` entry's value is set by [`set_parameter`], within the entry's own
///   bounds (resolved when the design is compiled);
/// - any other name is read in the book's notation (`<curve>T<x|y|z>`, `<curve>R<x|y|z>`,
///   `<curve>D<x|y|z>`, `<curve>cT`, `a`; the curve must exist) and applied as the optimiser
///   applies it: a dilation factor must not be 0, `a` must stay positive and needs a
///   polyharmonic operator, `cT` needs a B-spline. Such names have no bounds of their own.
///
/// Every value must be finite.
pub fn apply_values(
    base: &DesignSpec,
    values: &[(String, f64)],
) -> std::result::Result<DesignSpec, ValueError> {
    let fail = |index: usize, error: Error| ValueError { index, error };
    let declared = base
        .optimize
        .as_ref()
        .map(|o| &o.parameters[..])
        .unwrap_or(&[]);
    let mut spec = base.clone();
    let mut book: Vec<(ParamKind, f64, usize)> = Vec::new();
    for (i, (name, value)) in values.iter().enumerate() {
        let value = *value;
        if values[..i].iter().any(|(n, _)| n == name) {
            return Err(fail(
                i,
                Error::invalid(format!("the parameter '{name}' is given twice")),
            ));
        }
        if !value.is_finite() {
            return Err(fail(
                i,
                Error::invalid(format!("must be finite (got {value})")),
            ));
        }
        if let Some((lo, hi)) = declared
            .iter()
            .find(|p| &p.name == name)
            .and_then(|p| p.min.zip(p.max))
        {
            if !(lo..=hi).contains(&value) {
                return Err(fail(
                    i,
                    Error::invalid(format!(
                        "{value} lies outside the bounds [{lo}, {hi}] of [optimize]"
                    )),
                ));
            }
        }
        if base.parameters.iter().any(|p| &p.name == name) {
            set_parameter(&mut spec, name, Some(value)).map_err(|e| fail(i, e))?;
            continue;
        }
        let kind = parse_book_name(name, base).map_err(|e| fail(i, e))?;
        match &kind {
            ParamKind::Smoothing if value <= 0.0 => {
                return Err(fail(
                    i,
                    Error::invalid(format!(
                        "the smoothing parameter a must stay positive (got {value})"
                    )),
                ))
            }
            ParamKind::Smoothing if design_a(base).is_none() => {
                return Err(fail(
                    i,
                    Error::invalid("'a' needs a polyharmonic operator, and the design uses none"),
                ))
            }
            ParamKind::Dilate { .. } if value == 0.0 => {
                return Err(fail(i, Error::invalid("a dilation factor must not be 0")))
            }
            ParamKind::ControlOffset { curve }
                if !matches!(
                    base.curves.get(curve).map(|c| &c.kind),
                    Some(CurveKind::BSpline { .. })
                ) =>
            {
                return Err(fail(
                    i,
                    Error::invalid(format!(
                        "'{name}' needs a bspline curve, but '{curve}' is not one"
                    )),
                ));
            }
            _ => {}
        }
        book.push((kind, value, i));
    }
    if !book.is_empty() {
        let edits = BookEdits::new(base, book.iter().map(|(k, _, i)| (k, values[*i].0.clone())))
            .map_err(|e| {
                // The edits name the parameter by its place: find which one.
                let index = book
                    .iter()
                    .map(|(_, _, i)| *i)
                    .find(|i| e.place() == values[*i].0)
                    .unwrap_or(book[0].2);
                fail(index, e)
            })?;
        edits.apply(&mut spec, book.iter().map(|(k, v, _)| (k, *v)));
    }
    Ok(spec)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optimize::Parameters;
    use crate::spec::{parse_design, OptimizeSpec};

    fn example(name: &str) -> DesignSpec {
        let path = format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"));
        parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    fn one(name: &str, value: f64) -> Vec<(String, f64)> {
        vec![(name.to_string(), value)]
    }

    /// A `[[parameters]]` entry outside its own bounds is refused with its name; inside them the
    /// value is set on the entry.
    #[test]
    fn a_value_outside_the_entry_bounds_is_refused_with_its_name() {
        let spec = example("swirl_port_params.toml");
        let e = apply_values(&spec, &[("s".into(), 2.0), ("theta".into(), 1.5)]).unwrap_err();
        assert_eq!(e.index, 1);
        let message = e.error.to_string();
        assert!(
            message.contains("'theta'") && message.contains("[-1.2, 1.2]"),
            "{message}"
        );
        let set = apply_values(&spec, &one("theta", 0.5)).unwrap();
        let entry = set.parameters.iter().find(|p| p.name == "theta").unwrap();
        assert_eq!(entry.value, Some(0.5));
    }

    /// An `[optimize]` parameter keeps its declared bounds.
    #[test]
    fn optimize_bounds_hold() {
        let spec = example("optimize_curvature.toml");
        let e = apply_values(&spec, &one("d1Dx", 3.5)).unwrap_err();
        assert_eq!(
            e.error.to_string(),
            "3.5 lies outside the bounds [0.01, 3] of [optimize]"
        );
        assert!(apply_values(&spec, &one("d1Dx", 2.5)).is_ok());
    }

    /// Book names without declared bounds: applied as the optimiser applies them (the same
    /// design as `Parameters::apply` with any bounds holding the value), refused only where the
    /// kind admits no value: a dilation by 0, `a ≤ 0`, an unknown curve.
    #[test]
    fn book_names_apply_as_the_optimiser_does() {
        let spec = example("cup.toml");
        let values = vec![("bellyDx".to_string(), 1.3), ("rimTz".to_string(), -0.2)];
        let applied = apply_values(&spec, &values).unwrap();
        let opt: OptimizeSpec = toml::from_str(
            "objective = \"area\"\nparameters = [{ name = \"bellyDx\", min = 0.5, max = 2.0 }, \
             { name = \"rimTz\", min = -1.0, max = 1.0 }]\n",
        )
        .unwrap();
        let ps = Parameters::new(&spec, &opt).unwrap();
        assert_eq!(applied, ps.apply(&spec, &[1.3, -0.2]));
        let zero = apply_values(&spec, &one("bellyDx", 0.0)).unwrap_err();
        assert_eq!(zero.error.to_string(), "a dilation factor must not be 0");
        let a = apply_values(&spec, &one("a", -2.0)).unwrap_err();
        assert!(
            a.error.to_string().contains("must stay positive"),
            "{}",
            a.error
        );
        let unknown = apply_values(&spec, &one("lidTz", 1.0)).unwrap_err();
        assert!(
            unknown.error.to_string().contains("lid"),
            "{}",
            unknown.error
        );
    }
}
