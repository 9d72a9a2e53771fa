//! # pdeshape-io
//!
//! Readers, writers and pictures of pdeshape, beside the design layer: mesh formats
//! (`mesh_write`, and `design_write` for a solved design), CAD exchange with certified deviations
//! (`cad`: STEP, IGES), pictures (`render`), the outputs of dynamic-curve runs
//! (`dynamic_output`) and text for SVG plots (`svg`).

#![warn(missing_docs)]

use pdeshape_design::{design, memory, mesh, spec, trim};
use pdeshape_geometry::{
    curve, dynamic, elliptic, formula, majorant, nsided, spline, splinepde, surface,
};
pub use pdeshape_geometry::{Error, ErrorKind, Result, Vec3, TAU};

pub mod cad;
pub mod design_write;
pub mod dynamic_output;
pub mod format;
pub mod mesh_write;
pub mod render;
pub mod svg;
