//! What an animation samples: a design whose numbers are formulas in `t`, or a morph.

use super::morph::{ease, Morph};
use crate::spec::time::{TimeSpec, TimedDesign};
use crate::spec::DesignSpec;
use crate::Result;

/// A time-dependent design: frames at [`Animation::times`], each an ordinary design.
#[derive(Clone, Debug)]
pub enum Animation {
    /// A design file with `[time]` and formula fields.
    Timed(TimedDesign),
    /// A morph (§6.4.1) over the interval of `time` with the ease `γ`.
    Morph {
        /// The two designs interpolated.
        morph: Morph,
        /// The frames' times; the morph runs from `ε = 0` at `time.start` to `ε = 1` at `time.end`.
        time: TimeSpec,
        /// The ease exponent `γ`: `ε = τ^γ` with `τ = (t − start)/(end − start)` clamped to
        /// `[0, 1]`.
        ease: f64,
    },
}

impl Animation {
    /// The `[time]` section.
    pub fn time(&self) -> &TimeSpec {
        match self {
            Animation::Timed(d) => &d.time,
            Animation::Morph { time, .. } => time,
        }
    }

    /// The times of the frames.
    pub fn times(&self) -> Result<Vec<f64>> {
        self.time().times()
    }

    /// The morph parameter `ε` at time `t` (`None` for a timed design).
    pub fn epsilon(&self, t: f64) -> Option<f64> {
        match self {
            Animation::Timed(_) => None,
            Animation::Morph { time, ease: g, .. } => {
                let tau = if t >= time.end {
                    1.0
                } else {
                    (t - time.start) / (time.end - time.start)
                };
                Some(ease(tau, *g))
            }
        }
    }

    /// False when every frame is the same design: a timed design without formula fields in
    /// `t` and without a rig, or a morph between two equal designs.
    pub fn depends_on_time(&self) -> bool {
        match self {
            Animation::Timed(d) => d.depends_on_time(),
            Animation::Morph { morph, .. } => !morph.is_constant(),
        }
    }

    /// The design at time `t`.
    pub fn spec_at(&self, t: f64) -> Result<DesignSpec> {
        match self {
            Animation::Timed(d) => d.at(t),
            Animation::Morph { morph, .. } => morph.at(self.epsilon(t).unwrap_or(0.0)),
        }
    }
}
