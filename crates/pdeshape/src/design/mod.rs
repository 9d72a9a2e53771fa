//! The design layer: a parsed design file ([`crate::spec::DesignSpec`]) planned, validated,
//! built into curves and conditions, and dispatched to the solver each part asks for.

mod blend;
mod build;
mod dynamic;
mod edges;
mod fd;
mod parametric;
mod spline;

pub use blend::{solve_blend, validate_blend};
pub use build::{
    build_curves, build_design, check_grid, validate_design, BuiltDesign, ConditionInfo,
    NamedCurve, SharedEdge, DEFAULT_NU, DEFAULT_NV,
};
pub use dynamic::{build_dynamic, BuiltDynamic, DynamicPlan, DynamicRun, MAX_INTERVALS};
pub use edges::{edge_mismatch, EdgeReport, Patch};
pub use fd::{build_fd_design, FdDesign, FdPatch, DEFAULT_GRID};
pub use parametric::ParametricPatch;
pub use spline::{build_problem, solve_spec, SolvedSpline};

#[cfg(test)]
mod tests;
