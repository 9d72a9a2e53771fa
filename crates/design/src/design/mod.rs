//! The design layer: a parsed design file ([`crate::spec::DesignSpec`]) compiled once (planned,
//! validated, its curves built, every part dispatched to the solver it asks for) into a
//! [`CompiledDesign`] that holds a [`SolvedDesign`]; edits ([`Edit`]) re-solve only what they
//! touch.
//!
//! ```text
//! DesignSpec ──compile──▶ CompiledDesign ──solved()──▶ SolvedDesign (named surfaces, curves,
//!                 ▲             │                      conditions, spines, shared edges)
//!                 └──── apply(Edit) (re-solves what changed; returns the undo edit)
//! ```

mod attach;
mod blend;
mod compile;
mod curves;
mod disk;
mod dynamic;
mod edges;
mod edit;
mod fd;
mod network;
mod nsided;
mod nurbs;
mod parametric;
mod params;
mod patchwork;
mod preview;
mod solved;
mod spine;
mod spline;
mod transform;
mod trim;
mod validate;

pub use attach::{Attachment, AttachmentReport, CurveOnSurface, PathOnHost, TangentField};
pub use blend::{solve_blend, validate_blend};
pub use compile::{compile, solve_design, tangent_patches, validate_design, CompiledDesign};
pub use curves::{build_curve, build_curves};
pub use dynamic::{build_dynamic, BuiltDynamic, DynamicPlan, DynamicRun, MAX_INTERVALS};
pub use edges::{edge_mismatch, EdgeReport};
pub use edit::{Edit, PatchRef};
pub use fd::DEFAULT_GRID;
pub use network::{Joint, SolvedNetwork, CREASE_ANGLE};
pub use nurbs::NurbsSurface;
pub use params::{book_names, design_a, parse_book_name, poly_a, top_level_used, BookEdits};
pub use params::{
    design_parameters, resolve_parameters, set_parameter, DesignParameter, ParamKind,
};
pub use patchwork::MAX_PATCHWORK_ITEMS;
pub use solved::{
    curve_overlay, grid, ConditionInfo, DesignSurface, Export, NamedCurve, Overlay, OverlayKind,
    SharedEdge, SolvedDesign, SurfaceKind,
};
pub use spine::{
    spine_control_points, spine_hermite_of, spine_target, SpineEdited, SpineReport, Wave,
};
pub use spline::{build_problem, solve_spec, SolvedSpline};
pub use transform::{spec_point, transform_map, world_control_points};
pub use trim::{trim_curve, trim_method, SurfaceTrim};
pub use validate::{check_grid, DEFAULT_NU, DEFAULT_NV};

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_attach;
#[cfg(test)]
mod tests_local;
#[cfg(test)]
mod tests_network;
#[cfg(test)]
mod tests_nsided;
#[cfg(test)]
mod tests_params;
#[cfg(test)]
mod tests_patchwork;
#[cfg(test)]
mod tests_preview;
#[cfg(test)]
mod tests_spine;
