//! What a parameter is: `ParamKind` (what it changes) and `DesignParameter` (a `[[parameters]]`
//! entry read and checked, with its neutral value and its value).

use crate::Vec3;

/// What a parameter changes.
#[derive(Clone, Debug, PartialEq)]
pub enum ParamKind {
    /// `c_kT_i`: translation of the curve along axis `i` (0, 1, 2 for x, y, z).
    Translate {
        /// The driven curve's name in `[curves]`.
        curve: String,
        /// The axis index `i`: 0, 1 or 2 for x, y, z.
        axis: usize,
    },
    /// `c_kR_i`: rotation of the curve by the value (radians) about the axis `i` through the
    /// curve's centroid.
    Rotate {
        /// The driven curve's name in `[curves]`.
        curve: String,
        /// The axis index `i`: 0, 1 or 2 for x, y, z.
        axis: usize,
    },
    /// `c_kD_i`: dilation of the curve by the value along axis `i` about its centroid.
    Dilate {
        /// The driven curve's name in `[curves]`.
        curve: String,
        /// The axis index `i`: 0, 1 or 2 for x, y, z.
        axis: usize,
    },
    /// The smoothing parameter `a` of every polyharmonic operator of the design.
    Smoothing,
    /// `c_T`: the control point `c_j` of a B-spline curve moves by `(−1)^j c_T n_j`, `n_j` the
    /// unit normal of the control polygon at `c_j` in the `xy` plane, pointing away from the
    /// polygon's centroid (§7.5.1, Fig. 7.5: alternate points out and in make the ridges).
    ControlOffset {
        /// The driven B-spline curve's name in `[curves]`.
        curve: String,
    },
    /// The position parameter `X₁` (§6.1): the curve translated so that coordinate `axis` of
    /// its point at `v1` becomes the value.
    Position {
        /// The driven curve's name in `[curves]`.
        curve: String,
        /// The curve parameter of `X₁`.
        v1: f64,
        /// The coordinate set: 0, 1 or 2 for x, y, z.
        axis: usize,
    },
    /// The angling parameter `θ` (§6.1): the curve rotated by the value (radians, right-handed)
    /// about the line through its point at `v1` along the unit vector `axis`.
    Angle {
        /// The driven curve's name in `[curves]`.
        curve: String,
        /// The curve parameter of `X₁`, the point the rotation axis passes through.
        v1: f64,
        /// Unit direction of the rotation axis (from the entry's `axis`, or the normal of its
        /// `plane`).
        axis: Vec3,
    },
    /// The scaling parameter `s` (§6.1): the curve scaled uniformly about its point `X₁` at
    /// `v1` so that the distance to its point `X₂` at `v2` becomes the value.
    Scale {
        /// The driven curve's name in `[curves]`.
        curve: String,
        /// The curve parameter of `X₁`, the fixed point of the scaling.
        v1: f64,
        /// The curve parameter of `X₂`; the value is the distance `|X₁X₂|`.
        v2: f64,
    },
    /// The `v = 0` point (§6.4): the curve's `v_origin` becomes the value (radians).
    VOrigin {
        /// The driven (periodic) curve's name in `[curves]`.
        curve: String,
    },
}

impl ParamKind {
    /// The driven curve, if any.
    pub fn curve(&self) -> Option<&str> {
        match self {
            ParamKind::Smoothing => None,
            ParamKind::Translate { curve, .. }
            | ParamKind::Rotate { curve, .. }
            | ParamKind::Dilate { curve, .. }
            | ParamKind::ControlOffset { curve }
            | ParamKind::Position { curve, .. }
            | ParamKind::Angle { curve, .. }
            | ParamKind::Scale { curve, .. }
            | ParamKind::VOrigin { curve } => Some(curve),
        }
    }

    /// Whether it is one of §7.5's kinds (acting before the others, grouped per curve).
    pub(super) fn is_book_7_5(&self) -> bool {
        matches!(
            self,
            ParamKind::Translate { .. }
                | ParamKind::Rotate { .. }
                | ParamKind::Dilate { .. }
                | ParamKind::Smoothing
                | ParamKind::ControlOffset { .. }
        )
    }

    /// What it drives, in words (`check` prints it).
    pub fn describe(&self) -> String {
        const AXES: [&str; 3] = ["x", "y", "z"];
        match self {
            ParamKind::Translate { curve, axis } => {
                format!("translation of curve '{curve}' along {}", AXES[*axis])
            }
            ParamKind::Rotate { curve, axis } => format!(
                "rotation (rad) of curve '{curve}' about the {} axis through its centroid",
                AXES[*axis]
            ),
            ParamKind::Dilate { curve, axis } => format!(
                "dilation of curve '{curve}' along {} about its centroid",
                AXES[*axis]
            ),
            ParamKind::Smoothing => "the smoothing parameter a".to_string(),
            ParamKind::ControlOffset { curve } => {
                format!("control-point offsets c_T of curve '{curve}'")
            }
            ParamKind::Position { curve, v1, axis } => format!(
                "position: {} of X1, the point of curve '{curve}' at v = {v1}",
                AXES[*axis]
            ),
            ParamKind::Angle { curve, v1, axis } => format!(
                "angle (rad) of curve '{curve}' about [{}, {}, {}] through X1 (v = {v1})",
                axis.x, axis.y, axis.z
            ),
            ParamKind::Scale { curve, v1, v2 } => {
                format!("scale: |X1X2| of curve '{curve}' (v = {v1} and {v2}), about X1")
            }
            ParamKind::VOrigin { curve } => format!("v = 0 point (v_origin) of curve '{curve}'"),
        }
    }
}

/// A `[[parameters]]` entry read and checked, with its neutral value (the value that leaves
/// the design as written) and its value (given, else the neutral one).
#[derive(Clone, Debug, PartialEq)]
pub struct DesignParameter {
    /// The entry's unique `name`, by which `--set`, `[optimize]` and
    /// [`crate::design::Edit::SetParameter`] refer to it.
    pub name: String,
    /// Where it is in the file: `parameters[i]`.
    pub place: String,
    /// What the parameter changes, from the entry's `kind` and the keys that kind uses.
    pub kind: ParamKind,
    /// Further curves that follow the same map.
    pub with: Vec<String>,
    /// Lower bound of the value (the entry's `min`).
    pub min: f64,
    /// Upper bound of the value (the entry's `max`).
    pub max: f64,
    /// The value that leaves the design as written: `X₁`'s own coordinate, angle 0, the
    /// curve's own `|X₁X₂|`, its own `v_origin`, 0 for translations, rotations and
    /// `control_offset`, 1 for dilations, the design's own `a`.
    pub neutral: f64,
    /// The value in force: the entry's `value` if given, else `neutral` (angles in radians).
    pub value: f64,
}
