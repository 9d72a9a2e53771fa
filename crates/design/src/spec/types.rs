//! The serde types of the design file. Every table refuses unknown keys; `pdeshape schema` prints
//! the JSON schema derived from these types. The meaning of every key is documented in
//! `docs/design-file.md`.

use schemars::JsonSchema;
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::ser::Serializer;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

use super::write::{
    is_default_solver, is_false, is_z_axis, is_zero, is_zero3, is_zero_usize, never,
    serialize_kind_option, serialize_solver, Tagged,
};

/// A point or vector `[x, y, z]`.
pub type V3 = [f64; 3];

/// A whole design file. `DesignSpec::default()` is the empty design (no curves, no surfaces).
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DesignSpec {
    /// A name for the design (shown by `pdeshape check`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub title: Option<String>,
    /// The length unit of the design's coordinates: `mm` (the default), `cm`, `m` or `in`.
    /// Mesh files state it (glTF, which is in metres, is converted; OBJ, STL and PLY carry it
    /// in a comment or header).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<Units>,
    /// The elliptic operator of every patch that does not override it (default: polyharmonic,
    /// order 2, a = 1).
    #[serde(
        default,
        deserialize_with = "deserialize_operator",
        serialize_with = "serialize_kind_option",
        skip_serializing_if = "Option::is_none"
    )]
    pub operator: Option<OperatorSpec>,
    /// Options of the solver: a table, or just the method's name (`solver = "fd"`).
    #[serde(
        default,
        deserialize_with = "deserialize_solver",
        serialize_with = "serialize_solver",
        skip_serializing_if = "is_default_solver"
    )]
    #[schemars(with = "SolverForm")]
    pub solver: SolverSpec,
    /// Named curves, referenced by name from conditions and from other curves.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub curves: BTreeMap<String, CurveSpec>,
    /// The conditions of a single-patch design (exclusive with `patches`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub conditions: Option<Vec<ConditionSpec>>,
    /// The patches of a multi-patch design (exclusive with `conditions`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patches: Option<Vec<PatchSpec>>,
    /// Surfaces given by formulas in `u` and `v` (`[[parametric]]`), alongside or instead of
    /// the PDE patches.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub parametric: Vec<super::parametric::ParametricSpec>,
    /// Reference surfaces given as (rational) B-spline nets (`[[nurbs]]`): neighbours of
    /// `[[nsided]]` and `[[network]]` sides, not output.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub nurbs: Vec<super::nurbs::NurbsSpec>,
    /// Patches bounded by a loop of 3 to 8 curves (`[[nsided]]`), G1 on any side to another
    /// surface of the design.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub nsided: Vec<super::nsided::NSidedSpec>,
    /// Networks of curves that cross (`[[network]]`): every face they enclose is an n-sided
    /// patch, G1 across the inner curves.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub network: Vec<super::network::NetworkSpec>,
    /// Patch layouts given corner by corner (`[[patchwork]]`, what `pdeshape fit` writes for a
    /// general mesh): every face an n-sided patch, G1 across the edges the faces share.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub patchwork: Vec<super::patchwork::PatchworkSpec>,
    /// Polyharmonic patches on the unit disk through a loop of samples (`[[disk]]`: the
    /// patches `pdeshape fill --design` writes).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub disk: Vec<super::disk::DiskSpec>,
    /// Defaults for the command-line tool.
    #[serde(default, skip_serializing_if = "OutputSpec::is_default")]
    pub output: OutputSpec,
    /// A dynamic PDE curve (`pdeshape curve`); see `docs/design-file.md`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dynamic: Option<super::dynamic::DynamicSpec>,
    /// Design parameters, objective and search options of `pdeshape optimize` (§7.3–7.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub optimize: Option<super::optimize::OptimizeSpec>,
    /// A blending surface between two primary surfaces (`pdeshape blend`; see
    /// [`super::blend`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blend: Option<super::blend::BlendSpec>,
    /// A B-spline or Bézier surface solving a linear PDE from fixed control points (read by
    /// `pdeshape spline`; such a design needs no conditions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spline: Option<super::spline::SplineSpec>,
    /// Edits of the spines of PDE patches (`[[spine]]`, §5.3), at most one per patch.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub spine: Vec<super::spine::SpineSpec>,
    /// Holes cut out of surfaces by closed curves in their `(u, v)` planes (§5.2).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub trims: Vec<super::trim::TrimSpec>,
    /// Named, bounded design parameters (`[[parameters]]`, §6.1, §6.4, §7.5): what each drives
    /// (a curve's point, angle, size, `v = 0` point, …), its bounds and its value.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub parameters: Vec<super::params::DesignParameterSpec>,
    /// The design's time interval and frames (`pdeshape animate`); any number of the file may
    /// then be a formula in `t` (see [`super::time`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<super::time::TimeSpec>,
    /// Curves along which shared edges of patches are meant to be creases (a lid on a cup's
    /// rim): `check` reports their angle but does not count them against the verdict.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub creases: Vec<String>,
    /// The thin-shell strength analysis of `pdeshape shell` (thickness, material, elements,
    /// clamped edges, loads; SI units); without it, the book's set-up of §7.5.1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shell: Option<super::shell::ShellSpec>,
}

