//! Primary surfaces for blends: cylinders and planes with exact partials.

use crate::surface::{Closest, ClosestOptions, Partials, Surface, SurfaceNearest, VDomain};
use crate::{Error, Result, Vec3, TAU};

/// The cylinder `S(u, v) = base + v·axis + r (cos 2πu e₁ + sin 2πu e₂)` for `u, v ∈ [0, 1]`,
/// where `e₁` is the projection of `+x` on the plane normal to `axis` (`+y` if the axis is along
/// `x`) and `e₂ = â × e₁`. Seed 004 §6's `f(x, y) = (2y − 1, 2 cos 2πx, 2 sin 2πx)` is
/// `base = (−1, 0, 0)`, `axis = (2, 0, 0)`, `r = 2` with `(u, v) = (x, y)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Cylinder {
    base: Vec3,
    axis: Vec3,
    radius: f64,
    e1: Vec3,
    e2: Vec3,
}

fn finite(v: &Vec3, what: &str) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Error::invalid(format!("must be finite (got {v:?})")).at(what))
    }
}

impl Cylinder {
    /// Refuses a zero or non-finite axis and a non-positive radius.
    pub fn new(base: Vec3, axis: Vec3, radius: f64) -> Result<Self> {
        finite(&base, "base")?;
        finite(&axis, "axis")?;
        let n = axis.norm();
        if !(n > 0.0 && n.is_finite()) {
            return Err(Error::invalid("must not be the zero vector").at("axis"));
        }
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(
                Error::invalid(format!("must be positive and finite (got {radius})")).at("radius"),
            );
        }
        let a = axis / n;
        let x = Vec3::x();
        let proj = x - a * a.dot(&x);
        let e1 = if proj.norm() > 1e-9 {
            proj.normalize()
        } else {
            Vec3::y()
        };
        let e2 = a.cross(&e1);
        Ok(Cylinder {
            base,
            axis,
            radius,
            e1,
            e2,
        })
    }
}

impl Surface for Cylinder {
    fn v_domain(&self) -> VDomain {
        VDomain::Interval(0.0, 1.0)
    }
    /// `u` is the angle over `2πu`: closed.
    fn u_periodic(&self) -> bool {
        true
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        let (s, c) = (TAU * u).sin_cos();
        let r = self.radius;
        let radial = self.e1 * c + self.e2 * s;
        let tangential = self.e2 * c - self.e1 * s;
        Partials {
            x: self.base + self.axis * v + radial * r,
            xu: tangential * (TAU * r),
            xv: self.axis,
            xuu: radial * (-TAU * TAU * r),
            xuv: Vec3::zeros(),
            xvv: Vec3::zeros(),
        }
    }
}

/// The plane `S(u, v) = origin + u·du + v·dv`.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    origin: Vec3,
    du: Vec3,
    dv: Vec3,
}

impl Plane {
    /// Refuses non-finite vectors and parallel `du`, `dv`.
    pub fn new(origin: Vec3, du: Vec3, dv: Vec3) -> Result<Self> {
        finite(&origin, "origin")?;
        finite(&du, "du")?;
        finite(&dv, "dv")?;
        if du.cross(&dv).norm() <= 1e-12 * du.norm() * dv.norm() || du.norm() == 0.0 {
            return Err(Error::invalid("du and dv must not be parallel or zero").at("dv"));
        }
        Ok(Plane { origin, du, dv })
    }
}

impl Surface for Plane {
    fn v_domain(&self) -> VDomain {
        VDomain::Interval(0.0, 1.0)
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        Partials {
            x: self.origin + self.du * u + self.dv * v,
            xu: self.du,
            xv: self.dv,
            ..Default::default()
        }
    }
}

/// In closed form: `v` is the clamped projection of `p − base` on the axis and `u` the angle
/// of its part normal to the axis (`u = 0` for a point on the axis, where every `u` is as
/// close). The options are not used.
impl SurfaceNearest for Cylinder {
    fn nearest(&self, p: Vec3, _opts: &ClosestOptions) -> Option<Closest> {
        if !p.iter().all(|c| c.is_finite()) {
            return None;
        }
        let q = p - self.base;
        let along = q.dot(&self.axis) / self.axis.norm_squared();
        let radial = q - self.axis * along;
        let (x, y) = (radial.dot(&self.e1), radial.dot(&self.e2));
        let u = if x == 0.0 && y == 0.0 {
            0.0
        } else {
            let a = y.atan2(x) / TAU;
            if a < 0.0 {
                (a + 1.0).min(1.0 - f64::EPSILON / 2.0)
            } else {
                a
            }
        };
        let v = along.clamp(0.0, 1.0);
        let point = self.partials(u, v).x;
        Some(Closest {
            u,
            v,
            point,
            distance: (point - p).norm(),
            converged: true,
        })
    }
}

/// In closed form: the orthogonal projection on the plane if its parameters lie in
/// `[0, 1]²`, else the nearest of the four sides' clamped projections (the parallelogram is
/// convex, so its closest point is on the boundary when the projection is outside). The options
/// are not used.
impl SurfaceNearest for Plane {
    fn nearest(&self, p: Vec3, _opts: &ClosestOptions) -> Option<Closest> {
        if !p.iter().all(|c| c.is_finite()) {
            return None;
        }
        let q = p - self.origin;
        let (a, b, c) = (
            self.du.norm_squared(),
            self.du.dot(&self.dv),
            self.dv.norm_squared(),
        );
        let (r, s) = (q.dot(&self.du), q.dot(&self.dv));
        let det = a * c - b * b;
        let (u, v) = ((c * r - b * s) / det, (a * s - b * r) / det);
        let at = |u: f64, v: f64| {
            let point = self.origin + self.du * u + self.dv * v;
            Closest {
                u,
                v,
                point,
                distance: (point - p).norm(),
                converged: true,
            }
        };
        if (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v) {
            return Some(at(u, v));
        }
        let sides = [
            // v = 0 and v = 1: u from the projection on du.
            at(((r) / a).clamp(0.0, 1.0), 0.0),
            at(((r - b) / a).clamp(0.0, 1.0), 1.0),
            // u = 0 and u = 1.
            at(0.0, (s / c).clamp(0.0, 1.0)),
            at(1.0, ((s - b) / c).clamp(0.0, 1.0)),
        ];
        sides
            .into_iter()
            .min_by(|x, y| x.distance.total_cmp(&y.distance))
    }
}
