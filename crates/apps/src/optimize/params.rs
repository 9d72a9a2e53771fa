//! The optimiser's parameters (§7.5): entries of the design's `[[parameters]]` named by
//! `[optimize] parameters` (the position, angle, scale and `v = 0` parameters of §6.1 and §6.4
//! among them), or names in the book's notation: `c_kP_i` with `c` a curve, `P` the kind of
//! change (`T` translation, `R` rotation, `D` dilation) and `i` the axis; the smoothing
//! parameter `a`; and `c_T`, the amplitude of the control-point offsets of a B-spline curve
//! (Eq. 7.6). Both act through the design layer's one mechanism (`design::resolve_parameters`
//! and the §7.5 edits it shares): a named entry gets the value, a book name edits the
//! [`DesignSpec`] as that entry kind would (transform steps appended to the named curve, `a`
//! replaced, control points moved), so the design is rebuilt exactly as a design file with those
//! edits would be.

use crate::design::{
    design_a, design_parameters, parse_book_name, poly_a, top_level_used, BookEdits,
    DesignParameter,
};
use crate::spec::{
    key_path, CurveKind, CurveSpec, DesignSpec, OptimizeSpec, ParameterSpec, TransformStep,
};
use crate::{Error, Result};

pub use crate::design::ParamKind;

/// One design parameter of the search with its bounds.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// The name as written (`d1Dx`, `a`, `d1cT`, or a `[[parameters]]` entry's).
    pub name: String,
    /// What the parameter changes.
    pub kind: ParamKind,
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// The value the search starts from, within `[min, max]`.
    pub initial: f64,
    /// The index of the `[[parameters]]` entry it sets, if it names one.
    pub entry: Option<usize>,
}

/// The parameters of a search, ready to act on its design.
#[derive(Clone, Debug)]
pub struct Parameters {
    /// The parameters, in the order `[optimize] parameters` names them.
    pub list: Vec<Parameter>,
    /// What the book-notation parameters need (centroids, offset directions).
    book: BookEdits,
}

