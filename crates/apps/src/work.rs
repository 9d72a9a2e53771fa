//! Time priced like memory. Work whose amount an input file chooses (the closest-point
//! searches of a re-targeting, the sections a fitting template asks for) is counted before the
//! first step and refused above [`MAX_SECONDS`] of estimated work on one core, with the estimate
//! and what to change in the message, instead of running for minutes or hours.

use crate::{Error, Result};

/// Estimated seconds of one core's work a command may be asked for by its input.
pub const MAX_SECONDS: f64 = 8.0;

/// One kind of work: how many units an input asks for and how many a core does in a second
/// (measured on the 2-core development machine, see the callers).
#[derive(Clone, Copy, Debug)]
pub struct Work {
    /// Units asked for.
    pub units: f64,
    /// Units a core does in a second.
    pub per_second: f64,
}

impl Work {
    /// Estimated seconds.
    pub fn seconds(&self) -> f64 {
        self.units / self.per_second
    }
}

/// Refuses `parts` of work whose estimated seconds together exceed [`MAX_SECONDS`]: `what`
/// says what was asked for (`"a template of 9000 sections over 2 000 000 triangles"`),
/// `advice` what to change; `place` is where in the input it was asked.
pub fn check(parts: &[Work], what: &str, advice: &str, place: &str) -> Result<()> {
    check_within(parts, MAX_SECONDS, what, advice, place)
}

/// [`check`] against `limit` seconds instead of [`MAX_SECONDS`]: for a command whose own work
/// is bounded otherwise (the fit's layout rounds, by their estimated work), the part of it an
/// input's size decides before that bound is counted.
pub fn check_within(
    parts: &[Work],
    limit: f64,
    what: &str,
    advice: &str,
    place: &str,
) -> Result<()> {
    let seconds: f64 = parts.iter().map(Work::seconds).sum();
    if seconds.is_finite() && seconds <= limit {
        return Ok(());
    }
    let shown = if seconds.is_finite() && seconds < 1e6 {
        format!("{seconds:.0} s")
    } else {
        "more than 10⁶ s".to_string()
    };
    let e = Error::invalid(format!(
        "{what} needs about {shown} of work, more than the {limit:.0} s a run may be asked \
         for; {advice}"
    ));
    Err(if place.is_empty() { e } else { e.at(place) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn work_within_the_bound_passes_and_beyond_it_is_refused_with_the_estimate() {
        let w = |units| Work {
            units,
            per_second: 1e6,
        };
        assert!(check(&[w(3e6), w(5e6)], "x", "y", "p").is_ok());
        let e = check(&[w(4e6), w(5e6)], "a template", "use fewer", "parts[0]")
            .unwrap_err()
            .to_string();
        assert!(e.contains("about 9 s of work"), "{e}");
        assert!(e.contains("parts[0]") && e.contains("use fewer"), "{e}");
        let e = check(&[w(f64::INFINITY)], "a", "b", "")
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than 10⁶ s"), "{e}");
    }
}
