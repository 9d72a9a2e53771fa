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

pub mod analysis;
pub mod analysis_report;
pub mod anim;
pub mod bfs;
pub mod cad;
mod check;
pub mod curve;
mod decomp;
pub mod design;
pub mod diagnostics;
pub mod dynamic;
pub mod dynamic_run;
pub mod elliptic;
mod error;
pub mod fd;
pub mod fit;
mod formula;
pub mod fourier;
pub mod majorant;
pub mod memory;
pub mod mesh;
pub mod optimize;
pub mod render;
pub mod scalar;
pub mod shell;
pub mod spec;
pub mod spline;
pub mod splinepde;
pub mod surface;
pub mod trim;

pub use error::{Error, Result};

/// Points and vectors in R³.
pub type Vec3 = nalgebra::Vector3<f64>;

/// 2π: periodic curves live on `[0, 2π)`.
pub const TAU: f64 = std::f64::consts::TAU;

/// The README's code runs as a doc test.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