/// A length unit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
pub enum Units {
    /// Millimetres (the default).
    #[default]
    #[serde(rename = "mm")]
    Millimetre,
    /// Centimetres.
    #[serde(rename = "cm")]
    Centimetre,
    /// Metres.
    #[serde(rename = "m")]
    Metre,
    /// Inches (25.4 mm).
    #[serde(rename = "in")]
    Inch,
}

/// The IGES Global section's unit of a design's `units`.
impl From<Units> for crate::splinepde::export::IgesUnit {
    fn from(units: Units) -> Self {
        use crate::splinepde::export::IgesUnit;
        match units {
            Units::Millimetre => IgesUnit::MILLIMETRE,
            Units::Centimetre => IgesUnit::CENTIMETRE,
            Units::Metre => IgesUnit::METRE,
            Units::Inch => IgesUnit::INCH,
        }
    }
}

impl Units {
    /// Metres per unit.
    pub fn metres(self) -> f64 {
        match self {
            Units::Millimetre => 1e-3,
            Units::Centimetre => 1e-2,
            Units::Metre => 1.0,
            Units::Inch => 0.0254,
        }
    }

    /// The unit's symbol as the design file writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            Units::Millimetre => "mm",
            Units::Centimetre => "cm",
            Units::Metre => "m",
            Units::Inch => "in",
        }
    }

    /// Millimetres per unit.
    pub fn millimetres(self) -> f64 {
        match self {
            Units::Millimetre => 1.0,
            Units::Centimetre => 10.0,
            Units::Metre => 1000.0,
            Units::Inch => 25.4,
        }
    }

    /// Parses `mm`, `cm`, `m` or `in` (also spelt out: `millimetre`, `meter`, `inch`, …; any
    /// case, spaces around ignored).
    pub fn parse(s: &str) -> crate::Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "mm" | "millimetre" | "millimeter" => Ok(Units::Millimetre),
            "cm" | "centimetre" | "centimeter" => Ok(Units::Centimetre),
            "m" | "metre" | "meter" => Ok(Units::Metre),
            "in" | "inch" => Ok(Units::Inch),
            other => Err(crate::Error::invalid(format!(
                "unknown length unit `{other}` (mm, cm, m or in)"
            ))),
        }
    }
}

impl std::str::FromStr for Units {
    type Err = crate::Error;

    fn from_str(s: &str) -> crate::Result<Self> {
        Units::parse(s)
    }
}

