//! Writers. Each takes the patches of a design (one grid each) and writes them one after another.

use super::{GridMesh, Samples};
use crate::Result;
use std::io::Write;

/// Output formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Obj,
    Stl,
    Ply,
    Glb,
    Csv,
}

impl Format {
    /// The format for a path's extension (case-insensitive): obj, stl, ply, glb, csv.
    pub fn from_path(path: &std::path::Path) -> Result<Format> {
        let _ = path;
        todo!("writers")
    }
}

/// Wavefront OBJ with `v`, `vn`, `vt` and quad faces `f v/vt/vn`.
pub fn write_obj(meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    let _ = (meshes, w);
    todo!("writers")
}

/// Binary STL (triangles, facet normals from the vertex normals).
pub fn write_stl(meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    let _ = (meshes, w);
    todo!("writers")
}

/// Binary little-endian PLY with positions, normals, uv and faces.
pub fn write_ply(meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    let _ = (meshes, w);
    todo!("writers")
}

/// glTF 2.0 binary (`.glb`), one mesh primitive per patch.
pub fn write_glb(meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    let _ = (meshes, w);
    todo!("writers")
}

/// CSV samples `u,v,x,y,z,nx,ny,nz` (plus `patch` when there are several), rows u-major.
pub fn write_csv(samples: &[Samples], w: &mut dyn Write) -> Result<()> {
    let _ = (samples, w);
    todo!("writers")
}
