//! From triangle meshes to PDE patches: fitting and compression (book §8.2).
//!
//! Three modes, each producing an ordinary [`DesignSpec`](crate::spec::DesignSpec) (written
//! with [`crate::spec::write_design`], read, edited and re-tessellated at any resolution like
//! any design):
//!
//! - **tube** ([`fit_tube`]): a closed tube-like or star-shaped body is cut by planes across its
//!   main axis; each section becomes a periodic curve with one `v = 0` direction and one sense
//!   of turning for all sections; consecutive sections are joined by biharmonic patches whose
//!   derivative curves are chosen by least squares so the patches follow the mesh between
//!   them, and the ends are closed by poles.
//! - **sheet** ([`fit_sheet`]): an open surface (a face scan, §4.6) is cut by parallel planes
//!   into open profiles, each closed by an even reflection into a cosine series; patches with
//!   four position curves (§4.5) run through them.
//! - **template** ([`fit_template`]): the user names the planes of each part and its mode, for
//!   shapes the automatic modes cannot split.
//!
//! - **general** ([`fit_general`]): any edge-manifold, oriented mesh, closed or open, of any
//!   genus, as one `[[patchwork]]` of n-sided patches over a coarse layout of the mesh, G1
//!   across every layout edge (`layout`).
//!
//! [`fit_mesh`] chooses tube or sheet by whether the mesh is closed. In those modes patches are
//! split where the error exceeds the target and merged where it allows ([`chain`]).
//! [`fit_measured`] (`auto`) is what the command and Python call: the mode a user asks for, or
//! the automatic choice falling back to the general mode where the fast modes refuse the mesh
//! or miss the tolerance, measured.
//!
//! ```text
//! mesh bytes ──InputMesh::read────────▶ InputMesh ──fit_mesh / fit_template──▶ Fit { spec, … }
//!                                                 │ design::solve_design(spec)
//!                                                 ▼
//!                        measure(mesh, spec, solved) ──▶ Hausdorff, RMS, compression
//! ```
//!
//! Modules: `auto` (the tolerance and the choice of mode), `layout` (the general mode), `queue` (its candidate collapses, one per vertex), `features` (a mesh's sharp features: sectors, creases and the planes at them), `mesh` (reading and topology checks), `gltf_read` (glTF meshes and their frame), `repair` (what files leave that is not a
//! surface: degenerate and duplicate triangles, cracks, T-junctions, non-manifold edges, specks), `section` (plane sections: loops and open
//! pieces, and the periodic curves of loops), `profile` (open profiles as even periodic
//! curves), `basis` (the biharmonic patch mode by mode as a function of its four curves),
//! `chain` (the least squares over a sequence of sections, node choice, the design), `options`
//! (options, results and the automatic choice), `tube`, `sheet` and `template` (the modes),
//! `measure` (distances and sizes), `pack` (the packed size: numbers quantised to what the tolerance allows), `rate` (the rate–distortion sweep beside decimation, CSV and SVG), `picture` (the mesh and the fit side by side, coloured by
//! distance).

mod auto;
mod basis;
pub mod chain;
mod features;
mod frame;
mod gltf_read;
mod layout;
mod measure;
mod mesh;
mod options;
mod pack;
mod picture;
mod profile;
mod queue;
mod rate;
mod repair;
mod section;
mod sheet;
mod split;
mod template;
mod tube;

pub use auto::{
    fit_measured, measure_like, Fitted, ModeChoice, Request, DEFAULT_TOLERANCE, FAST_TARGET,
};
pub use basis::{position_weights, weights};
pub use frame::FileFrame;
pub use layout::{
    decimate, fit_general, fit_general_measured, layout_spec, require_oriented, vertex_normals,
    Decimation, Facing, Layout, Miss, MAX_ROUNDS, MEASURE_GRID,
};
pub use measure::{measure, Distances, Measures, MeshDistance, MeshSamples, PointDistances};
pub use mesh::{
    External, InputMesh, Joined, MeshFormat, MeshRead, Topology, MAX_COORDINATE, MAX_TRIANGLES,
    MIN_SPAN, WELD_FRACTION,
};
pub use options::{fit_mesh, Fit, FitMode, FitOptions, TubeFit, TubeOptions};
pub use pack::{pack, Packed, STEP_FRACTION};
pub use picture::{layout_edges, picture};
pub use rate::{
    rate_distortion, DecimatedPoint, RateDistortion, RatePoint, Refusal, MAX_TOLERANCES,
};
pub use repair::{
    repair, Repairs, CRACK_FRACTION, FOLD_SHARE, MAX_NONMANIFOLD_SHARE, MAX_PASSES, STRAY_EXTENT,
    STRAY_SHARE,
};
pub use section::{fourier, AxisFrame, Piece, Section, Slicer};
pub use sheet::{fit_sheet, SHEET_AM};
pub use template::{
    fit_template, parse_template, template_schema, End, Part, PartMode, Plane, Template,
};
pub use tube::{fit_open_tube, fit_tube, TUBE_A};