impl Parameters {
    /// The parameters' names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.list.iter().map(|p| p.name.as_str()).collect()
    }

    /// Reads and checks the parameters of `[optimize]`: a name of a `[[parameters]]` entry
    /// (bounds default to the entry's and must lie within them; the start is its value), else
    /// a name in the book's notation (curves must exist; `cT` only on B-splines; `a` only with a
    /// polyharmonic operator; `min` and `max` required); bounds `min < max`, finite, dilations
    /// and `a` bounded away from 0, the initial value inside the bounds, no name twice. Errors
    /// name their place, `optimize.parameters[i].<key>`.
    pub fn new(spec: &DesignSpec, opt: &OptimizeSpec) -> Result<Parameters> {
        if opt.parameters.is_empty() {
            return Err(
                Error::invalid("at least one parameter is needed").at("optimize.parameters")
            );
        }
        let entries = if spec.parameters.is_empty() {
            Vec::new()
        } else {
            design_parameters(spec)?
        };
        let mut list: Vec<Parameter> = Vec::new();
        for (i, p) in opt.parameters.iter().enumerate() {
            let place = format!("optimize.parameters[{i}]");
            let one = match spec.parameters.iter().position(|q| q.name == p.name) {
                Some(j) => Self::entry(p, &entries[j], j, &place)?,
                None => Self::one(spec, p, &place)?,
            };
            list.push(one);
            if list[..i].iter().any(|q| q.name == p.name) {
                return Err(
                    Error::invalid(format!("the parameter '{}' is given twice", p.name))
                        .at(&format!("{place}.name")),
                );
            }
        }
        let book = BookEdits::new(
            spec,
            list.iter()
                .enumerate()
                .filter(|(_, p)| p.entry.is_none())
                .map(|(i, p)| (&p.kind, format!("optimize.parameters[{i}].name"))),
        )?;
        Ok(Parameters { list, book })
    }

    /// A parameter naming the `[[parameters]]` entry `e` (index `j`).
    fn entry(p: &ParameterSpec, e: &DesignParameter, j: usize, place: &str) -> Result<Parameter> {
        let min = p.min.unwrap_or(e.min);
        let max = p.max.unwrap_or(e.max);
        for (key, x) in [("min", min), ("max", max)] {
            if !x.is_finite() {
                return Err(Error::invalid(format!("must be finite (got {x})"))
                    .at(&format!("{place}.{key}")));
            }
        }
        if min < e.min {
            return Err(Error::invalid(format!(
                "{min} lies below the bound min = {} of parameters[{j}] ('{}')",
                e.min, e.name
            ))
            .at(&format!("{place}.min")));
        }
        if max > e.max {
            return Err(Error::invalid(format!(
                "{max} lies above the bound max = {} of parameters[{j}] ('{}')",
                e.max, e.name
            ))
            .at(&format!("{place}.max")));
        }
        if min >= max {
            return Err(
                Error::invalid(format!("must be greater than min = {min} (got {max})"))
                    .at(&format!("{place}.max")),
            );
        }
        let initial = initial_within(p, e.value, min, max, place)?;
        Ok(Parameter {
            name: p.name.clone(),
            kind: e.kind.clone(),
            min,
            max,
            initial,
            entry: Some(j),
        })
    }

    /// A parameter in the book's notation.
    fn one(spec: &DesignSpec, p: &ParameterSpec, place: &str) -> Result<Parameter> {
        let kind = parse_book_name(&p.name, spec).map_err(|e| e.at(&format!("{place}.name")))?;
        let mut bounds = [0.0; 2];
        for (k, (key, x)) in [("min", p.min), ("max", p.max)].into_iter().enumerate() {
            bounds[k] = match x {
                None => {
                    return Err(Error::invalid(format!(
                        "'{}' is not a [[parameters]] entry, so it needs `min` and `max`",
                        p.name
                    ))
                    .at(place))
                }
                Some(x) if !x.is_finite() => {
                    return Err(Error::invalid(format!("must be finite (got {x})"))
                        .at(&format!("{place}.{key}")))
                }
                Some(x) => x,
            };
        }
        let [min, max] = bounds;
        if min >= max {
            return Err(
                Error::invalid(format!("must be greater than min = {min} (got {max})"))
                    .at(&format!("{place}.max")),
            );
        }
        match &kind {
            ParamKind::Dilate { .. } if min <= 0.0 && max >= 0.0 => {
                return Err(Error::invalid(format!(
                    "a dilation's range must not contain 0 (got [{min}, {max}])"
                ))
                .at(&format!("{place}.min")))
            }
            ParamKind::Smoothing if min <= 0.0 => {
                return Err(Error::invalid(format!(
                    "the smoothing parameter a must stay positive (got min = {min})"
                ))
                .at(&format!("{place}.min")))
            }
            ParamKind::ControlOffset { curve }
                if !matches!(
                    spec.curves.get(curve).map(|c| &c.kind),
                    Some(CurveKind::BSpline { .. })
                ) =>
            {
                return Err(Error::invalid(format!(
                    "'{}' needs a bspline curve, but '{curve}' is not one",
                    p.name
                ))
                .at(&format!("{place}.name")));
            }
            _ => {}
        }
        let neutral = match &kind {
            ParamKind::Dilate { .. } => 1.0,
            ParamKind::Smoothing => design_a(spec).ok_or_else(|| {
                Error::invalid(
                    "'a' needs a polyharmonic operator, and the design uses none".to_string(),
                )
                .at(&format!("{place}.name"))
            })?,
            _ => 0.0,
        };
        let initial = initial_within(p, neutral, min, max, place)?;
        Ok(Parameter {
            name: p.name.clone(),
            kind,
            min,
            max,
            initial,
            entry: None,
        })
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// Whether there are none (never, once built).
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// The initial values.
    pub fn initial(&self) -> Vec<f64> {
        self.list.iter().map(|p| p.initial).collect()
    }

    /// The bounds `(min, max)` of every parameter.
    pub fn bounds(&self) -> Vec<(f64, f64)> {
        self.list.iter().map(|p| (p.min, p.max)).collect()
    }

    /// The book-notation parameters with their values in `x`.
    fn book_pairs<'a>(
        &'a self,
        x: &'a [f64],
    ) -> impl Iterator<Item = (&'a ParamKind, f64)> + Clone {
        self.list
            .iter()
            .zip(x)
            .filter(|(p, _)| p.entry.is_none())
            .map(|(p, v)| (&p.kind, *v))
    }

    /// The design with the parameter values `x` applied (see the module documentation). `x` has
    /// one value per parameter, in the order of `[optimize].parameters`.
    pub fn apply(&self, base: &DesignSpec, x: &[f64]) -> DesignSpec {
        let mut spec = base.clone();
        for (p, &v) in self.list.iter().zip(x) {
            if let Some(entry) = p.entry.and_then(|j| spec.parameters.get_mut(j)) {
                entry.value = Some(v);
            }
        }
        self.book.apply(&mut spec, self.book_pairs(x));
        spec
    }

    fn smoothing(&self, x: &[f64]) -> Option<f64> {
        self.book_pairs(x)
            .find(|(k, _)| **k == ParamKind::Smoothing)
            .map(|(_, v)| v)
    }

    /// The design file's text with the parameter values `x` applied, keeping the file's layout
    /// and comments: transform steps appended to `curves.<name>.transform`, `a` written into
    /// the polyharmonic operators, moved control points written into `control`.
    pub fn apply_to_text(&self, text: &str, base: &DesignSpec, x: &[f64]) -> Result<String> {
        use toml_edit::{value, Array, DocumentMut, InlineTable, Item, Value};
        let mut doc: DocumentMut = text
            .parse()
            .map_err(|e: toml_edit::TomlError| Error::invalid(e.message().to_string()))?;
        let num_array = |v: &[f64; 3]| -> Value {
            let mut a = Array::new();
            for x in v {
                a.push(*x);
            }
            Value::Array(a)
        };
        // `[[parameters]]` entries: their `value`.
        for (p, &v) in self.list.iter().zip(x) {
            let Some(j) = p.entry else { continue };
            let place = format!("parameters[{j}]");
            let table = match doc.get_mut("parameters") {
                Some(Item::ArrayOfTables(arr)) => {
                    arr.get_mut(j).map(|t| t as &mut dyn toml_edit::TableLike)
                }
                Some(Item::Value(Value::Array(arr))) => arr
                    .get_mut(j)
                    .and_then(|v| v.as_inline_table_mut())
                    .map(|t| t as &mut dyn toml_edit::TableLike),
                _ => None,
            }
            .ok_or_else(|| Error::invalid("cannot edit this parameter's table").at(&place))?;
            table.insert("value", value(v));
        }
        for (curve, e) in BookEdits::per_curve(self.book_pairs(x)) {
            let place = format!("curves.{}", key_path(&curve));
            let table = doc
                .get_mut("curves")
                .and_then(|c| c.get_mut(&curve))
                .and_then(|c| c.as_table_like_mut())
                .ok_or_else(|| Error::invalid("cannot edit this curve's table").at(&place))?;
            if let (
                Some(amp),
                Some(CurveSpec {
                    kind: CurveKind::BSpline { control, .. },
                    ..
                }),
            ) = (e.offset, base.curves.get(&curve))
            {
                let mut arr = Array::new();
                for c in self.book.moved_control(&curve, control, amp) {
                    arr.push(num_array(&c));
                }
                table.insert("control", value(arr));
            }
            let steps: Vec<InlineTable> = self
                .book
                .steps(&curve, &e)
                .iter()
                .map(|s| {
                    let mut inner = InlineTable::new();
                    let mut outer = InlineTable::new();
                    match s {
                        TransformStep::Translate(t) => {
                            outer.insert("translate", num_array(t));
                        }
                        TransformStep::Rotate { axis, angle, about } => {
                            inner.insert("axis", num_array(axis));
                            inner.insert("angle", Value::from(*angle));
                            inner.insert("about", num_array(about));
                            outer.insert("rotate", Value::InlineTable(inner));
                        }
                        TransformStep::Dilate { factors, about } => {
                            inner.insert("factors", num_array(factors));
                            inner.insert("about", num_array(about));
                            outer.insert("dilate", Value::InlineTable(inner));
                        }
                        TransformStep::Scale { factor, about } => {
                            inner.insert("factor", Value::from(*factor));
                            inner.insert("about", num_array(about));
                            outer.insert("scale", Value::InlineTable(inner));
                        }
                    }
                    outer
                })
                .collect();
            match table.get_mut("transform") {
                Some(Item::Value(Value::Array(arr))) => {
                    for s in steps {
                        arr.push(Value::InlineTable(s));
                    }
                }
                Some(Item::ArrayOfTables(arr)) => {
                    for s in steps {
                        arr.push(s.into_table());
                    }
                }
                Some(_) => {
                    return Err(Error::invalid("expected an array of steps")
                        .at(&format!("{place}.transform")))
                }
                None => {
                    let mut arr = Array::new();
                    for s in steps {
                        arr.push(Value::InlineTable(s));
                    }
                    table.insert("transform", value(arr));
                }
            }
        }
        if let Some(a) = self.smoothing(x) {
            if top_level_used(base) {
                if base.operator.is_none() {
                    let mut t = InlineTable::new();
                    t.insert("kind", Value::from("polyharmonic"));
                    t.insert("a", Value::from(a));
                    doc.insert("operator", value(t));
                } else if poly_a(&base.operator).is_some() {
                    if let Some(op) = doc.get_mut("operator").and_then(|o| o.as_table_like_mut()) {
                        op.insert("a", value(a));
                    }
                }
            }
            if let Some(patches) = &base.patches {
                for (i, p) in patches.iter().enumerate() {
                    if p.operator.is_none() || poly_a(&p.operator).is_none() {
                        continue;
                    }
                    match doc.get_mut("patches") {
                        Some(Item::ArrayOfTables(arr)) => {
                            if let Some(op) = arr
                                .get_mut(i)
                                .and_then(|t| t.get_mut("operator"))
                                .and_then(|o| o.as_table_like_mut())
                            {
                                op.insert("a", value(a));
                            }
                        }
                        Some(Item::Value(Value::Array(arr))) => {
                            if let Some(op) = arr
                                .get_mut(i)
                                .and_then(|v| v.as_inline_table_mut())
                                .and_then(|t| t.get_mut("operator"))
                                .and_then(|o| o.as_inline_table_mut())
                            {
                                op.insert("a", Value::from(a));
                            }
                        }
                        _ => {}
                    }
                }
            }
        }
        Ok(doc.to_string())
    }
}

/// The parameter's initial value (`default` when the file gives none), refused outside
/// `[min, max]` at `initial`, or at `min` when the default is what lies outside.
fn initial_within(p: &ParameterSpec, default: f64, min: f64, max: f64, place: &str) -> Result<f64> {
    let initial = p.initial.unwrap_or(default);
    if (min..=max).contains(&initial) {
        return Ok(initial);
    }
    let key = if p.initial.is_some() {
        "initial"
    } else {
        "min"
    };
    Err(Error::invalid(format!(
        "the initial value {initial} lies outside [min, max] = [{min}, {max}]"
    ))
    .at(&format!("{place}.{key}")))
}
