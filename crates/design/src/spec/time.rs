//! Time in the design file (§6.4.1, §8.1): the `[time]` section (the interval, the number of
//! frames or their rate, looping, and named parameters that are formulas in `t`) and numeric
//! fields written as formulas in `t`.
//!
//! Any number of the design file may be written as a string that starts with `=`: the rest is a
//! formula (the crate's formula language, [`crate::formula`]) in `t` and in the names of
//! `[time.params]` (not in `title`, `name` keys, `[dynamic]`, `[optimize]` or `[[parametric]]`,
//! which have text and formula languages of their own). [`TimedDesign::at`] evaluates every such field at one `t` and reads the result
//! as an ordinary [`DesignSpec`], so a design at one time is an ordinary design.
//!
//! ```toml
//! [time]
//! end = 0.8
//! frames = 48
//! loop = true
//! [time.params]
//! s = "sin(pi*t/0.8)^2"
//! [curves.rim]
//! type = "circle"
//! center = [0.0, 0.0, "= 4 - 0.7*s"]
//! radius = "= 1.5*(1 - 0.3*s)"
//! ```

use super::dynamic::FormulaText;
use super::types::DesignSpec;
use super::{limits, locate};
use crate::formula::{self, short, Parsed, Variables};
use crate::{Error, Result};
use exmex::FloatOpsFactory;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The most frames a `[time]` section may ask for.
pub const MAX_FRAMES: usize = 10_000;

/// The `[time]` section: the design's time interval and how it is sampled into frames. `t` is in
/// seconds of playback.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// The first time (default 0).
    #[serde(default)]
    pub start: f64,
    /// The last time (default 1), greater than `start`.
    #[serde(default = "default_end")]
    pub end: f64,
    /// The number of frames (2 to 10000; 1 or more with `loop`); exclusive with `fps`. Default:
    /// 24 frames per second of `end − start`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frames: Option<usize>,
    /// Frames per second of `t`; exclusive with `frames`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fps: Option<f64>,
    /// The motion is periodic with period `end − start`: the frames are
    /// `start + k (end − start) / frames`, `k = 0 … frames − 1` (the time `end` is the first
    /// frame again); otherwise they run from `start` to `end` inclusive.
    #[serde(
        default,
        rename = "loop",
        skip_serializing_if = "super::write::is_false"
    )]
    pub looped: bool,
    /// Named parameters: formulas in `t` (and in the other parameters) that formula fields may
    /// use.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, FormulaText>,
}

fn default_end() -> f64 {
    1.0
}

impl Default for TimeSpec {
    fn default() -> Self {
        TimeSpec {
            start: 0.0,
            end: 1.0,
            frames: None,
            fps: None,
            looped: false,
            params: BTreeMap::new(),
        }
    }
}

impl TimeSpec {
    /// The times of the frames (checked: a finite interval with `end > start`, `frames` or `fps`
    /// but not both, at most [`MAX_FRAMES`] frames). Errors have their place (`time.frames`, …).
    pub fn times(&self) -> Result<Vec<f64>> {
        let (a, b) = (self.start, self.end);
        if b.is_nan() || a.is_nan() || b <= a {
            return Err(Error::invalid(format!(
                "must be greater than time.start ({}), got {}",
                short(a),
                short(b)
            ))
            .at("time.end"));
        }
        let span = b - a;
        let n = match (self.frames, self.fps) {
            (Some(_), Some(_)) => {
                return Err(
                    Error::invalid("give frames or fps, not both (fps sets frames)").at("time.fps"),
                )
            }
            (Some(n), None) => n,
            (None, fps) => {
                let fps = fps.unwrap_or(24.0);
                if fps.is_nan() || fps <= 0.0 {
                    return Err(
                        Error::invalid(format!("must be positive, got {}", short(fps)))
                            .at("time.fps"),
                    );
                }
                let n = (span * fps).round();
                if n > MAX_FRAMES as f64 {
                    return Err(Error::invalid(format!(
                        "(end − start)·fps = {} frames; at most {MAX_FRAMES}",
                        short(n)
                    ))
                    .at("time.fps"));
                }
                n as usize + usize::from(!self.looped)
            }
        };
        let least = if self.looped { 1 } else { 2 };
        if n < least || n > MAX_FRAMES {
            return Err(Error::invalid(format!(
                "{n} frames; {least} to {MAX_FRAMES} are allowed{}",
                if self.looped {
                    ""
                } else {
                    " (the first and the last frame are start and end)"
                }
            ))
            .at(if self.frames.is_some() {
                "time.frames"
            } else {
                "time.fps"
            }));
        }
        Ok(if self.looped {
            (0..n).map(|k| a + span * k as f64 / n as f64).collect()
        } else {
            (0..n)
                .map(|k| {
                    if k + 1 == n {
                        b
                    } else {
                        a + span * k as f64 / (n - 1) as f64
                    }
                })
                .collect()
        })
    }
}

