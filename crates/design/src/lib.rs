//! # pdeshape-design
//!
//! The design layer of pdeshape, above `pdeshape-geometry`: the design file's types and parser
//! (`spec`), the compiled design that is edited and re-solved incrementally (`design`), trimmed
//! patches (`trim`), curvatures and integrals (`analysis`), tessellation, triangle meshes and the
//! weld of a design's grids into one mesh (`mesh`), and the memory budget of one request
//! (`memory`).

#![warn(missing_docs)]

use pdeshape_geometry::{
    bfs, check, curve, disk, dynamic, elliptic, fd, formula, majorant, network, nsided, spline,
    splinepde, surface,
};
pub use pdeshape_geometry::{Error, ErrorKind, Result, Vec3, TAU};

pub mod analysis;
pub mod design;
pub mod memory;
pub mod mesh;
pub mod spec;
pub mod trim;

#[cfg(test)]
mod lower_layers_tests;