impl std::fmt::Display for Units {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The operator `Σ c_k ∂u^{2N−2k} ∂v^{2k}` of order `2N`.
// Serde reads and writes the externally tagged `{ polyharmonic = { … } }`; the file's
// `{ kind = "polyharmonic", … }` is read by `deserialize_tagged` and written by `write::Tagged`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(tag = "kind")]
pub enum OperatorSpec {
    /// `(∂²/∂u² + a² ∂²/∂v²)^N` (book Eqs. 4.1, 4.10, 4.35).
    #[serde(rename = "polyharmonic")]
    Polyharmonic {
        /// `N`, 1 to 20: the PDE has order `2N` and takes `2N` conditions (default 2).
        #[serde(default = "default_order")]
        order: usize,
        /// The smoothing parameter `a > 0` (default 1).
        #[serde(default = "default_a")]
        a: f64,
    },
    /// `a ∂u⁶ + b ∂u⁴∂v² + c ∂u²∂v⁴ + d ∂v⁶` (Eq. 4.54); here `a` is a coefficient, not the
    /// smoothing parameter.
    #[serde(rename = "sixth-order")]
    SixthOrder {
        /// Coefficient of ∂u⁶.
        a: f64,
        /// Coefficient of ∂u⁴∂v².
        b: f64,
        /// Coefficient of ∂u²∂v⁴.
        c: f64,
        /// Coefficient of ∂v⁶.
        d: f64,
    },
    /// `Σ_{k=0}^{N} c_k ∂u^{2N−2k} ∂v^{2k}` from `coefficients = [c_0, …, c_N]`; must be elliptic.
    #[serde(rename = "general")]
    General {
        /// [c_0, …, c_N]: c_k multiplies ∂u^(2N−2k) ∂v^(2k).
        coefficients: Vec<f64>,
    },
}

fn default_order() -> usize {
    2
}
fn default_a() -> f64 {
    1.0
}

impl Default for OperatorSpec {
    fn default() -> Self {
        OperatorSpec::Polyharmonic { order: 2, a: 1.0 }
    }
}

/// Solver options.
// Written without the keys that hold their defaults.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Fourier modes solved analytically, 1 to 256 (default 12).
    #[serde(default = "default_modes", skip_serializing_if = "is_default_modes")]
    #[schemars(skip_serializing_if = "never")]
    pub modes: usize,
    /// Add the spectral remainder (Eqs. 4.45–4.53) so that curves which are not finite Fourier
    /// series are met exactly (default true).
    #[serde(
        default = "default_true",
        skip_serializing_if = "super::write::is_true"
    )]
    #[schemars(skip_serializing_if = "never")]
    pub remainder: bool,
    /// Samples per curve for the FFT; 0 chooses automatically, otherwise at least `2·modes + 1`.
    #[serde(default, skip_serializing_if = "is_zero_usize")]
    #[schemars(skip_serializing_if = "never")]
    pub samples: usize,
    /// `"analytic"` (default): the Fourier-mode solution; `"fd"`: finite differences on a
    /// `(u, v)` grid (polyharmonic operators with N ≤ 3, conditions at u = 0 and 1 only).
    #[serde(default, skip_serializing_if = "SolverMethod::is_analytic")]
    pub method: SolverMethod,
    /// The finite-difference grid `[nu, nv]`: intervals in u and nodes around v (default
    /// `[64, 128]`); only with `method = "fd"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<[usize; 2]>,
}

/// How a design's patches are solved.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum SolverMethod {
    /// The analytic Fourier-mode solution with the spectral remainder.
    #[default]
    Analytic,
    /// Finite differences on a `(u, v)` grid.
    Fd,
}

impl SolverMethod {
    fn is_analytic(&self) -> bool {
        *self == SolverMethod::Analytic
    }
}

/// The two forms of `solver` (for the schema): a method's name or the table.
#[derive(JsonSchema)]
#[serde(untagged)]
#[allow(dead_code)]
enum SolverForm {
    /// `solver = "fd"` or `solver = "analytic"`: that method with default options.
    Method(SolverMethod),
    /// The `[solver]` table.
    Table(SolverSpec),
}

fn deserialize_solver<'de, D: Deserializer<'de>>(d: D) -> Result<SolverSpec, D::Error> {
    struct V;
    impl<'de> Visitor<'de> for V {
        type Value = SolverSpec;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("\"analytic\", \"fd\" or a [solver] table")
        }
        fn visit_str<E: de::Error>(self, s: &str) -> Result<SolverSpec, E> {
            let method = SolverMethod::deserialize(de::value::StrDeserializer::<E>::new(s))?;
            Ok(SolverSpec {
                method,
                ..SolverSpec::default()
            })
        }
        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<SolverSpec, A::Error> {
            SolverSpec::deserialize(de::value::MapAccessDeserializer::new(map))
        }
    }
    d.deserialize_any(V)
}

fn default_modes() -> usize {
    12
}
fn is_default_modes(n: &usize) -> bool {
    *n == default_modes()
}
fn default_true() -> bool {
    true
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            modes: 12,
            remainder: true,
            samples: 0,
            method: SolverMethod::Analytic,
            grid: None,
        }
    }
}

