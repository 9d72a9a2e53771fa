//! # pdeshape
//!
//! Geometric design with partial differential equations. A designer gives a few boundary curves
//! (position curves, derivative curves, intermediate curves), picks an elliptic operator and a
//! smoothing parameter `a`, and gets the surface that solves the Bloor–Wilson boundary-value problem
//! (H. Ugail, *Partial Differential Equations for Geometric Design*, chapters 4–6).
//!
//! The data flow:
//!
//! ```text
//! design file (TOML) ──spec──▶ curves, operator, conditions
//!                                │ elliptic::solve
//!                                ▼
//!                PdePatch (implements Surface: exact partials anywhere)
//!                                │ mesh::tessellate / mesh::sample
//!                                ▼
//!                Grid (positions, normals, uv) ──▶ obj, stl, ply, glb, csv, png
//! ```
//!
//! This crate is the façade of four layer crates, each depending only on those below it:
//! `pdeshape-geometry` (curves, surfaces, solvers), `pdeshape-design` (the design file, compile
//! and edit, trims, analysis, tessellation), `pdeshape-io` (mesh and CAD writers, pictures) and
//! `pdeshape-apps` (animation, shell analysis, optimisation, fitting). Its modules keep one path
//! for each item: `mesh` holds tessellation and the mesh writers, `design` the solved design and
//! its writing. The types most programs need are also at the top: [`parse_design`] and
//! [`DesignSpec`], [`compile`], [`CompiledDesign`], [`Edit`], [`SolvedDesign`] and its
//! [`WriteDesign`], [`diagnose`], [`solve`] and [`PdePatch`], [`Curve`], [`Surface`], the meshes,
//! [`OutputFormat`], [`Units`], the CAD model and the integrals.

#![warn(missing_docs)]

pub use pdeshape_apps::{anim, fill, fit, optimize, shell};
pub use pdeshape_design::{analysis, memory, spec, trim};
pub use pdeshape_geometry::{
    bfs, curve, dynamic, elliptic, fd, fourier, linalg, majorant, network, nsided, number, scalar,
    spline, splinepde, surface,
};
pub use pdeshape_geometry::{Error, ErrorKind, Result, Vec3, TAU};
pub use pdeshape_io::{cad, dynamic_output, format, render};

// The items most programs need, at the top (each also at its module's path).
pub use analysis::{integrate_design, Quadrature};
pub use cad::{approximate_design, CadModel};
pub use curve::{Curve, SharedCurve};
pub use design::{compile, CompiledDesign, Edit, Export, SolvedDesign, WriteDesign};
pub use diagnostics::{diagnose, Diagnostics, Verdict};
pub use elliptic::{solve, Condition, Operator, PdePatch, SolveOptions};
pub use format::OutputFormat;
pub use mesh::{GridMesh, TriMesh};
pub use open::DesignFile;
pub use spec::{parse_design, DesignSpec, Units};
pub use surface::{Partials, Surface};

pub mod analysis_report;
pub mod diagnostics;
pub mod dynamic_run;
pub mod open;

/// Designs: compile, edit, solve, and write (the design layer's `design` with the writing of
/// `pdeshape-io`).
pub mod design {
    pub use pdeshape_design::design::*;
    pub use pdeshape_io::design_write::{WriteDesign, WriteTimings, Written};
}

/// Tessellation, triangle meshes, the weld, and the writers of mesh and sample formats.
pub mod mesh {
    pub use pdeshape_design::mesh::*;
    pub use pdeshape_io::mesh_write::*;
}

/// The README's code runs as a doc test.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;

/// The library page's code runs as a doc test.
#[doc = include_str!("../../../docs/library.md")]
#[cfg(doctest)]
pub struct LibraryDocDoctests;
