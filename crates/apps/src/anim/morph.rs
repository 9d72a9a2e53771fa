//! Morphing between two designs (§6.4.1): every number of the source design `S` and the
//! target design `T` is interpolated, `I = (1 − ε) S + ε T` (Eq. 6.3), so every condition curve
//! and the smoothing parameter move together.
//!
//! Eq. 6.4 prints `ε = γ^i / m` for the `i`-th of `m` intermediate surfaces. That runs from
//! `γ/m` to `γ^m/m`: for `γ = 1` it is the constant `1/m`, and it reaches 1 at `i = m` only when
//! `γ^m = m`. The schedule used here is `ε = τ^γ` with `τ = i/m ∈ [0, 1]`: it runs from 0 to 1 for
//! every `γ > 0`, linear at `γ = 1`, and `γ` is the ease (see `docs/errata.md`).
//!
//! The two designs must share their structure: the same tables with the same keys, arrays of the
//! same lengths, the same strings (curve names, kinds, patch names) and the same integers where
//! an integer is a count or an order (`order`, `derivative`, `modes`, …). Curves whose numbers
//! enter them linearly (circle centres and radii, control points, derivative scales) then morph
//! exactly as Eq. 6.3 says.

use crate::spec::{self, DesignSpec};
use crate::{Error, Result};

/// Keys whose integers are structure (counts, orders, indices), never interpolated.
const STRUCTURAL: [&str; 9] = [
    "order",
    "derivative",
    "modes",
    "samples",
    "degree",
    "nu",
    "nv",
    "grid",
    "terms",
];

/// The morph schedule: `ε = τ^γ` for `τ ∈ [0, 1]` (the corrected Eq. 6.4).
pub fn ease(tau: f64, gamma: f64) -> f64 {
    let tau = tau.clamp(0.0, 1.0);
    if tau == 0.0 || tau == 1.0 {
        tau
    } else {
        tau.powf(gamma)
    }
}

/// Two designs of one structure, interpolated by [`Morph::at`].
#[derive(Clone, Debug)]
pub struct Morph {
    source: toml::Value,
    target: toml::Value,
}

/// Keys that belong to the file and not to the shape: not compared and taken from the source.
const OWN: [&str; 3] = ["title", "output", "time"];

impl Morph {
    /// Reads the source and target design files (each must parse as a design on its own; those
    /// errors carry places in their own file) and checks that their structures agree. A
    /// difference is reported with its place in the source file and says what the target has.
    pub fn new(source: &str, target: &str) -> Result<Morph> {
        spec::parse_design(source)?;
        spec::parse_design(target)
            .map_err(|e| Error::invalid(format!("the target: {e}")).at("morph.target"))?;
        let s: toml::Value =
            toml::Value::Table(toml::from_str(source).map_err(|e| Error::invalid(e.to_string()))?);
        let t: toml::Value =
            toml::Value::Table(toml::from_str(target).map_err(|e| Error::invalid(e.to_string()))?);
        same_structure(&s, &t, "", "")?;
        Ok(Morph {
            source: s,
            target: t,
        })
    }

    /// The design `(1 − ε) S + ε T` (ε = 0 is the source and ε = 1 the target exactly; equal
    /// numbers stay exactly as they are).
    pub fn at(&self, eps: f64) -> Result<DesignSpec> {
        spec::time::spec_of_value(mix(&self.source, &self.target, eps, ""))
    }

    /// True when the source and target have the same numbers everywhere (the morph is the
    /// source at every `ε`: [`mix`] keeps a number both sides share).
    pub fn is_constant(&self) -> bool {
        mix(&self.source, &self.target, 0.0, "") == mix(&self.source, &self.target, 1.0, "")
    }
}

fn join(place: &str, key: &str) -> String {
    if place.is_empty() {
        spec::key_path(key)
    } else {
        format!("{place}.{}", spec::key_path(key))
    }
}

fn kind(v: &toml::Value) -> &'static str {
    match v {
        toml::Value::String(_) => "a string",
        toml::Value::Integer(_) | toml::Value::Float(_) => "a number",
        toml::Value::Boolean(_) => "a boolean",
        toml::Value::Datetime(_) => "a date",
        toml::Value::Array(_) => "an array",
        toml::Value::Table(_) => "a table",
    }
}

fn differ(place: &str, what: String) -> Error {
    Error::invalid(format!(
        "the source and the target of a morph must have the same structure: {what}"
    ))
    .at(place)
}

fn same_structure(s: &toml::Value, t: &toml::Value, place: &str, key: &str) -> Result<()> {
    use toml::Value::*;
    match (s, t) {
        (Table(a), Table(b)) => {
            for (k, v) in a {
                if place.is_empty() && OWN.contains(&k.as_str()) {
                    continue;
                }
                match b.get(k) {
                    Some(w) => same_structure(v, w, &join(place, k), k)?,
                    None => {
                        return Err(differ(
                            &join(place, k),
                            "the target has no such key".to_string(),
                        ))
                    }
                }
            }
            if let Some(k) = b
                .keys()
                .find(|k| !(a.contains_key(*k) || place.is_empty() && OWN.contains(&k.as_str())))
            {
                let at = if place.is_empty() { "" } else { place };
                return Err(differ(
                    at,
                    format!("the target has '{k}' here and the source has not"),
                ));
            }
            Ok(())
        }
        (Array(a), Array(b)) => {
            if a.len() != b.len() {
                return Err(differ(
                    place,
                    format!(
                        "{} entries in the source, {} in the target",
                        a.len(),
                        b.len()
                    ),
                ));
            }
            for (i, (v, w)) in a.iter().zip(b).enumerate() {
                same_structure(v, w, &format!("{place}[{i}]"), key)?;
            }
            Ok(())
        }
        (String(a), String(b)) if a != b => Err(differ(
            place,
            format!("'{a}' in the source, '{b}' in the target"),
        )),
        (Integer(a), Integer(b)) if a != b && STRUCTURAL.contains(&key) => Err(differ(
            place,
            format!("{a} in the source, {b} in the target (a count or an order)"),
        )),
        (Boolean(a), Boolean(b)) if a != b => Err(differ(
            place,
            format!("{a} in the source, {b} in the target"),
        )),
        (Integer(_) | Float(_), Integer(_) | Float(_))
        | (String(_), String(_))
        | (Boolean(_), Boolean(_))
        | (Datetime(_), Datetime(_)) => Ok(()),
        _ => Err(differ(
            place,
            format!("{} in the source, {} in the target", kind(s), kind(t)),
        )),
    }
}

fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(x) => Some(*x),
        _ => None,
    }
}

/// `(1 − ε) s + ε t` leaf by leaf (the structures agree; checked by [`same_structure`]).
fn mix(s: &toml::Value, t: &toml::Value, eps: f64, place: &str) -> toml::Value {
    use toml::Value::*;
    match (s, t) {
        (Table(a), Table(b)) => Table(
            a.iter()
                .map(|(k, v)| {
                    let m = match b.get(k) {
                        Some(w) if !(place.is_empty() && OWN.contains(&k.as_str())) => {
                            mix(v, w, eps, &join(place, k))
                        }
                        _ => v.clone(),
                    };
                    (k.clone(), m)
                })
                .collect(),
        ),
        (Array(a), Array(b)) => Array(
            a.iter()
                .zip(b)
                .enumerate()
                .map(|(i, (v, w))| mix(v, w, eps, &format!("{place}[{i}]")))
                .collect(),
        ),
        (Integer(a), Integer(b)) if a == b => Integer(*a),
        _ => match (number(s), number(t)) {
            (Some(x), Some(y)) => {
                if x == y || eps == 0.0 {
                    s.clone()
                } else if eps == 1.0 {
                    t.clone()
                } else {
                    Float((1.0 - eps) * x + eps * y)
                }
            }
            _ => s.clone(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schedule_runs_from_zero_to_one_for_every_ease() {
        for g in [0.3, 1.0, 2.0, 5.0] {
            assert_eq!(ease(0.0, g), 0.0);
            assert_eq!(ease(1.0, g), 1.0);
            let mut last = 0.0;
            for i in 1..=10 {
                let e = ease(i as f64 / 10.0, g);
                assert!(e > last, "monotone");
                last = e;
            }
        }
        assert_eq!(ease(0.5, 1.0), 0.5);
        assert_eq!(ease(0.5, 2.0), 0.25);
        // Eq. 6.4 as printed, γ^i/m with γ = 1: the constant 1/m, never 1.
        let m = 10;
        let printed: Vec<f64> = (1..=m).map(|i| 1f64.powi(i) / m as f64).collect();
        assert!(printed.iter().all(|&e| e == 0.1));
    }

    fn circles(r: f64, extra: &str) -> String {
        format!(
            "[curves.a]\ntype = \"circle\"\ncenter = [0, 0, 0]\nradius = {r}\n{extra}\
             [curves.b]\ntype = \"circle\"\ncenter = [0.0, 0.0, 2.0]\nradius = 1.0\n\
             [operator]\nkind = \"polyharmonic\"\norder = 2\na = {r}\n"
        )
    }

    #[test]
    fn numbers_are_interpolated_and_the_ends_are_exact() {
        let m = Morph::new(&circles(1.0, ""), &circles(3.0, "")).unwrap();
        let radius = |d: &DesignSpec| match &d.curves["a"].kind {
            crate::spec::CurveKind::Circle { radius, .. } => *radius,
            _ => unreachable!(),
        };
        assert_eq!(radius(&m.at(0.0).unwrap()), 1.0);
        assert_eq!(radius(&m.at(0.25).unwrap()), 1.5);
        assert_eq!(radius(&m.at(1.0).unwrap()), 3.0);
        assert_eq!(
            m.at(0.0).unwrap(),
            spec::parse_design(&circles(1.0, "")).unwrap()
        );
        assert_eq!(
            m.at(1.0).unwrap(),
            spec::parse_design(&circles(3.0, "")).unwrap()
        );
        match m.at(0.5).unwrap().operator {
            Some(crate::spec::OperatorSpec::Polyharmonic { a, .. }) => assert_eq!(a, 2.0),
            o => panic!("{o:?}"),
        }
    }

    #[test]
    fn different_structures_are_refused_with_their_place() {
        let e = Morph::new(&circles(1.0, ""), &circles(1.0, "normal = [0, 1, 0]\n")).unwrap_err();
        assert_eq!(e.place(), "curves.a");
        assert!(e.to_string().contains("same structure"), "{e}");
        let t = circles(1.0, "").replace("order = 2", "order = 3");
        let e = Morph::new(&circles(1.0, ""), &t).unwrap_err();
        assert_eq!(e.place(), "operator.order");
        let t = circles(1.0, "").replace(
            "type = \"circle\"\ncenter = [0.0",
            "type = \"point\"\nat = [0.0",
        );
        let t = t.replacen("radius = 1.0\n", "", 1);
        let e = Morph::new(&circles(1.0, ""), &t).unwrap_err();
        assert!(e.place().starts_with("curves.b"), "{e}");
    }
}