/// Defaults for the command-line tool.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Grid rows (values of u), default 64.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nu: Option<usize>,
    /// Grid columns (values of v), default 128.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nv: Option<usize>,
}

impl OutputSpec {
    fn is_default(&self) -> bool {
        *self == OutputSpec::default()
    }
}

/// One patch of a multi-patch design.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PatchSpec {
    /// Unique name of the patch.
    pub name: String,
    /// Overrides the design's operator for this patch.
    #[serde(
        default,
        deserialize_with = "deserialize_operator",
        serialize_with = "serialize_kind_option",
        skip_serializing_if = "Option::is_none"
    )]
    pub operator: Option<OperatorSpec>,
    /// The patch's conditions (`2N` of them).
    pub conditions: Vec<ConditionSpec>,
}

/// `∂ᵈX/∂uᵈ (u, v) = curve(v)` for all v.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConditionSpec {
    /// Where the condition holds, `0 ≤ u ≤ 1`.
    pub u: f64,
    /// 0 (default) for a position curve, `d` for the `d`-th u-derivative (`d < 2N`).
    #[serde(default, skip_serializing_if = "is_zero_usize")]
    #[schemars(skip_serializing_if = "never")]
    pub derivative: usize,
    /// The curve: the name of a curve in `[curves]`, or an inline curve table.
    pub curve: CurveRef,
}

/// A curve given by name or inline.
// Written as the name's string or as the curve's table.
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum CurveRef {
    /// The name of a curve in `[curves]`.
    Name(String),
    /// An inline curve table.
    Inline(Box<CurveSpec>),
}

impl<'de> Deserialize<'de> for CurveRef {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = CurveRef;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a curve name or an inline curve table")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<CurveRef, E> {
                Ok(CurveRef::Name(s.to_string()))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<CurveRef, A::Error> {
                CurveSpec::deserialize(de::value::MapAccessDeserializer::new(map))
                    .map(|c| CurveRef::Inline(Box::new(c)))
            }
        }
        d.deserialize_any(V)
    }
}

/// A curve: its kind and the modifiers every kind accepts.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveSpec {
    /// What the curve is and its own keys, chosen by the file's `type` key (written flat into
    /// the curve's table, beside the modifiers below).
    pub kind: CurveKind,
    /// Affine maps applied in order (§6.1).
    pub transform: Vec<TransformStep>,
    /// `C̃(v) = C(v + v_origin)`, radians (§6.4); periodic curves only.
    pub v_origin: f64,
    /// Reparametrise by arc length (§5.1).
    pub arc_length: bool,
}

const COMMON_KEYS: [&str; 3] = ["transform", "v_origin", "arc_length"];

/// Marks the path of an error found inside a curve table: custom serde errors cannot extend the
/// path that `serde_path_to_error` tracks outside, so the inner path travels in the message and
/// [`split_path_marker`] moves it back into the error's place.
const PATH_MARK: char = '\u{1}';

fn with_path(inner: &str, message: &str) -> String {
    if inner.is_empty() {
        return message.to_string();
    }
    // A nested curve's message may carry a path already: join the two.
    match split_path_marker(message) {
        (Some(deeper), rest) => {
            let sep = if deeper.starts_with('[') { "" } else { "." };
            format!("{PATH_MARK}{inner}{sep}{deeper}{PATH_MARK}{rest}")
        }
        (None, rest) => format!("{PATH_MARK}{inner}{PATH_MARK}{rest}"),
    }
}

/// `(inner path, message)` of a message made by [`with_path`].
pub(crate) fn split_path_marker(message: &str) -> (Option<&str>, &str) {
    if let Some(rest) = message.strip_prefix(PATH_MARK) {
        if let Some((path, msg)) = rest.split_once(PATH_MARK) {
            return (Some(path), msg);
        }
    }
    (None, message)
}

