//! Time in the designer (§6.4.1, §8.1): a design whose numbers are formulas in `t` (or that has
//! a `[rig]`), or a morph file, is shown at one time `t` of its `[time]` interval; moving `t`
//! re-solves the design at that time (`anim::Animation::spec_at`, then the compiled design's
//! incremental re-solve), as `pdeshape animate` makes each frame.

use super::error::ApiError;
use pdeshape::anim::Animation;
use pdeshape::spec::DesignSpec;
use serde_json::{json, Value};

/// The animation of a session and the time shown.
pub(super) struct Timeline {
    animation: Animation,
    t: f64,
    frames: usize,
}

impl Timeline {
    /// The timeline of `animation` at its start time.
    pub(super) fn new(animation: Animation) -> Result<Timeline, ApiError> {
        let frames = animation
            .times()
            .map_err(|e| ApiError::unprocessable(crate::common::message_of(&e), e.place()))?
            .len();
        let t = animation.time().start;
        Ok(Timeline {
            animation,
            t,
            frames,
        })
    }

    pub(super) fn t(&self) -> f64 {
        self.t
    }

    /// The design at time `t`, checked to lie in the `[time]` interval. Nothing changes here
    /// until [`Timeline::set`] confirms that the design solved.
    pub(super) fn spec_at(&self, t: f64) -> Result<DesignSpec, ApiError> {
        let time = self.animation.time();
        if !(t.is_finite() && time.start <= t && t <= time.end) {
            return Err(ApiError::bad_request(
                format!(
                    "must lie in the design's [time] interval [{}, {}] (got {t})",
                    time.start, time.end
                ),
                "t",
            ));
        }
        self.animation
            .spec_at(t)
            .map_err(|e| ApiError::unprocessable(crate::common::message_of(&e), e.place()))
    }

    /// The time now shown.
    pub(super) fn set(&mut self, t: f64) {
        self.t = t;
    }

    /// What the page's timeline shows.
    pub(super) fn json(&self) -> Value {
        let time = self.animation.time();
        json!({
            "kind": match self.animation { Animation::Timed(_) => "timed", Animation::Morph { .. } => "morph" },
            "start": time.start,
            "end": time.end,
            "loop": time.looped,
            "frames": self.frames,
            "t": self.t,
            "epsilon": self.animation.epsilon(self.t),
        })
    }
}
