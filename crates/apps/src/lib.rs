//! # pdeshape-apps
//!
//! The applications of pdeshape, on top of the geometry, design and I/O layers: time-dependent
//! designs and their animation (`anim`), thin-shell strength analysis with CalculiX (`shell`),
//! design for function by optimisation (`optimize`), fitting triangle meshes with designs
//! (`fit`) and filling their holes with PDE patches (`fill`).

#![warn(missing_docs)]

use pdeshape_design::{analysis, design, memory, mesh, spec};
use pdeshape_geometry::{formula, number, surface};
pub use pdeshape_geometry::{Error, ErrorKind, Result, Vec3, TAU};
use pdeshape_io::{mesh_write, render};

pub mod anim;
pub mod fill;
pub mod fit;
pub mod optimize;
pub mod shell;
pub mod work;
