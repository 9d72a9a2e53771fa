//! The design file (TOML): its types (serde and JSON schema), parsing with error paths, and
//! error locations. A leaf: it imports no solver; [`crate::design`] compiles what it parses.
//!
//! ```text
//! text ──parse_design──▶ DesignSpec ──design::compile──▶ a solved design
//!      ◀──write_design──
//! ```
//!
//! Every error names its place as a path into the file (`curves.rim.radius`,
//! `conditions[2].curve`, `patches[1].operator.a`); [`locate`] turns such a path into a line and
//! column, and [`describe_error`] formats `file:line:col: path: message`.

mod blend;
mod disk;
mod dynamic;
pub mod limits;
mod locate;
mod network;
mod nsided;
mod nurbs;
mod optimize;
mod parametric;
mod params;
mod patchwork;
pub mod rig;
pub(crate) mod schema;
mod shell;
mod spine;
mod spline;
pub mod suggest;
pub mod time;
mod trim;
mod types;
pub mod words;
mod write;

pub use blend::{BlendSpec, EnergySpec, JoinSpec, PointSpec, SurfaceSpec};
pub use disk::DiskSpec;
pub use dynamic::{ComponentSpec, DynamicSpec, FormulaText, ParamsSpec};
pub use locate::{describe_error, key_path, locate};
pub use network::{NetworkCurveSpec, NetworkSpec};
pub use nsided::{LoopSideSpec, NSidedSpec};
pub use nurbs::NurbsSpec;
pub use optimize::{ConstraintSpec, OptimizeSpec, ParameterSpec};
pub use parametric::ParametricSpec;
pub use params::{AxisName, AxisSpec, DesignParameterSpec, DriveKind, PlaneSpec};
pub use patchwork::{PatchworkEdgeSpec, PatchworkSpec};
pub use shell::{EdgeSpec, LineLoadSpec, MaterialSpec, ShellSpec, SideSpec};
pub use spine::{
    SpineCarry, SpineHermite, SpineMove, SpineSpec, SpineWave, WaveKind, MAX_WAVE_TERMS,
};
pub use spline::{FixSpec, FixedPointSpec, SplineOperatorSpec, SplineSpec};
pub use trim::{TrimCurveSpec, TrimMethodSpec, TrimSpec};
pub use types::{
    ConditionSpec, CurveKind, CurveRef, CurveSpec, DesignSpec, DomainSpec, OperatorSpec,
    OutputSpec, ParamSpec, PatchSpec, SolverMethod, SolverSpec, TransformStep, Units, V3,
};
pub use words::plain as plain_message;
pub use write::write_design;

use crate::{Error, Result};

/// Parses a design file: TOML syntax and the schema (unknown keys, wrong types, missing keys).
/// The error's place is the path of the offending key (`curves.rim` for an unknown key inside the
/// `rim` table); NaN and infinite numbers are refused here with their exact path.
pub fn parse_design(text: &str) -> Result<DesignSpec> {
    limits::check_text(text)?;
    // Syntax first, so that a syntax error is reported as such and not as a schema mismatch.
    let doc: toml::Table =
        toml::from_str(text).map_err(|e| Error::invalid(one_line(e.message())))?;
    let doc = toml::Value::Table(doc);
    limits::check_value(&doc, "", 0)?;
    locate::check_finite(&doc, "")?;
    let de = toml::Deserializer::new(text);
    let spec = serde_path_to_error::deserialize::<_, DesignSpec>(de).map_err(|e| located(e, ""))?;
    // (A spec that does not write back as TOML has nothing to compare.)
    if let Ok(read) = toml::Value::try_from(&spec) {
        locate::check_lengths(&doc, &read, "")?;
    }
    limits::check_spec(&spec)?;
    Ok(spec)
}

/// Reads a `T` from a TOML tree found at `outer` (empty for the whole file), with the path of
/// any error inside it.
pub(crate) fn deserialize_at<T: serde::de::DeserializeOwned>(
    value: toml::Value,
    outer: &str,
) -> Result<T> {
    serde_path_to_error::deserialize::<_, T>(value).map_err(|e| located(e, outer))
}

/// An error of the deserializer with its place: the path serde tracked, under `outer`, joined
/// with the path a curve table's message carries.
fn located(e: serde_path_to_error::Error<toml::de::Error>, outer: &str) -> Error {
    let path = e.path().to_string();
    let path = if path == "." { String::new() } else { path };
    let path = match (outer.is_empty(), path.is_empty()) {
        (true, _) => path,
        (false, true) => outer.to_string(),
        (false, false) if path.starts_with('[') => format!("{outer}{path}"),
        (false, false) => format!("{outer}.{path}"),
    };
    let message = e.inner().message();
    match types::split_path_marker(message) {
        (Some(inner), rest) => {
            let place = if path.is_empty() {
                inner.to_string()
            } else if inner.starts_with('[') {
                format!("{path}{inner}")
            } else {
                format!("{path}.{inner}")
            };
            Error::invalid(suggest::with_suggestion(&one_line(rest))).at(&place)
        }
        (None, rest) => Error::invalid(suggest::with_suggestion(&one_line(rest))).at(&path),
    }
}

/// The JSON schema of the design file (pretty-printed).
pub fn json_schema() -> String {
    serde_json::to_string_pretty(&schema::schema_value())
        .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}

/// The JSON schema of a morph file (`[time]`, `[morph]`, `title`, `[output]`; pretty-printed).
pub fn morph_json_schema() -> String {
    serde_json::to_string_pretty(&schema::morph_schema_value())
        .unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
}

/// Joins the lines of a multi-line message.
fn one_line(s: &str) -> String {
    words::plain(
        &s.split('\n')
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect::<Vec<_>>()
            .join("; "),
    )
}
