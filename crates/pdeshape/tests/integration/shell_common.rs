//! Surfaces shared by the shell tests (`shell_mesh`, `shell_ccx`).
#![allow(dead_code)]

use pdeshape::surface::{Partials, Surface, VDomain};
use pdeshape::Vec3;

/// The cylinder `(R cos v, R sin v, z0 + H u)`: outward normals.
pub(crate) struct Cylinder {
    pub r: f64,
    pub z0: f64,
    pub h: f64,
}

impl Surface for Cylinder {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        let (s, c) = v.sin_cos();
        let r = self.r;
        Partials {
            x: Vec3::new(r * c, r * s, self.z0 + self.h * u),
            xu: Vec3::new(0.0, 0.0, self.h),
            xv: Vec3::new(-r * s, r * c, 0.0),
            xvv: Vec3::new(-r * c, -r * s, 0.0),
            ..Default::default()
        }
    }
}
