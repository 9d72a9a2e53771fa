//! Primary surfaces for blends: cylinders and planes with exact partials.

use crate::surface::{Partials, Surface, VDomain};
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
