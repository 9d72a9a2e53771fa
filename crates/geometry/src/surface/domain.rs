//! Parameter ranges: the interval `u` runs over and the whole `(u, v)` domain of a surface.

use super::VDomain;
use crate::TAU;

/// A closed parameter interval `[start, end]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Lower end.
    pub start: f64,
    /// Upper end.
    pub end: f64,
}

impl Interval {
    /// `[0, 1]`: the `u` range of every surface that does not say otherwise.
    pub const UNIT: Interval = Interval {
        start: 0.0,
        end: 1.0,
    };

    /// `[start, end]` (not checked; see [`Interval::is_valid`]).
    pub const fn new(start: f64, end: f64) -> Self {
        Interval { start, end }
    }

    /// True if both ends are finite and `start < end`.
    pub fn is_valid(&self) -> bool {
        self.start.is_finite() && self.end.is_finite() && self.start < self.end
    }

    /// `end − start`.
    pub fn length(&self) -> f64 {
        self.end - self.start
    }

    /// True if `start ≤ t ≤ end`.
    pub fn contains(&self, t: f64) -> bool {
        self.start <= t && t <= self.end
    }

    /// `t` clamped to `[start, end]` (NaN stays NaN).
    pub fn clamp(&self, t: f64) -> f64 {
        if t < self.start {
            self.start
        } else if t > self.end {
            self.end
        } else {
            t
        }
    }

    /// The point a fraction `s` of the way from `start` to `end`: `start + s (end − start)`.
    pub fn lerp(&self, s: f64) -> f64 {
        self.start + (self.end - self.start) * s
    }

    /// `t` moved into `[start, end)` by a whole number of periods `end − start` (for a periodic
    /// parameter; NaN and infinities give NaN).
    pub fn wrap(&self, t: f64) -> f64 {
        let w = self.start + (t - self.start).rem_euclid(self.length());
        // rem_euclid can round up to the period itself.
        if w >= self.end {
            self.start
        } else {
            w
        }
    }
}

impl VDomain {
    /// True for [`VDomain::Periodic`].
    pub fn is_periodic(&self) -> bool {
        matches!(self, VDomain::Periodic)
    }

    /// The `v` values one copy of the surface covers: `[0, 2π]` for a periodic domain (the
    /// end is the start again), else the interval itself.
    pub fn interval(&self) -> Interval {
        match *self {
            VDomain::Periodic => Interval::new(0.0, TAU),
            VDomain::Interval(a, b) => Interval::new(a, b),
        }
    }
}

/// The whole parameter domain of a surface: `u` over an interval (periodic or not) and `v` over
/// its [`VDomain`]. [`super::Surface::parameter_domain`] gives it; algorithms that search the
/// domain (closest points, grids) clamp a bounded parameter to its range and wrap a periodic one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParameterDomain {
    /// The `u` range.
    pub u: Interval,
    /// True if the sides `u = u.start` and `u = u.end` are the same curve and the surface
    /// continues smoothly across it, with period `u.end − u.start`.
    pub u_periodic: bool,
    /// The `v` domain.
    pub v: VDomain,
}

impl ParameterDomain {
    /// The `v` interval of one copy of the surface ([`VDomain::interval`]).
    pub fn v_interval(&self) -> Interval {
        self.v.interval()
    }

    /// True if `v` is periodic.
    pub fn v_periodic(&self) -> bool {
        self.v.is_periodic()
    }

    /// `(u, v)` brought into the domain: a periodic parameter wrapped into `[start, end)`, a
    /// bounded one clamped to `[start, end]`.
    pub fn normalize(&self, u: f64, v: f64) -> (f64, f64) {
        let u = if self.u_periodic {
            self.u.wrap(u)
        } else {
            self.u.clamp(u)
        };
        let vi = self.v_interval();
        let v = if self.v_periodic() {
            vi.wrap(v)
        } else {
            vi.clamp(v)
        };
        (u, v)
    }

    /// True if `(u, v)` lies in the domain (any `v` for a periodic `v`, likewise `u`; NaN never).
    pub fn contains(&self, u: f64, v: f64) -> bool {
        let inside = |i: Interval, periodic: bool, t: f64| {
            if periodic {
                t.is_finite()
            } else {
                i.contains(t)
            }
        };
        inside(self.u, self.u_periodic, u) && inside(self.v_interval(), self.v_periodic(), v)
    }

    /// The four corners `(u, v)` of the parameter rectangle (`v` over `[0, 2π]` if periodic):
    /// `(u₀, v₀), (u₁, v₀), (u₀, v₁), (u₁, v₁)`.
    pub fn corners(&self) -> [(f64, f64); 4] {
        let (u, v) = (self.u, self.v_interval());
        [
            (u.start, v.start),
            (u.end, v.start),
            (u.start, v.end),
            (u.end, v.end),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_clamp_wrap_and_interpolate() {
        let i = Interval::new(-1.0, 3.0);
        assert!(i.is_valid() && !Interval::new(1.0, 1.0).is_valid());
        assert!(!Interval::new(0.0, f64::INFINITY).is_valid());
        assert_eq!(i.length(), 4.0);
        assert_eq!(
            (i.clamp(-5.0), i.clamp(2.0), i.clamp(9.0)),
            (-1.0, 2.0, 3.0)
        );
        assert!(i.clamp(f64::NAN).is_nan());
        assert_eq!((i.lerp(0.0), i.lerp(0.5), i.lerp(1.0)), (-1.0, 1.0, 3.0));
        assert_eq!((i.wrap(3.0), i.wrap(-2.0), i.wrap(7.5)), (-1.0, 2.0, -0.5));
        assert!(i.wrap(f64::NAN).is_nan() && i.wrap(f64::INFINITY).is_nan());
        // Just below the start wraps to just below the end, never to the end itself.
        let w = Interval::UNIT.wrap(-1e-300);
        assert!((0.0..1.0).contains(&w), "{w}");
        assert_eq!(VDomain::Periodic.interval(), Interval::new(0.0, TAU));
        assert_eq!(
            VDomain::Interval(2.0, 5.0).interval(),
            Interval::new(2.0, 5.0)
        );
    }

    #[test]
    fn domains_normalize_and_contain() {
        let d = ParameterDomain {
            u: Interval::new(0.0, 2.0),
            u_periodic: false,
            v: VDomain::Periodic,
        };
        assert_eq!(d.normalize(-1.0, -1.0), (0.0, TAU - 1.0));
        assert_eq!(d.normalize(3.0, TAU), (2.0, 0.0));
        assert!(d.contains(1.0, 100.0) && !d.contains(2.5, 0.0) && !d.contains(1.0, f64::NAN));
        let p = ParameterDomain {
            u: Interval::UNIT,
            u_periodic: true,
            v: VDomain::Interval(-1.0, 1.0),
        };
        assert_eq!(p.normalize(1.25, 4.0), (0.25, 1.0));
        assert!(p.contains(-7.0, 0.5) && !p.contains(0.5, 1.5));
        assert_eq!(
            p.corners(),
            [(0.0, -1.0), (1.0, -1.0), (0.0, 1.0), (1.0, 1.0)]
        );
    }
}