/// Reads a table whose variant is chosen by the key `tag` (`type`, `kind`) as the externally
/// tagged `{ <variant> = { … } }`, so that errors inside the table keep their path (serde's
/// internally tagged enums buffer the table and lose it). `hint` is appended to "unknown field"
/// messages.
pub(crate) fn deserialize_tagged<T: serde::de::DeserializeOwned, E: de::Error>(
    mut table: toml::Table,
    tag: &str,
    hint: &str,
) -> Result<T, E> {
    let variant = match table.remove(tag) {
        Some(toml::Value::String(t)) => t,
        Some(other) => {
            return Err(E::custom(with_path(
                tag,
                &format!("expected a string, found {}", other.type_str()),
            )))
        }
        None => return Err(E::custom(format!("missing field `{tag}`"))),
    };
    let mut wrapped = toml::Table::new();
    wrapped.insert(variant, toml::Value::Table(table));
    serde_path_to_error::deserialize::<_, T>(toml::Value::Table(wrapped)).map_err(|e| {
        let path = e.path().to_string();
        // Drop the variant name (first segment) from the path.
        let inner = match path.find(['.', '[']) {
            Some(i) if path.as_bytes()[i] == b'.' => path[i + 1..].to_string(),
            Some(i) => path[i..].to_string(),
            None => String::new(),
        };
        let m = e.inner().message().to_string();
        let inner = if inner.is_empty() && m.starts_with("unknown variant") {
            tag.to_string()
        } else {
            inner
        };
        let m = if m.starts_with("unknown field") && !hint.is_empty() {
            format!("{m} {hint}")
        } else {
            m
        };
        E::custom(with_path(&inner, &m))
    })
}

fn deserialize_operator<'de, D: Deserializer<'de>>(d: D) -> Result<Option<OperatorSpec>, D::Error> {
    let table = toml::Table::deserialize(d)?;
    deserialize_tagged(table, "kind", "").map(Some)
}

impl<'de> Deserialize<'de> for CurveSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut table = toml::Table::deserialize(d)?;
        let take = |t: &mut toml::Table, k: &str| t.remove(k);
        let transform = match take(&mut table, "transform") {
            Some(v) => {
                serde_path_to_error::deserialize::<_, Vec<TransformStep>>(v).map_err(|e| {
                    let path = e.path().to_string();
                    let inner = if path == "." || path.is_empty() {
                        "transform".to_string()
                    } else if path.starts_with('[') {
                        format!("transform{path}")
                    } else {
                        format!("transform.{path}")
                    };
                    de::Error::custom(with_path(&inner, e.inner().message()))
                })?
            }
            None => Vec::new(),
        };
        let v_origin = match take(&mut table, "v_origin") {
            Some(v) => f64::deserialize(v)
                .map_err(|e| de::Error::custom(format!("v_origin: {}", e.message())))?,
            None => 0.0,
        };
        let arc_length = match take(&mut table, "arc_length") {
            Some(v) => bool::deserialize(v)
                .map_err(|e| de::Error::custom(format!("arc_length: {}", e.message())))?,
            None => false,
        };
        // `type` picks the variant; errors inside the table keep their path.
        let hint = format!("(or one of {})", COMMON_KEYS.join(", "));
        let kind: CurveKind = deserialize_tagged(table, "type", &hint)?;
        Ok(CurveSpec {
            kind,
            transform,
            v_origin,
            arc_length,
        })
    }
}

/// The file's form: `type` and the kind's keys, then the modifiers that differ from their
/// defaults (no transform, `v_origin = 0`, `arc_length = false`).
impl Serialize for CurveSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Flat<'a> {
            #[serde(flatten)]
            kind: Tagged<'a, CurveKind>,
            #[serde(skip_serializing_if = "<[TransformStep]>::is_empty")]
            transform: &'a [TransformStep],
            #[serde(skip_serializing_if = "is_zero")]
            v_origin: f64,
            #[serde(skip_serializing_if = "is_false")]
            arc_length: bool,
        }
        Flat {
            kind: Tagged {
                tag: "type",
                value: &self.kind,
            },
            transform: &self.transform,
            v_origin: self.v_origin,
            arc_length: self.arc_length,
        }
        .serialize(s)
    }
}

