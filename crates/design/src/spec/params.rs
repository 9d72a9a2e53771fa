//! `[[parameters]]`: named, bounded design parameters (§6.1, §6.4, §7.5). Each entry names what
//! it drives (a point of a curve dragged, the curve turned or resized about that point, the
//! curve's `v = 0` point, a translation, rotation or dilation about its centroid, the smoothing
//! parameter `a`, the control-point offsets `c_T`), its bounds and its value. The design layer
//! applies the values (`design::resolve_parameters`); the optimiser, `--set NAME=VALUE` and
//! `Edit::SetParameter` change them by name. Documented key by key in `docs/design-file.md`.

use super::types::V3;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// One `[[parameters]]` entry.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DesignParameterSpec {
    /// A unique name: `[optimize] parameters`, `--set NAME=VALUE` and the library's
    /// `Edit::SetParameter` refer to the parameter by it.
    pub name: String,
    /// What the parameter drives: `position`, `angle`, `scale`, `v_origin` (§6.1, §6.4),
    /// `translate`, `rotate`, `dilate`, `control_offset` (§7.5) or `smoothing` (`a`).
    pub kind: DriveKind,
    /// The driven curve (a name in `[curves]`; every kind but `smoothing`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub curve: Option<String>,
    /// Further curves that undergo the same map as `curve` (for `position`, `angle`, `scale`:
    /// the same translation, rotation or scaling, found on `curve`; for `v_origin`: the same
    /// `v_origin`), e.g. the curve a derivative curve points at.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub with: Vec<String>,
    /// `v₁`, the curve parameter of the point `X₁` (`position`, `angle`, `scale`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v1: Option<f64>,
    /// `v₂`, the curve parameter of the point `X₂` (`scale`: the value is `|X₁X₂|`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub v2: Option<f64>,
    /// `position`, `translate`, `rotate`, `dilate`: the coordinate axis `"x"`, `"y"` or `"z"`.
    /// `angle`: the direction of the rotation axis through `X₁`, a coordinate axis or a vector
    /// `[x, y, z]` (exclusive with `plane`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<AxisSpec>,
    /// `angle`: the plane `"xy"`, `"xz"` or `"yz"` in which the curve turns (the axis through
    /// `X₁` is normal to it); exclusive with `axis`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane: Option<PlaneSpec>,
    /// The value (default: the neutral value, which leaves the design as written: `X₁`'s own
    /// coordinate, angle 0, the curve's own `|X₁X₂|`, its own `v_origin`, 0 for translations,
    /// rotations and `control_offset`, 1 for dilations, the design's own `a`). Angles in
    /// radians.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    /// Lower bound of the value.
    pub min: f64,
    /// Upper bound of the value.
    pub max: f64,
}

/// What a design parameter drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DriveKind {
    /// The position parameter `X₁` (§6.1): the curve translated so that the `axis` coordinate
    /// of its point at `v1` becomes the value.
    Position,
    /// The angling parameter `θ` (§6.1): the curve rotated by the value (radians) about the
    /// line through `X₁` (its point at `v1`) along `axis`, or normal to `plane`.
    Angle,
    /// The scaling parameter `s` (§6.1): the curve scaled uniformly about `X₁` so that
    /// `|X₁X₂|` (its points at `v1`, `v2`) becomes the value.
    Scale,
    /// The curve's `v = 0` point (§6.4): its `v_origin` (radians), `C̃(v) = C(v + v_origin)`.
    VOrigin,
    /// `c_kT_i` (§7.5): translation along `axis` by the value.
    Translate,
    /// `c_kR_i` (§7.5): rotation by the value (radians) about `axis` through the centroid.
    Rotate,
    /// `c_kD_i` (§7.5): dilation along `axis` by the value (a factor) about the centroid.
    Dilate,
    /// `c_T` (§7.5.1, Eq. 7.6): amplitude of the control-point offsets of a B-spline curve.
    ControlOffset,
    /// The smoothing parameter `a` of every polyharmonic operator of the design.
    Smoothing,
}

impl DriveKind {
    /// The word the design file uses.
    pub fn word(self) -> &'static str {
        match self {
            DriveKind::Position => "position",
            DriveKind::Angle => "angle",
            DriveKind::Scale => "scale",
            DriveKind::VOrigin => "v_origin",
            DriveKind::Translate => "translate",
            DriveKind::Rotate => "rotate",
            DriveKind::Dilate => "dilate",
            DriveKind::ControlOffset => "control_offset",
            DriveKind::Smoothing => "smoothing",
        }
    }
}

/// A coordinate axis or a direction.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum AxisSpec {
    /// `"x"`, `"y"` or `"z"`.
    Name(AxisName),
    /// A direction `[x, y, z]` (not zero).
    Vector(V3),
}

/// A coordinate axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum AxisName {
    /// `"x"`, index 0.
    X,
    /// `"y"`, index 1.
    Y,
    /// `"z"`, index 2.
    Z,
}

impl AxisName {
    /// 0, 1, 2 for x, y, z.
    pub fn index(self) -> usize {
        match self {
            AxisName::X => 0,
            AxisName::Y => 1,
            AxisName::Z => 2,
        }
    }
}

/// A coordinate plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum PlaneSpec {
    /// `"xy"`: the curve turns in the xy plane, about the z direction through `X₁`.
    Xy,
    /// `"xz"`: the curve turns in the xz plane, about the y direction through `X₁`.
    Xz,
    /// `"yz"`: the curve turns in the yz plane, about the x direction through `X₁`.
    Yz,
}

impl PlaneSpec {
    /// The index of the axis normal to the plane (z for `xy`).
    pub fn normal_index(self) -> usize {
        match self {
            PlaneSpec::Xy => 2,
            PlaneSpec::Xz => 1,
            PlaneSpec::Yz => 0,
        }
    }
}