/// The `[morph]` section of a morph file (§6.4.1): the source and target designs (paths
/// relative to the morph file) and the ease `γ` of the schedule `ε = τ^γ`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MorphSpec {
    /// The design at `ε = 0`.
    pub source: String,
    /// The design at `ε = 1`; it must have the source's structure.
    pub target: String,
    /// `γ > 0`: `ε = τ^γ` with `τ = (t − start)/(end − start)` (1, the default, is linear;
    /// above 1 starts slowly, below 1 ends slowly).
    #[serde(default = "default_ease")]
    pub ease: f64,
}

fn default_ease() -> f64 {
    1.0
}

/// A morph file: `[time]`, `[morph]` and optionally `title` and `[output]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MorphFile {
    /// A name for the animation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub title: Option<String>,
    /// The frames (`loop` is refused: a morph runs from the source to the target).
    #[serde(default)]
    pub time: TimeSpec,
    /// The two designs and the ease.
    pub morph: MorphSpec,
    /// The grid of the frames.
    #[serde(default)]
    pub output: super::types::OutputSpec,
}

/// Reads a morph file (a file with a `[morph]` section); `None` when the file has none.
pub fn parse_morph_file(text: &str) -> Result<Option<MorphFile>> {
    limits::check_text(text)?;
    let doc: toml::Table =
        toml::from_str(text).map_err(|e| Error::invalid(super::one_line(e.message())))?;
    if !doc.contains_key("morph") {
        return Ok(None);
    }
    let doc = toml::Value::Table(doc);
    limits::check_value(&doc, "", 0)?;
    locate::check_finite(&doc, "")?;
    let file = super::deserialize_at::<MorphFile>(doc, "")?;
    if file.time.looped {
        return Err(
            Error::invalid("a morph runs from the source to the target once; remove loop")
                .at("time.loop"),
        );
    }
    if file.morph.ease.is_nan() || file.morph.ease <= 0.0 {
        return Err(
            Error::invalid(format!("must be positive, got {}", short(file.morph.ease)))
                .at("morph.ease"),
        );
    }
    file.time.times()?;
    Ok(Some(file))
}

type Formula = Parsed<f64, FloatOpsFactory<f64>>;

/// One step of the path to a formula field in the TOML tree.
#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

/// A formula field: where it is, its text and its parsed form.
#[derive(Clone, Debug)]
struct Field {
    steps: Vec<Step>,
    place: String,
    text: String,
    formula: Formula,
}

/// A design file whose numbers may be formulas in `t`: parse once with [`parse_timed`], then
/// [`TimedDesign::at`] gives the design at any time.
#[derive(Clone, Debug)]
pub struct TimedDesign {
    doc: toml::Value,
    /// The `[time]` section (the default when the file has none).
    pub time: TimeSpec,
    /// The parameters in an order where each comes after those it uses.
    params: Vec<(String, Formula)>,
    /// The variable names: `t`, then the parameters by name.
    names: Vec<String>,
    fields: Vec<Field>,
}