impl JsonSchema for CurveSpec {
    fn schema_name() -> String {
        "CurveSpec".to_string()
    }
    fn json_schema(gen: &mut schemars::gen::SchemaGenerator) -> schemars::schema::Schema {
        // The schema of the kind (one object per `type`), with the common modifiers added to
        // every variant's properties.
        let kind = CurveKind::json_schema(gen);
        let transform = gen.subschema_for::<Vec<TransformStep>>();
        let mut value = serde_json::to_value(&kind).unwrap_or_default();
        let common = serde_json::json!({
            "transform": {
                "description": "Affine maps applied in order after the curve is built (§6.1).",
                "allOf": [serde_json::to_value(&transform).unwrap_or_default()]
            },
            "v_origin": {
                "description": "Shift of the v = 0 point in radians (§6.4): C'(v) = C(v + v_origin).",
                "type": "number", "default": 0.0
            },
            "arc_length": {
                "description": "Reparametrise by arc length (§5.1).",
                "type": "boolean", "default": false
            }
        });
        if let Some(variants) = value.get_mut("oneOf").and_then(|v| v.as_array_mut()) {
            for variant in variants {
                if let Some(props) = variant
                    .get_mut("properties")
                    .and_then(|p| p.as_object_mut())
                {
                    for (k, v) in common.as_object().into_iter().flatten() {
                        props.insert(k.clone(), v.clone());
                    }
                }
            }
        }
        serde_json::from_value(value).unwrap_or(kind)
    }
}

