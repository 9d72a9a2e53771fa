//! From triangle meshes to PDE patches: fitting and compression (book §8.2).
//!
//! A closed mesh of a tube-like or star-shaped body is cut by planes across its main axis; each
//! section becomes a periodic curve with one `v = 0` direction and one sense of turning for all
//! sections; consecutive sections are joined by biharmonic patches whose derivative curves are
//! chosen by least squares so the patches follow the mesh between them, and the ends are closed
//! by poles (a point and a derivative curve). Patches are split where the error exceeds the
//! target and merged where it allows ([`fit_tube`]). The result is an ordinary
//! [`DesignSpec`](crate::spec::DesignSpec): written with [`crate::spec::write_design`], read,
//! edited and re-tessellated at any resolution like any design.
//!
//! ```text
//! OBJ/STL/PLY bytes ──TriMesh::read──▶ TriMesh ──fit_tube──▶ TubeFit { spec, … }
//!                                                 │ design::solve_design(spec)
//!                                                 ▼
//!                        measure(mesh, spec, solved) ──▶ Hausdorff, RMS, compression
//! ```
//!
//! Modules: `mesh` (reading and topology checks), `section` (plane sections and their
//! periodic curves), `basis` (the biharmonic patch mode by mode as a function of its four
//! curves), `tube` (the automatic mode), `measure` (distances and sizes), `picture` (the mesh and
//! the fit side by side, coloured by distance).

mod basis;
mod measure;
mod mesh;
mod picture;
mod section;
mod tube;

pub use basis::weights;
pub use measure::{
    closest_on_triangle, count_numbers, measure, Distances, Measures, MeshDistance, PointDistances,
};
pub use mesh::{MeshFormat, Topology, TriMesh, MAX_TRIANGLES};
pub use picture::picture;
pub use section::{fourier, Frame, Section, Slicer};
pub use tube::{fit_tube, TubeFit, TubeOptions};