/// Parses a design file that may have a `[time]` section and formula fields (strings starting
/// with `=`). The design is checked at `time.start` so that a mistake anywhere is reported now.
pub fn parse_timed(text: &str) -> Result<TimedDesign> {
    limits::check_text(text)?;
    let doc: toml::Table =
        toml::from_str(text).map_err(|e| Error::invalid(super::one_line(e.message())))?;
    let doc = toml::Value::Table(doc);
    limits::check_value(&doc, "", 0)?;
    locate::check_finite(&doc, "")?;
    let time = match doc.get("time") {
        Some(v) => super::deserialize_at::<TimeSpec>(v.clone(), "time")?,
        None => TimeSpec::default(),
    };
    let mut names: Vec<String> = vec!["t".to_string()];
    for name in time.params.keys() {
        let place = format!("time.params.{}", locate::key_path(name));
        let ok = name
            .chars()
            .next()
            .is_some_and(|c| c.is_alphabetic() || c == '_')
            && name.chars().all(|c| c.is_alphanumeric() || c == '_');
        if !ok || ["t", "pi", "e", "PI", "E", "TAU"].contains(&name.as_str()) {
            return Err(Error::invalid(format!(
                "'{name}' cannot name a parameter (a letter or _ then letters, digits or _; not \
                 t, pi or e)"
            ))
            .at(&place));
        }
        names.push(name.clone());
    }
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let vars = Variables::this(&refs);
    let mut parsed: BTreeMap<String, Formula> = BTreeMap::new();
    for (name, f) in &time.params {
        let place = format!("time.params.{}", locate::key_path(name));
        let text = f.text();
        let text = text.strip_prefix('=').unwrap_or(&text);
        parsed.insert(
            name.clone(),
            formula::parse(text, &vars).map_err(|e| e.at(&place))?,
        );
    }
    let params = order_params(&parsed, &names)?;
    let mut fields = Vec::new();
    collect(&doc, &mut Vec::new(), "", &vars, &mut fields)?;
    if let Some(f) = fields.iter().find(|f| f.place.starts_with("time.")) {
        return Err(Error::invalid(
            "the [time] section itself cannot depend on t (its params are formulas already)",
        )
        .at(&f.place));
    }
    let timed = TimedDesign {
        doc,
        time,
        params,
        names,
        fields,
    };
    timed.time.times()?;
    timed.at(timed.time.start)?;
    Ok(timed)
}

/// Orders the parameters so that each follows those its formula uses; a cycle is refused.
fn order_params(
    parsed: &BTreeMap<String, Formula>,
    names: &[String],
) -> Result<Vec<(String, Formula)>> {
    let deps = |f: &Formula| -> Vec<String> {
        f.slots
            .iter()
            .filter(|&&s| s > 0)
            .map(|&s| names[s].clone())
            .collect()
    };
    let mut done: Vec<(String, Formula)> = Vec::new();
    let mut state: BTreeMap<&str, u8> = BTreeMap::new();
    fn visit<'a>(
        name: &'a str,
        parsed: &'a BTreeMap<String, Formula>,
        deps: &dyn Fn(&Formula) -> Vec<String>,
        state: &mut BTreeMap<&'a str, u8>,
        done: &mut Vec<(String, Formula)>,
        chain: &mut Vec<String>,
    ) -> Result<()> {
        match state.get(name) {
            Some(2) => return Ok(()),
            Some(1) => {
                chain.push(name.to_string());
                return Err(Error::invalid(format!(
                    "the parameters refer to one another in a cycle: {}",
                    chain.join(" → ")
                ))
                .at(&format!("time.params.{}", locate::key_path(&chain[0]))));
            }
            _ => {}
        }
        state.insert(name, 1);
        chain.push(name.to_string());
        let (key, f) = parsed.get_key_value(name).expect("a parameter");
        for d in deps(f) {
            visit(
                parsed.get_key_value(&d).expect("a parameter").0,
                parsed,
                deps,
                state,
                done,
                chain,
            )?;
        }
        chain.pop();
        state.insert(key, 2);
        done.push((key.clone(), f.clone()));
        Ok(())
    }
    for name in parsed.keys() {
        visit(name, parsed, &deps, &mut state, &mut done, &mut Vec::new())?;
    }
    Ok(done)
}

fn join(place: &str, key: &str) -> String {
    if place.is_empty() {
        locate::key_path(key)
    } else {
        format!("{place}.{}", locate::key_path(key))
    }
}