/// The curve kinds, chosen by `type`. (Serde reads the externally tagged form that
/// `CurveSpec`'s deserializer builds from `type`; the schema shows the file's form.)
// `CurveSpec`'s serializer flattens the externally tagged form back into `type = "…"`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(tag = "type")]
pub enum CurveKind {
    /// `center + r (cos v e₁ + sin v e₂)` in the plane normal to `normal`; v = 0 lies along the
    /// projection of +x on that plane (+y if the normal is along x).
    #[serde(rename = "circle")]
    Circle {
        /// Centre of the circle [x, y, z].
        center: V3,
        /// Radius (> 0).
        radius: f64,
        /// Normal of the circle's plane (default [0, 0, 1]); v runs counter-clockwise about it.
        #[serde(default = "default_normal", skip_serializing_if = "is_z_axis")]
        #[schemars(skip_serializing_if = "never")]
        normal: V3,
    },
    /// Either `center + cos v · axis1 + sin v · axis2`, or semi-axes `rx` (along the circle's
    /// start direction) and `ry` in the plane normal to `normal`.
    #[serde(rename = "ellipse")]
    Ellipse {
        /// Centre of the ellipse [x, y, z].
        center: V3,
        /// The point at v = 0 minus the centre (with axis2; instead of rx, ry).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        axis1: Option<V3>,
        /// The point at v = π/2 minus the centre (with axis1).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        axis2: Option<V3>,
        /// Semi-axis along the start direction (> 0; with ry).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rx: Option<f64>,
        /// Semi-axis perpendicular to it in the plane (> 0; with rx).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ry: Option<f64>,
        /// Normal of the plane of rx, ry (default [0, 0, 1]).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        normal: Option<V3>,
    },
    /// A constant curve (closes the surface to a pole).
    #[serde(rename = "point")]
    Point {
        /// The point [x, y, z] the whole curve sits on (a pole).
        at: V3,
    },
    /// A B-spline, rational (NURBS) when it has `weights`. Periodic (default): `knots` are the
    /// `control.len() + 1` increasing breakpoints (mapped onto [0, 2π]); open: the full clamped
    /// knot vector.
    #[serde(rename = "bspline")]
    BSpline {
        /// Polynomial degree (1 to 30).
        degree: usize,
        /// Control points [x, y, z].
        control: Vec<V3>,
        /// Periodic: the control.len() + 1 increasing breakpoints (default uniform); open: the
        /// full clamped knot vector.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        knots: Option<Vec<f64>>,
        /// Closed periodic curve over [0, 2π] (default true) or an open clamped one.
        #[serde(default = "default_true")]
        periodic: bool,
        /// One positive weight per control point: a rational B-spline (NURBS), as CAD systems
        /// write circles and conics (default: none, a polynomial B-spline).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        weights: Option<Vec<f64>>,
    },
    /// A Bézier curve on [0, 1] (open: for drawing, not as a condition).
    #[serde(rename = "bezier")]
    Bezier {
        /// Control points [x, y, z] (degree = count − 1).
        control: Vec<V3>,
    },
    /// A cubic Hermite curve on [0, 1] (Eq. 5.4; open).
    #[serde(rename = "hermite")]
    Hermite {
        /// Position at the start.
        p0: V3,
        /// Position at the end.
        p1: V3,
        /// Derivative at the start.
        d0: V3,
        /// Derivative at the end.
        d1: V3,
    },
    /// `a0 + Σ_{n=1}^{M} [cos[n−1] cos nv + sin[n−1] sin nv]`.
    #[serde(rename = "fourier")]
    Fourier {
        /// The constant term [x, y, z].
        a0: V3,
        /// Coefficients of cos v, cos 2v, … (one [x, y, z] each).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        #[schemars(skip_serializing_if = "never")]
        cos: Vec<V3>,
        /// Coefficients of sin v, sin 2v, … (one [x, y, z] each).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        #[schemars(skip_serializing_if = "never")]
        sin: Vec<V3>,
    },
    /// Closed point samples interpolated by a periodic cubic spline.
    #[serde(rename = "samples")]
    Samples {
        /// The closed sequence of points [x, y, z] (the last is not repeated).
        points: Vec<V3>,
        /// How the samples are spread over [0, 2π]: uniform, chord (default) or centripetal.
        #[serde(default)]
        param: ParamSpec,
    },
    /// Three formulas in `v`, e.g. `x = "2*cos(v)"`.
    #[serde(rename = "formula")]
    Formula {
        /// x as a formula in v.
        x: String,
        /// y as a formula in v.
        y: String,
        /// z as a formula in v.
        z: String,
        /// The range of v: periodic over [0, 2π] (default) or an interval.
        #[serde(default, skip_serializing_if = "DomainSpec::is_periodic")]
        domain: DomainSpec,
    },
    /// The book's derivative curve (Eq. 5.2, sign chosen so it points where the surface heads):
    /// `X_u = scale · (direction − position)`.
    #[serde(rename = "derivative")]
    Derivative {
        /// The position curve (name or inline table).
        position: CurveRef,
        /// The direction curve (name or inline table).
        direction: CurveRef,
        /// The factor s of X_u = s (direction − position).
        #[serde(default = "default_a")]
        scale: f64,
    },
    /// A local edit of another curve (§6.2): `curve` unchanged outside `from < v < to` (on a
    /// periodic curve `to < from` is the interval across v = 0), a cubic B-spline bump inside
    /// that moves the handle `X₃ = C(at)` (default the middle) by `along` (from `X₁ = C(from)`
    /// towards `X₂ = C(to)`), `across` (in the plane of `X₁X₂X₃`, towards `X₃`) and `normal`
    /// (perpendicular to that plane).
    #[serde(rename = "local")]
    Local {
        /// The curve edited (name or inline table).
        curve: CurveRef,
        /// Start of the edited interval of v.
        from: f64,
        /// End of the edited interval of v (below from: across v = 0 on a periodic curve).
        to: f64,
        /// The handle's parameter (default the middle of the interval).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        at: Option<f64>,
        /// Move of the handle from C(from) towards C(to).
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        along: f64,
        /// Move of the handle in the plane of the three points, towards the handle.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        across: f64,
        /// Move of the handle perpendicular to that plane.
        #[serde(default, skip_serializing_if = "is_zero")]
        #[schemars(skip_serializing_if = "never")]
        normal: f64,
    },
    /// A curve on a PDE patch of the design (§5.2.1): the image `X_patch(u(s), v(s))` of the
    /// closed curve `path` in that patch's `(u, v)` plane, with `s ∈ [0, 2π)` running once round
    /// `path` (the attached patch's `v`). The patch is solved first; it is trimmed inside `path`
    /// unless `trim = false`.
    #[serde(rename = "on_patch")]
    OnPatch {
        /// The host: the name of a PDE patch of the design.
        patch: String,
        /// A closed curve in the host's `(u, v)` plane (`circle`, `ellipse`, `polyline` or
        /// `bspline`, as in `[[trims]]`).
        #[serde(
            deserialize_with = "super::trim::deserialize_curve",
            serialize_with = "super::trim::serialize_curve"
        )]
        path: super::trim::TrimCurveSpec,
        /// Trim the host inside `path` (default true).
        #[serde(
            default = "default_true",
            skip_serializing_if = "super::write::is_true"
        )]
        #[schemars(skip_serializing_if = "never")]
        trim: bool,
    },
    /// The derivative condition of a patch attached along an `on_patch` curve: at every point
    /// of that curve, `scale` times the unit vector of the host's tangent plane across the
    /// curve, pointing into the trimmed hole (the host continued across its boundary), so that
    /// the attached patch leaves the host tangentially (G1). A negative scale points the other
    /// way (back over the host).
    #[serde(rename = "tangent_field")]
    TangentField {
        /// The name of an `on_patch` curve.
        curve: String,
        /// The length of the field (default 1, not 0); a negative one points back over the host.
        #[serde(default = "default_a")]
        scale: f64,
    },
}

