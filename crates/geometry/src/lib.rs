//! # pdeshape-geometry
//!
//! The bottom layer of pdeshape: curves and surfaces with exact derivatives, formulas, splines,
//! linear algebra, and the solvers of the Bloor–Wilson PDE method and its relatives (H. Ugail,
//! *Partial Differential Equations for Geometric Design*): the analytic elliptic solver
//! (`elliptic`), finite differences (`fd`), Bogner–Fox–Schmit splines and blends (`bfs`), spline
//! solutions of linear PDEs (`splinepde`) and dynamic PDE curves (`dynamic`). No I/O, no design
//! file: the layers above (`pdeshape-design`, `pdeshape-io`, `pdeshape-apps`) build on it, and the
//! `pdeshape` crate re-exports what a user needs. Two modules serve only those layers and are
//! not re-exported by `pdeshape`: `check` (the value checks with located messages that every
//! constructor and the design file share) and `formula` (the formula language and its compiled
//! programs).

#![warn(missing_docs)]

pub mod bfs;
pub mod check;
pub mod curve;
pub mod disk;
pub mod dynamic;
pub mod elliptic;
mod error;
pub mod fd;
pub mod formula;
pub mod fourier;
pub mod linalg;
pub mod majorant;
pub mod network;
pub mod nsided;
pub mod number;
mod quadrature;
pub mod scalar;
pub mod spline;
pub mod splinepde;
pub mod surface;

pub use error::{Error, ErrorKind, Result};

/// Points and vectors in R³.
pub type Vec3 = nalgebra::Vector3<f64>;

/// 2π: periodic curves live on `[0, 2π)`.
pub const TAU: f64 = std::f64::consts::TAU;