/// Finds the formula fields (strings starting with `=`) of `value`.
fn collect(
    value: &toml::Value,
    steps: &mut Vec<Step>,
    place: &str,
    vars: &Variables,
    out: &mut Vec<Field>,
) -> Result<()> {
    match value {
        toml::Value::String(s) => {
            if let Some(text) = s.strip_prefix('=') {
                if place.starts_with("time.params") {
                    return Ok(());
                }
                let formula = formula::parse(text, vars).map_err(|e| e.at(place))?;
                out.push(Field {
                    steps: steps.clone(),
                    place: place.to_string(),
                    text: text.trim().to_string(),
                    formula,
                });
            }
        }
        toml::Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                steps.push(Step::Index(i));
                collect(item, steps, &format!("{place}[{i}]"), vars, out)?;
                steps.pop();
            }
        }
        toml::Value::Table(t) => {
            for (k, item) in t {
                // Names, titles and the sections with formula languages of their own are text.
                let text_key = ["title", "name"].contains(&k.as_str())
                    || (place.is_empty()
                        && ["dynamic", "optimize", "parametric"].contains(&k.as_str()));
                if text_key {
                    continue;
                }
                steps.push(Step::Key(k.clone()));
                collect(item, steps, &join(place, k), vars, out)?;
                steps.pop();
            }
        }
        _ => {}
    }
    Ok(())
}

impl TimedDesign {
    /// True when some field is a formula in `t` or the design has a `[rig]` (otherwise every
    /// frame is the same design).
    pub fn depends_on_time(&self) -> bool {
        !self.fields.is_empty() || self.doc.get("rig").is_some()
    }

    /// The places of the formula fields (`curves.rim.radius`, …), in file order by path.
    pub fn formula_places(&self) -> Vec<&str> {
        self.fields.iter().map(|f| f.place.as_str()).collect()
    }

    /// The values of `t` and of every parameter at time `t`, in the order of the variables.
    pub fn values(&self, t: f64) -> Result<Vec<f64>> {
        let mut values = vec![f64::NAN; self.names.len()];
        values[0] = t;
        for (name, f) in &self.params {
            let k = self.names.iter().position(|n| n == name).expect("a name");
            let x = f.eval(&values).unwrap_or(f64::NAN);
            if !x.is_finite() {
                return Err(
                    Error::invalid(format!("is not finite at t = {} (got {x})", short(t)))
                        .at(&format!("time.params.{}", locate::key_path(name))),
                );
            }
            values[k] = x;
        }
        Ok(values)
    }

    /// The design file's tree with every formula field replaced by its value at `t`, posed by
    /// its `[rig]` (see [`super::rig`]).
    pub fn value_at(&self, t: f64) -> Result<toml::Value> {
        let values = self.values(t)?;
        let mut doc = self.doc.clone();
        for f in &self.fields {
            let x = f.formula.eval(&values).unwrap_or(f64::NAN);
            if !x.is_finite() {
                return Err(Error::invalid(format!(
                    "'{}' is not finite at t = {} (got {x})",
                    f.text,
                    short(t)
                ))
                .at(&f.place));
            }
            let mut node = &mut doc;
            for s in &f.steps {
                node = match (s, node) {
                    (Step::Key(k), toml::Value::Table(t)) => t.get_mut(k).expect("a key"),
                    (Step::Index(i), toml::Value::Array(a)) => &mut a[*i],
                    _ => unreachable!("the path was read from this tree"),
                };
            }
            *node = toml::Value::Float(x);
        }
        super::rig::apply(&mut doc, t, self.time.start, self.time.end)?;
        Ok(doc)
    }

    /// The design at time `t`: an ordinary design (errors carry their place in the file).
    pub fn at(&self, t: f64) -> Result<DesignSpec> {
        spec_of_value(self.value_at(t)?)
    }
}

/// Reads a design from a TOML tree (as [`super::parse_design`] reads it from text).
pub fn spec_of_value(doc: toml::Value) -> Result<DesignSpec> {
    locate::check_finite(&doc, "")?;
    let spec = super::deserialize_at::<DesignSpec>(doc, "")?;
    limits::check_spec(&spec)?;
    Ok(spec)
}