fn default_normal() -> V3 {
    [0.0, 0.0, 1.0]
}

/// Parametrisation of closed point samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum ParamSpec {
    /// Equal parameter steps.
    Uniform,
    /// Steps proportional to the chord lengths between consecutive points (the default).
    #[default]
    Chord,
    /// Steps proportional to the square roots of the chord lengths.
    Centripetal,
}

/// `"periodic"` or `[t0, t1]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum DomainSpec {
    /// `"periodic"`: v on [0, 2π).
    #[default]
    Periodic,
    /// An open interval `[t0, t1]`.
    Interval([f64; 2]),
}

impl DomainSpec {
    /// True for the default, `"periodic"`.
    pub fn is_periodic(&self) -> bool {
        *self == DomainSpec::Periodic
    }
}

/// `"periodic"` or `[t0, t1]`, as read.
impl Serialize for DomainSpec {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            DomainSpec::Periodic => s.serialize_str("periodic"),
            DomainSpec::Interval(t) => t.serialize(s),
        }
    }
}

impl JsonSchema for DomainSpec {
    fn schema_name() -> String {
        "DomainSpec".to_string()
    }
    fn json_schema(_gen: &mut schemars::gen::SchemaGenerator) -> schemars::schema::Schema {
        let value = serde_json::json!({
            "description": "\"periodic\" (v on [0, 2π), the default) or an interval [t0, t1].",
            "oneOf": [
                { "type": "string", "enum": ["periodic"] },
                { "type": "array", "items": { "type": "number" }, "minItems": 2, "maxItems": 2 }
            ]
        });
        serde_json::from_value(value).unwrap_or(schemars::schema::Schema::Bool(true))
    }
}

impl<'de> Deserialize<'de> for DomainSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = DomainSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"periodic\" or [t0, t1]")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<DomainSpec, E> {
                if s == "periodic" {
                    Ok(DomainSpec::Periodic)
                } else {
                    Err(E::custom(format!(
                        "unknown domain '{s}', expected \"periodic\" or [t0, t1]"
                    )))
                }
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, seq: A) -> Result<DomainSpec, A::Error> {
                <[f64; 2]>::deserialize(de::value::SeqAccessDeserializer::new(seq))
                    .map(DomainSpec::Interval)
            }
        }
        d.deserialize_any(V)
    }
}

/// One affine step: `{ translate = [..] }`, `{ rotate = {..} }` or `{ scale = {..} }`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum TransformStep {
    /// Translation by a vector.
    Translate(V3),
    /// Rotation (right-handed, angle in degrees) about the line through `about` along `axis`.
    Rotate {
        /// Direction of the rotation axis (right-handed).
        axis: V3,
        /// Degrees.
        angle: f64,
        /// A point on the rotation axis (default the origin).
        #[serde(default, skip_serializing_if = "is_zero3")]
        #[schemars(skip_serializing_if = "never")]
        about: V3,
    },
    /// Uniform scaling by `factor ≠ 0` about the point `about`.
    Scale {
        /// The factor (non-zero).
        factor: f64,
        /// The fixed point (default the origin).
        #[serde(default, skip_serializing_if = "is_zero3")]
        #[schemars(skip_serializing_if = "never")]
        about: V3,
    },
    /// Scaling by `factors = [fx, fy, fz]` (each non-zero) along the axes about the point
    /// `about`: the dilations `d_kD_i` of §7.5.
    Dilate {
        /// [fx, fy, fz], each non-zero.
        factors: V3,
        /// The fixed point (default the origin).
        #[serde(default, skip_serializing_if = "is_zero3")]
        #[schemars(skip_serializing_if = "never")]
        about: V3,
    },
}