#[cfg(test)]
mod tests {
    use super::*;

    const DESIGN: &str = r#"
[time]
end = 2.0
frames = 5
[time.params]
s = "t/2"
w = "= 2*s"
[curves.rim]
type = "circle"
center = [0.0, 0.0, "= 1 + w"]
radius = "= 1 + t"
[[patches]]
name = "p"
operator = { kind = "polyharmonic", order = 2, a = "= 1 + s" }
conditions = [
  { u = 0.0, curve = { type = "circle", center = [0, 0, 0], radius = 1.0 } },
  { u = 0.0, derivative = 1, curve = { type = "circle", center = [0, 0, 1], radius = 1.0 } },
  { u = 1.0, curve = "rim" },
  { u = 1.0, derivative = 1, curve = { type = "circle", center = [0, 0, 1], radius = 1.0 } },
]
"#;

    #[test]
    fn formula_fields_follow_t_and_the_parameters() {
        let d = parse_timed(DESIGN).unwrap();
        assert!(d.depends_on_time());
        assert_eq!(d.time.times().unwrap(), vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        let s = d.at(1.5).unwrap();
        let rim = &s.curves["rim"];
        match &rim.kind {
            super::super::CurveKind::Circle { center, radius, .. } => {
                assert_eq!(*radius, 2.5);
                assert_eq!(center[2], 1.0 + 1.5);
            }
            k => panic!("{k:?}"),
        }
        match &s.patches.as_ref().unwrap()[0].operator {
            Some(super::super::OperatorSpec::Polyharmonic { a, .. }) => assert_eq!(*a, 1.75),
            o => panic!("{o:?}"),
        }
    }

    #[test]
    fn loop_frames_leave_out_the_end() {
        let t = TimeSpec {
            end: 0.8,
            frames: Some(4),
            looped: true,
            ..TimeSpec::default()
        };
        assert_eq!(t.times().unwrap(), vec![0.0, 0.2, 0.4, 0.6000000000000001]);
        let t = TimeSpec {
            fps: Some(10.0),
            ..TimeSpec::default()
        };
        assert_eq!(t.times().unwrap().len(), 11);
    }

    #[test]
    fn mistakes_are_refused_with_their_place() {
        let bad = DESIGN.replace("\"= 1 + t\"", "\"= 1 + q\"");
        let e = parse_timed(&bad).unwrap_err();
        assert_eq!(e.place(), "curves.rim.radius");
        assert!(e.to_string().contains("unknown variable 'q'"), "{e}");
        let bad = DESIGN.replace("\"= 1 + t\"", "\"= 1/(t - 0)\"");
        let e = parse_timed(&bad).unwrap_err();
        assert_eq!(e.place(), "curves.rim.radius");
        assert!(e.to_string().contains("not finite at t = 0"), "{e}");
        let bad = DESIGN.replace("s = \"t/2\"", "s = \"w/2\"");
        let e = parse_timed(&bad).unwrap_err();
        assert!(e.to_string().contains("cycle"), "{e}");
        let bad = DESIGN.replace("frames = 5", "frames = 5\nfps = 3");
        assert_eq!(parse_timed(&bad).unwrap_err().place(), "time.fps");
        let bad = DESIGN.replace("end = 2.0", "end = \"= 2*t\"");
        assert!(parse_timed(&bad).is_err());
        // A formula where a name is expected is a type error at its place.
        let bad = DESIGN.replace("curve = \"rim\"", "curve = \"= t\"");
        assert_eq!(
            parse_timed(&bad).unwrap_err().place(),
            "patches[0].conditions[2].curve"
        );
    }

    #[test]
    fn a_design_without_time_is_read_as_parse_design_reads_it() {
        let text = "[curves.c]\ntype = \"circle\"\ncenter = [0, 0, 1]\nradius = 2.0\n";
        let d = parse_timed(text).unwrap();
        assert!(!d.depends_on_time());
        assert_eq!(
            d.at(0.3).unwrap(),
            super::super::parse_design(text).unwrap()
        );
    }
}
